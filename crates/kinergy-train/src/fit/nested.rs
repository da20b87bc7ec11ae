//! A nested fit ([`fit_nested`], giving a [`NestedFit`]) and the run behind it
//! ([`NestedRun`]), which can be checkpointed, interrupted and resumed: the stages done and the
//! running stage's annealer state, written atomically, under the problem's identity.

use std::path::Path;

use kinergy_io::InvalidSetting;
use kinergy_solver::{Bounds, FitGrouping, FitObjective, Model, Optimizer, ParamsFile, StageScore};
use serde::{Deserialize, Serialize};

use super::single::{Fit, FitSettings, run_stage};
use crate::anneal::{AnnealSettings, AnnealState, Checkpoint, Control, Observer, Status};
use crate::captured::CapturedReach;
use crate::error::{Result, TrainError};
use crate::objective::{CostFunction, Objective};

/// The fits of a nested sequence of models, poorest first.
#[derive(Debug, Clone, PartialEq)]
pub struct NestedFit {
    /// One fit per model, in the order fitted.
    pub fits: Vec<Fit>,
}

impl NestedFit {
    /// The fit of `model`, if it was fitted.
    pub fn get(&self, model: Model) -> Option<&Fit> {
        self.fits.iter().find(|f| f.model() == model)
    }

    /// The parameters file of the richest model, recording the reaches it was fitted on,
    /// how they were grouped and every model's score.
    pub fn params_file(
        &self,
        reaches: &[CapturedReach],
        grouping: FitGrouping,
    ) -> Result<ParamsFile> {
        let last = self.fits.last().ok_or_else(|| {
            TrainError::Setting(InvalidSetting::new("models", "at least one fitted model"))
        })?;
        let mut file = last.params_file(reaches)?;
        if let Some(record) = file.fit.as_mut() {
            record.per = Some(grouping);
            record.nested = Some(
                self.fits
                    .iter()
                    .map(|f| StageScore {
                        model: f.model(),
                        score_m: f.score,
                        evaluations: f.evaluations,
                    })
                    .collect(),
            );
        }
        Ok(file)
    }

    /// Pairs (poorer, richer) where the richer model ended with a higher score.
    pub fn violations(&self) -> Vec<(Model, Model)> {
        self.fits
            .windows(2)
            .filter(|w| w[1].score > w[0].score)
            .map(|w| (w[0].model(), w[1].model()))
            .collect()
    }
}

/// What a nested fit is: compared by value when a checkpoint is resumed, so a checkpoint
/// of another problem (other clips, frames, models, optimizer or settings) is refused.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FitProblem {
    /// The models, poorest first, each once.
    pub models: Vec<Model>,
    /// The optimizer and its settings.
    pub optimizer: Optimizer,
    /// The captured reaches, in order.
    pub reaches: Vec<ClipFrames>,
    /// The annealer's settings (before the seed is mixed with each model).
    pub anneal: AnnealSettings,
    /// ε of the synthesis, meters.
    pub tolerance: f64,
    /// Parameter bounds.
    pub bounds: Bounds,
    /// What the fit minimizes (absent in checkpoints of the paper's metric, as before it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub objective: Option<FitObjective>,
}

impl FitProblem {
    /// The names of the fields in which `self` and `other` differ.
    pub fn differences(&self, other: &FitProblem) -> Vec<&'static str> {
        [
            ("models", self.models != other.models),
            ("optimizer", self.optimizer != other.optimizer),
            ("reaches", self.reaches != other.reaches),
            ("anneal", self.anneal != other.anneal),
            ("tolerance", self.tolerance != other.tolerance),
            ("bounds", self.bounds != other.bounds),
            ("objective", self.objective != other.objective),
        ]
        .into_iter()
        .filter(|&(_, differs)| differs)
        .map(|(name, _)| name)
        .collect()
    }
}

/// A captured reach as a checkpoint names it: its clip and frames.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ClipFrames {
    /// The clip's name.
    pub clip: String,
    /// The reach's frames `[start, end)` in the clip.
    pub frames: [usize; 2],
}

