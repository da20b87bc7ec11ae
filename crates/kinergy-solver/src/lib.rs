//! Synergy IK: iterative IK optimizers, the joint-synergy transform S_A–S_D (and S_E, beyond
//! the paper) and the controller that synthesizes a reach frame by frame (Aubry, Julliard &
//! Gibet 2009, DESIGN §1.1).
//!
//! - [`Optimizer`]: `jt`, `njt`, `svd`, `dls` turn the task error ΔX into a joint step Δθ
//!   ([`optimizer`] documents each formula and why the SVD goes through 3 × 3 algebra).
//! - [`Synergy`] in a [`ParamSpace`]: Δθ'_i = φ_i(t)·g_i·Δθ_i, the models [`Model`] S_A–S_D
//!   and S_E with named, bounded parameters; [`ParamsFile`] is their JSON file, with the
//!   [`FitRecord`] of how they were fitted.
//! - [`Controller`]: Θ ← clamp(Θ + S(t)·O(ΔX)) each frame, with a typed [`StopReason`].
//! - [`ReachSphere`]: near full extension the elbow takes the distance by the law of cosines
//!   and the optimizer the rest ([`reachability`]), so reaches to the edge of the arm's reach
//!   end on their target and targets beyond it stretched toward them.
//! - [`CaptureArm`]: the 7-DoF chain of a captured arm with the person's bone lengths, its
//!   base riding on the captured shoulder, the captured start posture, and the way back to
//!   the capture's skeleton for BVH output.
//!
//! ```
//! use kinergy_motion::Chain;
//! use kinergy_motion::nalgebra::{IsometryMatrix3, Point3};
//! use kinergy_solver::{Base, Controller, ControllerSettings, OptimizerKind, ArmTask, StopReason, Synergy, Task};
//!
//! let arm = Chain::arm(0.30, 0.26, 0.09)?;
//! let base = Base::Fixed(IsometryMatrix3::identity());
//! let start = [1.2, 0.0, 0.0, 0.6, 0.0, 0.0, 0.0];
//! let controller = Controller::new(
//!     OptimizerKind::Svd.default_optimizer(),
//!     Synergy::identity(7),
//!     ControllerSettings::at_frame_time(1.0 / 120.0),
//! )?;
//! let task = ArmTask { chain: &arm, base: &base, start: &start, task: Task::Position(Point3::new(0.1, -0.2, 0.45)), start_velocity: None };
//! let motion = controller.synthesize(&task)?;
//! assert_eq!(motion.stop, StopReason::Reached);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(clippy::print_stdout, clippy::print_stderr)]

pub mod analytic;
pub mod capture;
pub mod controller;
pub mod error;
pub mod fit_record;
pub mod optimizer;
pub mod params;
pub mod person;
pub mod reachability;
pub mod smoothing;
pub mod synergy;
pub mod task;

pub use capture::{BaseMode, CaptureArm, arms_beyond_limits, widen_to_include};
pub use controller::{
    ArmStepper, ArmTask, Base, Controller, ControllerSettings, LimitHandling, Observation,
    StallRule, StopReason, Synthesis,
};
pub use error::{Result, SolverError};
pub use fit_record::{
    ControllerKind, FitGrouping, FitMethod, FitObjective, FitRecord, FitStatus, FittedArm,
    FittedReach, PersonTempo, ReachTempo, StageScore,
};
pub use optimizer::{
    DampedLeastSquares, NormalizedTranspose, Optimizer, OptimizerKind, PseudoInverse, StepScratch,
    Transpose,
};
pub use params::{FORMAT_VERSION, ParamsFile};
pub use person::{FieldUse, PersonStyle, StyleAt, StyleError};
pub use reachability::ReachSphere;
pub use smoothing::{Finish, Smoothing};
pub use synergy::{
    ACCELERATION, Bounds, GROWTH, Interval, Model, OFFSET_ON, ONSET, ParamKind, ParamSpace,
    Synergy, TempoFactors, growth_factor, sig,
};
pub use task::{Task, TaskError};
