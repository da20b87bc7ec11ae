//! What can go wrong in the analytic limb IK.

use super::limits::LimbDof;

/// What can go wrong in the analytic limb IK.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AnalyticError {
    /// The wrist center (or, in position mode, the end effector) is outside the shell the
    /// limb reaches: farther than the outer radius or closer than the inner one.
    #[error(
        "the target is {} by {:.3} m: it is {distance:.3} m from the shoulder and the limb reaches \
         from {inner:.3} to {reach:.3} m",
        if .distance > .reach { "beyond reach" } else { "too close to reach" },
        if .distance > .reach { .distance - .reach } else { .inner - .distance }
    )]
    Unreachable {
        /// Distance from the shoulder, meters.
        distance: f64,
        /// Outer radius, meters (`L1 + L2` for the wrist center).
        reach: f64,
        /// Inner radius, meters (`|L1 − L2|` for the wrist center).
        inner: f64,
    },
    /// No orbit angle tried gives a posture within the joint limits.
    #[error(
        "no orbit angle of the {tried} tried gives a posture within limits; at the best, α = {:.1}°, the {dof} exceeds its limit by {:.1}°",
        .best_alpha.to_degrees(),
        .excess.to_degrees()
    )]
    LimitsViolated {
        /// The orbit angle whose posture was closest to the limits (least total excess).
        best_alpha: f64,
        /// The DoF farthest outside its limits at `best_alpha`.
        dof: LimbDof,
        /// How far outside, radians (see [`Violation`](super::Violation)).
        excess: f64,
        /// Orbit angles tried.
        tried: usize,
    },
    /// Postures within limits were found but the caller's predicate rejected all of them
    /// (e.g. every one collides).
    #[error(
        "the {within_limits} postures within limits (of {tried} orbit angles tried) were all rejected"
    )]
    Rejected {
        /// Postures that were within limits and rejected.
        within_limits: usize,
        /// Orbit angles tried.
        tried: usize,
    },
    /// The chain is not a shoulder swing + twist, elbow flexion + twist, wrist swing limb.
    #[error("unsupported chain: {0}")]
    UnsupportedChain(String),
    /// A goal, target or angle has NaN or infinite values.
    #[error("{0} is not finite")]
    NonFinite(String),
    /// A setting is outside what it may be (named by its field, e.g. `OrbitSearch::step`).
    #[error(transparent)]
    Setting(#[from] kinergy_io::InvalidSetting),
}

impl kinergy_io::Classify for AnalyticError {
    /// No posture for the goal is the task's failure; a chain, setting or value that is not
    /// what the solver takes is the input's.
    fn kind(&self) -> kinergy_io::ErrorKind {
        match self {
            AnalyticError::Unreachable { .. }
            | AnalyticError::LimitsViolated { .. }
            | AnalyticError::Rejected { .. } => kinergy_io::ErrorKind::Unreachable,
            _ => kinergy_io::ErrorKind::Input,
        }
    }
}
