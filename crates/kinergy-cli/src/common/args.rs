//! Options and argument parsers several subcommands share: reading a capture, finding the
//! arm, the annealer's search settings, and the `x,y,z`, `A..B` and `WxH` values.

use std::path::Path;

use kinergy_motion::nalgebra::Point3;
use kinergy_motion::{
    ArmJoints, Clip, ImportOptions, ImportReport, MotionError, PositionReadingChoice, Side,
    UnitChoice,
};
use kinergy_train::anneal::AnnealSettings;
use kinergy_train::fit::{FitSettings, OBJECTIVES, SearchOptions};

use super::failure::Failure;
use super::limits::{self, check_optional, check_range};

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
    pub up: kinergy_motion::UpChoice,
    /// The largest BVH file read, MiB (1 to 4096): a larger file is refused while reading.
    #[arg(long, default_value_t = limits::DEFAULT_INPUT_MB, value_name = "N")]
    pub max_input_mb: u64,
}

impl ReadArgs {
    /// Checks the options' ranges (before any work).
    pub fn check(&self) -> Result<(), Failure> {
        check_range("--max-input-mb", self.max_input_mb, limits::MAX_INPUT_MB)
    }

    /// The import options these flags say.
    pub fn options(&self) -> ImportOptions {
        ImportOptions {
            unit: self.from_unit,
            position_reading: self.positions,
            up: self.up,
            max_file_bytes: Some(self.max_input_mb.saturating_mul(kinergy_io::MIB)),
        }
    }

    /// Reads the clip at `path` with these options; errors name the file (and, for a file
    /// over the size limit, the flag that raises it).
    pub fn read(&self, path: &Path) -> Result<(Clip, ImportReport), Failure> {
        self.check()?;
        kinergy_motion::read_clip(path, &self.options()).map_err(|e| self.failure(path, e))
    }

    /// The clip at `path` could not be read: `e` naming the file, or, for a file over the
    /// size limit, the flag that raises it.
    pub fn failure(&self, path: &Path, e: MotionError) -> Failure {
        let too_large = matches!(
            &e,
            kinergy_motion::MotionError::Bvh(kinergy_bvh::Error::Io { source, .. })
                if source.kind() == std::io::ErrorKind::FileTooLarge
        );
        if too_large {
            Failure::Input(format!(
                "{}: larger than the {} MiB limit of --max-input-mb; raise it with \
                 --max-input-mb N (up to {})",
                path.display(),
                self.max_input_mb,
                limits::MAX_INPUT_MB.1
            ))
        } else {
            Failure::input(path, e)
        }
    }
}

/// Which arm `--arm` names: one side, or `auto`, each take's arms that reach.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ArmSide {
    /// This arm.
    Side(Side),
    /// Every arm of the take that reaches (a both-hands take: both).
    Auto,
}

impl std::str::FromStr for ArmSide {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s.eq_ignore_ascii_case("auto") {
            return Ok(ArmSide::Auto);
        }
        s.parse::<Side>()
            .map(ArmSide::Side)
            .map_err(|_| format!("unknown arm `{s}`: expected right, left or auto"))
    }
}

/// How to find the arm chain.
#[derive(Debug, clap::Args)]
pub struct ArmArgs {
    /// Which arm: right, left, or `auto` (fit, compare and segment: the arms of each take that
    /// reach — a both-hands take gives one reach per arm; a take where neither reaches is
    /// skipped, saying why).
    #[arg(long, default_value = "right", value_name = "right|left|auto")]
    pub arm: ArmSide,
    /// The arm's joints by name, overriding the search: clavicle,shoulder,elbow,wrist (or
    /// shoulder,elbow,wrist).
    #[arg(long, value_delimiter = ',', value_name = "JOINTS")]
    pub chain: Option<Vec<String>>,
}

