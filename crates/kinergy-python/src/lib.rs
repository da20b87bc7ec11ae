//! The extension module `kinergy._kinergy` that maturin builds into the Python package
//! `kinergy` (`python/`): a shell around the library `kinergy-py`, which holds the classes,
//! verbs and exceptions ([`kinergy_py::register`]).

use pyo3::prelude::*;

/// The module.
#[pymodule]
fn _kinergy(m: &Bound<'_, PyModule>) -> PyResult<()> {
    kinergy_py::register(m)
}
