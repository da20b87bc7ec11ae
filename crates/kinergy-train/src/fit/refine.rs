//! A local refinement after the annealing: Nelder–Mead and Levenberg–Marquardt in turn.
//!
//! The annealer finds a basin; near its floor the cost is a long, curved, ill-conditioned
//! valley (scaling the gains down while the sigmoid switches on later gives nearly the same
//! motion), along which its Gaussian proposals crawl, and it is not smooth everywhere (a
//! joint that reaches its limit on one frame rather than the next bends the motion).
//!
//! - **Levenberg–Marquardt** uses the structure of the cost: the motion distance is a mean of
//!   joint-position errors, so its residuals are at hand — for every reach, frame i and tracked
//!   point j (shoulder, elbow, wrist, hand), `r = (X_synth,ij − X_capture,ij) / √(frames ·
//!   points · reaches)`, whose squared norm is the mean squared point error. Each iteration
//!   takes the Jacobian J of r by forward differences (one synthesis per parameter, a step of
//!   `step` times the bound width, taken backward at the upper bound) and solves, in parameters
//!   scaled to their bound widths, `(JᵀJ + λ · diag(JᵀJ)) δ = −Jᵀ r` (Marquardt 1963); it keeps
//!   the clamped `x + δ` when ‖r‖² went down (λ ÷ 3), otherwise grows λ (× 4) and solves again
//!   with the same J. It ends when λ exceeds 10¹⁰ (J no longer predicts the cost: a kink),
//!   when ‖r‖² fell by less than a relative 10⁻¹², or when its budget is spent.
//! - **Nelder–Mead** ([`crate::baseline`], argmin's, a simplex of `simplex_step` times the
//!   bound widths around the point) needs no derivatives and walks over the kinks that stop
//!   Levenberg–Marquardt; it ends when its vertices' costs agree within 10⁻⁹ m or when it has
//!   spent half the budget left.
//!
//! A round is Nelder–Mead then Levenberg–Marquardt, each from the best vector so far; rounds
//! repeat while one lowers the motion distance by more than 1 % and the budget (evaluations:
//! syntheses of every reach) lasts. The vector returned is the one with the lowest motion
//! distance seen (the start included), so a refinement never makes a fit worse.
//!
//! **Reproducibility.** Nothing is random; Nelder–Mead evaluates one point at a time, the
//! Jacobian's columns are synthesized in parallel and assembled in parameter order, and every
//! sum runs in a fixed order, so the result is the same on any number of threads.

use kinergy_io::InvalidSetting;
use kinergy_solver::Synergy;
use nalgebra::{DMatrix, DVector};
use std::sync::atomic::{AtomicBool, Ordering};

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::baseline::{BaselineMethod, BaselineSettings};
use crate::captured::CapturedReach;
use crate::error::Result;
use crate::objective::Objective;

/// How a refinement runs.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RefineSettings {
    /// Budget: at most this many evaluations (each synthesizes every reach once; an
    /// iteration takes one per parameter for the Jacobian and one per trial step).
    pub max_evaluations: usize,
    /// Finite-difference step, as a fraction of each parameter's bound width, in (0, 0.01].
    pub step: f64,
    /// Initial damping λ (> 0).
    pub damping: f64,
    /// Edge of Nelder–Mead's initial simplex, as a fraction of each bound width, in (0, ½].
    pub simplex_step: f64,
}

impl Default for RefineSettings {
    fn default() -> RefineSettings {
        RefineSettings {
            max_evaluations: 1000,
            step: 1e-6,
            damping: 1e-3,
            simplex_step: 0.05,
        }
    }
}

impl RefineSettings {
    /// Checks every setting, naming the field otherwise.
    pub fn validate(&self) -> Result<()> {
        InvalidSetting::require(
            self.max_evaluations >= 1,
            "refine.max_evaluations",
            "at least 1",
        )?;
        InvalidSetting::require(
            self.step > 0.0 && self.step <= 0.01,
            "refine.step",
            "within (0, 0.01]",
        )?;
        InvalidSetting::require(
            self.damping > 0.0 && self.damping.is_finite(),
            "refine.damping",
            "a positive number",
        )?;
        InvalidSetting::require(
            self.simplex_step > 0.0 && self.simplex_step <= 0.5,
            "refine.simplex_step",
            "within (0, 0.5]",
        )?;
        Ok(())
    }
}

