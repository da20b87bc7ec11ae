//! The full-body character of Huang, Kapadia & Terzopoulos §3.1 (DESIGN §1.2): 21 bones and
//! 43 DoFs, its proportions, forward kinematics, centre of mass, support polygon and joint
//! limits, the four limbs as [`Chain`]s for the analytic limb IK, and BVH export.
//!
//! ```
//! use kinergy_reach::character::{Character, Limb, Proportions};
//!
//! let body = Character::new(&Proportions::from_height(1.75)?)?;
//! assert_eq!((body.bone_count(), body.dof_count()), (21, 43));
//! let mut pose = body.rest_pose();
//! pose[body.limb_dofs(Limb::RightArm).start + 3] = 1.2; // bend the right elbow
//! let chain = body.limb_chain(Limb::RightArm);
//! let tip = chain.end_position(&body.limb_base_frame(Limb::RightArm, &pose), &pose[body.limb_dofs(Limb::RightArm)])?;
//! let fk = body.world_positions(&pose)[body.limb_joints(Limb::RightArm)[3]];
//! assert!((tip - fk).norm() < 1e-12);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! # Conventions
//! SI units (meters, radians), right-handed, Y up (DESIGN §3). In the rest pose
//! ([`Character::rest_pose`]) the character stands upright at the origin with both feet flat
//! on y = 0, faces +Z and lets its arms hang straight down; with Y up and facing +Z, the
//! character's **left is +X** and its right is −X. The rest pose has every DoF at zero except
//! the root's height `root_ty` ([`Proportions::root_height`]): root translations are the
//! world position of the sacral joint, not a displacement.
//!
//! # The skeleton and its count
//! 24 joints (the BVH export has the same joints in the same order, see [`joint`]); a
//! *bone* is a rigid segment between two joints ([`Character::bones`]):
//!
//! | # | joint (BVH name) | parent | role | DoFs | BVH channels |
//! |---|---|---|---|---|---|
//! | 0 | `Hips` | — | sacral root | 3 translation + swing 2 + twist 1 = 6 | `Xposition Yposition Zposition Yrotation Xrotation Zrotation` |
//! | 1 | `Spine` | Hips | lumbar | swing 2 + twist 1 = 3 | `Yrotation Xrotation Zrotation` |
//! | 2 | `Chest` | Spine | thoracic | 3 | same |
//! | 3 | `Neck` | Chest | cervical (turns the head) | 3 | same |
//! | 4 | `Head` | Neck | skull base (ear-canal height) | 0 | none |
//! | 5 | `Head_End` | Head | top of the head (End Site) | 0 | — |
//! | 6, 11 | `RightShoulder`, `LeftShoulder` | Chest | clavicle joint, on the thoracic bone | 0 | none |
//! | 7, 12 | `RightArm`, `LeftArm` | …Shoulder | shoulder: base joint | swing 2 + twist 1 | `Zrotation Yrotation Xrotation` |
//! | 8, 13 | `RightForeArm`, `LeftForeArm` | …Arm | elbow: mid joint | flexion 1 + twist 1 | same |
//! | 9, 14 | `RightHand`, `LeftHand` | …ForeArm | wrist: end joint | swing 2 | same |
//! | 10, 15 | `RightHand_End`, `LeftHand_End` | …Hand | fingertip: 0-DoF tip (End Site) | 0 | — |
//! | 16, 20 | `RightUpLeg`, `LeftUpLeg` | Hips | hip: base joint | swing 2 + twist 1 | `Zrotation Yrotation Xrotation` |
//! | 17, 21 | `RightLeg`, `LeftLeg` | …UpLeg | knee: mid joint | flexion 1 + twist 1 | same |
//! | 18, 22 | `RightFoot`, `LeftFoot` | …Leg | ankle: end joint | swing 2 | same |
//! | 19, 23 | `RightFoot_End`, `LeftFoot_End` | …Foot | toe tip: 0-DoF tip (End Site) | 0 | — |
//!
//! End Sites are named `<parent>_End`, the name our BVH reader gives them, so names survive a
//! round trip. **Bones (21)**: the spine's four — sacrum (Hips→Spine), lumbar (Spine→Chest),
//! thorax (Chest→Neck), neck (Neck→Head) — and the head (Head→Head_End): 5; the two
//! clavicles (…Shoulder→…Arm), the 0-DoF shoulder bones: 2; the two pelvic bones
//! (Hips→…UpLeg), rigid with the root, so 0 DoFs of their own: 2; three bones per limb
//! (upper arm, forearm, hand; thigh, shank, foot): 12. 5 + 2 + 2 + 12 = 21. The clavicle
//! joints sit on the thoracic bone (Chest→…Shoulder is collinear with Chest→Neck), so that
//! link is not a bone of its own. **DoFs**: sacral 6 + lumbar 3 + thoracic 3 + cervical 3 +
//! 4 limbs × 7 = 6 + 3 + 3 + 3 + 28 = 43.
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
//!
//! # Proportions
//! [`Ratios::DRILLIS_CONTINI`] — segment lengths as fractions of the standing height H after
//! Drillis & Contini (1966), as reproduced in Winter, *Biomechanics and Motor Control of Human
//! Movement*, Fig. 4.1: upper arm 0.186, forearm 0.146, hand 0.108 (wrist to fingertip),
//! thigh 0.245, shank 0.246, ankle height 0.039, foot length 0.152, shoulder width 0.259,
//! hip width 0.191, shoulder height 0.818. Our choices on top: the widths are used as the
//! distances between the shoulder and hip joint centres (the figure's are breadths, so this
//! errs a few centimeters wide); the ankle lies a quarter of the foot length ahead of the
//! heel (heel 0.038, toe 0.114); the spine joints sit at vertebral landmarks — sacral root
//! 0.550 H (0.020 above the hips), lumbar L4–L5 0.595 H, thoracic T12–L1 0.700 H, cervical
//! C7–T1 0.845 H, skull base (ear canal) 0.930 H — and the clavicle joints at the shoulder
//! height 0.818 H, 0.027 H below the cervical joint.
//!
//! # Centre of mass
//! Segment masses as fractions of body mass and centres of mass along segments from the
//! proximal end, Dempster's data via Winter's Table 4.1 ([`Character::mass_segments`]):
//! hand 0.006 at 0.506 of wrist→knuckle II (the knuckle taken half-way along our
//! wrist→fingertip hand, so 0.253 of it); forearm 0.016 at 0.430; upper arm 0.028 at 0.436;
//! foot 0.0145 half-way from the ankle to the 2nd metatarsal head (taken at 0.7 of the
//! ankle→toe-tip vector, so 0.35 of it); shank 0.0465 at 0.433; thigh 0.100 at 0.433;
//! head and neck 0.081 at the ear canal (our `Head` joint); thorax 0.216 at 0.82 from C7–T1
//! (`Neck`) to T12–L1 (`Chest`); abdomen 0.139 at 0.44 from T12–L1 (`Chest`) to L4–L5
//! (`Spine`); pelvis 0.142 at 0.105 from L4–L5 (`Spine`) to the mid-point of the hip joints.
//! The fractions sum to 1.
//!
//! # Foot points and the support polygon
//! Each foot has a toe point, its tip (the `…Foot_End` End Site, `(0, toe, ankle_height)` in
//! the ankle frame), and a heel point `(0, −heel, ankle_height)` in the ankle frame: at rest
//! both lie on y = 0, the toe `toe` ahead of the ankle and the heel `heel` behind it
//! ([`Character::foot_points`]). The support polygon is the convex hull in x–z of the foot
//! points in contact: those within [`CONTACT_TOLERANCE`] of the lowest one.
//!
//! # BVH export
//! [`Character::to_skeleton`] writes world-aligned offsets (the rest pose is the zero pose of
//! the BVH, every rotation channel 0), and [`Character::to_clip`] writes each joint's
//! rotation as Euler angles in its channel order: with `C` the joint frame's world
//! orientation at rest and `M` the rotation of its motions, the BVH joint rotates by
//! `C · M · Cᵀ` relative to its parent. The orders keep gimbal lock away from the usual
//! poses: heading–pitch–roll (Y X Z, lock only at a 90° forward bend) for the spine, and
//! CMU's Z Y X for the limbs (lock only at a ±90° twist of the hanging limb). Frame to frame
//! the Euler solution nearest the previous frame is taken, so angles do not jump by 2π.
//! Root translations are written in the export's unit.

