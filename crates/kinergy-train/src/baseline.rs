//! Baselines for the annealer: the same [`CostFunction`] minimized under the same budget of
//! evaluations (synthesized motions) by Nelder–Mead and by particle swarm, both run by argmin
//! 0.11's [`Executor`], so a comparison shows what [`crate::anneal`] buys.
//!
//! - **Nelder–Mead** is argmin's [`NelderMead`] with its default coefficients (reflection
//!   α = 1, expansion γ = 2, contraction ρ = ½, shrink σ = ½). The initial simplex is the start
//!   `s` and the `n` vertices `s + h·(uᵢ − lᵢ)·eᵢ`, `h = simplex_step`; a vertex that would
//!   leave the bounds goes the other way, `s − h·(uᵢ − lᵢ)·eᵢ` (always inside for h ≤ ½).
//!   It stops when the sample standard deviation of the costs at the `n + 1` vertices falls
//!   below `sd_tolerance` (argmin's only convergence test, absolute, in cost units) or when the
//!   budget is spent. It draws no random numbers: the seed is not used.
//! - **Particle swarm** is argmin's [`ParticleSwarm`], Standard PSO 2011 (Zambrano-Bigiarini
//!   et al. 2013, §II.A), with its default coefficients: per particle and coordinate
//!   `v ← w·v + c₁·U(0, pᵢ − xᵢ) + c₂·U(0, gᵢ − xᵢ)`, `x ← clamp(x + v, l, u)`, with
//!   `w = 1 / (2 ln 2)`, `c₁ = c₂ = ½ + ln 2`, `p` the particle's best, `g` the swarm's best
//!   after the previous iteration. Its generator is rand_xoshiro's `Xoshiro256PlusPlus` (the
//!   `rand` 0.9 generator argmin itself uses) seeded by `seed_from_u64(seed)` and handed over
//!   by `with_rng_generator`, so the same seed gives the same run. It runs until the budget is
//!   spent.
//!
//!   The initial swarm is drawn as argmin's initialization draws it, from that generator: all
//!   positions uniform in the box, then all velocities uniform in `[−(u − l), u − l]`. One
//!   change: particle 0 starts at the given start (as annealing member 0 does), so neither
//!   baseline can end worse than the start. argmin takes such a swarm only as a user population
//!   (`PopulationState::population`, with its costs), so the swarm is drawn and evaluated here,
//!   before the executor starts, and the generator is handed to argmin where the draws left it;
//!   but for particle 0 the run is the one argmin's own initialization gives (a unit test
//!   in this module checks this, call for call).
//!
//! **Budget.** Every call of the cost function counts as one evaluation. A call that would take
//! the count past `max_evaluations` is not made (the solver is told `f64::MAX`) and the run
//! stops after that iteration, so [`BaselineResult::evaluations`] is exactly the number of
//! calls and never exceeds the budget. Nelder–Mead uses 1 to `n + 2` evaluations an iteration
//! (`n + 1` to start), particle swarm one per particle (all of them once more for the initial
//! swarm).
//!
//! **Bounds.** Nelder–Mead is unconstrained: its vertices may leave the box. The cost of a point
//! outside is the cost of its mirror image in the bounds (each coordinate reflected at the bound
//! it crossed, repeatedly if it crossed the box more than once), so the cost function only ever
//! sees points inside the box, and the returned best is a mirrored point. Mirroring rather than
//! clamping: clamping makes the cost flat outside the box, and a simplex that overshoots a
//! corner then finds the same cost at every vertex, which argmin's standard-deviation test takes
//! for convergence (a sphere centred outside `[−1, 2]³` stops so after 20 evaluations at the
//! corner `(2, −1, 2)`, cost 1.5 against the 1.25 at the face). Mirroring keeps distances, so
//! the cost rises again beyond a bound, and a minimum on a face becomes a fold the simplex
//! closes on. A vertex with a non-finite coordinate costs `f64::MAX` and is not evaluated.
//! Particle swarm clamps its positions itself, so mirroring never changes them. The best is
//! tracked here, over every evaluation actually made (the first of equal costs wins), not taken
//! from argmin's state, which records unmirrored vertices.
//!
//! **Why the annealer is not argmin's.** argmin's simulated annealing runs one proposal per
//! executor iteration, about 0.9 µs of executor overhead each against about 26 ns for the
//! hand-written loop, and draws from a single sequential generator held in the solver, which can
//! only be checkpointed with argmin's `serde1` feature (off here) and which ties the draws to the
//! evaluation order. Ours derives each member's generator from (seed, iteration, member), so
//! nothing random needs checkpointing, members evaluate in parallel, and a resumed run ends bit for
//! bit where an uninterrupted one does. The baselines run single-threaded (argmin's `rayon` feature
//! is off), which costs them nothing in evaluations.

