//! The limb's joint limits as read from its chain ([`LimbLimits`]), how far a configuration
//! lies outside them ([`Violation`], named by [`LimbDof`]), and the middle of a range that
//! angles from `atan2` are moved toward. `LimbIk::violation` (in `solver.rs`) applies them.

use std::fmt;

/// One joint motion of the limb, as named in limit reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LimbDof {
    /// Shoulder swing, configuration entries 0 and 1.
    ShoulderSwing,
    /// Shoulder twist, entry 2.
    ShoulderTwist,
    /// Elbow flexion, entry 3.
    ElbowFlexion,
    /// Elbow twist (pronation), entry 4.
    ElbowTwist,
    /// Wrist swing, entries 5 and 6.
    WristSwing,
}

impl LimbDof {
    /// All motions, proximal to distal.
    pub const ALL: [LimbDof; 5] = [
        LimbDof::ShoulderSwing,
        LimbDof::ShoulderTwist,
        LimbDof::ElbowFlexion,
        LimbDof::ElbowTwist,
        LimbDof::WristSwing,
    ];

    /// The index of its first entry in a configuration.
    pub fn first_index(self) -> usize {
        match self {
            LimbDof::ShoulderSwing => 0,
            LimbDof::ShoulderTwist => 2,
            LimbDof::ElbowFlexion => 3,
            LimbDof::ElbowTwist => 4,
            LimbDof::WristSwing => 5,
        }
    }

    /// A human-readable name, e.g. `"wrist swing"`.
    pub fn name(self) -> &'static str {
        match self {
            LimbDof::ShoulderSwing => "shoulder swing",
            LimbDof::ShoulderTwist => "shoulder twist",
            LimbDof::ElbowFlexion => "elbow flexion",
            LimbDof::ElbowTwist => "elbow twist",
            LimbDof::WristSwing => "wrist swing",
        }
    }
}

impl fmt::Display for LimbDof {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The limb's joint limits, radians, as read from the chain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimbLimits {
    /// Shoulder swing ellipse radii `(rx, ry)`: `(sx/rx)² + (sy/ry)² ≤ 1`.
    pub shoulder_swing: (f64, f64),
    /// Shoulder twist `(min, max)`.
    pub shoulder_twist: (f64, f64),
    /// Elbow flexion `(min, max)`.
    pub elbow_flexion: (f64, f64),
    /// Elbow twist `(min, max)`.
    pub elbow_twist: (f64, f64),
    /// Wrist swing ellipse radii `(rx, ry)`.
    pub wrist_swing: (f64, f64),
}

/// How far a configuration lies outside the limits.
///
/// A revolute DoF's excess is its distance to `[min, max]`; a swing's is the length by which
/// the swing vector overshoots the ellipse along its own direction, `|s| (1 − 1/√e)` with
/// `e = (sx/rx)² + (sy/ry)²` — both radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Violation {
    /// The DoF with the largest excess.
    pub dof: LimbDof,
    /// Its excess, radians.
    pub excess: f64,
    /// The sum of every DoF's excess, radians.
    pub total: f64,
}

/// Where angles from `atan2` are moved toward: the middle of the limits, or π inside a
/// one-sided infinite range.
pub(super) fn middle((min, max): (f64, f64)) -> f64 {
    match (min.is_finite(), max.is_finite()) {
        (true, true) => 0.5 * (min + max),
        (true, false) => min + std::f64::consts::PI,
        (false, true) => max - std::f64::consts::PI,
        (false, false) => 0.0,
    }
}

pub(super) fn revolute_excess(x: f64, (min, max): (f64, f64)) -> f64 {
    if (min..=max).contains(&x) {
        0.0
    } else if x < min {
        min - x
    } else if x > max {
        x - max
    } else {
        f64::INFINITY // NaN
    }
}

/// The same test as [`Chain::within_limits`], so both agree on every configuration.
///
/// [`Chain::within_limits`]: kinergy_motion::Chain::within_limits
pub(super) fn swing_excess(sx: f64, sy: f64, (rx, ry): (f64, f64)) -> f64 {
    let e = (sx / rx).powi(2) + (sy / ry).powi(2);
    if e <= 1.0 + 1e-12 {
        0.0
    } else if e.is_finite() {
        (sx * sx + sy * sy).sqrt() * (1.0 - 1.0 / e.sqrt())
    } else {
        f64::INFINITY
    }
}