impl ArmArgs {
    /// The one arm named, for the commands that work on one (`--arm auto` is refused:
    /// they cannot choose).
    pub fn side(&self) -> Result<Side, Failure> {
        match self.arm {
            ArmSide::Side(side) => Ok(side),
            ArmSide::Auto => Err(Failure::Input(
                "--arm auto: this command works on one arm; name it (right or left) — fit, \
                 compare and segment take auto"
                    .into(),
            )),
        }
    }

    /// The arm's joints in `clip` (read from `path`, named in errors). An unknown `--chain`
    /// joint gets "did you mean …"; an arm not found, the other arm (`--arm left`) when the
    /// skeleton has it, and `--chain`.
    pub fn find(&self, clip: &Clip, path: &Path) -> Result<ArmJoints, Failure> {
        self.find_side(clip, path, self.side()?)
    }

    /// [`find`](Self::find) on `side`.
    pub fn find_side(&self, clip: &Clip, path: &Path, side: Side) -> Result<ArmJoints, Failure> {
        let found = match &self.chain {
            Some(names) => {
                let names: Vec<&str> = names.iter().map(String::as_str).collect();
                ArmJoints::from_names(clip.skeleton(), &names)
            }
            None => ArmJoints::find(clip.skeleton(), side),
        };
        found.map_err(|e| arm_failure(e, clip, path, Some(side)))
    }
}

/// An arm that could not be found in `clip` (read from `path`), said for the command line:
/// an unknown `--chain` joint with "did you mean …" and the skeleton's joints; an arm not
/// found with the other arm when the skeleton has it (`side` is the one asked for with
/// `--arm`) and `--chain`.
pub fn arm_failure(e: MotionError, clip: &Clip, path: &Path, side: Option<Side>) -> Failure {
    let other = side.map(Side::opposite).filter(|&other| {
        matches!(e, MotionError::ArmNotFound { .. })
            && ArmJoints::find(clip.skeleton(), other).is_ok()
    });
    arm_failure_with(e, path, other)
}

/// [`arm_failure`] given `other`: the other side, when the arm was not found and the
/// skeleton has one there.
pub fn arm_failure_with(e: MotionError, path: &Path, other: Option<Side>) -> Failure {
    match e {
        MotionError::UnknownJoint { name, available } => {
            let known: Vec<&str> = available.iter().map(String::as_str).collect();
            Failure::input(
                path,
                format!("--chain: {}", super::names::unknown("joint", &name, &known)),
            )
        }
        e @ MotionError::ArmNotFound { .. } => Failure::input(
            path,
            format!(
                "{e}{}; or name its joints with --chain clavicle,shoulder,elbow,wrist",
                other.map_or_else(String::new, |o| format!(
                    "; this skeleton has a {o} arm: use --arm {o}"
                ))
            ),
        ),
        e => Failure::input(path, e),
    }
}

/// Search settings shared by `fit` and `compare`.
#[derive(Debug, clap::Args)]
pub struct SearchArgs {
    /// Seed of every random draw (same seed, same result, on any thread count).
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Threads, 1 to 1024 (default: all cores). The result does not depend on it.
    #[arg(long)]
    pub threads: Option<usize>,
    /// Evaluation budget per model fit, 1 to 10000000 (each evaluation synthesizes every
    /// reach once).
    #[arg(long, default_value_t = AnnealSettings::default().max_evaluations, value_name = "N")]
    pub budget: usize,
    /// Members of the annealing population, 1 to 1000.
    #[arg(long, default_value_t = AnnealSettings::default().population, value_name = "N")]
    pub population: usize,
    /// Initial temperature relative to the initial mean score, 0 to 1000000 (0: the paper's
    /// greedy rule).
    #[arg(long, default_value_t = AnnealSettings::default().temperature, value_name = "T")]
    pub temperature: f64,
    /// The stopping rule: a fit ends when the population's mean score changed by at most this
    /// share over the last `--stable-window` iterations, 0 to 1 (default: 0.0001; 0.001 for a
    /// library, `fit --per clip --out-dir`). A coarser rule is faster and scores about as
    /// well, but ends in other parameters: `docs/guide/libraries-and-clusters.md` "A library's
    /// stopping rule" measures what 0.001 over 15 iterations does.
    #[arg(long, value_name = "REL")]
    pub stable_change: Option<f64>,
    /// Iterations over which `--stable-change` is measured, 1 to 100000 (default: 25; 15 for a
    /// library).
    #[arg(long, value_name = "N")]
    pub stable_window: Option<usize>,
    /// What the fit minimizes: `positions` (the paper's mean joint-position distance) or
    /// `positions+speed` (plus `--speed-weight` × the RMS error of the hand's speed over the
    /// captured frames; `docs/guide/fitting.md` "`fit`" measures it).
    #[arg(long, value_enum, default_value_t = ObjectiveArg::Positions, value_name = "KIND")]
    pub objective: ObjectiveArg,
    /// With `--objective positions+speed`: meters of distance per m/s of RMS hand-speed error
    /// (seconds), 0 to 10; default 0.05. Refused with the paper's objective, which has no
    /// speed term.
    #[arg(long, value_name = "S")]
    pub speed_weight: Option<f64>,
}

