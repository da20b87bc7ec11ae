//! The joint-synergy transform of Aubry et al. (2009) §3.2 and §4:
//! Δθ'_i = φ_i(t) · (M Δθ)_i with M diagonal gains and φ a time function built on
//! sig(x) = 1 / (1 + eˣ).
//!
//! | model | M | φ_i(t) | parameters |
//! |---|---|---|---|
//! | S_A | g·I | 1 | `g` |
//! | S_B | diag(g_i) | 1 | `g_<dof>` per DoF |
//! | S_C | diag(g_i) | sig(−s·t + o) | `g_<dof>`…, `s`, `o` |
//! | S_D | diag(g_i) | sig(−s_i·t + o_i) | `g_<dof>`…, `s_<dof>`…, `o_<dof>`… |
//! | S_E | diag(g_i) | e^{k_i(1 − e^{−t})}·sig(−s_i·t + o_i) | S_D's, `k_<dof>`…, `acceleration`, `onset` |
//!
//! t is seconds since the start of the motion, so φ rises from sig(o) at t = 0 through ½
//! at t = o/s (when the DoF "switches on") toward 1. Default bounds are the paper's,
//! g ∈ [−5, 5], s ∈ [1, 10], o ∈ [0, 20], but for o's lower bound: −40 ([`OFFSET_ON`]), a
//! sigmoid switched on before the motion starts. There φ = 1 to double precision
//! (1 + e⁻³⁷ rounds to 1), so S_C holds S_B's motion exactly and each model nests the poorer
//! ones ([`ParamSpace::extend_to`]); with the paper's o ≥ 0, φ(0) ≤ ½ and S_C cannot move as
//! S_B does. Searches still start from a sigmoid switching on as the motion starts, o = 0
//! ([`ParamSpace::neutral`]).
//!
//! S_E is ours, beyond the paper: a DoF's gain moves from g_i at the start toward g_i·e^{k_i}
//! (time constant 1 s; k ∈ [−3, 3]: the shoulder can lead and fade, the elbow come in later),
//! and two factors on the smooth controller's bounds ([`crate::smoothing`]) make its tempo the
//! person's: `acceleration` on the hand's and joints' acceleration bounds ([0.25, 4]) and
//! `onset` on the time they take to rise from zero ([0, 2.5]). With k = 0 and both factors 1 it
//! is S_D exactly.

use std::fmt;
use std::str::FromStr;

use kinergy_io::InvalidSetting;
use serde::{Deserialize, Serialize};

use crate::error::{Result, SolverError};

/// A synergy model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Model {
    /// One gain for every DoF, φ = 1: the raw controller scaled.
    Sa,
    /// A gain per DoF, φ = 1.
    Sb,
    /// A gain per DoF and one shared sigmoid.
    Sc,
    /// A gain and a sigmoid per DoF.
    Sd,
    /// Beyond the paper: S_D with a gain that grows or fades over the reach per DoF and the
    /// person's own acceleration and onset for the smooth controller (see the module
    /// documentation).
    Se,
}

impl Model {
    /// Every model, poorest first.
    pub const ALL: [Model; 5] = [Model::Sa, Model::Sb, Model::Sc, Model::Sd, Model::Se];

    /// `sa`, `sb`, `sc`, `sd` or `se`.
    pub fn name(self) -> &'static str {
        match self {
            Model::Sa => "sa",
            Model::Sb => "sb",
            Model::Sc => "sc",
            Model::Sd => "sd",
            Model::Se => "se",
        }
    }

    /// The paper's name: `S_A` … `S_D` (and `S_E`, ours).
    pub fn paper_name(self) -> &'static str {
        match self {
            Model::Sa => "S_A",
            Model::Sb => "S_B",
            Model::Sc => "S_C",
            Model::Sd => "S_D",
            Model::Se => "S_E",
        }
    }

    /// The model this one extends (S_B extends S_A, …), `None` for S_A.
    pub fn poorer(self) -> Option<Model> {
        match self {
            Model::Sa => None,
            Model::Sb => Some(Model::Sa),
            Model::Sc => Some(Model::Sb),
            Model::Sd => Some(Model::Sc),
            Model::Se => Some(Model::Sd),
        }
    }

    /// The number of parameters on a chain of `dofs` DoFs: 1, n, n + 2, 3n, 4n + 2.
    pub fn parameter_count(self, dofs: usize) -> usize {
        match self {
            Model::Sa => 1,
            Model::Sb => dofs,
            Model::Sc => dofs + 2,
            Model::Sd => 3 * dofs,
            Model::Se => 4 * dofs + 2,
        }
    }
}

