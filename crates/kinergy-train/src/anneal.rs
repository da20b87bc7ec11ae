//! Simulated annealing over a bounded parameter space (DESIGN §1.1; the paper's Algorithm 1
//! made real).
//!
//! A population of parameter vectors evolves together. Each iteration every member proposes
//! a Gaussian move — each coordinate moves by `N(0, 1) · step · (upper − lower)`, reflected
//! back into the bounds — and the proposal replaces the member when its cost is not higher,
//! or, when higher by Δ, with the Metropolis probability `exp(−Δ / T)`. The temperature starts
//! at `T₀ = temperature × (the initial population's mean cost)` and falls geometrically by
//! `cooling` per iteration; `temperature = 0` is the paper's greedy rule (keep a change only
//! if the score did not get worse). Each member's step adapts: every `adapt_every` proposals
//! it grows by 1.3× when more than `target_acceptance` of them were accepted and shrinks by
//! 1.3× otherwise, within `[min_step, max_step]`. Every `share_best_every` iterations the
//! worst member jumps to the best vector found so far. The run stops when the population's mean
//! cost changed by at most `stable_tolerance` (relative) over the last `stable_window`
//! iterations, or when the next iteration would exceed `max_evaluations`. The best vector
//! ever evaluated is returned; member 0 starts at the given start vector, so the result is
//! never worse than the start.
//!
//! Split as argmin splits it (STYLE.md, "long-running work"): the problem is a
//! [`CostFunction`], the [`AnnealState`] holds everything that changes (serializable), the
//! [`Annealer`] is the executor, [`Observer`]s watch it, and [`Control`] says where to write
//! checkpoints and when to stop early.
//!
//! **Reproducibility.** Randomness never lives in the state: the generator of member `m` at
//! iteration `k` is a ChaCha8 seeded from `(seed, k, m)`. Members are evaluated in parallel
//! (rayon) but each one's draws depend only on its own generator, and results are combined
//! in member order — so the same seed gives the same result on any number of threads, and a
//! run resumed from a checkpoint ends bit for bit where an uninterrupted run does.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{Result, TrainError, require};
use crate::objective::CostFunction;

/// The checkpoint format this version writes and reads.
pub const CHECKPOINT_VERSION: u32 = 1;

/// How the annealer searches and when it stops.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnnealSettings {
    /// Members of the population (≥ 1).
    pub population: usize,
    /// Budget: the run stops before an iteration would take the evaluations past this.
    pub max_evaluations: usize,
    /// Initial step, as a fraction of each parameter's bound width.
    pub initial_step: f64,
    /// Smallest step (fraction of the width).
    pub min_step: f64,
    /// Largest step (fraction of the width).
    pub max_step: f64,
    /// Acceptance rate above which a member's step grows, below which it shrinks.
    pub target_acceptance: f64,
    /// Proposals between two step adaptations of a member.
    pub adapt_every: usize,
    /// Initial temperature relative to the initial population's mean cost; 0 = greedy.
    pub temperature: f64,
    /// Temperature factor per iteration, in (0, 1].
    pub cooling: f64,
    /// Iterations over which the population's mean cost must be stable to stop.
    pub stable_window: usize,
    /// Relative change of the mean cost over `stable_window` counted as stable.
    pub stable_tolerance: f64,
    /// Every this many iterations the population's worst member moves to the best vector
    /// found so far (keeping its own step), so no member wanders for long far from the best
    /// region; 0 never does.
    pub share_best_every: usize,
    /// Seed of every random draw.
    pub seed: u64,
}

impl AnnealSettings {
    /// The names of the settings in which `self` and `other` differ.
    pub fn differences(&self, other: &AnnealSettings) -> Vec<String> {
        let (Ok(serde_json::Value::Object(a)), Ok(serde_json::Value::Object(b))) =
            (serde_json::to_value(self), serde_json::to_value(other))
        else {
            return vec!["settings".into()];
        };
        a.iter()
            .filter(|&(k, v)| b.get(k) != Some(v))
            .map(|(k, _)| k.clone())
            .collect()
    }
}

impl Default for AnnealSettings {
    fn default() -> AnnealSettings {
        AnnealSettings {
            population: 8,
            max_evaluations: 4000,
            initial_step: 0.05,
            min_step: 1e-4,
            max_step: 0.5,
            target_acceptance: 0.3,
            adapt_every: 8,
            temperature: 0.02,
            cooling: 0.95,
            stable_window: 25,
            stable_tolerance: 1e-4,
            share_best_every: 10,
            seed: 0,
        }
    }
}

