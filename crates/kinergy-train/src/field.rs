//! A parameter field over the reach space, per person (DESIGN §1.1, beyond the paper).
//!
//! Aubry et al. (2009) learn synergy parameters clip by clip and name that as their limit: a
//! new target has no parameters until a clip reaching it is fitted. A [`ParamField`] turns a
//! person's per-clip fits — reach k's target t_k and its fitted vector p_k — into parameters
//! p(t) for any target t, by Gaussian-kernel regression in target space. Targets are meters
//! in one frame for all samples: a person's field takes them in the arm's base frame on each
//! reach's first frame ([`crate::CapturedReach::local_target`]), so reaches compare wherever
//! the person stood and whichever way they faced.
//!
//! [`FieldFile`] is the field as a product (`kinergy fit --per person --field`): the field,
//! the optimizer and the fitted reaches (clip, frames, arm), format-versioned; a person's
//! parameters are read with [`crate::person::PersonParams`], which takes a field file or a
//! parameters file.
//!
//! # The method
//!
//! Kernel weights, with bandwidth h (meters):
//!
//! w_k(t) = exp(−|t − t_k|² / 2h²),
//!
//! computed in log space relative to the largest one (the nearest sample's weight is exactly
//! 1), so far from every sample they never all underflow to zero.
//!
//! - [`Regression::NadarayaWatson`] (the default), the local-constant fit:
//!   p(t) = Σ_k w_k(t) p_k / Σ_k w_k(t).
//! - [`Regression::LocalLinear`], the local-linear fit: p(t) = a, the intercept of the
//!   weighted least-squares plane p_k ≈ a + B u_k, u_k = (t_k − t)/h, with a ridge penalty on
//!   the slopes: with normalized weights ŵ_k = w_k / Σ w, minimize
//!   Σ_k ŵ_k |p_k − a − B u_k|² + λ |B|². Centred on the weighted mean target
//!   t̄ = Σ ŵ_k t_k (v_k = (t_k − t̄)/h, so Σ ŵ_k v_k = 0) the normal equations separate and
//!   a = p_NW(t) + B̂ (t − t̄)/h, B̂ = [Σ_k ŵ_k (p_k − p_NW) v_kᵀ] S⁺, S = Σ_k ŵ_k v_k v_kᵀ + λI:
//!   Nadaraya–Watson plus a slope correction. λ = 0 is the plain local-linear fit (it
//!   reproduces a field linear in t exactly wherever the weighted targets span 3-D); λ → ∞
//!   tends to Nadaraya–Watson. S⁺ inverts the eigenvalues of S above 10⁻¹² of the largest,
//!   so with λ = 0 and targets on a plane or a line there is no slope across them (the λ → 0
//!   limit). The result is clamped into the bounds, since a linear fit can leave them when it
//!   extrapolates (it is no longer a convex combination).
//!
//! # Properties
//!
//! - Within bounds, always: a Nadaraya–Watson value is a convex combination of fitted
//!   vectors, so each entry lies between the samples' smallest and largest value of that
//!   entry (the result is clamped to that range to absorb rounding); a local-linear value is
//!   clamped into the [`ParamSpace`] bounds.
//! - One sample: the field is that sample's vector everywhere, exactly. Samples at one and
//!   the same target: their mean everywhere (Nadaraya–Watson).
//! - Far from every sample (or as h → 0) Nadaraya–Watson and local-linear with λ > 0 tend to
//!   the nearest sample's vector (its weight dominates, t̄ → its target, the spread in S
//!   vanishes against λ and so does the slope). Plain local-linear (λ = 0) is blind to the
//!   scale of the weights and keeps the slopes of whatever spread the weights still see.
//!   As h → ∞ Nadaraya–Watson tends to the mean of all samples.
//! - Deterministic: no randomness; the same samples and settings give the same field, bit for
//!   bit, on any thread count.
//!
//! # Bandwidth
//!
//! [`Bandwidth::Fixed`] gives h in meters. [`Bandwidth::Auto`] takes d, the median over the
//! targets of the distance to the nearest *other* (distinct) target, tries h = f·d for every f
//! of [`AUTO_FACTORS`] (½ to 8, steps of √2) and keeps the h of smallest leave-one-out error in
//! parameter space: each sample predicted by the field of the others with that h, the error
//! per entry divided by the entry's bound width (entries of zero width are skipped), the root
//! mean square over entries and samples ([`BandwidthScore`]). Exact ties go to the larger h
//! (the smoother field). With fewer than two distinct targets there is no scale and nothing to
//! choose from (the field is constant): h = [`FALLBACK_BANDWIDTH`].
//!
//! # Anchored to the person's vector
//!
//! A person's single vector v, fitted on all their reaches at once, is the best one vector
//! for them; the per-reach fits p_k scatter around it, by the target and by the noise of
//! single-take fits. [`ParamField::anchored`] keeps v as the field's level and lets the
//! kernel regression add only how the reaches *vary* with the target:
//!
//! p(t) = v + (p̂(t) − p̄),
//!
//! p̂ the regression above and p̄ the plain mean of the p_k (its h → ∞ limit), clamped into
//! the bounds. [`Bandwidth::Auto`] then also tries h = ∞ (a flat field, scored by predicting
//! each p_k by the mean of the others) and prefers it on ties: where the reaches show no
//! dependence on the target, the anchored field *is* the person's vector, exactly; where they
//! do, it follows the dependence. A field file chooses an anchored field's bandwidth by what
//! matters, the motion ([`FieldFile::anchored`]): each reach synthesized with the
//! field of the others at its target, the candidate of the smallest mean distance kept
//! (ties to the larger h, h = ∞ the largest).
//!
//! # Leave one target out
//!
//! [`leave_one_out`] fits, for each reach k, the field of all the other reaches (its automatic
//! bandwidth included), evaluates it at t_k and lets the caller synthesize reach k with those
//! parameters and measure its distance, which is then reported next to reach k's own fit.
//!
//! ```
//! use kinergy_motion::nalgebra::Point3;
//! use kinergy_solver::{Bounds, Model, ParamSpace};
//! use kinergy_train::field::{FieldSettings, ParamField};
//!
//! let space = ParamSpace::new(Model::Sa, &["elbow".to_string()], Bounds::default()).unwrap();
//! let samples = vec![
//!     (Point3::new(0.3, 0.0, 1.0), vec![1.0]),
//!     (Point3::new(0.5, 0.0, 1.0), vec![2.0]),
//! ];
//! let field = ParamField::fit(&space, &samples, &FieldSettings::default()).unwrap();
//! let g = field.evaluate(&Point3::new(0.4, 0.0, 1.0))[0];
//! assert!((g - 1.5).abs() < 1e-12); // halfway: equal weights
//! ```

