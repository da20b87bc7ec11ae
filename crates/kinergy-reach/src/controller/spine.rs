//! The spine controller (Huang, Kapadia & Terzopoulos §3.3–3.4): the twist toward the target
//! (eqs. 5–6), the squat or stoop, and the swing about `s = d × y` (eq. 7) with the root's
//! COM shift `r = −kφ d_p` (eq. 8) — each decided once, from the posture the decisions before
//! it leave — and the poses that apply them.
//!
//! - **Twist**: the total twist θ is searched (1° steps) until the target's horizontal
//!   direction from the shoulder lies within the comfortable reaching angle of the chest's
//!   forward direction (eq. 6), and split equally over sacral, lumbar and thoracic joints
//!   (eq. 5).
//! - **Squat or stoop**: when the shoulder is higher above the target than the stoop range
//!   `arm length / flexibility`, the root is lowered by the excess (within what the legs
//!   allow) before the swing is searched; a low flexibility stoops instead.
//! - **Swing**: when the vertical shoulder–target distance exceeds the start swing distance,
//!   or the arm cannot reach, the spine swings about `s = d × y` (eq. 7), the angle raised in
//!   1° steps (split equally over the three joints, within their limits) until the arm can
//!   reach; the root moves by `r = −kφ d_p` (eq. 8, `k = r_max/φ_max`) to keep the COM over
//!   the feet.

use kinergy_motion::Motion;
use kinergy_motion::Side;
use kinergy_motion::nalgebra::{Point3, Rotation3, Vector3};

use super::arm::{ReachingArm, shoulder_position};
use super::settings::ReachSettings;
use crate::character::{Character, Limb, Pose, SpineJoint, dof, joint};

/// The spine joints that twist and swing: all but the cervical (the head's).
const LOWER_SPINE: [SpineJoint; 3] = [SpineJoint::Sacral, SpineJoint::Lumbar, SpineJoint::Thoracic];

/// The total twist θ (radians, about world up) for the `arm` to reach `target` from `pose`:
/// the smallest |θ| (1° steps, + before −) putting the target within the comfortable angle
/// (eq. 6); when none within the limits does, the θ turning closest to it.
pub(super) fn plan_twist(
    character: &Character,
    pose: &Pose,
    arm: Limb,
    target: &Point3<f64>,
    comfortable_angle: f64,
) -> f64 {
    let max_twist = max_twist_split(character);
    let forward_local = chest_forward_local(character);
    let mut closest = (f64::INFINITY, 0.0);
    for k in 0..=180 {
        for sign in [1.0, -1.0] {
            let theta = sign * (k as f64).to_radians();
            if theta.abs() > max_twist {
                continue;
            }
            let mut p = *pose;
            set_twist(&mut p, theta);
            let a = comfort_angle(character, &p, arm, target, &forward_local);
            if a <= comfortable_angle {
                return theta;
            }
            if a < closest.0 - 1e-12 {
                closest = (a, theta);
            }
        }
    }
    closest.1
}

/// How far to lower the root (meters, 0: none): by what the shoulder's height above the
/// target exceeds the `stoop_range`, as far as the legs allow.
pub(super) fn plan_squat(
    character: &Character,
    pose: &Pose,
    arm: Limb,
    target: &Point3<f64>,
    stoop_range: f64,
) -> f64 {
    let shoulder = shoulder_position(character, pose, arm);
    let drop = shoulder.y - target.y;
    if drop > stoop_range {
        (drop - stoop_range).min(max_squat(character))
    } else {
        0.0
    }
}

/// The deepest squat, as a fraction of the leg length (hip to ankle): the hips lowered to
/// about the knees' standing height. With Drillis & Contini's proportions (Winter,
/// *Biomechanics and Motor Control of Human Movement*, Fig. 4.1: hip 0.530 H, knee 0.285 H,
/// leg 0.491 H) the hips at knee height would be 0.245 H = 0.50 of the leg. 0.45, the depth
/// the reach grids' balance and planted-feet checks hold at, stays until the deeper,
/// kneel-like crouch is checked the same way.
const DEEPEST_SQUAT: f64 = 0.45;

