//! The scheduler (Huang, Kapadia & Terzopoulos §4): the reach planned once from the rest
//! posture ([`super::plan`]), then animated frame by frame ([`animate`]) with the controllers
//! started by state:
//!
//! - state 0 starts the step;
//! - state 1 (the step has progressed `r_st`, or no step) starts arm, head and twist;
//! - state 2 (the twist has progressed `r_tw`, or no twist) starts swing, COM adjustment and
//!   squat — the squat, beyond the paper, not before the last foot has landed;
//! - state 3 ends when the hand is at the target and every controller has finished, or at
//!   the timeout.
//!
//! Each frame composes the root and spine ([`Body`]), turns the head, lets the arm's phase
//! pose the arm ([`ArmPhase`]: waiting, analytic, a person's synergy, plain IK), then solves
//! the legs, the reaching arm and the idle arm (hanging, [`IdleArm`]) and corrects the
//! balance, at most ten passes ([`BalanceCorrection`], carried from frame to frame at a
//! bounded speed); at its end the arm's phase steps.

use kinergy_motion::nalgebra::IsometryMatrix3;
use kinergy_solver::analytic::LimbIk;

use super::arm::{ArmFollower, IdleArm, ProfileTime};
use super::balance::BalanceCorrection;
use super::head::Head;
use super::legs::{LOWER_BLEND, leg_iks, lower_root_for_legs_in, solve_legs_in};
use super::phase::{ArmPhase, ArmRules};
use super::plan::Plan;
use super::report::{ReachMotion, ReachReport, ReachStop};
use super::settings::ReachSettings;
use super::synergy::ArmDrive;
use super::timeline::{Body, Timeline};
use crate::character::{Character, Limb, Pose, dof};
use crate::error::Result;

/// One frame's limbs, solved again on every balance pass: the legs for the feet, the reaching
/// arm on its profile (when the profile drives it), the idle arm hanging.
struct FrameLimbs<'a> {
    character: &'a Character,
    leg_iks: &'a [LimbIk; 2],
    feet: &'a [IsometryMatrix3<f64>; 2],
    plan: &'a Plan,
    /// The root's height on the planned path (lowered where the legs need it).
    height: f64,
    /// Whether the legs lower the root smoothly ([`RootRise`], [`LOWER_BLEND`]).
    smooth_root: bool,
    /// The least the legs lower the root on this frame ([`RootRise`]).
    lowered_at_least: f64,
    /// How far the legs themselves needed the root lowered on the last pass, meters.
    lowered_needed: f64,
    /// The profile and the seconds into it, when it drives the reaching arm.
    follow: Option<ProfileTime<'a>>,
    arm: &'a mut ArmFollower,
    /// The reaching arm hanging as the idle one does, before it reaches.
    waiting: Option<&'a mut IdleArm>,
    idle: &'a mut IdleArm,
    idle_limb: Limb,
    /// The reaching arm's base frame after the last pass (the girdle where the arm put it).
    arm_base: IsometryMatrix3<f64>,
    /// The reaching arm's DoFs and the trunk's (root, spine, neck) `arm_base` is for.
    arm_solved: ([f64; 7], [f64; TRUNK_DOFS]),
    /// The orbit angles solved at, for the frame's end.
    arm_alpha: Option<f64>,
    idle_alpha: Option<f64>,
}

impl FrameLimbs<'_> {
    /// Solves the limbs into `pose` with the root where it is horizontally; returns the
    /// reaching hand's distance from the target and the pose's world frames.
    fn solve(&mut self, pose: &mut Pose, first_pass: bool) -> (f64, Vec<IsometryMatrix3<f64>>) {
        let c = self.character;
        // The root as low as the legs need where it is now (not where a pass before put it).
        pose[dof::ROOT_Y] = self.height;
        // The legs' bases do not depend on the limbs, the arms' on their own arm only (the
        // girdle, solved with the arm): one FK of the trunk serves all three.
        let mut above = c.frames_above_limbs(pose);
        let blend = if self.smooth_root { LOWER_BLEND } else { 0.0 };
        lower_root_for_legs_in(c, pose, &mut above, self.feet, blend);
        self.lowered_needed = self.height - pose[dof::ROOT_Y];
        let extra = self.lowered_at_least - self.lowered_needed;
        if extra > 0.0 {
            pose[dof::ROOT_Y] -= extra;
            for f in above.iter_mut() {
                f.translation.vector.y -= extra;
            }
        }
        solve_legs_in(c, pose, &above, self.leg_iks, self.feet);
        let base = c.limb_base_frame_in(self.plan.arm, &above);
        let arm_dofs = c.limb_dofs(self.plan.arm);
        let at: [f64; 7] = std::array::from_fn(|i| pose[arm_dofs.start + i]);
        if let Some(now) = self.follow
            && let Some(a) = self
                .arm
                .follow(c, pose, &base, &self.plan.target, now, first_pass)
        {
            self.arm_alpha = Some(a);
        }
        if let Some(hanging) = self.waiting.as_deref_mut()
            && let Some(a) = hanging.hang(c, pose, &base)
        {
            self.arm_alpha = Some(a);
        }
        if let Some(a) = self
            .idle
            .hang(c, pose, &c.limb_base_frame_in(self.idle_limb, &above))
        {
            self.idle_alpha = Some(a);
        }
        // The arm's base where the girdle puts it for the arm just solved (only the girdle
        // moved it since `above`).
        let solved: [f64; 7] = std::array::from_fn(|i| pose[arm_dofs.start + i]);
        let base = c.arm_base_moved(self.plan.arm, &base, &at, &solved);
        self.arm_base = base;
        self.arm_solved = (solved, std::array::from_fn(|i| pose[i]));
        let error = (self.arm.hand(c, &base, pose, self.plan.target) - self.plan.target).norm();
        // The trunk's frames still hold (the root lowered with them): the limbs' complete them.
        c.complete_limb_frames(pose, &mut above);
        (error, above)
    }
}

