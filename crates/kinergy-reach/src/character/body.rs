//! The character's body: its joints, built by walking one table of joint rows
//! ([`Character::new`]), its bones, its exported skeleton, forward kinematics, and a pose
//! checked against and clamped into the joints' limits.
//!
//! Each row names a joint, its parent, where it sits in the parent's frame and how it moves (the
//! [character docs](super#the-skeleton-and-its-count) list the skeleton); walking the rows in order
//! assigns the DoF indices of a [`Pose`]. The spine joints stack up the spine frame's +z by the
//! [`SpineSegments`](super::SpineSegments); each limb hangs from its clavicle (arms) or from the
//! root (legs), its base joint turned into the limb's rest frame and the rest placed by the limb's
//! [`Chain`].
//!
//! One file per concept: `table.rs` the joint table and the character built by walking it,
//! `kinematics.rs` forward kinematics, the limbs' base frames and the shoulder girdle's turn,
//! `pose_limits.rs` a pose checked against and clamped into the joints' limits.

mod kinematics;
mod pose_limits;
mod table;

use std::ops::Range;
use std::sync::Arc;

use kinergy_motion::rotation::Axis;
use kinergy_motion::{Chain, Motion, Skeleton};
use nalgebra::{Rotation3, Vector3};

pub use kinematics::GirdleTurn;
pub(super) use kinematics::motion_rotation;
pub use pose_limits::{DofLimit, OVERHEAD_TWIST_FROM, angle_difference, wrap_or_clamp};

use super::layout::{DOF_COUNT, DofKind, Limb, Pose, dof};
use super::proportions::Proportions;

/// One joint of the [`Character`].
#[derive(Debug, Clone, PartialEq)]
pub struct CharacterJoint {
    /// The BVH name (see the [character docs](super#the-skeleton-and-its-count)).
    pub name: String,
    /// The parent joint, `None` for the root.
    pub parent: Option<usize>,
    /// Position in the parent's joint frame (world for the root), meters.
    pub offset: Vector3<f64>,
    /// Fixed rotation in the parent's frame, applied before the motions.
    pub rest: Rotation3<f64>,
    /// True for the root: three world translations come first among its DoFs.
    pub translates: bool,
    /// The rotational motions, in order (with their limits).
    pub motions: Vec<Motion>,
    /// Every DoF, translations first.
    pub dofs: Vec<DofKind>,
    /// The index of its first DoF in a [`Pose`].
    pub first_dof: usize,
    /// True for an End Site (a 0-DoF tip).
    pub end_site: bool,
    /// The BVH rotation channel order (used when it has motions or a girdle role).
    pub channel_order: [Axis; 3],
    /// Its part in the shoulder girdle, if any ([`GirdleRole`]).
    pub girdle: Option<GirdleRole>,
}

/// A joint's part in the shoulder girdle ([girdle](super::girdle)): the clavicle turns with
/// the arm's elevation, and the arm's base joint turns back by as much, so the arm's DoFs
/// stay humerothoracic (measured in a frame fixed to the thorax) while its shoulder rides the
/// clavicle's end.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GirdleRole {
    /// The sternoclavicular joint of this arm: rotated by the girdle, 0 DoFs of its own.
    Clavicle(Limb),
    /// This arm's base joint (the shoulder): the clavicle's rotation undone before its rest.
    Shoulder(Limb),
}

impl CharacterJoint {
    /// True when it rotates: it has motions or is a clavicle (the export gives it channels).
    pub fn rotates(&self) -> bool {
        !self.motions.is_empty() || matches!(self.girdle, Some(GirdleRole::Clavicle(_)))
    }

    /// Its DoFs' indices in a [`Pose`].
    pub fn dof_range(&self) -> Range<usize> {
        self.first_dof..self.first_dof + self.dofs.len()
    }
}

/// A rigid segment between two joints.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Bone {
    /// E.g. `thorax`, `right_clavicle`, `left_shank`.
    pub name: &'static str,
    /// The joint it hangs from.
    pub from: usize,
    /// The joint at its other end.
    pub to: usize,
}

/// The 21-bone, 43-DoF character (see the [character docs](super)). Immutable; poses are
/// [`Pose`]s.
#[derive(Debug, Clone)]
pub struct Character {
    pub(super) proportions: Proportions,
    pub(super) joints: Vec<CharacterJoint>,
    pub(super) bones: Vec<Bone>,
    pub(super) dof_names: Vec<String>,
    pub(super) chains: [Chain; 4],
    /// Per joint: the world orientation of its frame at rest.
    pub(super) rest_world: Vec<Rotation3<f64>>,
    pub(super) skeleton: Arc<Skeleton>,
}

impl Character {
    /// Its proportions.
    pub fn proportions(&self) -> &Proportions {
        &self.proportions
    }

    /// The joints, parents first (End Sites included); indices as in [`joint`](super::joint).
    pub fn joints(&self) -> &[CharacterJoint] {
        &self.joints
    }

    /// The joint named `name`.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The 21 bones.
    pub fn bones(&self) -> &[Bone] {
        &self.bones
    }

    /// 21.
    pub fn bone_count(&self) -> usize {
        self.bones.len()
    }

    /// 43.
    pub fn dof_count(&self) -> usize {
        self.dof_names.len()
    }

    /// Every DoF's name, in [`Pose`] order (e.g. `root_ty`, `right_elbow_flexion`).
    pub fn dof_names(&self) -> &[String] {
        &self.dof_names
    }

    /// The index of the DoF named `name`.
    pub fn dof_index(&self, name: &str) -> Option<usize> {
        self.dof_names.iter().position(|n| n == name)
    }

    /// The limb as a chain for IK, in the limb's rest frame
    /// ([`Character::limb_base_frame`]); its configuration is `&pose[limb_dofs(limb)]`.
    /// Arms are [`Chain::arm`]; legs have the hip, knee and ankle limits of the
    /// [limits](super::limits) and the toe tip `(0, toe, ankle_height)` in the ankle
    /// frame as their end effector.
    pub fn limb_chain(&self, limb: Limb) -> &Chain {
        &self.chains[limb.index()]
    }

    /// The limb's DoFs in a [`Pose`].
    pub fn limb_dofs(&self, limb: Limb) -> Range<usize> {
        limb.dofs()
    }

    /// The limb's joints: base, mid, end and tip.
    pub fn limb_joints(&self, limb: Limb) -> [usize; 4] {
        limb.joints()
    }

    /// Standing at the origin, feet flat on y = 0, facing +Z, arms hanging: every DoF 0
    /// except `root_ty` = [`Proportions::root_height`].
    pub fn rest_pose(&self) -> Pose {
        let mut pose = [0.0; DOF_COUNT];
        pose[dof::ROOT_Y] = self.proportions.root_height();
        pose
    }
}