/// The deepest squat, meters the root is lowered ([`DEEPEST_SQUAT`] of the leg length: 0.39 m
/// for a 1.75 m body).
pub(super) fn max_squat(character: &Character) -> f64 {
    let leg = character.proportions().leg(Side::Right);
    DEEPEST_SQUAT * (leg.thigh + leg.shank)
}

/// The spine's swing: its total angle φ (radians, 0: none) about `axis`, and d_p, the
/// ground direction the COM shift of eq. 8 is measured along.
#[derive(Debug, Clone, Copy)]
pub(super) struct SwingPlan {
    /// φ, radians about `axis`.
    pub angle: f64,
    /// `s = d × y` normalized (+X when the target is straight above or below).
    pub axis: Vector3<f64>,
    /// d_p: the target's ground direction from the shoulder (`direction` when straight above
    /// or below).
    pub dp: Vector3<f64>,
    /// The hand's distance from the target with the arm solved at the swung posture, meters
    /// (what the posture search asks: can the hand reach from here).
    pub hand_error: f64,
}

/// The swing about `s = d × y` from `pose`, raised in 1° steps until the `arm` reaches its
/// target — or the limits or φ_max stop it — with the root shifted by `r = −k_com |φ| d_p`
/// (eq. 8) on the way. `direction` is the step's, d_p's fallback.
pub(super) fn plan_swing(
    arm: &ReachingArm<'_>,
    pose: &Pose,
    direction: Vector3<f64>,
    k_com: f64,
    s: &ReachSettings,
) -> SwingPlan {
    let (character, target) = (arm.character, arm.target);
    let shoulder = arm.shoulder(pose);
    let dv = target - shoulder;
    let vertical = dv.y.abs();
    // How far the body is from letting the hand reach comfortably: the hand's distance from
    // the target with the arm solved at this posture, or the shoulder's distance beyond 90 %
    // of the arm's length, whichever is larger.
    let reach_of = |p: &Pose| {
        let beyond = (arm.shoulder(p) - target).norm() - 0.9 * arm.length;
        arm.error(p).max(beyond).max(0.0)
    };
    let reachable = 0.5 * s.tolerance;
    let horizontal = Vector3::new(dv.x, 0.0, dv.z);
    let axis = {
        let a = dv.cross(&Vector3::y());
        if a.norm() > 1e-9 {
            a.normalize()
        } else {
            Vector3::x()
        }
    };
    let dp = if horizontal.norm() > 1e-9 {
        horizontal.normalize()
    } else {
        direction
    };
    let mut swing = 0.0;
    if vertical > s.start_swing_distance || reach_of(pose) > reachable {
        let max_swing = s.phi_max.min(max_swing_split(character));
        let at = |phi: f64| {
            let mut p = *pose;
            apply_swing(character, &mut p, &axis, phi);
            let shift = -k_com * phi.abs() * dp;
            p[dof::ROOT_X] += shift.x;
            p[dof::ROOT_Z] += shift.z;
            p
        };
        // The direction (clockwise or not) that brings the shoulder closer.
        let step = 1f64.to_radians();
        let sign = if reach_of(&at(step)) <= reach_of(&at(-step)) {
            1.0
        } else {
            -1.0
        };
        let mut best = (reach_of(pose), 0.0);
        let mut phi: f64 = 0.0;
        while phi + step <= max_swing + 1e-12 {
            phi += step;
            let r = reach_of(&at(sign * phi));
            if r < best.0 - 1e-9 {
                best = (r, sign * phi);
            }
            if r <= reachable {
                break;
            }
        }
        swing = best.1;
    }
    let mut swung = *pose;
    if swing != 0.0 {
        apply_swing(character, &mut swung, &axis, swing);
        let shift = -k_com * swing.abs() * dp;
        swung[dof::ROOT_X] += shift.x;
        swung[dof::ROOT_Z] += shift.z;
    }
    SwingPlan {
        angle: swing,
        axis,
        dp,
        hand_error: arm.error(&swung),
    }
}

/// The largest total angle that splits equally over sacral, lumbar and thoracic within each
/// one's limit of the DoF `index(joint)`.
fn max_equal_split(character: &Character, index: impl Fn(SpineJoint) -> usize) -> f64 {
    LOWER_SPINE
        .iter()
        .map(|&j| 3.0 * dof_limit(character, index(j)))
        .fold(f64::INFINITY, f64::min)
}