impl fmt::Display for Model {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.paper_name())
    }
}

impl FromStr for Model {
    type Err = SolverError;

    fn from_str(s: &str) -> Result<Model> {
        let key = s.replace('_', "").to_ascii_lowercase();
        Model::ALL
            .into_iter()
            .find(|m| m.name() == key)
            .ok_or_else(|| {
                SolverError::Setting(InvalidSetting::new(
                    "model",
                    format!("`{s}` is not one of sa, sb, sc, sd, se"),
                ))
            })
    }
}

/// A closed interval `[lower, upper]`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Interval {
    /// Lower end.
    pub lower: f64,
    /// Upper end.
    pub upper: f64,
}

impl Interval {
    /// `[lower, upper]`.
    pub const fn new(lower: f64, upper: f64) -> Interval {
        Interval { lower, upper }
    }

    /// True when `v` lies inside.
    pub fn contains(&self, v: f64) -> bool {
        (self.lower..=self.upper).contains(&v)
    }

    /// `v` clamped into the interval.
    pub fn clamp(&self, v: f64) -> f64 {
        v.clamp(self.lower, self.upper)
    }
}

/// Bounds of the synergy parameters by kind (the paper's defaults), configurable.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Bounds {
    /// Gains g: [−5, 5].
    pub gain: Interval,
    /// Sigmoid slopes s, 1/s: [1, 10].
    pub slope: Interval,
    /// Sigmoid offsets o: [−40, 20] (the paper's [0, 20], and a sigmoid already on at the
    /// start, [`OFFSET_ON`]).
    pub offset: Interval,
}

impl Default for Bounds {
    fn default() -> Bounds {
        Bounds {
            gain: Interval::new(-5.0, 5.0),
            slope: Interval::new(1.0, 10.0),
            offset: Interval::new(OFFSET_ON, 20.0),
        }
    }
}

impl Bounds {
    /// Checks each interval is finite and not inverted, naming the field otherwise.
    pub fn validate(&self) -> Result<()> {
        for (name, i) in [
            ("bounds.gain", self.gain),
            ("bounds.slope", self.slope),
            ("bounds.offset", self.offset),
        ] {
            InvalidSetting::require(
                i.lower.is_finite() && i.upper.is_finite() && i.lower <= i.upper,
                name,
                "finite [lower, upper] with lower ≤ upper",
            )?;
        }
        Ok(())
    }
}

/// What each entry of a parameter vector means.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ParamKind {
    /// A gain (of every DoF for S_A, else of one DoF).
    Gain,
    /// A sigmoid slope.
    Slope,
    /// A sigmoid offset.
    Offset,
    /// S_E: a DoF's gain growth k (its gain is g·e^{k(1 − e^{−t})}, [`growth_factor`]).
    Growth,
    /// S_E: the factor on the smooth controller's acceleration bounds.
    Acceleration,
    /// S_E: the factor on the smooth controller's onset (the time its bounds take to rise).
    Onset,
}

/// The default lower bound of the sigmoid offsets, below the paper's 0: a sigmoid on from the
/// start, φ(t) = sig(−s·t − 40) = 1 to double precision for every t ≥ 0 and s ≥ 0 (e⁻⁴⁰ is
/// below half of f64's ε, so 1 + e⁻⁴⁰ rounds to 1). The carry-over of S_A or S_B into a
/// model with sigmoids puts its offsets here: the same motion, bit for bit.
pub const OFFSET_ON: f64 = -40.0;

