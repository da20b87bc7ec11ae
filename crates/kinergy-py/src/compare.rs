//! `kinergy.compare`: the paper's experiments (Fig. 3, Fig. 4, the methods) on captures, as
//! `kinergy compare` runs them ([`kinergy_train::experiment::run_until`]): the same rows as
//! its `results.csv`, as dicts.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::Duration;

use kinergy_solver::{Model, OptimizerKind};
use kinergy_train::experiment::{ExperimentSettings, Results, run_until};
use pyo3::prelude::*;
use pyo3::types::PyList;

use crate::clip::parse;
use crate::errors;
use crate::verbs::{ReachSource, fit_settings, thread_pool};

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
    clips: Option<&Bound<'py, PyAny>>,
    models: Vec<String>,
    optimizers: Vec<String>,
    optimizer: &str,
    baselines: bool,
    arm: &str,
    chain: Option<Vec<String>>,
    select: Option<&Bound<'py, PyAny>>,
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
        fit: fit_settings(
            false,
            seed,
            budget,
            population,
            temperature,
            stable_change,
            stable_window,
            objective,
            speed_weight,
        )?,
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
        reading: (unit, up, positions),
    }
    .load(py, kinergy_train::source::Controller::default())?;
    let total = reaches.len();
    let done = AtomicUsize::new(0);
    let stop = AtomicBool::new(false);
    let mut raised = None;
    let outcome = py.detach(|| {
        std::thread::scope(|scope| {
            let worker = scope.spawn(|| {
                let go = || {
                    run_until(
                        &reaches,
                        &settings,
                        &|| {
                            done.fetch_add(1, Ordering::SeqCst);
                        },
                        &stop,
                    )
                };
                match &pool {
                    Some(pool) => pool.install(go),
                    None => go(),
                }
            });
            // This (the calling) thread watches for Ctrl-C and reports progress.
            let mut reported = 0;
            while !worker.is_finished() {
                std::thread::sleep(Duration::from_millis(25));
                let now = done.load(Ordering::SeqCst);
                let checked = Python::attach(|py| -> PyResult<()> {
                    py.check_signals()?;
                    if let Some(callback) = &progress
                        && now != reported
                    {
                        callback.call1(py, (now, total))?;
                    }
                    Ok(())
                });
                reported = now;
                if let Err(e) = checked {
                    stop.store(true, Ordering::SeqCst);
                    raised.get_or_insert(e);
                }
            }
            worker.join()
        })
    });
    if let Some(e) = raised {
        return Err(e);
    }
    let results = outcome
        .map_err(|_| errors::KinergyError::new_err("the experiment's worker thread failed"))?
        .map_err(errors::raise)?
        .ok_or_else(|| errors::KinergyError::new_err("the experiment was stopped"))?;
    rows(py, &results)
}

/// The results as dicts with results.csv's columns ([`kinergy_train::experiment::Row`]'s
/// one schema).
fn rows<'py>(py: Python<'py>, results: &Results) -> PyResult<Bound<'py, PyList>> {
    let json = py.import("json")?;
    let out = PyList::empty(py);
    for r in &results.rows {
        let text = serde_json::to_string(r)
            .map_err(|e| errors::KinergyError::new_err(format!("results row: {e}")))?;
        out.append(json.call_method1("loads", (text,))?)?;
    }
    Ok(out)
}
