//! One model's fit (a *stage*): how it searches ([`FitSettings`]), its seed ([`model_seed`]),
//! running it ([`ModelRun`], [`fit_model`]) and what it gives ([`Fit`]). See the [parent module](super).

use kinergy_io::InvalidSetting;
use kinergy_solver::{
    Bounds, FitMethod, FitObjective, FitRecord, FittedReach, Model, Optimizer, ParamKind,
    ParamSpace, ParamsFile,
};

use super::refine::{RefineSettings, Refinement, refine_until};
use crate::anneal::{AnnealSettings, AnnealState, Annealer, Control, Observer, Status};
use crate::captured::{CapturedReach, DEFAULT_TOLERANCE};
use crate::error::Result;
use crate::objective::{CostFunction, Objective};

/// How a fit searches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitSettings {
    /// The annealer's settings (its seed is mixed with the model for each fit, see
    /// [`FitSettings::anneal_for`]).
    pub anneal: AnnealSettings,
    /// ε of the synthesis, meters.
    pub tolerance: f64,
    /// Parameter bounds.
    pub bounds: Bounds,
    /// What the fit minimizes: the paper's joint-position distance (the default), or that
    /// plus the weighted hand-speed error ([`FitObjective`]).
    pub objective: FitObjective,
}

impl Default for FitSettings {
    fn default() -> FitSettings {
        FitSettings {
            anneal: AnnealSettings::default(),
            tolerance: DEFAULT_TOLERANCE,
            bounds: Bounds::default(),
            objective: FitObjective::Positions,
        }
    }
}

impl FitSettings {
    /// The annealer's settings for a fit of `model`: [`FitSettings::anneal`] with its seed
    /// mixed with the model ([`model_seed`]).
    pub fn anneal_for(&self, model: Model) -> AnnealSettings {
        AnnealSettings {
            seed: model_seed(self.anneal.seed, model),
            ..self.anneal
        }
    }

    /// The objective of `model` on `reaches` (at least one) with `optimizer`: the parameter
    /// space of the first reach's DoFs within [`FitSettings::bounds`], ε =
    /// [`FitSettings::tolerance`], minimizing [`FitSettings::objective`].
    pub fn objective(
        &self,
        reaches: &[CapturedReach],
        model: Model,
        optimizer: Optimizer,
    ) -> Result<Objective> {
        InvalidSetting::require(!reaches.is_empty(), "reaches", "at least one reach to fit")?;
        let space = ParamSpace::new(model, &reaches[0].dof_names(), self.bounds)?;
        Objective::new(
            crate::captured::under_person_tempo(reaches),
            space,
            optimizer,
        )?
        .with_tolerance(self.tolerance)?
        .with_kind(self.objective)
    }
}

/// The seed of one model's fit: the user's seed mixed with the model, so each model of a
/// nested sequence draws differently but reproducibly: `seed ^ k · 0x9e3779b97f4a7c15`
/// ([`kinergy_motion::seed::combine`])
/// with k = 1, 2, 3, 4, 5 for S_A–S_E.
pub fn model_seed(seed: u64, model: Model) -> u64 {
    let k = match model {
        Model::Sa => 1u64,
        Model::Sb => 2,
        Model::Sc => 3,
        Model::Sd => 4,
        Model::Se => 5,
    };
    kinergy_motion::seed::combine(seed, k, 0)
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
    /// The local refinement that followed the annealing ([`Fit::refined`]), if any: its
    /// evaluations are counted in `evaluations`, its result is `values`.
    pub refinement: Option<Refinement>,
    /// What the fit minimized (its score and distances are that objective's values).
    pub objective: FitObjective,
}

impl Fit {
    /// The model.
    pub fn model(&self) -> Model {
        self.space.model()
    }

    /// This fit refined by Nelder–Mead and Levenberg–Marquardt ([`refine`](super::refine)) on `reaches` (the reaches it was
    /// fitted on) with the ε of `settings`: the values, score and distances of the best
    /// vector the refinement saw (never worse than the annealing's), the evaluations added.
    pub fn refined(
        self,
        reaches: &[CapturedReach],
        settings: &FitSettings,
        refine_settings: &RefineSettings,
    ) -> Result<Fit> {
        self.refined_until(reaches, settings, refine_settings, None)
    }