/// The trunk's DoFs (root, spine and neck): those before the limbs' in a [`Pose`].
const TRUNK_DOFS: usize = dof::CERVICAL.end;

/// The fastest the root rises back, m/s, once the legs no longer need it lowered.
const ROOT_RISE_SPEED: f64 = 0.3;

/// How fast the root's rise gathers speed, m/s².
const ROOT_RISE_ACCELERATION: f64 = 3.0;

/// How far below its planned height the legs hold the root, carried from frame to frame where
/// the scheduler smooths the root (`smooth_root` in [`animate`]): the root goes down at once
/// where a leg needs it (a planted foot behind a stepping body), but
/// rises back no faster than [`ROOT_RISE_SPEED`], gathering and losing speed at
/// [`ROOT_RISE_ACCELERATION`] — slowing as it comes back to where the legs need it, so it
/// rejoins their need at rest. (Released at once, the root rose 1.1 cm in three frames when
/// the trailing foot left the ground — 1.3 m/s, which the reaching hand showed.)
#[derive(Debug, Default, Clone, Copy)]
struct RootRise {
    /// The last frame's lowering, meters.
    lowered: f64,
    /// How far the legs themselves needed it lowered on the last frame, meters.
    needed: f64,
    /// How fast the root rose over the last frame, m/s.
    speed: f64,
}

impl RootRise {
    /// The least lowering for a frame of `dt` seconds.
    fn at_least(&self, dt: f64) -> f64 {
        let gap = (self.lowered - self.needed).max(0.0);
        let speed = (self.speed + ROOT_RISE_ACCELERATION * dt)
            .min(ROOT_RISE_SPEED)
            .min((2.0 * ROOT_RISE_ACCELERATION * gap).sqrt());
        (self.lowered - speed * dt).max(0.0)
    }