impl AnnealSettings {
    /// The paper's greedy search: temperature zero.
    pub fn greedy() -> AnnealSettings {
        AnnealSettings {
            temperature: 0.0,
            ..AnnealSettings::default()
        }
    }

    /// Checks every setting, naming the field otherwise.
    pub fn validate(&self) -> Result<()> {
        require(self.population >= 1, "anneal.population", "at least 1")?;
        require(
            self.max_evaluations >= self.population,
            "anneal.max_evaluations",
            format!("at least the population ({})", self.population),
        )?;
        let fraction = |v: f64| v > 0.0 && v <= 1.0;
        require(
            fraction(self.min_step) && fraction(self.max_step) && self.min_step <= self.max_step,
            "anneal.min_step/max_step",
            "0 < min_step ≤ max_step ≤ 1",
        )?;
        require(
            self.initial_step >= self.min_step && self.initial_step <= self.max_step,
            "anneal.initial_step",
            "within [min_step, max_step]",
        )?;
        require(
            self.target_acceptance > 0.0 && self.target_acceptance < 1.0,
            "anneal.target_acceptance",
            "within (0, 1)",
        )?;
        require(self.adapt_every >= 1, "anneal.adapt_every", "at least 1")?;
        require(
            self.temperature >= 0.0 && self.temperature.is_finite(),
            "anneal.temperature",
            "a finite number ≥ 0",
        )?;
        require(
            self.cooling > 0.0 && self.cooling <= 1.0,
            "anneal.cooling",
            "within (0, 1]",
        )?;
        require(
            self.stable_window >= 1,
            "anneal.stable_window",
            "at least 1",
        )?;
        require(
            self.stable_tolerance >= 0.0 && self.stable_tolerance.is_finite(),
            "anneal.stable_tolerance",
            "a finite number ≥ 0",
        )
    }
}

/// One member of the population.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Member {
    /// Its parameter vector.
    pub x: Vec<f64>,
    /// Its cost.
    pub cost: f64,
    /// Its step, as a fraction of each parameter's bound width.
    pub step: f64,
    /// Proposals since its step last adapted.
    pub proposed: usize,
    /// Of those, how many were accepted.
    pub accepted: usize,
}

/// Why a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Status {
    /// Still running (only seen in checkpoints).
    Running,
    /// The population's mean cost was stable.
    Converged,
    /// The evaluation budget is spent.
    BudgetSpent,
    /// Stopped from outside ([`Control::interrupt`]); resumable from the state.
    Interrupted,
}

impl Status {
    /// A short name.
    pub fn name(self) -> &'static str {
        match self {
            Status::Running => "running",
            Status::Converged => "converged",
            Status::BudgetSpent => "budget_spent",
            Status::Interrupted => "interrupted",
        }
    }
}

/// Everything that changes during a run: write it and the run can continue from it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AnnealState {
    /// [`CHECKPOINT_VERSION`].
    pub format_version: u32,
    /// The settings the run was started with (a resume must use the same).
    pub settings: AnnealSettings,
    /// Free text naming the problem (e.g. model, optimizer, clips); a resume must match it.
    pub tag: String,
    /// The problem's bounds.
    pub lower: Vec<f64>,
    /// The problem's bounds.
    pub upper: Vec<f64>,
    /// Iterations done.
    pub iteration: usize,
    /// Cost evaluations done (including the initial population).
    pub evaluations: usize,
    /// The current temperature.
    pub temperature: f64,
    /// The population.
    pub members: Vec<Member>,
    /// The best vector evaluated so far.
    pub best_x: Vec<f64>,
    /// Its cost.
    pub best_cost: f64,
    /// The population's mean cost after initialization and after each iteration.
    pub mean_history: Vec<f64>,
    /// Where the run stands.
    pub status: Status,
}

impl AnnealState {
    /// Writes the state as JSON, atomically (temporary file + rename).
    pub fn save(&self, path: &Path) -> Result<()> {
        kinergy_io::write_json(path, self).map_err(|source| TrainError::Io {
            path: path.to_path_buf(),
            source,
        })
    }

    /// Reads a state written by [`AnnealState::save`], refusing a damaged one (see
    /// [`AnnealState::check`]).
    pub fn load(path: &Path) -> Result<AnnealState> {
        let state: AnnealState = read_checkpoint(path)?;
        state
            .check()
            .map_err(|(field, why)| TrainError::Checkpoint {
                path: path.to_path_buf(),
                why: format!("`{field}` {why}"),
            })?;
        Ok(state)
    }