impl ClipFrames {
    /// The clip and frames of `reach`.
    pub fn of(reach: &CapturedReach) -> ClipFrames {
        ClipFrames {
            clip: reach.name().to_string(),
            frames: [reach.frames().start, reach.frames().end],
        }
    }
}

/// One finished stage of a nested fit, as its checkpoint records it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stage {
    /// The model fitted.
    pub model: Model,
    /// The best vector.
    pub values: Vec<f64>,
    /// Its score.
    pub score: f64,
    /// The start vector's score.
    pub start_score: f64,
    /// Evaluations spent.
    pub evaluations: usize,
    /// Iterations.
    pub iterations: usize,
    /// Why it ended.
    pub status: Status,
    /// The annealer's seed.
    pub seed: u64,
}

impl Stage {
    /// The stage a finished fit records.
    fn of(fit: &Fit) -> Stage {
        Stage {
            model: fit.model(),
            values: fit.values.clone(),
            score: fit.score,
            start_score: fit.start_score,
            evaluations: fit.evaluations,
            iterations: fit.iterations,
            status: fit.status,
            seed: fit.seed,
        }
    }

    /// The fit this finished stage of a checkpoint records (its distances computed again).
    fn to_fit(&self, objective: &Objective) -> Result<Fit> {
        Ok(Fit {
            distances: objective.distances(&self.values)?,
            space: objective.space().clone(),
            optimizer: objective.optimizer(),
            values: self.values.clone(),
            score: self.score,
            start_score: self.start_score,
            evaluations: self.evaluations,
            iterations: self.iterations,
            status: self.status,
            seed: self.seed,
            frames_synthesized: self.evaluations * objective.frames_per_evaluation(),
            refinement: None,
            objective: objective.kind(),
        })
    }
}

/// The checkpoint of a nested fit: the finished stages and the running one's state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NestedCheckpoint {
    /// [`crate::anneal::CHECKPOINT_VERSION`].
    pub format_version: u32,
    /// The problem: models, optimizer, reaches, settings.
    pub problem: FitProblem,
    /// Stages done, poorest first.
    pub completed: Vec<Stage>,
    /// The running stage's annealer state (`None` once every stage is done).
    pub current: Option<AnnealState>,
}

impl NestedCheckpoint {
    /// Reads a checkpoint, naming the file in errors, and refuses a damaged one: the
    /// problem's settings valid, every finished stage consistent with them, the running
    /// stage's state checked as [`AnnealState::check`] does (fields named by their path,
    /// `current.members[3].x`).
    pub fn load(path: &Path) -> Result<NestedCheckpoint> {
        let checkpoint: NestedCheckpoint = crate::anneal::read_checkpoint(path)?;
        checkpoint
            .check()
            .map_err(|(field, why)| TrainError::Checkpoint {
                path: path.to_path_buf(),
                why: format!("`{field}` {why}"),
            })?;
        Ok(checkpoint)
    }

    /// See [`NestedCheckpoint::load`]: the first field that is wrong and why.
    pub fn check(&self) -> std::result::Result<(), (String, String)> {
        let anneal = &self.problem.anneal;
        if let Err(e) = anneal.validate() {
            return Err(("problem.anneal".into(), e.to_string()));
        }
        if self.completed.len() > self.problem.models.len() {
            return Err((
                "completed".into(),
                format!(
                    "has {} stages for {} models",
                    self.completed.len(),
                    self.problem.models.len()
                ),
            ));
        }
        for (i, stage) in self.completed.iter().enumerate() {
            let at = |f: &str| format!("completed[{i}].{f}");
            if stage.model != self.problem.models[i] {
                return Err((
                    at("model"),
                    format!(
                        "is {}, the problem's model {i} is {}",
                        stage.model.name(),
                        self.problem.models[i].name()
                    ),
                ));
            }
            if let Some(k) = stage.values.iter().position(|v| !v.is_finite()) {
                return Err((
                    format!("completed[{i}].values[{k}]"),
                    "is not a finite number".into(),
                ));
            }
            for (name, score) in [("score", stage.score), ("start_score", stage.start_score)] {
                if score.is_nan() || score < 0.0 {
                    return Err((at(name), format!("is {score}: expected ≥ 0")));
                }
            }
            // S_E runs two annealings (its own parameters, then all), each initialized once
            // and within the budget; its iterations are both runs'.
            let runs = if stage.model == Model::Se { 2 } else { 1 };
            let expected = stage
                .iterations
                .checked_add(runs)
                .and_then(|k| k.checked_mul(anneal.population));
            let budget = anneal.max_evaluations.saturating_mul(runs);
            if expected != Some(stage.evaluations) || stage.evaluations > budget {
                return Err((
                    at("evaluations"),
                    format!(
                        "is {} after {} iterations: expected population × (iterations + {runs}) within the budget of {budget}",
                        stage.evaluations, stage.iterations
                    ),
                ));
            }
            if matches!(stage.status, Status::Running | Status::Interrupted) {
                return Err((
                    at("status"),
                    format!(
                        "is {}: a finished stage converged or spent its budget",
                        stage.status.name()
                    ),
                ));
            }
        }
        match &self.current {
            Some(_) if self.completed.len() == self.problem.models.len() => Err((
                "current".into(),
                format!(
                    "holds a running stage after all {} stages are done",
                    self.completed.len()
                ),
            )),
            Some(state) => state
                .check()
                .map_err(|(f, why)| (format!("current.{f}"), why)),
            None => Ok(()),
        }
    }