/// `--objective`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum ObjectiveArg {
    /// The paper's joint-position distance.
    Positions,
    /// The distance plus the weighted hand-speed error.
    #[value(name = "positions+speed")]
    PositionsSpeed,
}

impl SearchArgs {
    /// Checks the options' ranges (before any work).
    pub fn check(&self) -> Result<(), Failure> {
        check_optional("--threads", self.threads, limits::THREADS)?;
        check_range("--budget", self.budget, limits::BUDGET)?;
        check_range("--population", self.population, limits::POPULATION)?;
        check_range("--temperature", self.temperature, limits::TEMPERATURE)?;
        check_optional("--stable-change", self.stable_change, limits::STABLE_CHANGE)?;
        check_optional("--stable-window", self.stable_window, limits::STABLE_WINDOW)?;
        check_optional("--speed-weight", self.speed_weight, limits::SPEED_WEIGHT)?;
        if self.speed_weight.is_some() && self.objective == ObjectiveArg::Positions {
            return Err(Failure::Input(
                "--speed-weight weighs the speed term of --objective positions+speed: add it, \
                 or drop --speed-weight"
                    .into(),
            ));
        }
        if self.budget < self.population {
            return Err(Failure::Input(format!(
                "--budget {}: at least --population ({}), the evaluations of the first \
                 generation",
                self.budget, self.population
            )));
        }
        Ok(())
    }

    /// Fit settings from the flags, with the default stopping rule where the flags give none.
    pub fn settings(&self) -> Result<FitSettings, Failure> {
        self.options(false).settings().map_err(Failure::from)
    }

    /// Fit settings from the flags for a library of captures: its stopping rule
    /// ([`AnnealSettings::for_library`]) where the flags give none.
    pub fn library_settings(&self) -> Result<FitSettings, Failure> {
        self.options(true).settings().map_err(Failure::from)
    }

    fn options(&self, library: bool) -> SearchOptions {
        SearchOptions {
            seed: self.seed,
            budget: Some(self.budget),
            population: Some(self.population),
            temperature: Some(self.temperature),
            stable_change: self.stable_change,
            stable_window: self.stable_window,
            objective: Some(
                match self.objective {
                    ObjectiveArg::Positions => OBJECTIVES[0],
                    ObjectiveArg::PositionsSpeed => OBJECTIVES[1],
                }
                .to_string(),
            ),
            speed_weight: self.speed_weight,
            library,
        }
    }

    /// Checks the options ([`SearchArgs::check`]), then sizes rayon's global pool.
    pub fn apply_threads(&self) -> Result<(), Failure> {
        self.check()?;
        if let Some(n) = self.threads {
            rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .build_global()
                .map_err(|e| Failure::Task(format!("--threads {n}: {e}")))?;
        }
        Ok(())
    }
}