    /// Checks everything a checkpoint says against the annealer's invariants, so that a
    /// damaged or hand-edited file is refused by name instead of resumed into a different
    /// run (or a panic): valid settings; bounds finite, ordered and of one length n; exactly
    /// `population` members, each of n values within the bounds, a cost ≥ 0, a step within
    /// the settings' and adaptation counts below `adapt_every`; `evaluations` =
    /// population × (iteration + 1) within the budget; the history one mean per iteration;
    /// the temperature finite, ≥ 0 and no higher than the schedule allows; the best vector
    /// within the bounds and no worse than any member. Returns the first field that is
    /// wrong (its path in the JSON) and what is wrong with it.
    pub fn check(&self) -> std::result::Result<(), (String, String)> {
        let fail = |field: &str, why: String| Err((field.to_string(), why));
        let s = &self.settings;
        if let Err(e) = s.validate() {
            return fail("settings", e.to_string());
        }
        let n = self.lower.len();
        if n == 0 {
            return fail("lower", "is empty: the problem has no parameter".into());
        }
        if self.upper.len() != n {
            return fail(
                "upper",
                format!("has {} values, `lower` {n}", self.upper.len()),
            );
        }
        for (i, (lo, hi)) in self.lower.iter().zip(&self.upper).enumerate() {
            if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
                return fail(
                    &format!("lower[{i}]/upper[{i}]"),
                    format!("are {lo} and {hi}: expected finite bounds, lower ≤ upper"),
                );
            }
        }
        let within = |x: &[f64]| {
            x.iter()
                .zip(self.lower.iter().zip(&self.upper))
                .position(|(v, (lo, hi))| !(v >= lo && v <= hi))
        };
        let cost_ok = |c: f64| c >= 0.0; // NaN fails; f64::MAX marks a failed evaluation
        if self.members.len() != s.population {
            return fail(
                "members",
                format!(
                    "has {} members, the settings' population is {}",
                    self.members.len(),
                    s.population
                ),
            );
        }
        let (step_lo, step_hi) = (s.min_step, s.max_step);
        for (m, member) in self.members.iter().enumerate() {
            let at = |f: &str| format!("members[{m}].{f}");
            if member.x.len() != n {
                return fail(
                    &at("x"),
                    format!("has {} values, expected {n}", member.x.len()),
                );
            }
            if let Some(i) = within(&member.x) {
                return fail(
                    &format!("members[{m}].x[{i}]"),
                    format!(
                        "is {}, outside its bounds [{}, {}]",
                        member.x[i], self.lower[i], self.upper[i]
                    ),
                );
            }
            if !cost_ok(member.cost) {
                return fail(&at("cost"), format!("is {}: expected ≥ 0", member.cost));
            }
            if !(member.step >= step_lo && member.step <= step_hi) {
                return fail(
                    &at("step"),
                    format!(
                        "is {}, outside [min_step, max_step] = [{step_lo}, {step_hi}]",
                        member.step
                    ),
                );
            }
            if member.proposed >= s.adapt_every || member.accepted > member.proposed {
                return fail(
                    &at("proposed"),
                    format!(
                        "{} proposed and {} accepted: expected accepted ≤ proposed < adapt_every ({})",
                        member.proposed, member.accepted, s.adapt_every
                    ),
                );
            }
        }
        let expected = self
            .iteration
            .checked_add(1)
            .and_then(|k| k.checked_mul(s.population));
        if expected != Some(self.evaluations) {
            return fail(
                "evaluations",
                format!(
                    "is {} after {} iterations of {} members: expected population × (iteration + 1)",
                    self.evaluations, self.iteration, s.population
                ),
            );
        }
        if self.evaluations > s.max_evaluations {
            return fail(
                "evaluations",
                format!(
                    "is {}, beyond the budget of {}",
                    self.evaluations, s.max_evaluations
                ),
            );
        }
        if self.mean_history.len() != self.iteration + 1 {
            return fail(
                "mean_history",
                format!(
                    "has {} means after {} iterations: expected one more than the iterations",
                    self.mean_history.len(),
                    self.iteration
                ),
            );
        }
        if let Some(i) = self.mean_history.iter().position(|&c| !cost_ok(c)) {
            return fail(
                &format!("mean_history[{i}]"),
                format!("is {}: expected ≥ 0", self.mean_history[i]),
            );
        }
        // The schedule: T_k = T₀ cᵏ with T₀ = temperature × the mean of the initial finite
        // costs, which is at most the initial mean over all members.
        let t = self.temperature;
        let initial = self.mean_history[0];
        let exponent = i32::try_from(self.iteration).unwrap_or(i32::MAX);
        let ceiling = if initial < f64::MAX {
            s.temperature * initial * s.cooling.powi(exponent) * (1.0 + 1e-9)
        } else {
            f64::INFINITY
        };
        if !(t.is_finite() && t >= 0.0 && t <= ceiling) || (s.temperature == 0.0 && t != 0.0) {
            return fail(
                "temperature",
                format!(
                    "is {t}: the schedule allows at most {ceiling:.6e} after {} iterations",
                    self.iteration
                ),
            );
        }
        if self.best_x.len() != n {
            return fail(
                "best_x",
                format!("has {} values, expected {n}", self.best_x.len()),
            );
        }
        if let Some(i) = within(&self.best_x) {
            return fail(
                &format!("best_x[{i}]"),
                format!(
                    "is {}, outside its bounds [{}, {}]",
                    self.best_x[i], self.lower[i], self.upper[i]
                ),
            );
        }
        let best_member = self
            .members
            .iter()
            .map(|m| m.cost)
            .fold(f64::INFINITY, f64::min);
        if !cost_ok(self.best_cost) || self.best_cost > best_member {
            return fail(
                "best_cost",
                format!(
                    "is {}: expected ≥ 0 and no worse than the best member ({best_member})",
                    self.best_cost
                ),
            );
        }
        Ok(())
    }

    /// The population's current mean cost.
    pub fn mean_cost(&self) -> f64 {
        mean_cost(&self.members)
    }
}

