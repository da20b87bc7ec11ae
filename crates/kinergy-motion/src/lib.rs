//! Skeletons, poses, clips and the kinematics Kinergy is built on.
//!
//! - [`Skeleton`]: an immutable joint hierarchy with BVH-style DoFs; a pose is a `&[f64]`
//!   (radians, meters). [`Skeleton::fk`] gives world transforms, [`Skeleton::jacobian`] the
//!   positional Jacobian of any joint or End Site w.r.t. any DoFs.
//! - [`Clip`]: a skeleton and its poses over time, resampled with slerp.
//! - [`clip_from_bvh`] / [`clip_to_bvh`]: BVH ↔ clip in SI units, with the unit guessed or
//!   given and a documented reading of position channels ([`convert`]).
//! - [`ArmJoints`], [`LegJoints`]: the arm chain and the leg found by joint role in CMU,
//!   Bandai Namco, Character Creator, Mixamo and Collar-style skeletons ([`limbs`]).
//! - [`Chain`]: serial chains for IK, among them the 7-DoF swing-twist [`Chain::arm`], with
//!   joint limits, FK and the Jacobian.
//! - [`Trajectory`] and [`motion_distance`]: the paper's joint-position motion distance, and
//!   hand-speed series.
//! - [`seed`]: seed mixing (SplitMix64), one place for every seeded stream.
//! - [`segment`]: the reach segments of a clip from its hand-speed series (onset, peak, end,
//!   label).
//!
//! Conventions: SI units, right-handed, Y up.
//!
//! ```
//! use kinergy_motion::{clip_from_bvh, ArmJoints, ImportOptions, Side, motion_distance};
//!
//! let text = "HIERARCHY\nROOT Chest\n{\n OFFSET 0 140 0\n CHANNELS 3 Zrotation Xrotation Yrotation\n \
//!     JOINT RightShoulder\n {\n  OFFSET -5 10 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n  \
//!     JOINT RightArm\n  {\n   OFFSET -15 0 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n   \
//!     JOINT RightForeArm\n   {\n    OFFSET -28 0 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n    \
//!     JOINT RightHand\n    {\n     OFFSET -26 0 0\n     CHANNELS 3 Zrotation Xrotation Yrotation\n     \
//!     End Site\n     {\n      OFFSET -9 0 0\n     }\n    }\n   }\n  }\n }\n}\n\
//!     MOTION\nFrames: 2\nFrame Time: 0.0333333\n\
//!     0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n0 0 0 0 0 0 -45 0 0 0 0 0 0 0 0\n";
//! let bvh = kinergy_bvh::parse(text)?;
//! let options = ImportOptions { unit: "cm".parse()?, ..Default::default() };
//! let (clip, _report) = clip_from_bvh(&bvh, &options)?;
//! let arm = ArmJoints::find(clip.skeleton(), Side::Right)?;
//! let hand = clip.trajectory(&arm.metric_joints())?;
//! assert_eq!(motion_distance(&hand, &hand)?, 0.0);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(clippy::print_stdout, clippy::print_stderr)]

pub mod chain;
pub mod clip;
pub mod convert;
pub mod error;
pub mod fidelity;
pub mod glitch;
pub mod jumps;
pub mod limbs;
pub mod retarget;
pub mod rotation;
pub mod seed;
pub mod segment;
pub mod side;
pub mod skeleton;
pub mod trajectory;
pub mod trig;
pub mod units;
pub mod up;

pub use chain::{Chain, ChainJoint, ChainPose, Linearization, Motion, TrigMemo};
pub use clip::{
    Clip, FromPositions, JointMap, PositionArrays, PositionTable, Stretch, TableReading,
    read_names, read_positions_csv, read_positions_npy,
};
pub use convert::{
    ExportOptions, ImportOptions, ImportReport, PositionReadingChoice, clip_from_bvh, clip_to_bvh,
    read_clip, write_clip,
};
pub use convert::{ExportUp, RootReading, RootReadingBasis};
pub use error::{MotionError, Result};
pub use glitch::{Glitch, GlitchOptions, find_glitches};
pub use limbs::{ArmJoints, ArmLengths, BodyJoints, LegJoints};
pub use retarget::{RetargetReport, Retargeted, Retargeter, TargetArms, with_source_arms};
pub use rotation::Axis;
pub use side::Side;
pub use skeleton::{Dof, Joint, PositionReading, Skeleton};
pub use trajectory::{Trajectory, frame_distance, motion_distance, speed_series};
pub use units::{LengthUnit, UnitChoice};
pub use up::{UpAxis, UpChoice, UpDetection};

/// The linear-algebra crate of every public type here, re-exported so callers use the same version.
pub use nalgebra;

/// The BVH format crate the conversion reads and writes, re-exported so callers use the same
/// version (and need not depend on it to parse text).
pub use kinergy_bvh;
