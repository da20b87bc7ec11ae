//! The character's index tables: joint and DoF indices ([`joint`], [`dof`]), the four limbs
//! ([`Limb`]) and the spine joints ([`SpineJoint`]), what each DoF does ([`DofKind`]) and the
//! orientation of the joint frames at rest.
//!
//! # DoFs, frames and the order of the 43-vector
//! Every rotating joint composes, in its parent's frame, a fixed *rest* rotation and then its
//! motions (exactly [`kinergy_motion::ChainJoint`]'s model): `R = rest · S(sx, sy) · R_z(τ)`
//! for swing + twist, `rest · R_x(φ) · R_z(τ)` for flexion + twist, `rest · S(sx, sy)` for a
//! swing, with `S(sx, sy) = exp([(sx, sy, 0)]×)` (Huang's split of a rotation into a swing
//! about an axis in the joint's x–y plane and a twist about its z axis). The root translates
//! first (along world axes), then rotates. World orientation of the joint frames at rest:
//!
//! | frames | x | y | z (the bone) | so that |
//! |---|---|---|---|---|
//! | spine (root … head) | +X (left) | −Z (back) | +Y (up) | swing_x > 0 bends forward, swing_y > 0 bends left, twist > 0 turns left |
//! | arms (both) | −X | −Z | −Y (down) | shoulder swing_x > 0 raises the arm forward, swing_y > 0 swings it toward −X (abducts the right arm, adducts the left); elbow flexion > 0 brings the forearm forward |
//! | legs (both) | +X | +Z | −Y (down) | hip swing_x < 0 raises the thigh forward (flexion), swing_y > 0 swings it toward +X; knee flexion > 0 bends the shank backward; ankle swing_x > 0 points the toe down |
//!
//! A limb's *rest frame* is the frame of its base joint before its motions: with all its
//! DoFs at zero the limb hangs straight along the frame's +z, which is what
//! [`Chain::arm`] expects. [`Character::limb_base_frame`] gives it in world for a pose and
//! [`Character::limb_chain`] the chain; `chain.end_position(base_frame, &pose[limb_dofs])`
//! is the limb's tip (fingertip, toe tip).
//!
//! | indices | DoFs ([`Character::dof_names`]) |
//! |---|---|
//! | 0–2 | `root_tx`, `root_ty`, `root_tz`: world position of the sacral joint, meters |
//! | 3–5 | `root_swing_x`, `root_swing_y`, `root_twist` |
//! | 6–8, 9–11, 12–14 | `lumbar_…`, `thoracic_…`, `cervical_…`: swing_x, swing_y, twist |
//! | 15–21, 22–28 | `right_…`, `left_…`: `shoulder_swing_x`, `shoulder_swing_y`, `shoulder_twist`, `elbow_flexion`, `elbow_twist`, `wrist_swing_x`, `wrist_swing_y` |
//! | 29–35, 36–42 | `right_…`, `left_…`: `hip_swing_x`, `hip_swing_y`, `hip_twist`, `knee_flexion`, `knee_twist`, `ankle_swing_x`, `ankle_swing_y` |
//!
//! [`Chain::arm`]: kinergy_motion::Chain::arm
//! [`Character::limb_base_frame`]: super::Character::limb_base_frame
//! [`Character::limb_chain`]: super::Character::limb_chain
//! [`Character::dof_names`]: super::Character::dof_names

use std::fmt;
use std::ops::Range;

use kinergy_motion::Side;
use kinergy_motion::rotation::Axis;
use nalgebra::{Matrix3, Rotation3, Vector3};
use serde::{Deserialize, Serialize};

/// The character's number of DoFs, the length of a [`Pose`].
pub const DOF_COUNT: usize = 43;

/// The character's number of bones.
pub const BONE_COUNT: usize = 21;

/// A pose of the character: [`DOF_COUNT`] values (meters for the root translation,
/// radians otherwise) in the order of the [module docs](self).
pub type Pose = [f64; DOF_COUNT];