use kinergy_motion::nalgebra::{Matrix3, Point3, Vector3};
use kinergy_solver::ParamSpace;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{Result, TrainError, require};

mod file;

pub use file::{FIELD_FORMAT_VERSION, FieldFile};

/// The factors of the median nearest-neighbour distance that [`Bandwidth::Auto`] tries:
/// 2^(i/2) for i = −2…6, i.e. ½ … 8 in steps of √2. The floor is ½ because below about half
/// the spacing a sample's kernel hardly reaches its neighbours and the field turns into
/// nearest-neighbour steps — which leave-one-out cannot see on a regular layout, where each
/// left-out sample is predicted from symmetric neighbours (exact for a linear field): on a
/// 0.1 m grid with a linear field it picked ¼ (held-out error 2.2% of the bound width, against
/// 0.2% at ½). The top, 8, lets sparse or clustered targets be bridged and a field that does
/// not depend on the target tend to the mean.
pub const AUTO_FACTORS: [f64; 9] = [
    0.5,
    std::f64::consts::FRAC_1_SQRT_2,
    1.0,
    std::f64::consts::SQRT_2,
    2.0,
    2.0 * std::f64::consts::SQRT_2,
    4.0,
    4.0 * std::f64::consts::SQRT_2,
    8.0,
];

