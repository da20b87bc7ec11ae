//! What the subcommands share: failures with exit codes, output on stdout, the options
//! several subcommands take ([`args`]), clip paths ([`clips`]), captured reaches from the
//! command line ([`captured`]), the progress bar ([`progress`]) and the checks every output
//! passes before any work ([`outputs`]).

use std::path::Path;

pub mod args;
pub mod captured;
pub mod clips;
pub mod failure;
pub mod limits;
pub use kinergy_io::names;
pub mod outputs;
pub mod progress;

pub use args::{
    ArmArgs, ArmSide, ReadArgs, SearchArgs, check_world_target, parse_frames, parse_point,
    parse_size, parse_world_target,
};
pub use captured::{
    CaptureArgs, CaptureClips, ControllerKind, Skipped, nothing_to_fit, report_skipped,
};
pub use clips::collect_clips;
pub use failure::{Failure, person_failure, read_person};
pub use limits::{check_optional, check_range};
pub use outputs::{Output, check_outputs, clean_folder, is_stdout, make_folder};
pub use progress::Bar;

/// Writes `rows` as CSV (a header from the row type's fields) to `path`, atomically.
pub fn write_csv<T: serde::Serialize>(
    path: &Path,
    rows: impl IntoIterator<Item = T>,
) -> Result<(), Failure> {
    let name = path.display();
    let mut w = csv::Writer::from_writer(Vec::new());
    for row in rows {
        w.serialize(row)
            .map_err(|e| Failure::Task(format!("{name}: {e}")))?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| Failure::Task(format!("{name}: {e}")))?;
    kinergy_io::write_atomic(path, &bytes).map_err(|e| Failure::task(path, e))
}

/// The picture format the file name of `option` asks for (`.svg` or `.png`).
pub fn picture_format(path: &Path, option: &str) -> Result<kinergy_draw::Format, Failure> {
    kinergy_draw::Format::of(path).map_err(|e| Failure::Input(format!("{option} {e}")))
}

/// Prints a value as pretty JSON on stdout.
pub fn print_json(value: &impl serde::Serialize) -> Result<(), Failure> {
    let text = kinergy_io::to_pretty_json(value)
        .map_err(|e| Failure::Task(format!("could not encode JSON: {e}")))?;
    emit(&text)
}

/// Set by `--quiet`: reports are not printed (errors still go to stderr, and data asked
/// for on stdout with `-o -` is still written).
static QUIET: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Turns the stdout report off (`--quiet`) or on.
pub fn set_quiet(quiet: bool) {
    QUIET.store(quiet, std::sync::atomic::Ordering::Relaxed);
}

/// Writes the report `text` to stdout, unless `--quiet`. A closed pipe
/// (`kinergy inspect … | head`) is not an error.
pub fn emit(text: &str) -> Result<(), Failure> {
    if QUIET.load(std::sync::atomic::Ordering::Relaxed) {
        return Ok(());
    }
    emit_data(text.as_bytes())
}

/// How messages name an output: its path, or `standard output` for `-`.
pub fn shown(path: &Path) -> String {
    if is_stdout(path) {
        "standard output".into()
    } else {
        path.display().to_string()
    }
}

/// Writes `clip` as BVH to `path`, atomically, or to standard output for `-` (then the
/// report is not printed: the data has stdout). Errors name the file.
pub fn write_clip(
    path: &Path,
    clip: &kinergy_motion::Clip,
    options: &kinergy_motion::ExportOptions,
) -> Result<(), Failure> {
    if is_stdout(path) {
        set_quiet(true);
        let text = kinergy_bvh::to_string(&kinergy_motion::clip_to_bvh(clip, options))
            .map_err(|e| Failure::Task(format!("could not write the BVH: {e}")))?;
        return emit_data(text.as_bytes());
    }
    kinergy_motion::write_clip(path, clip, options).map_err(|e| Failure::task(path, e))
}

/// Writes data asked for on stdout (`-o -`), `--quiet` or not. A closed pipe is not an
/// error.
pub fn emit_data(bytes: &[u8]) -> Result<(), Failure> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(bytes).and_then(|()| out.flush()) {
        Err(e) if e.kind() != std::io::ErrorKind::BrokenPipe => {
            Err(Failure::Task(format!("could not write to stdout: {e}")))
        }
        _ => Ok(()),
    }
}

/// A length for people: three significant digits, in mm below 1 m (`4.20 mm`, `931 mm`,
/// `1.54 m`).
pub fn length(meters: f64) -> String {
    let (value, unit) = if meters.abs() < 1.0 {
        (meters * 1e3, "mm")
    } else {
        (meters, "m")
    };
    let digits = if value.abs() >= 100.0 {
        0
    } else if value.abs() >= 10.0 {
        1
    } else {
        2
    };
    format!("{value:.digits$} {unit}")
}

/// A flag's parser for a library enum read by its names (`FromStr`): clap lists `names` (with
/// their help, if given as [`clap::builder::PossibleValue`]s) in `--help` and the shell
/// completions, and the library's own parse makes the value.
pub fn named<T>(
    names: impl IntoIterator<Item = impl Into<clap::builder::PossibleValue>>,
) -> impl clap::builder::TypedValueParser<Value = T>
where
    T: std::str::FromStr + Clone + Send + Sync + 'static,
    T::Err: Into<Box<dyn std::error::Error + Send + Sync + 'static>>,
{
    use clap::builder::TypedValueParser;
    clap::builder::PossibleValuesParser::new(names).try_map(|s| s.parse::<T>())
}
