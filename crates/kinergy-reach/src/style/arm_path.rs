//! The arm-path measure: how far an arm's posture over a reach is from another's, whatever the
//! bodies' sizes and where they stood.
//!
//! For one body reaching, with shoulder `s`, elbow `e`, wrist `w` and hand `h` (the point
//! beyond the wrist, where the skeleton has one) at world positions `p_j(t)` over the reach's
//! frames, `R` the rotation of the body's reach frame on the reach's first frame
//! ([`super::reach_frame`]: y up, z horizontal from the other shoulder to this one, x = y × z;
//! so where the person stood and which way they faced do not matter) and
//! `L = |e − s| + |w − e|` the arm's length (upper arm + forearm) on that frame:
//!
//! ```text
//! q_j(τ) = Rᵀ (p_j(τ) − p_s(τ)) / L,   j ∈ {e, w, h},   τ ∈ {0, 1/(N−1), …, 1}
//! ```
//!
//! where `p_j(τ)` interpolates the frames linearly at the fraction `τ` of the reach
//! (`N` = [`SAMPLES`]). The **arm-path distance** of two reaches A and B is the RMS over the
//! samples and the joints both have (the hand only where both have one) of
//! `|q_j^A(τ) − q_j^B(τ)|`:
//!
//! ```text
//! D(A, B) = sqrt( Σ_τ Σ_j |q_j^A(τ) − q_j^B(τ)|² / (N · |J|) )
//! ```
//!
//! a fraction of the arm's length (0.1: the joints are on average a tenth of an arm apart).
//! It is 0 for a reach against itself, unchanged by a rigid translation of either reach (the
//! positions are taken from the shoulder) or by a rigid rotation that turns the reach frame
//! with it, and symmetric. Positions are from the shoulder on every frame, but all in the
//! reach frame of the reach's start, so a trunk that leans or twists moves the arm's path.

use kinergy_motion::nalgebra::{Point3, Rotation3, Vector3};

use super::{SAMPLES, normalized};

/// One reach's arm path: elbow, wrist and hand from the shoulder, in the reach frame at the
/// reach's start, in arm lengths, at [`SAMPLES`] fractions of the reach (see the
/// [module docs](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct ArmPath {
    /// `[elbow, wrist, hand]` at each sample (the hand is the wrist where there is none).
    samples: Vec<[Vector3<f64>; 3]>,
    /// Whether the hand is a point of its own beyond the wrist.
    hand: bool,
}

impl ArmPath {
    /// The path of an arm whose `[shoulder, elbow, wrist, hand]` are at `frames` (world
    /// meters, one entry per frame of the reach, the hand `None` where the skeleton has no
    /// point beyond the wrist), `base` the rotation of the reach frame at the reach's start. `None` when there are no frames or the arm has no length on the first one.
    pub fn new(frames: &[[Option<Point3<f64>>; 4]], base: &Rotation3<f64>) -> Option<ArmPath> {
        let first = frames.first()?;
        let [s, e, w] = [first[0]?, first[1]?, first[2]?];
        let length = (e - s).norm() + (w - e).norm();
        if !(length.is_finite() && length > 0.0) {
            return None;
        }
        let hand = frames.iter().all(|f| f[3].is_some());
        // Each joint's coordinates over the frames, then each resampled.
        let mut series: Vec<Vec<f64>> = (0..9).map(|_| Vec::with_capacity(frames.len())).collect();
        for f in frames {
            let shoulder = f[0]?;
            for j in 0..3 {
                let at = if j == 2 && !hand { f[2] } else { f[j + 1] }?;
                let q = base.inverse() * (at - shoulder) / length;
                for (c, &v) in q.iter().enumerate() {
                    series[3 * j + c].push(v);
                }
            }
        }
        let resampled: Vec<Vec<f64>> = series.iter().map(|s| normalized(s)).collect();
        let samples = (0..SAMPLES)
            .map(|k| {
                let v = |j: usize| {
                    Vector3::new(
                        resampled[3 * j][k],
                        resampled[3 * j + 1][k],
                        resampled[3 * j + 2][k],
                    )
                };
                [v(0), v(1), v(2)]
            })
            .collect();
        Some(ArmPath { samples, hand })
    }

    /// Whether the hand is a point of its own beyond the wrist (else the wrist ends the arm).
    pub fn has_hand(&self) -> bool {
        self.hand
    }

    /// The `[elbow, wrist, hand]` positions at each of the [`SAMPLES`] fractions of the reach,
    /// from the shoulder in the reach frame, in arm lengths.
    pub fn samples(&self) -> &[[Vector3<f64>; 3]] {
        &self.samples
    }