    fn save(&self, path: &Path) -> Result<()> {
        kinergy_io::write_json(path, self).map_err(|source| TrainError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// Writes a [`NestedCheckpoint`] with the stages done so far around the running state.
struct NestedSink<'a> {
    path: &'a Path,
    problem: &'a FitProblem,
    completed: &'a [Stage],
}

impl Checkpoint for NestedSink<'_> {
    fn save(&self, state: &AnnealState) -> Result<()> {
        NestedCheckpoint {
            format_version: crate::anneal::CHECKPOINT_VERSION,
            problem: self.problem.clone(),
            completed: self.completed.to_vec(),
            current: Some(state.clone()),
        }
        .save(self.path)
    }
    fn path(&self) -> &Path {
        self.path
    }
}

/// A nested fit that can be checkpointed, interrupted and resumed.
#[derive(Debug, Clone, Copy)]
pub struct NestedRun<'a> {
    /// The reaches fitted (one for a per-clip fit, all of a person's for a per-person fit).
    pub reaches: &'a [CapturedReach],
    /// The models, in any order (fitted poorest first).
    pub models: &'a [Model],
    /// The optimizer.
    pub optimizer: Optimizer,
    /// Search settings.
    pub settings: &'a FitSettings,
}

/// How a [`NestedRun`] ended.
#[derive(Debug, Clone, PartialEq)]
pub struct NestedOutcome {
    /// The finished fits (all of them unless interrupted).
    pub fits: NestedFit,
    /// True when the run was interrupted; resume it from the checkpoint.
    pub interrupted: bool,
}

