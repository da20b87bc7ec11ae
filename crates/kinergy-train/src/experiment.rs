//! The paper's comparison on a set of captured reaches (Aubry, Julliard & Gibet 2009, §4;
//! DESIGN §1.1), plus what simulated annealing buys over argmin's optimizers and what the
//! parameter field predicts:
//!
//! - **Fig. 3** — every model of [`ExperimentSettings::models`] fitted per clip with
//!   [`ExperimentSettings::optimizer`], nested: each richer model starts from the poorer one's
//!   solution ([`crate::fit::fit_nested`]).
//! - **Fig. 4** — every optimizer of [`ExperimentSettings::optimizers`] with S_A and with S_C,
//!   per clip (S_C starting from S_A's solution; for the Fig. 3 optimizer the Fig. 3 fits are
//!   reused when they include S_A and S_C).
//! - **Methods** — S_C per clip from its neutral vector under the same evaluation budget with
//!   simulated annealing, argmin's Nelder–Mead and argmin's particle swarm.
//! - **Parameter field** — per person (the clips of one folder), each clip's S_C parameters
//!   predicted from the other clips' Fig. 3 fits by the field over targets, scored on the clip
//!   (leave one target out).
//!
//! - **Held-out takes** — per person, models fitted on all but the last K takes, scored on
//!   those K against neutral parameters, against the other persons' vectors, and (with
//!   [`HoldoutSettings::field`]) the person's parameter field against their single vector
//!   ([`run_holdout`], module `holdout`).
//!
//! [`run`] returns one [`Row`] per fit and the nested fits that ended worse than their
//! poorer model; [`Summary::of`] condenses the rows into the tables of the figures. Clips are
//! fitted in parallel; every number but the seconds is the same on any thread count.

mod csv_row;
mod holdout;
mod stats;

pub use holdout::{
    FieldLine, HeldOutTempo, HoldoutLine, HoldoutResults, HoldoutRow, HoldoutSettings,
    HoldoutSummary, Params, PersonFit, Take, check_split, group_by_person, run_holdout,
};
pub use stats::Stats;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use kinergy_io::InvalidSetting;
use kinergy_solver::{Model, OptimizerKind, ParamSpace};
use rayon::prelude::*;

use crate::anneal::{Control, Status};
use crate::baseline::{BaselineMethod, BaselineSettings};
use crate::captured::CapturedReach;
use crate::error::{Result, TrainError};
use crate::field::{FieldSettings, leave_one_out};
use crate::fit::{FitSettings, ModelRun, NestedFit, NestedRun};
use crate::objective::{CostFunction, Objective};

/// The paper's reductions of the mean distance from one model to the next (§4), percent.
pub const PAPER_MODEL_REDUCTIONS: [(Model, Model, f64); 3] = [
    (Model::Sa, Model::Sb, 55.0),
    (Model::Sb, Model::Sc, 13.0),
    (Model::Sc, Model::Sd, 10.0),
];

/// The paper's reductions of the mean distance with S_C instead of S_A, per optimizer (§4),
/// percent.
pub const PAPER_OPTIMIZER_REDUCTIONS: [(OptimizerKind, f64); 3] = [
    (OptimizerKind::Jt, 34.0),
    (OptimizerKind::Njt, 47.0),
    (OptimizerKind::Svd, 66.0),
];

/// How a row's parameters were found.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Method {
    /// Simulated annealing in a nested sequence of models (Fig. 3 and Fig. 4).
    NestedAnnealing,
    /// Simulated annealing of S_C from its neutral vector.
    AnnealingFromNeutral,
    /// argmin's Nelder–Mead from the neutral vector, the same budget.
    NelderMead,
    /// argmin's particle swarm from the neutral vector, the same budget.
    ParticleSwarm,
    /// Predicted by the parameter field of the person's other clips (leave one target out).
    FieldLeaveOneOut,
}

