//! What the trainer minimizes: the mean motion distance, over a set of captured reaches, of
//! the motions the synergy controller synthesizes with a parameter vector.

use kinergy_io::InvalidSetting;
use rayon::prelude::*;

use kinergy_solver::{FitObjective, Optimizer, ParamSpace, Synergy};

use crate::captured::{CapturedReach, DEFAULT_TOLERANCE};
use crate::error::{Result, TrainError};

/// The relative margin by which a reach's partial distance must pass its share of the limit
/// before [`Objective::score_within`] abandons it: far beyond the rounding of the mean.
const WITHIN_MARGIN: f64 = 1e-9;

/// A bounded cost function: what [`crate::anneal`] and [`crate::baseline`] minimize.
/// Evaluations must be deterministic; `cost` is called from several threads at once.
pub trait CostFunction: Sync {
    /// The number of parameters.
    fn dimension(&self) -> usize;
    /// The lower and upper bound of every parameter (lower < upper).
    fn bounds(&self) -> (Vec<f64>, Vec<f64>);
    /// The cost of `x` (within the bounds). Failures and non-finite costs are reported as
    /// `f64::MAX`, worse than anything else.
    fn cost(&self, x: &[f64]) -> f64;
    /// The cost of `x` where it is at most `limit`; above, the cost or any number greater
    /// than `limit` and not greater than the cost (an evaluation may stop as soon as it knows
    /// the cost exceeds `limit`). The annealer asks this with the cost above which it would
    /// reject the proposal anyway. By default the cost itself.
    fn cost_within(&self, x: &[f64], limit: f64) -> f64 {
        let _ = limit;
        self.cost(x)
    }
    /// Synthesized frames per evaluation (for speed reports; 0 when not meaningful).
    fn frames_per_evaluation(&self) -> usize {
        0
    }
}

/// `cost`'s bounds, checked (one pair per parameter, lower < upper) together with a start
/// vector (one value per parameter, within the bounds); errors name `bounds` or `start`.
pub fn checked_bounds(cost: &dyn CostFunction, start: &[f64]) -> Result<(Vec<f64>, Vec<f64>)> {
    let (lower, upper) = cost.bounds();
    let n = cost.dimension();
    InvalidSetting::require(
        lower.len() == n && upper.len() == n,
        "bounds",
        "one lower and one upper bound per parameter",
    )?;
    InvalidSetting::require(
        lower.iter().zip(&upper).all(|(l, u)| l < u),
        "bounds",
        "lower < upper for every parameter",
    )?;
    InvalidSetting::require(start.len() == n, "start", format!("{n} parameters"))?;
    InvalidSetting::require(
        start
            .iter()
            .zip(lower.iter().zip(&upper))
            .all(|(x, (l, u))| x >= l && x <= u),
        "start",
        "within the bounds",
    )?;
    Ok((lower, upper))
}

/// The mean motion distance over `reaches` of the motions synthesized with a parameter
/// vector of `space` and `optimizer` — with [`FitObjective::PositionsSpeed`], each reach's
/// distance plus its weighted hand-speed error ([`CapturedReach::score`]).
#[derive(Debug, Clone)]
pub struct Objective {
    reaches: Vec<CapturedReach>,
    space: ParamSpace,
    optimizer: Optimizer,
    tolerance: f64,
    kind: FitObjective,
}

impl Objective {
    /// An objective over `reaches` (at least one; every reach's chain must have the DoF
    /// names of `space`), with ε = [`DEFAULT_TOLERANCE`].
    pub fn new(
        reaches: Vec<CapturedReach>,
        space: ParamSpace,
        optimizer: Optimizer,
    ) -> Result<Objective> {
        InvalidSetting::require(!reaches.is_empty(), "reaches", "at least one reach to fit")?;
        optimizer.validate()?;
        for r in &reaches {
            if r.dof_names() != space.dof_names() {
                return Err(TrainError::Reach {
                    clip: r.name().to_string(),
                    why: format!(
                        "its arm's DoFs ({}) differ from the parameters' ({})",
                        kinergy_io::list_some(&r.dof_names(), 8),
                        kinergy_io::list_some(space.dof_names(), 8)
                    ),
                });
            }
        }
        Ok(Objective {
            reaches,
            space,
            optimizer,
            tolerance: DEFAULT_TOLERANCE,
            kind: FitObjective::Positions,
        })
    }

