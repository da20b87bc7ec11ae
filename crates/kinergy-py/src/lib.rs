//! `kinergy._kinergy`: the extension module of the Python package `kinergy` (`python/`).
//!
//! Everything here is a thin layer over the library crates, doing what the `kinergy`
//! command does with the same defaults, so that a fit from Python writes the byte-identical
//! parameters file the CLI writes and a clip written from Python is the CLI's `convert`
//! output. Python sees [`clip::Clip`] (numpy in and out), [`params::Params`], the verbs
//! `read_bvh`, `segment`, `fit`, `synthesize`, `reach`, and the exceptions of [`errors`].
//!
//! Long calls release the GIL ([`Python::detach`]) and check for Ctrl-C between iterations
//! ([`progress::Watch`]): a `KeyboardInterrupt` stops them cleanly. Nothing that comes from
//! Python can panic across the boundary: every input is checked and every library error
//! becomes a Python exception.

use pyo3::prelude::*;

pub mod body;
pub mod clip;
pub mod compare;
pub mod errors;
pub mod library;
pub mod params;
pub mod progress;
pub mod reach;
pub mod synthesize;
pub mod verbs;

/// The module: classes, functions and exceptions.
#[pymodule]
fn _kinergy(m: &Bound<'_, PyModule>) -> PyResult<()> {
    verbs::LOADED_BY.get_or_init(std::process::id);
    m.add_class::<clip::Clip>()?;
    m.add_class::<params::Params>()?;
    m.add_function(wrap_pyfunction!(clip::read_bvh, m)?)?;
    m.add_function(wrap_pyfunction!(clip::_clip_from_state, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::segment, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::fit, m)?)?;
    m.add_function(wrap_pyfunction!(synthesize::synthesize, m)?)?;
    m.add_function(wrap_pyfunction!(reach::reach, m)?)?;
    m.add_function(wrap_pyfunction!(verbs::hand_speed, m)?)?;
    m.add_function(wrap_pyfunction!(body::style, m)?)?;
    m.add_function(wrap_pyfunction!(body::plan, m)?)?;
    m.add_function(wrap_pyfunction!(compare::compare, m)?)?;
    m.add_function(wrap_pyfunction!(library::collect, m)?)?;
    errors::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add(
        "RESULTS_COLUMNS",
        kinergy_train::experiment::Row::COLUMNS.to_vec(),
    )?;
    Ok(())
}