/// What a refinement did.
#[derive(Debug, Clone, PartialEq)]
pub struct Refinement {
    /// The best vector seen (the start if nothing was better).
    pub values: Vec<f64>,
    /// Its mean motion distance, meters.
    pub score: f64,
    /// The start's mean motion distance, meters.
    pub start_score: f64,
    /// Evaluations made (the start's included).
    pub evaluations: usize,
    /// Rounds (Nelder–Mead then Levenberg–Marquardt).
    pub rounds: usize,
    /// Whether it was interrupted ([`refine_until`]) before it ended on its own.
    pub interrupted: bool,
}

/// One evaluation: the residuals and the mean motion distance of `x`, or `None` when a
/// synthesis failed or went non-finite.
fn evaluate(objective: &Objective, x: &[f64]) -> Option<(DVector<f64>, f64)> {
    let synergy = Synergy::new(objective.space(), x).ok()?;
    let reaches = objective.reaches();
    let weight = 1.0 / reaches.len() as f64;
    let mut residuals = Vec::new();
    let mut score = 0.0;
    for reach in reaches {
        let (r, d) = reach_residuals(objective, reach, &synergy)?;
        let scale = weight.sqrt();
        residuals.extend(r.iter().map(|v| v * scale));
        score += d * weight;
    }
    let finite = score.is_finite() && residuals.iter().all(|v| v.is_finite());
    finite.then(|| (DVector::from_vec(residuals), score))
}

/// One reach's residuals (over its frames and tracked points, scaled so that their squared
/// norm is the mean squared point error) and motion distance.
fn reach_residuals(
    objective: &Objective,
    reach: &CapturedReach,
    synergy: &Synergy,
) -> Option<(Vec<f64>, f64)> {
    let synthesis = reach
        .synthesize(
            objective.optimizer(),
            synergy.clone(),
            objective.tolerance(),
        )
        .ok()?;
    let distance = reach.distance(&synthesis).ok()?;
    let synthesized = reach.arm().synthesized_trajectory(&synthesis).ok()?;
    let captured = reach.captured();
    // A fitting synthesis runs exactly the capture's frames; one that stopped early failed.
    if synthesized.frame_count() != captured.frame_count() || distance == f64::MAX {
        return None;
    }
    let count = (captured.frame_count() * captured.joint_count()) as f64;
    let scale = 1.0 / count.sqrt();
    let residuals = synthesized
        .frames()
        .zip(captured.frames())
        .flat_map(|(a, b)| a.iter().zip(b).map(|(p, q)| (p - q) * scale))
        .flat_map(|v| [v.x, v.y, v.z])
        .collect();
    Some((residuals, distance))
}

/// Refines `start` (within the objective's bounds) by rounds of Nelder–Mead and
/// Levenberg–Marquardt (module docs).
pub fn refine(
    objective: &Objective,
    start: &[f64],
    settings: &RefineSettings,
) -> Result<Refinement> {
    refine_until(objective, start, settings, None)
}

