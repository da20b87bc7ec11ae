//! The leg controller's decisions and paths (Huang, Kapadia & Terzopoulos §3.5 and
//! State 0 of §4; DESIGN §1.2): whether to step, a half or a full step, which foot, how
//! long a step, and the paths of the foot and of the spine root.
//!
//! With d = √(d_x² + d_z²) the horizontal distance from the reaching arm's shoulder to the
//! target ([`horizontal_distance`]), d_c the radius of the convenient reaching range
//! (CRR) and d_max that of the maximum reaching range (MRR), both vertical cylinders
//! around the shoulder, and x = (d − d_c) / (d_max − d_c):
//!
//! | where the target is | P(step) | P(half step \| step) | step length (eq. 9) |
//! |---|---|---|---|
//! | inside the CRR, d ≤ d_c | 0 | — | l_min |
//! | between, d_c < d < d_max | x | P_max + (P_min − P_max) x | between l_min and l_max |
//! | outside the MRR, d ≥ d_max | 1 | P_min | l_max |
//!
//! The paper writes the step probability as P(x) without saying what P is; we take the
//! linear P(x) = x (DESIGN §1.2), so the probability rises from 0 at the CRR to 1 at the
//! MRR and is continuous at both. The paper defines P_half on d_c < d < d_max only; beyond
//! the MRR we keep its end value P_min.
//!
//! The step goes along d_p, the target direction projected on the ground
//! ([`step_direction`], the paper's Fig. 2(c)). In a half step one foot moves and the other
//! stays; in a full step the first foot lands, then the other follows to the same spot
//! while the root keeps moving. [`foot_path`] and [`root_path`] are the paper's "convex
//! arc" of the foot and "concave arc" of the root, simplified to piecewise linear paths.
//!
//! ```
//! use kinergy_motion::Side;
//! use kinergy_reach::steps::{self, StepDecision, StepSettings};
//! use nalgebra::Point3;
//! use rand::SeedableRng;
//! use rand::rngs::ChaCha8Rng;
//!
//! let settings = StepSettings::for_arm_length(0.7).unwrap();
//! let shoulder = Point3::new(-0.18, 1.45, 0.0);
//! let target = Point3::new(-0.18, 1.0, 1.2); // 1.2 m ahead: beyond the MRR (0.91 m)
//! let d = steps::horizontal_distance(&shoulder, &target);
//! let mut rng = ChaCha8Rng::seed_from_u64(7);
//! let decision = steps::decide(&settings, d, Side::Right, &mut rng);
//! assert_ne!(decision, StepDecision::NoStep);
//! let p = steps::draw_p(&settings, &mut rng);
//! assert_eq!(steps::step_length(&settings, d, p), settings.l_max);
//! ```

use std::fmt;

use kinergy_io::InvalidSetting;
use kinergy_motion::Side;
use nalgebra::{Point3, Unit, Vector3};
use rand::{Rng, RngExt};
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use crate::error::Result;

/// The paper's default step length, m (§3.5: "an empirically selected default value of
/// 0.433 m"). Our default l_min and l_max are centred on it, so eq. 9 gives exactly this
/// at the middle of the CRR–MRR band with the mean p = ½.
pub const PAPER_STEP_LENGTH: f64 = 0.433;
/// Default CRR radius d_c per meter of arm length (shoulder to hand). Ours: the paper
/// gives no value.
pub const CRR_PER_ARM_LENGTH: f64 = 0.8;
/// Default MRR radius d_max per meter of arm length. Ours: the paper gives no value; a
/// standing adult reaches about 0.2–0.3 m beyond arm's length by leaning (the functional
/// reach test).
pub const MRR_PER_ARM_LENGTH: f64 = 1.3;
/// The arm length [`StepSettings::default`] is made for, m: shoulder to hand of a 1.75 m
/// adult (≈ 0.40 of the height, Drillis & Contini).
pub const REFERENCE_ARM_LENGTH: f64 = 0.70;

