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
use super::spine::{SwingPlan, max_squat};
use super::spine::{apply_swing, plan_squat, plan_swing, plan_twist, set_twist};
use super::stance::{Stance, StanceCandidate};
use crate::character::{Character, Limb, Pose, dof, joint};
use crate::error::Result;
use crate::steps::StepDecision;

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

/// How much deeper each squat the posture search tries is, meters.
const SQUAT_INCREMENT: f64 = 0.02;

/// How much longer each step the posture search tries is, meters.
const STEP_INCREMENT: f64 = 0.05;

/// Chooses the arm, the step, the twist, the squat and the swing, each from the posture the
/// ones before it leave, and the COM shift the final posture needs.
///
/// The paper's decisions come first: the step its state machine draws, the squat the leg
/// flexibility asks for, the swing that brings the hand in reach. Where the hand still cannot
/// reach from that posture, the body searches on as a person does ([`search_posture`]):
/// squatting deeper (down to [`max_squat`]) or stepping toward the target and stooping — eq.
/// 9's step, then longer ones up to [`legs::longest_step`] — in the order the leg flexibility
/// prefers, then stepping and squatting. Only a target no such posture brings in reach stays out of it (the report's
/// `unreachable`, with the margin).
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
    let drawn = legs::plan_step(
        character,
        &root,
        &shoulder,
        &target,
        side,
        &step_settings,
        s.seed,
    );
    // Eq. 9's step where the body holds it, else the longest it holds (the balance model).
    let balance = legs::StepBalance::new(character, rest, arm, s)?;
    let drawn = balance.fit(&drawn);
    let arm_ik = arm_ik(character, arm)?;
    let reaching = ReachingArm {
        character,
        limb: arm,
        ik: &arm_ik,
        target: &target,
        length: arm_length,
    };
    let k_com = s.r_max / s.phi_max;
    let at =
        |step: &StepPlan, squat: Option<f64>| posture_at(&reaching, rest, step, squat, k_com, s);
    // A posture with its COM shift and the hand's distance from the target after it (the root
    // moved back for balance can leave the hand short of a target it reached before).
    let feet_rest = [frames[joint::RIGHT_FOOT], frames[joint::LEFT_FOOT]];
    let settle = |mut c: Candidate| -> Result<Candidate> {
        let feet = c.step.feet_after(feet_rest);
        let (shift, error) = plan_com_shift(
            &reaching,
            &c.pose,
            &feet,
            -k_com * c.swing.angle.abs() * c.swing.dp,
            s.balance_margin + 0.02,
        )?;
        c.com_shift = Some(shift);
        c.hand_error = c.hand_error.max(error);
        Ok(c)
    };
    let reached = 0.5 * s.tolerance;
    let paper = at(&drawn, None);
    let paper = if paper.hand_error <= reached {
        settle(paper)?
    } else {
        paper
    };
    let chosen = if paper.hand_error <= reached {
        paper
    } else {
        search_posture(
            &reaching,
            paper,
            &drawn,
            &balance,
            s.flexibility,
            reached,
            &Evaluate {
                at: &at,
                settle: &settle,
            },
        )?
    };
    let chosen = match chosen.com_shift {
        Some(_) => chosen,
        None => settle(chosen)?,
    };
    let Candidate {
        step,
        twist,
        squat,
        swing,
        com_shift,
        ..
    } = chosen;
    let com_shift = com_shift.unwrap_or_else(Vector3::zeros);
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

/// One posture the scheduler can plan: the step, the twist, the squat and the swing, and the
/// body they leave (before the COM shift), with the hand's distance from the target there.
#[derive(Debug, Clone)]
struct Candidate {
    step: StepPlan,
    twist: f64,
    squat: f64,
    swing: SwingPlan,
    pose: Pose,
    hand_error: f64,
    /// The root's COM adjustment once settled (`plan`'s `settle`), when it has been.
    com_shift: Option<Vector3<f64>>,
}

