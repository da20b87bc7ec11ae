//! Where a person meets the body: a person's parameters — one vector or a field over targets
//! ([`PersonStyle`]) — become the drive of the character's reaching arm. `kinergy reach`,
//! `plan`, `style` and `synth` (and the Python bindings) all come through here, so the base
//! frame a field is asked in, the mirror across arms and the synergy's set-up are decided
//! once.
//!
//! A field predicts a vector for a target in the reaching arm's *fitted base frame at rest*
//! ([`fitted_base_at_rest`]: the frame a fit of the character's own motion would use), so the
//! character and a capture agree on where a target is relative to the shoulder; a field
//! fitted on the other arm is asked with the frame mirrored ([`PersonStyle::params_for_arm`]).
//! The hand-over policy — a synergy that stalls or runs [`crate::controller::SYNERGY_TIME`]
//! hands over to plain IK, then to the analytic IK — belongs to the scheduler, which every
//! drive made here runs under.
//!
//! ```
//! use kinergy_motion::nalgebra::Point3;
//! use kinergy_reach::character::Character;
//! use kinergy_reach::controller::{ReachSettings, arm_dof_names, reach_full_body_driven};
//! use kinergy_reach::drive::PersonArm;
//! use kinergy_solver::{Bounds, Model, OptimizerKind, ParamSpace, ParamsFile};
//!
//! let character = Character::from_height(1.75)?;
//! // A person whose synergy is the neutral S_C on the character's arm.
//! let space = ParamSpace::new(Model::Sc, &arm_dof_names(&character), Bounds::default())?;
//! let person = ParamsFile::new(&space, OptimizerKind::Svd.default_optimizer(), &space.neutral())?;
//! let target = Point3::new(-0.3, 1.3, 0.45);
//! let arm = PersonArm::toward(&character, &person, &target, None)?;
//! let motion = reach_full_body_driven(&character, target, &ReachSettings::default(), &arm.drive)?;
//! assert!(motion.report.final_error < 0.01);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

mod knobs;
mod person_reach;

pub use knobs::{COMFORTABLE_ANGLE_DEG, HEAD_SPEED_DEG_S, HuangKnobs, START_SWING_DISTANCE_M, V_S};
pub use person_reach::{
    DEFAULT_HEIGHT_M, FLEXIBILITY, HEIGHT_M, MAX_TARGET_M, NotReached, PersonReach,
    PersonReachOutcome, PersonReachReport, Profile, TIMEOUT_S, check_settings, check_target,
};

use kinergy_motion::Side;
use kinergy_motion::nalgebra::Point3;
use kinergy_solver::{FieldUse, ParamsFile, PersonStyle};

use crate::character::Character;
use crate::controller::{ArmDrive, arm_dof_names, fitted_base_at_rest, reaching_side};
use crate::error::{ReachError, Result};

/// A person's drive of one reaching arm toward one target.
#[derive(Debug, Clone, PartialEq)]
pub struct PersonArm {
    /// The arm that reaches.
    pub side: Side,
    /// The person's synergy controller, as the scheduler runs it.
    pub drive: ArmDrive,
    /// The parameters it runs with (a field's prediction for the target, or the file).
    pub params: ParamsFile,
    /// How a field gave them; `None` for one vector.
    pub field: Option<FieldUse>,
}

impl PersonArm {
    /// The person's drive of `character`'s arm toward `target` (world meters): the arm
    /// `arm`, or the one on the target's side ([`reaching_side`]). A field is asked for the
    /// target in that arm's fitted base frame at rest.
    ///
    /// Errors: [`ReachError::Params`] when the person's parameters do not fit the target or
    /// the character's arm (a field's prediction out of bounds, other DoF names).
    pub fn toward(
        character: &Character,
        person: &dyn PersonStyle,
        target: &Point3<f64>,
        arm: Option<Side>,
    ) -> Result<PersonArm> {
        let side = reaching_side(character, target, arm);
        let base = fitted_base_at_rest(character, side)?;
        PersonArm::in_base(character, person, &(base.inverse() * target), side)
    }

    /// The person's drive of `character`'s arm on `side` toward `local`, meters in that arm's
    /// fitted base frame at rest (a captured reach's target carried over to the character,
    /// [`PersonArm::world_target`] gives it in world).
    pub fn in_base(
        character: &Character,
        person: &dyn PersonStyle,
        local: &Point3<f64>,
        side: Side,
    ) -> Result<PersonArm> {
        let at = person
            .params_for_arm(local, side)
            .map_err(|source| ReachError::Params { source })?;
        let synergy = at
            .params
            .synergy_for(&arm_dof_names(character))
            .map_err(|e| ReachError::Params { source: e.into() })?;
        Ok(PersonArm {
            side,
            drive: ArmDrive::Synergy {
                optimizer: at.params.optimizer,
                synergy,
                tempo: at.params.fit.as_ref().and_then(|f| f.tempo()),
                controller: at.params.fit.as_ref().and_then(|f| f.controller),
            },
            params: at.params,
            field: at.field,
        })
    }

    /// `local` (meters in the fitted base frame at rest of `character`'s arm on `side`) in
    /// world.
    pub fn world_target(
        character: &Character,
        local: &Point3<f64>,
        side: Side,
    ) -> Result<Point3<f64>> {
        Ok(fitted_base_at_rest(character, side)? * local)
    }
}

/// What drives the reaching arm of reaches toward many targets (a synthetic set, a scene's
/// tasks): the default speed profile, or a person whose parameters — one vector or a field —
/// are asked again for each target.
#[derive(Clone, Copy)]
pub enum Driver<'a> {
    /// [`ArmDrive::Profile`] for every reach.
    Profile,
    /// The person's synergy, for each reach their parameters for its target
    /// ([`PersonArm::toward`]).
    Person(&'a dyn PersonStyle),
}

impl std::fmt::Debug for Driver<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Driver::Profile => f.write_str("Profile"),
            Driver::Person(p) => match p.field_kernel() {
                Some((bandwidth, samples)) => write!(
                    f,
                    "Person(field of {samples} samples, bandwidth {bandwidth} m)"
                ),
                None => f.write_str("Person(one vector)"),
            },
        }
    }
}

impl Driver<'_> {
    /// The drive of `character`'s arm (`arm`, or the one on the target's side) toward
    /// `target` (world meters).
    pub fn toward(
        &self,
        character: &Character,
        target: &Point3<f64>,
        arm: Option<Side>,
    ) -> Result<ArmDrive> {
        match self {
            Driver::Profile => Ok(ArmDrive::Profile),
            Driver::Person(person) => Ok(PersonArm::toward(character, *person, target, arm)?.drive),
        }
    }

    /// Whether a person drives.
    pub fn is_person(&self) -> bool {
        matches!(self, Driver::Person(_))
    }
}
