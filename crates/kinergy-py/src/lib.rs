//! Kinergy from Python: everything the extension module `kinergy._kinergy` holds, as a Rust
//! library that the module's shell (`crates/kinergy-python`) registers with
//! [`register`], and that Rust code can reach.
//!
//! Each file is one Python verb — [`segment`], [`fit`], [`synthesize`], [`reach`],
//! [`style`], [`plan`], [`compare`], [`retarget`], [`library`] (`fit(..., out_dir=)` and
//! `collect`),
//! [`plot`] (`hand_speed`), [`view`] (the page of `kinergy view`) — or one of the classes ([`clip::Clip`], [`params::Params`]),
//! plus [`args`] (Python's arguments into the library's types, and its reports back),
//! [`errors`] (the exception classes, from the library errors' kinds) and [`progress`]
//! (Ctrl-C and progress callbacks). Each verb is parse → the library's request → run →
//! Python objects, doing what the `kinergy` command of the same name does with the same
//! defaults: a fit from Python writes the byte-identical parameters file the CLI writes.
//!
//! Long calls release the GIL ([`Python::detach`]) and check for Ctrl-C
//! ([`progress::Watch`], [`progress::watched`]): a `KeyboardInterrupt` stops them cleanly.
//! Nothing that comes from Python can panic across the boundary: every input is checked and
//! every library error becomes a Python exception.

use pyo3::prelude::*;

pub mod args;
pub mod clip;
pub mod compare;
pub mod convert;
pub mod errors;
pub mod fit;
pub mod library;
pub mod params;
pub mod plan;
pub mod plot;
pub mod progress;
pub mod reach;
pub mod retarget;
pub mod segment;
pub mod style;
pub mod synthesize;
pub mod view;

/// Fills the module `kinergy._kinergy`: classes, functions, exceptions and constants.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    args::LOADED_BY.get_or_init(std::process::id);
    m.add_class::<clip::Clip>()?;
    m.add_class::<params::Params>()?;
    m.add_function(wrap_pyfunction!(clip::read_bvh, m)?)?;
    m.add_function(wrap_pyfunction!(clip::from_positions, m)?)?;
    m.add_function(wrap_pyfunction!(clip::_clip_from_state, m)?)?;
    m.add_function(wrap_pyfunction!(segment::segment, m)?)?;
    m.add_function(wrap_pyfunction!(fit::fit, m)?)?;
    m.add_function(wrap_pyfunction!(synthesize::synthesize, m)?)?;
    m.add_function(wrap_pyfunction!(reach::reach, m)?)?;
    m.add_function(wrap_pyfunction!(plot::hand_speed, m)?)?;
    m.add_function(wrap_pyfunction!(view::view, m)?)?;
    m.add_function(wrap_pyfunction!(style::style, m)?)?;
    m.add_function(wrap_pyfunction!(plan::plan, m)?)?;
    m.add_function(wrap_pyfunction!(compare::compare, m)?)?;
    m.add_function(wrap_pyfunction!(retarget::retarget, m)?)?;
    m.add_function(wrap_pyfunction!(library::collect, m)?)?;
    errors::register(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add(
        "RESULTS_COLUMNS",
        kinergy_train::experiment::Row::COLUMNS.to_vec(),
    )?;
    Ok(())
}