use std::ops::Range;
use std::sync::Arc;

use kinergy_motion::rotation::{Axis, axis_rotation, euler_angles, swing_rotation, unwrap_near};
use kinergy_motion::{
    ArmJoints, ArmLengths, Chain, ChainJoint, Clip, Dof, Joint, Motion, PositionReading, Side,
    Skeleton,
};
use nalgebra::{IsometryMatrix3, Matrix3, Point2, Point3, Rotation3, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::{ReachError, Result, require};

/// The character's number of DoFs, the length of a [`Pose`].
pub const DOF_COUNT: usize = 43;

/// The character's number of bones.
pub const BONE_COUNT: usize = 21;

/// A pose of the character: [`DOF_COUNT`] values (meters for the root translation,
/// radians otherwise) in the order of the [module docs](self).
pub type Pose = [f64; DOF_COUNT];

/// How far above the lowest foot point (meters) a heel or toe still counts as touching the
/// ground, for the support polygon.
pub const CONTACT_TOLERANCE: f64 = 0.01;

/// Foot breadth as a fraction of height (Drillis & Contini: 0.055).
pub const FOOT_BREADTH: f64 = 0.055;

/// Indices of the character's joints in [`Character::joints`] (and in the exported skeleton).
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

/// One of the four limbs.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Limb {
    /// The right arm (shoulder, elbow, wrist, fingertip).
    RightArm,
    /// The left arm.
    LeftArm,
    /// The right leg (hip, knee, ankle, toe tip).
    RightLeg,
    /// The left leg.
    LeftLeg,
}

impl Limb {
    /// The four limbs, in DoF order.
    pub const ALL: [Limb; 4] = [Limb::RightArm, Limb::LeftArm, Limb::RightLeg, Limb::LeftLeg];

    fn index(self) -> usize {
        self as usize
    }

    /// `right_arm`, `left_arm`, `right_leg` or `left_leg`.
    pub fn name(self) -> &'static str {
        ["right_arm", "left_arm", "right_leg", "left_leg"][self.index()]
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

    /// Its joints: base, mid, end and the 0-DoF tip (indices into [`Character::joints`]).
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

    /// The index of its joint in [`Character::joints`].
    pub fn joint(self) -> usize {
        self as usize
    }

    /// Its rotation DoFs in a [`Pose`]: swing_x, swing_y, twist.
    pub fn rotation_dofs(self) -> Range<usize> {
        let start = 3 * (self as usize + 1);
        start..start + 3
    }
}

// ---------------------------------------------------------------------------------------
// Proportions
// ---------------------------------------------------------------------------------------

/// Segment lengths and joint placements as fractions of the standing height (see the
/// [module docs](self#proportions) for the sources). The vertical ones — `ankle_height`,
/// `shank`, `thigh`, `pelvis_rise`, `sacrum`, `lumbar`, `thoracic`, `neck`, `head` — stack
/// from the floor to the top of the head and must sum to 1.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Ratios {
    /// Shoulder to elbow.
    pub upper_arm: f64,
    /// Elbow to wrist.
    pub forearm: f64,
    /// Wrist to fingertip.
    pub hand: f64,
    /// Hip to knee.
    pub thigh: f64,
    /// Knee to ankle.
    pub shank: f64,
    /// Ankle joint above the floor.
    pub ankle_height: f64,
    /// Toe tip ahead of the ankle.
    pub toe: f64,
    /// Heel behind the ankle.
    pub heel: f64,
    /// Between the shoulder joint centres.
    pub shoulder_width: f64,
    /// Between the hip joint centres.
    pub hip_width: f64,
    /// Sacral root above the hip joints.
    pub pelvis_rise: f64,
    /// Sacral root to lumbar joint.
    pub sacrum: f64,
    /// Lumbar to thoracic joint.
    pub lumbar: f64,
    /// Thoracic to cervical joint.
    pub thoracic: f64,
    /// Cervical joint to skull base.
    pub neck: f64,
    /// Skull base to the top of the head.
    pub head: f64,
    /// Clavicle (and shoulder) joints below the cervical joint.
    pub shoulder_drop: f64,
}

impl Ratios {
    /// Drillis & Contini's ratios (Winter, Fig. 4.1) with our spine landmarks.
    pub const DRILLIS_CONTINI: Ratios = Ratios {
        upper_arm: 0.186,
        forearm: 0.146,
        hand: 0.108,
        thigh: 0.245,
        shank: 0.246,
        ankle_height: 0.039,
        toe: 0.114,
        heel: 0.038,
        shoulder_width: 0.259,
        hip_width: 0.191,
        pelvis_rise: 0.020,
        sacrum: 0.045,
        lumbar: 0.105,
        thoracic: 0.145,
        neck: 0.085,
        head: 0.070,
        shoulder_drop: 0.027,
    };

    fn fields(&self) -> [(&'static str, f64); 17] {
        [
            ("upper_arm", self.upper_arm),
            ("forearm", self.forearm),
            ("hand", self.hand),
            ("thigh", self.thigh),
            ("shank", self.shank),
            ("ankle_height", self.ankle_height),
            ("toe", self.toe),
            ("heel", self.heel),
            ("shoulder_width", self.shoulder_width),
            ("hip_width", self.hip_width),
            ("pelvis_rise", self.pelvis_rise),
            ("sacrum", self.sacrum),
            ("lumbar", self.lumbar),
            ("thoracic", self.thoracic),
            ("neck", self.neck),
            ("head", self.head),
            ("shoulder_drop", self.shoulder_drop),
        ]
    }

    /// The sum of the vertical ratios (1 for a consistent set).
    pub fn vertical_sum(&self) -> f64 {
        self.ankle_height + self.shank + self.thigh + self.spine_sum()
    }

    fn spine_sum(&self) -> f64 {
        self.pelvis_rise + self.sacrum + self.lumbar + self.thoracic + self.neck + self.head
    }

    /// Every ratio finite, in (0, 1); the vertical ones summing to 1 (±0.001); the clavicles
    /// on the thoracic bone. Errors name the field, e.g. `ratios.thigh`.
    pub fn validate(&self) -> Result<()> {
        for (name, v) in self.fields() {
            require(
                v.is_finite() && v > 0.0 && v < 1.0,
                &format!("ratios.{name}"),
                format!("{v} is not a fraction of the height in (0, 1)"),
            )?;
        }
        let sum = self.vertical_sum();
        require(
            (sum - 1.0).abs() <= 1e-3,
            "ratios",
            format!(
                "the vertical ratios (ankle_height + shank + thigh + pelvis_rise + sacrum + lumbar + thoracic + neck + head) sum to {sum}, not 1"
            ),
        )?;
        require(
            self.shoulder_drop < self.thoracic,
            "ratios.shoulder_drop",
            "the shoulders must lie on the thoracic bone (shoulder_drop < thoracic)",
        )
    }
}

impl Default for Ratios {
    fn default() -> Ratios {
        Ratios::DRILLIS_CONTINI
    }
}

/// An arm's bone lengths, meters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ArmSegments {
    /// Shoulder to elbow.
    pub upper_arm: f64,
    /// Elbow to wrist.
    pub forearm: f64,
    /// Wrist to fingertip (the arm's tip).
    pub hand: f64,
}

/// A leg's bone lengths and foot geometry, meters.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LegSegments {
    /// Hip to knee.
    pub thigh: f64,
    /// Knee to ankle.
    pub shank: f64,
    /// Ankle joint above the sole.
    pub ankle_height: f64,
    /// Toe tip ahead of the ankle, along the sole.
    pub toe: f64,
    /// Heel behind the ankle, along the sole.
    pub heel: f64,
}

