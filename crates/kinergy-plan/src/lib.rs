//! Collision-free reaching and manipulation after Kallmann (2005), *Scalable Solutions for
//! Interactive Virtual Humans that can Manipulate Objects* (DESIGN §1.3).
//!
//! - [`body`]: capsules on the character's bones and the pairs never tested;
//! - [`scene`]: obstacles and graspable objects from JSON (boxes, spheres, capsules, OBJ
//!   meshes), [`obj`]: the OBJ reader, [`shelf`]: the bookshelf example's shelf unit;
//! - [`space`]: the arm's configuration space: collision tests, Kallmann's distance, IK with
//!   collision avoidance (the orbit-angle search rejecting colliding postures);
//! - [`posture`]: the body's DoFs in a configuration (the spine's swing and twist, the squat,
//!   the feet planted), used where the arm alone cannot reach its goal;
//! - [`level`]: Kallmann's three levels of a reach — IK, IK with collision avoidance along a
//!   straight hand line, the planner — and `auto`, which escalates from one to the next;
//! - [`rrt`]: bidirectional RRT-Connect (Algorithm 1), shortcut smoothing, the bell time warp;
//! - [`hand`]: hand targets' grip point, hand shapes, fingers in the BVH export;
//! - [`task`]: reach, grasp, relocate and push/pull sequences made of planned and straight
//!   motions;
//! - [`approach`]: a reach finished by a person's synergy controller where its motion is free;
//! - [`report`]: the moved objects' poses per frame, as a task's report writes and reads them.

pub mod approach;
pub mod body;
mod colliders;
pub mod error;
pub mod hand;
pub mod level;
pub mod obj;
pub mod person;
pub mod posture;
pub mod report;
pub mod request;
pub mod rrt;
pub mod scene;
pub mod shelf;
pub mod space;
pub mod task;

pub use error::{PlanError, Result};