/// Indices of the character's joints in [`Character::joints`](super::Character::joints) (and
/// in the exported skeleton).
pub mod joint {
    /// The sacral root.
    pub const HIPS: usize = 0;
    /// The lumbar joint.
    pub const SPINE: usize = 1;
    /// The thoracic joint.
    pub const CHEST: usize = 2;
    /// The cervical joint.
    pub const NECK: usize = 3;
    /// The skull base (0 DoFs).
    pub const HEAD: usize = 4;
    /// The top of the head (End Site).
    pub const HEAD_END: usize = 5;
    /// The right clavicle joint (0 DoFs).
    pub const RIGHT_SHOULDER: usize = 6;
    /// The right shoulder (the arm's base joint).
    pub const RIGHT_ARM: usize = 7;
    /// The right elbow.
    pub const RIGHT_FOREARM: usize = 8;
    /// The right wrist.
    pub const RIGHT_HAND: usize = 9;
    /// The right fingertip (End Site).
    pub const RIGHT_HAND_END: usize = 10;
    /// The left clavicle joint (0 DoFs).
    pub const LEFT_SHOULDER: usize = 11;
    /// The left shoulder.
    pub const LEFT_ARM: usize = 12;
    /// The left elbow.
    pub const LEFT_FOREARM: usize = 13;
    /// The left wrist.
    pub const LEFT_HAND: usize = 14;
    /// The left fingertip (End Site).
    pub const LEFT_HAND_END: usize = 15;
    /// The right hip (the leg's base joint).
    pub const RIGHT_UP_LEG: usize = 16;
    /// The right knee.
    pub const RIGHT_LEG: usize = 17;
    /// The right ankle.
    pub const RIGHT_FOOT: usize = 18;
    /// The right toe tip (End Site).
    pub const RIGHT_FOOT_END: usize = 19;
    /// The left hip.
    pub const LEFT_UP_LEG: usize = 20;
    /// The left knee.
    pub const LEFT_LEG: usize = 21;
    /// The left ankle.
    pub const LEFT_FOOT: usize = 22;
    /// The left toe tip (End Site).
    pub const LEFT_FOOT_END: usize = 23;
    /// The number of joints, End Sites included.
    pub const COUNT: usize = 24;
}

/// Indices into a [`Pose`].
pub mod dof {
    use std::ops::Range;

    /// The root's world x, meters.
    pub const ROOT_X: usize = 0;
    /// The root's world y (height of the sacral joint), meters.
    pub const ROOT_Y: usize = 1;
    /// The root's world z, meters.
    pub const ROOT_Z: usize = 2;
    /// The root's translation.
    pub const ROOT_TRANSLATION: Range<usize> = 0..3;
    /// The root's rotation: swing_x, swing_y, twist.
    pub const ROOT_ROTATION: Range<usize> = 3..6;
    /// The lumbar joint: swing_x, swing_y, twist.
    pub const LUMBAR: Range<usize> = 6..9;
    /// The thoracic joint: swing_x, swing_y, twist.
    pub const THORACIC: Range<usize> = 9..12;
    /// The cervical joint: swing_x, swing_y, twist.
    pub const CERVICAL: Range<usize> = 12..15;
    /// The right arm's 7 DoFs.
    pub const RIGHT_ARM: Range<usize> = 15..22;
    /// The left arm's 7 DoFs.
    pub const LEFT_ARM: Range<usize> = 22..29;
    /// The right leg's 7 DoFs.
    pub const RIGHT_LEG: Range<usize> = 29..36;
    /// The left leg's 7 DoFs.
    pub const LEFT_LEG: Range<usize> = 36..43;
    /// Offset of the swing about x within a spine joint's three DoFs.
    pub const SWING_X: usize = 0;
    /// Offset of the swing about y within a spine joint's three DoFs.
    pub const SWING_Y: usize = 1;
    /// Offset of the twist within a spine joint's three DoFs.
    pub const TWIST: usize = 2;
}

/// One of the four limbs. Serialized by its [name](Limb::name), `right_arm` …; the
/// variants' own names (`RightArm` …) are read too.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Limb {
    /// The right arm (shoulder, elbow, wrist, fingertip).
    #[serde(alias = "RightArm")]
    RightArm,
    /// The left arm.
    #[serde(alias = "LeftArm")]
    LeftArm,
    /// The right leg (hip, knee, ankle, toe tip).
    #[serde(alias = "RightLeg")]
    RightLeg,
    /// The left leg.
    #[serde(alias = "LeftLeg")]
    LeftLeg,
}

impl Limb {
    /// The four limbs, in DoF order.
    pub const ALL: [Limb; 4] = [Limb::RightArm, Limb::LeftArm, Limb::RightLeg, Limb::LeftLeg];

    pub(super) fn index(self) -> usize {
        self as usize
    }