use std::fmt;
use std::str::FromStr;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Mutex, PoisonError};

use argmin::core::{
    CostFunction as ArgminCost, Error as ArgminError, Executor, IterState, KV, PopulationState,
    Problem, Solver, State, TerminationReason, TerminationStatus,
};
use argmin::solver::neldermead::NelderMead;
use argmin::solver::particleswarm::{Particle, ParticleSwarm};
use argmin_math::ArgminRandom;
use kinergy_io::InvalidSetting;
use rand_xoshiro::Xoshiro256PlusPlus;
use rand_xoshiro::rand_core::SeedableRng;

use crate::error::{Result, TrainError};
use crate::objective::CostFunction;

/// A baseline optimizer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BaselineMethod {
    /// argmin's Nelder–Mead simplex search.
    NelderMead,
    /// argmin's particle swarm (Standard PSO 2011), particle 0 at the start.
    ParticleSwarm,
}

impl BaselineMethod {
    /// Every method, in a fixed order.
    pub const ALL: [BaselineMethod; 2] =
        [BaselineMethod::NelderMead, BaselineMethod::ParticleSwarm];

    /// Its name: `nelder_mead` or `particle_swarm`.
    pub fn name(self) -> &'static str {
        match self {
            BaselineMethod::NelderMead => "nelder_mead",
            BaselineMethod::ParticleSwarm => "particle_swarm",
        }
    }
}

impl fmt::Display for BaselineMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for BaselineMethod {
    type Err = TrainError;

    /// Parses a [`BaselineMethod::name`] (`-` may stand for `_`).
    fn from_str(s: &str) -> Result<BaselineMethod> {
        let s = s.trim().replace('-', "_");
        BaselineMethod::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                TrainError::Setting(InvalidSetting::new(
                    "baseline.method",
                    format!("`{s}` is not one of nelder_mead, particle_swarm"),
                ))
            })
    }
}

/// Budget and knobs of a baseline run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BaselineSettings {
    /// Budget: at most this many evaluations of the cost function (≥ 1; at least `n + 1` for
    /// Nelder–Mead and `particles` for the swarm, checked by [`minimize`]).
    pub max_evaluations: usize,
    /// Seed of the swarm's generator (Nelder–Mead draws nothing).
    pub seed: u64,
    /// Particles of the swarm (≥ 1).
    pub particles: usize,
    /// Edge of Nelder–Mead's initial simplex, as a fraction of each bound width, in (0, ½].
    pub simplex_step: f64,
    /// Nelder–Mead converges when the standard deviation of the costs at its vertices is below
    /// this (absolute, cost units, ≥ 0; 0 = only the budget stops it).
    pub sd_tolerance: f64,
}

impl Default for BaselineSettings {
    fn default() -> BaselineSettings {
        BaselineSettings {
            max_evaluations: 4000,
            seed: 0,
            particles: 20,
            simplex_step: 0.1,
            sd_tolerance: 1e-12,
        }
    }
}

impl BaselineSettings {
    /// Checks every setting, naming the field otherwise.
    pub fn validate(&self) -> Result<()> {
        InvalidSetting::require(
            self.max_evaluations >= 1,
            "baseline.max_evaluations",
            "at least 1",
        )?;
        InvalidSetting::require(self.particles >= 1, "baseline.particles", "at least 1")?;
        InvalidSetting::require(
            self.simplex_step > 0.0 && self.simplex_step <= 0.5,
            "baseline.simplex_step",
            "within (0, 0.5]",
        )?;
        InvalidSetting::require(
            self.sd_tolerance >= 0.0 && self.sd_tolerance.is_finite(),
            "baseline.sd_tolerance",
            "a finite number ≥ 0",
        )?;
        Ok(())
    }
}

/// Why a baseline run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BaselineStop {
    /// Nelder–Mead's simplex costs agreed within `sd_tolerance`.
    Converged,
    /// The evaluation budget is spent.
    BudgetSpent,
    /// The executor's backstop of `max_evaluations + 1` iterations was reached before the
    /// budget was spent (only possible if iterations stop evaluating, e.g. a simplex whose
    /// vertices overflowed to non-finite coordinates).
    IterationCap,
}

