//! What every subcommand shares: failures with exit codes, reading clips, output files.

use std::fmt;
use std::path::Path;

use kinergy_motion::UpChoice;
use kinergy_motion::{
    ArmJoints, Clip, ImportOptions, ImportReport, PositionReadingChoice, Side, UnitChoice,
};

/// Why a command stopped: bad input (exit 2) or a task that could not be done (exit 1).
#[derive(Debug)]
pub enum Failure {
    /// The input was wrong: a missing or malformed file, a bad argument.
    Input(String),
    /// The input was fine but the task failed (e.g. an unreachable target).
    Task(String),
}

impl Failure {
    pub fn exit_code(&self) -> u8 {
        match self {
            Failure::Input(_) => 2,
            Failure::Task(_) => 1,
        }
    }

    /// Bad input concerning `path`.
    pub fn input(path: &Path, e: impl fmt::Display) -> Failure {
        let text = e.to_string();
        // Library errors about files already name them.
        if text.contains(&*path.to_string_lossy()) {
            Failure::Input(text)
        } else {
            Failure::Input(format!("{}: {text}", path.display()))
        }
    }
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Failure::Input(m) | Failure::Task(m) => f.write_str(m),
        }
    }
}

/// Options for reading a capture, shared by every subcommand that reads BVH.
#[derive(Debug, clap::Args)]
pub struct ReadArgs {
    /// Length unit of the file: m, cm, mm, in, cmu (CMU's 0.0564 m), or auto (guessed from the
    /// skeleton's size in its first frame).
    #[arg(long = "from-unit", default_value = "auto", value_name = "UNIT")]
    pub from_unit: UnitChoice,
    /// How position channels combine with OFFSETs: auto (non-root joints replace it; the root
    /// takes the reading that puts the body's lowest point nearer the ground in the first
    /// frame, add on a tie), add, or replace (every joint).
    #[arg(long, default_value = "auto", value_name = "READING")]
    pub positions: PositionReadingChoice,
    /// The file's up axis: y, z, x (or -y, -z, -x), or auto (detected from the first frame).
    /// Read into Kinergy's Y-up world either way.
    #[arg(
        long,
        default_value = "auto",
        value_name = "AXIS",
        allow_hyphen_values = true
    )]
    pub up: UpChoice,
}

impl ReadArgs {
    pub fn read(&self, path: &Path) -> Result<(Clip, ImportReport), Failure> {
        let options = ImportOptions {
            unit: self.from_unit,
            position_reading: self.positions,
            up: self.up,
        };
        kinergy_motion::read_clip(path, &options).map_err(|e| Failure::input(path, e))
    }
}

/// How to find the arm chain.
#[derive(Debug, clap::Args)]
pub struct ArmArgs {
    /// Which arm.
    #[arg(long, default_value = "right", value_name = "SIDE")]
    pub arm: Side,
    /// The arm's joints by name, overriding the search: clavicle,shoulder,elbow,wrist (or
    /// shoulder,elbow,wrist).
    #[arg(long, value_delimiter = ',', value_name = "JOINTS")]
    pub chain: Option<Vec<String>>,
}

impl ArmArgs {
    pub fn find(&self, clip: &Clip, path: &Path) -> Result<ArmJoints, Failure> {
        let found = match &self.chain {
            Some(names) => {
                let names: Vec<&str> = names.iter().map(String::as_str).collect();
                ArmJoints::from_names(clip.skeleton(), &names)
            }
            None => ArmJoints::find(clip.skeleton(), self.arm),
        };
        found.map_err(|e| Failure::input(path, e))
    }
}

/// Prints a value as pretty JSON on stdout.
pub fn print_json(value: &impl serde::Serialize) -> Result<(), Failure> {
    let text = kinergy_io::to_pretty_json(value)
        .map_err(|e| Failure::Task(format!("could not encode JSON: {e}")))?;
    emit(&text)
}

/// Writes `text` to stdout. A closed pipe (`kinergy inspect … | head`) is not an error.
pub fn emit(text: &str) -> Result<(), Failure> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(Failure::Task(format!("could not write to stdout: {e}")))
        }
        _ => Ok(()),
    }
}
