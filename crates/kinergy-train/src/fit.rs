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

use kinergy_solver::{Bounds, Model, Optimizer, ParamSpace, ParamsFile};
use serde_json::json;

use crate::anneal::{AnnealSettings, Annealer, Control, Observer, Status};
use crate::error::{Result, require};
use crate::objective::Objective;
use crate::reach::{DEFAULT_TOLERANCE, ReachData};

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

    /// The parameters file of this fit, recording the reaches it was fitted on.
    pub fn params_file(&self, reaches: &[ReachData]) -> Result<ParamsFile> {
        let mut file = ParamsFile::new(&self.space, self.optimizer, &self.values)?;
        file.fit = Some(json!({
            "method": "simulated_annealing",
            "score_m": self.score,
            "start_score_m": self.start_score,
            "evaluations": self.evaluations,
            "iterations": self.iterations,
            "status": self.status.name(),
            "seed": self.seed,
            "reaches": reaches
                .iter()
                .zip(&self.distances)
                .map(|(r, d)| json!({
                    "clip": r.name(),
                    "frames": [r.frames().start, r.frames().end],
                    "distance_m": d,
                }))
                .collect::<Vec<_>>(),
        }));
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
pub fn tag(model: Model, optimizer: &Optimizer, reaches: &[ReachData]) -> String {
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
    reaches: &[ReachData],
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
    let tag = tag(model, &optimizer, reaches);
    let state = match resume {
        Some(state) => {
            let path = control
                .checkpoint
                .map(std::path::Path::to_path_buf)
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
                .map(ReachData::frame_count)
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
    reaches: &[ReachData],
    models: &[Model],
    optimizer: Optimizer,
    settings: &FitSettings,
) -> Result<NestedFit> {
    require(!models.is_empty(), "models", "at least one model")?;
    let mut models = models.to_vec();
    models.sort();
    models.dedup();
    let mut fits: Vec<Fit> = Vec::with_capacity(models.len());
    for model in models {
        let start = match fits.last() {
            Some(poorer) => {
                let richer = ParamSpace::new(model, poorer.space.dof_names(), settings.bounds)?;
                Some(poorer.space.extend_to(&poorer.values, &richer)?)
            }
            None => None,
        };
        let fit = fit_model(
            reaches,
            model,
            optimizer,
            start.as_deref(),
            settings,
            &mut (),
            &Control::default(),
            None,
        )?;
        fits.push(fit);
    }
    Ok(NestedFit { fits })
}