/// The bandwidth (meters) [`Bandwidth::Auto`] takes when the targets give no scale (one
/// sample, or every target the same): the field is then constant and h does not matter.
pub const FALLBACK_BANDWIDTH: f64 = 0.1;

/// The ridge λ of [`Regression::local_linear`].
pub const DEFAULT_RIDGE: f64 = 0.01;

/// Eigenvalues of the local-linear slope matrix below this fraction of the largest count as
/// zero (no slope along their direction).
const MIN_EIGENVALUE_RATIO: f64 = 1e-12;

/// The kernel's width.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Bandwidth {
    /// h in meters (finite, > 0).
    Fixed(f64),
    /// Chosen among [`AUTO_FACTORS`] × the median nearest-neighbour distance by
    /// leave-one-out error in parameter space (see the [module docs](self)).
    Auto,
}

/// The local model fitted around each evaluated target.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Regression {
    /// Local-constant: the kernel-weighted mean of the fitted vectors (within their range).
    NadarayaWatson,
    /// Local-linear with a ridge λ ≥ 0 on the slopes, clamped into the bounds.
    LocalLinear {
        /// λ (finite, ≥ 0), relative to the total weight, slopes per bandwidth.
        ridge: f64,
    },
}

impl Regression {
    /// Local-linear with λ = [`DEFAULT_RIDGE`].
    pub fn local_linear() -> Regression {
        Regression::LocalLinear {
            ridge: DEFAULT_RIDGE,
        }
    }
}

/// How a [`ParamField`] is fitted.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldSettings {
    /// The kernel's width.
    pub bandwidth: Bandwidth,
    /// The local model.
    pub regression: Regression,
}

impl Default for FieldSettings {
    /// Automatic bandwidth, Nadaraya–Watson.
    fn default() -> FieldSettings {
        FieldSettings {
            bandwidth: Bandwidth::Auto,
            regression: Regression::NadarayaWatson,
        }
    }
}

impl FieldSettings {
    /// Checks every setting, naming the field otherwise.
    pub fn validate(&self) -> Result<()> {
        if let Bandwidth::Fixed(h) = self.bandwidth {
            require(
                h > 0.0 && h.is_finite(),
                "field.bandwidth",
                format!("a finite number of meters > 0, not {h}"),
            )?;
        }
        if let Regression::LocalLinear { ridge } = self.regression {
            require(
                ridge >= 0.0 && ridge.is_finite(),
                "field.ridge",
                format!("a finite number ≥ 0, not {ridge}"),
            )?;
        }
        Ok(())
    }
}

/// The leave-one-out error of one candidate bandwidth ([`Bandwidth::Auto`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BandwidthScore {
    /// h, meters; ∞ (`null` in JSON) for the flat field of an anchored one.
    #[serde(with = "infinite_as_null")]
    pub bandwidth: f64,
    /// Root mean square over samples and entries of the leave-one-out prediction error, each
    /// entry divided by its bound width.
    pub loo_error: f64,
    /// For an anchored field chosen by motion ([`FieldFile::anchored`]): the mean
    /// over the samples' reaches of their motion distance synthesized with the field of the
    /// others at their targets, meters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loo_distance_m: Option<f64>,
}

/// Parameters as a smooth function of the target, learned from per-clip fits (see the
/// [module docs](self) for the method and its properties).
#[derive(Debug, Clone, PartialEq)]
pub struct ParamField {
    space: ParamSpace,
    lower: Vec<f64>,
    upper: Vec<f64>,
    targets: Vec<Point3<f64>>,
    values: Vec<Vec<f64>>,
    settings: FieldSettings,
    bandwidth: f64,
    selection: Vec<BandwidthScore>,
    /// The person's single vector the field is anchored to ([`ParamField::anchored`]).
    anchor: Option<Vec<f64>>,
}

