//! What the end effector must reach: a position, or a position and an orientation.

use kinergy_io::InvalidSetting;
use kinergy_motion::Linearization;
use kinergy_motion::nalgebra::{Point3, UnitQuaternion, Vector3};

use crate::error::{Result, SolverError};

/// The IK task.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Task {
    /// Bring the end effector to a world position (meters): the paper's reaching task.
    Position(Point3<f64>),
    /// Bring the end effector to a world position and its frame to a world orientation.
    /// Orientation errors (radians) are scaled by `weight` (meters per radian) so they are
    /// commensurate with position errors: the task error is (ΔX, weight·Δr).
    Pose {
        /// Target position, meters.
        position: Point3<f64>,
        /// Target orientation of the end frame.
        orientation: UnitQuaternion<f64>,
        /// Meters per radian of orientation error.
        weight: f64,
    },
}

/// The task error at one configuration.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TaskError {
    /// Position error X_d − X, meters.
    pub linear: Vector3<f64>,
    /// Orientation error as a world rotation vector (radians), for pose tasks.
    pub angular: Option<Vector3<f64>>,
    /// Meters per radian applied to `angular`.
    pub weight: f64,
}

impl TaskError {
    /// A position-only error.
    pub fn position(linear: Vector3<f64>) -> TaskError {
        TaskError {
            linear,
            angular: None,
            weight: 0.0,
        }
    }

    /// The error's size in meters: |ΔX|, or |(ΔX, weight·Δr)| for pose tasks.
    pub fn norm(&self) -> f64 {
        let a = self
            .angular
            .map_or(0.0, |r| (r * self.weight).norm_squared());
        (self.linear.norm_squared() + a).sqrt()
    }
}

impl Task {
    /// The target position.
    pub fn position(&self) -> Point3<f64> {
        match *self {
            Task::Position(p) | Task::Pose { position: p, .. } => p,
        }
    }

    /// Checks that the task is finite (and the weight positive).
    pub fn validate(&self) -> Result<()> {
        let p = self.position();
        if !p.coords.iter().all(|v| v.is_finite()) {
            return Err(SolverError::NonFinite(format!(
                "the target ({}, {}, {})",
                p.x, p.y, p.z
            )));
        }
        if let Task::Pose {
            orientation,
            weight,
            ..
        } = self
        {
            if !orientation.coords.iter().all(|v| v.is_finite()) {
                return Err(SolverError::NonFinite("the target orientation".into()));
            }
            InvalidSetting::require(
                weight.is_finite() && *weight > 0.0,
                "task.weight",
                "a positive number of meters per radian",
            )?;
        }
        Ok(())
    }

    /// The error of a linearized configuration.
    pub fn error(&self, lin: &Linearization) -> TaskError {
        match *self {
            Task::Position(p) => TaskError::position(p - lin.end),
            Task::Pose {
                position,
                orientation,
                weight,
            } => {
                let current = UnitQuaternion::from_rotation_matrix(&lin.end_rotation);
                // World rotation taking the current frame to the target: its rotation vector.
                let delta = orientation * current.inverse();
                TaskError {
                    linear: position - lin.end,
                    angular: Some(delta.scaled_axis()),
                    weight,
                }
            }
        }
    }
}
