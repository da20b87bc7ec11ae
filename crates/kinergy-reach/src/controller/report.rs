//! What a full-body reach decided and achieved ([`ReachReport`]), why it ended
//! ([`ReachStop`]), and the motion itself ([`ReachMotion`]).

use std::fmt;

use kinergy_motion::nalgebra::Point3;
use serde::Serialize;

use crate::character::{Character, Limb, Pose};
use crate::steps::{self, StepDecision};

/// Why a reach ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ReachStop {
    /// The hand is within the tolerance of the target.
    Reached,
    /// Every controller finished with the hand at the nearest point it can reach.
    Unreachable,
    /// The timeout came first.
    Timeout,
}

/// How the body lowered itself toward the target.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Posture {
    /// The root was lowered (the legs bent).
    Squat,
    /// The spine swung toward a target below the resting hand, legs straight.
    Stoop,
    /// Neither.
    Upright,
}

impl Posture {
    /// `squat`, `stoop` or `upright`.
    pub fn name(self) -> &'static str {
        match self {
            Posture::Squat => "squat",
            Posture::Stoop => "stoop",
            Posture::Upright => "upright",
        }
    }
}

impl fmt::Display for Posture {
    /// Its [name](Posture::name).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl PartialEq<&str> for Posture {
    /// Whether `name` is its [name](Posture::name).
    fn eq(&self, name: &&str) -> bool {
        self.name() == *name
    }
}

/// What drove the reaching arm, in a report ([`super::ArmDrive::kind`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ArmDriveKind {
    /// The speed profile and the analytic IK ([`super::ArmDrive::Profile`]).
    Profile,
    /// A person's synergy controller ([`super::ArmDrive::Synergy`]).
    Synergy,
}

impl ArmDriveKind {
    /// `profile` or `synergy`.
    pub fn name(self) -> &'static str {
        match self {
            ArmDriveKind::Profile => "profile",
            ArmDriveKind::Synergy => "synergy",
        }
    }
}

impl fmt::Display for ArmDriveKind {
    /// Its [name](ArmDriveKind::name).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// What a reach decided and achieved. Serialized with each decision by its name.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReachReport {
    /// The reaching arm: `right_arm` or `left_arm`.
    pub arm: Limb,
    /// The step decision: `none`, `half_left`, `half_right` or `full`.
    #[serde(serialize_with = "steps::serialize_name")]
    pub step: StepDecision,
    /// The step length, meters (0 without a step).
    pub step_length: f64,
    /// Horizontal shoulder–target distance at the start, meters.
    pub horizontal_distance: f64,
    /// Total spine twist, degrees.
    pub twist_deg: f64,
    /// Total spine swing, degrees.
    pub swing_deg: f64,
    /// How far the root was lowered to squat, meters (0: none).
    pub squat_m: f64,
    /// `squat`, `stoop` or `upright`.
    pub posture: Posture,
    /// Distance from the hand to the target on the last frame, meters.
    pub final_error: f64,
    /// Why it ended.
    pub stop: ReachStop,
    /// Frames written.
    pub frames: usize,
    /// Seconds.
    pub duration: f64,
    /// The smallest margin of the COM projection inside the support polygon over the reach,
    /// meters (negative: outside).
    pub min_balance_margin: f64,
    /// The first frame the arm controller ran on (state 1).
    pub arm_onset_frame: usize,
    /// What drove the reaching arm: `profile` (the speed profile and analytic IK) or
    /// `synergy` (a person's synergy controller).
    pub arm_drive: ArmDriveKind,
    /// When plain IK took the hand over from the synergy controller, if it did.
    pub hand_over: Option<HandOver>,
    /// The time of the first frame on which the character's limits (or the arm's speed
    /// limit) held the person's synergy arm off its own step, if any: from there on the arm
    /// is not the person's synergy alone (a fit of those frames could not retrace it).
    pub synergy_limited_at_s: Option<f64>,
    /// The tempo the person's synergy arm was bounded by, when the smooth controller's
    /// bounds were made from one ([`crate::controller::reach_smoothing`]): a fit of the
    /// driven frames under these bounds retraces the arm (`kinergy synth --params` writes
    /// them into its segments file).
    pub synergy_tempo: Option<SynergyTempo>,
}

/// The reach a smooth controller's bounds were made for ([`kinergy_solver::Smoothing::for_reach`]):
/// the hand's peak speed relative to the shoulder and the reach's duration.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SynergyTempo {
    /// Peak hand speed, m/s.
    pub peak_speed_m_s: f64,
    /// Duration, seconds.
    pub duration_s: f64,
}

/// Plain inverse kinematics taking the hand over from a person's synergy controller for the
/// last centimeters (see [`super::ArmDrive::Synergy`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct HandOver {
    /// When, seconds from the reach's start.
    pub at_s: f64,
    /// How far the hand was from the target then, meters.
    pub distance_m: f64,
    /// Why.
    pub why: HandOverWhy,
    /// When plain IK stalled too and the analytic IK finished, seconds from the reach's start
    /// (`None`: plain IK finished).
    pub analytic_at_s: Option<f64>,
}

/// Why the synergy controller handed the hand over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum HandOverWhy {
    /// Its progress stalled once the body had stopped (a joint limit, a singular posture).
    Stalled,
    /// It drove longer than [`super::SYNERGY_TIME`].
    TooLong,
    /// Its step was not finite.
    NotFinite,
}

impl HandOverWhy {
    /// `stalled`, `too_long` or `not_finite`.
    pub fn name(self) -> &'static str {
        match self {
            HandOverWhy::Stalled => "stalled",
            HandOverWhy::TooLong => "too_long",
            HandOverWhy::NotFinite => "not_finite",
        }
    }
}

/// A synthesized reach.
#[derive(Debug, Clone)]
pub struct ReachMotion {
    /// One pose per frame.
    pub poses: Vec<Pose>,
    /// Seconds per frame.
    pub frame_time: f64,
    /// What happened.
    pub report: ReachReport,
}

impl ReachMotion {
    /// The reaching arm's hand point relative to its shoulder (world meters, one per frame)
    /// from the arm controller's start to the end of the motion: the hand's tip, or with
    /// `wrist` the wrist (the point a capture without a hand bone tracks).
    pub fn arm_relative(&self, character: &Character, wrist: bool) -> Vec<Point3<f64>> {
        let [shoulder, _, w, hand] = self.report.arm.joints();
        let point = if wrist { w } else { hand };
        let start = self.report.arm_onset_frame.min(self.poses.len());
        self.poses[start..]
            .iter()
            .map(|p| {
                let x = character.world_positions(p);
                Point3::from(x[point] - x[shoulder])
            })
            .collect()
    }

    /// The reaching hand's speed relative to its shoulder (m/s, between consecutive frames)
    /// from the arm controller's start to the end of the motion — or, with `to_hand_over`, to
    /// the hand-over if there was one (a person's synergy's own part).
    pub fn arm_speeds(&self, character: &Character, to_hand_over: bool) -> Vec<f64> {
        let [shoulder, _, _, hand] = self.report.arm.joints();
        let end = match self.report.hand_over {
            Some(h) if to_hand_over => {
                ((h.at_s / self.frame_time).round() as usize).min(self.poses.len())
            }
            _ => self.poses.len(),
        };
        let start = self.report.arm_onset_frame.min(end);
        let relative: Vec<_> = self.poses[start..end]
            .iter()
            .map(|p| {
                let w = character.world_positions(p);
                w[hand] - w[shoulder]
            })
            .collect();
        relative
            .windows(2)
            .map(|w| (w[1] - w[0]).norm() / self.frame_time)
            .collect()
    }
}
