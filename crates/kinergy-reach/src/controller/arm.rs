//! The arm controller (Huang, Kapadia & Terzopoulos §3.2, with [`crate::profile`]): the hand
//! moves on the straight line from where it is when the arm controller starts to the target
//! with the speed profile (the paper's ease-out by default); each frame the arm is solved by
//! analytic IK with Kallmann's orbit-angle search in the current shoulder frame. A goal out
//! of reach is replaced by the nearest reachable point on the shoulder→goal line, so an
//! unreachable target ends at the nearest point.
//!
//! Beyond the paper, the arm moves continuously: each frame's orbit angle is the one whose elbow is
//! nearest the last frame's (the posture nearest the last, for a nearly straight arm:
//! [`ArmFollower`]), and the arm shown *tracks* the analytic solution rather than taking it: the
//! solution's own joint velocity fed forward, the lag behind where the solution was a frame ago
//! closed in [`ARM_TRACKING_TIME`](tracking::ARM_TRACKING_TIME) no faster than the arm can brake,
//! the joint velocity changing by at most [`ARM_ACCELERATION`](tracking::ARM_ACCELERATION)·dt a
//! frame and no DoF faster than [`ARM_MAX_SPEED`](tracking::ARM_MAX_SPEED) — each bound scaling the
//! whole vector, so the arm keeps its direction of motion — and the hand's velocity in the world
//! changing by at most [`REACH_HAND_ACCELERATION`](tracking::REACH_HAND_ACCELERATION)·dt a frame.
//! Why: from the hanging, straight arm the analytic solution flexes the elbow like the square root
//! of the hand's travel (0.12 rad for the first 1.7 mm). Clamping each DoF alone let the shoulder
//! swing on while the elbow was held back, and the hand jumped sideways at 2.5 m/s; a ramped
//! joint-speed limit instead chased those solutions for 0.28 s and then dropped to the profile's
//! speed in one frame (0.7 → 0.2 m/s on 9 of 10 grid targets); a stepping body moving the shoulder
//! away from the hand's world path threw it from 0.7 to 2.1 m/s.
//!
//! The profile is read through a clock that ramps and waits for the hand ([`clock`]): a physical
//! arm cannot jump from rest to the ease-out's v_s, and an arm that lagged its goal and then
//! caught up ran the hand at 0.35 m/s (1.75 v_s). The hand's path is Huang's straight line in the
//! world, from where the hand is at the arm's onset to the target: a stepping, twisting, bending
//! body moves the shoulder, the arm takes up that motion (the world bound above, with the joints'
//! bounds leaving room for it), and the hand keeps to its line. The profile's own arm starts
//! relaxed, its elbow bent as the idle arm's hangs, where its reach starts on the first frame.
//!
//! Where the line passes too close to the shoulder for the elbow's flexion (a hand raised from
//! hanging to overhead), the goal goes out to where the elbow flexes to its limit on the
//! shoulder→goal line and the hand runs round the shoulder at the profile's speed; every solve
//! there had failed, the arm had held its last posture, and the hand, at rest 0.38 m short, had
//! jumped to 1.25 m/s once the line came clear 1.4 s later.
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
//! One file per concept: `follower.rs` the reaching arm over the frames of a reach, `clock.rs`
//! where its goal is on its line, `tracking.rs` the tracking law its joint velocity follows, `idle.rs` the arm that does not
//! reach, and `solve.rs` the analytic solve on the girdle they share (orbit search, reach
//! clamp, the fixed-point iteration) with the shoulder, hand and reach-error queries the
//! scheduler's planning asks.

mod clock;
mod follower;
mod idle;
mod solve;
mod tracking;

pub(super) use follower::{ArmFollower, ProfileTime};
pub(super) use idle::IdleArm;
pub(super) use solve::{ReachingArm, arm_ik, hand_position, shoulder_position};