/// [`refine`], stopping once `interrupt` is raised (Ctrl-C): no evaluation starts after it,
/// and the result says [`Refinement::interrupted`] (the best vector so far, which a caller
/// should not take for a finished refinement). Before, `fit --refine 10000000` ran on for
/// its whole budget after Ctrl-C and wrote its file as if uninterrupted.
pub fn refine_until(
    objective: &Objective,
    start: &[f64],
    settings: &RefineSettings,
    interrupt: Option<&AtomicBool>,
) -> Result<Refinement> {
    settings.validate()?;
    let stop = || interrupt.is_some_and(|f| f.load(Ordering::SeqCst));
    let (lower, upper) = crate::objective::checked_bounds(objective, start)?;
    let n = start.len();
    let start_score = objective.score(start)?;
    let mut out = Refinement {
        values: start.to_vec(),
        score: start_score,
        start_score,
        evaluations: 1,
        rounds: 0,
        interrupted: false,
    };
    let bounds = Bounds { lower, upper };
    loop {
        let before = out.score;
        let left = settings.max_evaluations.saturating_sub(out.evaluations);
        if left < 2 * (n + 1) {
            break;
        }
        if stop() {
            out.interrupted = true;
            break;
        }
        out.rounds += 1;
        let simplex = crate::baseline::minimize_until(
            BaselineMethod::NelderMead,
            objective,
            &out.values,
            &BaselineSettings {
                max_evaluations: left / 2,
                simplex_step: settings.simplex_step,
                sd_tolerance: 1e-9,
                ..BaselineSettings::default()
            },
            interrupt,
        )?;
        out.evaluations += simplex.evaluations;
        if simplex.best_cost < out.score {
            out.score = simplex.best_cost;
            out.values = simplex.best_x;
        }
        let left = settings.max_evaluations.saturating_sub(out.evaluations);
        if stop() {
            out.interrupted = true;
            break;
        }
        let (x, score, evaluations) =
            levenberg_marquardt(objective, &out.values, &bounds, left, settings, &stop);
        out.evaluations += evaluations;
        if score < out.score {
            out.score = score;
            out.values = x;
        }
        if out.score >= 0.99 * before {
            break;
        }
    }
    // Raised inside a round: the round ended early.
    out.interrupted |= stop();
    Ok(out)
}

/// The objective's bounds.
struct Bounds {
    lower: Vec<f64>,
    upper: Vec<f64>,
}

/// Levenberg–Marquardt from `start` with at most `budget` evaluations (module docs): the
/// best vector it saw by motion distance, that distance, and the evaluations made.
fn levenberg_marquardt(
    objective: &Objective,
    start: &[f64],
    bounds: &Bounds,
    budget: usize,
    settings: &RefineSettings,
    stop: &dyn Fn() -> bool,
) -> (Vec<f64>, f64, usize) {
    let (lower, upper) = (&bounds.lower, &bounds.upper);
    let n = start.len();
    let width: Vec<f64> = lower.iter().zip(upper).map(|(l, u)| u - l).collect();
    let mut best = (start.to_vec(), f64::MAX);
    let mut evaluations = 1;
    let Some((mut r, score)) = evaluate(objective, start) else {
        return (best.0, best.1, evaluations);
    };
    best.1 = score;
    let mut x = start.to_vec();
    let mut lambda = settings.damping;
    // An iteration needs n evaluations for J and at least one trial.
    while evaluations + n < budget && lambda <= 1e10 && !stop() {
        let columns: Vec<Option<DVector<f64>>> = (0..n)
            .into_par_iter()
            .map(|k| {
                let h = settings.step * width[k];
                let h = if x[k] + h <= upper[k] { h } else { -h };
                let mut moved = x.clone();
                moved[k] += h;
                // The column in scaled parameters: ∂r/∂(x_k / width_k).
                evaluate(objective, &moved).map(|(rk, _)| (rk - &r) * (width[k] / h))
            })
            .collect();
        evaluations += n;
        let Some(columns) = columns.into_iter().collect::<Option<Vec<_>>>() else {
            break; // a neighbour failed to synthesize: stay where we are
        };
        let j = DMatrix::from_columns(&columns);
        let jtj = j.tr_mul(&j);
        let gradient = j.tr_mul(&r);
        let cost = r.norm_squared();
        let mut improved = false;
        while evaluations < budget && lambda <= 1e10 {
            let mut a = jtj.clone();
            for k in 0..n {
                a[(k, k)] += lambda * jtj[(k, k)].max(1e-12);
            }
            let Some(delta) = a.cholesky().map(|c| c.solve(&-&gradient)) else {
                lambda *= 4.0;
                continue;
            };
            let trial: Vec<f64> = (0..n)
                .map(|k| (x[k] + delta[k] * width[k]).clamp(lower[k], upper[k]))
                .collect();
            evaluations += 1;
            match evaluate(objective, &trial) {
                Some((rt, score)) if rt.norm_squared() < cost => {
                    if score < best.1 {
                        best = (trial.clone(), score);
                    }
                    improved = (cost - rt.norm_squared()) / cost > 1e-12;
                    x = trial;
                    r = rt;
                    lambda = (lambda / 3.0).max(1e-12);
                    break;
                }
                _ => lambda *= 4.0,
            }
        }
        if !improved {
            break;
        }
    }
    (best.0, best.1, evaluations)
}
