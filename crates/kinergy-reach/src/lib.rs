//! Full-body reaching after Huang, Kapadia & Terzopoulos (DESIGN §1.2): the 21-bone,
//! 43-DoF character, the arm, spine, head and leg controllers and their scheduler, and the
//! synthetic motion capture made with them.
//!
//! - [`character`]: the character's skeleton, proportions and BVH export;
//! - [`profile`]: hand speed profiles (the paper's ease-out, a minimum-jerk bell);
//! - [`steps`]: the leg controller's decisions (reaching cylinders, step probability, half
//!   or full step, step length) and foot and root paths;
//! - [`controller`]: the controllers and their scheduler, run by
//!   [`controller::reach_full_body`];
//! - [`synth`]: the synthetic motion-capture set.
#![warn(clippy::print_stdout, clippy::print_stderr)]

pub mod character;
pub mod controller;
pub mod drive;
pub mod error;
pub mod profile;
pub mod steps;
pub mod style;
pub mod synth;

pub use error::{ReachError, Result};