/// What the stepping decision state machine (§3.5) chose.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum StepDecision {
    /// Reach without stepping.
    NoStep,
    /// One foot steps, the other stays where it is.
    HalfStep {
        /// The foot that steps.
        foot: Side,
    },
    /// Both feet step: the first lands, then the other follows it.
    FullStep,
}

impl StepDecision {
    /// Whether the character steps at all.
    pub fn steps(self) -> bool {
        self != StepDecision::NoStep
    }

    /// Its name in reports: `none`, `half_left`, `half_right` or `full`.
    pub fn name(self) -> &'static str {
        match self {
            StepDecision::NoStep => "none",
            StepDecision::HalfStep { foot: Side::Left } => "half_left",
            StepDecision::HalfStep { foot: Side::Right } => "half_right",
            StepDecision::FullStep => "full",
        }
    }
}

impl fmt::Display for StepDecision {
    /// Its [name](StepDecision::name).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Serializes a step decision by its [name](StepDecision::name) (`none`, `half_left` …),
/// as reports and manifests show it: `#[serde(serialize_with = "steps::serialize_name")]`.
/// (The decision's own form, `{"kind": "half_step", "foot": "right"}`, reads back.)
pub fn serialize_name<S: serde::Serializer>(
    step: &StepDecision,
    serializer: S,
) -> std::result::Result<S::Ok, S::Error> {
    serializer.serialize_str(step.name())
}

impl PartialEq<&str> for StepDecision {
    /// Whether `name` is its [name](StepDecision::name).
    fn eq(&self, name: &&str) -> bool {
        self.name() == *name
    }
}

/// The leg controller's parameters (§3.5). Lengths in meters.
///
/// The paper names d_c, d_max, P_max, P_min, l_min, l_max and the normal random p but
/// gives a value only for the default step length (0.433 m, [`PAPER_STEP_LENGTH`]); every
/// other default here is ours and says so.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepSettings {
    /// d_c: radius of the convenient reaching range (CRR), the vertical cylinder around
    /// the reaching shoulder inside which the character never steps. Default
    /// [`CRR_PER_ARM_LENGTH`] × [`REFERENCE_ARM_LENGTH`] = 0.56 m.
    pub d_c: f64,
    /// d_max: radius of the maximum reaching range (MRR), outside which the character
    /// always steps; > d_c. Default [`MRR_PER_ARM_LENGTH`] × [`REFERENCE_ARM_LENGTH`] =
    /// 0.91 m.
    pub d_max: f64,
    /// P_max: probability of a half step (given a step) at d = d_c. Default 0.9 (ours).
    pub p_max: f64,
    /// P_min: probability of a half step (given a step) at d = d_max and beyond; ≤ P_max.
    /// Default 0.1 (ours).
    pub p_min: f64,
    /// l_min: the step length at d ≤ d_c (eq. 9). Default 0.233 m (ours: the paper's
    /// 0.433 m − 0.2 m).
    pub l_min: f64,
    /// l_max: the step length at d ≥ d_max (eq. 9); ≥ l_min. Default 0.633 m (ours: the
    /// paper's 0.433 m + 0.2 m).
    pub l_max: f64,
    /// Mean of the normal random p of eq. 9. Default ½: at p = ½ eq. 9 is the linear
    /// interpolation between l_min and l_max in d.
    pub p_mean: f64,
    /// Standard deviation of p. Default 1/6, so that [0, 1] is mean ± 3σ and the clamp
    /// changes 0.27 % of the draws.
    pub p_std: f64,
    /// Peak height of the foot above its straight path ([`foot_path`]). Default 0.08 m
    /// (ours).
    pub foot_lift: f64,
    /// Deepest drop of the root below its straight path ([`root_path`]). Default 0.03 m
    /// (ours: about how much a 0.9 m leg's hip drops when the feet stand 0.433 m apart,
    /// 0.9 − √(0.9² − 0.2165²)).
    pub root_dip: f64,
}

