//! The annealer's settings: how it searches and when it stops.

use kinergy_io::InvalidSetting;
use serde::{Deserialize, Serialize};

use crate::error::Result;

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

/// The stopping rule's relative change for a library of captures
/// ([`AnnealSettings::for_library`]): 0.1 %.
pub const LIBRARY_STABLE_TOLERANCE: f64 = 1e-3;
/// The stopping rule's window for a library of captures ([`AnnealSettings::for_library`]):
/// 15 iterations.
pub const LIBRARY_STABLE_WINDOW: usize = 15;

impl AnnealSettings {
    /// These settings with a library's stopping rule: a fit stops once its population's mean
    /// score changed by at most [`LIBRARY_STABLE_TOLERANCE`] over [`LIBRARY_STABLE_WINDOW`]
    /// iterations (not 0.01 % over 25). On 1,008 real 30-frame raises (S_A → S_D nested, per
    /// take) it halves the evaluations and ends with the same mean distances (S_D 20.53 mm
    /// against 20.47): what a survey of thousands of takes needs. The vectors differ where the
    /// score is flat, and those directions drive a full-body character differently, so a
    /// person's fit for a character keeps the finer default.
    pub fn for_library(self) -> AnnealSettings {
        AnnealSettings {
            stable_tolerance: LIBRARY_STABLE_TOLERANCE,
            stable_window: LIBRARY_STABLE_WINDOW,
            ..self
        }
    }

    /// The paper's greedy search: temperature zero.
    pub fn greedy() -> AnnealSettings {
        AnnealSettings {
            temperature: 0.0,
            ..AnnealSettings::default()
        }
    }

    /// Checks every setting, naming the field otherwise.
    pub fn validate(&self) -> Result<()> {
        InvalidSetting::require(self.population >= 1, "anneal.population", "at least 1")?;
        InvalidSetting::require(
            self.max_evaluations >= self.population,
            "anneal.max_evaluations",
            format!("at least the population ({})", self.population),
        )?;
        let fraction = |v: f64| v > 0.0 && v <= 1.0;
        InvalidSetting::require(
            fraction(self.min_step) && fraction(self.max_step) && self.min_step <= self.max_step,
            "anneal.min_step/max_step",
            "0 < min_step ≤ max_step ≤ 1",
        )?;
        InvalidSetting::require(
            self.initial_step >= self.min_step && self.initial_step <= self.max_step,
            "anneal.initial_step",
            "within [min_step, max_step]",
        )?;
        InvalidSetting::require(
            self.target_acceptance > 0.0 && self.target_acceptance < 1.0,
            "anneal.target_acceptance",
            "within (0, 1)",
        )?;
        InvalidSetting::require(self.adapt_every >= 1, "anneal.adapt_every", "at least 1")?;
        InvalidSetting::require(
            self.temperature >= 0.0 && self.temperature.is_finite(),
            "anneal.temperature",
            "a finite number ≥ 0",
        )?;
        InvalidSetting::require(
            self.cooling > 0.0 && self.cooling <= 1.0,
            "anneal.cooling",
            "within (0, 1]",
        )?;
        InvalidSetting::require(
            self.stable_window >= 1,
            "anneal.stable_window",
            "at least 1",
        )?;
        InvalidSetting::require(
            self.stable_tolerance >= 0.0 && self.stable_tolerance.is_finite(),
            "anneal.stable_tolerance",
            "a finite number ≥ 0",
        )?;
        Ok(())
    }
}
