//! How a field is fitted: the bandwidth, the regression, their defaults, and the score of
//! each candidate bandwidth.

use kinergy_io::InvalidSetting;
use serde::{Deserialize, Serialize};

use crate::error::Result;

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

/// The kernel's width.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Bandwidth {
    /// h in meters (finite, > 0).
    Fixed(f64),
    /// Chosen among [`AUTO_FACTORS`] × the median nearest-neighbour distance by
    /// leave-one-out error in parameter space (see the [module docs](super)).
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

/// How a [`ParamField`](super::ParamField) is fitted.
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
            InvalidSetting::require(
                h > 0.0 && h.is_finite(),
                "field.bandwidth",
                format!("a finite number of meters > 0, not {h}"),
            )?;
        }
        if let Regression::LocalLinear { ridge } = self.regression {
            InvalidSetting::require(
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
    /// For an anchored field chosen by motion ([`FieldFile::anchored`](super::FieldFile::anchored)): the mean
    /// over the samples' reaches of their motion distance synthesized with the field of the
    /// others at their targets, meters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub loo_distance_m: Option<f64>,
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