/// The posture after `step`, the twist toward the target, the squat `squat` (`None`: the one
/// the leg flexibility asks for, [`plan_squat`]) and the swing that brings the hand nearest.
fn posture_at(
    reaching: &ReachingArm<'_>,
    rest: &Pose,
    step: &StepPlan,
    squat: Option<f64>,
    k_com: f64,
    s: &ReachSettings,
) -> Candidate {
    let (character, arm, target) = (reaching.character, reaching.limb, reaching.target);
    let mut pose = *rest;
    let root_move = step.root_move();
    pose[dof::ROOT_X] += step.direction.x * root_move;
    pose[dof::ROOT_Z] += step.direction.z * root_move;
    let twist = plan_twist(character, &pose, arm, target, s.comfortable_angle);
    set_twist(&mut pose, twist);
    let squat = squat.unwrap_or_else(|| {
        plan_squat(
            character,
            &pose,
            arm,
            target,
            reaching.length / s.flexibility,
        )
    });
    pose[dof::ROOT_Y] -= squat;
    let swing = plan_swing(reaching, &pose, step.direction, k_com, s);
    if swing.angle != 0.0 {
        apply_swing(character, &mut pose, &swing.axis, swing.angle);
    }
    Candidate {
        step: *step,
        twist,
        squat,
        hand_error: swing.hand_error,
        swing,
        pose,
        com_shift: None,
    }
}

/// How the search evaluates a posture: `at` builds it (a step and a squat, `None` for the
/// flexibility's), `settle` gives it its COM shift and the hand's distance after it.
#[derive(Clone, Copy)]
struct Evaluate<'a> {
    at: &'a dyn Fn(&StepPlan, Option<f64>) -> Candidate,
    settle: &'a dyn Fn(Candidate) -> Result<Candidate>,
}

/// The posture search beyond the paper's decisions ([`plan`]): deeper squats from the
/// paper's posture, and steps toward the target (the drawn step if it stepped, else a full
/// step of eq. 9's length; then longer ones up to the balance's limit) with a stoop alone —
/// the squats first for a flexible body, the steps for a stiff one — then the steps with
/// every squat from the least to the deepest. The first posture from which the hand reaches wins; if none does, the
/// one that brings it nearest (the reach ends `unreachable` there, with its margin). A
/// posture reaches when the hand, the arm solved there, is within `reached` meters.
fn search_posture(
    reaching: &ReachingArm<'_>,
    paper: Candidate,
    drawn: &StepPlan,
    balance: &legs::StepBalance<'_>,
    flexibility: f64,
    reached: f64,
    evaluate: &Evaluate<'_>,
) -> Result<Candidate> {
    let Evaluate { at, settle } = *evaluate;
    let character = reaching.character;
    let settings = balance.steps();
    let reachable = |c: &Candidate| c.hand_error <= reached;
    let deepest = max_squat(character);
    let squats_from = |from: f64| {
        let n = ((deepest - from) / SQUAT_INCREMENT).ceil().max(0.0) as usize;
        (1..=n).map(move |k| (from + k as f64 * SQUAT_INCREMENT).min(deepest))
    };
    let mut best = paper.clone();
    // A posture reaches once settled with its COM shift.
    let mut consider = |c: Candidate| -> Result<Option<Candidate>> {
        let c = if reachable(&c) { settle(c)? } else { c };
        if reachable(&c) {
            return Ok(Some(c));
        }
        if c.hand_error < best.hand_error {
            best = c;
        }
        Ok(None)
    };
    // Step toward the target: the drawn step if it stepped, else a full step of eq. 9's
    // length; then longer ones up to the balance's limit.
    let d = drawn.horizontal_distance;
    let first = if drawn.step.steps() {
        drawn.length
    } else {
        crate::steps::step_length(settings, d, settings.p_mean)
    };
    // The drawn kind of step first (a full one where none was drawn), then — a half step
    // moves the root only half as far — a full one.
    let drawn_kind = match drawn.step {
        StepDecision::NoStep => StepDecision::FullStep,
        kind => kind,
    };
    let kinds: &[StepDecision] = if drawn_kind == StepDecision::FullStep {
        &[StepDecision::FullStep]
    } else {
        &[drawn_kind, StepDecision::FullStep]
    };
    let reach_limit = legs::longest_step(character).min((d - 0.5 * settings.d_c).max(0.0));
    let mut steps = Vec::new();
    for &kind in kinds {
        let step_of = |length: f64| StepPlan::new(character, kind, length, drawn.direction, d);
        let longest = balance
            .longest(&step_of(reach_limit))
            .map_or(0.0, |st| st.length);
        let mut length = first.min(longest);
        while length > 1e-3 {
            let drawn_again = kind == drawn.step && (length - drawn.length).abs() < 1e-9;
            if !drawn_again && let Some(held) = balance.balanced(&step_of(length)) {
                steps.push(held);
            }
            if length >= longest - 1e-9 {
                break;
            }
            length = (length + STEP_INCREMENT).min(longest);
        }
    }
    // A flexible body squats deeper before it steps; a stiff one (flexibility below 1: the
    // paper's stooper) steps and stoops before it squats.
    let mut order: Vec<(StepPlan, f64)> = Vec::new();
    let deeper = squats_from(paper.squat).map(|q| (*drawn, q));
    let stepped_stoop = steps.iter().map(|st| (*st, 0.0));
    let stepped_squat = steps
        .iter()
        .flat_map(|st| squats_from(0.0).map(move |q| (*st, q)));
    if flexibility >= 1.0 {
        order.extend(deeper);
        order.extend(stepped_stoop);
    } else {
        order.extend(stepped_stoop);
        order.extend(deeper);
    }
    order.extend(stepped_squat);
    for (step, squat) in order {
        if let Some(c) = consider(at(&step, Some(squat)))? {
            return Ok(c);
        }
    }
    Ok(best)
}

