//! The error type of `kinergy-reach`.

use kinergy_motion::MotionError;

/// Everything that can go wrong in `kinergy-reach`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReachError {
    /// A skeleton, chain or clip operation failed.
    #[error(transparent)]
    Motion(#[from] MotionError),
    /// An arm taken from a capture, or a synergy, could not be made.
    #[error(transparent)]
    Solver(#[from] kinergy_solver::SolverError),
    /// A setting or input is outside what it may be (named by its field, e.g. `person.height`).
    #[error(transparent)]
    Setting(#[from] kinergy_io::InvalidSetting),
    /// A file or folder could not be written (a full disk says "disk full").
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or folder.
        path: std::path::PathBuf,
        /// The operating system's error.
        source: std::io::Error,
    },
    /// A person's parameters do not fit the reach: a field's prediction out of its bounds, a
    /// non-finite target, DoF names that are not the character's arm's.
    #[error("{source}")]
    Params {
        /// The parameters' own error, naming the field.
        source: kinergy_solver::StyleError,
    },
}

/// Shorthand for results of this crate.
pub type Result<T, E = ReachError> = std::result::Result<T, E>;

impl kinergy_io::Classify for ReachError {
    /// Settings and targets are the input's fault, a person's parameters that do not fit
    /// the body the parameters file's; the rest (a file not written, a failed computation)
    /// failed tasks.
    fn kind(&self) -> kinergy_io::ErrorKind {
        match self {
            ReachError::Setting(_) => kinergy_io::ErrorKind::Input,
            ReachError::Params { .. } => kinergy_io::ErrorKind::Params,
            ReachError::Io { .. } => kinergy_io::ErrorKind::Io,
            ReachError::Motion(e) if e.location().is_some() => e.kind(),
            ReachError::Motion(_) | ReachError::Solver(_) => kinergy_io::ErrorKind::Task,
        }
    }

    fn location(&self) -> Option<kinergy_io::Location> {
        match self {
            ReachError::Motion(e) => e.location(),
            _ => None,
        }
    }
}
