//! The reaching arm driven by a person's synergy controller (Aubry et al.) instead of the speed
//! profile and the analytic IK: the scheduler moves the body as always, and each frame the
//! person's controller takes one step toward the target from where the trunk has carried the
//! shoulder ([`kinergy_solver::ArmStepper`]) — the same step a fit replays on a captured torso.
//!
//! # Conventions
//! The person's parameters were fitted on [`kinergy_solver::CaptureArm`]'s chain, whose base
//! rides the clavicle with z pointing sideways out of the shoulder, y up and x = y × z (at
//! rest) — its zero swing is the arm raised sideways. The character's own arm chain (the same
//! [`kinergy_motion::Chain::arm`], same bone lengths) has its base turned so that its zero is
//! the hanging arm. Both bases ride the clavicle, so one constant rotation `K` (character
//! base → capture base) relates them: the controller runs in the capture convention, on the
//! base `R_character · K`, and its shoulder rotation is carried over as
//! `R_character_shoulder = K · R_capture_shoulder` (split again into swing and twist); elbow
//! and wrist DoFs are the same in both.
//!
//! # Limits
//! The character's limits are the character's: a configuration the controller reaches is
//! clamped into them, and the controller continues from the clamped arm. The controller's own
//! chain (`synergy_chain`) has the character's elbow and wrist limits but bounds the shoulder
//! only away from its convention's singular swing of π (the arm across the chest), its twist
//! open to ±π: the generic table's shoulder limits read in the capture convention are not the
//! character's anatomical ones (the hanging arm sits on their ±90° twist, and every raise turns
//! it further), and the character's humerothoracic limits ([`crate::character::girdle`]) clamp
//! the arm anyway. The synergy arm has arrived when the
//! hand is within half the reach's tolerance.
//!
//! # Hand-over
//! Where the synergy arm alone cannot finish — its progress stalls for [`STALL_WINDOW`]
//! seconds once the body has stopped, its step is not finite, or [`SYNERGY_TIME`] seconds
//! pass — plain inverse kinematics takes the hand the last centimeters from the posture the
//! synergy left: the same controller with damped least squares and no synergy (every gain 1,
//! no timing), so the arm keeps its posture and only closes the gap. (The analytic IK's
//! solution for the target can lie far from that posture in joint space: going there, the
//! hand of a real capture's synergy swung 0.99 m away before coming back.) Only if plain IK
//! stalls too, or drives more than a second, does the analytic IK finish (in the character's
//! own limits). The report says when, from how far and who finished ([`super::HandOver`]).
//!
//! One file per concept: `arm.rs` the synergy arm frame by frame ([`SynergyArm`]) and the
//! chain it steps, `conventions.rs` the character's arm convention and the fitted one,
//! `brake.rs` the brake before the character's limits.

mod arm;
mod brake;
mod conventions;

use kinergy_motion::Side;
use kinergy_motion::nalgebra::IsometryMatrix3;
use kinergy_solver::{Optimizer, PersonTempo, Smoothing, Synergy};

pub use arm::{PersonController, SynergyArm};
pub use brake::TWIST_BRAKE_BELOW;

use super::report::ArmDriveKind;
use crate::character::{Character, Limb};
use crate::error::Result;
use conventions::capture_rotation;

/// How long (seconds) the synergy arm's progress may stall, once the body has stopped,
/// before the analytic IK takes over.
pub const STALL_WINDOW: f64 = 0.25;

/// The least progress (meters) over [`STALL_WINDOW`] that is not a stall.
pub const STALL_PROGRESS: f64 = 1e-4;

/// The longest the synergy arm drives (seconds after it started) before the analytic IK
/// takes over.
pub const SYNERGY_TIME: f64 = 4.0;

/// The longest plain inverse kinematics drives after a hand-over (seconds) before the
/// analytic IK finishes.
pub const PLAIN_IK_TIME: f64 = 1.0;

/// The elbow flexion the synergy starts from at least, radians.
pub const RELAXED_ELBOW: f64 = 0.17;

/// What drives the reaching arm.
#[derive(Debug, Clone, Default, PartialEq)]
#[allow(
    clippy::large_enum_variant,
    reason = "one per reach, never held in bulk: a box would only add an indirection"
)]
pub enum ArmDrive {
    /// The speed profile of [`super::ReachSettings::profile`] along the straight line to the
    /// target, the arm solved by analytic IK every frame (Huang et al.).
    #[default]
    Profile,
    /// A person's synergy controller: their optimizer and synergy (model and values), as a
    /// parameters file holds them ([`kinergy_solver::ParamsFile::synergy_for`] with
    /// [`arm_dof_names`]).
    Synergy {
        /// Turns the task error into a joint step.
        optimizer: Optimizer,
        /// The person's synergy.
        synergy: Synergy,
        /// The person's tempo over their fitted reaches ([`kinergy_solver::FitRecord::tempo`]):
        /// the smooth controller's bounds are those of a reach of theirs over the hand's
        /// distance. `None` (files without it): a reach peaking at 1 m/s (`SYNERGY_PEAK_SPEED`)
        /// or the profile's peak, whichever is faster.
        tempo: Option<PersonTempo>,
        /// The controller the person's parameters were fitted under
        /// ([`kinergy_solver::FitRecord::controller`]), what the arm runs unless the settings
        /// choose ([`super::ReachSettings::synergy_controller`]); `None`: not recorded (smooth).
        controller: Option<kinergy_solver::ControllerKind>,
    },
}

impl ArmDrive {
    /// Which drive, without its values: what a report says.
    pub fn kind(&self) -> ArmDriveKind {
        match self {
            ArmDrive::Profile => ArmDriveKind::Profile,
            ArmDrive::Synergy { .. } => ArmDriveKind::Synergy,
        }
    }

    /// `profile` or `synergy`.
    pub fn name(&self) -> &'static str {
        self.kind().name()
    }
}

/// The DoF names of the character's arm chain (the same as a captured arm's), in order: what
/// a parameters file's `dof_names` must be.
pub fn arm_dof_names(character: &Character) -> Vec<String> {
    character
        .limb_chain(Limb::RightArm)
        .dof_names()
        .map(String::from)
        .collect()
}

/// The base frame of the arm on `side` at rest, as a fit of the character's motion defines
/// it ([`kinergy_solver::CaptureArm`]: at the shoulder, z out of it sideways, y up, x = y ×
/// z): the frame a parameter field's targets are given in.
pub fn fitted_base_at_rest(character: &Character, side: Side) -> Result<IsometryMatrix3<f64>> {
    let limb = Limb::arm(side);
    let rest = character.rest_pose();
    let k = capture_rotation(character, limb, &rest)?;
    let base = character.limb_base_frame(limb, &rest);
    Ok(IsometryMatrix3::from_parts(
        base.translation,
        base.rotation * k,
    ))
}

/// The smooth controller's bounds ([`Smoothing::for_reach`]) for the synergy arm of `limb`
/// on a reach planned to peak at `peak_speed` m/s over `duration` seconds (the reach's speed
/// profile): the hand starts from rest and its acceleration is bounded as the profile's is,
/// so the first frames have no speed spike.
pub fn reach_smoothing(
    character: &Character,
    limb: Limb,
    peak_speed: f64,
    duration: f64,
) -> Smoothing {
    let a = character.proportions().arm(limb.side());
    Smoothing::for_reach(peak_speed, duration, a.upper_arm + a.forearm + a.hand)
}