/// The stances the posture search tries with the feet where they stand in `rest` (the public
/// [`super::stance::standing_stances`]): [`posture_at`] with no step, the paper's squat
/// first, then squats [`SQUAT_INCREMENT`] deeper each to [`max_squat`].
pub(super) fn standing_stances(
    character: &Character,
    rest: &Pose,
    target: &Point3<f64>,
    s: &ReachSettings,
) -> Result<Vec<StanceCandidate>> {
    let side = reaching_side(character, target, s.arm);
    let arm = Limb::arm(side);
    let segments = character.proportions().arm(side);
    let arm_ik = arm_ik(character, arm)?;
    let reaching = ReachingArm {
        character,
        limb: arm,
        ik: &arm_ik,
        target,
        length: segments.upper_arm + segments.forearm + segments.hand,
    };
    let shoulder = shoulder_position(character, rest, arm);
    let still = StepPlan::new(
        character,
        crate::steps::StepDecision::NoStep,
        0.0,
        crate::steps::step_direction(&shoulder, target)
            .map(|u| u.into_inner())
            .unwrap_or_else(Vector3::z),
        crate::steps::horizontal_distance(&shoulder, target),
    );
    let k_com = s.r_max / s.phi_max;
    let at = |squat: Option<f64>| {
        let c = posture_at(&reaching, rest, &still, squat, k_com, s);
        StanceCandidate {
            stance: Stance {
                swing: c.swing.angle,
                twist: c.twist,
                squat: c.squat,
                axis: c.swing.axis,
                dp: c.swing.dp,
            },
            hand_error: c.hand_error,
        }
    };
    let paper = at(None);
    let deepest = max_squat(character);
    let n = ((deepest - paper.stance.squat) / SQUAT_INCREMENT)
        .ceil()
        .max(0.0) as usize;
    let mut out = vec![paper];
    out.extend((1..=n).map(|k| {
        at(Some(
            (paper.stance.squat + k as f64 * SQUAT_INCREMENT).min(deepest),
        ))
    }));
    Ok(out)
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