    /// [`Fit::refined`], stopping once `interrupt` is raised (Ctrl-C): the fit's
    /// [`Refinement::interrupted`](super::Refinement::interrupted) says so, and its values are
    /// the best so far, not a finished refinement's.
    pub fn refined_until(
        self,
        reaches: &[CapturedReach],
        settings: &FitSettings,
        refine_settings: &RefineSettings,
        interrupt: Option<&std::sync::atomic::AtomicBool>,
    ) -> Result<Fit> {
        let objective = settings.objective(reaches, self.model(), self.optimizer)?;
        let mut refinement = refine_until(&objective, &self.values, refine_settings, interrupt)?;
        // The refinement moves every parameter; those no reach can see stay neutral.
        let neutral = objective.space().neutral();
        for i in pinned_params(&objective) {
            refinement.values[i] = neutral[i];
        }
        let evaluations = self.evaluations + refinement.evaluations;
        Ok(Fit {
            distances: objective.distances(&refinement.values)?,
            values: refinement.values.clone(),
            score: refinement.score,
            evaluations,
            frames_synthesized: evaluations * objective.frames_per_evaluation(),
            refinement: Some(refinement),
            ..self
        })
    }

    /// The record of this fit on `reaches` (the reaches it was fitted on, in order).
    pub fn record(&self, reaches: &[CapturedReach]) -> FitRecord {
        FitRecord {
            method: match self.refinement {
                Some(_) => FitMethod::RefinedAnnealing,
                None => FitMethod::SimulatedAnnealing,
            },
            score_m: self.score,
            start_score_m: self.start_score,
            evaluations: self.evaluations,
            iterations: self.iterations,
            status: self.status.into(),
            seed: self.seed,
            reaches: reaches
                .iter()
                .zip(&self.distances)
                .map(|(r, &distance_m)| FittedReach {
                    clip: r.name().to_string(),
                    frames: [r.frames().start, r.frames().end],
                    distance_m,
                    arm: Some(r.fitted_arm().clone()),
                    tempo: Some(r.tempo()),
                })
                .collect(),
            per: None,
            nested: None,
            objective: self.objective.recorded(),
            unobserved: None,
            tempo_law: None,
            controller: reaches.first().map(CapturedReach::controller),
            started_from: None,
        }
    }

    /// The parameters file of this fit, recording the reaches it was fitted on (and the DoFs
    /// none of them could see, [`FitRecord::unobserved`]).
    pub fn params_file(&self, reaches: &[CapturedReach]) -> Result<ParamsFile> {
        let mut record = self.record(reaches);
        record.unobserved = unobserved_names(&self.space, &record);
        record.tempo_law = crate::captured::person_tempo(reaches);
        let mut file = ParamsFile::new(&self.space, self.optimizer, &self.values)?;
        file.fit = Some(record);
        Ok(file)
    }
}

/// The names of the DoFs of `space` that `record`'s reaches could not see
/// ([`FitRecord::unobserved_dofs`], which numbers the standard arm's DoFs); `None` when every
/// DoF was seen or `space` is not on the standard arm's DoFs.
pub(crate) fn unobserved_names(space: &ParamSpace, record: &FitRecord) -> Option<Vec<String>> {
    let names = space.dof_names();
    let arm = kinergy_motion::Chain::arm(1.0, 1.0, 0.0).ok()?;
    if !arm.dof_names().eq(names.iter().map(String::as_str)) {
        return None;
    }
    let hidden = record.unobserved_dofs();
    (!hidden.is_empty()).then(|| hidden.iter().map(|&d| names[d].clone()).collect())
}