impl LegSegments {
    /// The hip joint's height above the floor when standing: ankle height + shank + thigh.
    pub fn hip_height(&self) -> f64 {
        self.ankle_height + self.shank + self.thigh
    }

    /// Ankle to toe tip, the foot bone's length.
    pub fn foot(&self) -> f64 {
        self.toe.hypot(self.ankle_height)
    }
}

/// The spine's segments, meters, from the hips up.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SpineSegments {
    /// Sacral root above the mid-point of the hip joints (≥ 0).
    pub pelvis_rise: f64,
    /// Sacral root to lumbar joint.
    pub sacrum: f64,
    /// Lumbar to thoracic joint.
    pub lumbar: f64,
    /// Thoracic to cervical joint.
    pub thoracic: f64,
    /// Cervical joint to skull base.
    pub neck: f64,
    /// Skull base to the top of the head.
    pub head: f64,
    /// The clavicle and shoulder joints below the cervical joint (in `[0, thoracic)`).
    pub shoulder_drop: f64,
}

impl SpineSegments {
    /// From the hips' mid-point to the top of the head.
    pub fn above_hips(&self) -> f64 {
        self.pelvis_rise + self.sacrum + self.lumbar + self.thoracic + self.neck + self.head
    }
}

/// The character's measurements, meters. Built from a height and [`Ratios`]
/// ([`Proportions::from_height`]) or measured on a capture skeleton
/// ([`Proportions::from_skeleton`], [`Proportions::from_clip`]); arms and legs may differ
/// between sides.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Proportions {
    /// The right arm.
    pub right_arm: ArmSegments,
    /// The left arm.
    pub left_arm: ArmSegments,
    /// The right leg.
    pub right_leg: LegSegments,
    /// The left leg.
    pub left_leg: LegSegments,
    /// The spine.
    pub spine: SpineSegments,
    /// Between the shoulder joint centres.
    pub shoulder_width: f64,
    /// Between the hip joint centres.
    pub hip_width: f64,
}

impl Proportions {
    /// The shortest standing height accepted, meters.
    pub const MIN_HEIGHT: f64 = 0.5;
    /// The tallest standing height accepted, meters.
    pub const MAX_HEIGHT: f64 = 2.5;

    /// A person `height` meters tall with Drillis & Contini's ratios.
    pub fn from_height(height: f64) -> Result<Proportions> {
        Proportions::from_ratios(height, &Ratios::default())
    }

    /// A person `height` meters tall with the given ratios (validated, errors naming the
    /// field: `height`, `ratios.<name>`). Every length is its ratio × `height`, so the
    /// standing height is `height` × [`Ratios::vertical_sum`].
    pub fn from_ratios(height: f64, ratios: &Ratios) -> Result<Proportions> {
        check_height(height)?;
        ratios.validate()?;
        let h = height;
        let arm = ArmSegments {
            upper_arm: ratios.upper_arm * h,
            forearm: ratios.forearm * h,
            hand: ratios.hand * h,
        };
        let leg = LegSegments {
            thigh: ratios.thigh * h,
            shank: ratios.shank * h,
            ankle_height: ratios.ankle_height * h,
            toe: ratios.toe * h,
            heel: ratios.heel * h,
        };
        let p = Proportions {
            right_arm: arm,
            left_arm: arm,
            right_leg: leg,
            left_leg: leg,
            spine: SpineSegments {
                pelvis_rise: ratios.pelvis_rise * h,
                sacrum: ratios.sacrum * h,
                lumbar: ratios.lumbar * h,
                thoracic: ratios.thoracic * h,
                neck: ratios.neck * h,
                head: ratios.head * h,
                shoulder_drop: ratios.shoulder_drop * h,
            },
            shoulder_width: ratios.shoulder_width * h,
            hip_width: ratios.hip_width * h,
        };
        p.validate()?;
        Ok(p)
    }

    /// Measured on a capture skeleton in its zero pose (see [`Proportions::from_clip`]).
    pub fn from_skeleton(skeleton: &Skeleton) -> Result<Proportions> {
        measure(skeleton, &skeleton.rest_pose())
    }

    /// Measured on a capture: bone lengths in the clip's first frame (position channels may
    /// stretch bones), widths and heights in the skeleton's zero pose when it is upright (the
    /// head above the hips, Y up), else in the first frame (Bandai Namco's zero pose lies
    /// along +X). A wrist without a hand point below it gets a hand
    /// [`kinergy_motion::arm::HAND_PER_FOREARM`] × its forearm long.
    ///
    /// Best effort by joint role: arms by [`ArmJoints::find`] (shoulder→elbow, elbow→wrist,
    /// wrist→hand point); legs by names (`UpLeg`/`UpperLeg`/`Thigh`/`Hip` →
    /// `Leg`/`LowerLeg`/`Knee`/`Shin`/`Calf` → `Foot`/`Ankle`, the toe tip being the ankle's
    /// farthest descendant); the top of the head as the highest point of the `Head` joint
    /// and its descendants. The standing height H is the head's top above the hips plus the
    /// mean leg (thigh + shank + ankle height 0.039 H); ankle height and heel come from
    /// [`Ratios::DRILLIS_CONTINI`], the toe keeps the measured ankle→toe-tip distance, the
    /// spine segments are Drillis & Contini's scaled to the measured hips→head-top distance,
    /// the shoulders sit at their measured height when it falls on the thoracic bone, and
    /// the widths are the measured distances between the shoulder and between the hip
    /// joints. Errors name what is missing.
    pub fn from_clip(clip: &Clip) -> Result<Proportions> {
        let pose = clip.frame(0).ok_or_else(|| ReachError::Setting {
            field: "clip".into(),
            why: "it has no frames to measure".into(),
        })?;
        measure(clip.skeleton(), pose)
    }

    /// The standing height: floor to the top of the head, `hip height + spine`, with the
    /// mean of the two legs' hip heights.
    pub fn height(&self) -> f64 {
        self.mean_hip_height() + self.spine.above_hips()
    }

    /// The sacral root's height when standing (the rest pose's `root_ty`).
    pub fn root_height(&self) -> f64 {
        self.mean_hip_height() + self.spine.pelvis_rise
    }

    fn mean_hip_height(&self) -> f64 {
        0.5 * (self.right_leg.hip_height() + self.left_leg.hip_height())
    }

    /// The arm on `side`.
    pub fn arm(&self, side: Side) -> &ArmSegments {
        match side {
            Side::Right => &self.right_arm,
            Side::Left => &self.left_arm,
        }
    }

    /// The leg on `side`.
    pub fn leg(&self, side: Side) -> &LegSegments {
        match side {
            Side::Right => &self.right_leg,
            Side::Left => &self.left_leg,
        }
    }

