//! Watching a long call from Python: Ctrl-C and the optional progress callback.
//!
//! A fit runs with the GIL released; after every annealing iteration [`Watch`] attaches to
//! the interpreter for a moment to run its signal handlers (`KeyboardInterrupt` on Ctrl-C)
//! and call the user's callback. An exception from either stops the run at the end of that
//! iteration (the annealer's interrupt flag) and is raised when the call returns.

use std::sync::atomic::{AtomicBool, Ordering};

use kinergy_train::anneal::{Observer, Progress};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// The observer of a fit called from Python.
pub struct Watch<'a> {
    /// Called after every iteration with a dict (see `kinergy.fit`).
    pub callback: Option<&'a Py<PyAny>>,
    /// Raised to stop the run.
    pub interrupt: &'a AtomicBool,
    /// The exception that stopped it.
    pub error: Option<PyErr>,
    /// The model being fitted (0-based stage of the nested fit) and how many there are.
    pub stage: usize,
    /// The models fitted in turn, by name.
    pub models: Vec<&'static str>,
}

impl<'a> Watch<'a> {
    /// A watch calling `callback`, raising `interrupt`.
    pub fn new(
        callback: Option<&'a Py<PyAny>>,
        interrupt: &'a AtomicBool,
        models: Vec<&'static str>,
    ) -> Watch<'a> {
        Watch {
            callback,
            interrupt,
            error: None,
            stage: 0,
            models,
        }
    }

    /// Runs the signal handlers and the callback; an exception stops the run.
    fn check(&mut self, progress: Option<&Progress>) {
        if self.error.is_some() {
            return;
        }
        let model = self.models.get(self.stage).copied().unwrap_or("?");
        let outcome = Python::attach(|py| -> PyResult<()> {
            py.check_signals()
                .map_err(|e| explained(py, e, &format!("Ctrl-C during the fit of {model}")))?;
            if let (Some(callback), Some(p)) = (self.callback, progress) {
                let info = PyDict::new(py);
                info.set_item("model", model)?;
                info.set_item("stage", self.stage)?;
                info.set_item("stages", self.models.len())?;
                info.set_item("iteration", p.iteration)?;
                info.set_item("evaluations", p.evaluations)?;
                info.set_item("max_evaluations", p.max_evaluations)?;
                info.set_item("best_m", p.best_cost)?;
                info.set_item("mean_m", p.mean_cost)?;
                info.set_item("temperature", p.temperature)?;
                callback.call1(py, (info,)).map_err(|e| {
                    let at = format!(
                        "the progress callback raised at iteration {} of {model}: the fit stopped",
                        p.iteration
                    );
                    explained(py, e, &at)
                })?;
            }
            Ok(())
        });
        if let Err(e) = outcome {
            self.error = Some(e);
            self.interrupt.store(true, Ordering::SeqCst);
        }
    }

    /// Marks the start of the next group of models (a per-clip fit's next reach).
    pub fn next_group(&mut self) {
        self.stage = 0;
    }

    /// The exception that stopped the run, if one did; otherwise checks once more.
    pub fn finish(&mut self) -> PyResult<()> {
        self.check(None);
        self.error.take().map_or(Ok(()), Err)
    }
}

impl Observer for Watch<'_> {
    fn on_stage(&mut self, index: usize, _model: kinergy_solver::Model) {
        self.stage = index;
    }

    fn on_iteration(&mut self, progress: &Progress) {
        self.check(Some(progress));
    }
}

/// `error` saying `why` it stopped a run: a `KeyboardInterrupt` without a message (Ctrl-C, or
/// one a callback raised bare) becomes one that says it, caused by the original; any other
/// exception keeps its own message and gets `why` as a note (Python ≥ 3.11).
fn explained(py: Python<'_>, error: PyErr, why: &str) -> PyErr {
    let value = error.value(py);
    let bare = value
        .getattr("args")
        .is_ok_and(|a| a.len().is_ok_and(|n| n == 0));
    if error.is_instance_of::<pyo3::exceptions::PyKeyboardInterrupt>(py) && bare {
        let told = pyo3::exceptions::PyKeyboardInterrupt::new_err(why.to_string());
        if !why.starts_with("Ctrl-C") {
            told.set_cause(py, Some(error));
        }
        return told;
    }
    if value.hasattr("add_note").unwrap_or(false) {
        // A failed note leaves the exception as it was.
        let _ = value.call_method1("add_note", (why,));
    }
    error
}

/// Runs `work` on a worker thread with the GIL released while this (the calling) thread
/// checks for Ctrl-C every 25 ms and calls `tick` (e.g. to report progress): a
/// `KeyboardInterrupt`, or an exception `tick` raises, raises `stop` so the work ends early,
/// and is returned in place of the work's result.
pub fn watched<R: Send>(
    py: Python<'_>,
    stop: &AtomicBool,
    work: impl FnOnce() -> R + Send,
    mut tick: impl FnMut(Python<'_>) -> PyResult<()> + Send,
) -> PyResult<R> {
    let mut raised = None;
    let outcome = py.detach(|| {
        std::thread::scope(|scope| {
            let worker = scope.spawn(work);
            while !worker.is_finished() {
                std::thread::sleep(std::time::Duration::from_millis(25));
                let checked = Python::attach(|py| {
                    py.check_signals()?;
                    tick(py)
                });
                if let Err(e) = checked {
                    stop.store(true, std::sync::atomic::Ordering::SeqCst);
                    raised.get_or_insert(e);
                }
            }
            worker.join()
        })
    });
    if let Some(e) = raised {
        return Err(e);
    }
    outcome.map_err(|_| crate::errors::KinergyError::new_err("a worker thread failed"))
}