    /// `right_arm`, `left_arm`, `right_leg` or `left_leg`.
    pub fn name(self) -> &'static str {
        ["right_arm", "left_arm", "right_leg", "left_leg"][self.index()]
    }

    /// The arm on `side`: the one conversion from a [`Side`] to an arm.
    pub fn arm(side: Side) -> Limb {
        match side {
            Side::Right => Limb::RightArm,
            Side::Left => Limb::LeftArm,
        }
    }

    /// The leg on `side`.
    pub fn leg(side: Side) -> Limb {
        match side {
            Side::Right => Limb::RightLeg,
            Side::Left => Limb::LeftLeg,
        }
    }

    /// Which side of the body.
    pub fn side(self) -> Side {
        match self {
            Limb::RightArm | Limb::RightLeg => Side::Right,
            Limb::LeftArm | Limb::LeftLeg => Side::Left,
        }
    }

    /// True for the arms.
    pub fn is_arm(self) -> bool {
        matches!(self, Limb::RightArm | Limb::LeftArm)
    }

    /// The limb's DoFs in a [`Pose`], in chain order.
    pub fn dofs(self) -> Range<usize> {
        let start = 15 + 7 * self.index();
        start..start + 7
    }

    /// Its joints: base, mid, end and the 0-DoF tip (indices into
    /// [`Character::joints`](super::Character::joints)).
    pub fn joints(self) -> [usize; 4] {
        let base = [
            joint::RIGHT_ARM,
            joint::LEFT_ARM,
            joint::RIGHT_UP_LEG,
            joint::LEFT_UP_LEG,
        ][self.index()];
        [base, base + 1, base + 2, base + 3]
    }
}

impl fmt::Display for Limb {
    /// Its [name](Limb::name).
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl PartialEq<&str> for Limb {
    /// Whether `name` is its [name](Limb::name).
    fn eq(&self, name: &&str) -> bool {
        self.name() == *name
    }
}

/// One of the four spine joints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum SpineJoint {
    /// The root (`Hips`), 6 DoFs.
    Sacral,
    /// `Spine`, 3 DoFs.
    Lumbar,
    /// `Chest`, 3 DoFs.
    Thoracic,
    /// `Neck`, 3 DoFs: turns the head.
    Cervical,
}

impl SpineJoint {
    /// The four, root first.
    pub const ALL: [SpineJoint; 4] = [
        SpineJoint::Sacral,
        SpineJoint::Lumbar,
        SpineJoint::Thoracic,
        SpineJoint::Cervical,
    ];

    /// The index of its joint in [`Character::joints`](super::Character::joints).
    pub fn joint(self) -> usize {
        self as usize
    }

    /// Its rotation DoFs in a [`Pose`]: swing_x, swing_y, twist.
    pub fn rotation_dofs(self) -> Range<usize> {
        let start = 3 * (self as usize + 1);
        start..start + 3
    }
}

/// What one DoF of the character does.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DofKind {
    /// The root's translation along a world axis, meters.
    Translation(Axis),
    /// The x component of a swing vector.
    SwingX,
    /// The y component of a swing vector.
    SwingY,
    /// A rotation about the joint's z axis (the bone).
    Twist,
    /// A rotation about the joint's x axis (elbow and knee).
    Flexion,
}

/// World orientation of the spine's frames at rest: x = +X, y = −Z, z = +Y.
pub(super) fn spine_frame() -> Rotation3<f64> {
    Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
        Vector3::x(),
        -Vector3::z(),
        Vector3::y(),
    ]))
}

/// World orientation of the arms' rest frames: x = −X, y = −Z, z = −Y.
pub(super) fn arm_frame() -> Rotation3<f64> {
    Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
        -Vector3::x(),
        -Vector3::z(),
        -Vector3::y(),
    ]))
}

/// World orientation of the legs' rest frames: x = +X, y = +Z, z = −Y.
pub(super) fn leg_frame() -> Rotation3<f64> {
    Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
        Vector3::x(),
        Vector3::z(),
        -Vector3::y(),
    ]))
}

/// The spine's channel order: heading–pitch–roll (gimbal lock only at a 90° forward bend).
pub(super) const SPINE_ORDER: [Axis; 3] = [Axis::Y, Axis::X, Axis::Z];
/// The limbs' channel order, CMU's (gimbal lock only at a ±90° twist of the hanging limb).
pub(super) const LIMB_ORDER: [Axis; 3] = [Axis::Z, Axis::Y, Axis::X];
