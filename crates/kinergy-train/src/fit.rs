//! Fitting a synergy model to captured reaches: per clip (the paper's experiment: one reach,
//! one vector) or per person (one vector for all of a person's reaches), and the nested
//! sequence S_A → S_B → S_C → S_D in which each richer model starts from the poorer one's
//! solution.
//!
//! **The nested guarantee.** The annealer's member 0 starts at the poorer solution carried
//! into the richer space ([`ParamSpace::extend_to`]) and the best vector ever evaluated is
//! returned, so a richer fit never scores worse than that carried-over vector. S_A → S_B
//! and S_C → S_D carry over exactly (the same motion). S_B → S_C does not: the paper's
//! sigmoid sig(−s·t + o) with o ≥ 0 is at most ½ at t = 0, so S_C cannot reproduce S_B's
//! constant φ = 1; the carried vector switches the sigmoid on as early as the bounds allow
//! (s = s_max, o = o_min: φ > 0.95 after 0.3 s). [`NestedFit::violations`] lists any richer
//! fit that still ended worse than its poorer model, so a report can say so.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use kinergy_solver::{
    Bounds, FitGrouping, FitRecord, FittedReach, Model, Optimizer, ParamSpace, ParamsFile,
    StageScore,
};
use serde::{Deserialize, Serialize};

use crate::anneal::{AnnealSettings, AnnealState, Annealer, Checkpoint, Control, Observer, Status};
use crate::captured::{CapturedReach, DEFAULT_TOLERANCE};
use crate::error::{Result, TrainError, require};
use crate::objective::CostFunction;
use crate::objective::Objective;

/// How a fit searches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitSettings {
    /// The annealer's settings (its seed is mixed with the model for each fit).
    pub anneal: AnnealSettings,
    /// ε of the synthesis, meters.
    pub tolerance: f64,
    /// Parameter bounds.
    pub bounds: Bounds,
}

impl Default for FitSettings {
    fn default() -> FitSettings {
        FitSettings {
            anneal: AnnealSettings::default(),
            tolerance: DEFAULT_TOLERANCE,
            bounds: Bounds::default(),
        }
    }
}

/// One fitted model.
#[derive(Debug, Clone, PartialEq)]
pub struct Fit {
    /// The parameter space (model, DoF names, bounds).
    pub space: ParamSpace,
    /// The optimizer the motions were synthesized with.
    pub optimizer: Optimizer,
    /// The best vector.
    pub values: Vec<f64>,
    /// Its mean motion distance over the reaches, meters.
    pub score: f64,
    /// The start vector's score (the neutral vector, or the poorer model's solution).
    pub start_score: f64,
    /// The best vector's distance on each reach, meters, in the reaches' order.
    pub distances: Vec<f64>,
    /// Cost evaluations spent (each synthesizes every reach once).
    pub evaluations: usize,
    /// Annealing iterations.
    pub iterations: usize,
    /// Why the search ended.
    pub status: Status,
    /// The seed the annealer used.
    pub seed: u64,
    /// Frames synthesized in all (evaluations × frames per evaluation).
    pub frames_synthesized: usize,
}

impl Fit {
    /// The model.
    pub fn model(&self) -> Model {
        self.space.model()
    }

    /// The record of this fit on `reaches` (the reaches it was fitted on, in order).
    pub fn record(&self, reaches: &[CapturedReach]) -> FitRecord {
        FitRecord {
            method: "simulated_annealing".into(),
            score_m: self.score,
            start_score_m: self.start_score,
            evaluations: self.evaluations,
            iterations: self.iterations,
            status: self.status.name().into(),
            seed: self.seed,
            reaches: reaches
                .iter()
                .zip(&self.distances)
                .map(|(r, &distance_m)| FittedReach {
                    clip: r.name().to_string(),
                    frames: [r.frames().start, r.frames().end],
                    distance_m,
                })
                .collect(),
            per: None,
            nested: None,
        }
    }

    /// The parameters file of this fit, recording the reaches it was fitted on.
    pub fn params_file(&self, reaches: &[CapturedReach]) -> Result<ParamsFile> {
        let mut file = ParamsFile::new(&self.space, self.optimizer, &self.values)?;
        file.fit = Some(self.record(reaches));
        Ok(file)
    }
}

/// The seed of one model's fit: the user's seed mixed with the model, so each model of a
/// nested sequence draws differently but reproducibly.
pub fn model_seed(seed: u64, model: Model) -> u64 {
    let k = match model {
        Model::Sa => 1u64,
        Model::Sb => 2,
        Model::Sc => 3,
        Model::Sd => 4,
    };
    seed ^ k.wrapping_mul(0x9e37_79b9_7f4a_7c15)
}

/// A problem tag for checkpoints: model, optimizer and reaches.
pub fn tag_of(model: Model, optimizer: &Optimizer, reaches: &[CapturedReach]) -> String {
    let names: Vec<String> = reaches
        .iter()
        .map(|r| format!("{}[{}..{}]", r.name(), r.frames().start, r.frames().end))
        .collect();
    format!("{} {optimizer:?} {}", model.name(), names.join(" "))
}

