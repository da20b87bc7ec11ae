//! The limb's joint limits as read from its chain ([`LimbLimits`]), how far a configuration
//! lies outside them ([`Violation`], named by [`LimbDof`]), and the middle of a range that
//! angles from `atan2` are moved toward.

use std::fmt;

use super::solver::LimbIk;

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

fn revolute_excess(x: f64, (min, max): (f64, f64)) -> f64 {
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
fn swing_excess(sx: f64, sy: f64, (rx, ry): (f64, f64)) -> f64 {
    let e = (sx / rx).powi(2) + (sy / ry).powi(2);
    if e <= 1.0 + 1e-12 {
        0.0
    } else if e.is_finite() {
        (sx * sx + sy * sy).sqrt() * (1.0 - 1.0 / e.sqrt())
    } else {
        f64::INFINITY
    }
}

impl LimbIk {
    /// True when `q` is within the limits — the same test as [`Chain::within_limits`].
    ///
    /// [`Chain::within_limits`]: kinergy_motion::Chain::within_limits
    pub fn within_limits(&self, q: &[f64; 7]) -> bool {
        self.violation(q).is_none()
    }

    /// How far `q` lies outside the limits; `None` when within them.
    pub fn violation(&self, q: &[f64; 7]) -> Option<Violation> {
        let l = &self.limits;
        let excess = [
            swing_excess(q[0], q[1], l.shoulder_swing),
            revolute_excess(q[2], l.shoulder_twist),
            revolute_excess(q[3], l.elbow_flexion),
            revolute_excess(q[4], l.elbow_twist),
            swing_excess(q[5], q[6], l.wrist_swing),
        ];
        let total: f64 = excess.iter().sum();
        if total == 0.0 {
            return None;
        }
        let (i, &worst) = excess
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .expect("five entries");
        Some(Violation {
            dof: LimbDof::ALL[i],
            excess: worst,
            total,
        })
    }
}
