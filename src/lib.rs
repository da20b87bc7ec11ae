//! Kinergy learns how a particular person moves their arm when reaching, and synthesizes
//! reaching motions in that style.
//!
//! This umbrella crate re-exports the library crates as modules:
//! - [`bvh`]: the BVH format alone, read and written at full precision, never panicking;
//! - [`motion`]: skeletons, poses, clips, forward kinematics, Jacobians, joint limits, arm
//!   chains by role, the motion distance and hand-speed series.
//!
//! `use kinergy::prelude::*;` brings the types most programs need.
//!
//! ```
//! use kinergy::prelude::*;
//!
//! let arm = Chain::arm(0.30, 0.25, 0.08)?;
//! let base = kinergy::motion::nalgebra::IsometryMatrix3::identity();
//! let hand = arm.end_position(&base, &[0.0; 7])?;
//! assert!((hand.z - 0.63).abs() < 1e-12);
//! # Ok::<(), kinergy::motion::MotionError>(())
//! ```
#![warn(clippy::print_stdout, clippy::print_stderr)]

pub use kinergy_bvh as bvh;
pub use kinergy_motion as motion;

/// The types most programs need.
pub mod prelude {
    pub use kinergy_bvh::Bvh;
    pub use kinergy_motion::{
        ArmJoints, Chain, Clip, ExportOptions, ImportOptions, LengthUnit, MotionError, Side,
        Skeleton, Trajectory, UnitChoice, clip_from_bvh, clip_to_bvh, motion_distance, read_clip,
        write_clip,
    };
}