    /// The same objective minimizing `kind` (a speed weight finite and ≥ 0, else a
    /// `speed_weight` error).
    pub fn with_kind(mut self, kind: FitObjective) -> Result<Objective> {
        let w = kind.speed_weight();
        InvalidSetting::require(
            w.is_finite() && w >= 0.0,
            "speed_weight",
            "a number of seconds ≥ 0",
        )?;
        self.kind = kind;
        Ok(self)
    }

    /// What it minimizes.
    pub fn kind(&self) -> FitObjective {
        self.kind
    }

    /// The same objective with ε = `tolerance` (meters, positive).
    pub fn with_tolerance(mut self, tolerance: f64) -> Result<Objective> {
        InvalidSetting::require(
            tolerance > 0.0 && tolerance.is_finite(),
            "tolerance",
            "a positive number of meters",
        )?;
        self.tolerance = tolerance;
        Ok(self)
    }

    /// The reaches.
    pub fn reaches(&self) -> &[CapturedReach] {
        &self.reaches
    }

    /// The parameter space.
    pub fn space(&self) -> &ParamSpace {
        &self.space
    }

    /// The optimizer.
    pub fn optimizer(&self) -> Optimizer {
        self.optimizer
    }

    /// ε, meters.
    pub fn tolerance(&self) -> f64 {
        self.tolerance
    }

    /// The distance of every reach's synthesis with `x`, in the order of the reaches
    /// (computed in parallel, deterministic).
    pub fn distances(&self, x: &[f64]) -> Result<Vec<f64>> {
        let synergy = Synergy::new(&self.space, x)?;
        self.reaches
            .par_iter()
            .map(|r| r.evaluate_for(self.optimizer, synergy.clone(), self.tolerance, self.kind))
            .collect()
    }

    /// Every reach's synthesis with `x`, in the order of the reaches: the motions
    /// [`Objective::distances`] scores (for pictures and pages; not abandoned early).
    pub fn syntheses(&self, x: &[f64]) -> Result<Vec<kinergy_solver::Synthesis>> {
        let synergy = Synergy::new(&self.space, x)?;
        self.reaches
            .iter()
            .map(|r| r.synthesize(self.optimizer, synergy.clone(), self.tolerance))
            .collect()
    }

    /// The mean distance over the reaches (summed in the reaches' order, so the same on any
    /// thread count).
    pub fn score(&self, x: &[f64]) -> Result<f64> {
        Ok(Objective::mean(&self.distances(x)?))
    }

    /// [`Objective::score`] where it is at most `limit`; above, a number greater than `limit`
    /// and not greater than the score. Each reach's synthesis is abandoned once its own
    /// distance puts the mean above `limit` (the others' distances being non-negative; with
    /// a relative margin of 10⁻⁹ against rounding). See [`CapturedReach::evaluate_within`].
    pub fn score_within(&self, x: &[f64], limit: f64) -> Result<f64> {
        let synergy = Synergy::new(&self.space, x)?;
        let each = limit * self.reaches.len() as f64 * (1.0 + WITHIN_MARGIN);
        let d = self
            .reaches
            .par_iter()
            .map(|r| {
                r.evaluate_within_for(
                    self.optimizer,
                    synergy.clone(),
                    self.tolerance,
                    self.kind,
                    each,
                )
            })
            .collect::<Result<Vec<f64>>>()?;
        Ok(Objective::mean(&d))
    }

    /// The mean of the reaches' distances, `f64::MAX` when not finite.
    fn mean(d: &[f64]) -> f64 {
        let sum: f64 = d.iter().sum();
        if sum.is_finite() {
            sum / d.len() as f64
        } else {
            f64::MAX
        }
    }
}

impl CostFunction for Objective {
    fn dimension(&self) -> usize {
        self.space.len()
    }

    fn bounds(&self) -> (Vec<f64>, Vec<f64>) {
        (self.space.lower(), self.space.upper())
    }

    fn cost(&self, x: &[f64]) -> f64 {
        self.score(x).unwrap_or(f64::MAX)
    }

    fn cost_within(&self, x: &[f64], limit: f64) -> f64 {
        self.score_within(x, limit).unwrap_or(f64::MAX)
    }

    fn frames_per_evaluation(&self) -> usize {
        self.reaches.iter().map(CapturedReach::frame_count).sum()
    }
}
