//! The error type of `kinergy-train`.

use std::ops::Range;
use std::path::{Path, PathBuf};

use kinergy_io::ErrorKind;
use kinergy_motion::{MotionError, Side};
use kinergy_solver::SolverError;

/// Everything that can go wrong in `kinergy-train`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum TrainError {
    /// A skeleton, chain or clip operation failed.
    #[error(transparent)]
    Motion(#[from] MotionError),
    /// The synergy solver refused a setting, a parameter or a reach.
    #[error(transparent)]
    Solver(#[from] SolverError),
    /// The full-body character could not reach (its settings, the person's parameters on
    /// it, a target it cannot take).
    #[error(transparent)]
    Body(#[from] kinergy_reach::ReachError),
    /// A setting is outside what it may be (named by its field, e.g. `anneal.population`).
    #[error(transparent)]
    Setting(#[from] kinergy_io::InvalidSetting),
    /// No reach could be found or prepared in a clip.
    #[error("{clip}: {why}")]
    Reach {
        /// The clip's name.
        clip: String,
        /// What is wrong.
        why: String,
    },
    /// A checkpoint cannot be read, written or resumed.
    #[error("checkpoint {}: {why}", path.display())]
    Checkpoint {
        /// The checkpoint file.
        path: PathBuf,
        /// What is wrong.
        why: String,
    },
    /// A parameters or field file cannot be read, is damaged, or is of another format
    /// version: `why` names the field (`samples[2].values`) or the line and column.
    #[error("{}{why}", file_prefix(.path.as_deref()))]
    File {
        /// The file, when the text was read from one.
        path: Option<PathBuf>,
        /// What is wrong.
        why: String,
    },
    /// A file could not be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The underlying error.
        source: std::io::Error,
    },
    /// A capture could not be read ([`crate::source`]).
    #[error("{}", naming(path, source))]
    Clip {
        /// The capture file.
        path: PathBuf,
        /// What reading it said.
        source: MotionError,
    },
    /// A capture's arm was not found ([`crate::source::ArmChoice`]).
    #[error(
        "{}{}",
        naming(path, source),
        other_side.map_or_else(String::new, |s| format!("; this skeleton has a {s} arm"))
    )]
    Arm {
        /// The capture file.
        path: PathBuf,
        /// Why the arm was not found: no such arm, or an unknown joint name.
        source: MotionError,
        /// The other side, when the arm was looked for by side, was not found, and the
        /// skeleton has an arm on the other side.
        other_side: Option<Side>,
    },
    /// A segments file is malformed, or a row's frames are outside its clip (a
    /// [`crate::segments_file::SegmentsFileError`]).
    #[error("{}: {why}", at(path, *line))]
    Segments {
        /// The segments file.
        path: PathBuf,
        /// The line (1-based), when the error is about one.
        line: Option<usize>,
        /// What is wrong.
        why: String,
    },
    /// The reach of a segments file's row could not be prepared: its clip could not be
    /// read, its arm was not found, or its frames make no reach.
    #[error("{}: {}: {source}", at(file, *line), clip.display())]
    Row {
        /// The segments file.
        file: PathBuf,
        /// The row's line (1-based), when it was read from the file.
        line: Option<usize>,
        /// The row's capture, as the clips were given.
        clip: PathBuf,
        /// What went wrong.
        source: Box<TrainError>,
    },
    /// A field was asked of reaches of both arms: its targets are in one arm's base frame.
    #[error(
        "{first} is a reach of the {} arm and {other} of the {} arm; a field holds one arm's \
         reaches (its targets are in that arm's base frame): fit each arm on its own",
        side_name(*first_side),
        side_name(*other_side)
    )]
    MixedArms {
        /// The first reach.
        first: String,
        /// Its arm's side.
        first_side: Option<Side>,
        /// A reach of another arm.
        other: String,
        /// That arm's side.
        other_side: Option<Side>,
    },
    /// No row of a segments file names any of the clips given.
    #[error("{}: no row names any of the clips given", file.display())]
    NoRows {
        /// The segments file.
        file: PathBuf,
    },
    /// A take with nothing to fit: no arm of it reaches (a walk, a wave that never leaves
    /// the hand somewhere). Not bad input in a library: the take is skipped, saying why.
    #[error("{}: nothing to fit: {why}", path.display())]
    NothingToFit {
        /// The capture.
        path: PathBuf,
        /// What there is instead, arm by arm.
        why: String,
    },
    /// A synthesized motion did not reach its target.
    #[error("{}", not_reached(stop, *final_error_m, *shoulder_to_target_m, *arm_length_m))]
    NotReached {
        /// Why the synthesis stopped.
        stop: String,
        /// The hand's distance to the target at the end, meters.
        final_error_m: f64,
        /// The shoulder's distance to the target on the last frame, meters.
        shoulder_to_target_m: f64,
        /// The arm's length, meters.
        arm_length_m: f64,
    },
    /// The user stopped a fit (its interrupt flag was raised).
    #[error("interrupted during the {}", match during {
        crate::fit::Interrupted::Annealing => "annealing",
        crate::fit::Interrupted::Refinement => "refinement",
    })]
    Interrupted {
        /// Where the fit was.
        during: crate::fit::Interrupted,
    },
    /// A set of takes that gave no reach: every one of them has nothing to fit.
    #[error("nothing to fit: all {takes} takes were skipped: {listed}")]
    NothingFound {
        /// How many takes.
        takes: usize,
        /// The first of them, each with why.
        listed: String,
    },
    /// The frames chosen for a reach are outside the clip or fewer than 2.
    #[error(
        "frames {}..{}: {clip} has {available} frames and a reach needs at least 2",
        frames.start,
        frames.end
    )]
    Frames {
        /// The clip's name.
        clip: String,
        /// The frames chosen.
        frames: Range<usize>,
        /// The clip's frames.
        available: usize,
    },
}