/// One model's fit (a *stage*) that can be observed, checkpointed, interrupted and resumed,
/// as [`NestedRun`](super::NestedRun) runs a sequence of them: the reaches, the model, the
/// optimizer, where the search starts and how it searches. [`fit_model`] runs one from the
/// neutral vector with nothing watching.
#[derive(Debug, Clone, Copy)]
pub struct ModelRun<'a> {
    /// The reaches fitted (at least one).
    pub reaches: &'a [CapturedReach],
    /// The model.
    pub model: Model,
    /// The optimizer the motions are synthesized with.
    pub optimizer: Optimizer,
    /// The start vector, of `model`; `None`: the model's neutral vector.
    pub start: Option<&'a [f64]>,
    /// Search settings.
    pub settings: &'a FitSettings,
}

impl ModelRun<'_> {
    /// Runs the fit. `observer` and `control` are the annealer's; pass a checkpointed state of
    /// this same fit to `resume` to continue it (the annealer checks its settings, seed,
    /// bounds and model; [`NestedRun`](super::NestedRun) checks the whole problem).
    pub fn run(
        &self,
        observer: &mut dyn Observer,
        control: &Control<'_>,
        resume: Option<AnnealState>,
    ) -> Result<Fit> {
        let objective = self
            .settings
            .objective(self.reaches, self.model, self.optimizer)?;
        let start = match self.start {
            Some(s) => {
                objective.space().validate(s)?;
                s.to_vec()
            }
            None => objective.space().neutral(),
        };
        run_stage(&objective, &start, self.settings, resume, observer, control)
    }
}

/// Fits `model` to `reaches` with `optimizer` from the model's neutral vector: a
/// [`ModelRun`] with nothing watching (no observer, checkpoint or interruption).
pub fn fit_model(
    reaches: &[CapturedReach],
    model: Model,
    optimizer: Optimizer,
    settings: &FitSettings,
) -> Result<Fit> {
    let run = ModelRun {
        reaches,
        model,
        optimizer,
        start: None,
        settings,
    };
    run.run(&mut (), &Control::default(), None)
}

/// A model's fit on `objective` from `start` (or from `resume`, a state of the same stage):
/// the one place a stage runs, for a [`ModelRun`] and every stage of a [`NestedRun`].
pub(super) fn run_stage(
    objective: &Objective,
    start: &[f64],
    settings: &FitSettings,
    resume: Option<AnnealState>,
    observer: &mut dyn Observer,
    control: &Control<'_>,
) -> Result<Fit> {
    let model = objective.space().model();
    // The parameters of DoFs no reach can see are held at their neutral values (annealed,
    // they would be random walks that move the full body's hand).
    let neutral = objective.space().neutral();
    let pinned = pinned_params(objective);
    let mut held = start.to_vec();
    for &i in &pinned {
        held[i] = neutral[i];
    }
    let exact = held.as_slice();
    // Fail on a broken setup here, with its message, rather than as a silent f64::MAX.
    let start_score = objective.score(exact)?;
    // The search covers the paper's offsets (from the neutral one, o = 0, switching on as
    // the motion starts): a sigmoid on from before the start (a poorer model's constant φ
    // carried over, o at OFFSET_ON) starts it switching on at the start. The start itself
    // stays the stage's best-so-far: kept when the search ends worse.
    let raised = search_start(objective.space(), exact);
    let start = raised.as_slice();
    let anneal = settings.anneal_for(model);
    let annealer = Annealer::new(anneal)?;
    // S_E first searches its own parameters with S_D's held (see `own_first`), then all;
    // a resumed S_E stage runs that first phase again (deterministic) for its count.
    let own = own_first(objective, start, settings, observer, control)?;
    let (own_evaluations, own_iterations) = own
        .as_ref()
        .map_or((0, 0), |o| (o.evaluations, o.iterations));
    if own.as_ref().is_some_and(|o| o.interrupted) {
        // Interrupted in the first phase: nothing of this stage is checkpointed, so a
        // resumed fit starts it afresh, exactly as an uninterrupted one.
        return Ok(Fit {
            objective: objective.kind(),
            distances: objective.distances(exact)?,
            space: objective.space().clone(),
            optimizer: objective.optimizer(),
            values: exact.to_vec(),
            score: start_score,
            start_score,
            evaluations: own_evaluations,
            iterations: own_iterations,
            status: Status::Interrupted,
            seed: anneal.seed,
            frames_synthesized: own_evaluations * objective.frames_per_evaluation(),
            refinement: None,
        });
    }
    let start = match &own {
        Some(o) => o.values.as_slice(),
        None => start,
    };
    let searched = Searched::new(objective);
    let part = Subspace {
        inner: &searched,
        base: start.to_vec(),
        free: (0..objective.space().len())
            .filter(|i| !pinned.contains(i))
            .collect(),
    };
    // Nothing held: the objective itself, with no copy of the vector per evaluation.
    let cost: &dyn CostFunction = if pinned.is_empty() { &searched } else { &part };
    // The stage's name in the annealer's state; the problem itself is checked by value by
    // the caller's checkpoint (see `FitProblem`).
    let tag = model.name();
    let state = match resume {
        Some(state) => {
            let path = control
                .checkpoint
                .map(|c| c.path().to_path_buf())
                .unwrap_or_default();
            annealer.check_resume(cost, &state, tag, &path)?;
            state
        }
        None => annealer.init(cost, &part.part(start), tag)?,
    };
    let state = annealer.run(cost, state, observer, control)?;
    let (values, score) = if start_score < state.best_cost && state.status != Status::Interrupted {
        (exact.to_vec(), start_score)
    } else {
        (part.full(&state.best_x), state.best_cost)
    };
    Ok(Fit {
        objective: objective.kind(),
        distances: objective.distances(&values)?,
        space: objective.space().clone(),
        optimizer: objective.optimizer(),
        values,
        score,
        start_score,
        evaluations: own_evaluations + state.evaluations,
        iterations: own_iterations + state.iteration,
        status: state.status,
        seed: anneal.seed,
        frames_synthesized: (own_evaluations + state.evaluations)
            * objective.frames_per_evaluation(),
        refinement: None,
    })
}