impl Method {
    /// The methods that start S_C from its neutral vector, in the order they are run.
    pub const FROM_NEUTRAL: [Method; 3] = [
        Method::AnnealingFromNeutral,
        Method::NelderMead,
        Method::ParticleSwarm,
    ];

    /// Its name in tables: `sa`, `sa_from_neutral`, `nelder_mead`, `particle_swarm`,
    /// `field_loo`.
    pub fn name(self) -> &'static str {
        match self {
            Method::NestedAnnealing => "sa",
            Method::AnnealingFromNeutral => "sa_from_neutral",
            Method::NelderMead => BaselineMethod::NelderMead.name(),
            Method::ParticleSwarm => BaselineMethod::ParticleSwarm.name(),
            Method::FieldLeaveOneOut => "field_loo",
        }
    }
}

impl From<BaselineMethod> for Method {
    fn from(method: BaselineMethod) -> Method {
        match method {
            BaselineMethod::NelderMead => Method::NelderMead,
            BaselineMethod::ParticleSwarm => Method::ParticleSwarm,
        }
    }
}

/// What the experiment runs.
#[derive(Debug, Clone, PartialEq)]
pub struct ExperimentSettings {
    /// The models of Fig. 3 (any order; fitted poorest first).
    pub models: Vec<Model>,
    /// The optimizers of Fig. 4, in the order reported.
    pub optimizers: Vec<OptimizerKind>,
    /// The optimizer of Fig. 3, of the methods and of the field.
    pub optimizer: OptimizerKind,
    /// Whether to run argmin's Nelder–Mead and particle swarm (and annealing from neutral).
    pub baselines: bool,
    /// How every fit searches; its budget and seed are the baselines' too.
    pub fit: FitSettings,
}

impl ExperimentSettings {
    /// The models of Fig. 3, poorest first, each once.
    pub fn sorted_models(&self) -> Vec<Model> {
        let mut models = self.models.clone();
        models.sort();
        models.dedup();
        models
    }
}

/// One fit's result.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The clip's name.
    pub clip: String,
    /// The reach's arm (two reaches of one clip may differ only by it).
    pub arm: Option<kinergy_motion::Side>,
    /// The reach's first frame in the clip.
    pub onset: usize,
    /// The frame after the reach's last.
    pub end: usize,
    /// The model.
    pub model: Model,
    /// The optimizer the motions were synthesized with.
    pub optimizer: OptimizerKind,
    /// How the parameters were found.
    pub method: Method,
    /// Mean motion distance, meters.
    pub distance_m: f64,
    /// Frames of the reach.
    pub frames: usize,
    /// Evaluations spent.
    pub evaluations: usize,
    /// Wall time of the fit, seconds (a nested fit's time is shared equally by its models).
    pub seconds: f64,
}

/// A richer model of a clip's Fig. 3 fits that ended worse than the poorer model it
/// started from (see [`crate::fit::NestedFit::violations`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Violation {
    /// The clip's name.
    pub clip: String,
    /// The poorer model and its distance, meters.
    pub poorer: (Model, f64),
    /// The richer model and its distance, meters.
    pub richer: (Model, f64),
}

/// What the experiment found.
#[derive(Debug, Clone, PartialEq)]
pub struct Results {
    /// Every fit: per clip its Fig. 3, Fig. 4 and method rows, then the field rows.
    pub rows: Vec<Row>,
    /// The Fig. 3 fits that ended worse than their poorer model, clip by clip.
    pub violations: Vec<Violation>,
    /// The first reach's Fig. 3 fits: each model's parameter values (for
    /// [`fig3_clips`], the page of its motions).
    pub first_reach_fits: Vec<(Model, Vec<f64>)>,
}

impl Results {
    /// The rows of `model`, `optimizer` and `method`.
    pub fn select(
        &self,
        model: Model,
        optimizer: OptimizerKind,
        method: Method,
    ) -> impl Iterator<Item = &Row> {
        self.rows
            .iter()
            .filter(move |r| r.model == model && r.optimizer == optimizer && r.method == method)
    }

