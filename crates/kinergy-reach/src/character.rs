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
//! The files, one concept each:
//!
//! | module | what |
//! |---|---|
//! | [`layout`] | index tables: [`joint`] and [`dof`] indices, [`Limb`], [`SpineJoint`], DoF kinds, rest frames and BVH channel orders |
//! | [`proportions`] | [`Ratios`], the segments and [`Proportions`] |
//! | [`measure`] | the proportions measured on a capture's skeleton |
//! | [`body`] | the [`Character`] built from its joint table, its bones, forward kinematics, poses checked and clamped into the limits |
//! | [`mass`] | segment masses, the centre of mass, foot points and the [`SupportPolygon`] |
//! | [`girdle`] | the shoulder girdle: the clavicle's elevation and retraction by the scapulohumeral rhythm |
//! | [`limits`] | the joint limits' values |
//! | [`export`] | the BVH skeleton and clip |
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
//! | 6, 11 | `RightShoulder`, `LeftShoulder` | Chest | sternoclavicular joint, on the thoracic bone: elevation + retraction driven by the arm's elevation ([`girdle`]) | 0 (dependent) | `Zrotation Yrotation Xrotation` |
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
//! clavicles (…Shoulder→…Arm), the shoulder bones, with no DoFs of their own — each turns by
//! its arm's elevation through the scapulohumeral rhythm ([`girdle`]; the arm's DoFs stay
//! humerothoracic, its base joint turning back by the clavicle's rotation): 2; the two pelvic bones
//! (Hips→…UpLeg), rigid with the root, so 0 DoFs of their own: 2; three bones per limb
//! (upper arm, forearm, hand; thigh, shank, foot): 12. 5 + 2 + 2 + 12 = 21. The clavicle
//! joints sit on the thoracic bone (Chest→…Shoulder is collinear with Chest→Neck), so that
//! link is not a bone of its own. **DoFs**: sacral 6 + lumbar 3 + thoracic 3 + cervical 3 +
//! 4 limbs × 7 = 6 + 3 + 3 + 3 + 28 = 43.
//!
//! [`Chain`]: kinergy_motion::Chain

pub mod body;
pub mod export;
pub mod girdle;
pub mod layout;
pub mod limits;
pub mod mass;
pub mod measure;
pub mod proportions;

pub use body::{
    Bone, Character, CharacterJoint, DofLimit, GirdleRole, GirdleTurn, OVERHEAD_TWIST_FROM,
    angle_difference, wrap_or_clamp,
};
pub use girdle::{ArmGirdle, Girdle, GirdleAngles};
pub use layout::{BONE_COUNT, DOF_COUNT, DofKind, Limb, Pose, SpineJoint, dof, joint};
pub use mass::{CONTACT_TOLERANCE, FOOT_BREADTH, MassSegment, SupportPolygon};
pub use proportions::{ArmSegments, LegSegments, Proportions, Ratios, SpineSegments};
