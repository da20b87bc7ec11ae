//! The error type of `kinergy-train`.

use std::path::PathBuf;

use kinergy_motion::MotionError;
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
    /// A setting is outside what it may be (named by its field).
    #[error("invalid `{field}`: {why}")]
    Setting {
        /// The setting's name, e.g. `anneal.population`.
        field: String,
        /// What was expected.
        why: String,
    },
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

/// A `Setting` error unless `ok`.
pub(crate) fn require(ok: bool, field: &str, why: impl Into<String>) -> Result<()> {
    if ok {
        Ok(())
    } else {
        Err(TrainError::Setting {
            field: field.to_string(),
            why: why.into(),
        })
    }
}