    /// How many different clips the rows are about.
    pub fn clip_count(&self) -> usize {
        self.rows
            .iter()
            .map(|r| r.clip.as_str())
            .collect::<BTreeSet<_>>()
            .len()
    }
}

/// Runs the experiment on `reaches`, calling `clip_done` as each clip's fits end (from
/// several threads).
pub fn run(
    reaches: &[CapturedReach],
    settings: &ExperimentSettings,
    clip_done: &(dyn Fn() + Sync),
) -> Result<Results> {
    let never = AtomicBool::new(false);
    match run_until(reaches, settings, clip_done, &never)? {
        Some(results) => Ok(results),
        // Nothing raises `never`: a run without a stop flag always ends with its results.
        None => Err(TrainError::Setting(InvalidSetting::new(
            "stop",
            "the experiment stopped though nothing asked it to",
        ))),
    }
}

/// [`run`] that stops early when `stop` becomes true: the clips already started finish, the
/// others are not started, and the result is `None`. (A caller watching for Ctrl-C raises it;
/// the results of a run that was not stopped are [`run`]'s.)
pub fn run_until(
    reaches: &[CapturedReach],
    settings: &ExperimentSettings,
    clip_done: &(dyn Fn() + Sync),
    stop: &AtomicBool,
) -> Result<Option<Results>> {
    InvalidSetting::require(!reaches.is_empty(), "reaches", "at least one reach")?;
    InvalidSetting::require(
        !settings.models.is_empty() && !settings.optimizers.is_empty(),
        "models/optimizers",
        "at least one each",
    )?;
    check_baseline_budget(reaches, settings)?;
    let per_clip: Vec<Option<ClipResults>> = reaches
        .par_iter()
        .map(|reach| {
            if stop.load(Ordering::SeqCst) {
                return Ok(None);
            }
            let results = clip_results(reach, settings, stop)?;
            if results.is_some() {
                clip_done();
            }
            Ok(results)
        })
        .collect::<Result<_>>()?;
    let Some(per_clip) = per_clip.into_iter().collect::<Option<Vec<ClipResults>>>() else {
        return Ok(None);
    };
    if stop.load(Ordering::SeqCst) {
        return Ok(None);
    }
    let mut rows = Vec::new();
    let mut violations = Vec::new();
    let mut sc = Vec::with_capacity(per_clip.len());
    let first_reach_fits = per_clip.first().map(|c| c.fig3.clone()).unwrap_or_default();
    for clip in per_clip {
        rows.extend(clip.rows);
        violations.extend(clip.violations);
        sc.push(clip.sc);
    }
    rows.extend(field_rows(reaches, &sc, settings)?);
    Ok(Some(Results {
        rows,
        violations,
        first_reach_fits,
    }))
}

/// With the baselines, the budget they share must hold each one's first iteration (a
/// particle swarm's population, a simplex of S_C's dimension + 1): said of the budget,
/// before any work.
fn check_baseline_budget(reaches: &[CapturedReach], settings: &ExperimentSettings) -> Result<()> {
    if !settings.baselines {
        return Ok(());
    }
    let optimizer = settings.optimizer.default_optimizer();
    let dimension = match reaches.first() {
        Some(reach) => settings
            .fit
            .objective(std::slice::from_ref(reach), Model::Sc, optimizer)?
            .dimension(),
        None => return Ok(()),
    };
    let needed = BaselineSettings::default().particles.max(dimension + 1);
    let budget = settings.fit.anneal.max_evaluations;
    InvalidSetting::require(
        budget >= needed,
        "budget",
        format!(
            "{budget}: at least {needed} with the baselines, which share it (a particle swarm's \
             first generation, a Nelder–Mead simplex of S_C): raise it, or run without the \
             baselines"
        ),
    )?;
    Ok(())
}