impl Default for StepSettings {
    /// The settings for [`REFERENCE_ARM_LENGTH`].
    fn default() -> StepSettings {
        StepSettings {
            d_c: CRR_PER_ARM_LENGTH * REFERENCE_ARM_LENGTH,
            d_max: MRR_PER_ARM_LENGTH * REFERENCE_ARM_LENGTH,
            p_max: 0.9,
            p_min: 0.1,
            l_min: PAPER_STEP_LENGTH - 0.2,
            l_max: PAPER_STEP_LENGTH + 0.2,
            p_mean: 0.5,
            p_std: 1.0 / 6.0,
            foot_lift: 0.08,
            root_dip: 0.03,
        }
    }
}

impl StepSettings {
    /// The default settings with the reaching cylinders scaled to a person's arm length
    /// (shoulder to hand, m): d_c = [`CRR_PER_ARM_LENGTH`] × arm, d_max =
    /// [`MRR_PER_ARM_LENGTH`] × arm.
    pub fn for_arm_length(arm_length: f64) -> Result<StepSettings> {
        InvalidSetting::require(
            arm_length.is_finite() && arm_length > 0.0,
            "arm_length",
            "a positive length (m)",
        )?;
        let settings = StepSettings {
            d_c: CRR_PER_ARM_LENGTH * arm_length,
            d_max: MRR_PER_ARM_LENGTH * arm_length,
            ..StepSettings::default()
        };
        settings.validate()?;
        Ok(settings)
    }

    /// Checks every setting, naming the field (`steps.d_c`, `steps.p_min`, …) otherwise.
    pub fn validate(&self) -> Result<()> {
        let finite_non_negative = |v: f64| v.is_finite() && v >= 0.0;
        let probability = |v: f64| (0.0..=1.0).contains(&v);
        InvalidSetting::require(
            self.d_c.is_finite() && self.d_c > 0.0,
            "steps.d_c",
            "a positive CRR radius (m)",
        )?;
        InvalidSetting::require(
            self.d_max.is_finite() && self.d_max > self.d_c,
            "steps.d_max",
            format!("an MRR radius (m) greater than d_c = {}", self.d_c),
        )?;
        InvalidSetting::require(
            probability(self.p_max),
            "steps.p_max",
            "a probability in [0, 1]",
        )?;
        InvalidSetting::require(
            probability(self.p_min) && self.p_min <= self.p_max,
            "steps.p_min",
            format!("a probability in [0, p_max = {}]", self.p_max),
        )?;
        InvalidSetting::require(
            self.l_min.is_finite() && self.l_min > 0.0,
            "steps.l_min",
            "a positive step length (m)",
        )?;
        InvalidSetting::require(
            self.l_max.is_finite() && self.l_max >= self.l_min,
            "steps.l_max",
            format!("a step length (m) ≥ l_min = {}", self.l_min),
        )?;
        InvalidSetting::require(probability(self.p_mean), "steps.p_mean", "a mean in [0, 1]")?;
        InvalidSetting::require(
            finite_non_negative(self.p_std),
            "steps.p_std",
            "a finite standard deviation ≥ 0",
        )?;
        InvalidSetting::require(
            finite_non_negative(self.foot_lift),
            "steps.foot_lift",
            "a finite height ≥ 0 (m)",
        )?;
        InvalidSetting::require(
            finite_non_negative(self.root_dip),
            "steps.root_dip",
            "a finite depth ≥ 0 (m)",
        )?;
        Ok(())
    }

    /// x = (d − d_c) / (d_max − d_c), clamped to [0, 1]: where d lies in the CRR–MRR band.
    fn band(&self, d: f64) -> f64 {
        ((d - self.d_c) / (self.d_max - self.d_c)).clamp(0.0, 1.0)
    }
}

