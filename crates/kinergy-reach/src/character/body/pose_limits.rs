//! A pose checked against and clamped into the joints' limits, and the limits of a limb's
//! DoFs at a pose.

use kinergy_motion::Motion;

use super::{Character, CharacterJoint, GirdleRole};
use crate::character::layout::{Limb, Pose};

// The joint limits' values are `character/limits.rs`'s; the check and the clamp walk the joints
// here.
impl Character {
    /// The radii `(rx, ry)` of the swing ellipse whose first DoF is `k` (the swing `(k, k + 1)`
    /// lies within it when `(q_k / rx)² + (q_(k+1) / ry)² ≤ 1`); `None` when DoF `k` does not
    /// start a swing.
    pub fn swing_radii(&self, k: usize) -> Option<(f64, f64)> {
        for j in &self.joints {
            let mut at = j.first_dof + if j.translates { 3 } else { 0 };
            for m in &j.motions {
                if let Motion::Swing { rx, ry } = *m
                    && at == k
                {
                    return Some((rx, ry));
                }
                at += m.dof_count();
            }
        }
        None
    }

    /// The limits of `limb`'s seven DoFs at `pose` (in the limb's DoF order, as
    /// [`Character::revolute_range`] and [`Character::swing_radii`] give them one DoF at a
    /// time), walking the limb's own joints once: what a controller bounding every DoF of an
    /// arm each frame needs.
    pub fn limb_limits(&self, limb: Limb, pose: &Pose) -> [DofLimit; 7] {
        let mut out = [DofLimit::Free; 7];
        let start = self.limb_dofs(limb).start;
        for &ji in &limb.joints()[..3] {
            let j = &self.joints[ji];
            let mut at = j.first_dof + if j.translates { 3 } else { 0 };
            for m in &j.motions {
                let Some(i) = at.checked_sub(start).filter(|&i| i < 7) else {
                    at += m.dof_count();
                    continue;
                };
                match *m {
                    Motion::Revolute { min, max, .. } => {
                        let (min, max) = revolute_range(j, min, max, pose, at);
                        out[i] = DofLimit::Revolute { min, max };
                    }
                    Motion::Swing { rx, ry } => {
                        out[i] = DofLimit::Swing { rx, ry };
                        if i + 1 < 7 {
                            out[i + 1] = DofLimit::SwingSecond;
                        }
                    }
                }
                at += m.dof_count();
            }
        }
        out
    }

    /// The range `[min, max]` of DoF `k` of `pose` when it is a revolute one (at `pose`: the
    /// shoulder's twist range widens with the arm's elevation); `None` for a swing's or a
    /// root's DoF, or `k` out of range.
    pub fn revolute_range(&self, k: usize, pose: &Pose) -> Option<(f64, f64)> {
        for j in &self.joints {
            let mut at = j.first_dof + if j.translates { 3 } else { 0 };
            for m in &j.motions {
                if let Motion::Revolute { min, max, .. } = *m
                    && at == k
                {
                    return Some(revolute_range(j, min, max, pose, at));
                }
                at += m.dof_count();
            }
        }
        None
    }

    /// `Ok` when every value is finite and every rotation DoF within its limits (swings
    /// inside their ellipse, 1e-12 of slack); otherwise the first violation, naming the DoF.
    pub fn joint_limits_ok(&self, pose: &Pose) -> std::result::Result<(), String> {
        if let Some(i) = pose.iter().position(|v| !v.is_finite()) {
            return Err(format!("DoF `{}` is {}", self.dof_names[i], pose[i]));
        }
        for j in &self.joints {
            let mut k = j.first_dof + if j.translates { 3 } else { 0 };
            for m in &j.motions {
                match *m {
                    Motion::Revolute { min, max, .. } => {
                        let v = pose[k];
                        let (min, max) = revolute_range(j, min, max, pose, k);
                        if v < min - 1e-12 || v > max + 1e-12 {
                            return Err(format!(
                                "DoF `{}` = {:.3}° is outside [{:.3}°, {:.3}°]",
                                self.dof_names[k],
                                v.to_degrees(),
                                min.to_degrees(),
                                max.to_degrees()
                            ));
                        }
                    }
                    Motion::Swing { rx, ry } => {
                        let (sx, sy) = (pose[k], pose[k + 1]);
                        let e = (sx / rx).powi(2) + (sy / ry).powi(2);
                        if e > 1.0 + 1e-12 {
                            return Err(format!(
                                "DoFs `{}`, `{}` = ({:.3}°, {:.3}°) lie outside their swing ellipse ({:.3}°, {:.3}°)",
                                self.dof_names[k],
                                self.dof_names[k + 1],
                                sx.to_degrees(),
                                sy.to_degrees(),
                                rx.to_degrees(),
                                ry.to_degrees()
                            ));
                        }
                    }
                }
                k += m.dof_count();
            }
        }
        Ok(())
    }