impl BaselineStop {
    /// A short name.
    pub fn name(self) -> &'static str {
        match self {
            BaselineStop::Converged => "converged",
            BaselineStop::BudgetSpent => "budget_spent",
            BaselineStop::IterationCap => "iteration_cap",
        }
    }
}

/// The outcome of a baseline run.
#[derive(Debug, Clone, PartialEq)]
pub struct BaselineResult {
    /// The method that ran.
    pub method: BaselineMethod,
    /// The best point evaluated (within the bounds).
    pub best_x: Vec<f64>,
    /// Its cost.
    pub best_cost: f64,
    /// Evaluations made: the number of calls of the cost function, ≤ the budget.
    pub evaluations: usize,
    /// Iterations argmin's executor ran (not counting the solver's initialization).
    pub iterations: u64,
    /// Why the run ended.
    pub stop: BaselineStop,
}

/// Minimizes `cost` from `start` (within the bounds) by `method` under `settings`.
pub fn minimize(
    method: BaselineMethod,
    cost: &dyn CostFunction,
    start: &[f64],
    settings: &BaselineSettings,
) -> Result<BaselineResult> {
    minimize_until(method, cost, start, settings, None)
}

/// [`minimize`], stopping early (with the best point so far) once `interrupt` is raised: no
/// evaluation starts after it (Ctrl-C during `fit --refine`).
pub fn minimize_until(
    method: BaselineMethod,
    cost: &dyn CostFunction,
    start: &[f64],
    settings: &BaselineSettings,
    interrupt: Option<&AtomicBool>,
) -> Result<BaselineResult> {
    settings.validate()?;
    let (lower, upper) = crate::objective::checked_bounds(cost, start)?;
    let n = cost.dimension();
    let needed = match method {
        BaselineMethod::NelderMead => n + 1,
        BaselineMethod::ParticleSwarm => settings.particles,
    };
    InvalidSetting::require(
        settings.max_evaluations >= needed,
        "baseline.max_evaluations",
        format!("at least {needed} for {method} (its first iteration)"),
    )?;

    let tracker = Tracker {
        cost,
        lower: &lower,
        upper: &upper,
        budget: settings.max_evaluations,
        used: AtomicUsize::new(0),
        best: Mutex::new(None),
        interrupt,
    };
    // Every iteration makes at least one evaluation until the budget stops the run, so the
    // iteration cap is only a backstop.
    let cap = settings.max_evaluations as u64 + 1;
    let (iterations, reason) = match method {
        BaselineMethod::NelderMead => {
            let simplex = initial_simplex(start, &lower, &upper, settings.simplex_step);
            let solver = NelderMead::new(simplex)
                .with_sd_tolerance(settings.sd_tolerance)
                .map_err(|e| argmin_failed(method, &e))?;
            run(&tracker, solver, method, |state: Iter| state.max_iters(cap))?
        }
        BaselineMethod::ParticleSwarm => {
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(settings.seed);
            let (mut positions, velocities) =
                initial_swarm(&lower, &upper, settings.particles, &mut rng);
            positions[0] = start.to_vec();
            // Within the budget (checked above): `particles` evaluations, all made.
            let swarm: Vec<Particle<Param, f64>> = positions
                .into_iter()
                .zip(velocities)
                .map(|(x, v)| {
                    let c = tracker.evaluate(&x);
                    Particle::new(x, c, v)
                })
                .collect();
            let solver = ParticleSwarm::new((lower.clone(), upper.clone()), settings.particles)
                .with_rng_generator(rng);
            run(&tracker, solver, method, |state: Swarm| {
                state.population(swarm).max_iters(cap)
            })?
        }
    };
    let stop = match reason {
        Some(TerminationReason::SolverConverged) => BaselineStop::Converged,
        Some(TerminationReason::MaxItersReached) => BaselineStop::IterationCap,
        _ => BaselineStop::BudgetSpent,
    };
    let evaluations = tracker.used.load(Ordering::SeqCst);
    let (best_x, best_cost) = tracker
        .best
        .into_inner()
        .unwrap_or_else(PoisonError::into_inner)
        .unwrap_or_else(|| (start.to_vec(), f64::MAX));
    Ok(BaselineResult {
        method,
        best_x,
        best_cost,
        evaluations,
        iterations,
        stop,
    })
}

type Param = Vec<f64>;
/// Nelder–Mead's state.
type Iter = IterState<Param, (), (), (), (), f64>;
/// The swarm's state.
type Swarm = PopulationState<Particle<Param, f64>, f64>;