impl kinergy_io::Classify for TrainError {
    /// A take with no reach on the arm asked for (or on any arm with `--arm auto`) has
    /// nothing to fit, which a library run skips and lists; captures, parameters, checkpoints,
    /// segments files and settings that are not what they should be are the input's fault;
    /// the rest (a file not written, a fit that fails) failed tasks.
    fn kind(&self) -> ErrorKind {
        match self {
            TrainError::NothingToFit { .. }
            | TrainError::NothingFound { .. }
            | TrainError::Motion(MotionError::Reach { .. }) => ErrorKind::NothingToFit,
            TrainError::Body(e) => e.kind(),
            TrainError::Solver(e) => e.kind(),
            TrainError::Clip { .. } => ErrorKind::Capture,
            TrainError::File { .. } | TrainError::Checkpoint { .. } => ErrorKind::Params,
            TrainError::Setting(_)
            | TrainError::Reach { .. }
            | TrainError::Arm { .. }
            | TrainError::Segments { .. }
            | TrainError::Row { .. }
            | TrainError::NoRows { .. }
            | TrainError::MixedArms { .. }
            | TrainError::Frames { .. } => ErrorKind::Input,
            TrainError::Io { .. } => ErrorKind::Io,
            TrainError::Interrupted { .. } => ErrorKind::Interrupted,
            TrainError::NotReached { .. } => ErrorKind::Unreachable,
            TrainError::Motion(_) => ErrorKind::Task,
        }
    }

    fn location(&self) -> Option<kinergy_io::Location> {
        match self {
            TrainError::Clip { source, .. } | TrainError::Motion(source) => source.location(),
            TrainError::Body(e) => e.location(),
            TrainError::Row { source, .. } => source.location(),
            _ => None,
        }
    }
}

/// `e` naming `path` once: errors about files often name them already.
fn naming(path: &Path, e: &impl std::fmt::Display) -> String {
    let text = e.to_string();
    if text.contains(&*path.to_string_lossy()) {
        text
    } else {
        format!("{}: {text}", path.display())
    }
}

/// Why a motion did not reach: a target beyond the arm, or one not reached in time.
fn not_reached(stop: &str, error: f64, shoulder: f64, arm: f64) -> String {
    if shoulder > arm {
        format!(
            "the target is beyond reach by {:.1} mm: it is {:.3} m from the shoulder on the last \
             frame and the arm is {:.3} m long; the motion ends with the hand {:.1} mm from it",
            (shoulder - arm) * 1e3,
            shoulder,
            arm,
            error * 1e3
        )
    } else {
        format!(
            "the target was not reached ({stop}): the motion ends {:.1} mm from it",
            error * 1e3
        )
    }
}

/// `file line N`, or `file` for a row not read from it.
fn at(file: &Path, line: Option<usize>) -> String {
    match line {
        Some(line) => format!("{} line {line}", file.display()),
        None => file.display().to_string(),
    }
}

/// `path: ` for a file error read from a file, nothing otherwise.
fn file_prefix(path: Option<&std::path::Path>) -> String {
    path.map_or_else(String::new, |p| format!("{}: ", p.display()))
}

/// Shorthand for results of this crate.
pub type Result<T, E = TrainError> = std::result::Result<T, E>;

/// A [`TrainError::File`] error without a path, given `path` (other errors as they are).
pub(crate) fn in_file(e: TrainError, path: &std::path::Path) -> TrainError {
    match e {
        TrainError::File { path: None, why } => TrainError::File {
            path: Some(path.to_path_buf()),
            why,
        },
        other => other,
    }
}

/// A side's name, `unnamed` for an arm named by its joints.
fn side_name(side: Option<Side>) -> String {
    side.map_or_else(|| "unnamed".to_string(), |s| s.to_string())
}