impl ParamField {
    /// Fits the field of `samples` — (target in meters, fitted vector of `space`) — with
    /// `settings`. Errors name the offending field: `field.bandwidth`, `field.ridge`,
    /// `samples` (none given), `samples[k].target` (not finite), `samples[k].params` (wrong
    /// length or out of bounds; the message names the parameter).
    pub fn fit(
        space: &ParamSpace,
        samples: &[(Point3<f64>, Vec<f64>)],
        settings: &FieldSettings,
    ) -> Result<ParamField> {
        check_inputs(space, samples, settings)?;
        let (targets, values) = samples.iter().cloned().unzip();
        Ok(ParamField::build(
            space.clone(),
            targets,
            values,
            *settings,
            None,
        ))
    }

    /// The same samples anchored to `vector`, the person's single vector (see the
    /// [module docs](self#anchored-to-the-persons-vector)); an automatic bandwidth is chosen
    /// again, h = ∞ among the candidates. Errors name `anchor` (wrong length, out of bounds).
    pub fn anchored(&self, vector: Vec<f64>) -> Result<ParamField> {
        self.space
            .validate(&vector)
            .map_err(|e| TrainError::Setting {
                field: "anchor".into(),
                why: e.to_string(),
            })?;
        Ok(ParamField::build(
            self.space.clone(),
            self.targets.clone(),
            self.values.clone(),
            self.settings,
            Some(vector),
        ))
    }

    /// Fits without checks (the inputs are known valid).
    fn build(
        space: ParamSpace,
        targets: Vec<Point3<f64>>,
        values: Vec<Vec<f64>>,
        settings: FieldSettings,
        anchor: Option<Vec<f64>>,
    ) -> ParamField {
        let lower = space.lower();
        let upper = space.upper();
        let (bandwidth, selection) = match settings.bandwidth {
            Bandwidth::Fixed(h) => (h, Vec::new()),
            Bandwidth::Auto => {
                let data = Data {
                    targets: &targets,
                    values: &values,
                    lower: &lower,
                    upper: &upper,
                };
                data.select(settings.regression, anchor.is_some())
            }
        };
        ParamField::stored(
            space, targets, values, settings, bandwidth, selection, anchor,
        )
    }