    /// Every length finite and positive (`pelvis_rise` and `shoulder_drop` may be 0,
    /// `shoulder_drop` below `spine.thoracic`), the height within
    /// [`MIN_HEIGHT`](Self::MIN_HEIGHT)–[`MAX_HEIGHT`](Self::MAX_HEIGHT), and each hip below
    /// the sacral root. Errors name the field, e.g. `right_leg.thigh`.
    pub fn validate(&self) -> Result<()> {
        for (side, arm) in [("right_arm", &self.right_arm), ("left_arm", &self.left_arm)] {
            check_length(arm.upper_arm, &format!("{side}.upper_arm"))?;
            check_length(arm.forearm, &format!("{side}.forearm"))?;
            check_length(arm.hand, &format!("{side}.hand"))?;
        }
        for (side, leg) in [("right_leg", &self.right_leg), ("left_leg", &self.left_leg)] {
            check_length(leg.thigh, &format!("{side}.thigh"))?;
            check_length(leg.shank, &format!("{side}.shank"))?;
            check_length(leg.ankle_height, &format!("{side}.ankle_height"))?;
            check_length(leg.toe, &format!("{side}.toe"))?;
            check_length(leg.heel, &format!("{side}.heel"))?;
        }
        let s = &self.spine;
        require(
            s.pelvis_rise.is_finite() && s.pelvis_rise >= 0.0,
            "spine.pelvis_rise",
            format!("{} m is not a length ≥ 0", s.pelvis_rise),
        )?;
        check_length(s.sacrum, "spine.sacrum")?;
        check_length(s.lumbar, "spine.lumbar")?;
        check_length(s.thoracic, "spine.thoracic")?;
        check_length(s.neck, "spine.neck")?;
        check_length(s.head, "spine.head")?;
        require(
            s.shoulder_drop.is_finite() && s.shoulder_drop >= 0.0 && s.shoulder_drop < s.thoracic,
            "spine.shoulder_drop",
            format!(
                "{} m does not put the shoulders on the thoracic bone (0 ≤ drop < {} m)",
                s.shoulder_drop, s.thoracic
            ),
        )?;
        check_length(self.shoulder_width, "shoulder_width")?;
        check_length(self.hip_width, "hip_width")?;
        // The height is a sum of segments: allow its rounding at the bounds.
        check_height_within(self.height(), 1e-12)?;
        let root = self.root_height();
        for (side, leg) in [("right_leg", &self.right_leg), ("left_leg", &self.left_leg)] {
            require(
                leg.hip_height() < root + s.sacrum,
                side,
                format!(
                    "its hip ({} m high) lies above the lumbar joint ({} m): the legs differ too much in length",
                    leg.hip_height(),
                    root + s.sacrum
                ),
            )?;
        }
        Ok(())
    }
}

fn check_height(h: f64) -> Result<()> {
    check_height_within(h, 0.0)
}

/// The height check with a relative `slack` (for heights summed from segments).
fn check_height_within(h: f64, slack: f64) -> Result<()> {
    let range = Proportions::MIN_HEIGHT * (1.0 - slack)..=Proportions::MAX_HEIGHT * (1.0 + slack);
    require(
        h.is_finite() && range.contains(&h),
        "height",
        format!(
            "{h} m is not a standing height within {}–{} m",
            Proportions::MIN_HEIGHT,
            Proportions::MAX_HEIGHT
        ),
    )
}

fn check_length(v: f64, field: &str) -> Result<()> {
    require(
        v.is_finite() && v > 0.0,
        field,
        format!("{v} m is not a positive length"),
    )
}

fn setting(field: &str, why: impl Into<String>) -> ReachError {
    ReachError::Setting {
        field: field.to_string(),
        why: why.into(),
    }
}

/// A capture's leg, by joint role.
struct LegJoints {
    hip: usize,
    knee: usize,
    ankle: usize,
    toe: usize,
}

/// The side a name's tokens give, and its role: the other tokens joined (`RightUpLeg` →
/// `upleg`, `CC_Base_L_Calf` → `ccbasecalf`).
fn side_and_role(name: &str) -> (Option<Side>, String) {
    let tokens = kinergy_motion::arm::name_tokens(name);
    let mut side = None;
    let mut role = String::new();
    for t in &tokens {
        match t.as_str() {
            "right" | "r" => side = Some(Side::Right),
            "left" | "l" => side = Some(Side::Left),
            other => role.push_str(other),
        }
    }
    (side, role)
}

fn is_ankle_role(role: &str) -> bool {
    role.ends_with("foot") || role.ends_with("ankle")
}

fn is_knee_role(role: &str) -> bool {
    ["lowerleg", "lowleg", "knee", "shin", "calf"]
        .iter()
        .any(|k| role.ends_with(k))
        || (role.ends_with("leg") && !role.ends_with("upleg") && !role.ends_with("upperleg"))
}

fn is_hip_role(role: &str) -> bool {
    ["upleg", "upperleg", "thigh", "hip"]
        .iter()
        .any(|k| role.ends_with(k))
}

fn is_helper_role(role: &str) -> bool {
    ["twist", "roll", "share", "helper"]
        .iter()
        .any(|k| role.contains(k))
}

fn find_leg(skeleton: &Skeleton, side: Side) -> Result<LegJoints> {
    let info: Vec<(Option<Side>, String)> = skeleton
        .joints()
        .iter()
        .map(|j| side_and_role(&j.name))
        .collect();
    let parent_skipping_helpers = |mut j: usize| -> Option<usize> {
        loop {
            j = skeleton.joint(j).parent?;
            if !is_helper_role(&info[j].1) {
                return Some(j);
            }
        }
    };
    let zero = skeleton.world_positions(&skeleton.rest_pose())?;
    for ankle in (0..skeleton.joint_count()).filter(|&j| {
        !skeleton.joint(j).end_site && info[j].0 == Some(side) && is_ankle_role(&info[j].1)
    }) {
        let Some(knee) = parent_skipping_helpers(ankle).filter(|&k| is_knee_role(&info[k].1))
        else {
            continue;
        };
        let Some(hip) = parent_skipping_helpers(knee).filter(|&h| is_hip_role(&info[h].1)) else {
            continue;
        };
        let toe = (ankle + 1..skeleton.joint_count())
            .filter(|&d| skeleton.is_ancestor_or_self(ankle, d))
            .max_by(|&a, &b| {
                let da = (zero[a] - zero[ankle]).norm();
                let db = (zero[b] - zero[ankle]).norm();
                da.total_cmp(&db)
            });
        let Some(toe) = toe else {
            return Err(setting(
                "skeleton",
                format!(
                    "the {side} ankle `{}` has no toe joint or End Site below it",
                    skeleton.joint(ankle).name
                ),
            ));
        };
        return Ok(LegJoints {
            hip,
            knee,
            ankle,
            toe,
        });
    }
    let leg_like: Vec<&str> = skeleton
        .joints()
        .iter()
        .zip(&info)
        .filter(|(j, (_, r))| {
            !j.end_site && (is_ankle_role(r) || is_knee_role(r) || is_hip_role(r))
        })
        .map(|(j, _)| j.name.as_str())
        .collect();
    Err(setting(
        "skeleton",
        format!(
            "no {side} leg found (UpLeg/Thigh/Hip → Leg/Knee/Shin/Calf → Foot/Ankle); leg-like joints: {}",
            if leg_like.is_empty() {
                "none".to_string()
            } else {
                leg_like.join(", ")
            }
        ),
    ))
}