/// S_E's growths k: [−3, 3] (a gain can end up to e³ ≈ 20 times larger or smaller).
pub const GROWTH: Interval = Interval::new(-3.0, 3.0);
/// S_E's acceleration factor: [0.25, 4].
pub const ACCELERATION: Interval = Interval::new(0.25, 4.0);
/// S_E's onset factor: [0, 2.5] (an onset of up to half the reach).
pub const ONSET: Interval = Interval::new(0.0, 2.5);

/// The parameter space of one model on one chain: names, kinds and bounds of the entries.
#[derive(Debug, Clone, PartialEq)]
pub struct ParamSpace {
    model: Model,
    dof_names: Vec<String>,
    bounds: Bounds,
    names: Vec<String>,
    kinds: Vec<ParamKind>,
}

impl ParamSpace {
    /// The space of `model` on a chain with these DoF names.
    pub fn new(model: Model, dof_names: &[String], bounds: Bounds) -> Result<ParamSpace> {
        bounds.validate()?;
        InvalidSetting::require(!dof_names.is_empty(), "dof_names", "at least one DoF")?;
        let n = dof_names.len();
        let mut names = Vec::with_capacity(model.parameter_count(n));
        let mut kinds = Vec::with_capacity(names.capacity());
        let mut push = |name: String, kind| {
            names.push(name);
            kinds.push(kind);
        };
        match model {
            Model::Sa => push("g".into(), ParamKind::Gain),
            _ => dof_names
                .iter()
                .for_each(|d| push(format!("g_{d}"), ParamKind::Gain)),
        }
        match model {
            Model::Sa | Model::Sb => {}
            Model::Sc => {
                push("s".into(), ParamKind::Slope);
                push("o".into(), ParamKind::Offset);
            }
            Model::Sd | Model::Se => {
                dof_names
                    .iter()
                    .for_each(|d| push(format!("s_{d}"), ParamKind::Slope));
                dof_names
                    .iter()
                    .for_each(|d| push(format!("o_{d}"), ParamKind::Offset));
            }
        }
        if model == Model::Se {
            dof_names
                .iter()
                .for_each(|d| push(format!("k_{d}"), ParamKind::Growth));
            push("acceleration".into(), ParamKind::Acceleration);
            push("onset".into(), ParamKind::Onset);
        }
        Ok(ParamSpace {
            model,
            dof_names: dof_names.to_vec(),
            bounds,
            names,
            kinds,
        })
    }

    /// The model.
    pub fn model(&self) -> Model {
        self.model
    }

    /// The chain's DoF names.
    pub fn dof_names(&self) -> &[String] {
        &self.dof_names
    }

    /// The bounds by kind.
    pub fn bounds(&self) -> &Bounds {
        &self.bounds
    }

    /// Number of parameters.
    pub fn len(&self) -> usize {
        self.names.len()
    }

    /// Always false: every model has at least one parameter.
    pub fn is_empty(&self) -> bool {
        self.names.is_empty()
    }

    /// The entries' names, in vector order: `g` or `g_<dof>`…, then `s`, `o` or
    /// `s_<dof>`…, `o_<dof>`…, then S_E's `k_<dof>`…, `acceleration`, `onset`.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The entries' kinds.
    pub fn kinds(&self) -> &[ParamKind] {
        &self.kinds
    }

    /// The interval of entry `i`.
    pub fn interval(&self, i: usize) -> Interval {
        match self.kinds[i] {
            ParamKind::Gain => self.bounds.gain,
            ParamKind::Slope => self.bounds.slope,
            ParamKind::Offset => self.bounds.offset,
            ParamKind::Growth => GROWTH,
            ParamKind::Acceleration => ACCELERATION,
            ParamKind::Onset => ONSET,
        }
    }

    /// Lower bounds, one per entry.
    pub fn lower(&self) -> Vec<f64> {
        (0..self.len()).map(|i| self.interval(i).lower).collect()
    }

    /// Upper bounds, one per entry.
    pub fn upper(&self) -> Vec<f64> {
        (0..self.len()).map(|i| self.interval(i).upper).collect()
    }

    /// The index of the entry with this name.
    pub fn index(&self, name: &str) -> Option<usize> {
        self.names.iter().position(|n| n == name)
    }