    /// The arm-path distance `D` to `other` (see the [module docs](self)), in arm lengths.
    pub fn distance(&self, other: &ArmPath) -> f64 {
        let joints = if self.hand && other.hand { 3 } else { 2 };
        let sum: f64 = self
            .samples
            .iter()
            .zip(&other.samples)
            .map(|(a, b)| {
                (0..joints)
                    .map(|j| (a[j] - b[j]).norm_squared())
                    .sum::<f64>()
            })
            .sum();
        (sum / (self.samples.len().min(other.samples.len()) * joints) as f64).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use kinergy_motion::nalgebra::{Translation3, UnitQuaternion};

    /// A raise: the straight arm (upper arm 0.3, forearm 0.25, hand 0.1 m) swings from hanging
    /// down to forward over `n` frames, the shoulder at `shoulder`.
    fn raise(n: usize, shoulder: Point3<f64>) -> Vec<[Option<Point3<f64>>; 4]> {
        (0..n)
            .map(|i| {
                let a = std::f64::consts::FRAC_PI_2 * i as f64 / (n - 1) as f64;
                let dir = Vector3::new(0.0, -a.cos(), a.sin());
                [0.0, 0.3, 0.55, 0.65].map(|r| Some(shoulder + dir * r))
            })
            .collect()
    }

    #[test]
    fn a_reach_is_at_distance_zero_from_itself() {
        let r = raise(30, Point3::new(0.1, 1.4, 0.0));
        let p = ArmPath::new(&r, &Rotation3::identity()).expect("path");
        assert_eq!(p.distance(&p), 0.0);
    }

    #[test]
    fn a_rigid_translation_changes_nothing_and_a_rotation_with_its_base_neither() {
        let r = raise(30, Point3::new(0.1, 1.4, 0.0));
        let p = ArmPath::new(&r, &Rotation3::identity()).expect("path");
        let moved: Vec<_> = r
            .iter()
            .map(|f| f.map(|q| q.map(|q| Translation3::new(2.0, -0.3, 5.0) * q)))
            .collect();
        let m = ArmPath::new(&moved, &Rotation3::identity()).expect("path");
        assert_relative_eq!(p.distance(&m), 0.0, epsilon = 1e-12);
        let turn = Rotation3::from_axis_angle(&Vector3::y_axis(), 2.1);
        let turned: Vec<_> = r.iter().map(|f| f.map(|q| q.map(|q| turn * q))).collect();
        let t = ArmPath::new(&turned, &turn).expect("path");
        assert_relative_eq!(p.distance(&t), 0.0, epsilon = 1e-12);
        // Not invariant to a turn the base frame does not share.
        let u = ArmPath::new(&turned, &Rotation3::identity()).expect("path");
        assert!(p.distance(&u) > 0.1);
    }

    #[test]
    fn a_constant_offset_of_the_hand_is_its_length_over_the_arm_and_root_of_three() {
        // Only the hand moves by d: one joint of three is |d| / L away on every sample,
        // D = sqrt(|d|² / (3 L²)) with L = 0.55 m (the hand is not part of L).
        let r = raise(30, Point3::origin());
        let d = Vector3::new(0.02, 0.05, -0.01);
        let off: Vec<_> = r
            .iter()
            .map(|f| [f[0], f[1], f[2], f[3].map(|h| h + d)])
            .collect();
        let (a, b) = (
            ArmPath::new(&r, &Rotation3::identity()).expect("path"),
            ArmPath::new(&off, &Rotation3::identity()).expect("path"),
        );
        assert_relative_eq!(
            a.distance(&b),
            d.norm() / (0.55 * 3f64.sqrt()),
            epsilon = 1e-12
        );
        // Without a hand on one side, only elbow and wrist count: the same arms agree.
        let handless: Vec<_> = off.iter().map(|f| [f[0], f[1], f[2], None]).collect();
        let c = ArmPath::new(&handless, &Rotation3::identity()).expect("path");
        assert!(!c.has_hand());
        assert_relative_eq!(a.distance(&c), 0.0, epsilon = 1e-12);
    }

    #[test]
    fn a_bigger_body_making_the_same_motion_slower_is_at_distance_zero() {
        // Scaled by 1.3 about its shoulder and sampled at 61 frames instead of 21: linear
        // in time between frames, so it samples to the same path in arm lengths.
        let small = raise(21, Point3::origin());
        let lerp = |i: usize| {
            let x = i as f64 / 3.0;
            let (k, u) = ((x.floor() as usize).min(19), x - x.floor().min(19.0));
            let s = Point3::new(0.4, 1.5, 0.2);
            let k2 = (k + 1).min(20);
            [0, 1, 2, 3].map(|j| {
                let a = small[k][j].expect("joint").coords;
                let b = small[k2][j].expect("joint").coords;
                Some(s + (a * (1.0 - u) + b * u) * 1.3)
            })
        };
        let big: Vec<_> = (0..61).map(lerp).collect();
        let a = ArmPath::new(&small, &Rotation3::identity()).expect("path");
        let b = ArmPath::new(&big, &Rotation3::identity()).expect("path");
        assert_relative_eq!(a.distance(&b), 0.0, epsilon = 1e-12);
    }

    #[test]
    fn a_turn_of_the_base_by_a_right_angle_moves_a_hanging_arm_by_the_closed_form() {
        // A still arm hanging straight down: a base turned 90° about z reads it sideways;
        // each joint at r/L from the shoulder moves by r/L·√2.
        let still: Vec<[Option<Point3<f64>>; 4]> = (0..5)
            .map(|_| [0.0, 0.3, 0.55, 0.65].map(|r| Some(Point3::new(0.0, -r, 0.0))))
            .collect();
        let a = ArmPath::new(&still, &Rotation3::identity()).expect("path");
        let q = UnitQuaternion::from_axis_angle(&Vector3::z_axis(), std::f64::consts::FRAC_PI_2);
        let b = ArmPath::new(&still, &q.to_rotation_matrix()).expect("path");
        let l = 0.55;
        let expected =
            ((0.3f64.powi(2) + 0.55f64.powi(2) + 0.65f64.powi(2)) * 2.0 / (3.0 * l * l)).sqrt();
        assert_relative_eq!(a.distance(&b), expected, epsilon = 1e-12);
    }

    #[test]
    fn no_frames_or_no_length_is_no_path() {
        assert!(ArmPath::new(&[], &Rotation3::identity()).is_none());
        let p = Some(Point3::origin());
        assert!(ArmPath::new(&[[p, p, p, p]], &Rotation3::identity()).is_none());
    }
}