/// Reads and decodes a checkpoint file of either kind (versioned JSON), naming the file in
/// errors. The caller checks what it holds.
pub(crate) fn read_checkpoint<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text =
        kinergy_io::read_to_string_limited(path, kinergy_io::MAX_JSON_BYTES).map_err(|source| {
            TrainError::Io {
                path: path.to_path_buf(),
                source,
            }
        })?;
    kinergy_io::parse_versioned(&text, CHECKPOINT_VERSION).map_err(|e| TrainError::Checkpoint {
        path: path.to_path_buf(),
        why: e.to_string(),
    })
}

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
    /// After every iteration.
    fn on_iteration(&mut self, _progress: &Progress) {}
    /// After a checkpoint was written.
    fn on_checkpoint(&mut self, _path: &Path, _iteration: usize) {}
}

/// The observer that does nothing.
impl Observer for () {}

/// An observer borrowed.
impl<T: Observer + ?Sized> Observer for &mut T {
    fn on_iteration(&mut self, p: &Progress) {
        (**self).on_iteration(p);
    }
    fn on_checkpoint(&mut self, path: &Path, iteration: usize) {
        (**self).on_checkpoint(path, iteration);
    }
}

/// Observers side by side.
impl<A: Observer, B: Observer> Observer for (A, B) {
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
    /// checkpoint and returns [`Status::Interrupted`] (e.g. set from a Ctrl-C handler).
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

/// The simulated-annealing executor.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Annealer {
    settings: AnnealSettings,
}

impl Annealer {
    /// An annealer with validated settings.
    pub fn new(settings: AnnealSettings) -> Result<Annealer> {
        settings.validate()?;
        Ok(Annealer { settings })
    }

    /// The settings.
    pub fn settings(&self) -> &AnnealSettings {
        &self.settings
    }

