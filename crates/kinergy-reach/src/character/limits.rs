//! The character's joint limits: the values (spine joints, legs; arms are
//! [`Chain::arm`]'s), the check of a pose against them and the clamp into them.
//!
//! # Joint limits
//! Swings lie in a spherical ellipse `(sx/rx)² + (sy/ry)² ≤ 1`, twists and flexions within
//! `[min, max]` (Kallmann 2005). Arms use [`Chain::arm`]'s defaults. The other values are
//! our choice, rounded from typical active ranges of motion (e.g. the AAOS tables); a swing
//! ellipse is symmetric, so it admits as much extension as flexion:
//!
//! | joint | swing rx, ry | twist / flexion |
//! |---|---|---|
//! | root (sacral) | 90°, 45° | twist ±180° (any heading) |
//! | lumbar | 50°, 30° | twist ±20° |
//! | thoracic | 40°, 30° | twist ±35° |
//! | cervical | 60°, 45° | twist ±80° |
//! | shoulder, elbow, wrist | 130°, 100° | twist ±90°; elbow flexion 0–150°, twist ±90°; wrist 70°, 30° |
//! | hip | 120°, 45° | twist ±40° |
//! | knee | — | flexion 0–150° (backward), twist ±30° |
//! | ankle | 45°, 25° | — |

use kinergy_motion::rotation::Axis;
use kinergy_motion::{Chain, ChainJoint, Motion};
use nalgebra::Vector3;

use super::body::Character;
use super::layout::{Pose, SpineJoint};
use super::proportions::LegSegments;
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

impl Character {
    /// `Ok` when every value is finite and every rotation DoF within its limits (swings
    /// inside their ellipse, 1e-12 of slack); otherwise the first violation, naming the DoF.
    pub fn joint_limits_ok(&self, pose: &Pose) -> std::result::Result<(), String> {
        if let Some(i) = pose.iter().position(|v| !v.is_finite()) {
            return Err(format!("DoF `{}` is {}", self.dof_names[i], pose[i]));
        }
        for j in &self.joints {
            let mut k = j.first_dof + if j.translates { 3 } else { 0 };
            for m in &j.motions {
                match *m {
                    Motion::Revolute { min, max, .. } => {
                        let v = pose[k];
                        if v < min - 1e-12 || v > max + 1e-12 {
                            return Err(format!(
                                "DoF `{}` = {:.3}° is outside [{:.3}°, {:.3}°]",
                                self.dof_names[k],
                                v.to_degrees(),
                                min.to_degrees(),
                                max.to_degrees()
                            ));
                        }
                    }
                    Motion::Swing { rx, ry } => {
                        let (sx, sy) = (pose[k], pose[k + 1]);
                        let e = (sx / rx).powi(2) + (sy / ry).powi(2);
                        if e > 1.0 + 1e-12 {
                            return Err(format!(
                                "DoFs `{}`, `{}` = ({:.3}°, {:.3}°) lie outside their swing ellipse ({:.3}°, {:.3}°)",
                                self.dof_names[k],
                                self.dof_names[k + 1],
                                sx.to_degrees(),
                                sy.to_degrees(),
                                rx.to_degrees(),
                                ry.to_degrees()
                            ));
                        }
                    }
                }
                k += m.dof_count();
            }
        }
        Ok(())
    }

    /// Brings `pose` within the limits: revolute DoFs clamped, swings outside their ellipse
    /// scaled toward zero onto it (as [`Chain::clamp`]); non-finite values become 0.
    pub fn clamp_pose(&self, pose: &mut Pose) {
        for v in pose.iter_mut() {
            if !v.is_finite() {
                *v = 0.0;
            }
        }
        for j in &self.joints {
            let mut k = j.first_dof + if j.translates { 3 } else { 0 };
            for m in &j.motions {
                match *m {
                    Motion::Revolute { min, max, .. } => pose[k] = pose[k].clamp(min, max),
                    Motion::Swing { rx, ry } => {
                        let e = (pose[k] / rx).powi(2) + (pose[k + 1] / ry).powi(2);
                        if e > 1.0 {
                            let s = 1.0 / e.sqrt();
                            pose[k] *= s;
                            pose[k + 1] *= s;
                        }
                    }
                }
                k += m.dof_count();
            }
        }
    }
}