/// One clip's rows, its Fig. 3 violations and its Fig. 3 S_C values (for the field).
struct ClipResults {
    rows: Vec<Row>,
    violations: Vec<Violation>,
    sc: Option<Vec<f64>>,
    /// Each Fig. 3 model's values.
    fig3: Vec<(Model, Vec<f64>)>,
}

/// The rows of one clip: Fig. 3, Fig. 4, methods; `None` once `stop` is raised (every fit and
/// baseline checks it between iterations).
fn clip_results(
    reach: &CapturedReach,
    settings: &ExperimentSettings,
    stop: &AtomicBool,
) -> Result<Option<ClipResults>> {
    let reaches = std::slice::from_ref(reach);
    let fit = &settings.fit;
    let control = Control {
        interrupt: Some(stop),
        ..Control::default()
    };
    let nested = |models: &[Model], optimizer: OptimizerKind| -> Result<Option<NestedFit>> {
        let run = NestedRun {
            reaches,
            models,
            optimizer: optimizer.default_optimizer(),
            settings: fit,
        };
        let outcome = run.run(&mut (), &control, false)?;
        Ok((!outcome.interrupted).then_some(outcome.fits))
    };
    let mut rows = Vec::new();
    let row = |model, optimizer, method, distance_m, evaluations, seconds| Row {
        clip: reach.name().to_string(),
        arm: reach.fitted_arm().side,
        onset: reach.frames().start,
        end: reach.frames().end,
        model,
        optimizer,
        method,
        distance_m,
        frames: reach.frame_count(),
        evaluations,
        seconds,
    };
    // Fig. 3.
    let clock = Instant::now();
    let Some(fig3) = nested(&settings.models, settings.optimizer)? else {
        return Ok(None);
    };
    let per_fit = clock.elapsed().as_secs_f64() / fig3.fits.len() as f64;
    for f in &fig3.fits {
        rows.push(row(
            f.model(),
            settings.optimizer,
            Method::NestedAnnealing,
            f.score,
            f.evaluations,
            per_fit,
        ));
    }
    let score = |model| fig3.get(model).map_or(f64::NAN, |f| f.score);
    let violations = fig3
        .violations()
        .into_iter()
        .map(|(poorer, richer)| Violation {
            clip: reach.name().to_string(),
            poorer: (poorer, score(poorer)),
            richer: (richer, score(richer)),
        })
        .collect();
    let sc = fig3.get(Model::Sc).map(|f| f.values.clone());
    let fig3_values = fig3
        .fits
        .iter()
        .map(|f| (f.model(), f.values.clone()))
        .collect();
    // Fig. 4.
    for &optimizer in &settings.optimizers {
        if optimizer == settings.optimizer
            && fig3.get(Model::Sa).is_some()
            && fig3.get(Model::Sc).is_some()
        {
            continue; // the Fig. 3 rows serve
        }
        let clock = Instant::now();
        let Some(fits) = nested(&[Model::Sa, Model::Sc], optimizer)? else {
            return Ok(None);
        };
        let per_fit = clock.elapsed().as_secs_f64() / fits.fits.len() as f64;
        for f in &fits.fits {
            rows.push(row(
                f.model(),
                optimizer,
                Method::NestedAnnealing,
                f.score,
                f.evaluations,
                per_fit,
            ));
        }
    }
    // Methods: S_C from neutral, the same budget.
    if settings.baselines {
        let optimizer = settings.optimizer.default_optimizer();
        let clock = Instant::now();
        let run = ModelRun {
            reaches,
            model: Model::Sc,
            optimizer,
            start: None,
            settings: fit,
        };
        let annealed = run.run(&mut (), &control, None)?;
        if annealed.status == Status::Interrupted {
            return Ok(None);
        }
        rows.push(row(
            Model::Sc,
            settings.optimizer,
            Method::AnnealingFromNeutral,
            annealed.score,
            annealed.evaluations,
            clock.elapsed().as_secs_f64(),
        ));
        let objective = fit.objective(reaches, Model::Sc, optimizer)?;
        let start = objective.space().neutral();
        for method in BaselineMethod::ALL {
            let clock = Instant::now();
            let result = crate::baseline::minimize_until(
                method,
                &objective as &dyn CostFunction,
                &start,
                &BaselineSettings {
                    max_evaluations: fit.anneal.max_evaluations,
                    seed: fit.anneal.seed,
                    ..BaselineSettings::default()
                },
                Some(stop),
            )?;
            if stop.load(Ordering::SeqCst) {
                return Ok(None);
            }
            rows.push(row(
                Model::Sc,
                settings.optimizer,
                method.into(),
                result.best_cost,
                result.evaluations,
                clock.elapsed().as_secs_f64(),
            ));
        }
    }
    Ok(Some(ClipResults {
        rows,
        violations,
        sc,
        fig3: fig3_values,
    }))
}

