//! A fit as either front end asks for it: the models (the one asked for, or every poorer
//! one first), the optimizer, the search settings and an optional local refinement, run on a
//! group of reaches with checkpoints and interruption.

use std::sync::atomic::AtomicBool;

use kinergy_solver::{Model, Optimizer};

use super::{FitSettings, ModelRun, NestedFit, NestedRun, RefineSettings};
use crate::CapturedReach;
use crate::anneal::{Control, Observer, Status};
use crate::error::{Result, TrainError};

/// A nested fit of a group of reaches, then its refinement.
#[derive(Debug, Clone)]
pub struct FitJob {
    /// The models fitted, poorest first ([`FitJob::models_up_to`]).
    pub models: Vec<Model>,
    /// The IK optimizer the motions are synthesized with.
    pub optimizer: Optimizer,
    /// The search settings.
    pub settings: FitSettings,
    /// At most this many evaluations of a local refinement of the last model's vector after
    /// the annealing (none without).
    pub refine: Option<usize>,
}

/// Where a fit was when it was interrupted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interrupted {
    /// During the annealing: a checkpoint, where there is one, holds the fit so far.
    Annealing,
    /// During the refinement, which has no checkpoint: nothing of the fit is kept.
    Refinement,
}

impl FitJob {
    /// The models a fit of `model` runs: `model` alone, or (`nested`) every model up to it,
    /// each starting from the previous one's solution.
    pub fn models_up_to(model: Model, nested: bool) -> Vec<Model> {
        if nested {
            Model::ALL.into_iter().filter(|m| *m <= model).collect()
        } else {
            vec![model]
        }
    }

    /// Checks the settings before any work: the annealer's, and a refinement of at least
    /// one evaluation.
    pub fn validate(&self) -> Result<()> {
        self.settings.anneal.validate()?;
        if self.models.is_empty() {
            return Err(kinergy_io::InvalidSetting::new("models", "at least one model").into());
        }
        if self.refine == Some(0) {
            return Err(kinergy_io::InvalidSetting::new("refine", "at least 1 evaluation").into());
        }
        Ok(())
    }

    /// Fits `group` (one reach, or all of a person's): the nested stages, each iteration
    /// seen by `observer`, stopped and checkpointed as `control` says (resumed from its
    /// checkpoint with `resume`), then the refinement. [`TrainError::Interrupted`] when
    /// `control`'s flag stopped it.
    pub fn run(
        &self,
        group: &[CapturedReach],
        observer: &mut dyn Observer,
        control: &Control<'_>,
        resume: bool,
    ) -> Result<NestedFit> {
        let run = NestedRun {
            reaches: group,
            models: &self.models,
            optimizer: self.optimizer,
            settings: &self.settings,
        };
        let outcome = run.run(observer, control, resume)?;
        if outcome.interrupted {
            return Err(TrainError::Interrupted {
                during: Interrupted::Annealing,
            });
        }
        self.refine_last(group, outcome.fits, control)
    }

    /// The model asked for alone ([`FitJob::models`]' last), annealed from `start` — a
    /// vector of that model, such as a fit of another reach of the same person (a library's
    /// warm start, [`crate::library`]) — then the refinement, as [`run`](Self::run) does;
    /// stopped by `interrupt`, without checkpoints. The start stays the fit's best so far: a
    /// search that ends worse keeps it.
    pub fn run_from(
        &self,
        group: &[CapturedReach],
        start: &[f64],
        observer: &mut dyn Observer,
        interrupt: Option<&AtomicBool>,
    ) -> Result<NestedFit> {
        let Some(&model) = self.models.last() else {
            return Err(kinergy_io::InvalidSetting::new("models", "at least one model").into());
        };
        let control = Control {
            interrupt,
            ..Control::default()
        };
        let run = ModelRun {
            reaches: group,
            model,
            optimizer: self.optimizer,
            start: Some(start),
            settings: &self.settings,
        };
        let fit = run.run(observer, &control, None)?;
        if fit.status == Status::Interrupted {
            return Err(TrainError::Interrupted {
                during: Interrupted::Annealing,
            });
        }
        self.refine_last(group, NestedFit { fits: vec![fit] }, &control)
    }

    /// `fits` with its last fit refined, where the job asks for a refinement.
    fn refine_last(
        &self,
        group: &[CapturedReach],
        mut fits: NestedFit,
        control: &Control<'_>,
    ) -> Result<NestedFit> {
        let Some(max_evaluations) = self.refine else {
            return Ok(fits);
        };
        let Some(last) = fits.fits.pop() else {
            return Ok(fits);
        };
        let refined = last.refined_until(
            group,
            &self.settings,
            &RefineSettings {
                max_evaluations,
                ..RefineSettings::default()
            },
            control.interrupt,
        )?;
        // A refinement stopped part way is not the refined vector: nothing is returned.
        if refined.refinement.as_ref().is_some_and(|r| r.interrupted) {
            return Err(TrainError::Interrupted {
                during: Interrupted::Refinement,
            });
        }
        fits.fits.push(refined);
        Ok(fits)
    }

    /// [`run`](Self::run) without checkpoints, stopped by `interrupt`.
    pub fn run_stoppable(
        &self,
        group: &[CapturedReach],
        observer: &mut dyn Observer,
        interrupt: Option<&AtomicBool>,
    ) -> Result<NestedFit> {
        let control = Control {
            interrupt,
            ..Control::default()
        };
        self.run(group, observer, &control, false)
    }
}
