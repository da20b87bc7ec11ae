//! The exceptions Python sees: `KinergyError` and below it `BvhError` (with `path`, `line`
//! and `column` where the reader knows them), `ParamsError`, `UnreachableError` and
//! `InputError` (bad arguments). Library errors are mapped here, once.

use pyo3::create_exception;
use pyo3::exceptions::PyException;
use pyo3::prelude::*;

create_exception!(
    kinergy,
    KinergyError,
    PyException,
    "Every error Kinergy raises (the CLI's messages)."
);
create_exception!(
    kinergy,
    BvhError,
    KinergyError,
    "A BVH file that cannot be read or written; `path`, `line` and `column` say where (None when unknown)."
);
create_exception!(
    kinergy,
    ParamsError,
    KinergyError,
    "A parameters or field file that cannot be read, or does not fit the arm it drives."
);
create_exception!(
    kinergy,
    UnreachableError,
    KinergyError,
    "A target the motion did not reach (beyond the arm, or not reached in time); `clip` holds the motion made."
);
create_exception!(
    kinergy,
    InputError,
    KinergyError,
    "An argument Kinergy refuses (a value out of range, an unknown name, a take with nothing to fit)."
);

/// Adds the exception classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    m.add("KinergyError", py.get_type::<KinergyError>())?;
    m.add("BvhError", py.get_type::<BvhError>())?;
    m.add("ParamsError", py.get_type::<ParamsError>())?;
    m.add("UnreachableError", py.get_type::<UnreachableError>())?;
    m.add("InputError", py.get_type::<InputError>())?;
    Ok(())
}

/// A `BvhError` for `e` (reading or writing), with its path, line and column.
pub fn bvh(e: &kinergy_bvh::Error) -> PyErr {
    let (path, line, column) = match e {
        kinergy_bvh::Error::Parse { path, source } => (
            Some(path.display().to_string()),
            Some(source.line),
            Some(source.column),
        ),
        kinergy_bvh::Error::Io { path, .. } | kinergy_bvh::Error::Write { path, .. } => {
            (Some(path.display().to_string()), None, None)
        }
        _ => (None, None, None),
    };
    let err = BvhError::new_err(e.to_string());
    Python::attach(|py| {
        let value = err.value(py);
        // Setting attributes on a fresh exception instance cannot fail but for memory.
        let _ = value.setattr("path", path);
        let _ = value.setattr("line", line);
        let _ = value.setattr("column", column);
    });
    err
}

/// A motion error: a BVH error as [`bvh`], the rest `KinergyError` (`InputError` for
/// invalid values given).
pub fn motion(e: kinergy_motion::MotionError) -> PyErr {
    use kinergy_motion::MotionError as E;
    match &e {
        E::Bvh(b) => bvh(b),
        E::Invalid { .. } | E::NonFinite { .. } | E::PoseLength { .. } => {
            InputError::new_err(e.to_string())
        }
        _ => KinergyError::new_err(e.to_string()),
    }
}

/// A training error: files and settings as `ParamsError` / `InputError`, a clip's BVH error
/// as `BvhError`, the rest `KinergyError`.
pub fn train(e: kinergy_train::TrainError) -> PyErr {
    use kinergy_train::TrainError as E;
    match e {
        E::Clip { source, .. } => match &source {
            kinergy_motion::MotionError::Bvh(b) => bvh(b),
            _ => KinergyError::new_err(source.to_string()),
        },
        E::Motion(m) => motion(m),
        E::Body(b) => reach(b),
        e @ (E::File { .. } | E::Checkpoint { .. }) => ParamsError::new_err(e.to_string()),
        e if e.is_nothing_to_fit() => InputError::new_err(e.to_string()),
        e @ (E::Setting { .. } | E::Arm { .. } | E::Frames { .. } | E::Row { .. }) => {
            InputError::new_err(e.to_string())
        }
        e => KinergyError::new_err(e.to_string()),
    }
}

/// A solver error: a parameters file's as `ParamsError`, a setting's as `InputError`.
pub fn solver(e: kinergy_solver::SolverError) -> PyErr {
    use kinergy_solver::SolverError as E;
    match e {
        e @ E::ParamsFile(_) => ParamsError::new_err(e.to_string()),
        e => KinergyError::new_err(e.to_string()),
    }
}

/// A full-body reaching error: parameters as `ParamsError`, settings as `InputError`.
pub fn reach(e: kinergy_reach::ReachError) -> PyErr {
    use kinergy_reach::ReachError as E;
    match e {
        e @ E::Params { .. } => ParamsError::new_err(e.to_string()),
        e @ E::Setting { .. } => InputError::new_err(e.to_string()),
        E::Motion(m) => motion(m),
        e => KinergyError::new_err(e.to_string()),
    }
}

/// `InputError(message)`.
pub fn input(message: impl Into<String>) -> PyErr {
    InputError::new_err(message.into())
}

/// `InputError` unless `value` of the keyword argument `name` is within `range` (both ends
/// included; NaN never is): the ranges are the CLI's ([`kinergy_train::limits`]).
pub fn check_range<T: PartialOrd + std::fmt::Display + Copy>(
    name: &str,
    value: T,
    range: (T, T),
) -> PyResult<()> {
    let (lo, hi) = range;
    if lo <= value && value <= hi {
        Ok(())
    } else {
        Err(input(format!("{name}={value}: expected {lo} to {hi}")))
    }
}