/// `start` with every sigmoid offset below the neutral one (o = 0 with the default bounds:
/// a sigmoid on before the motion starts) raised to it, into the region [`Searched`] covers.
fn search_start(space: &ParamSpace, start: &[f64]) -> Vec<f64> {
    let neutral = space.neutral();
    start
        .iter()
        .zip(space.kinds())
        .zip(&neutral)
        .map(|((&v, &kind), &n)| {
            if kind == ParamKind::Offset {
                v.max(n)
            } else {
                v
            }
        })
        .collect()
}

/// The region of a model's space its search covers: its bounds, but the sigmoid offsets
/// from the neutral one up (the paper's o ≥ 0 with the default bounds). Below it a sigmoid
/// is on before the motion starts: the constant φ of S_A and S_B, which a carry-over holds
/// exactly ([`kinergy_solver::OFFSET_ON`]) and a stage keeps when its search ends worse, but
/// where moving an offset changes nothing a search could follow.
struct Searched<'a> {
    inner: &'a Objective,
    lower: Vec<f64>,
}

impl<'a> Searched<'a> {
    fn new(inner: &'a Objective) -> Searched<'a> {
        let space = inner.space();
        let (lower, _) = inner.bounds();
        let lower = search_start(space, &lower);
        Searched { inner, lower }
    }
}

impl CostFunction for Searched<'_> {
    fn dimension(&self) -> usize {
        self.inner.dimension()
    }

    fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        (self.lower.clone(), self.inner.bounds().1)
    }

    fn cost(&self, x: &[f64]) -> f64 {
        self.inner.cost(x)
    }

    fn cost_within(&self, x: &[f64], limit: f64) -> f64 {
        self.inner.cost_within(x, limit)
    }

    fn frames_per_evaluation(&self) -> usize {
        self.inner.frames_per_evaluation()
    }
}

