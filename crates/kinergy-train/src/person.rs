//! A person's parameters, from whichever file holds them: a parameters file (one vector for
//! every target, `kinergy fit`) or a field file (a vector per target, `kinergy fit --field`,
//! [`FieldFile`]). Every consumer — `synthesize`, `reach`, `plan` — reads them with
//! [`PersonParams::read`] and asks [`PersonParams::params_for`] for the plain
//! [`ParamsFile`] of the target at hand, so none of them needs to know which file it was given.
//!
//! Targets are meters in the arm's base frame (origin at the shoulder, z lateral outward, y up,
//! x = y × z: the capture convention of [`kinergy_solver::CaptureArm`]); for a captured reach,
//! [`crate::CapturedReach::to_local`] puts a world point there.
//!
//! ```
//! use kinergy_motion::nalgebra::Point3;
//! use kinergy_solver::{Bounds, Model, OptimizerKind, ParamSpace, ParamsFile};
//! use kinergy_train::person::PersonParams;
//!
//! let dofs = vec!["elbow".to_string()];
//! let space = ParamSpace::new(Model::Sa, &dofs, Bounds::default()).unwrap();
//! let file = ParamsFile::new(&space, OptimizerKind::Svd.default_optimizer(), &[1.5]).unwrap();
//! let person = PersonParams::from_json(&file.to_json()).unwrap();
//! // One vector: the same file for every target.
//! assert_eq!(person.params_for(&Point3::new(0.1, -0.3, 0.2)).unwrap(), file);
//! assert!(person.field().is_none());
//! ```

use std::path::Path;

use kinergy_io::InvalidSetting;
use kinergy_motion::Side;
use kinergy_motion::nalgebra::Point3;
use kinergy_solver::{FitRecord, Model, Optimizer, ParamsFile, PersonStyle, StyleError};

use crate::error::{Result, TrainError, in_file};
use crate::field::FieldFile;

/// A person's parameters: one vector, or a field over targets.
#[derive(Debug, Clone, PartialEq)]
pub enum PersonParams {
    /// One vector for every target (a parameters file).
    Vector(ParamsFile),
    /// A vector per target (a field file).
    Field(FieldFile),
}

impl PersonParams {
    /// Reads a parameters file or a field file, told apart by their content (a field file
    /// has `samples`, a parameters file `values`). Errors ([`TrainError::File`]) name the
    /// file and the field, or say it is neither.
    pub fn read(path: &Path) -> Result<PersonParams> {
        let text =
            kinergy_io::read_to_string_limited(path, kinergy_io::MAX_JSON_BYTES).map_err(|e| {
                TrainError::File {
                    path: Some(path.to_path_buf()),
                    why: format!("cannot read it: {e}"),
                }
            })?;
        PersonParams::from_json(&text).map_err(|e| in_file(e, path))
    }

    /// [`PersonParams::read`] from a file's text.
    pub fn from_json(text: &str) -> Result<PersonParams> {
        let bad = |why: String| TrainError::File { path: None, why };
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| bad(format!("not JSON: {e}")))?;
        if value.get("samples").is_some() {
            return FieldFile::from_json(text).map(PersonParams::Field);
        }
        if value.get("values").is_some() {
            return ParamsFile::from_json(text)
                .map(PersonParams::Vector)
                .map_err(|e| bad(e.to_string()));
        }
        Err(bad(
            "neither a parameters file (from `kinergy fit`, with `values`) nor a field file \
             (from `kinergy fit --field`, with `samples`)"
                .into(),
        ))
    }

    /// The parameters for a reach to `target` (meters in the arm's base frame, finite; else
    /// a `target` error): the parameters file itself, or the one the field predicts there
    /// ([`FieldFile::params_for`]: in bounds, the field's model, optimizer, DoF names and
    /// arms).
    pub fn params_for(&self, target: &Point3<f64>) -> Result<ParamsFile> {
        match self {
            PersonParams::Vector(file) => {
                InvalidSetting::require(
                    target.iter().all(|c| c.is_finite()),
                    "target",
                    "finite coordinates",
                )?;
                Ok(file.clone())
            }
            PersonParams::Field(field) => field.params_for(target),
        }
    }

    /// The field, when the parameters are one.
    pub fn field(&self) -> Option<&FieldFile> {
        match self {
            PersonParams::Vector(_) => None,
            PersonParams::Field(field) => Some(field),
        }
    }

    /// How the parameters were fitted: the parameters file's record (if it has one), or the
    /// field's ([`FieldFile::record`]: its reaches, their frames and arms).
    pub fn record(&self) -> Option<FitRecord> {
        match self {
            PersonParams::Vector(file) => file.fit.clone(),
            PersonParams::Field(field) => Some(field.record()),
        }
    }

    /// The synergy model.
    pub fn model(&self) -> Model {
        match self {
            PersonParams::Vector(file) => file.model,
            PersonParams::Field(field) => field.model(),
        }
    }

    /// The optimizer a controller runs with.
    pub fn optimizer(&self) -> Optimizer {
        match self {
            PersonParams::Vector(file) => file.optimizer,
            PersonParams::Field(field) => field.optimizer(),
        }
    }
}

/// How the layers above ask for a person's parameters (the full-body drive in
/// `kinergy-reach`, `synthesize`): the file's vector, or the field's prediction.
impl PersonStyle for PersonParams {
    fn params_at(&self, target: &Point3<f64>) -> std::result::Result<ParamsFile, StyleError> {
        Ok(self.params_for(target)?)
    }

    fn fitted_side(&self) -> Option<Side> {
        self.field().and_then(|f| f.arm()).and_then(|a| a.side)
    }

    fn field_kernel(&self) -> Option<(f64, usize)> {
        self.field()
            .map(|f| (f.field().bandwidth(), f.field().len()))
    }

    fn ends_at_wrist(&self) -> bool {
        self.record().is_some_and(|r| r.ends_at_wrist())
    }
}