    /// The neutral vector, where searches start: gains 1, and sigmoids switching on as the
    /// motion starts, as steeply as the bounds allow (largest slope, offset 0 — the paper's
    /// lowest — clamped into the bounds).
    pub fn neutral(&self) -> Vec<f64> {
        (0..self.len())
            .map(|i| {
                let b = self.interval(i);
                match self.kinds[i] {
                    ParamKind::Gain => b.clamp(1.0),
                    ParamKind::Slope => b.upper,
                    ParamKind::Offset => b.clamp(0.0),
                    ParamKind::Growth => 0.0,
                    ParamKind::Acceleration | ParamKind::Onset => 1.0,
                }
            })
            .collect()
    }

    /// Checks the length and that every value is finite and within its bounds, naming the
    /// first entry that is not.
    pub fn validate(&self, values: &[f64]) -> Result<()> {
        if values.len() != self.len() {
            return Err(SolverError::ParamCount {
                model: self.model.to_string(),
                dofs: self.dof_names.len(),
                expected: self.len(),
                found: values.len(),
            });
        }
        for (i, &v) in values.iter().enumerate() {
            let b = self.interval(i);
            if !b.contains(v) {
                return Err(SolverError::OutOfBounds {
                    name: self.names[i].clone(),
                    value: v,
                    lower: b.lower,
                    upper: b.upper,
                });
            }
        }
        Ok(())
    }

    /// `values` clamped into the bounds (NaN becomes the lower bound).
    pub fn clamp(&self, values: &mut [f64]) {
        for (i, v) in values.iter_mut().enumerate() {
            let b = self.interval(i);
            *v = if v.is_nan() { b.lower } else { b.clamp(*v) };
        }
    }

    /// Carries a vector of this space into a richer model's space on the same chain, so
    /// that training the richer model can start from this one's solution: S_A's gain goes
    /// to every DoF; S_C's shared sigmoid goes to every DoF of S_D; S_E's own parameters are
    /// neutral (no growth, the tempo factors 1). S_A and S_B gain sigmoids switched on as
    /// early as the bounds allow (largest slope, smallest offset): with the default bounds
    /// (o down to [`OFFSET_ON`]) φ = 1 and every carry-over is the same motion, bit for bit;
    /// with the paper's o ≥ 0 that sigmoid starts at ½ and S_A/S_B → S_C is not exact. Going
    /// to the same model returns the vector unchanged.
    pub fn extend_to(&self, values: &[f64], richer: &ParamSpace) -> Result<Vec<f64>> {
        self.validate(values)?;
        InvalidSetting::require(
            richer.dof_names == self.dof_names,
            "dof_names",
            "the same chain in both parameter spaces",
        )?;
        InvalidSetting::require(
            richer.model >= self.model,
            "model",
            "a model at least as rich as the one extended",
        )?;
        let n = self.dof_names.len();
        let gains: Vec<f64> = match self.model {
            Model::Sa => vec![values[0]; n],
            _ => values[..n].to_vec(),
        };
        let (slopes, offsets): (Vec<f64>, Vec<f64>) = match self.model {
            Model::Sa | Model::Sb => {
                // On as early as the bounds allow: φ = 1 where they reach OFFSET_ON.
                let b = richer.bounds;
                (vec![b.slope.upper; n], vec![b.offset.lower; n])
            }
            Model::Sc => (vec![values[n]; n], vec![values[n + 1]; n]),
            Model::Sd | Model::Se => (values[n..2 * n].to_vec(), values[2 * n..3 * n].to_vec()),
        };
        // S_E's own part: the growth rates and the tempo factors, neutral (no growth, the
        // default bounds) unless extended from S_E itself.
        let own: Vec<f64> = match self.model {
            Model::Se => values[3 * n..].to_vec(),
            _ => richer
                .neutral()
                .get(3 * n..)
                .map(<[f64]>::to_vec)
                .unwrap_or_default(),
        };
        let mut out = match richer.model {
            Model::Sa => vec![gains[0]],
            Model::Sb => gains,
            Model::Sc => {
                let mut v = gains;
                v.extend([slopes[0], offsets[0]]);
                v
            }
            Model::Sd => {
                let mut v = gains;
                v.extend(slopes);
                v.extend(offsets);
                v
            }
            Model::Se => {
                let mut v = gains;
                v.extend(slopes);
                v.extend(offsets);
                v.extend(own);
                v
            }
        };
        richer.clamp(&mut out);
        Ok(out)
    }
}