fn measure(skeleton: &Skeleton, pose: &[f64]) -> Result<Proportions> {
    let zero = skeleton.world_positions(&skeleton.rest_pose())?;
    let p = skeleton.world_positions(pose)?;
    let d = |a: usize, b: usize| (p[a] - p[b]).norm();
    let ratios = Ratios::DRILLIS_CONTINI;

    let mut arms = Vec::with_capacity(2);
    let mut shoulders = Vec::with_capacity(2);
    for side in [Side::Right, Side::Left] {
        let a = ArmJoints::find(skeleton, side)?;
        let measured = ArmLengths {
            upper_arm: d(a.shoulder, a.elbow),
            forearm: d(a.elbow, a.wrist),
            hand: a.hand.map_or(0.0, |h| d(a.wrist, h)),
        };
        // A wrist with no hand point below it (Bandai's Hand_R) gets the default hand.
        arms.push(ArmSegments {
            upper_arm: measured.upper_arm,
            forearm: measured.forearm,
            hand: measured.hand_or_default(),
        });
        shoulders.push(a.shoulder);
    }
    let legs = [
        find_leg(skeleton, Side::Right)?,
        find_leg(skeleton, Side::Left)?,
    ];
    let head = (0..skeleton.joint_count())
        .find(|&j| {
            let joint = skeleton.joint(j);
            !joint.end_site
                && kinergy_motion::arm::name_tokens(&joint.name)
                    .iter()
                    .any(|t| t == "head")
                && side_and_role(&joint.name).0.is_none()
        })
        .ok_or_else(|| {
            setting(
                "skeleton",
                "no head joint (named like `Head`) to measure the height to",
            )
        })?;
    // Skeletons whose zero pose is not upright (Bandai Namco's lies along +X) are measured
    // upright in the clip's first frame instead.
    let above_hips = |q: &[Point3<f64>]| {
        let top = (head..skeleton.joint_count())
            .filter(|&j| skeleton.is_ancestor_or_self(head, j))
            .map(|j| q[j].y)
            .fold(f64::NEG_INFINITY, f64::max);
        top - 0.5 * (q[legs[0].hip].y + q[legs[1].hip].y)
    };
    let zero = if above_hips(&zero) > 0.0 || above_hips(&p) <= 0.0 {
        zero
    } else {
        p.clone()
    };
    let top = (head..skeleton.joint_count())
        .filter(|&j| skeleton.is_ancestor_or_self(head, j))
        .map(|j| zero[j].y)
        .fold(f64::NEG_INFINITY, f64::max);
    let hips_y = 0.5 * (zero[legs[0].hip].y + zero[legs[1].hip].y);
    let upper = top - hips_y;
    require(
        upper.is_finite() && upper > 0.0,
        "skeleton",
        format!(
            "the top of the head (`{}`) is not above the hips in the zero pose",
            skeleton.joint(head).name
        ),
    )?;
    let mean_thigh_shank = 0.5
        * legs
            .iter()
            .map(|l| d(l.hip, l.knee) + d(l.knee, l.ankle))
            .sum::<f64>();
    let height = (mean_thigh_shank + upper) / (1.0 - ratios.ankle_height);
    check_height(height)?;
    let ankle_height = ratios.ankle_height * height;
    let mut leg_segments = Vec::with_capacity(2);
    for (l, side) in legs.iter().zip(["right", "left"]) {
        let foot = d(l.ankle, l.toe);
        require(
            foot > ankle_height,
            "skeleton",
            format!(
                "the {side} foot (`{}` to `{}`, {foot} m) is shorter than the ankle height {ankle_height} m",
                skeleton.joint(l.ankle).name,
                skeleton.joint(l.toe).name
            ),
        )?;
        leg_segments.push(LegSegments {
            thigh: d(l.hip, l.knee),
            shank: d(l.knee, l.ankle),
            ankle_height,
            toe: (foot * foot - ankle_height * ankle_height).sqrt(),
            heel: ratios.heel * height,
        });
    }
    let k = upper / ratios.spine_sum();
    let mut spine = SpineSegments {
        pelvis_rise: ratios.pelvis_rise * k,
        sacrum: ratios.sacrum * k,
        lumbar: ratios.lumbar * k,
        thoracic: ratios.thoracic * k,
        neck: ratios.neck * k,
        head: ratios.head * k,
        shoulder_drop: ratios.shoulder_drop * k,
    };
    let cervical = spine.pelvis_rise + spine.sacrum + spine.lumbar + spine.thoracic;
    let shoulder_y = 0.5 * (zero[shoulders[0]].y + zero[shoulders[1]].y) - hips_y;
    let drop = cervical - shoulder_y;
    if drop >= 0.0 && drop < spine.thoracic {
        spine.shoulder_drop = drop;
    }
    let proportions = Proportions {
        right_arm: arms[0],
        left_arm: arms[1],
        right_leg: leg_segments[0],
        left_leg: leg_segments[1],
        spine,
        shoulder_width: (zero[shoulders[0]] - zero[shoulders[1]]).norm(),
        hip_width: (zero[legs[0].hip] - zero[legs[1].hip]).norm(),
    };
    proportions.validate()?;
    Ok(proportions)
}

// ---------------------------------------------------------------------------------------
// The character
// ---------------------------------------------------------------------------------------

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

/// One joint of the [`Character`].
#[derive(Debug, Clone, PartialEq)]
pub struct CharacterJoint {
    /// The BVH name (see the [module docs](self#the-skeleton-and-its-count)).
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
    /// The BVH rotation channel order (used when it has motions).
    pub channel_order: [Axis; 3],
}

impl CharacterJoint {
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

/// One body segment's share of the mass and its centre of mass in a pose.
#[derive(Debug, Clone, PartialEq)]
pub struct MassSegment {
    /// E.g. `thorax`, `right_thigh`.
    pub name: &'static str,
    /// Fraction of the body's mass.
    pub mass_fraction: f64,
    /// World position of its centre of mass.
    pub com: Point3<f64>,
}

/// The convex hull of the foot points touching the ground, in the x–z plane (points are
/// `(x, z)`), counter-clockwise in that plane.
#[derive(Debug, Clone, PartialEq)]
pub struct SupportPolygon {
    vertices: Vec<Point2<f64>>,
}

impl SupportPolygon {
    /// The convex hull of `points` (Andrew's monotone chain; collinear points dropped).
    pub fn hull(points: &[Point2<f64>]) -> SupportPolygon {
        let mut pts: Vec<Point2<f64>> = points.to_vec();
        pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
        pts.dedup_by(|a, b| (*a - *b).norm() < 1e-12);
        if pts.len() < 3 {
            return SupportPolygon { vertices: pts };
        }
        let cross = |o: &Point2<f64>, a: &Point2<f64>, b: &Point2<f64>| (a - o).perp(&(b - o));
        let half = |points: &mut dyn Iterator<Item = &Point2<f64>>| {
            let mut chain: Vec<Point2<f64>> = Vec::with_capacity(pts.len());
            for p in points {
                while chain.len() >= 2
                    && cross(&chain[chain.len() - 2], &chain[chain.len() - 1], p) <= 1e-15
                {
                    chain.pop();
                }
                chain.push(*p);
            }
            chain.pop();
            chain
        };
        let mut hull = half(&mut pts.iter());
        hull.extend(half(&mut pts.iter().rev()));
        SupportPolygon { vertices: hull }
    }

    /// The vertices `(x, z)`, counter-clockwise in the x–z plane.
    pub fn vertices(&self) -> &[Point2<f64>] {
        &self.vertices
    }

    /// Distance from `(x, z)` to the polygon's boundary, positive inside, negative outside
    /// (a polygon of one or two points has no inside).
    pub fn margin(&self, p: Point2<f64>) -> f64 {
        let v = &self.vertices;
        match v.len() {
            0 => f64::NEG_INFINITY,
            1 => -(p - v[0]).norm(),
            _ => {
                let n = v.len();
                let mut nearest = f64::INFINITY;
                let mut inside = n >= 3;
                for i in 0..n {
                    let (a, b) = (v[i], v[(i + 1) % n]);
                    let ab = b - a;
                    let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                    nearest = nearest.min((p - (a + ab * t)).norm());
                    if ab.perp(&(p - a)) < 0.0 {
                        inside = false;
                    }
                }
                if inside { nearest } else { -nearest }
            }
        }
    }

    /// True when `(x, z)` lies inside or on the polygon.
    pub fn contains(&self, p: Point2<f64>) -> bool {
        self.margin(p) >= -1e-12
    }
}

/// The 21-bone, 43-DoF character (see the [module docs](self)). Immutable; poses are
/// [`Pose`]s.
#[derive(Debug, Clone)]
pub struct Character {
    proportions: Proportions,
    joints: Vec<CharacterJoint>,
    bones: Vec<Bone>,
    dof_names: Vec<String>,
    chains: [Chain; 4],
    /// Per joint: the world orientation of its frame at rest.
    rest_world: Vec<Rotation3<f64>>,
    skeleton: Arc<Skeleton>,
}

/// World orientation of the spine's frames at rest: x = +X, y = −Z, z = +Y.
fn spine_frame() -> Rotation3<f64> {
    Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
        Vector3::x(),
        -Vector3::z(),
        Vector3::y(),
    ]))
}

/// World orientation of the arms' rest frames: x = −X, y = −Z, z = −Y.
fn arm_frame() -> Rotation3<f64> {
    Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
        -Vector3::x(),
        -Vector3::z(),
        -Vector3::y(),
    ]))
}

