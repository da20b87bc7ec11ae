//! The full-body reaching controllers and their scheduler (Huang, Kapadia & Terzopoulos §3–4;
//! DESIGN §1.2).
//!
//! A reach is first **planned** from the rest posture — every decision made once, from the
//! seeded generator — then **animated** frame by frame:
//!
//! - **Legs** ([`crate::steps`]): the target's horizontal distance from the reaching
//!   shoulder against the CRR and MRR cylinders decides no step, a half step or a full step
//!   and its length (eq. 9) toward `d_p`; the stepping foot follows the convex foot path,
//!   the root the concave root path (a half step moves the root half the step). Planted feet
//!   stay exactly where they are: every frame both legs are solved by analytic IK for their
//!   foot frames.
//! - **Spine twist**: the total twist θ is searched (1° steps) until the target's horizontal
//!   direction from the shoulder lies within the comfortable reaching angle of the chest's
//!   forward direction (eq. 6), and split equally over sacral, lumbar and thoracic joints
//!   (eq. 5).
//! - **Spine swing**: when the vertical shoulder–target distance exceeds the start swing
//!   distance, or the arm cannot reach, the spine swings about `s = d × y` (eq. 7), the angle
//!   raised in 1° steps (split equally over the three joints, within their limits) until the
//!   arm can reach; the root moves by `r = −kφ d_p` (eq. 8, `k = r_max/φ_max`) to keep the
//!   COM over the feet. **Squat or stoop**: when the shoulder is higher above the target than
//!   the stoop range `arm length / flexibility`, the root is lowered by the excess (within
//!   what the legs allow) before the swing is searched; a low flexibility stoops instead.
//! - **Arm** ([`crate::profile`]): the hand moves on the straight line from where it is when
//!   the arm controller starts to the target with the speed profile (the paper's ease-out by
//!   default); each frame the arm is solved by analytic IK with Kallmann's orbit-angle search
//!   in the current shoulder frame. A goal out of reach is replaced by the nearest reachable
//!   point on the shoulder→goal line, so an unreachable target ends at the nearest point.
//!   Beyond the paper: the line is held in the world while the body moves under it; the
//!   profile is read through a clock that takes the hand from its own speed to the profile's in
//!   0.08 s and waits where the arm lags; the arm shown tracks the analytic solution within
//!   joint and hand bounds; a line passing too close to the shoulder for the elbow is rounded
//!   at the profile's speed (`arm.rs`).
//!   The paper's ease-out hand is within 5 % of v_s 0.075 s after the arm's onset from rest and
//!   holds it within 1.5 % until its deceleration; a stepping reach's hand, carried at up to
//!   1 m/s at the onset, is within 5 % of v_s after 0.13–0.15 s and within 2 cm of its line
//!   (1.9 cm at the onset, 0.2 cm after) wherever the arm can reach the line
//!   (`tests/profile_realtime.rs`).
//! - **Head**: turns toward the target at a bounded angular speed, then tracks it.
//! - **Balance** (beyond the paper): after composing a frame, if the COM's ground projection
//!   is less than `balance_margin` inside the support polygon, the root is shifted
//!   horizontally to bring it back, and the limbs solved again.
//! - **Scheduler**: state 0 starts the step; state 1 (the step has progressed `r_st`, or no
//!   step) starts arm, head and twist; state 2 (the twist has progressed `r_tw`, or no
//!   twist) starts swing, COM adjustment and squat; state 3 ends when the hand is at the
//!   target and every controller has finished, or at the timeout.
//!
//! # Arm driven by a person's synergy
//! With [`ArmDrive::Synergy`] ([`reach_full_body_driven`]) the scheduler decides and moves
//! the body as above, and the reaching arm is driven from state 1 on by a person's fitted
//! synergy controller (their model, optimizer and values, from `kinergy fit`) instead of the
//! profile and the analytic IK: each frame the controller steps from where the trunk has
//! carried the shoulder, in the convention it was fitted in (the capture arm's base: z out
//! of the shoulder, y up), its arm clamped into the character's limits. Where it cannot
//! finish — progress stalled for [`STALL_WINDOW`] once the body has stopped, more than
//! [`SYNERGY_TIME`], a step not finite — plain inverse kinematics (damped least squares from
//! the posture the synergy left) takes the hand the last centimeters, and
//! [`ReachReport::hand_over`] says so.
//!
//! One (private) file per controller — `legs.rs`, `spine.rs`, `head.rs`, `arm.rs`,
//! `balance.rs` (with the balance correction carried from frame to frame), `synergy.rs` (a
//! person's arm), `stance.rs` (the spine and the squat as one posture with the feet planted,
//! for a planner: [`Stance`], [`standing_stances`]) — and the scheduler's: `plan.rs` (every decision, made once),
//! `timeline.rs` (when the body's controllers start, and the body they bring about),
//! `phase.rs` (the reaching arm's phases: waiting, analytic, synergy, plain IK, each stepping
//! to the next) and `scheduler.rs`, which animates the states frame by frame;
//! [`ReachSettings`] tune a reach and [`ReachReport`] says what happened.
//!
//! ```
//! use kinergy_motion::nalgebra::Point3;
//! use kinergy_reach::character::Character;
//! use kinergy_reach::controller::{ReachSettings, ReachStop, reach_full_body};
//!
//! let character = Character::from_height(1.75)?;
//! let target = Point3::new(0.3, 1.1, 0.4);
//! let motion = reach_full_body(&character, target, &ReachSettings::default())?;
//! assert_eq!(motion.report.stop, ReachStop::Reached);
//! let clip = character.to_clip(&motion.poses, motion.frame_time)?;
//! assert_eq!(clip.frame_count(), motion.report.frames);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod arm;
mod balance;
mod ending;
mod head;
mod legs;
mod phase;
mod plan;
mod report;
mod scheduler;
mod settings;
mod spine;
mod stance;
mod synergy;
mod timeline;