/// S_E's growth of a gain: e^{k(1 − e^{−t})}, 1 at t = 0 and e^k after a few seconds (time
/// constant 1 s). Tried against e^{kt} and e^{k·min(t, 1)} on held-out takes of the shared
/// people (docs/guide/fitting.md, "S_E, beyond the paper"): unbounded in time, the growth fitted on short reaches blew up over
/// a slow person's longer ones.
#[inline]
pub fn growth_factor(k: f64, t: f64) -> f64 {
    (k * growth_rise(t)).exp()
}

/// 1 − e^{−t}, the share of its growth a gain has made at `t` (the same for every DoF).
#[inline]
fn growth_rise(t: f64) -> f64 {
    -(-t).exp_m1()
}

/// sig(x) = 1 / (1 + eˣ), the paper's sigmoid.
#[inline]
pub fn sig(x: f64) -> f64 {
    1.0 / (1.0 + x.exp())
}

/// The time part of a synergy.
#[derive(Debug, Clone, PartialEq)]
enum Timing {
    /// φ = 1.
    Constant,
    /// φ = sig(−s t + o) for every DoF.
    Shared { slope: f64, offset: f64 },
    /// φ_i = sig(−s_i t + o_i).
    PerDof { slopes: Vec<f64>, offsets: Vec<f64> },
    /// φ_i = e^{k_i(1 − e^{−t})} sig(−s_i t + o_i) (S_E).
    Growing {
        slopes: Vec<f64>,
        offsets: Vec<f64>,
        growth: Vec<f64>,
    },
}

/// S_E's factors on the smooth controller's bounds ([`Synergy::tempo`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TempoFactors {
    /// On the hand's and the joints' acceleration bounds.
    pub acceleration: f64,
    /// On the onset, the time over which the bounds rise from zero.
    pub onset: f64,
}

/// A synergy transform S(t, Θ) ready to apply: validated parameters of one model.
#[derive(Debug, Clone, PartialEq)]
pub struct Synergy {
    model: Model,
    gains: Vec<f64>,
    timing: Timing,
    tempo: Option<TempoFactors>,
}

impl Synergy {
    /// The synergy of `values` in `space`, validated against the bounds.
    pub fn new(space: &ParamSpace, values: &[f64]) -> Result<Synergy> {
        space.validate(values)?;
        let n = space.dof_names.len();
        let gains = match space.model {
            Model::Sa => vec![values[0]; n],
            _ => values[..n].to_vec(),
        };
        let timing = match space.model {
            Model::Sa | Model::Sb => Timing::Constant,
            Model::Sc => Timing::Shared {
                slope: values[n],
                offset: values[n + 1],
            },
            Model::Sd => Timing::PerDof {
                slopes: values[n..2 * n].to_vec(),
                offsets: values[2 * n..].to_vec(),
            },
            Model::Se => Timing::Growing {
                slopes: values[n..2 * n].to_vec(),
                offsets: values[2 * n..3 * n].to_vec(),
                growth: values[3 * n..4 * n].to_vec(),
            },
        };
        let tempo = (space.model == Model::Se).then(|| TempoFactors {
            acceleration: values[4 * n],
            onset: values[4 * n + 1],
        });
        Ok(Synergy {
            model: space.model,
            gains,
            timing,
            tempo,
        })
    }

    /// The identity synergy on `dofs` DoFs (S_A with g = 1): the raw optimizer.
    pub fn identity(dofs: usize) -> Synergy {
        Synergy {
            model: Model::Sa,
            gains: vec![1.0; dofs],
            timing: Timing::Constant,
            tempo: None,
        }
    }

    /// S_E's factors on the smooth controller's bounds (`None` for S_A … S_D): the
    /// controller scales its [`crate::Smoothing`] by them.
    pub fn tempo(&self) -> Option<TempoFactors> {
        self.tempo
    }

