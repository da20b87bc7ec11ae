//! The character's joint limits: the values (spine joints, legs; arms are
//! [`Chain::arm`]'s). A pose is checked against them and clamped into them by
//! [`Character::joint_limits_ok`](super::Character::joint_limits_ok) and
//! [`Character::clamp_pose`](super::Character::clamp_pose).
//!
//! # Joint limits
//! Swings lie in a spherical ellipse `(sx/rx)² + (sy/ry)² ≤ 1`, twists and flexions within
//! `[min, max]` (Kallmann 2005). Arms use [`Chain::arm`]'s elbow and wrist, and a shoulder
//! whose swing is the arm's humerothoracic elevation: the glenohumeral joint's 130° in every
//! plane ([`GLENOHUMERAL_MAX`]: [`Chain::arm`]'s flexion radius, Inman's 120° GH abduction
//! rounded up) plus the girdle's share by the scapulohumeral rhythm
//! ([girdle](super::girdle)) gives 180°, the AAOS flexion and abduction (1965). The ellipse
//! being symmetric, it admits as much extension and adduction as flexion and abduction (the
//! tables give about 60° and 45°, NASA-STD-3000 vol. I fig. 3.3.2.3-1: 61°, 48°); the
//! analytic IK's orbit search and the reach controllers do not seek them. The other values are
//! our choice, rounded from typical active ranges of motion (e.g. the AAOS tables); a swing
//! ellipse is symmetric, so it admits as much extension as flexion:
//!
//! | joint | swing rx, ry | twist / flexion |
//! |---|---|---|
//! | root (sacral) | 90°, 45° | twist ±180° (any heading) |
//! | lumbar | 50°, 30° | twist ±20° |
//! | thoracic | 40°, 30° | twist ±35° |
//! | cervical | 60°, 45° | twist ±80° |
//! | shoulder (humerothoracic) | 180°, 180° | twist ±90° |
//! | elbow, wrist | — | elbow flexion 0–150°, twist ±90°; wrist 70°, 30° |
//! | hip | 120°, 45° | twist ±40° |
//! | knee | — | flexion 0–150° (backward), twist ±30° |
//! | ankle | 45°, 25° | — |

use kinergy_motion::rotation::Axis;
use kinergy_motion::{Chain, ChainJoint, Motion};
use nalgebra::Vector3;

use super::girdle::{GLENOHUMERAL_MAX, Girdle};
use super::layout::SpineJoint;
use super::proportions::{ArmSegments, LegSegments};
use crate::error::Result;

/// A rotation about `axis` within `[min_deg, max_deg]` degrees.
fn revolute(axis: Axis, min_deg: f64, max_deg: f64) -> Motion {
    Motion::Revolute {
        axis,
        min: min_deg.to_radians(),
        max: max_deg.to_radians(),
    }
}

/// A swing within the ellipse of radii `rx_deg`, `ry_deg` degrees.
fn swing(rx_deg: f64, ry_deg: f64) -> Motion {
    Motion::Swing {
        rx: rx_deg.to_radians(),
        ry: ry_deg.to_radians(),
    }
}

/// A spine joint's motions: a swing within its ellipse `(rx, ry)`, then a twist within ±its
/// bound (the table above).
pub(super) fn spine_motions(joint: SpineJoint) -> Vec<Motion> {
    let (rx, ry, twist) = match joint {
        SpineJoint::Sacral => (90.0, 45.0, 180.0),
        SpineJoint::Lumbar => (50.0, 30.0, 20.0),
        SpineJoint::Thoracic => (40.0, 30.0, 35.0),
        SpineJoint::Cervical => (60.0, 45.0, 80.0),
    };
    vec![swing(rx, ry), revolute(Axis::Z, -twist, twist)]
}

/// A leg as a chain: hip swing (120°, 45°) + twist ±40°, knee flexion 0–150° + twist ±30°,
/// ankle swing (45°, 25°); the end effector is the toe tip `(0, toe, ankle_height)`.
pub(super) fn leg_chain(leg: &LegSegments) -> Result<Chain> {
    Ok(Chain::new(
        vec![
            ChainJoint::new(
                "hip",
                Vector3::zeros(),
                vec![swing(120.0, 45.0), revolute(Axis::Z, -40.0, 40.0)],
            ),
            ChainJoint::new(
                "knee",
                Vector3::new(0.0, 0.0, leg.thigh),
                vec![
                    revolute(Axis::X, 0.0, 150.0),
                    revolute(Axis::Z, -30.0, 30.0),
                ],
            ),
            ChainJoint::new(
                "ankle",
                Vector3::new(0.0, 0.0, leg.shank),
                vec![swing(45.0, 25.0)],
            ),
        ],
        Vector3::new(0.0, leg.toe, leg.ankle_height),
    )?)
}

/// The largest humerothoracic elevation of the arm, radians: the glenohumeral limit with the
/// girdle's share (180°).
pub fn shoulder_elevation_max() -> f64 {
    Girdle::elevation_for_glenohumeral(GLENOHUMERAL_MAX)
}

/// An arm as a chain: [`Chain::arm`]'s joints with the shoulder's swing bounded by
/// [`shoulder_elevation_max`] in every plane (module docs).
pub(super) fn arm_chain(arm: &ArmSegments) -> Result<Chain> {
    let default = Chain::arm(arm.upper_arm, arm.forearm, arm.hand)?;
    let top = shoulder_elevation_max();
    let joints = default
        .joints()
        .iter()
        .enumerate()
        .map(|(i, j)| {
            let mut j = j.clone();
            if i == 0 {
                for m in &mut j.motions {
                    if let Motion::Swing { rx, ry } = m {
                        (*rx, *ry) = (top, top);
                    }
                }
            }
            j
        })
        .collect();
    Ok(Chain::new(joints, default.end_effector())?)
}