    /// A field read back from a file: everything as stored, nothing chosen again.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn stored(
        space: ParamSpace,
        targets: Vec<Point3<f64>>,
        values: Vec<Vec<f64>>,
        settings: FieldSettings,
        bandwidth: f64,
        selection: Vec<BandwidthScore>,
        anchor: Option<Vec<f64>>,
    ) -> ParamField {
        ParamField {
            lower: space.lower(),
            upper: space.upper(),
            space,
            targets,
            values,
            settings,
            bandwidth,
            selection,
            anchor,
        }
    }

    /// The field of all samples but sample `k`, fitted with the same settings (an automatic
    /// bandwidth is chosen again, from the remaining samples only) and the same anchor. Needs
    /// ≥ 2 samples.
    pub fn without(&self, k: usize) -> Result<ParamField> {
        require(
            self.targets.len() >= 2,
            "samples",
            "at least two samples to leave one out",
        )?;
        require(
            k < self.targets.len(),
            "k",
            format!("a sample index below {}", self.targets.len()),
        )?;
        let mut targets = self.targets.clone();
        let mut values = self.values.clone();
        targets.remove(k);
        values.remove(k);
        Ok(ParamField::build(
            self.space.clone(),
            targets,
            values,
            self.settings,
            self.anchor.clone(),
        ))
    }

    /// The field of all samples but sample `k` with bandwidth `h` (∞: flat) and the same
    /// anchor, nothing chosen. Needs ≥ 2 samples and `k` in range (callers check).
    pub(crate) fn without_at(&self, k: usize, h: f64) -> ParamField {
        let mut targets = self.targets.clone();
        let mut values = self.values.clone();
        targets.remove(k);
        values.remove(k);
        let settings = FieldSettings {
            bandwidth: Bandwidth::Fixed(h),
            ..self.settings
        };
        ParamField::build(
            self.space.clone(),
            targets,
            values,
            settings,
            self.anchor.clone(),
        )
    }

    /// The same field with bandwidth `h` in use, chosen among `selection`.
    pub(crate) fn with_bandwidth(&self, h: f64, selection: Vec<BandwidthScore>) -> ParamField {
        ParamField {
            bandwidth: h,
            selection,
            ..self.clone()
        }
    }

    /// The parameters at `target`, always within the bounds (see the [module docs](self)).
    /// A non-finite target carries no position: it gets the mean of the samples' vectors
    /// (use [`ParamField::try_evaluate`] to have it refused instead).
    pub fn evaluate(&self, target: &Point3<f64>) -> Vec<f64> {
        let data = self.data();
        let p = data.predict(self.bandwidth, self.settings.regression, target, None);
        let Some(anchor) = &self.anchor else {
            return p;
        };
        // p̄, the h → ∞ limit, computed as p is (for h = ∞ the two agree bit for bit and the
        // field is the anchor exactly).
        let mean = data.predict(
            f64::INFINITY,
            Regression::NadarayaWatson,
            &Point3::origin(),
            None,
        );
        (0..anchor.len())
            .map(|i| (anchor[i] + (p[i] - mean[i])).clamp(self.lower[i], self.upper[i]))
            .collect()
    }

    /// The person's single vector the field is anchored to, if it is.
    pub fn anchor(&self) -> Option<&[f64]> {
        self.anchor.as_deref()
    }

    /// [`ParamField::evaluate`], refusing a target that is not finite (`target`).
    pub fn try_evaluate(&self, target: &Point3<f64>) -> Result<Vec<f64>> {
        require(
            target.iter().all(|c| c.is_finite()),
            "target",
            "finite coordinates",
        )?;
        Ok(self.evaluate(target))
    }

    /// The bandwidth h in use, meters (the chosen one for [`Bandwidth::Auto`]; ∞ for an
    /// anchored field that is flat).
    pub fn bandwidth(&self) -> f64 {
        self.bandwidth
    }

    /// The candidates [`Bandwidth::Auto`] tried with their errors, smallest h first (empty
    /// for a fixed bandwidth or when there was no scale to choose from).
    pub fn selection(&self) -> &[BandwidthScore] {
        &self.selection
    }

    /// The settings it was fitted with.
    pub fn settings(&self) -> &FieldSettings {
        &self.settings
    }

    /// The parameter space.
    pub fn space(&self) -> &ParamSpace {
        &self.space
    }

    /// The samples' targets, meters.
    pub fn targets(&self) -> &[Point3<f64>] {
        &self.targets
    }

    /// The samples' fitted vectors, in the order of the targets.
    pub fn values(&self) -> &[Vec<f64>] {
        &self.values
    }

    /// The number of samples.
    pub fn len(&self) -> usize {
        self.targets.len()
    }

    /// Always false: a field has at least one sample.
    pub fn is_empty(&self) -> bool {
        self.targets.is_empty()
    }

    fn data(&self) -> Data<'_> {
        Data {
            targets: &self.targets,
            values: &self.values,
            lower: &self.lower,
            upper: &self.upper,
        }
    }
}

/// Serializes f64::INFINITY as `null` (JSON has no infinity) and reads `null` back as it.
pub(crate) mod infinite_as_null {
    use serde::{Deserialize, Deserializer, Serializer};

    /// `null` for +∞, the number otherwise.
    pub fn serialize<S: Serializer>(v: &f64, s: S) -> std::result::Result<S::Ok, S::Error> {
        if *v == f64::INFINITY {
            s.serialize_none()
        } else {
            s.serialize_f64(*v)
        }
    }