/// S_E's first phase: its own parameters (the growth rates and the tempo factors, from
/// neutral) annealed with S_D's part held at `start`'s, on the same budget: the vector, its
/// evaluations and iterations; `None` for the other models. Started at S_D's solution, an
/// annealer moving every parameter at once finds nothing better (every proposal of 30
/// parameters moves S_D's sharp optimum too): on the shared people's takes 1–4 the
/// whole-vector stage ends where it begins for two persons of three.
fn own_first(
    objective: &Objective,
    start: &[f64],
    settings: &FitSettings,
    observer: &mut dyn Observer,
    control: &Control<'_>,
) -> Result<Option<OwnPhase>> {
    let space = objective.space();
    if space.model() != Model::Se {
        return Ok(None);
    }
    let pinned = pinned_params(objective);
    let own: Vec<usize> = (3 * space.dof_names().len()..space.len())
        .filter(|i| !pinned.contains(i))
        .collect();
    let part = Subspace {
        inner: objective,
        base: start.to_vec(),
        free: own,
    };
    let anneal = AnnealSettings {
        seed: kinergy_motion::seed::combine(settings.anneal_for(Model::Se).seed, 1, 0),
        ..settings.anneal
    };
    let annealer = Annealer::new(anneal)?;
    let state = annealer.init(&part, &part.part(start), "se-own")?;
    let quiet = Control {
        checkpoint: None,
        checkpoint_every: 0,
        interrupt: control.interrupt,
    };
    let state = annealer.run(&part, state, observer, &quiet)?;
    Ok(Some(OwnPhase {
        values: part.full(&state.best_x),
        evaluations: state.evaluations,
        iterations: state.iteration,
        interrupted: state.status == Status::Interrupted,
    }))
}

/// The parameters of `objective` held at their neutral values ([`ParamSpace::neutral`]: gain 1,
/// the sigmoid on from the start, growth 0) instead of annealed: those of the DoFs that no
/// reach can see ([`kinergy_solver::FittedArm::unobserved_dofs`] on every reach; the forearm's
/// twist and the wrist of a capture without a hand bone), whose values cannot change the
/// fitted motion and so would be random walks of the annealer. Shared parameters (S_A's gain,
/// S_C's sigmoid, S_E's tempo factors) are never held.
pub(crate) fn pinned_params(objective: &Objective) -> Vec<usize> {
    let mut hidden: Option<Vec<usize>> = None;
    for reach in objective.reaches() {
        let here = reach.fitted_arm().unobserved_dofs();
        hidden = Some(match hidden {
            None => here,
            Some(h) => h.into_iter().filter(|d| here.contains(d)).collect(),
        });
    }
    let space = objective.space();
    let names = space.dof_names();
    let hidden: Vec<&str> = hidden
        .unwrap_or_default()
        .into_iter()
        .filter_map(|d| names.get(d).map(String::as_str))
        .collect();
    space
        .names()
        .iter()
        .enumerate()
        .filter(|(_, name)| {
            name.split_once('_')
                .is_some_and(|(_, dof)| hidden.contains(&dof))
        })
        .map(|(i, _)| i)
        .collect()
}

/// What S_E's first phase ended with.
struct OwnPhase {
    /// The whole S_E vector (S_D's part as it started, S_E's own part the best found).
    values: Vec<f64>,
    evaluations: usize,
    iterations: usize,
    interrupted: bool,
}

/// A cost function over the entries `free` (in order) of `inner`'s vectors, the others held
/// at `base`'s.
struct Subspace<'a, C: CostFunction + ?Sized> {
    inner: &'a C,
    base: Vec<f64>,
    free: Vec<usize>,
}

impl<C: CostFunction + ?Sized> Subspace<'_, C> {
    fn full(&self, x: &[f64]) -> Vec<f64> {
        let mut v = self.base.clone();
        for (&i, &xi) in self.free.iter().zip(x) {
            v[i] = xi;
        }
        v
    }

    fn part(&self, full: &[f64]) -> Vec<f64> {
        self.free.iter().map(|&i| full[i]).collect()
    }
}

impl<C: CostFunction + ?Sized> CostFunction for Subspace<'_, C> {
    fn dimension(&self) -> usize {
        self.free.len()
    }

    fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        let (lower, upper) = self.inner.bounds();
        (self.part(&lower), self.part(&upper))
    }

    fn cost(&self, x: &[f64]) -> f64 {
        self.inner.cost(&self.full(x))
    }

    fn cost_within(&self, x: &[f64], limit: f64) -> f64 {
        self.inner.cost_within(&self.full(x), limit)
    }

    fn frames_per_evaluation(&self) -> usize {
        self.inner.frames_per_evaluation()
    }
}
