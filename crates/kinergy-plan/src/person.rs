//! A person's timing for a planned path: the bell of their synergy's hand speed, measured on
//! a reach of their own, warps the path's time ([`Warp::Beta`]).

use kinergy_motion::nalgebra::Vector3;
use kinergy_reach::character::{Character, Limb};
use kinergy_reach::controller::{ReachSettings, reach_full_body_driven};
use kinergy_reach::drive::PersonArm;

use crate::error::{PlanError, Result};
use crate::rrt::Warp;

/// Where the person's bell is measured: a point 0.4 m in front of and 0.15 m below the
/// reaching shoulder at rest, meters.
const BELL_REACH: Vector3<f64> = Vector3::new(0.0, -0.15, 0.4);

/// The time warp of `arm`'s person: their synergy drives `character`'s arm from rest to a
/// point 0.4 m in front of and 0.15 m below the shoulder (as `kinergy reach --params` does);
/// the hand's speed relative to the shoulder, from the arm's onset to its end (or to a
/// hand-over: the synergy's own part), gives the peak and spread ([`Warp::from_speeds`]).
///
/// Errors: [`PlanError::NoBell`] when the motion has no bell to take.
pub fn person_warp(character: &Character, arm: &PersonArm) -> Result<Warp> {
    let at_rest = character.world_positions(&character.rest_pose());
    let front = at_rest[Limb::arm(arm.side).joints()[0]] + BELL_REACH;
    let settings = ReachSettings {
        arm: Some(arm.side),
        ..ReachSettings::default()
    };
    let motion = reach_full_body_driven(character, front, &settings, &arm.drive)?;
    let speeds = motion.arm_speeds(character, true);
    Warp::from_speeds(&speeds).ok_or(PlanError::NoBell {
        frames: speeds.len(),
    })
}
