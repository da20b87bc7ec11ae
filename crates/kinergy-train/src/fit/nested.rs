//! A nested fit that can be checkpointed, interrupted and resumed: the stages done and the
//! running stage's annealer state, written atomically, under the problem's identity.

use std::path::Path;

use kinergy_solver::{Bounds, Model, Optimizer};
use serde::{Deserialize, Serialize};

use super::{Fit, FitSettings, NestedFit, run_stage};
use crate::anneal::{AnnealSettings, AnnealState, Checkpoint, Control, Observer, Status};
use crate::captured::CapturedReach;
use crate::error::{Result, TrainError, require};

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
    /// Reads a checkpoint, naming the file in errors.
    pub fn load(path: &Path) -> Result<NestedCheckpoint> {
        let bad = |why: String| TrainError::Checkpoint {
            path: path.to_path_buf(),
            why,
        };
        let text = kinergy_io::read_to_string_limited(path, kinergy_io::MAX_JSON_BYTES).map_err(
            |source| TrainError::Io {
                path: path.to_path_buf(),
                source,
            },
        )?;
        kinergy_io::parse_versioned(&text, crate::anneal::CHECKPOINT_VERSION)
            .map_err(|e| bad(e.to_string()))
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
        require(
            !self.reaches.is_empty(),
            "reaches",
            "at least one reach to fit",
        )?;
        require(!self.models.is_empty(), "models", "at least one model")?;
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
                return Err(TrainError::Setting {
                    field: "resume".into(),
                    why: "needs a checkpoint file".into(),
                });
            }
            _ => (Vec::new(), None),
        };
        let mut fits: Vec<Fit> = Vec::with_capacity(models.len());
        for (i, &model) in models.iter().enumerate() {
            let objective = self
                .settings
                .objective(self.reaches, model, self.optimizer)?;
            if let Some(stage) = completed.get(i) {
                require(
                    stage.model == model,
                    "checkpoint.completed",
                    "the same models in the same order",
                )?;
                fits.push(Fit::from_stage(stage, &objective)?);
                continue;
            }
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