use kinergy_io::InvalidSetting;
use kinergy_motion::nalgebra::Point3;

pub use ending::Ending;
pub use plan::reaching_side;
pub use report::{
    ArmDriveKind, HandOver, HandOverWhy, Posture, ReachMotion, ReachReport, ReachStop, SynergyTempo,
};
pub use settings::{ReachSettings, SynergyStart};
pub use stance::{
    PlantedLegs, Stance, StanceCandidate, StanceLimits, pose_stance, stance_limits,
    standing_stances,
};
pub use synergy::{
    ArmDrive, PLAIN_IK_TIME, PersonController, RELAXED_ELBOW, STALL_PROGRESS, STALL_WINDOW,
    SYNERGY_TIME, SynergyArm, TWIST_BRAKE_BELOW, arm_dof_names, fitted_base_at_rest,
    reach_smoothing,
};

use crate::character::Character;
use crate::error::Result;

/// Synthesizes a full-body reach of `character` toward `target` (world meters) from the
/// rest posture, the arm on the speed profile ([`ArmDrive::Profile`]).
pub fn reach_full_body(
    character: &Character,
    target: Point3<f64>,
    settings: &ReachSettings,
) -> Result<ReachMotion> {
    reach_full_body_driven(character, target, settings, &ArmDrive::Profile)
}

/// [`reach_full_body`] with the reaching arm driven by `drive`: with
/// [`ArmDrive::Synergy`], a person's synergy controller moves the arm on the body the
/// scheduler moves (module [`synergy`](self#arm-driven-by-a-persons-synergy)).
pub fn reach_full_body_driven(
    character: &Character,
    target: Point3<f64>,
    settings: &ReachSettings,
    drive: &ArmDrive,
) -> Result<ReachMotion> {
    let plan = plan_reach(character, target, settings)?;
    animate_reach(character, &plan, settings, drive)
}

/// A reach's plan: every decision made once before the first frame — the arm, the step, the
/// posture (twist, swing, squat, COM shift) and the timeline ([`plan_reach`]).
#[derive(Debug, Clone)]
pub struct ReachPlan {
    plan: plan::Plan,
}

impl ReachPlan {
    /// The target the plan reaches for, world meters.
    pub fn target(&self) -> Point3<f64> {
        self.plan.target
    }
}

/// Plans a full-body reach of `character` toward `target` from the rest posture (the first
/// half of [`reach_full_body_driven`]; [`animate_reach`] is the second).
pub fn plan_reach(
    character: &Character,
    target: Point3<f64>,
    settings: &ReachSettings,
) -> Result<ReachPlan> {
    settings.validate()?;
    InvalidSetting::require(
        target.coords.iter().all(|v| v.is_finite()),
        "target",
        "finite coordinates",
    )?;
    let rest = character.rest_pose();
    Ok(ReachPlan {
        plan: plan::plan(character, &rest, target, settings)?,
    })
}

/// Animates a [`ReachPlan`] frame by frame from the rest posture, the reaching arm driven by
/// `drive` (`settings` as the plan was made with: the frame rate, profile and timeout are
/// read here).
pub fn animate_reach(
    character: &Character,
    plan: &ReachPlan,
    settings: &ReachSettings,
    drive: &ArmDrive,
) -> Result<ReachMotion> {
    settings.validate()?;
    let rest = character.rest_pose();
    scheduler::animate(character, &rest, &plan.plan, settings, drive)
}
