//! A planned reach finished by a person's synergy controller (where the body does not move:
//! the synergy drives the arm alone, on the body standing).
//!
//! RRT-Connect finds a collision-free path; the person's synergy controller
//! ([`kinergy_reach::controller::SynergyArm`]) knows how they move. A reach's planned phase is
//! ended by the synergy wherever the synergy's own motion is free of obstacles: from points
//! every [`CANDIDATE_STEP`] along the smoothed path in turn, its start first (the whole
//! reach in the person's style), the synergy is run toward the hand position of the planned
//! goal, and every frame it makes is checked — within the joint limits, free of collisions with the
//! planner's clearance, and the motion from the previous frame free at the planner's
//! resolution. The first point from which the synergy arrives with every frame free wins:
//! the planned path is played to that point (timed with the phase's warp, ending at rest) and
//! the synergy moves the arm from there. Where no point's approach is free, the planned path
//! stays in force to the end.
//!
//! The synergy aims at the position the planned goal puts the hand at, not at the goal's
//! posture: it arrives within [`ARRIVED`] with its own elbow and wrist. A straight `settle`
//! phase then takes the grip to the goal's grip point with the target's orientation, the IK
//! with collision avoidance solving every frame ([`crate::task`]); where no free posture
//! follows the straight line, the settle is planned to the goal instead.
//!
//! Like the full-body reach, a synergy that stalls or runs [`SYNERGY_TIME`] seconds hands
//! over to plain inverse kinematics (damped least squares from its posture) for at most
//! [`PLAIN_IK_TIME`] seconds; an approach that does not arrive then is not used.

use kinergy_io::InvalidSetting;
use kinergy_reach::character::{Character, Pose};
use kinergy_reach::controller::{
    PLAIN_IK_TIME, PersonController, STALL_WINDOW, SYNERGY_TIME, SynergyArm, reach_smoothing,
};
use kinergy_reach::profile::CUBIC_PEAK_RATIO;
use kinergy_solver::{Optimizer, Synergy};

use crate::error::{PlanError, Result};
use crate::space::{ArmConfig, ArmSpace};

/// The synergy has arrived when the hand is this close (meters) to the planned goal's.
pub const ARRIVED: f64 = 0.005;

/// The spacing (meters of the planner's distance) of the points along a planned path the
/// synergy is tried from.
pub const CANDIDATE_STEP: f64 = 0.05;

/// How a planned phase was finished by the person's synergy.
#[derive(Debug, Clone, PartialEq)]
pub struct SynergyApproach {
    /// How far along the smoothed path the synergy started, meters of the planner's
    /// distance (0: the whole phase).
    pub from_m: f64,
    /// The smoothed path's length, meters of the planner's distance.
    pub path_m: f64,
    /// Why each earlier point's approach was not used, in order.
    pub rejected: Vec<String>,
    /// The phase's frame where the synergy takes over (counted from the phase's first frame):
    /// the last one of the planned path, the synergy's start; it moves the arm from the next.
    pub first_frame: usize,
    /// Frames the synergy (and plain IK after it) drove.
    pub frames: usize,
    /// The frame (counted from the phase's first frame) from which plain IK drove, after the
    /// synergy stalled or ran [`SYNERGY_TIME`] seconds.
    pub plain_ik_from: Option<usize>,
    /// The hand's distance to the planned goal's when the synergy arrived, meters.
    pub distance_m: f64,
}

/// A synergy run from one waypoint.
pub(crate) enum Run {
    /// Every frame free, arrived: the configurations (the first is the waypoint's, the elbow
    /// relaxed), where plain IK took over, the final distance.
    Arrived {
        configs: Vec<ArmConfig>,
        plain_ik_from: Option<usize>,
        distance: f64,
    },
    /// Not used, and why.
    Rejected(String),
}

/// The person's synergy in a planned space: the character standing in `body`, the arm's
/// configuration space, the controller.
pub(crate) struct PersonArm<'a> {
    pub character: &'a Character,
    pub body: &'a Pose,
    pub space: &'a ArmSpace,
    pub optimizer: &'a Optimizer,
    pub synergy: &'a Synergy,
    pub frame_rate: f64,
    /// The planner's reach speed, m/s, and least phase duration, s (the smooth controller's
    /// timing).
    pub reach_speed: f64,
    pub min_duration: f64,
    /// The controller the person's parameters were fitted under (`None`: not recorded, the
    /// smooth one); the paper's runs without the smooth bounds.
    pub controller: Option<kinergy_solver::ControllerKind>,
}

