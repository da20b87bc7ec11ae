//! Watching a run: observers of its progress, the CSV log, checkpoint sinks, and the
//! control that says where checkpoints go and when to stop early.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use super::state::AnnealState;
use crate::error::{Result, TrainError};

/// What an observer sees after every iteration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Progress {
    /// Iterations done.
    pub iteration: usize,
    /// Evaluations done.
    pub evaluations: usize,
    /// The budget.
    pub max_evaluations: usize,
    /// The temperature used in this iteration.
    pub temperature: f64,
    /// The best cost so far.
    pub best_cost: f64,
    /// The population's mean cost.
    pub mean_cost: f64,
    /// The fraction of this iteration's proposals that were accepted.
    pub acceptance: f64,
}

/// Watches a run. Observers must not change the run: they only see it.
pub trait Observer {
    /// Before a nested fit's stage `index` (0-based) fits `model`: the iterations that follow
    /// are that model's until the next stage (a model's annealing may run in phases).
    fn on_stage(&mut self, _index: usize, _model: kinergy_solver::Model) {}
    /// After every iteration.
    fn on_iteration(&mut self, _progress: &Progress) {}
    /// After a checkpoint was written.
    fn on_checkpoint(&mut self, _path: &Path, _iteration: usize) {}
}

/// The observer that does nothing.
impl Observer for () {}

/// An observer borrowed.
impl<T: Observer + ?Sized> Observer for &mut T {
    fn on_stage(&mut self, index: usize, model: kinergy_solver::Model) {
        (**self).on_stage(index, model);
    }
    fn on_iteration(&mut self, p: &Progress) {
        (**self).on_iteration(p);
    }
    fn on_checkpoint(&mut self, path: &Path, iteration: usize) {
        (**self).on_checkpoint(path, iteration);
    }
}

/// Observers side by side.
impl<A: Observer, B: Observer> Observer for (A, B) {
    fn on_stage(&mut self, index: usize, model: kinergy_solver::Model) {
        self.0.on_stage(index, model);
        self.1.on_stage(index, model);
    }
    fn on_iteration(&mut self, p: &Progress) {
        self.0.on_iteration(p);
        self.1.on_iteration(p);
    }
    fn on_checkpoint(&mut self, path: &Path, iteration: usize) {
        self.0.on_checkpoint(path, iteration);
        self.1.on_checkpoint(path, iteration);
    }
}

/// A CSV log of the run, one row per iteration:
/// `iteration,evaluations,temperature,best_cost,mean_cost,acceptance`. Write errors are kept
/// and reported by [`CsvLog::finish`].
///
/// The log is written atomically (see [`kinergy_io::atomic`]): rows go to a temporary file
/// beside it, which replaces the log at each checkpoint and on [`CsvLog::finish`]. So the
/// file at its path is always whole: the previous log, or this run's up to its last
/// checkpoint (the iteration a resumed run continues from), or this run's complete log. A
/// log dropped without `finish` leaves the file as it last was.
#[derive(Debug)]
pub struct CsvLog {
    path: PathBuf,
    out: Option<kinergy_io::AtomicFile>,
    error: Option<std::io::Error>,
}

impl CsvLog {
    /// Starts the log (with its header), or continues the existing one when `append` (a
    /// resumed run).
    pub fn create(path: &Path, append: bool) -> Result<CsvLog> {
        use std::io::Write;
        let io = |source| TrainError::Io {
            path: path.to_path_buf(),
            source,
        };
        let mut out = kinergy_io::AtomicFile::create(path).map_err(io)?;
        let continued = append && out.copy_existing().map_err(io)?;
        if !continued {
            writeln!(
                out,
                "iteration,evaluations,temperature,best_cost,mean_cost,acceptance"
            )
            .map_err(io)?;
        }
        Ok(CsvLog {
            path: path.to_path_buf(),
            out: Some(out),
            error: None,
        })
    }

    /// Puts the complete log in place; the first write error, if any.
    pub fn finish(mut self) -> Result<()> {
        if let Some(out) = self.out.take()
            && self.error.is_none()
            && let Err(e) = out.commit()
        {
            self.error = Some(e);
        }
        match self.error.take() {
            Some(source) => Err(TrainError::Io {
                path: self.path.clone(),
                source,
            }),
            None => Ok(()),
        }
    }
}

impl Observer for CsvLog {
    fn on_iteration(&mut self, p: &Progress) {
        use std::io::Write;
        if self.error.is_some() {
            return;
        }
        if let Some(out) = self.out.as_mut()
            && let Err(e) = writeln!(
                out,
                "{},{},{},{},{},{}",
                p.iteration, p.evaluations, p.temperature, p.best_cost, p.mean_cost, p.acceptance
            )
        {
            self.error = Some(e);
        }
    }

    fn on_checkpoint(&mut self, _path: &Path, _iteration: usize) {
        if self.error.is_some() {
            return;
        }
        if let Some(out) = self.out.as_mut()
            && let Err(e) = out.publish()
        {
            self.error = Some(e);
        }
    }
}

/// Where checkpoints go; other sinks can wrap the state in more (e.g. the finished stages of a nested fit).
/// A [`PathBuf`] writes the [`AnnealState`] itself there, atomically.
pub trait Checkpoint {
    /// Writes `state`.
    fn save(&self, state: &AnnealState) -> Result<()>;
    /// The file written, for observers and messages.
    fn path(&self) -> &Path;
}

impl Checkpoint for PathBuf {
    fn save(&self, state: &AnnealState) -> Result<()> {
        state.save(self)
    }
    fn path(&self) -> &Path {
        self
    }
}

/// Checkpoints and early stopping for a run.
#[derive(Default)]
pub struct Control<'a> {
    /// Write the state here every `checkpoint_every` iterations and when the run ends.
    pub checkpoint: Option<&'a dyn Checkpoint>,
    /// Iterations between checkpoints (0: only at the end).
    pub checkpoint_every: usize,
    /// When this becomes true the run stops after the current iteration, writes its
    /// checkpoint and returns [`Status::Interrupted`](super::Status::Interrupted) (e.g. set from a Ctrl-C handler).
    pub interrupt: Option<&'a AtomicBool>,
}

impl std::fmt::Debug for Control<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Control")
            .field("checkpoint", &self.checkpoint.map(Checkpoint::path))
            .field("checkpoint_every", &self.checkpoint_every)
            .field("interrupt", &self.interrupt)
            .finish()
    }
}
