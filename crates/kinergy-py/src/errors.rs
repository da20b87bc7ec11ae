//! The exceptions Python sees: `KinergyError` and below it `BvhError` (with `path`, `line`
//! and `column` where the reader knows them), `ParamsError`, `UnreachableError`,
//! `NothingToFitError` and `InputError` (bad arguments). Library errors are mapped here,
//! once, by their [`ErrorKind`] ([`raise`]).

use kinergy_io::{Classify, ErrorKind, Location};
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
    NothingToFitError,
    KinergyError,
    "The captures hold nothing to fit: no take has a reach on the arm asked for (the CLI exits 1)."
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
    m.add("NothingToFitError", py.get_type::<NothingToFitError>())?;
    Ok(())
}

/// The exception for a library error, by its kind ([`ErrorKind`], the rule the CLI's exit
/// codes follow too): `InputError`, `BvhError` (with `path`, `line` and `column`),
/// `ParamsError`, `NothingToFitError`, `UnreachableError`, or `KinergyError` for a file not
/// written, an interruption or another failed task.
pub fn raise<E: Classify>(e: E) -> PyErr {
    let message = e.to_string();
    match e.kind() {
        ErrorKind::Input => InputError::new_err(message),
        ErrorKind::Capture => bvh_error(message, e.location()),
        ErrorKind::Params => ParamsError::new_err(message),
        ErrorKind::NothingToFit => NothingToFitError::new_err(message),
        ErrorKind::Unreachable => UnreachableError::new_err(message),
        _ => KinergyError::new_err(message),
    }
}

/// [`raise`], the message naming `path` (the take the error is about) unless it does.
pub fn raise_naming<E: Classify>(path: &std::path::Path, e: E) -> PyErr {
    let named = e.to_string().contains(&*path.to_string_lossy());
    let err = raise(e);
    if named {
        return err;
    }
    Python::attach(|py| {
        let value = err.value(py);
        let message = format!("{}: {value}", path.display());
        // A fresh exception's args can always be replaced.
        let _ = value.setattr("args", (message,));
    });
    err
}

/// A `BvhError` saying `message`, with the file's `path`, `line` and `column` (None where
/// unknown).
fn bvh_error(message: String, at: Option<Location>) -> PyErr {
    let (path, line, column) = match at {
        Some(at) => (Some(at.path.display().to_string()), at.line, at.column),
        None => (None, None, None),
    };
    let err = BvhError::new_err(message);
    Python::attach(|py| {
        let value = err.value(py);
        // Setting attributes on a fresh exception instance cannot fail but for memory.
        let _ = value.setattr("path", path);
        let _ = value.setattr("line", line);
        let _ = value.setattr("column", column);
    });
    err
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
        Err(input(format!(
            "{name}={}: expected {lo} to {hi}",
            kinergy_io::quote_number(value)
        )))
    }
}