    /// The model.
    pub fn model(&self) -> Model {
        self.model
    }

    /// The number of DoFs it applies to.
    pub fn dof_count(&self) -> usize {
        self.gains.len()
    }

    /// The gain of DoF `i` (the diagonal of M).
    pub fn gain(&self, i: usize) -> f64 {
        self.gains[i]
    }

    /// φ_i(t).
    pub fn phi(&self, i: usize, t: f64) -> f64 {
        match &self.timing {
            Timing::Constant => 1.0,
            Timing::Shared { slope, offset } => sig(-slope * t + offset),
            Timing::PerDof { slopes, offsets } => sig(-slopes[i] * t + offsets[i]),
            Timing::Growing {
                slopes,
                offsets,
                growth,
            } => growth_factor(growth[i], t) * sig(-slopes[i] * t + offsets[i]),
        }
    }

    /// Δθ ← S(t) Δθ in place: Δθ_i ← φ_i(t) · g_i · Δθ_i.
    #[inline]
    pub fn apply(&self, t: f64, dtheta: &mut [f64]) {
        match &self.timing {
            Timing::Constant => {
                for (d, g) in dtheta.iter_mut().zip(&self.gains) {
                    *d *= g;
                }
            }
            Timing::Shared { slope, offset } => {
                let phi = sig(-slope * t + offset);
                for (d, g) in dtheta.iter_mut().zip(&self.gains) {
                    *d *= g * phi;
                }
            }
            Timing::PerDof { slopes, offsets } => {
                for (i, d) in dtheta.iter_mut().enumerate() {
                    *d *= self.gains[i] * sig(-slopes[i] * t + offsets[i]);
                }
            }
            Timing::Growing {
                slopes,
                offsets,
                growth,
            } => {
                let rise = growth_rise(t);
                for (i, d) in dtheta.iter_mut().enumerate() {
                    *d *=
                        self.gains[i] * (growth[i] * rise).exp() * sig(-slopes[i] * t + offsets[i]);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn dofs() -> Vec<String> {
        ["a", "b", "c"].map(String::from).to_vec()
    }

    #[test]
    fn names_counts_and_bounds_follow_the_paper_but_the_offset_s_lower_bound() {
        let d = dofs();
        let sc = ParamSpace::new(Model::Sc, &d, Bounds::default()).expect("sc");
        assert_eq!(sc.names(), ["g_a", "g_b", "g_c", "s", "o"]);
        assert_eq!(sc.lower(), [-5.0, -5.0, -5.0, 1.0, OFFSET_ON]);
        assert_eq!(sc.upper(), [5.0, 5.0, 5.0, 10.0, 20.0]);
        let sd = ParamSpace::new(Model::Sd, &d, Bounds::default()).expect("sd");
        assert_eq!(sd.names()[3..], ["s_a", "s_b", "s_c", "o_a", "o_b", "o_c"]);
        // The paper's counts on its 7-DoF chain: S_C 9, S_D 21.
        assert_eq!(Model::Sc.parameter_count(7), 9);
        assert_eq!(Model::Sd.parameter_count(7), 21);
        assert_eq!(
            ParamSpace::new(Model::Sa, &d, Bounds::default())
                .expect("sa")
                .names(),
            ["g"]
        );
    }

    #[test]
    fn validation_names_the_entry_out_of_bounds() {
        let sc = ParamSpace::new(Model::Sc, &dofs(), Bounds::default()).expect("sc");
        let err = sc
            .validate(&[1.0, 1.0, 1.0, 11.0, 2.0])
            .expect_err("slope 11");
        assert!(err.to_string().contains("`s` = 11"), "{err}");
        let err = sc
            .validate(&[1.0, f64::NAN, 1.0, 5.0, 2.0])
            .expect_err("NaN");
        assert!(err.to_string().contains("g_b"), "{err}");
        let err = sc.validate(&[1.0]).expect_err("count");
        assert!(matches!(
            err,
            SolverError::ParamCount {
                expected: 5,
                found: 1,
                ..
            }
        ));
        let bad = Bounds {
            slope: Interval::new(3.0, 2.0),
            ..Bounds::default()
        };
        let err = ParamSpace::new(Model::Sc, &dofs(), bad).expect_err("inverted");
        assert!(err.to_string().contains("bounds.slope"), "{err}");
    }

    #[test]
    fn the_sigmoid_switches_on_at_o_over_s() {
        let sc = ParamSpace::new(Model::Sc, &dofs(), Bounds::default()).expect("sc");
        let syn = Synergy::new(&sc, &[1.0, 2.0, -1.0, 4.0, 6.0]).expect("synergy");
        assert_relative_eq!(syn.phi(0, 1.5), 0.5);
        assert!(syn.phi(0, 0.0) < 0.01 && syn.phi(0, 3.0) > 0.99);
        let mut d = [1.0, 1.0, 1.0];
        syn.apply(1.5, &mut d);
        assert_eq!(d, [0.5, 1.0, -0.5]);
    }

    #[test]
    fn extending_keeps_the_motion_where_the_bounds_allow() {
        let d = dofs();
        let spaces: Vec<_> = Model::ALL
            .iter()
            .map(|&m| ParamSpace::new(m, &d, Bounds::default()).expect("space"))
            .collect();
        let sb = spaces[0].extend_to(&[2.5], &spaces[1]).expect("sa→sb");
        assert_eq!(sb, [2.5, 2.5, 2.5]);
        let sc_values = [1.0, -2.0, 3.0, 4.0, 6.0];
        let sd = spaces[2].extend_to(&sc_values, &spaces[3]).expect("sc→sd");
        let (a, b) = (
            Synergy::new(&spaces[2], &sc_values).expect("sc"),
            Synergy::new(&spaces[3], &sd).expect("sd"),
        );
        for t in [0.0, 0.7, 1.5, 4.0] {
            let (mut x, mut y) = ([0.3, -0.2, 0.1], [0.3, -0.2, 0.1]);
            a.apply(t, &mut x);
            b.apply(t, &mut y);
            assert_eq!(x, y);
        }
        let err = spaces[3].extend_to(&sd, &spaces[0]).expect_err("poorer");
        assert!(err.to_string().contains("model"), "{err}");
    }

    // Issue 43, item 9: with the default bounds every model carries into every richer one as
    // the same step, bit for bit, at any time — S_B into S_C too, its sigmoid on from before
    // the start (o = OFFSET_ON). With the paper's o ≥ 0 it starts at ½: not the same step.
    #[test]
    fn every_carry_over_is_the_same_step_bit_for_bit() {
        let d = dofs();
        let spaces: Vec<_> = Model::ALL
            .iter()
            .map(|&m| ParamSpace::new(m, &d, Bounds::default()).expect("space"))
            .collect();
        let values: [&[f64]; 4] = [
            &[-1.7],
            &[1.3, -0.4, 4.9],
            &[0.8, 2.0, -3.0, 2.5, 7.0],
            &[1.5, -0.5, 2.0, 4.0, 6.0, 2.0, 1.0, 0.0, 3.0],
        ];
        for (i, v) in values.iter().enumerate() {
            let poorer = Synergy::new(&spaces[i], v).expect("poorer");
            for richer in &spaces[i + 1..] {
                let carried = spaces[i].extend_to(v, richer).expect("extend");
                let r = Synergy::new(richer, &carried).expect("richer");
                for t in [0.0, 0.01, 0.3, 1.0, 2.5, 30.0] {
                    let (mut x, mut y) = ([0.3, -0.7, 1.1], [0.3, -0.7, 1.1]);
                    poorer.apply(t, &mut x);
                    r.apply(t, &mut y);
                    assert_eq!(
                        x.map(f64::to_bits),
                        y.map(f64::to_bits),
                        "{} → {} at t = {t}",
                        spaces[i].model(),
                        richer.model()
                    );
                }
            }
        }
        let paper = Bounds {
            offset: Interval::new(0.0, 20.0),
            ..Bounds::default()
        };
        let sb = ParamSpace::new(Model::Sb, &d, paper).expect("sb");
        let sc = ParamSpace::new(Model::Sc, &d, paper).expect("sc");
        let carried = sb.extend_to(values[1], &sc).expect("extend");
        let phi = Synergy::new(&sc, &carried).expect("sc").phi(0, 0.0);
        assert_relative_eq!(phi, 0.5);
    }

    #[test]
    fn models_parse_both_spellings() {
        assert_eq!("S_C".parse::<Model>().expect("S_C"), Model::Sc);
        assert_eq!("sd".parse::<Model>().expect("sd"), Model::Sd);
        assert_eq!("S_E".parse::<Model>().expect("S_E"), Model::Se);
        assert!("sf".parse::<Model>().is_err());
    }

    #[test]
    fn s_e_names_its_own_parameters_after_s_d_s() {
        let d = dofs();
        let se = ParamSpace::new(Model::Se, &d, Bounds::default()).expect("se");
        assert_eq!(Model::Se.parameter_count(3), 14);
        assert_eq!(se.len(), 14);
        assert_eq!(
            &se.names()[9..],
            ["k_a", "k_b", "k_c", "acceleration", "onset"].map(String::from)
        );
        let neutral = se.neutral();
        assert_eq!(&neutral[9..], &[0.0, 0.0, 0.0, 1.0, 1.0]);
        assert_eq!(Model::Se.poorer(), Some(Model::Sd));
        assert_eq!("se".parse::<Model>().expect("se"), Model::Se);
        assert_eq!(Model::Se.paper_name(), "S_E");
    }

    #[test]
    fn s_e_gains_grow_exponentially_over_s_d_s_sigmoid() {
        let d = dofs();
        let se = ParamSpace::new(Model::Se, &d, Bounds::default()).expect("se");
        let values = [
            1.5, -0.5, 2.0, 4.0, 6.0, 2.0, 1.0, 0.0, 3.0, 0.7, -1.2, 0.0, 1.3, 0.6,
        ];
        let s = Synergy::new(&se, &values).expect("S_E");
        for t in [0.0, 0.1, 0.45, 1.3] {
            let mut step = [1.0, 1.0, 1.0];
            s.apply(t, &mut step);
            for i in 0..3 {
                let phi = (values[9 + i] * (1.0 - (-t).exp())).exp()
                    * sig(-values[3 + i] * t + values[6 + i]);
                assert_relative_eq!(s.phi(i, t), phi, epsilon = 1e-15);
                assert_relative_eq!(step[i], values[i] * phi, epsilon = 1e-15);
            }
        }
        let tempo = s.tempo().expect("tempo");
        assert_eq!((tempo.acceleration, tempo.onset), (1.3, 0.6));
        let sd = ParamSpace::new(Model::Sd, &d, Bounds::default()).expect("sd");
        assert_eq!(Synergy::new(&sd, &values[..9]).expect("S_D").tempo(), None);
    }

    #[test]
    fn s_d_carries_into_s_e_exactly_and_s_e_into_itself() {
        let d = dofs();
        let sd = ParamSpace::new(Model::Sd, &d, Bounds::default()).expect("sd");
        let se = ParamSpace::new(Model::Se, &d, Bounds::default()).expect("se");
        let v = [1.5, -0.5, 2.0, 4.0, 6.0, 2.0, 1.0, 0.0, 3.0];
        let carried = sd.extend_to(&v, &se).expect("extend");
        assert_eq!(&carried[..9], &v);
        assert_eq!(&carried[9..], &se.neutral()[9..]);
        let (a, b) = (
            Synergy::new(&sd, &v).expect("S_D"),
            Synergy::new(&se, &carried).expect("S_E"),
        );
        for t in [0.0, 0.2, 0.9] {
            let (mut x, mut y) = ([0.3, -0.7, 1.1], [0.3, -0.7, 1.1]);
            a.apply(t, &mut x);
            b.apply(t, &mut y);
            assert_eq!(x.map(f64::to_bits), y.map(f64::to_bits));
        }
        let mut own = carried.clone();
        own[12] = 2.0;
        assert_eq!(se.extend_to(&own, &se).expect("same"), own);
        // Out of S_E's own bounds: named.
        own[9] = 4.0;
        let e = se.validate(&own).expect_err("out of bounds").to_string();
        assert!(e.contains("k_a"), "{e}");
    }
}
