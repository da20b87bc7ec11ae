//! The simulated-annealing executor: initialization, one iteration, the stopping rule, a
//! whole run with observers and checkpoints.

use std::path::Path;
use std::sync::atomic::Ordering;

use kinergy_io::InvalidSetting;
use kinergy_motion::seed::splitmix64;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};
use rand_distr::StandardNormal;
use rayon::prelude::*;

use super::observe::{Control, Observer, Progress};
use super::settings::AnnealSettings;
use super::state::{AnnealState, CHECKPOINT_VERSION, Member, Status, mean_cost};
use crate::error::{Result, TrainError};
use crate::objective::CostFunction;

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
                let c = clean(cost.cost_within(&x, rejected_above(member.cost, t, u)));
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
        InvalidSetting::require(
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

/// A cost above which a proposal is surely rejected by the Metropolis rule below (the
/// proposal's draw `u` known before its cost): the member's `cost` at temperature zero,
/// `cost − t ln u` (where exp(−(c − cost)/t) = u) otherwise, raised by a relative 10⁻⁹ so
/// that rounding in the rule's own `exp` cannot accept a cost above it; infinite when every
/// cost could be accepted. A cost above it is also above the best, which is never above a
/// member's: so the exact cost of such a proposal is never used, and the objective may stop
/// evaluating it early ([`CostFunction::cost_within`]).
fn rejected_above(cost: f64, t: f64, u: f64) -> f64 {
    let threshold = if t > 0.0 { cost - t * u.ln() } else { cost };
    if threshold.is_finite() && threshold < f64::MAX {
        threshold + REJECTION_MARGIN * threshold.abs()
    } else {
        f64::INFINITY
    }
}

/// The relative margin of [`rejected_above`].
const REJECTION_MARGIN: f64 = 1e-9;

/// Non-finite costs count as the worst.
fn clean(c: f64) -> f64 {
    if c.is_finite() { c } else { f64::MAX }
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