/// World orientation of the legs' rest frames: x = +X, y = +Z, z = −Y.
fn leg_frame() -> Rotation3<f64> {
    Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
        Vector3::x(),
        Vector3::z(),
        -Vector3::y(),
    ]))
}

fn revolute(axis: Axis, min_deg: f64, max_deg: f64) -> Motion {
    Motion::Revolute {
        axis,
        min: min_deg.to_radians(),
        max: max_deg.to_radians(),
    }
}

fn swing(rx_deg: f64, ry_deg: f64) -> Motion {
    Motion::Swing {
        rx: rx_deg.to_radians(),
        ry: ry_deg.to_radians(),
    }
}

/// A leg as a chain: hip swing (120°, 45°) + twist ±40°, knee flexion 0–150° + twist ±30°,
/// ankle swing (45°, 25°); the end effector is the toe tip `(0, toe, ankle_height)`.
fn leg_chain(leg: &LegSegments) -> Result<Chain> {
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

const SPINE_ORDER: [Axis; 3] = [Axis::Y, Axis::X, Axis::Z];
const LIMB_ORDER: [Axis; 3] = [Axis::Z, Axis::Y, Axis::X];

/// Builds the joint list, assigning DoF indices in order.
struct JointBuilder {
    joints: Vec<CharacterJoint>,
    dof_names: Vec<String>,
}

impl JointBuilder {
    #[allow(clippy::too_many_arguments)]
    fn push(
        &mut self,
        name: &str,
        parent: Option<usize>,
        offset: Vector3<f64>,
        rest: Rotation3<f64>,
        motions: Vec<Motion>,
        names: Vec<String>,
        channel_order: [Axis; 3],
    ) {
        let translates = parent.is_none();
        let mut dofs = Vec::new();
        if translates {
            dofs.extend([Axis::X, Axis::Y, Axis::Z].map(DofKind::Translation));
        }
        for m in &motions {
            match m {
                Motion::Swing { .. } => dofs.extend([DofKind::SwingX, DofKind::SwingY]),
                Motion::Revolute { axis: Axis::Z, .. } => dofs.push(DofKind::Twist),
                Motion::Revolute { .. } => dofs.push(DofKind::Flexion),
            }
        }
        debug_assert_eq!(dofs.len(), names.len());
        self.joints.push(CharacterJoint {
            name: name.to_string(),
            parent,
            offset,
            rest,
            translates,
            motions,
            dofs,
            first_dof: self.dof_names.len(),
            end_site: false,
            channel_order,
        });
        self.dof_names.extend(names);
    }

    fn fixed(&mut self, name: &str, parent: usize, offset: Vector3<f64>, end_site: bool) {
        self.joints.push(CharacterJoint {
            name: name.to_string(),
            parent: Some(parent),
            offset,
            rest: Rotation3::identity(),
            translates: false,
            motions: Vec::new(),
            dofs: Vec::new(),
            first_dof: self.dof_names.len(),
            end_site,
            channel_order: LIMB_ORDER,
        });
    }
}

impl Character {
    /// The character with these proportions (validated first).
    pub fn new(proportions: &Proportions) -> Result<Character> {
        proportions.validate()?;
        let p = proportions;
        let s = &p.spine;
        let spine_rest = spine_frame();
        let arm_rest = spine_rest.inverse() * arm_frame();
        let leg_rest = spine_rest.inverse() * leg_frame();
        let chains = [
            Chain::arm(p.right_arm.upper_arm, p.right_arm.forearm, p.right_arm.hand)?,
            Chain::arm(p.left_arm.upper_arm, p.left_arm.forearm, p.left_arm.hand)?,
            leg_chain(&p.right_leg)?,
            leg_chain(&p.left_leg)?,
        ];
        let up = |h: f64| Vector3::new(0.0, 0.0, h);
        let spine_names = |joint: &str| {
            ["swing_x", "swing_y", "twist"]
                .map(|d| format!("{joint}_{d}"))
                .to_vec()
        };
        let spine_motions =
            |rx: f64, ry: f64, twist: f64| vec![swing(rx, ry), revolute(Axis::Z, -twist, twist)];
        let mut b = JointBuilder {
            joints: Vec::with_capacity(joint::COUNT),
            dof_names: Vec::with_capacity(DOF_COUNT),
        };
        let mut root_names: Vec<String> =
            ["root_tx", "root_ty", "root_tz"].map(String::from).to_vec();
        root_names.extend(spine_names("root"));
        b.push(
            "Hips",
            None,
            Vector3::zeros(),
            spine_rest,
            spine_motions(90.0, 45.0, 180.0),
            root_names,
            SPINE_ORDER,
        );
        b.push(
            "Spine",
            Some(joint::HIPS),
            up(s.sacrum),
            Rotation3::identity(),
            spine_motions(50.0, 30.0, 20.0),
            spine_names("lumbar"),
            SPINE_ORDER,
        );
        b.push(
            "Chest",
            Some(joint::SPINE),
            up(s.lumbar),
            Rotation3::identity(),
            spine_motions(40.0, 30.0, 35.0),
            spine_names("thoracic"),
            SPINE_ORDER,
        );
        b.push(
            "Neck",
            Some(joint::CHEST),
            up(s.thoracic),
            Rotation3::identity(),
            spine_motions(60.0, 45.0, 80.0),
            spine_names("cervical"),
            SPINE_ORDER,
        );
        b.fixed("Head", joint::NECK, up(s.neck), false);
        b.fixed("Head_End", joint::HEAD, up(s.head), true);
        let limb = |b: &mut JointBuilder, limb: Limb, parent: usize, offset: Vector3<f64>| {
            let chain = &chains[limb.index()];
            let side = match limb.side() {
                Side::Right => "Right",
                Side::Left => "Left",
            };
            let names = if limb.is_arm() {
                ["Arm", "ForeArm", "Hand"]
            } else {
                ["UpLeg", "Leg", "Foot"]
            };
            let prefix = if limb.side() == Side::Right {
                "right"
            } else {
                "left"
            };
            let rest = if limb.is_arm() { arm_rest } else { leg_rest };
            let mut previous = parent;
            for (i, cj) in chain.joints().iter().enumerate() {
                let (offset, rest) = if i == 0 {
                    (offset, rest)
                } else {
                    (cj.offset, cj.rest)
                };
                b.push(
                    &format!("{side}{}", names[i]),
                    Some(previous),
                    offset,
                    rest,
                    cj.motions.clone(),
                    cj.dof_names
                        .iter()
                        .map(|n| format!("{prefix}_{n}"))
                        .collect(),
                    LIMB_ORDER,
                );
                previous = b.joints.len() - 1;
            }
            b.fixed(
                &format!("{side}{}_End", names[2]),
                previous,
                chain.end_effector(),
                true,
            );
        };
        let shoulder_at = up(s.thoracic - s.shoulder_drop);
        for (limb_id, name, x) in [
            (Limb::RightArm, "RightShoulder", -0.5 * p.shoulder_width),
            (Limb::LeftArm, "LeftShoulder", 0.5 * p.shoulder_width),
        ] {
            b.fixed(name, joint::CHEST, shoulder_at, false);
            let clavicle = b.joints.len() - 1;
            limb(&mut b, limb_id, clavicle, Vector3::new(x, 0.0, 0.0));
        }
        let root = p.root_height();
        for (limb_id, x) in [
            (Limb::RightLeg, -0.5 * p.hip_width),
            (Limb::LeftLeg, 0.5 * p.hip_width),
        ] {
            let hip_y = p.leg(limb_id.side()).hip_height() - root;
            // Spine-frame coordinates: world (x, y, 0) is (x, 0, y).
            limb(&mut b, limb_id, joint::HIPS, Vector3::new(x, 0.0, hip_y));
        }
        debug_assert_eq!(b.joints.len(), joint::COUNT);
        debug_assert_eq!(b.dof_names.len(), DOF_COUNT);

        let bones = [
            ("sacrum", joint::HIPS, joint::SPINE),
            ("lumbar", joint::SPINE, joint::CHEST),
            ("thorax", joint::CHEST, joint::NECK),
            ("neck", joint::NECK, joint::HEAD),
            ("head", joint::HEAD, joint::HEAD_END),
            ("right_clavicle", joint::RIGHT_SHOULDER, joint::RIGHT_ARM),
            ("right_upper_arm", joint::RIGHT_ARM, joint::RIGHT_FOREARM),
            ("right_forearm", joint::RIGHT_FOREARM, joint::RIGHT_HAND),
            ("right_hand", joint::RIGHT_HAND, joint::RIGHT_HAND_END),
            ("left_clavicle", joint::LEFT_SHOULDER, joint::LEFT_ARM),
            ("left_upper_arm", joint::LEFT_ARM, joint::LEFT_FOREARM),
            ("left_forearm", joint::LEFT_FOREARM, joint::LEFT_HAND),
            ("left_hand", joint::LEFT_HAND, joint::LEFT_HAND_END),
            ("right_pelvis", joint::HIPS, joint::RIGHT_UP_LEG),
            ("right_thigh", joint::RIGHT_UP_LEG, joint::RIGHT_LEG),
            ("right_shank", joint::RIGHT_LEG, joint::RIGHT_FOOT),
            ("right_foot", joint::RIGHT_FOOT, joint::RIGHT_FOOT_END),
            ("left_pelvis", joint::HIPS, joint::LEFT_UP_LEG),
            ("left_thigh", joint::LEFT_UP_LEG, joint::LEFT_LEG),
            ("left_shank", joint::LEFT_LEG, joint::LEFT_FOOT),
            ("left_foot", joint::LEFT_FOOT, joint::LEFT_FOOT_END),
        ]
        .map(|(name, from, to)| Bone { name, from, to })
        .to_vec();

        let joints = b.joints;
        let mut rest_world: Vec<Rotation3<f64>> = Vec::with_capacity(joints.len());
        for j in &joints {
            let parent = j.parent.map_or(Rotation3::identity(), |p| rest_world[p]);
            rest_world.push(parent * j.rest);
        }
        let skeleton_joints = joints
            .iter()
            .map(|j| {
                let mut dofs = Vec::new();
                if j.translates {
                    dofs.extend([Axis::X, Axis::Y, Axis::Z].map(Dof::Translation));
                }
                if !j.motions.is_empty() {
                    dofs.extend(j.channel_order.map(Dof::Rotation));
                }
                Joint {
                    name: j.name.clone(),
                    parent: j.parent,
                    offset: j.parent.map_or(j.offset, |p| rest_world[p] * j.offset),
                    dofs,
                    end_site: j.end_site,
                    position_reading: PositionReading::AddToOffset,
                }
            })
            .collect();
        let skeleton = Arc::new(Skeleton::new(skeleton_joints)?);
        Ok(Character {
            proportions: *proportions,
            joints,
            bones,
            dof_names: b.dof_names,
            chains,
            rest_world,
            skeleton,
        })
    }

    /// A character `height` meters tall with Drillis & Contini's proportions.
    pub fn from_height(height: f64) -> Result<Character> {
        Character::new(&Proportions::from_height(height)?)
    }

    /// Its proportions.
    pub fn proportions(&self) -> &Proportions {
        &self.proportions
    }

    /// The joints, parents first (End Sites included); indices as in [`joint`].
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
    /// [module docs](self#joint-limits) and the toe tip `(0, toe, ankle_height)` in the ankle
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

    /// The world frame of the limb's chain base at `pose`: its base joint's frame before the
    /// joint's own motions (parent frame · offset · rest rotation).
    pub fn limb_base_frame(&self, limb: Limb, pose: &Pose) -> IsometryMatrix3<f64> {
        self.limb_base_frame_in(limb, &self.world_frames(pose))
    }

    /// [`Character::limb_base_frame`] from world frames already computed
    /// ([`Character::world_frames`]); only the frames above the limb matter.
    pub fn limb_base_frame_in(
        &self,
        limb: Limb,
        frames: &[IsometryMatrix3<f64>],
    ) -> IsometryMatrix3<f64> {
        let base = limb.joints()[0];
        let j = &self.joints[base];
        let mut frame = j.parent.map_or(IsometryMatrix3::identity(), |p| frames[p]);
        frame.translation.vector += frame.rotation * j.offset;
        frame.rotation *= j.rest;
        frame
    }

    /// Standing at the origin, feet flat on y = 0, facing +Z, arms hanging: every DoF 0
    /// except `root_ty` = [`Proportions::root_height`].
    pub fn rest_pose(&self) -> Pose {
        let mut pose = [0.0; DOF_COUNT];
        pose[dof::ROOT_Y] = self.proportions.root_height();
        pose
    }

    /// Forward kinematics: every joint's world frame (after its motions).
    pub fn world_frames(&self, pose: &Pose) -> Vec<IsometryMatrix3<f64>> {
        let mut out: Vec<IsometryMatrix3<f64>> = Vec::with_capacity(self.joints.len());
        for j in &self.joints {
            let mut frame = j.parent.map_or(IsometryMatrix3::identity(), |p| out[p]);
            let mut k = j.first_dof;
            let mut offset = j.offset;
            if j.translates {
                offset += Vector3::new(pose[k], pose[k + 1], pose[k + 2]);
                k += 3;
            }
            frame.translation.vector += frame.rotation * offset;
            frame.rotation *= j.rest;
            for m in &j.motions {
                frame.rotation *= motion_rotation(m, &pose[k..]);
                k += m.dof_count();
            }
            out.push(frame);
        }
        out
    }

    /// Forward kinematics: every joint's world position, End Sites included, in
    /// [`Character::joints`] order.
    pub fn world_positions(&self, pose: &Pose) -> Vec<Point3<f64>> {
        self.world_frames(pose)
            .iter()
            .map(|f| Point3::from(f.translation.vector))
            .collect()
    }

    /// The foot points `[right heel, right toe, left heel, left toe]` in world.
    pub fn foot_points(&self, pose: &Pose) -> [Point3<f64>; 4] {
        let f = self.world_frames(pose);
        let heel = |ankle: usize, leg: &LegSegments| {
            f[ankle] * Point3::new(0.0, -leg.heel, leg.ankle_height)
        };
        let p = &self.proportions;
        [
            heel(joint::RIGHT_FOOT, &p.right_leg),
            Point3::from(f[joint::RIGHT_FOOT_END].translation.vector),
            heel(joint::LEFT_FOOT, &p.left_leg),
            Point3::from(f[joint::LEFT_FOOT_END].translation.vector),
        ]
    }

    /// Every body segment's mass fraction and centre of mass (Winter's Table 4.1, see the
    /// [module docs](self#centre-of-mass)).
    pub fn mass_segments(&self, pose: &Pose) -> Vec<MassSegment> {
        self.mass_segments_in(&self.world_frames(pose))
    }

    /// [`Character::mass_segments`] from world frames already computed.
    pub fn mass_segments_in(&self, frames: &[IsometryMatrix3<f64>]) -> Vec<MassSegment> {
        let p: Vec<Point3<f64>> = frames
            .iter()
            .map(|f| Point3::from(f.translation.vector))
            .collect();
        let along = |a: usize, b: usize, t: f64| p[a] + (p[b] - p[a]) * t;
        let seg = |name, mass_fraction, com| MassSegment {
            name,
            mass_fraction,
            com,
        };
        let hips_mid =
            Point3::from((p[joint::RIGHT_UP_LEG].coords + p[joint::LEFT_UP_LEG].coords) * 0.5);
        let mut out = vec![
            seg("head_and_neck", 0.081, p[joint::HEAD]),
            seg("thorax", 0.216, along(joint::NECK, joint::CHEST, 0.82)),
            seg("abdomen", 0.139, along(joint::CHEST, joint::SPINE, 0.44)),
            seg(
                "pelvis",
                0.142,
                p[joint::SPINE] + (hips_mid - p[joint::SPINE]) * 0.105,
            ),
        ];
        let arms: [(&'static str, &'static str, &'static str, Limb); 2] = [
            (
                "right_upper_arm",
                "right_forearm",
                "right_hand",
                Limb::RightArm,
            ),
            ("left_upper_arm", "left_forearm", "left_hand", Limb::LeftArm),
        ];
        for (upper, fore, hand, limb) in arms {
            let [s, e, w, t] = limb.joints();
            out.push(seg(upper, 0.028, along(s, e, 0.436)));
            out.push(seg(fore, 0.016, along(e, w, 0.430)));
            out.push(seg(hand, 0.006, along(w, t, 0.253)));
        }
        let legs: [(&'static str, &'static str, &'static str, Limb); 2] = [
            ("right_thigh", "right_shank", "right_foot", Limb::RightLeg),
            ("left_thigh", "left_shank", "left_foot", Limb::LeftLeg),
        ];
        for (thigh, shank, foot, limb) in legs {
            let [h, k, a, t] = limb.joints();
            out.push(seg(thigh, 0.100, along(h, k, 0.433)));
            out.push(seg(shank, 0.0465, along(k, a, 0.433)));
            out.push(seg(foot, 0.0145, along(a, t, 0.35)));
        }
        out
    }

    /// The whole body's centre of mass: the mass-weighted mean of [`Character::mass_segments`].
    pub fn com(&self, pose: &Pose) -> Point3<f64> {
        self.com_in(&self.world_frames(pose))
    }

    /// [`Character::com`] from world frames already computed.
    pub fn com_in(&self, frames: &[IsometryMatrix3<f64>]) -> Point3<f64> {
        let segments = self.mass_segments_in(frames);
        let total: f64 = segments.iter().map(|s| s.mass_fraction).sum();
        let sum = segments.iter().fold(Vector3::zeros(), |acc, s| {
            acc + s.com.coords * s.mass_fraction
        });
        Point3::from(sum / total)
    }

    /// The support polygon: the convex hull in x–z of the feet's soles — each heel and toe
    /// point widened sideways by half the foot breadth ([`FOOT_BREADTH`] of the height) —
    /// of the points within [`CONTACT_TOLERANCE`] of the lowest. One foot on the ground
    /// gives its sole's rectangle, not a line.
    pub fn support_polygon(&self, pose: &Pose) -> SupportPolygon {
        self.support_polygon_in(&self.world_frames(pose))
    }

    /// [`Character::support_polygon`] from world frames already computed.
    pub fn support_polygon_in(&self, f: &[IsometryMatrix3<f64>]) -> SupportPolygon {
        let half = 0.5 * FOOT_BREADTH * self.proportions.height();
        let p = &self.proportions;
        let mut points = Vec::with_capacity(8);
        for (ankle, leg) in [
            (joint::RIGHT_FOOT, &p.right_leg),
            (joint::LEFT_FOOT, &p.left_leg),
        ] {
            for y in [-leg.heel, leg.toe] {
                for x in [-half, half] {
                    points.push(f[ankle] * Point3::new(x, y, leg.ankle_height));
                }
            }
        }
        let lowest = points.iter().map(|p| p.y).fold(f64::INFINITY, f64::min);
        let contact: Vec<Point2<f64>> = points
            .iter()
            .filter(|p| p.y <= lowest + CONTACT_TOLERANCE)
            .map(|p| Point2::new(p.x, p.z))
            .collect();
        SupportPolygon::hull(&contact)
    }

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

    /// The exported skeleton (shared): the character's joints with world-aligned offsets and
    /// BVH channels (see the [module docs](self#bvh-export)).
    pub fn skeleton(&self) -> &Arc<Skeleton> {
        &self.skeleton
    }

    /// The exported skeleton, as an owned value.
    pub fn to_skeleton(&self) -> Skeleton {
        (*self.skeleton).clone()
    }

    /// The skeleton pose (BVH channel values, meters and radians) of a character pose.
    /// `near`, the previous frame's skeleton pose, picks the Euler solutions nearest it.
    pub fn skeleton_pose(&self, pose: &Pose, near: Option<&[f64]>) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.skeleton.dof_count());
        for (j, joint) in self.joints.iter().enumerate() {
            let mut k = joint.first_dof;
            if joint.translates {
                out.extend_from_slice(&pose[k..k + 3]);
                k += 3;
            }
            if joint.motions.is_empty() {
                continue;
            }
            let mut m = Rotation3::identity();
            for motion in &joint.motions {
                m *= motion_rotation(motion, &pose[k..]);
                k += motion.dof_count();
            }
            let c = self.rest_world[j];
            let bvh = c * m * c.inverse();
            // Three distinct axes always decompose.
            let angles = euler_angles(joint.channel_order, &bvh).unwrap_or_default();
            let start = out.len();
            let angles = match near.and_then(|n| n.get(start..start + 3)) {
                Some(n) => nearest_euler(angles, [n[0], n[1], n[2]]),
                None => angles,
            };
            out.extend_from_slice(&angles);
        }
        out
    }

    /// A clip of the exported skeleton playing `poses` at `frame_time` seconds per frame.
    /// Write it with [`kinergy_motion::write_clip`].
    pub fn to_clip(&self, poses: &[Pose], frame_time: f64) -> Result<Clip> {
        let n = self.skeleton.dof_count();
        let mut values: Vec<f64> = Vec::with_capacity(poses.len() * n);
        let mut previous: Option<Vec<f64>> = None;
        for pose in poses {
            let frame = self.skeleton_pose(pose, previous.as_deref());
            values.extend_from_slice(&frame);
            previous = Some(frame);
        }
        Ok(Clip::new(self.skeleton.clone(), frame_time, values)?)
    }
}

/// The rotation of one motion at DoF values `q` (its first one or two).
fn motion_rotation(m: &Motion, q: &[f64]) -> Rotation3<f64> {
    match *m {
        Motion::Revolute { axis, .. } => axis_rotation(axis, q[0]),
        Motion::Swing { .. } => swing_rotation(q[0], q[1]),
    }
}

/// Of the two Tait–Bryan solutions (α, β, γ) and (α + π, π − β, γ + π), each unwrapped
/// toward `near`, the one closest to `near`.
fn nearest_euler(angles: [f64; 3], near: [f64; 3]) -> [f64; 3] {
    use std::f64::consts::PI;
    let [a, b, c] = angles;
    let mut best = angles;
    let mut best_d = f64::INFINITY;
    for cand in [[a, b, c], [a + PI, PI - b, c + PI]] {
        let un = [0, 1, 2].map(|i| unwrap_near(cand[i], near[i]));
        let d: f64 = un.iter().zip(&near).map(|(x, y)| (x - y).powi(2)).sum();
        if d < best_d {
            best_d = d;
            best = un;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tokens_and_roles_of_common_leg_names() {
        assert_eq!(
            side_and_role("RightUpLeg"),
            (Some(Side::Right), "upleg".into())
        );
        assert_eq!(
            side_and_role("RHipJoint"),
            (Some(Side::Right), "hipjoint".into())
        );
        assert_eq!(side_and_role("Calf_L"), (Some(Side::Left), "calf".into()));
        assert!(is_knee_role("leg") && !is_knee_role("upleg") && is_hip_role("thigh"));
        assert!(!is_hip_role("hipjoint"));
    }

    #[test]
    fn hull_drops_interior_and_collinear_points() {
        let pts = [
            Point2::new(0.0, 0.0),
            Point2::new(1.0, 0.0),
            Point2::new(0.5, 0.0),
            Point2::new(1.0, 1.0),
            Point2::new(0.0, 1.0),
            Point2::new(0.5, 0.5),
        ];
        let hull = SupportPolygon::hull(&pts);
        assert_eq!(hull.vertices().len(), 4);
        assert!((hull.margin(Point2::new(0.5, 0.5)) - 0.5).abs() < 1e-15);
        assert!((hull.margin(Point2::new(2.0, 0.5)) + 1.0).abs() < 1e-15);
    }
}
