//! The scheduler (Huang, Kapadia & Terzopoulos §4): the reach planned once from the rest
//! posture ([`plan`]: arm, step, twist, squat, swing, COM shift), then animated frame by frame
//! ([`animate`]) with the controllers started by state:
//!
//! - state 0 starts the step;
//! - state 1 (the step has progressed `r_st`, or no step) starts arm, head and twist;
//! - state 2 (the twist has progressed `r_tw`, or no twist) starts swing, COM adjustment and
//!   squat — the squat, beyond the paper, not before the last foot has landed;
//! - state 3 ends when the hand is at the target and every controller has finished, or at
//!   the timeout.
//!
//! Each frame composes the root and spine, turns the head, then solves the legs, the reaching
//! arm and the idle arm (hanging, [`IdleArm`]) and corrects the balance, at most ten passes;
//! the balance correction is carried from frame to frame and moves the root at most
//! [`BALANCE_SPEED`].

use kinergy_motion::Side;
use kinergy_motion::nalgebra::{IsometryMatrix3, Point3, Vector2, Vector3};
use kinergy_solver::analytic::LimbIk;

use super::arm::{ArmFollower, IdleArm, arm_ik, hand_position, shoulder_position};
use super::balance::{plan_com_shift, rebalance};
use super::head::Head;
use super::legs::{self, StepPlan, Stepping, leg_iks, lower_root_for_legs_in, solve_legs_in};
use super::report::{HandOver, HandOverWhy, Posture, ReachMotion, ReachReport, ReachStop};
use super::settings::ReachSettings;
use super::spine::{apply_swing, plan_squat, plan_swing, plan_twist, set_twist};
use super::synergy::{
    ArmDrive, PLAIN_IK_TIME, STALL_PROGRESS, STALL_WINDOW, SYNERGY_TIME, SynergyArm,
};
use crate::character::{Character, Limb, Pose, dof, joint};
use crate::error::Result;
use crate::profile::{BellTiming, SpeedProfile};

/// The hand's mean speed when the analytic IK finishes a reach the synergy arm and plain IK
/// could not, m/s.
const FINAL_APPROACH_SPEED: f64 = 0.3;

/// The fastest the balance correction moves the root, m/s.
const BALANCE_SPEED: f64 = 0.5;

/// The fastest it moves the root when the COM would otherwise leave the support polygon, m/s.
const URGENT_BALANCE_SPEED: f64 = 1.5;