impl PersonArm<'_> {
    /// Runs the synergy from `from` toward the hand position of `goal`, checking every frame.
    pub(crate) fn run(&self, from: &ArmConfig, goal: &ArmConfig) -> Result<Run> {
        let limb = self.space.limb();
        let dt = 1.0 / self.frame_rate;
        let start = self.space.pose_with(self.body, from);
        let chain = self.character.limb_chain(limb);
        // The shoulder rides the girdle: each arm's hand on its own base.
        let end = |q: &ArmConfig| {
            chain
                .end_position(&self.space.base_for(q), &crate::space::arm_of(q))
                .map_err(|e| PlanError::Setting(InvalidSetting::new("character", e.to_string())))
        };
        let target = end(goal)?;
        // The smooth controller, bounded as a planned phase over the hand's distance is
        // timed: at the reach speed (no shorter than the least duration), a cubic bell.
        let distance = (end(from)? - target).norm();
        let duration = (distance / self.reach_speed).max(self.min_duration);
        let smoothing = reach_smoothing(
            self.character,
            limb,
            CUBIC_PEAK_RATIO * distance / duration,
            duration,
        );
        let reach_error = |e: kinergy_reach::ReachError| {
            PlanError::Setting(InvalidSetting::new("params", e.to_string()))
        };
        let mut arm = SynergyArm::new(
            self.character,
            limb,
            &self.character.rest_pose(),
            &start,
            target,
            PersonController {
                optimizer: self.optimizer,
                synergy: self.synergy,
                frame_time: dt,
                smoothing: (self.controller.unwrap_or_default()
                    == kinergy_solver::ControllerKind::Smooth)
                    .then_some(smoothing),
            },
            None,
        )
        .map_err(reach_error)?;
        let stall_window = ((STALL_WINDOW / dt).ceil() as usize).max(1);
        let max_frames = ((SYNERGY_TIME + PLAIN_IK_TIME) / dt).ceil() as usize + 1;
        let mut configs: Vec<ArmConfig> = Vec::new();
        let mut plain_ik_from: Option<usize> = None;
        let mut previous = *from;
        let mut distance = distance;
        for frame in 0..max_frames {
            let mut pose = start;
            arm.pose_arm(self.character, limb, &mut pose);
            self.character.clamp_pose(&mut pose);
            let q = self.space.config_of(&pose);
            if let Some(why) = self.blocked(&previous, &q) {
                return Ok(Run::Rejected(format!(
                    "frame {frame}, {distance:.3} m from the goal: {why}"
                )));
            }
            configs.push(q);
            previous = q;
            let base = self.character.limb_base_frame(limb, &pose);
            let Some(d) = arm.end_frame(&pose, &base).map_err(reach_error)? else {
                return Ok(Run::Rejected(format!(
                    "frame {frame}: the controller's step is not finite"
                )));
            };
            distance = d;
            if d <= ARRIVED {
                return Ok(Run::Arrived {
                    configs,
                    plain_ik_from,
                    distance,
                });
            }
            let t = frame as f64 * dt;
            let stalled = arm.stalled(stall_window);
            match plain_ik_from {
                None if stalled || t >= SYNERGY_TIME => {
                    arm.hand_over(dt).map_err(reach_error)?;
                    plain_ik_from = Some(frame + 1);
                }
                Some(from) if stalled || (frame - from) as f64 * dt >= PLAIN_IK_TIME => {
                    return Ok(Run::Rejected(format!(
                        "plain IK stopped {d:.3} m from the goal"
                    )));
                }
                _ => {}
            }
        }
        Ok(Run::Rejected(format!(
            "{distance:.3} m from the goal after {:.1} s",
            SYNERGY_TIME + PLAIN_IK_TIME
        )))
    }

    /// Why the frame `q` after `previous` cannot be played, if it cannot.
    fn blocked(&self, previous: &ArmConfig, q: &ArmConfig) -> Option<String> {
        if !self.space.within_limits(q) {
            return Some("outside the joint limits".into());
        }
        if let Some(contact) = self.space.contact(q) {
            return Some(contact);
        }
        (!self.space.edge_free(previous, q)).then(|| "collides between two frames".into())
    }
}