/// d = √(d_x² + d_z²), the horizontal (x–z, Y up) distance from the shoulder to the target
/// (§3.5): the distance from the axis of the reaching cylinders.
pub fn horizontal_distance(shoulder: &Point3<f64>, target: &Point3<f64>) -> f64 {
    (target.x - shoulder.x).hypot(target.z - shoulder.z)
}

/// d_p: the unit direction from the shoulder to the target projected on the ground (eq. 6
/// without the y part), the direction of the step (Fig. 2(c)). `None` when the target is
/// straight above or below the shoulder.
pub fn step_direction(shoulder: &Point3<f64>, target: &Point3<f64>) -> Option<Unit<Vector3<f64>>> {
    let d = target - shoulder;
    Unit::try_new(Vector3::new(d.x, 0.0, d.z), f64::EPSILON)
}

/// The side of the body the target is on: the sign of its offset from the sagittal plane
/// through `root` (the pelvis) with the character facing `facing` (Y up, so the
/// character's left is up × facing; facing +Z, left is +X). A target on the plane counts
/// as on the reaching arm's side.
pub fn target_side(
    root: &Point3<f64>,
    facing: &Vector3<f64>,
    target: &Point3<f64>,
    reaching_arm: Side,
) -> Side {
    let left = Vector3::y().cross(facing);
    let lateral = (target - root).dot(&left);
    if lateral > 0.0 {
        Side::Left
    } else if lateral < 0.0 {
        Side::Right
    } else {
        reaching_arm
    }
}

/// The probability of stepping at horizontal distance d (§3.5): 0 inside the CRR,
/// (d − d_c) / (d_max − d_c) between the cylinders, 1 outside the MRR; 0 for a NaN d.
pub fn step_probability(settings: &StepSettings, d: f64) -> f64 {
    if d.is_nan() || d <= settings.d_c {
        0.0
    } else if d >= settings.d_max {
        1.0
    } else {
        settings.band(d)
    }
}

/// P_half, the probability that a step is a half step (§3.5): P_max at d = d_c, falling
/// linearly to P_min at d = d_max, P_min beyond. P_full = 1 − P_half.
pub fn half_step_probability(settings: &StepSettings, d: f64) -> f64 {
    let x = settings.band(d);
    settings.p_max + (settings.p_min - settings.p_max) * x
}

/// The stepping decision state machine (§3.5; State 0 of §4) for a target at horizontal
/// distance `d` from the shoulder:
/// - inside the CRR (d ≤ d_c), and for a NaN d: no step;
/// - between the cylinders: a step with probability [`step_probability`];
/// - outside the MRR (d ≥ d_max): a step.
///
/// A step is a half step with probability [`half_step_probability`], else a full step.
/// A half step moves the foot on `target_side` (see [`target_side`]): the paper does not
/// say which foot; stepping with the foot on the target's side never crosses the legs.
///
/// Always draws exactly two uniform numbers from `rng` (step?, then half?), whatever the
/// outcome, so the draws after it do not depend on d.
pub fn decide<R: Rng + ?Sized>(
    settings: &StepSettings,
    d: f64,
    target_side: Side,
    rng: &mut R,
) -> StepDecision {
    let u_step: f64 = rng.random();
    let u_half: f64 = rng.random();
    if u_step >= step_probability(settings, d) {
        StepDecision::NoStep
    } else if u_half < half_step_probability(settings, d) {
        StepDecision::HalfStep { foot: target_side }
    } else {
        StepDecision::FullStep
    }
}

/// p for eq. 9: normal with mean [`StepSettings::p_mean`] and standard deviation
/// [`StepSettings::p_std`] (defaults ½ and 1/6), clamped to [0, 1].
pub fn draw_p<R: Rng + ?Sized>(settings: &StepSettings, rng: &mut R) -> f64 {
    let z: f64 = StandardNormal.sample(rng);
    (settings.p_mean + settings.p_std * z).clamp(0.0, 1.0)
}