/// The plan: every decision, made once at the start.
#[derive(Debug, Clone)]
pub(super) struct Plan {
    arm: Limb,
    target: Point3<f64>,
    step: StepPlan,
    /// Total twist θ (radians, about world up) and swing φ (radians, about `axis`).
    twist: f64,
    swing: f64,
    axis: Vector3<f64>,
    squat: f64,
    com_shift: Vector3<f64>,
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
    let arm = match side {
        Side::Left => Limb::LeftArm,
        Side::Right => Limb::RightArm,
    };
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
    let k_com = s.r_max / s.phi_max;
    let swing = plan_swing(
        character,
        &pose,
        arm,
        &arm_ik,
        &target,
        arm_length,
        step.direction,
        k_com,
        s,
    );
    if swing.angle != 0.0 {
        apply_swing(character, &mut pose, &swing.axis, swing.angle);
    }
    let feet = step.feet_after([frames[joint::RIGHT_FOOT], frames[joint::LEFT_FOOT]]);
    let com_shift = plan_com_shift(
        character,
        &pose,
        &feet,
        arm,
        &arm_ik,
        &target,
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

/// Smoothstep on [0, 1].
pub(super) fn ease(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// When the controllers start and how long they take, seconds.
#[derive(Debug, Clone, Copy)]
struct Timeline {
    /// The step's end (0 without a step).
    step_total: f64,
    /// State 1: arm, head and twist start.
    t_arm: f64,
    /// The twist's duration (0 without a twist).
    twist_time: f64,
    /// State 2: swing, COM adjustment and squat start.
    t_swing: f64,
    /// Their duration (0 without any).
    swing_time: f64,
    /// When the squat starts: with the swing, but not before the last foot has landed (a
    /// squat on one leg would drop the root further to keep the swinging foot reachable).
    t_squat: f64,
}

impl Timeline {
    fn new(plan: &Plan, step_total: f64, landed: f64, s: &ReachSettings) -> Timeline {
        let t_arm = if plan.step.step.steps() {
            s.r_st * step_total
        } else {
            0.0
        };
        let twist_time = if plan.twist != 0.0 { s.twist_time } else { 0.0 };
        let swing_time = if plan.swing != 0.0 || plan.squat != 0.0 {
            s.swing_time
        } else {
            0.0
        };
        let t_swing = t_arm + s.r_tw * twist_time;
        Timeline {
            step_total,
            t_arm,
            twist_time,
            t_swing,
            swing_time,
            t_squat: t_swing.max(landed),
        }
    }

    /// The twist's progress at `t`, eased, in [0, 1].
    fn twist_at(&self, t: f64) -> f64 {
        if self.twist_time > 0.0 {
            ease((t - self.t_arm) / self.twist_time)
        } else {
            1.0
        }
    }

    /// The swing's (and COM shift's and squat's) progress at `t`, eased, in [0, 1].
    fn swing_at(&self, t: f64) -> f64 {
        if self.swing_time > 0.0 {
            ease((t - self.t_swing) / self.swing_time)
        } else {
            1.0
        }
    }

    /// The squat's progress at `t`, eased, in [0, 1].
    fn squat_at(&self, t: f64) -> f64 {
        if self.swing_time > 0.0 {
            ease((t - self.t_squat) / self.swing_time)
        } else {
            1.0
        }
    }

    /// Whether every controller but the arm has finished at `t`.
    fn body_done(&self, t: f64) -> bool {
        t >= self.t_squat + self.swing_time
            && t >= self.step_total
            && t >= self.t_arm + self.twist_time
    }
}

/// The frame at `t` before its limbs: the root on its step path, shifted and lowered by the
/// COM shift and the squat, and the spine twisted and swung as far as they have progressed.
fn body_at(
    character: &Character,
    rest: &Pose,
    plan: &Plan,
    stepping: &Stepping,
    timeline: &Timeline,
    t: f64,
) -> Pose {
    let mut pose = *rest;
    let root_path = stepping.root(t);
    let tw = timeline.twist_at(t);
    let sw = timeline.swing_at(t);
    pose[dof::ROOT_X] = root_path.x + plan.com_shift.x * sw;
    pose[dof::ROOT_Y] = root_path.y - plan.squat * timeline.squat_at(t);
    pose[dof::ROOT_Z] = root_path.z + plan.com_shift.z * sw;
    set_twist(&mut pose, plan.twist * tw);
    if t >= timeline.t_swing && plan.swing != 0.0 {
        apply_swing(character, &mut pose, &plan.axis, plan.swing * sw);
    }
    pose
}

/// Who drives the reaching arm on a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Driver {
    /// The speed profile, the arm solved by analytic IK; the profile's clock started at this
    /// time.
    Profile(f64),
    /// The person's synergy controller (or, after a hand-over, plain IK from its posture).
    Synergy,
}

/// One frame's limbs, solved again on every balance pass: the legs for the feet, the reaching
/// arm on its profile (when the profile drives it), the idle arm hanging.
struct FrameLimbs<'a> {
    character: &'a Character,
    leg_iks: &'a [LimbIk; 2],
    feet: &'a [IsometryMatrix3<f64>; 2],
    plan: &'a Plan,
    /// The root's height on the planned path (lowered where the legs need it).
    height: f64,
    /// Seconds into the profile, and the profile, when it drives the reaching arm.
    follow: Option<(f64, &'a SpeedProfile)>,
    arm: &'a mut ArmFollower,
    idle: &'a mut IdleArm,
    idle_limb: Limb,
    /// The orbit angles solved at, for the frame's end.
    arm_alpha: Option<f64>,
    idle_alpha: Option<f64>,
}

impl FrameLimbs<'_> {
    /// Solves the limbs into `pose` with the root where it is horizontally; returns the
    /// reaching hand's distance from the target.
    fn solve(&mut self, pose: &mut Pose, first_pass: bool) -> f64 {
        let c = self.character;
        // The root as low as the legs need where it is now (not where a pass before put it).
        pose[dof::ROOT_Y] = self.height;
        // The limbs' bases do not depend on the limbs: one FK serves all three.
        let mut above = c.world_frames(pose);
        lower_root_for_legs_in(c, pose, &mut above, self.feet);
        solve_legs_in(c, pose, &above, self.leg_iks, self.feet);
        let base = c.limb_base_frame_in(self.plan.arm, &above);
        if let Some((elapsed, profile)) = self.follow
            && let Some(a) = self.arm.follow(
                c,
                pose,
                &base,
                &self.plan.target,
                profile,
                elapsed,
                first_pass,
            )
        {
            self.arm_alpha = Some(a);
        }
        if let Some(a) = self
            .idle
            .hang(pose, &c.limb_base_frame_in(self.idle_limb, &above))
        {
            self.idle_alpha = Some(a);
        }
        (self.arm.hand(c, &base, pose, self.plan.target) - self.plan.target).norm()
    }
}

/// Runs the scheduler frame by frame, the reaching arm driven by `drive`.
pub(super) fn animate(
    character: &Character,
    rest: &Pose,
    plan: &Plan,
    s: &ReachSettings,
    drive: &ArmDrive,
) -> Result<ReachMotion> {
    let dt = 1.0 / s.frame_rate;
    let max_frames = ((s.timeout / dt).ceil() as usize)
        .saturating_add(1)
        .min(kinergy_solver::controller::MAX_FRAMES);
    let stepping = Stepping::new(character, rest, &plan.step, plan.arm, s)?;
    let leg_iks = leg_iks(character)?;
    let mut arm = ArmFollower::new(character, plan.arm, rest)?;
    let mut synergy: Option<SynergyArm> = None;
    let mut hand_over: Option<HandOver> = None;
    // When plain IK, after a hand-over, stalled too: from then on the analytic IK finishes on
    // a minimum-jerk path.
    let mut gave_up: Option<f64> = None;
    let approach = SpeedProfile::minimum_jerk(BellTiming::MeanSpeed {
        speed: FINAL_APPROACH_SPEED,
    })?;
    let stall_window = ((STALL_WINDOW / dt).ceil() as usize).max(1);
    // The synergy arm has arrived within half the tolerance (it approaches its target
    // asymptotically: stopping at the tolerance would stop it still moving).
    let arrived = 0.5 * s.tolerance;
    // A tight tolerance (a synthetic set's) is approached with progress below STALL_PROGRESS
    // well before arrival: the least progress is then a tenth of the arrival distance.
    let min_progress = STALL_PROGRESS.min(0.1 * arrived);
    let idle_limb = match plan.arm {
        Limb::LeftArm => Limb::RightArm,
        _ => Limb::LeftArm,
    };
    let mut idle = IdleArm::new(character, idle_limb, rest)?;
    let timeline = Timeline::new(plan, stepping.total(), stepping.landed(), s);
    let mut head = Head::default();
    let mut poses = Vec::new();
    let mut min_margin = f64::INFINITY;
    let mut stop = ReachStop::Timeout;
    let mut final_error = f64::INFINITY;
    // The balance correction of the root (x, z) carried from frame to frame.
    let mut correction = Vector2::zeros();
    for frame in 0..max_frames {
        let t = frame as f64 * dt;
        let mut pose = body_at(character, rest, plan, &stepping, &timeline, t);
        let planned = Vector2::new(pose[dof::ROOT_X], pose[dof::ROOT_Z]);
        let planned_height = pose[dof::ROOT_Y];
        pose[dof::ROOT_X] += correction.x;
        pose[dof::ROOT_Z] += correction.y;
        if t >= timeline.t_arm {
            head.turn_toward(character, &pose, &plan.target, s.head_speed * dt);
        }
        head.apply(&mut pose);

        // The reaching arm's driver: the profile from the arm controller's start, or the
        // person's synergy controller (started on this frame's body) until a hand-over.
        let driver = match (drive, gave_up) {
            (_, Some(from)) => Driver::Profile(from),
            (ArmDrive::Synergy { .. }, None) if t >= timeline.t_arm => Driver::Synergy,
            _ => Driver::Profile(timeline.t_arm),
        };
        if driver == Driver::Synergy {
            if synergy.is_none()
                && let ArmDrive::Synergy {
                    optimizer,
                    synergy: person,
                } = drive
            {
                synergy = Some(SynergyArm::new(
                    character,
                    plan.arm,
                    rest,
                    &pose,
                    plan.target,
                    optimizer,
                    person,
                    dt,
                )?);
            }
            if let Some(arm) = synergy.as_mut() {
                arm.pose_arm(&mut pose);
            }
        }
        let profile = match gave_up {
            Some(_) => &approach,
            None => &s.profile,
        };

        // Limbs, then balance (at most nine corrections).
        let feet = stepping.feet(t);
        let mut limbs = FrameLimbs {
            character,
            leg_iks: &leg_iks,
            feet: &feet,
            plan,
            height: planned_height,
            follow: match driver {
                Driver::Profile(from) if t >= from && t >= timeline.t_arm => {
                    Some((t - from, profile))
                }
                _ => None,
            },
            arm: &mut arm,
            idle: &mut idle,
            idle_limb,
            arm_alpha: None,
            idle_alpha: None,
        };
        let mut error = f64::INFINITY;
        let mut frame_margin = f64::INFINITY;
        for pass in 0..10 {
            error = limbs.solve(&mut pose, pass == 0);
            let balance = rebalance(
                character,
                &character.world_frames(&pose),
                s.balance_margin,
                1.5,
            );
            match balance.shift {
                Some(shift) if pass < 9 => {
                    pose[dof::ROOT_X] += shift.x;
                    pose[dof::ROOT_Z] += shift.y;
                }
                _ => {
                    frame_margin = balance.margin;
                    break;
                }
            }
        }
        // The correction moves the root no faster than BALANCE_SPEED: a support polygon that
        // changes at once (a heel rising) is followed over a few frames, not in one jump —
        // faster (URGENT_BALANCE_SPEED) when the COM would otherwise leave the polygon.
        let wanted = Vector2::new(pose[dof::ROOT_X], pose[dof::ROOT_Z]) - planned;
        let change = wanted - correction;
        if change.norm() > BALANCE_SPEED * dt {
            let before = correction;
            for speed in [BALANCE_SPEED, URGENT_BALANCE_SPEED] {
                let largest = speed * dt;
                correction = if change.norm() > largest {
                    before + change * (largest / change.norm())
                } else {
                    wanted
                };
                pose[dof::ROOT_X] = planned.x + correction.x;
                pose[dof::ROOT_Z] = planned.y + correction.y;
                error = limbs.solve(&mut pose, false);
                frame_margin =
                    rebalance(character, &character.world_frames(&pose), 0.0, 1.0).margin;
                if frame_margin >= 0.0 {
                    break;
                }
            }
        } else {
            correction = wanted;
        }
        let (frame_alpha, idle_alpha) = (limbs.arm_alpha, limbs.idle_alpha);
        min_margin = min_margin.min(frame_margin);
        if let Driver::Profile(from) = driver
            && arm.end_frame(
                character,
                &mut pose,
                frame_alpha,
                t - from.max(timeline.t_arm),
                dt,
            )
        {
            let hand = character.joint_frame(plan.arm.joints()[3], &pose);
            error = (Point3::from(hand.translation.vector) - plan.target).norm();
        }
        idle.end_frame(&mut pose, idle_alpha, dt);
        character.clamp_pose(&mut pose);
        if let (Driver::Synergy, Some(synergy_arm)) = (driver, synergy.as_mut()) {
            // The controller sees this frame's final body and arm, and steps.
            let base = character.limb_base_frame(plan.arm, &pose);
            let seen = synergy_arm.end_frame(&pose, &base)?;
            error = seen.unwrap_or(error);
            let stalled = error > arrived
                && timeline.body_done(t)
                && synergy_arm.stalled_by(stall_window, min_progress);
            if hand_over.is_some() {
                // Plain IK cannot close the gap either (the two chains' limits disagree): the
                // analytic IK finishes, in the character's own limits.
                let slow = hand_over.is_some_and(|h| t - h.at_s >= PLAIN_IK_TIME);
                if seen.is_none() || stalled || slow {
                    gave_up = Some(t + dt);
                    arm.resume_from(&pose);
                    if let Some(h) = hand_over.as_mut() {
                        h.analytic_at_s = gave_up;
                    }
                }
            } else {
                let why = if seen.is_none() {
                    Some(HandOverWhy::NotFinite)
                } else if stalled {
                    Some(HandOverWhy::Stalled)
                } else if error > arrived && t - timeline.t_arm >= SYNERGY_TIME {
                    Some(HandOverWhy::TooLong)
                } else {
                    None
                };
                if let Some(why) = why {
                    hand_over = Some(HandOver {
                        at_s: t + dt,
                        distance_m: error,
                        why,
                        analytic_at_s: None,
                    });
                    synergy_arm.hand_over(dt)?;
                }
            }
        }
        final_error = error;
        arm.settle(&pose);
        idle.settle(&pose);
        poses.push(pose);
        let hand_done = match driver {
            // After a hand-over, within the tolerance: plain IK closes in slowest at the end.
            Driver::Synergy if hand_over.is_some() => error <= s.tolerance,
            Driver::Synergy => error <= arrived,
            Driver::Profile(from) => {
                t >= from.max(timeline.t_arm) + profile.duration(arm.path_length(&plan.target))
            }
        };
        if timeline.body_done(t) && hand_done {
            if error <= s.tolerance {
                stop = ReachStop::Reached;
                break;
            }
            // Hold a few frames to let the nearest point settle, then give up.
            if t >= timeline.t_squat + timeline.swing_time + 0.25 && t >= timeline.t_arm + 0.25 {
                stop = ReachStop::Unreachable;
                break;
            }
        }
    }
    let frames = poses.len();
    let report = ReachReport {
        arm: plan.arm,
        step: plan.step.step,
        step_length: plan.step.length,
        horizontal_distance: plan.step.horizontal_distance,
        twist_deg: plan.twist.to_degrees(),
        swing_deg: plan.swing.to_degrees(),
        squat_m: plan.squat,
        posture: if plan.squat > 0.0 {
            Posture::Squat
        } else if plan.swing != 0.0 && plan.target.y < hand_position(character, rest, plan.arm).y {
            Posture::Stoop
        } else {
            Posture::Upright
        },
        final_error,
        stop,
        frames,
        duration: frames as f64 * dt,
        min_balance_margin: min_margin,
        arm_onset_frame: (0..frames)
            .find(|&k| k as f64 * dt >= timeline.t_arm)
            .unwrap_or(frames),
        arm_drive: drive.name(),
        hand_over,
    };
    Ok(ReachMotion {
        poses,
        frame_time: dt,
        report,
    })
}