/// Runs `solver` on `tracker`, its state set up by `configure`, until it converges or the
/// budget is spent; returns the iterations and argmin's termination reason.
fn run<'t, S, I>(
    tracker: &'t Tracker<'t>,
    solver: S,
    method: BaselineMethod,
    configure: impl FnOnce(I) -> I,
) -> Result<(u64, Option<TerminationReason>)>
where
    S: Solver<Evaluator<'t>, I>,
    I: State,
{
    let solver = WithBudget {
        solver,
        used: &tracker.used,
        budget: tracker.budget,
        interrupt: tracker.interrupt,
    };
    let result = Executor::new(Evaluator(tracker), solver)
        .configure(configure)
        .ctrlc(false)
        .run()
        .map_err(|e| argmin_failed(method, &e))?;
    let state = &result.state;
    Ok((state.get_iter(), state.get_termination_reason().cloned()))
}

fn argmin_failed(method: BaselineMethod, e: &ArgminError) -> TrainError {
    TrainError::Setting(InvalidSetting::new(
        "baseline.method",
        format!("argmin's {method} failed: {e}"),
    ))
}

/// The start and one vertex along each axis, `simplex_step` of the width away, inward.
fn initial_simplex(start: &[f64], lower: &[f64], upper: &[f64], step: f64) -> Vec<Param> {
    let mut simplex = vec![start.to_vec()];
    for i in 0..start.len() {
        let h = step * (upper[i] - lower[i]);
        let mut v = start.to_vec();
        v[i] = if start[i] + h <= upper[i] {
            start[i] + h
        } else {
            start[i] - h
        };
        simplex.push(v);
    }
    simplex
}

/// `count` positions uniform in the box, then `count` velocities uniform in
/// `[−(upper − lower), upper − lower]`, drawn from `rng` exactly as argmin 0.11's
/// `ParticleSwarm` initializes a swarm.
fn initial_swarm(
    lower: &Param,
    upper: &Param,
    count: usize,
    rng: &mut Xoshiro256PlusPlus,
) -> (Vec<Param>, Vec<Param>) {
    let width: Param = upper.iter().zip(lower).map(|(u, l)| u - l).collect();
    let negative: Param = width.iter().map(|w| w * -1.0).collect();
    let positions = (0..count)
        .map(|_| Param::rand_from_range(lower, upper, rng))
        .collect();
    let velocities = (0..count)
        .map(|_| Param::rand_from_range(&negative, &width, rng))
        .collect();
    (positions, velocities)
}

/// The problem as both solvers see it: evaluations counted against the budget, points
/// mirrored into the bounds, the best remembered.
struct Tracker<'a> {
    cost: &'a dyn CostFunction,
    lower: &'a [f64],
    upper: &'a [f64],
    budget: usize,
    used: AtomicUsize,
    best: Mutex<Option<(Param, f64)>>,
    interrupt: Option<&'a AtomicBool>,
}

impl Tracker<'_> {
    fn evaluate(&self, x: &[f64]) -> f64 {
        if x.iter().any(|v| !v.is_finite()) || interrupted(self.interrupt) {
            return f64::MAX;
        }
        let claimed = self
            .used
            .fetch_update(Ordering::SeqCst, Ordering::SeqCst, |u| {
                (u < self.budget).then_some(u + 1)
            })
            .is_ok();
        if !claimed {
            return f64::MAX;
        }
        let p: Param = x
            .iter()
            .zip(self.lower.iter().zip(self.upper))
            .map(|(&v, (&l, &u))| mirror(v, l, u))
            .collect();
        let c = self.cost.cost(&p);
        let c = if c.is_finite() { c } else { f64::MAX };
        let mut best = self.best.lock().unwrap_or_else(PoisonError::into_inner);
        if best.as_ref().is_none_or(|(_, b)| c < *b) {
            *best = Some((p, c));
        }
        c
    }
}

/// `v` reflected into `[l, u]` at the bound it crossed, as often as needed (a triangle wave of
/// period `2 (u − l)`; the identity inside).
fn mirror(v: f64, l: f64, u: f64) -> f64 {
    if (l..=u).contains(&v) {
        return v;
    }
    let w = u - l;
    let t = (v - l).rem_euclid(2.0 * w);
    (l + if t > w { 2.0 * w - t } else { t }).clamp(l, u)
}

/// argmin's view of a [`Tracker`].
struct Evaluator<'a>(&'a Tracker<'a>);