impl NestedRun<'_> {
    /// The problem, as its checkpoints name it.
    pub fn problem(&self) -> FitProblem {
        FitProblem {
            models: self.sorted_models(),
            optimizer: self.optimizer,
            reaches: self.reaches.iter().map(ClipFrames::of).collect(),
            anneal: self.settings.anneal,
            tolerance: self.settings.tolerance,
            bounds: self.settings.bounds,
            objective: self.settings.objective.recorded(),
        }
    }

    fn sorted_models(&self) -> Vec<Model> {
        let mut m = self.models.to_vec();
        m.sort();
        m.dedup();
        m
    }

    /// Runs the stages, as [`crate::anneal::Annealer::run`] runs one: `observer` sees every
    /// iteration of every stage; `control` says when to stop early, and where and how often
    /// to checkpoint — the run writes its own [`NestedCheckpoint`] (the stages done and the
    /// running state) to the path of `control.checkpoint`. With `resume`, continues from that
    /// checkpoint, which must belong to the same problem; the result is bit for bit the
    /// uninterrupted run's.
    pub fn run(
        &self,
        observer: &mut dyn Observer,
        control: &Control<'_>,
        resume: bool,
    ) -> Result<NestedOutcome> {
        InvalidSetting::require(
            !self.reaches.is_empty(),
            "reaches",
            "at least one reach to fit",
        )?;
        InvalidSetting::require(!self.models.is_empty(), "models", "at least one model")?;
        let models = self.sorted_models();
        let problem = self.problem();
        let path = control.checkpoint.map(Checkpoint::path);
        let (mut completed, mut current) = match (resume, path) {
            (true, Some(path)) => {
                let c = NestedCheckpoint::load(path)?;
                if c.problem != problem {
                    return Err(TrainError::Checkpoint {
                        path: path.to_path_buf(),
                        why: format!(
                            "it belongs to another fit (its {} differ)",
                            c.problem.differences(&problem).join(", ")
                        ),
                    });
                }
                (c.completed, c.current)
            }
            (true, None) => {
                return Err(TrainError::Setting(InvalidSetting::new(
                    "resume",
                    "needs a checkpoint file",
                )));
            }
            _ => (Vec::new(), None),
        };
        let mut fits: Vec<Fit> = Vec::with_capacity(models.len());
        for (i, &model) in models.iter().enumerate() {
            let objective = self
                .settings
                .objective(self.reaches, model, self.optimizer)?;
            if let Some(stage) = completed.get(i) {
                InvalidSetting::require(
                    stage.model == model,
                    "checkpoint.completed",
                    "the same models in the same order",
                )?;
                let damaged = |field: &str, why: String| TrainError::Checkpoint {
                    path: path.map(Path::to_path_buf).unwrap_or_default(),
                    why: format!("`completed[{i}].{field}` {why}"),
                };
                let dimension = crate::objective::CostFunction::dimension(&objective);
                if stage.values.len() != dimension {
                    return Err(damaged(
                        "values",
                        format!(
                            "has {} values; {} has {dimension}",
                            stage.values.len(),
                            model.name()
                        ),
                    ));
                }
                let (lower, upper) = crate::objective::CostFunction::bounds(&objective);
                if let Some(k) = (0..dimension)
                    .find(|&k| !(stage.values[k] >= lower[k] && stage.values[k] <= upper[k]))
                {
                    return Err(damaged(
                        &format!("values[{k}]"),
                        format!(
                            "is {}, outside its bounds [{}, {}]",
                            kinergy_io::Num(stage.values[k]),
                            kinergy_io::Num(lower[k]),
                            kinergy_io::Num(upper[k])
                        ),
                    ));
                }
                let seed = self.settings.anneal_for(model).seed;
                if stage.seed != seed {
                    return Err(damaged(
                        "seed",
                        format!(
                            "is {}, this fit's {} stage runs with {seed}",
                            stage.seed,
                            model.name()
                        ),
                    ));
                }
                fits.push(stage.to_fit(&objective)?);
                continue;
            }
            observer.on_stage(i, model);
            let start = match fits.last() {
                Some(poorer) => poorer.space.extend_to(&poorer.values, objective.space())?,
                None => objective.space().neutral(),
            };
            let sink = path.map(|path| NestedSink {
                path,
                problem: &problem,
                completed: &completed,
            });
            let stage_control = Control {
                checkpoint: sink.as_ref().map(|s| s as &dyn Checkpoint),
                ..*control
            };
            let fit = run_stage(
                &objective,
                &start,
                self.settings,
                current.take(),
                observer,
                &stage_control,
            )?;
            if fit.status == Status::Interrupted {
                return Ok(NestedOutcome {
                    fits: NestedFit { fits },
                    interrupted: true,
                });
            }
            completed.push(Stage::of(&fit));
            fits.push(fit);
        }
        if let Some(path) = path {
            NestedCheckpoint {
                format_version: crate::anneal::CHECKPOINT_VERSION,
                problem,
                completed,
                current: None,
            }
            .save(path)?;
        }
        Ok(NestedOutcome {
            fits: NestedFit { fits },
            interrupted: false,
        })
    }
}

/// Fits `models` (any order; fitted poorest first) to `reaches`, each richer model starting
/// from the previous one's solution.
pub fn fit_nested(
    reaches: &[CapturedReach],
    models: &[Model],
    optimizer: Optimizer,
    settings: &FitSettings,
) -> Result<NestedFit> {
    let run = NestedRun {
        reaches,
        models,
        optimizer,
        settings,
    };
    Ok(run.run(&mut (), &Control::default(), false)?.fits)
}