/// The largest total twist splitting equally over the three lower spine joints within their
/// limits.
pub(super) fn max_twist_split(character: &Character) -> f64 {
    max_equal_split(character, |j| j.rotation_dofs().start + dof::TWIST)
}

/// The largest total swing splitting equally over the three lower spine joints (the
/// smaller ellipse radius of each, so every direction fits).
pub(super) fn max_swing_split(character: &Character) -> f64 {
    LOWER_SPINE
        .iter()
        .map(|&j| {
            let joint = &character.joints()[j.joint()];
            joint
                .motions
                .iter()
                .find_map(|m| match *m {
                    Motion::Swing { rx, ry } => Some(3.0 * rx.min(ry)),
                    _ => None,
                })
                .unwrap_or(0.0)
        })
        .fold(f64::INFINITY, f64::min)
}

/// The symmetric limit of a revolute DoF (the smaller of |min| and |max|).
fn dof_limit(character: &Character, index: usize) -> f64 {
    for j in character.joints() {
        let range = j.dof_range();
        if !range.contains(&index) {
            continue;
        }
        let mut k = j.first_dof + if j.translates { 3 } else { 0 };
        for m in &j.motions {
            if (k..k + m.dof_count()).contains(&index) {
                return match *m {
                    Motion::Revolute { min, max, .. } => min.abs().min(max.abs()),
                    Motion::Swing { rx, ry } => rx.min(ry),
                };
            }
            k += m.dof_count();
        }
    }
    0.0
}

/// Sets the spine's total twist θ, split equally over the three lower spine joints (eq. 5).
pub(super) fn set_twist(pose: &mut Pose, theta: f64) {
    for j in LOWER_SPINE {
        pose[j.rotation_dofs().start + dof::TWIST] = theta / 3.0;
    }
}

/// Sets the three lower spine joints' swings so the spine turns by `phi` about the world
/// axis `axis`, each joint a third, each expressed in its own frame before its motions.
pub(super) fn apply_swing(character: &Character, pose: &mut Pose, axis: &Vector3<f64>, phi: f64) {
    for j in LOWER_SPINE {
        // The parent's frame by its ancestors alone (the same values as the full pass, which
        // cost a quarter of a stepping frame here: three passes a call).
        let cj = &character.joints()[j.joint()];
        let parent = cj.parent.map_or(Rotation3::identity(), |p| {
            character.joint_frame(p, pose).rotation
        });
        let local = (parent * cj.rest).inverse() * axis;
        let planar = Vector3::new(local.x, local.y, 0.0);
        let v = if planar.norm() > 1e-9 {
            planar.normalize() * (phi / 3.0)
        } else {
            Vector3::zeros()
        };
        let r = j.rotation_dofs();
        pose[r.start + dof::SWING_X] = v.x;
        pose[r.start + dof::SWING_Y] = v.y;
    }
}

/// The angle between the target's horizontal direction from the shoulder and the chest's
/// horizontal forward direction (eq. 6).
fn comfort_angle(
    character: &Character,
    pose: &Pose,
    arm: Limb,
    target: &Point3<f64>,
    forward_local: &Vector3<f64>,
) -> f64 {
    let forward = character.joint_frame(joint::CHEST, pose).rotation * forward_local;
    let shoulder = shoulder_position(character, pose, arm);
    let d = target - shoulder;
    let (f, d) = (
        Vector3::new(forward.x, 0.0, forward.z),
        Vector3::new(d.x, 0.0, d.z),
    );
    if d.norm() < 1e-6 || f.norm() < 1e-9 {
        return 0.0;
    }
    f.normalize().dot(&d.normalize()).clamp(-1.0, 1.0).acos()
}

/// The chest's forward direction in its own frame (world +Z at rest).
fn chest_forward_local(character: &Character) -> Vector3<f64> {
    let rest = character.rest_pose();
    let frames = character.world_frames(&rest);
    frames[joint::CHEST].rotation.inverse() * Vector3::z()
}
