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
//!
//! [`ParamSpace`]: kinergy_solver::ParamSpace

mod file;
mod param_field;
mod person_fit;
mod regression;
mod settings;

pub use file::{FIELD_FORMAT_VERSION, FieldFile};
pub use param_field::{LooRow, ParamField, leave_one_out};
pub use person_fit::{FieldReport, FieldSample, check_one_arm, field_groups};
pub use settings::{
    AUTO_FACTORS, Bandwidth, BandwidthScore, DEFAULT_RIDGE, FALLBACK_BANDWIDTH, FieldSettings,
    Regression,
};