    /// The initial state: member 0 at `start`, the others around it (three initial steps
    /// away on average), all evaluated. `tag` names the problem for resume checks.
    pub fn init(&self, cost: &dyn CostFunction, start: &[f64], tag: &str) -> Result<AnnealState> {
        let (lower, upper) = crate::objective::checked_bounds(cost, start)?;
        let s = &self.settings;
        let xs: Vec<Vec<f64>> = (0..s.population)
            .map(|m| {
                if m == 0 {
                    start.to_vec()
                } else {
                    let mut rng = member_rng(s.seed, u64::MAX, m);
                    propose(start, 3.0 * s.initial_step, &lower, &upper, &mut rng)
                }
            })
            .collect();
        let costs: Vec<f64> = xs.par_iter().map(|x| clean(cost.cost(x))).collect();
        let members: Vec<Member> = xs
            .into_iter()
            .zip(costs)
            .map(|(x, cost)| Member {
                x,
                cost,
                step: s.initial_step,
                proposed: 0,
                accepted: 0,
            })
            .collect();
        let (best_x, best_cost) = best_of(&members);
        let finite: Vec<f64> = members
            .iter()
            .map(|m| m.cost)
            .filter(|&c| c < f64::MAX)
            .collect();
        let t0 = if finite.is_empty() {
            0.0
        } else {
            s.temperature * finite.iter().sum::<f64>() / finite.len() as f64
        };
        let mean = mean_cost(&members);
        Ok(AnnealState {
            format_version: CHECKPOINT_VERSION,
            settings: *s,
            tag: tag.to_string(),
            lower,
            upper,
            iteration: 0,
            evaluations: s.population,
            temperature: t0,
            members,
            best_x,
            best_cost,
            mean_history: vec![mean],
            status: Status::Running,
        })
    }

    /// Checks that `state` belongs to this annealer and `cost` (same settings, tag and
    /// bounds), so that resuming it continues the same run.
    pub fn check_resume(
        &self,
        cost: &dyn CostFunction,
        state: &AnnealState,
        tag: &str,
        path: &Path,
    ) -> Result<()> {
        let bad = |why: String| TrainError::Checkpoint {
            path: path.to_path_buf(),
            why,
        };
        if state.settings != self.settings {
            return Err(bad(format!(
                "it was written with other settings (its {} differ); resume with the same ones",
                state.settings.differences(&self.settings).join(", ")
            )));
        }
        if state.tag != tag {
            return Err(bad(format!(
                "it belongs to another problem (`{}`, not `{tag}`)",
                kinergy_io::clip_text(&state.tag, kinergy_io::MAX_QUOTED_CHARS)
            )));
        }
        let (lower, upper) = cost.bounds();
        if state.lower != lower || state.upper != upper {
            return Err(bad("its bounds differ from the problem's".into()));
        }
        Ok(())
    }

    /// One iteration: every member proposes, is scored, and accepts or not; then the best,
    /// the steps, the temperature and the history are updated.
    pub fn iterate(&self, cost: &dyn CostFunction, state: &mut AnnealState) -> Progress {
        let s = &self.settings;
        let k = state.iteration as u64;
        let t = state.temperature;
        let (lower, upper) = (&state.lower, &state.upper);
        let outcomes: Vec<(Vec<f64>, f64, f64)> = state
            .members
            .par_iter()
            .enumerate()
            .map(|(m, member)| {
                let mut rng = member_rng(s.seed, k, m);
                let x = propose(&member.x, member.step, lower, upper, &mut rng);
                let u: f64 = rng.random();
                let c = clean(cost.cost(&x));
                (x, c, u)
            })
            .collect();
        let mut accepted = 0;
        for (member, (x, c, u)) in state.members.iter_mut().zip(outcomes) {
            let delta = c - member.cost;
            let accept = delta <= 0.0 || (t > 0.0 && c < f64::MAX && u < (-delta / t).exp());
            if c < state.best_cost {
                state.best_cost = c;
                state.best_x.clone_from(&x);
            }
            member.proposed += 1;
            if accept {
                member.x = x;
                member.cost = c;
                member.accepted += 1;
                accepted += 1;
            }
            if member.proposed >= s.adapt_every {
                let rate = member.accepted as f64 / member.proposed as f64;
                member.step = if rate > s.target_acceptance {
                    member.step * 1.3
                } else {
                    member.step / 1.3
                }
                .clamp(s.min_step, s.max_step);
                member.proposed = 0;
                member.accepted = 0;
            }
        }
        state.iteration += 1;
        if s.share_best_every > 0 && state.iteration.is_multiple_of(s.share_best_every) {
            // The worst member (the last of equals) takes the best vector.
            let worst = (0..state.members.len())
                .rev()
                .max_by(|&a, &b| state.members[a].cost.total_cmp(&state.members[b].cost))
                .unwrap_or(0);
            if state.members[worst].cost > state.best_cost {
                state.members[worst].x.clone_from(&state.best_x);
                state.members[worst].cost = state.best_cost;
            }
        }
        state.evaluations += s.population;
        state.temperature *= s.cooling;
        let mean = mean_cost(&state.members);
        state.mean_history.push(mean);
        Progress {
            iteration: state.iteration,
            evaluations: state.evaluations,
            max_evaluations: s.max_evaluations,
            temperature: t,
            best_cost: state.best_cost,
            mean_cost: mean,
            acceptance: accepted as f64 / s.population as f64,
        }
    }