/// Parses `x,y,z` (meters) into a finite point.
pub fn parse_point(text: &str, flag: &str) -> Result<Point3<f64>, Failure> {
    let parts: Vec<&str> = text.split(',').map(str::trim).collect();
    let bad = |why: String| {
        let quoted = kinergy_io::clip_text(text, 60);
        Failure::Input(format!("{flag} `{quoted}`: {why}"))
    };
    if parts.len() != 3 {
        return Err(bad(format!(
            "expected three comma-separated numbers x,y,z, got {}",
            parts.len()
        )));
    }
    let mut v = [0.0; 3];
    for (i, p) in parts.iter().enumerate() {
        let x: f64 = p
            .parse()
            .map_err(|_| bad(format!("`{p}` is not a number")))?;
        if !x.is_finite() {
            return Err(bad(format!("`{p}` is not a finite number")));
        }
        v[i] = x;
    }
    Ok(Point3::new(v[0], v[1], v[2]))
}

/// Parses a world target `x,y,z` (meters) for the character standing at the origin: a
/// finite point within [`kinergy_train::MAX_TARGET_DISTANCE`] of the origin. Farther, no
/// body reaches it whatever it does (it is a target in another unit, or a typo): bad input,
/// not an unreachable target to walk the arm toward.
pub fn parse_world_target(text: &str, flag: &str) -> Result<Point3<f64>, Failure> {
    check_world_target(parse_point(text, flag)?, text, flag)
}

/// `point`, read from `text` given with `flag`, when it is a target a body could reach
/// (see [`parse_world_target`]).
pub fn check_world_target(
    point: Point3<f64>,
    text: &str,
    flag: &str,
) -> Result<Point3<f64>, Failure> {
    // `hypot` does not overflow where the squares would (a target of 1e155 m).
    let distance = point.x.hypot(point.y).hypot(point.z);
    let max = kinergy_train::MAX_TARGET_DISTANCE;
    if distance > max {
        return Err(Failure::Input(format!(
            "{flag} `{}`: the target is {} from the character (standing at the origin), \
             beyond what any body reaches (at most {max} m): a target in another unit, or a typo?",
            kinergy_io::clip_text(text, 60),
            kinergy_io::meters(distance)
        )));
    }
    Ok(point)
}

/// `A..B` → `A..B`, with `A < B`.
pub fn parse_frames(text: &str) -> Result<std::ops::Range<usize>, Failure> {
    let bad = |why: &str| Failure::Input(format!("--frames `{text}`: {why}"));
    let (a, b) = text
        .split_once("..")
        .ok_or_else(|| bad("expected A..B, e.g. 12..140"))?;
    let a: usize = a
        .trim()
        .parse()
        .map_err(|_| bad("A is not a frame number"))?;
    let b: usize = b
        .trim()
        .parse()
        .map_err(|_| bad("B is not a frame number"))?;
    if a >= b {
        return Err(bad("A must be smaller than B"));
    }
    Ok(a..b)
}

/// `WxH` → (W, H) pixels, each side within [`limits::PICTURE_SIDE`]; errors name `--size`.
pub fn parse_size(text: &str) -> Result<(u32, u32), Failure> {
    let range = limits::PICTURE_SIDE.0..=limits::PICTURE_SIDE.1;
    let bad = |why: &str| Failure::Input(format!("--size `{text}`: {why}"));
    let (w, h) = text
        .split_once(['x', 'X'])
        .ok_or_else(|| bad("expected WxH, e.g. 640x480"))?;
    let side = |s: &str| -> Result<u32, Failure> {
        let n: u32 = s
            .trim()
            .parse()
            .map_err(|_| bad("W and H must be whole numbers of pixels"))?;
        if range.contains(&n) {
            Ok(n)
        } else {
            Err(bad(&format!(
                "each side must be {} to {} pixels",
                range.start(),
                range.end()
            )))
        }
    };
    Ok((side(w)?, side(h)?))
}