    /// +∞ for `null`.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
        Ok(Option::<f64>::deserialize(d)?.unwrap_or(f64::INFINITY))
    }
}

/// One row of [`leave_one_out`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LooRow {
    /// The sample (reach) left out and scored.
    pub index: usize,
    /// Its target, meters.
    pub target: [f64; 3],
    /// The bandwidth of the field of the other samples, meters.
    pub bandwidth: f64,
    /// That field's parameters at the target.
    pub field_params: Vec<f64>,
    /// The caller's score (the reach's motion distance) with those parameters.
    pub field_distance: f64,
}

/// Leave-one-target-out evaluation: for each sample k, the field of the other samples (its
/// automatic bandwidth included, chosen without sample k) evaluated at t_k, and
/// `score(k, params)` — the caller synthesizes reach k with `params` and returns its
/// distance, reported as given. Needs ≥ 2 samples (validated as in [`ParamField::fit`]).
/// Rows run in parallel and come back in sample order; if scores fail, the error of the
/// lowest k is returned.
pub fn leave_one_out<F>(
    space: &ParamSpace,
    samples: &[(Point3<f64>, Vec<f64>)],
    settings: &FieldSettings,
    score: F,
) -> Result<Vec<LooRow>>
where
    F: Fn(usize, &[f64]) -> Result<f64> + Sync,
{
    check_inputs(space, samples, settings)?;
    require(
        samples.len() >= 2,
        "samples",
        "at least two samples to leave one out",
    )?;
    let rows: Vec<Result<LooRow>> = (0..samples.len())
        .into_par_iter()
        .map(|k| {
            let (targets, values) = samples
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != k)
                .map(|(_, s)| s.clone())
                .unzip();
            let field = ParamField::build(space.clone(), targets, values, *settings, None);
            let target = samples[k].0;
            let field_params = field.evaluate(&target);
            let field_distance = score(k, &field_params)?;
            Ok(LooRow {
                index: k,
                target: [target.x, target.y, target.z],
                bandwidth: field.bandwidth(),
                field_params,
                field_distance,
            })
        })
        .collect();
    rows.into_iter().collect()
}

fn check_inputs(
    space: &ParamSpace,
    samples: &[(Point3<f64>, Vec<f64>)],
    settings: &FieldSettings,
) -> Result<()> {
    settings.validate()?;
    require(
        !samples.is_empty(),
        "samples",
        "at least one (target, parameters) sample",
    )?;
    for (k, (t, p)) in samples.iter().enumerate() {
        check_sample(space, k, t, p)?;
    }
    Ok(())
}

fn check_sample(space: &ParamSpace, k: usize, target: &Point3<f64>, params: &[f64]) -> Result<()> {
    require(
        target.iter().all(|c| c.is_finite()),
        &format!("samples[{k}].target"),
        format!(
            "finite coordinates, not ({}, {}, {})",
            target.x, target.y, target.z
        ),
    )?;
    space.validate(params).map_err(|e| TrainError::Setting {
        field: format!("samples[{k}].params"),
        why: e.to_string(),
    })
}

/// The samples and bounds the regression works on.
struct Data<'a> {
    targets: &'a [Point3<f64>],
    values: &'a [Vec<f64>],
    lower: &'a [f64],
    upper: &'a [f64],
}

