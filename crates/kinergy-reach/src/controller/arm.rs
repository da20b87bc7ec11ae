//! The arm controller (Huang, Kapadia & Terzopoulos §3.2, with [`crate::profile`]): the hand
//! moves on the straight line from where it is when the arm controller starts to the target
//! with the speed profile (the paper's ease-out by default); each frame the arm is solved by
//! analytic IK with Kallmann's orbit-angle search in the current shoulder frame. A goal out
//! of reach is replaced by the nearest reachable point on the shoulder→goal line, so an
//! unreachable target ends at the nearest point.
//!
//! Beyond the paper, the arm moves continuously: each frame's orbit search starts at the previous
//! frame's orbit angle ([`ArmFollower`]), and the arm shown *tracks* the analytic solution rather
//! than taking it: the solution's own joint velocity fed forward, the lag closed in
//! [`ARM_TRACKING_TIME`](tracking::ARM_TRACKING_TIME) no faster than the arm can brake, the joint
//! velocity changing by at most [`ARM_ACCELERATION`](tracking::ARM_ACCELERATION)·dt a frame and no
//! DoF faster than [`ARM_MAX_SPEED`](tracking::ARM_MAX_SPEED) — each bound scaling the whole
//! vector, so the arm keeps its direction of motion. The hand relative to the shoulder is a
//! function of the arm's DoFs alone (the girdle follows them), so its speed cannot jump either,
//! whatever the body does. Why: from the hanging, straight arm the analytic solution flexes the
//! elbow like the square root of the hand's travel (0.12 rad for the first 1.7 mm). Clamping each
//! DoF alone let the shoulder swing on while the elbow was held back, and the hand jumped sideways
//! at 2.5 m/s; a ramped joint-speed limit instead chased those solutions for 0.28 s and then
//! dropped to the profile's speed in one frame (0.7 → 0.2 m/s on 9 of 10 grid targets); a stepping
//! body moving the shoulder away from the hand's world path threw it from 0.7 to 2.1 m/s.
//!
//! The shoulder rides the clavicle, which the girdle turns with the arm's elevation
//! ([`crate::character::girdle`]): the arm's base depends on the arm's own solution. Every solve is
//! a short fixed-point iteration ([`GIRDLE_PASSES`](solve::GIRDLE_PASSES)): solve with the base
//! where the girdle puts it for the previous frame's arm, move the base to where the girdle puts it
//! for the solution, solve again. The base moves by the clavicle's end, at most ~5 cm per radian of
//! elevation, while the solution's elevation moves by about a radian per meter of base: each pass
//! shrinks the base's error some tenfold. Near a straight arm the elevation turns much faster with
//! the base and the plain iteration can swing from side to side of the fixed point: the passes mix
//! the last two (Anderson mixing of depth one), which settles there.
//!
//! One file per concept: `follower.rs` the reaching arm over the frames of a reach,
//! `tracking.rs` the tracking law its joint velocity follows, `idle.rs` the arm that does not
//! reach, and `solve.rs` the analytic solve on the girdle they share (orbit search, reach
//! clamp, the fixed-point iteration) with the shoulder, hand and reach-error queries the
//! scheduler's planning asks.

mod follower;
mod idle;
mod solve;
mod tracking;

pub(super) use follower::{ArmFollower, ProfileTime};
pub(super) use idle::IdleArm;
pub(super) use solve::{ReachingArm, arm_ik, hand_position, shoulder_position};