    /// Whether the run is over, and why.
    pub fn stop_reason(&self, state: &AnnealState) -> Option<Status> {
        let s = &self.settings;
        let h = &state.mean_history;
        if h.len() > s.stable_window {
            let (then, now) = (h[h.len() - 1 - s.stable_window], h[h.len() - 1]);
            if now < f64::MAX && (then - now).abs() <= s.stable_tolerance * now.abs() {
                return Some(Status::Converged);
            }
        }
        if state.evaluations + s.population > s.max_evaluations {
            return Some(Status::BudgetSpent);
        }
        None
    }

    /// Runs from `state` (new from [`Annealer::init`] or loaded from a checkpoint) until it
    /// converges, spends its budget or is interrupted. Returns the final state, whose
    /// `status` says why it ended.
    pub fn run(
        &self,
        cost: &dyn CostFunction,
        mut state: AnnealState,
        observer: &mut dyn Observer,
        control: &Control<'_>,
    ) -> Result<AnnealState> {
        require(
            state.settings == self.settings,
            "state.settings",
            "the annealer's own settings",
        )?;
        state.status = Status::Running;
        loop {
            if let Some(status) = self.stop_reason(&state) {
                state.status = status;
                break;
            }
            if control.interrupt.is_some_and(|f| f.load(Ordering::SeqCst)) {
                state.status = Status::Interrupted;
                break;
            }
            let progress = self.iterate(cost, &mut state);
            observer.on_iteration(&progress);
            if let Some(sink) = control.checkpoint
                && control.checkpoint_every > 0
                && state.iteration.is_multiple_of(control.checkpoint_every)
            {
                sink.save(&state)?;
                observer.on_checkpoint(sink.path(), state.iteration);
            }
        }
        if let Some(sink) = control.checkpoint {
            sink.save(&state)?;
            observer.on_checkpoint(sink.path(), state.iteration);
        }
        Ok(state)
    }

    /// [`Annealer::init`] then [`Annealer::run`] without observers or checkpoints.
    pub fn minimize(&self, cost: &dyn CostFunction, start: &[f64]) -> Result<AnnealState> {
        let state = self.init(cost, start, "")?;
        self.run(cost, state, &mut (), &Control::default())
    }
}

/// The generator of member `m` at iteration `k` (`k = u64::MAX`: initialization).
fn member_rng(seed: u64, k: u64, m: usize) -> ChaCha8Rng {
    let mixed = splitmix64(seed ^ splitmix64(k ^ splitmix64(m as u64 ^ 0x6b69_6e65_7267_7921)));
    ChaCha8Rng::seed_from_u64(mixed)
}

/// SplitMix64's finalizer: a bijective mix of 64 bits.
fn splitmix64(mut z: u64) -> u64 {
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    z ^ (z >> 31)
}

/// `x + N(0, 1) · step · width` per coordinate, reflected into `[lower, upper]` (and clamped,
/// for steps wider than the box).
fn propose(x: &[f64], step: f64, lower: &[f64], upper: &[f64], rng: &mut ChaCha8Rng) -> Vec<f64> {
    x.iter()
        .zip(lower.iter().zip(upper))
        .map(|(&xi, (&lo, &hi))| {
            let z: f64 = rng.sample(StandardNormal);
            let mut v = xi + z * step * (hi - lo);
            if v > hi {
                v = 2.0 * hi - v;
            }
            if v < lo {
                v = 2.0 * lo - v;
            }
            v.clamp(lo, hi)
        })
        .collect()
}

/// Non-finite costs count as the worst.
fn clean(c: f64) -> f64 {
    if c.is_finite() { c } else { f64::MAX }
}

fn mean_cost(members: &[Member]) -> f64 {
    let sum: f64 = members.iter().map(|m| m.cost).sum();
    let mean = sum / members.len() as f64;
    if mean.is_finite() { mean } else { f64::MAX }
}

/// The lowest-cost member (the first of equals).
fn best_of(members: &[Member]) -> (Vec<f64>, f64) {
    let mut best = &members[0];
    for m in &members[1..] {
        if m.cost < best.cost {
            best = m;
        }
    }
    (best.x.clone(), best.cost)
}