impl Data<'_> {
    /// The value at `at` from every sample but `skip`.
    fn predict(
        &self,
        h: f64,
        regression: Regression,
        at: &Point3<f64>,
        skip: Option<usize>,
    ) -> Vec<f64> {
        let used: Vec<usize> = (0..self.targets.len())
            .filter(|&k| Some(k) != skip)
            .collect();
        if used.len() == 1 {
            return self.values[used[0]].clone();
        }
        if !at.iter().all(|c| c.is_finite()) {
            let w = vec![1.0; used.len()];
            return self.weighted_mean(&used, &w);
        }
        let w = self.weights(h, at, &used);
        let nw = self.weighted_mean(&used, &w);
        match regression {
            Regression::NadarayaWatson => nw,
            Regression::LocalLinear { ridge } => self.local_linear(h, ridge, at, &used, &w, nw),
        }
    }

    /// Kernel weights of the `used` samples, the largest exactly 1.
    fn weights(&self, h: f64, at: &Point3<f64>, used: &[usize]) -> Vec<f64> {
        let logs: Vec<f64> = used
            .iter()
            .map(|&k| {
                let r = (at - self.targets[k]).norm() / h;
                -0.5 * r * r
            })
            .collect();
        let max = logs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if max.is_finite() {
            return logs.iter().map(|l| (l - max).exp()).collect();
        }
        // Every distance overflowed: the nearest sample, compared at a scale that cannot.
        let scale = used
            .iter()
            .map(|&k| (at - self.targets[k]).amax())
            .fold(0.0, f64::max);
        let scaled: Vec<f64> = used
            .iter()
            .map(|&k| ((at - self.targets[k]) / scale).norm_squared())
            .collect();
        let nearest = (0..used.len())
            .min_by(|&a, &b| scaled[a].total_cmp(&scaled[b]))
            .unwrap_or(0);
        (0..used.len())
            .map(|i| if i == nearest { 1.0 } else { 0.0 })
            .collect()
    }

    /// Σ w_k p_k / Σ w_k, clamped to the range of the `used` samples' values.
    fn weighted_mean(&self, used: &[usize], w: &[f64]) -> Vec<f64> {
        let dim = self.lower.len();
        let total: f64 = w.iter().sum();
        (0..dim)
            .map(|i| {
                let mut sum = 0.0;
                let mut lo = f64::INFINITY;
                let mut hi = f64::NEG_INFINITY;
                for (&k, &wk) in used.iter().zip(w) {
                    let v = self.values[k][i];
                    sum += wk * v;
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
                (sum / total).clamp(lo, hi)
            })
            .collect()
    }

    /// The local-linear value: `nw` (the weighted mean, also the weighted mean of the plane
    /// fitted around the weighted mean target t̄) carried along the ridge-regularized slopes
    /// from t̄ to `at`, clamped into the bounds.
    fn local_linear(
        &self,
        h: f64,
        ridge: f64,
        at: &Point3<f64>,
        used: &[usize],
        w: &[f64],
        nw: Vec<f64>,
    ) -> Vec<f64> {
        let total: f64 = w.iter().sum();
        // Only the samples that carry weight (far ones may have underflowed to exactly 0).
        let kept: Vec<(usize, f64)> = used
            .iter()
            .zip(w)
            .filter(|&(_, &wk)| wk > 0.0)
            .map(|(&k, &wk)| (k, wk / total))
            .collect();
        let mean = kept.iter().fold(Vector3::zeros(), |acc, &(k, wk)| {
            acc + wk * self.targets[k].coords
        });
        let v = |k: usize| (self.targets[k].coords - mean) / h;
        // S = Σ ŵ v vᵀ + λI, inverted on its numerically nonzero eigenvalues: with λ = 0 and
        // targets on a plane or a line, no slope across them (the λ → 0 limit).
        let mut s = Matrix3::<f64>::identity() * ridge;
        for &(k, wk) in &kept {
            let vk = v(k);
            s += wk * vk * vk.transpose();
        }
        let eigen = s.symmetric_eigen();
        let largest = eigen.eigenvalues.amax();
        let inverse_values = eigen.eigenvalues.map(|e| {
            if largest > 0.0 && e > MIN_EIGENVALUE_RATIO * largest {
                1.0 / e
            } else {
                0.0
            }
        });
        let s_plus = eigen.eigenvectors
            * Matrix3::from_diagonal(&inverse_values)
            * eigen.eigenvectors.transpose();
        // p_i(at) = nw_i + b_iᵀ (at − t̄)/h with b_i = S⁺ Σ ŵ_k v_k (p_k,i − nw_i);
        // equivalently, the direction d = S⁺ (at − t̄)/h and p_i = nw_i + Σ ŵ_k (d·v_k)(p_k,i − nw_i).
        let d = s_plus * ((at.coords - mean) / h);
        let mut out = nw.clone();
        for &(k, wk) in &kept {
            let c = wk * d.dot(&v(k));
            for ((o, p), n) in out.iter_mut().zip(&self.values[k]).zip(&nw) {
                *o += c * (p - n);
            }
        }
        if !out.iter().all(|x| x.is_finite()) {
            return nw;
        }
        for ((o, lo), hi) in out.iter_mut().zip(self.lower).zip(self.upper) {
            *o = o.clamp(*lo, *hi);
        }
        out
    }

    /// The median distance from each target to its nearest distinct target; `None` when no
    /// two targets differ.
    fn median_nearest_distance(&self) -> Option<f64> {
        let mut nearest: Vec<f64> = self
            .targets
            .iter()
            .filter_map(|a| {
                self.targets
                    .iter()
                    .map(|b| (a - b).norm())
                    .filter(|&d| d > 0.0)
                    .min_by(f64::total_cmp)
            })
            .collect();
        if nearest.is_empty() {
            return None;
        }
        nearest.sort_by(f64::total_cmp);
        let n = nearest.len();
        Some(if n % 2 == 1 {
            nearest[n / 2]
        } else {
            0.5 * (nearest[n / 2 - 1] + nearest[n / 2])
        })
    }

    /// Root mean square leave-one-out error with bandwidth `h`, per entry relative to its
    /// bound width.
    fn loo_error(&self, h: f64, regression: Regression) -> f64 {
        let widths: Vec<f64> = self
            .lower
            .iter()
            .zip(self.upper)
            .map(|(lo, hi)| hi - lo)
            .collect();
        let mut sum = 0.0;
        let mut count = 0usize;
        for (j, (t, p)) in self.targets.iter().zip(self.values).enumerate() {
            let pred = self.predict(h, regression, t, Some(j));
            for ((q, v), wd) in pred.iter().zip(p).zip(&widths) {
                if *wd > 0.0 {
                    let e = (q - v) / wd;
                    sum += e * e;
                    count += 1;
                }
            }
        }
        if count == 0 {
            0.0
        } else {
            (sum / count as f64).sqrt()
        }
    }

    /// [`Bandwidth::Auto`]: the chosen h and every candidate's score; with `flat`, h = ∞ is
    /// a candidate too (an anchored field).
    fn select(&self, regression: Regression, flat: bool) -> (f64, Vec<BandwidthScore>) {
        let Some(d) = self.median_nearest_distance() else {
            return (FALLBACK_BANDWIDTH, Vec::new());
        };
        let mut scores: Vec<BandwidthScore> = AUTO_FACTORS
            .par_iter()
            .map(|f| {
                let bandwidth = f * d;
                BandwidthScore {
                    bandwidth,
                    loo_error: self.loo_error(bandwidth, regression),
                    loo_distance_m: None,
                }
            })
            .collect();
        if flat {
            scores.push(BandwidthScore {
                bandwidth: f64::INFINITY,
                loo_error: self.loo_error(f64::INFINITY, regression),
                loo_distance_m: None,
            });
        }
        // Largest h first, strict improvement only: ties go to the smoother field.
        let best = scores
            .iter()
            .rev()
            .fold(None::<&BandwidthScore>, |best, s| match best {
                Some(b) if b.loo_error.total_cmp(&s.loo_error).is_le() => Some(b),
                _ => Some(s),
            })
            .map_or(FALLBACK_BANDWIDTH, |s| s.bandwidth);
        (best, scores)
    }
}
