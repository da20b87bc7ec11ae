//! The error type of `kinergy-solver`.

use kinergy_motion::MotionError;

/// Everything that can go wrong in `kinergy-solver`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SolverError {
    /// A skeleton, chain or clip operation failed.
    #[error(transparent)]
    Motion(#[from] MotionError),
    /// A setting is outside what it may be (named by its field, e.g. `optimizer.rate`).
    #[error(transparent)]
    Setting(#[from] kinergy_io::InvalidSetting),
    /// A synergy parameter lies outside its bounds.
    #[error(
        "synergy parameter `{name}` = {} is outside its bounds [{lower}, {upper}]",
        kinergy_io::Num(*value)
    )]
    OutOfBounds {
        /// The parameter's name, e.g. `g_elbow_flexion`.
        name: String,
        /// Its value.
        value: f64,
        /// Lower bound.
        lower: f64,
        /// Upper bound.
        upper: f64,
    },
    /// A parameter vector has the wrong length for its model and chain.
    #[error("model {model} on {dofs} DoFs needs {expected} parameters, got {found}")]
    ParamCount {
        /// The model.
        model: String,
        /// The chain's DoF count.
        dofs: usize,
        /// Parameters expected.
        expected: usize,
        /// Parameters given.
        found: usize,
    },
    /// A parameters file does not fit the chain or model it is used with, or is malformed.
    #[error("parameters file: {0}")]
    ParamsFile(String),
    /// A start posture, base or target has NaN or infinite values.
    #[error("{0} is not finite")]
    NonFinite(String),
    /// The capture cannot carry the synthesized arm (e.g. a joint lacks 3 rotation channels).
    #[error("cannot write the synthesized arm into the capture: {0}")]
    Capture(String),
}

/// Shorthand for results of this crate.
pub type Result<T, E = SolverError> = std::result::Result<T, E>;

impl kinergy_io::Classify for SolverError {
    /// Settings, parameters and non-finite values are the input's; an arm that cannot be
    /// written back into its capture, or a kinematics failure, is a failed task.
    fn kind(&self) -> kinergy_io::ErrorKind {
        match self {
            SolverError::Motion(_) | SolverError::Capture(_) => kinergy_io::ErrorKind::Task,
            SolverError::ParamsFile(_) => kinergy_io::ErrorKind::Params,
            _ => kinergy_io::ErrorKind::Input,
        }
    }
}
