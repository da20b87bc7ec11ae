//! `kinergy.compare`: the paper's experiments (Fig. 3, Fig. 4, the methods) on captures, as
//! `kinergy compare` runs them ([`kinergy_train::experiment::run_until`]): the same rows as
//! its `results.csv`, as dicts.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use kinergy_solver::{Model, OptimizerKind};
use kinergy_train::experiment::{ExperimentSettings, run_until};
use kinergy_train::fit::SearchOptions;
use pyo3::prelude::*;
use pyo3::types::PyList;

use crate::args::{
    Arg, ClipsArg, ReachSource, Reading, SelectArg, on_pool, parse, thread_pool, to_python,
};
use crate::errors;
use crate::progress::watched;

/// The paper's experiments on captures, as `kinergy compare` runs them: per reach, the models
/// fitted nested with `optimizer` (Fig. 3), S_A and S_C with each of `optimizers` (Fig. 4),
/// and with `baselines` S_C from neutral, Nelder–Mead and particle swarm at the same budget,
/// then the parameter field's leave-one-out rows. Returns one dict per fit with the columns of
/// the CLI's results.csv: clip, arm, onset, end, model, optimizer, method, distance_m,
/// frames, evaluations, seconds — the same numbers for the same inputs and seed (seconds
/// aside).
///
/// clips: paths, folders or Clips (or `segments=`), read and cut as `fit` reads them.
/// progress: called as each reach's fits end with (done, total). Ctrl-C stops the run after
/// the reaches in progress (KeyboardInterrupt).
#[pyfunction]
#[pyo3(signature = (clips = None, *, models = vec!["sa".to_string(), "sb".to_string(), "sc".to_string(), "sd".to_string()], optimizers = vec!["jt".to_string(), "njt".to_string(), "svd".to_string()], optimizer = "svd", baselines = true, arm = "right", chain = None, select = None, frames = None, segments = None, fixed_base = false, seed = 1, budget = None, population = None, temperature = None, stable_change = None, stable_window = None, objective = "positions", speed_weight = None, threads = None, progress = None, unit = "auto", up = "auto", positions = "auto"))]
#[allow(clippy::too_many_arguments)]
pub fn compare<'py>(
    py: Python<'py>,
    clips: Option<Arg<ClipsArg>>,
    models: Vec<String>,
    optimizers: Vec<String>,
    optimizer: &str,
    baselines: bool,
    arm: &str,
    chain: Option<Vec<String>>,
    select: Option<Arg<SelectArg>>,
    frames: Option<(usize, usize)>,
    segments: Option<PathBuf>,
    fixed_base: bool,
    seed: u64,
    budget: Option<usize>,
    population: Option<usize>,
    temperature: Option<f64>,
    stable_change: Option<f64>,
    stable_window: Option<usize>,
    objective: &str,
    speed_weight: Option<f64>,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
    unit: &str,
    up: &str,
    positions: &str,
) -> PyResult<Bound<'py, PyList>> {
    let models = models
        .iter()
        .map(|m| parse::<Model>("models", m))
        .collect::<PyResult<Vec<_>>>()?;
    let optimizers = optimizers
        .iter()
        .map(|o| parse::<OptimizerKind>("optimizers", o))
        .collect::<PyResult<Vec<_>>>()?;
    if models.is_empty() || optimizers.is_empty() {
        return Err(errors::input(
            "models and optimizers need at least one each",
        ));
    }
    let settings = ExperimentSettings {
        models,
        optimizers,
        optimizer: parse::<OptimizerKind>("optimizer", optimizer)?,
        baselines,
        fit: SearchOptions {
            seed,
            budget,
            population,
            temperature,
            stable_change,
            stable_window,
            objective: Some(objective.to_string()),
            speed_weight,
            library: false,
        }
        .settings()
        .map_err(errors::raise)?,
    };
    let pool = thread_pool(threads)?;
    let reaches = ReachSource {
        clips,
        segments,
        arm,
        chain,
        select,
        frames,
        fixed_base,
        reading: Reading {
            unit,
            up,
            positions,
        },
    }
    .load(py, kinergy_train::source::ControllerKind::default())?;
    let total = reaches.len();
    let done = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let count = || {
        done.fetch_add(1, Ordering::SeqCst);
    };
    let mut reported = 0;
    let results = watched(
        py,
        &stop,
        || on_pool(&pool, || run_until(&reaches, &settings, &count, &stop)),
        |py| {
            let now = done.load(Ordering::SeqCst);
            if let Some(callback) = &progress
                && now != reported
            {
                reported = now;
                callback.call1(py, (now, total))?;
            }
            Ok(())
        },
    )?
    .map_err(errors::raise)?
    .ok_or_else(|| errors::KinergyError::new_err("the experiment was stopped"))?;
    to_python(py, &results.rows)?
        .cast_into::<PyList>()
        .map_err(Into::into)
}
