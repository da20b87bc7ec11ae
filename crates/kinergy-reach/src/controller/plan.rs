//! The scheduler's plan (Huang, Kapadia & Terzopoulos §4): every decision made once, from
//! the rest posture, before the first frame — the arm, the step, the twist, the squat, the
//! swing and the COM shift — each from the posture the ones before it leave.

use kinergy_motion::Side;
use kinergy_motion::nalgebra::{Point3, Vector3};

use super::arm::{ReachingArm, arm_ik, hand_position, shoulder_position};
use super::balance::plan_com_shift;
use super::legs::{self, StepPlan};
use super::report::Posture;
use super::settings::ReachSettings;
use super::spine::{apply_swing, plan_squat, plan_swing, plan_twist, set_twist};
use crate::character::{Character, Limb, Pose, dof, joint};
use crate::error::Result;

/// The plan: every decision, made once at the start.
#[derive(Debug, Clone)]
pub(super) struct Plan {
    /// The reaching arm.
    pub(super) arm: Limb,
    /// The target, world meters.
    pub(super) target: Point3<f64>,
    /// The step: decision, length, direction.
    pub(super) step: StepPlan,
    /// Total twist θ, radians about world up.
    pub(super) twist: f64,
    /// Total swing φ, radians about `axis`.
    pub(super) swing: f64,
    /// The swing's axis, world.
    pub(super) axis: Vector3<f64>,
    /// How far the root is lowered, meters.
    pub(super) squat: f64,
    /// The root's COM adjustment, world meters.
    pub(super) com_shift: Vector3<f64>,
}

impl Plan {
    /// How the body lowers itself toward the target: a squat when the root is lowered, a
    /// stoop when the spine swings toward a target below the resting hand, else upright.
    pub(super) fn posture(&self, character: &Character, rest: &Pose) -> Posture {
        if self.squat > 0.0 {
            Posture::Squat
        } else if self.swing != 0.0 && self.target.y < hand_position(character, rest, self.arm).y {
            Posture::Stoop
        } else {
            Posture::Upright
        }
    }
}

/// Chooses the arm, the step, the twist, the squat and the swing, each from the posture the
/// ones before it leave, and the COM shift the final posture needs.
pub(super) fn plan(
    character: &Character,
    rest: &Pose,
    target: Point3<f64>,
    s: &ReachSettings,
) -> Result<Plan> {
    let frames = character.world_frames(rest);
    let root = Point3::from(frames[joint::HIPS].translation.vector);
    let side = reaching_side(character, &target, s.arm);
    let arm = Limb::arm(side);
    let segments = character.proportions().arm(side);
    let arm_length = segments.upper_arm + segments.forearm + segments.hand;
    let step_settings = legs::step_settings(character, arm, s)?;
    let shoulder = shoulder_position(character, rest, arm);
    let step = legs::plan_step(
        character,
        &root,
        &shoulder,
        &target,
        side,
        &step_settings,
        s.seed,
    );
    let mut pose = *rest;
    let root_move = step.root_move();
    pose[dof::ROOT_X] += step.direction.x * root_move;
    pose[dof::ROOT_Z] += step.direction.z * root_move;

    let twist = plan_twist(character, &pose, arm, &target, s.comfortable_angle);
    set_twist(&mut pose, twist);
    let squat = plan_squat(character, &pose, arm, &target, arm_length / s.flexibility);
    pose[dof::ROOT_Y] -= squat;

    let arm_ik = arm_ik(character, arm)?;
    let reaching = ReachingArm {
        character,
        limb: arm,
        ik: &arm_ik,
        target: &target,
        length: arm_length,
    };
    let k_com = s.r_max / s.phi_max;
    let swing = plan_swing(&reaching, &pose, step.direction, k_com, s);
    if swing.angle != 0.0 {
        apply_swing(character, &mut pose, &swing.axis, swing.angle);
    }
    let feet = step.feet_after([frames[joint::RIGHT_FOOT], frames[joint::LEFT_FOOT]]);
    let com_shift = plan_com_shift(
        &reaching,
        &pose,
        &feet,
        -k_com * swing.angle.abs() * swing.dp,
        s.balance_margin + 0.02,
    )?;
    Ok(Plan {
        arm,
        target,
        step,
        twist,
        swing: swing.angle,
        axis: swing.axis,
        squat,
        com_shift,
    })
}

/// The arm that reaches for `target`: `arm` if given, else the one on the target's side of
/// the root at rest.
pub fn reaching_side(character: &Character, target: &Point3<f64>, arm: Option<Side>) -> Side {
    let root = character.world_frames(&character.rest_pose())[joint::HIPS]
        .translation
        .vector;
    arm.unwrap_or(if target.x >= root.x {
        Side::Left
    } else {
        Side::Right
    })
}