/// Fits `model` to `reaches` with `optimizer`, starting from `start` (the model's neutral
/// vector when `None`). `observer` and `control` are the annealer's; pass a checkpoint
/// state to `resume` to continue an interrupted fit.
#[allow(clippy::too_many_arguments)]
pub fn fit_model(
    reaches: &[CapturedReach],
    model: Model,
    optimizer: Optimizer,
    start: Option<&[f64]>,
    settings: &FitSettings,
    observer: &mut dyn Observer,
    control: &Control<'_>,
    resume: Option<crate::anneal::AnnealState>,
) -> Result<Fit> {
    require(!reaches.is_empty(), "reaches", "at least one reach to fit")?;
    let space = ParamSpace::new(model, &reaches[0].dof_names(), settings.bounds)?;
    let objective = Objective::new(reaches.to_vec(), space.clone(), optimizer)?
        .with_tolerance(settings.tolerance)?;
    let start = match start {
        Some(s) => {
            space.validate(s)?;
            s.to_vec()
        }
        None => space.neutral(),
    };
    // Fail on a broken setup here, with its message, rather than as a silent f64::MAX.
    let start_score = objective.score(&start)?;
    let seed = model_seed(settings.anneal.seed, model);
    let annealer = Annealer::new(AnnealSettings {
        seed,
        ..settings.anneal
    })?;
    let tag = tag_of(model, &optimizer, reaches);
    let state = match resume {
        Some(state) => {
            let path = control
                .checkpoint
                .map(|c| c.path().to_path_buf())
                .unwrap_or_default();
            annealer.check_resume(&objective, &state, &tag, &path)?;
            state
        }
        None => annealer.init(&objective, &start, &tag)?,
    };
    let state = annealer.run(&objective, state, observer, control)?;
    let distances = objective.distances(&state.best_x)?;
    Ok(Fit {
        optimizer,
        values: state.best_x.clone(),
        score: state.best_cost,
        start_score,
        distances,
        evaluations: state.evaluations,
        iterations: state.iteration,
        status: state.status,
        seed,
        frames_synthesized: state.evaluations
            * objective
                .reaches()
                .iter()
                .map(CapturedReach::frame_count)
                .sum::<usize>(),
        space,
    })
}

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
        let last = self.fits.last().ok_or_else(|| TrainError::Setting {
            field: "models".into(),
            why: "at least one fitted model".into(),
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
    Ok(run.run(&mut (), None, None, false)?.fits)
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

/// The checkpoint of a nested fit: the finished stages and the running one's state.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NestedCheckpoint {
    /// [`crate::anneal::CHECKPOINT_VERSION`].
    pub format_version: u32,
    /// Names the problem: models, optimizer, reaches, settings.
    pub tag: String,
    /// Stages done, poorest first.
    pub completed: Vec<Stage>,
    /// The running stage's annealer state (`None` once every stage is done).
    pub current: Option<AnnealState>,
}

impl NestedCheckpoint {
    /// Reads a checkpoint, naming the file in errors.
    pub fn load(path: &Path) -> Result<NestedCheckpoint> {
        let bad = |why: String| TrainError::Checkpoint {
            path: path.to_path_buf(),
            why,
        };
        let text = std::fs::read_to_string(path).map_err(|source| TrainError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        let c: NestedCheckpoint = serde_json::from_str(&text).map_err(|e| bad(e.to_string()))?;
        if c.format_version != crate::anneal::CHECKPOINT_VERSION {
            return Err(bad(format!(
                "`format_version` is {}, this version reads {}",
                c.format_version,
                crate::anneal::CHECKPOINT_VERSION
            )));
        }
        Ok(c)
    }

    fn save(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_vec_pretty(self).map_err(|e| TrainError::Checkpoint {
            path: path.to_path_buf(),
            why: e.to_string(),
        })?;
        kinergy_bvh::write_atomic(path, &text).map_err(|source| TrainError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// Writes a [`NestedCheckpoint`] with the stages done so far around the running state.
struct NestedSink {
    path: PathBuf,
    tag: String,
    completed: Vec<Stage>,
}

impl Checkpoint for NestedSink {
    fn save(&self, state: &AnnealState) -> Result<()> {
        NestedCheckpoint {
            format_version: crate::anneal::CHECKPOINT_VERSION,
            tag: self.tag.clone(),
            completed: self.completed.clone(),
            current: Some(state.clone()),
        }
        .save(&self.path)
    }
    fn path(&self) -> &Path {
        &self.path
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
    /// The problem's name in checkpoints: models, optimizer, reaches and settings.
    pub fn tag(&self) -> String {
        let models: Vec<&str> = self.sorted_models().iter().map(|m| m.name()).collect();
        format!(
            "nested {} | {} | {:?} {} {:?}",
            models.join(","),
            tag_of(self.sorted_models()[0], &self.optimizer, self.reaches),
            self.settings.anneal,
            self.settings.tolerance,
            self.settings.bounds
        )
    }

    fn sorted_models(&self) -> Vec<Model> {
        let mut m = self.models.to_vec();
        m.sort();
        m.dedup();
        m
    }

    /// Runs the stages, writing `checkpoint` (path, iterations between writes) as it goes
    /// and stopping early when `interrupt` is set. With `resume`, continues from the
    /// checkpoint, which must belong to the same problem; the result is bit for bit the
    /// uninterrupted run's.
    pub fn run(
        &self,
        observer: &mut dyn Observer,
        checkpoint: Option<(&Path, usize)>,
        interrupt: Option<&AtomicBool>,
        resume: bool,
    ) -> Result<NestedOutcome> {
        require(
            !self.reaches.is_empty(),
            "reaches",
            "at least one reach to fit",
        )?;
        require(!self.models.is_empty(), "models", "at least one model")?;
        let models = self.sorted_models();
        let tag = self.tag();
        let (mut completed, mut current) = match (resume, checkpoint) {
            (true, Some((path, _))) => {
                let c = NestedCheckpoint::load(path)?;
                if c.tag != tag {
                    return Err(TrainError::Checkpoint {
                        path: path.to_path_buf(),
                        why: format!(
                            "it belongs to another fit (`{}`), not this one (`{tag}`)",
                            c.tag
                        ),
                    });
                }
                (c.completed, c.current)
            }
            (true, None) => {
                return Err(TrainError::Setting {
                    field: "resume".into(),
                    why: "needs a checkpoint file".into(),
                });
            }
            _ => (Vec::new(), None),
        };
        let mut fits: Vec<Fit> = Vec::with_capacity(models.len());
        for (i, &model) in models.iter().enumerate() {
            let space = ParamSpace::new(model, &self.reaches[0].dof_names(), self.settings.bounds)?;
            let objective = Objective::new(self.reaches.to_vec(), space.clone(), self.optimizer)?
                .with_tolerance(self.settings.tolerance)?;
            if let Some(stage) = completed.get(i) {
                require(
                    stage.model == model,
                    "checkpoint.completed",
                    "the same models in the same order",
                )?;
                fits.push(Fit {
                    distances: objective.distances(&stage.values)?,
                    optimizer: self.optimizer,
                    values: stage.values.clone(),
                    score: stage.score,
                    start_score: stage.start_score,
                    evaluations: stage.evaluations,
                    iterations: stage.iterations,
                    status: stage.status,
                    seed: stage.seed,
                    frames_synthesized: stage.evaluations * objective.frames_per_evaluation(),
                    space,
                });
                continue;
            }
            let start = match fits.last() {
                Some(poorer) => poorer.space.extend_to(&poorer.values, &space)?,
                None => space.neutral(),
            };
            let start_score = objective.score(&start)?;
            let seed = model_seed(self.settings.anneal.seed, model);
            let annealer = Annealer::new(AnnealSettings {
                seed,
                ..self.settings.anneal
            })?;
            let stage_tag = tag_of(model, &self.optimizer, self.reaches);
            let state = match current.take() {
                Some(state) => {
                    let path = checkpoint.map(|(p, _)| p.to_path_buf()).unwrap_or_default();
                    annealer.check_resume(&objective, &state, &stage_tag, &path)?;
                    state
                }
                None => annealer.init(&objective, &start, &stage_tag)?,
            };
            let sink = checkpoint.map(|(path, _)| NestedSink {
                path: path.to_path_buf(),
                tag: tag.clone(),
                completed: completed.clone(),
            });
            let control = Control {
                checkpoint: sink.as_ref().map(|s| s as &dyn Checkpoint),
                checkpoint_every: checkpoint.map_or(0, |(_, every)| every),
                interrupt,
            };
            let state = annealer.run(&objective, state, observer, &control)?;
            if state.status == Status::Interrupted {
                return Ok(NestedOutcome {
                    fits: NestedFit { fits },
                    interrupted: true,
                });
            }
            completed.push(Stage {
                model,
                values: state.best_x.clone(),
                score: state.best_cost,
                start_score,
                evaluations: state.evaluations,
                iterations: state.iteration,
                status: state.status,
                seed,
            });
            fits.push(Fit {
                distances: objective.distances(&state.best_x)?,
                optimizer: self.optimizer,
                values: state.best_x,
                score: state.best_cost,
                start_score,
                evaluations: state.evaluations,
                iterations: state.iteration,
                status: state.status,
                seed,
                frames_synthesized: state.evaluations * objective.frames_per_evaluation(),
                space,
            });
        }
        if let Some((path, _)) = checkpoint {
            NestedCheckpoint {
                format_version: crate::anneal::CHECKPOINT_VERSION,
                tag,
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
