//! A person's style as the layers above consume it: whatever file holds it (one parameters
//! file, or a field of vectors over targets that `kinergy-train` fits), the parameters for a
//! reach toward a target, seen from the reaching arm.
//!
//! Targets are meters in the reaching arm's base frame (origin at the shoulder, z lateral
//! outward, y up, x = y × z: the capture convention of [`crate::CaptureArm`]). A field is
//! fitted on one arm; for the other arm the frame is mirrored, since its x (forward for the
//! right arm) points backward for the left ([`PersonStyle::params_for_arm`]).
//!
//! ```
//! use kinergy_motion::{Side, nalgebra::Point3};
//! use kinergy_solver::{Bounds, Model, OptimizerKind, ParamSpace, ParamsFile, PersonStyle};
//!
//! let dofs = vec!["elbow".to_string()];
//! let space = ParamSpace::new(Model::Sa, &dofs, Bounds::default()).unwrap();
//! let file = ParamsFile::new(&space, OptimizerKind::Svd.default_optimizer(), &[1.5]).unwrap();
//! // One vector: the same parameters for every target and either arm.
//! let at = file.params_for_arm(&Point3::new(0.1, -0.3, 0.2), Side::Left).unwrap();
//! assert_eq!(at.params, file);
//! assert!(at.field.is_none());
//! ```

use kinergy_motion::nalgebra::Point3;
use kinergy_motion::{ArmJoints, Side};

use crate::params::ParamsFile;

/// Why a person's parameters could not be had for a target (a field's prediction out of its
/// bounds, a non-finite target): the source's own error, whose message names the field.
pub type StyleError = Box<dyn std::error::Error + Send + Sync>;

/// What a field reports of one prediction.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct FieldUse {
    /// The target the field was asked for: in the reaching arm's base frame, mirrored when
    /// the field was fitted on the other arm; meters.
    pub target_in_base_m: [f64; 3],
    /// The kernel's bandwidth, meters; infinite (`null` in JSON) for a flat field (the
    /// person's single vector everywhere).
    pub bandwidth_m: f64,
    /// The fitted reaches it holds.
    pub samples: usize,
}

/// The parameters for one reach, and how a field gave them.
#[derive(Debug, Clone, PartialEq)]
pub struct StyleAt {
    /// The parameters file the arm runs with.
    pub params: ParamsFile,
    /// Set when the parameters came from a field.
    pub field: Option<FieldUse>,
}

/// A person's synergy parameters for reaches toward any target: a [`ParamsFile`] (one
/// vector for every target) or a field over targets (`kinergy_train::PersonParams`).
pub trait PersonStyle: Send + Sync {
    /// The parameters for a reach toward `target`, meters in the base frame of the arm the
    /// parameters were fitted on.
    fn params_at(&self, target: &Point3<f64>) -> Result<ParamsFile, StyleError>;

    /// The arm a field was fitted on (`None` for one vector, or a field that does not
    /// record it): its targets are that arm's.
    fn fitted_side(&self) -> Option<Side>;

    /// A field's bandwidth (meters, infinite when flat) and sample count; `None` for one
    /// vector.
    fn field_kernel(&self) -> Option<(f64, usize)>;

    /// Whether the person was fitted on arms that end at the wrist
    /// ([`crate::FitRecord::ends_at_wrist`]); false when the file does not say.
    fn ends_at_wrist(&self) -> bool {
        false
    }

    /// A capture's arm `joints` as the person's fit saw arms: for a person fitted on arms that
    /// end at the wrist, the wrist is the end effector here too (the hand point dropped), so
    /// the synergy steers and is measured where it was learned; otherwise `joints` unchanged.
    /// A body with a hand bone would otherwise have its wrist driven by parameters the
    /// captures never decided, and its speed measured a hand's length farther out.
    fn arm_as_fitted(&self, joints: &ArmJoints) -> ArmJoints {
        let mut joints = joints.clone();
        if self.ends_at_wrist() {
            joints.hand = None;
        }
        joints
    }

    /// The parameters for a reach by the arm on `side` toward `target` (meters in that arm's
    /// base frame): across arms a field's frame is mirrored (x negated).
    fn params_for_arm(&self, target: &Point3<f64>, side: Side) -> Result<StyleAt, StyleError> {
        let mut local = *target;
        if self.fitted_side().is_some_and(|s| s != side) {
            local.x = -local.x;
        }
        let params = self.params_at(&local)?;
        let field = self.field_kernel().map(|(bandwidth_m, samples)| FieldUse {
            target_in_base_m: [local.x, local.y, local.z],
            bandwidth_m,
            samples,
        });
        Ok(StyleAt { params, field })
    }
}

impl PersonStyle for ParamsFile {
    /// The file itself, for any finite target.
    fn params_at(&self, target: &Point3<f64>) -> Result<ParamsFile, StyleError> {
        if target.iter().all(|c| c.is_finite()) {
            Ok(self.clone())
        } else {
            Err(crate::SolverError::NonFinite("the target".into()).into())
        }
    }

    fn fitted_side(&self) -> Option<Side> {
        None
    }

    fn ends_at_wrist(&self) -> bool {
        self.fit
            .as_ref()
            .is_some_and(crate::FitRecord::ends_at_wrist)
    }

    fn field_kernel(&self) -> Option<(f64, usize)> {
        None
    }
}
