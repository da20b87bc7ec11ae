//! Kinergy learns how a particular person moves their arm when reaching, and synthesizes
//! reaching motions in that style.
//!
//! This umbrella crate re-exports the library crates as modules:
//! - [`io`]: atomic file replacement and versioned JSON documents, shared by every crate;
//! - [`bvh`]: the BVH format alone, read and written at full precision, never panicking;
//! - [`motion`]: skeletons, poses, clips, forward kinematics, Jacobians, joint limits, arm
//!   chains by role, the motion distance and hand-speed series;
//! - [`solver`]: the synergy IK — the JT, NJT, SVD and DLS optimizers, the synergy
//!   transform S_A–S_D with named, bounded parameters, the frame-by-frame controller, arms
//!   taken from captures, and the parameters file;
//! - [`train`]: fitting synergy parameters to captured reaches — segmentation, simulated
//!   annealing with checkpoints, per-clip and per-person nested fits, argmin baselines, the
//!   parameter field over targets;
//! - [`reach`]: full-body reaching — the 43-DoF character, speed profiles, stepping, the
//!   controllers and their scheduler, the synthetic motion-capture set;
//! - [`plan`]: collision-free reaching and manipulation (Kallmann 2005) — body capsules,
//!   JSON scenes with OBJ meshes, IK with collision avoidance, RRT-Connect, smoothing,
//!   grasp / relocate / push-pull.
//!
//! `use kinergy::prelude::*;` brings the types most programs need. From a person's takes to
//! the full-body character reaching a new target in their style (`cargo run --release
//! --example person_reach` is the same with a full budget and a BVH written):
//!
//! ```
//! use kinergy::prelude::*;
//!
//! // Each take's main reach of the right arm, riding on the captured torso.
//! let mut reaches = Vec::new();
//! for path in capture_files(&["data-synthetic/p01/r01.bvh".into(), "data-synthetic/p01/r02.bvh".into()])? {
//!     let take = Capture::read(&path, &ImportOptions::default())?;
//!     let main = ReachFrames::Segments(Selection::Main);
//!     reaches.extend(take.reaches(&ArmChoice::side(Side::Right), &main, BaseMode::Replay)?);
//! }
//! // One vector for the person: S_A, then S_C from its solution (a small budget here).
//! let anneal = AnnealSettings { max_evaluations: 48, seed: 1, ..AnnealSettings::default() };
//! let settings = FitSettings { anneal, ..FitSettings::default() };
//! let svd = OptimizerKind::Svd.default_optimizer();
//! let fits = fit_nested(&reaches, &[Model::Sa, Model::Sc], svd, &settings)?;
//! let person = fits.params_file(&reaches, FitGrouping::Person)?;
//! // The character reaches a new target in their style.
//! let character = Character::from_height(1.75)?;
//! let target = Point3::new(-0.3, 1.3, 0.45);
//! let arm = PersonArm::toward(&character, &person, &target, None)?;
//! let motion = reach_full_body_driven(&character, target, &ReachSettings::default(), &arm.drive)?;
//! assert_eq!(Ending::of(&character, &motion), Ending::Reached);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! ```
//! use kinergy::prelude::*;
//!
//! let arm = Chain::arm(0.30, 0.25, 0.08)?;
//! let base = kinergy::motion::nalgebra::IsometryMatrix3::identity();
//! let hand = arm.end_position(&base, &[0.0; 7])?;
//! assert!((hand.z - 0.63).abs() < 1e-12);
//!
//! // Reach a point 40 cm in front of the shoulder with SVD and the neutral S_A.
//! let controller = Controller::new(
//!     OptimizerKind::Svd.default_optimizer(),
//!     Synergy::identity(7),
//!     ControllerSettings::at_frame_time(1.0 / 120.0),
//! )?;
//! let target = kinergy::motion::nalgebra::Point3::new(0.1, -0.2, 0.35);
//! let start = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
//! let motion = controller.synthesize(&ArmTask {
//!     chain: &arm,
//!     base: &Base::Fixed(base),
//!     start: &start,
//!     task: Task::Position(target),
//!     start_velocity: None,
//! })?;
//! assert_eq!(motion.stop, StopReason::Reached);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(clippy::print_stdout, clippy::print_stderr)]

pub use kinergy_bvh as bvh;
pub use kinergy_io as io;
pub use kinergy_motion as motion;
pub use kinergy_plan as plan;
pub use kinergy_reach as reach;
pub use kinergy_solver as solver;
pub use kinergy_train as train;

/// The types most programs need: read captures, fit a person, and drive the arm alone or
/// the full body (and a planned task) in their style.
pub mod prelude {
    pub use kinergy_bvh::Bvh;
    pub use kinergy_motion::nalgebra::{Point3, Vector3};
    pub use kinergy_motion::segment::Selection;
    pub use kinergy_motion::{
        ArmJoints, Chain, Clip, ExportOptions, ImportOptions, LengthUnit, MotionError, Side,
        Skeleton, Trajectory, UnitChoice, clip_from_bvh, clip_to_bvh, motion_distance, read_clip,
        write_clip,
    };
    pub use kinergy_plan::scene::Scene;
    pub use kinergy_plan::task::{Manipulation, Planner, TaskSettings};
    pub use kinergy_reach::character::{Character, Limb, Proportions};
    pub use kinergy_reach::controller::{
        ArmDrive, Ending, ReachMotion, ReachReport, ReachSettings, reach_full_body_driven,
    };
    pub use kinergy_reach::drive::{Driver, PersonArm};
    pub use kinergy_solver::{
        ArmTask, Base, BaseMode, CaptureArm, Controller, ControllerSettings, FitGrouping, Model,
        Optimizer, OptimizerKind, ParamSpace, ParamsFile, PersonStyle, SolverError, StopReason,
        Synergy, Synthesis, Task,
    };
    pub use kinergy_train::anneal::AnnealSettings;
    pub use kinergy_train::fit::{Fit, FitSettings, NestedFit, fit_nested};
    pub use kinergy_train::source::{ArmChoice, Capture, ReachFrames, capture_files};
    pub use kinergy_train::{CapturedReach, PersonParams};
}