/// The motions of `reach`'s Fig. 3 fits (`fits`, [`Results::first_reach_fits`]) as clips on
/// the skeleton of `clip`, the capture the reach was taken from: each model's synthesis under
/// the settings the fit scored it with, the rest of the body as captured
/// ([`CapturedReach::to_clip`]).
pub fn fig3_clips(
    reach: &CapturedReach,
    clip: &kinergy_motion::Clip,
    fits: &[(Model, Vec<f64>)],
    settings: &ExperimentSettings,
) -> Result<Vec<(Model, kinergy_motion::Clip)>> {
    let optimizer = settings.optimizer.default_optimizer();
    fits.iter()
        .map(|(model, values)| {
            let objective =
                settings
                    .fit
                    .objective(std::slice::from_ref(reach), *model, optimizer)?;
            let synthesis = objective.syntheses(values)?.remove(0);
            let motion = objective.reaches()[0].to_clip(clip, &synthesis)?;
            Ok((*model, motion))
        })
        .collect()
}

/// The person a reach belongs to: the folder of its clip.
pub fn person_of(reach: &CapturedReach) -> PathBuf {
    Path::new(reach.name())
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default()
}

/// The persons of `reaches` (sorted), each with the indices of its reaches in order.
pub fn persons(reaches: &[CapturedReach]) -> Vec<(PathBuf, Vec<usize>)> {
    let of: Vec<PathBuf> = reaches.iter().map(person_of).collect();
    let mut persons = of.clone();
    persons.sort();
    persons.dedup();
    persons
        .into_iter()
        .map(|p| {
            let members = (0..reaches.len()).filter(|&i| of[i] == p).collect();
            (p, members)
        })
        .collect()
}

/// Leave one target out with the parameter field, per person: for each clip, S_C parameters
/// from the field of the person's other Fig. 3 S_C fits (`sc`, one per reach; targets in the
/// arm's base frame, [`CapturedReach::local_target`]), scored on the clip; one row per clip
/// of a person with at least two such fits.
fn field_rows(
    reaches: &[CapturedReach],
    sc: &[Option<Vec<f64>>],
    settings: &ExperimentSettings,
) -> Result<Vec<Row>> {
    let optimizer = settings.optimizer.default_optimizer();
    let mut rows = Vec::new();
    for (_, members) in persons(reaches) {
        let members: Vec<usize> = members.into_iter().filter(|&i| sc[i].is_some()).collect();
        if members.len() < 2 {
            continue;
        }
        let space = ParamSpace::new(
            Model::Sc,
            &reaches[members[0]].dof_names(),
            settings.fit.bounds,
        )?;
        let samples: Vec<_> = members
            .iter()
            .map(|&i| (reaches[i].local_target(), sc[i].clone().unwrap_or_default()))
            .collect();
        let clock = Instant::now();
        let loo = leave_one_out(&space, &samples, &FieldSettings::default(), |k, params| {
            Objective::new(vec![reaches[members[k]].clone()], space.clone(), optimizer)?
                .with_tolerance(settings.fit.tolerance)?
                .score(params)
        })?;
        let per = clock.elapsed().as_secs_f64() / loo.len() as f64;
        for row in loo {
            let reach = &reaches[members[row.index]];
            rows.push(Row {
                clip: reach.name().to_string(),
                arm: reach.fitted_arm().side,
                onset: reach.frames().start,
                end: reach.frames().end,
                model: Model::Sc,
                optimizer: settings.optimizer,
                method: Method::FieldLeaveOneOut,
                distance_m: row.field_distance,
                frames: reach.frame_count(),
                evaluations: 1,
                seconds: per,
            });
        }
    }
    Ok(rows)
}