    /// Brings `pose` within the limits: revolute DoFs clamped, swings outside their ellipse
    /// scaled toward zero onto it (as [`Chain::clamp`](kinergy_motion::Chain::clamp)); non-finite values become 0.
    pub fn clamp_pose(&self, pose: &mut Pose) {
        for v in pose.iter_mut() {
            if !v.is_finite() {
                *v = 0.0;
            }
        }
        for j in &self.joints {
            let mut k = j.first_dof + if j.translates { 3 } else { 0 };
            for m in &j.motions {
                match *m {
                    Motion::Revolute { min, max, .. } => {
                        let (min, max) = revolute_range(j, min, max, pose, k);
                        pose[k] = wrap_or_clamp(pose[k], min, max);
                    }
                    Motion::Swing { rx, ry } => {
                        let e = (pose[k] / rx).powi(2) + (pose[k + 1] / ry).powi(2);
                        if e > 1.0 {
                            let s = 1.0 / e.sqrt();
                            pose[k] *= s;
                            pose[k + 1] *= s;
                        }
                    }
                }
                k += m.dof_count();
            }
        }
    }
}

/// A DoF's limit ([`Character::limb_limits`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DofLimit {
    /// No limit (or not a rotation DoF).
    Free,
    /// A revolute DoF's range at the pose.
    Revolute {
        /// The least value, radians.
        min: f64,
        /// The largest value, radians.
        max: f64,
    },
    /// The first DoF of a swing, within the ellipse `(q / rx)² + (q_next / ry)² ≤ 1`.
    Swing {
        /// The ellipse's radius along this DoF, radians.
        rx: f64,
        /// Its radius along the next DoF, radians.
        ry: f64,
    },
    /// The second DoF of a swing (its limit is the first's).
    SwingSecond,
}

/// A revolute DoF's value `v` within `[min, max]`: the same rotation a turn away (`v ∓ 2π`)
/// where that lies within the range, else clamped. Near the arm straight up the shoulder's
/// twist range reaches ±180° and a twist carried on continuously passes beyond it: clamped,
/// 3.79 rad became 3.11 — a different arm, the hand thrown 12 cm in a frame — where −2.50 is
/// the same arm within the range.
pub fn wrap_or_clamp(v: f64, min: f64, max: f64) -> f64 {
    use std::f64::consts::TAU;
    if v > max && v - TAU >= min {
        v - TAU
    } else if v < min && v + TAU <= max {
        v + TAU
    } else {
        v.clamp(min, max)
    }
}

/// `a − b` wrapped into (−π, π]: a revolute DoF's change, the same for values a turn apart
/// (what [`wrap_or_clamp`] may put between two frames). Not
/// `kinergy_motion::rotation::unwrap_near(a, b) − b`, which is exact where this rounds a
/// negative change by 1e-16: the committed synthetic set was made with this one, and three of
/// its clips part by up to 4.7° from such a rounding.
pub fn angle_difference(a: f64, b: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let d = (a - b).rem_euclid(TAU);
    if d > PI { d - TAU } else { d }
}

/// Where the shoulder's twist range starts to widen: humerothoracic elevations above 90°
/// (from 120° a synergy that turns the twist hard still met the clamp at 130°–150° and circled
/// the arm overhead: Bandai *active* fitted on takes 1–6, r 0.50 with 120°, 0.81 with 90°).
pub const OVERHEAD_TWIST_FROM: f64 = 90.0 * std::f64::consts::PI / 180.0;

/// The range of the revolute DoF `k` of joint `j` (`[min, max]` in its table) at `pose`: the
/// table's, except the shoulder's twist (the revolute after an arm's swing), whose range widens
/// linearly from the table's at [`OVERHEAD_TWIST_FROM`] of elevation to ±180° at 180°. The
/// twist is that of the swing–twist split from the hanging arm, singular with the arm
/// straight up: there a swing of π about u followed by a twist τ is the swing of π about u
/// turned by −τ/2, with no twist (a π turn about a horizontal axis flips z, so
/// `S(πu)·Rz(τ) = Rz(−τ/2)·S(πu)·Rz(τ/2) = S(π·Rz(−τ/2)u)`); near it, a small turn of the arm
/// moves the twist coordinate by a lot. A fixed ±90° there limited nothing anatomical, and
/// clamping the coordinate turned an overhead arm by up to 1.6 rad on single frames (Bandai
/// *active* raises under the person's synergy).
fn revolute_range(j: &CharacterJoint, min: f64, max: f64, pose: &Pose, k: usize) -> (f64, f64) {
    use std::f64::consts::PI;
    if !matches!(j.girdle, Some(GirdleRole::Shoulder(_))) || k < 2 {
        return (min, max);
    }
    let elevation = pose[k - 2].hypot(pose[k - 1]);
    let w = ((elevation - OVERHEAD_TWIST_FROM) / (PI - OVERHEAD_TWIST_FROM)).clamp(0.0, 1.0);
    (min + w * (-PI - min), max + w * (PI - max))
}
