//! What changes during a run (the population, the temperature, the best vector), and the
//! checkpoint file that holds it.

use std::path::Path;

use kinergy_solver::FitStatus;
use serde::{Deserialize, Serialize};

use super::settings::AnnealSettings;
use crate::error::{Result, TrainError};

/// The checkpoint format this version writes and reads.
pub const CHECKPOINT_VERSION: u32 = 1;

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
    /// Stopped from outside ([`Control::interrupt`](super::Control::interrupt)); resumable from the state.
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

/// The status a fit record writes for the run's (same names).
impl From<Status> for FitStatus {
    fn from(status: Status) -> FitStatus {
        match status {
            Status::Running => FitStatus::Running,
            Status::Converged => FitStatus::Converged,
            Status::BudgetSpent => FitStatus::BudgetSpent,
            Status::Interrupted => FitStatus::Interrupted,
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
                        kinergy_io::Num(member.x[i]),
                        kinergy_io::Num(self.lower[i]),
                        kinergy_io::Num(self.upper[i])
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
                    kinergy_io::Num(self.best_x[i]),
                    kinergy_io::Num(self.lower[i]),
                    kinergy_io::Num(self.upper[i])
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
    // A checkpoint that cannot be read (missing, a link loop, a folder) is bad input, like
    // one that reads wrong: it is what `--resume` was told to continue.
    let text =
        kinergy_io::read_to_string_limited(path, kinergy_io::MAX_JSON_BYTES).map_err(|source| {
            TrainError::Checkpoint {
                path: path.to_path_buf(),
                why: format!("cannot be read: {source}"),
            }
        })?;
    kinergy_io::parse_versioned(&text, CHECKPOINT_VERSION).map_err(|e| TrainError::Checkpoint {
        path: path.to_path_buf(),
        why: e.to_string(),
    })
}

/// The population's mean cost (`f64::MAX` when not finite).
pub(super) fn mean_cost(members: &[Member]) -> f64 {
    let sum: f64 = members.iter().map(|m| m.cost).sum();
    let mean = sum / members.len() as f64;
    if mean.is_finite() { mean } else { f64::MAX }
}