/// The step length l of eq. 9 for a target at horizontal distance d and a random p:
///
/// l = l_min if d ≤ d_c;
/// l = (l_max |d − d_c| p + l_min |d − d_max| (1 − p)) / (|d − d_c| p + |d − d_max| (1 − p))
///   if d_c < d < d_max;
/// l = l_max if d ≥ d_max;
///
/// with d_c, d_max the CRR and MRR radii and l_min, l_max the settings' step lengths. The
/// middle case is the weighted mean (1 − λ) l_min + λ l_max with
/// λ = p |d − d_c| / (p |d − d_c| + (1 − p) |d − d_max|), which is how it is computed
/// (exact at λ = 0 and 1): p = ½ gives the linear interpolation in d, p → 1 pulls
/// towards l_max, p → 0 towards l_min.
///
/// p is clamped to [0, 1] first: the paper's "normally distributed" p can fall outside,
/// where the denominator can vanish or turn negative and l leaves [l_min, l_max]. Within
/// [0, 1] the denominator is positive strictly inside the band, and l ∈ [l_min, l_max].
pub fn step_length(settings: &StepSettings, d: f64, p: f64) -> f64 {
    let StepSettings {
        d_c,
        d_max,
        l_min,
        l_max,
        ..
    } = *settings;
    if d <= d_c {
        return l_min;
    }
    if d >= d_max {
        return l_max;
    }
    let p = p.clamp(0.0, 1.0);
    let toward_max = p * (d - d_c).abs();
    let toward_min = (1.0 - p) * (d - d_max).abs();
    let lambda = toward_max / (toward_max + toward_min);
    (1.0 - lambda) * l_min + lambda * l_max
}

/// The foot's path for path parameter s ∈ [0, 1] (clamped): the paper's convex arc
/// (§3.5, after Williams), piecewise linear. Along the chord from `from` to `to` at
/// parameter s, raised along +Y by `lift` × a(s), where a is the 4-segment polygon
/// inscribed in the parabola 4s(1 − s) — knots (0, 0), (¼, ¾), (½, 1), (¾, ¾), (1, 0).
/// The foot rises fastest just after lift-off, is highest (`lift` above the chord) at
/// s = ½ and comes down steepest just before landing; it is never below the chord, and is
/// exactly `from` at s = 0 and `to` at s = 1. The timing s(t) is the caller's.
pub fn foot_path(from: Point3<f64>, to: Point3<f64>, lift: f64, s: f64) -> Point3<f64> {
    arc_path(from, to, lift, s)
}

/// The spine root's path for s ∈ [0, 1] (clamped): the paper's concave arc (§3.5),
/// piecewise linear. The chord from `from` to `to` lowered along −Y by `dip` × a(s), the
/// same polygon as [`foot_path`]'s: the root sinks while the legs spread and rises again,
/// `dip` below the chord at s = ½, never above it, exactly `from` at s = 0 and `to` at
/// s = 1.
pub fn root_path(from: Point3<f64>, to: Point3<f64>, dip: f64, s: f64) -> Point3<f64> {
    arc_path(from, to, -dip, s)
}

/// The chord at s plus `height` × a(s) along +Y.
fn arc_path(from: Point3<f64>, to: Point3<f64>, height: f64, s: f64) -> Point3<f64> {
    let s = s.clamp(0.0, 1.0);
    // (1 − s) from + s to is exact at s = 0 and s = 1, and a(0) = a(1) = 0.
    let mut p = Point3::from(from.coords * (1.0 - s) + to.coords * s);
    p.y += height * arc_polygon(s);
    p
}

/// The polygon inscribed in 4s(1 − s) with knots at s = 0, ¼, ½, ¾, 1.
fn arc_polygon(s: f64) -> f64 {
    const KNOTS: [f64; 5] = [0.0, 0.75, 1.0, 0.75, 0.0];
    let u = s * 4.0;
    let i = (u.floor() as usize).min(3);
    let f = u - i as f64;
    KNOTS[i] * (1.0 - f) + KNOTS[i + 1] * f
}