/// The field's leave-one-out distances beside the same clips' own Fig. 3 S_C fits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FieldComparison {
    /// The parameters the field predicts from the person's other clips.
    pub field: Stats,
    /// The clips' own fits.
    pub direct: Stats,
}

/// The experiment's tables, distances in meters.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// Fig. 3: each model's distances (the Fig. 3 optimizer), poorest first.
    pub models: Vec<(Model, Stats)>,
    /// Fig. 4: each optimizer's distances with S_A and with S_C.
    pub optimizers: Vec<(OptimizerKind, Option<Stats>, Option<Stats>)>,
    /// S_C from its neutral vector by each method (the Fig. 3 optimizer).
    pub methods: Vec<(Method, Stats)>,
    /// The parameter field against the direct fits, when there were field rows.
    pub field: Option<FieldComparison>,
}

impl Summary {
    /// The tables of `results`, run with `settings`.
    pub fn of(results: &Results, settings: &ExperimentSettings) -> Summary {
        let select = |model, optimizer, method| {
            Stats::of(
                results
                    .select(model, optimizer, method)
                    .map(|r| r.distance_m),
            )
        };
        let fig3 = settings.optimizer;
        let models = settings
            .sorted_models()
            .into_iter()
            .filter_map(|m| select(m, fig3, Method::NestedAnnealing).map(|s| (m, s)))
            .collect();
        let optimizers = settings
            .optimizers
            .iter()
            .map(|&o| {
                (
                    o,
                    select(Model::Sa, o, Method::NestedAnnealing),
                    select(Model::Sc, o, Method::NestedAnnealing),
                )
            })
            .collect();
        let methods = Method::FROM_NEUTRAL
            .into_iter()
            .filter_map(|m| select(Model::Sc, fig3, m).map(|s| (m, s)))
            .collect();
        // Each field row beside the first Fig. 3 S_C row of its clip.
        let pairs: Vec<(f64, f64)> = results
            .rows
            .iter()
            .filter(|r| r.method == Method::FieldLeaveOneOut)
            .filter_map(|f| {
                results
                    .select(Model::Sc, fig3, Method::NestedAnnealing)
                    .find(|r| r.clip == f.clip)
                    .map(|d| (d.distance_m, f.distance_m))
            })
            .collect();
        let field = Stats::of(pairs.iter().map(|p| p.1))
            .zip(Stats::of(pairs.iter().map(|p| p.0)))
            .map(|(field, direct)| FieldComparison { field, direct });
        Summary {
            models,
            optimizers,
            methods,
            field,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn methods_keep_the_names_of_results_csv() {
        let names: Vec<&str> = [
            Method::NestedAnnealing,
            Method::AnnealingFromNeutral,
            Method::NelderMead,
            Method::ParticleSwarm,
            Method::FieldLeaveOneOut,
        ]
        .map(Method::name)
        .to_vec();
        assert_eq!(
            names,
            [
                "sa",
                "sa_from_neutral",
                "nelder_mead",
                "particle_swarm",
                "field_loo"
            ]
        );
        for b in BaselineMethod::ALL {
            assert_eq!(Method::from(b).name(), b.name());
        }
    }
}