    /// The frame of `dt` seconds ended with the root `lowered` meters below its plan, the legs
    /// needing `needed`.
    fn ended(&mut self, lowered: f64, needed: f64, dt: f64) {
        self.speed = ((self.lowered - lowered) / dt).max(0.0);
        self.lowered = lowered.max(0.0);
        self.needed = needed.max(0.0);
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
    let body = Body::new(character, rest, plan, s)?;
    let timeline = body.timeline;
    let leg_iks = leg_iks(character)?;
    let rules = ArmRules::new(character, rest, plan, s, drive, timeline, dt)?;
    let idle_limb = Limb::arm(plan.arm.side().opposite());
    let mut idle = IdleArm::new(character, idle_limb, rest)?;
    // The other arm hangs relaxed from the first frame: held to its speed from the straight
    // rest arm, its elbow snapped 0.2 rad in the first three frames of every reach (8 rad/s).
    let mut relaxed = *rest;
    idle.relax(character, &mut relaxed);
    // Before its reach the reaching arm hangs relaxed like the other: its elbow already bent
    // a little where a reach starts (a synergy starts from `RELAXED_ELBOW` at least, and
    // from the straight rest arm that would be a one-frame snap of the elbow).
    let mut hanging = IdleArm::new(character, plan.arm, rest)?;
    // The profile's arm starts relaxed on the first frame too, where its reach starts at once:
    // from the straight rest arm the analytic solution flexes the elbow like the square root of
    // the hand's travel, and the hand could not take up the ease-out's speed within 0.1 s.
    let mut start = *rest;
    if matches!(drive, ArmDrive::Profile) {
        hanging.relax(character, &mut start);
    }
    let mut arm = ArmFollower::new(character, plan.arm, &start)?;
    if matches!(drive, ArmDrive::Profile) {
        arm = arm.driven_by_profile();
    }
    let mut head = Head::default();
    let mut phase = ArmPhase::Waiting;
    let mut synergy_limited_at_s = None;
    let mut synergy_tempo = None;
    let mut balance = BalanceCorrection::default();
    let mut rise = RootRise::default();
    // The body moves its root smoothly where a step jolts it, and wherever the profile holds
    // the hand to its world line, which shows every jolt of the shoulder one for one. A
    // person's synergy arm rides the shoulder as the fit's replay does, and on a body that only
    // bends its root moves as it always has (the synthetic sets that person retraces).
    let smooth_root = plan.step.step.steps() || matches!(drive, ArmDrive::Profile);
    let mut poses = Vec::new();
    let mut min_margin = f64::INFINITY;
    let mut stop = ReachStop::Timeout;
    let mut final_error = f64::INFINITY;
    for frame in 0..max_frames {
        let t = frame as f64 * dt;
        // The body where its controllers have brought it: state 0 the step, state 1 the
        // twist, state 2 the swing, COM adjustment and squat; then the balance correction.
        let mut pose = *rest;
        body.step(&mut pose, t);
        body.twist(&mut pose, t);
        body.swing(&mut pose, t);
        let planned = balance.carry(&mut pose);
        // State 1 also starts the head and the arm's driver.
        if t >= timeline.t_arm {
            head.turn_toward(character, &pose, &plan.target, s.head_speed * dt);
        }
        head.apply(&mut pose);
        // The reaching arm as it ended the last frame: where any driver starts from.
        pose[character.limb_dofs(plan.arm)].copy_from_slice(arm.last_posture());
        phase = phase.begin(&rules, t, &mut pose)?;
        synergy_tempo = synergy_tempo.or(phase.synergy_tempo());
        let waiting = matches!(phase, ArmPhase::Waiting);

        // Limbs, then balance.
        let feet = body.feet(t);
        let mut limbs = FrameLimbs {
            character,
            leg_iks: &leg_iks,
            feet: &feet,
            plan,
            height: planned.height,
            lowered_at_least: if smooth_root { rise.at_least(dt) } else { 0.0 },
            smooth_root,
            lowered_needed: 0.0,
            follow: phase.follow(&rules, t),
            arm: &mut arm,
            waiting: waiting.then_some(&mut hanging),
            idle: &mut idle,
            idle_limb,
            arm_base: IsometryMatrix3::identity(),
            arm_solved: ([0.0; 7], [f64::NAN; TRUNK_DOFS]),
            arm_alpha: None,
            idle_alpha: None,
        };
        let balanced = balance.balance(
            character,
            s.balance_margin,
            dt,
            &planned,
            &mut pose,
            |pose, first_pass| limbs.solve(pose, first_pass),
        );
        let (arm_alpha, idle_alpha, arm_base) = (limbs.arm_alpha, limbs.idle_alpha, limbs.arm_base);
        let arm_solved = limbs.arm_solved;
        let needed = limbs.lowered_needed;
        min_margin = min_margin.min(balanced.margin);

        // The frame's end: the arms held to their speeds, the pose within the limits, then
        // the arm's phase steps.
        let error = phase
            .hold(&rules, &mut arm, &mut pose, arm_alpha, &arm_base)
            .unwrap_or(balanced.error);
        if waiting {
            hanging.solved_at(arm_alpha);
        }
        idle.end_frame(&mut pose, idle_alpha, dt);
        character.clamp_pose(&mut pose);
        let stepped = phase.step(&rules, &mut arm, &pose, t, error)?;
        phase = stepped.phase;
        if stepped.limited && synergy_limited_at_s.is_none() {
            synergy_limited_at_s = Some(t);
        }
        final_error = stepped.error;
        rise.ended(planned.height - pose[dof::ROOT_Y], needed, dt);
        // The arm's base as the limbs' last pass left it, moved by the girdle for the arm shown,
        // where only the arms changed since (the clamp can move the trunk).
        let final_base = if pose[..TRUNK_DOFS] == arm_solved.1[..] {
            let dofs = character.limb_dofs(plan.arm);
            let shown: [f64; 7] = std::array::from_fn(|i| pose[dofs.start + i]);
            character.arm_base_moved(plan.arm, &arm_base, &arm_solved.0, &shown)
        } else {
            character.limb_base_frame(plan.arm, &pose)
        };
        arm.settle(character, &pose, &final_base, dt);
        idle.settle(&pose);
        hanging.settle(&pose);
        poses.push(pose);

        // State 3: the end.
        if let Some(end) = ending(&timeline, t, stepped.error, stepped.hand_done, s.tolerance) {
            stop = end;
            break;
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
        posture: plan.posture(character, rest),
        final_error,
        stop,
        frames,
        duration: frames as f64 * dt,
        min_balance_margin: min_margin,
        arm_onset_frame: (0..frames)
            .find(|&k| k as f64 * dt >= timeline.t_arm)
            .unwrap_or(frames),
        arm_drive: drive.kind(),
        hand_over: phase.hand_over(),
        synergy_limited_at_s,
        synergy_tempo,
    };
    Ok(ReachMotion {
        poses,
        frame_time: dt,
        report,
    })
}

/// State 3: once the body and the arm's driver are done at `t`, the reach ends — reached
/// with the hand `error` meters from the target within the `tolerance`, else, the nearest
/// point held a moment, unreachable.
fn ending(
    timeline: &Timeline,
    t: f64,
    error: f64,
    hand_done: bool,
    tolerance: f64,
) -> Option<ReachStop> {
    if !(timeline.body_done(t) && hand_done) {
        None
    } else if error <= tolerance {
        Some(ReachStop::Reached)
    } else if timeline.held_long_enough(t) {
        Some(ReachStop::Unreachable)
    } else {
        None
    }
}