impl ArgminCost for Evaluator<'_> {
    type Param = Param;
    type Output = f64;

    fn cost(&self, x: &Param) -> std::result::Result<f64, ArgminError> {
        Ok(self.0.evaluate(x))
    }
}

/// Whether `interrupt` is raised.
fn interrupted(interrupt: Option<&AtomicBool>) -> bool {
    interrupt.is_some_and(|f| f.load(Ordering::SeqCst))
}

/// A solver that also stops once the budget is spent or it is interrupted.
struct WithBudget<'a, S> {
    solver: S,
    used: &'a AtomicUsize,
    budget: usize,
    interrupt: Option<&'a AtomicBool>,
}

impl<O, I: State, S: Solver<O, I>> Solver<O, I> for WithBudget<'_, S> {
    fn name(&self) -> &str {
        self.solver.name()
    }

    fn init(
        &mut self,
        problem: &mut Problem<O>,
        state: I,
    ) -> std::result::Result<(I, Option<KV>), ArgminError> {
        self.solver.init(problem, state)
    }

    fn next_iter(
        &mut self,
        problem: &mut Problem<O>,
        state: I,
    ) -> std::result::Result<(I, Option<KV>), ArgminError> {
        self.solver.next_iter(problem, state)
    }

    fn terminate(&mut self, state: &I) -> TerminationStatus {
        let inner = self.solver.terminate(state);
        if interrupted(self.interrupt) {
            TerminationStatus::Terminated(TerminationReason::SolverExit("interrupted".into()))
        } else if inner.terminated() || self.used.load(Ordering::SeqCst) < self.budget {
            inner
        } else {
            TerminationStatus::Terminated(TerminationReason::SolverExit(
                "evaluation budget spent".into(),
            ))
        }
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Mutex;

    use argmin::core::{CostFunction as ArgminCost, Error as ArgminError, Executor};
    use argmin::solver::particleswarm::{Particle, ParticleSwarm};
    use rand_xoshiro::Xoshiro256PlusPlus;
    use rand_xoshiro::rand_core::SeedableRng;

    use super::{Param, Swarm, initial_swarm};

    /// A shifted sphere that logs its calls.
    #[derive(Default)]
    struct Logged(Mutex<Vec<(Param, f64)>>);

    impl Logged {
        fn value(&self, x: &Param) -> f64 {
            let c = x
                .iter()
                .enumerate()
                .map(|(i, v)| (v - 0.1 * i as f64).powi(2))
                .sum();
            self.0.lock().unwrap().push((x.clone(), c));
            c
        }
    }

    impl ArgminCost for &Logged {
        type Param = Param;
        type Output = f64;

        fn cost(&self, x: &Param) -> Result<f64, ArgminError> {
            Ok(self.value(x))
        }
    }

    /// The swarm drawn here and handed to argmin as a population runs call for call as argmin's
    /// own initialization does, from the same seed.
    #[test]
    fn the_initial_swarm_is_the_one_argmin_draws() {
        let (lower, upper) = (vec![-2.0, -1.0, 0.0], vec![2.0, 3.0, 0.5]);
        let (count, iterations) = (7, 6);
        for seed in [0, 1, 99] {
            let own = Logged::default();
            let solver = ParticleSwarm::new((lower.clone(), upper.clone()), count)
                .with_rng_generator(Xoshiro256PlusPlus::seed_from_u64(seed));
            let a = Executor::new(&own, solver)
                .configure(|state: Swarm| state.max_iters(iterations))
                .run()
                .unwrap();

            let given = Logged::default();
            let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
            let (positions, velocities) = initial_swarm(&lower, &upper, count, &mut rng);
            let swarm: Vec<Particle<Param, f64>> = positions
                .into_iter()
                .zip(velocities)
                .map(|(x, v)| Particle::new(x.clone(), given.value(&x), v))
                .collect();
            let solver =
                ParticleSwarm::new((lower.clone(), upper.clone()), count).with_rng_generator(rng);
            let b = Executor::new(&given, solver)
                .configure(|state: Swarm| state.population(swarm).max_iters(iterations))
                .run()
                .unwrap();

            assert_eq!(a.state.get_best_cost(), b.state.get_best_cost());
            drop((a, b));
            let (own, given) = (own.0.into_inner().unwrap(), given.0.into_inner().unwrap());
            assert_eq!(own.len(), count * (1 + iterations as usize));
            assert!(own == given, "seed {seed}: the runs differ");
        }
    }
}
