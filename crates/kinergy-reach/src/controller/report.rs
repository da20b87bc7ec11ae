//! What a full-body reach decided and achieved ([`ReachReport`]), why it ended
//! ([`ReachStop`]), and the motion itself ([`ReachMotion`]).

use serde::Serialize;

use crate::character::Pose;

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

/// What a reach decided and achieved.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReachReport {
    /// The reaching arm.
    pub arm: &'static str,
    /// The step decision: `none`, `half_left`, `half_right` or `full`.
    pub step: String,
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
    pub posture: &'static str,
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
