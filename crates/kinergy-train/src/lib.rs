//! Fitting joint-synergy parameters to captured reaches (Aubry, Julliard & Gibet 2009, §3.3–4;
//! DESIGN §1.1):
//!
//! - [`listing`]: a capture's labelled segments, arm by arm, as `segment` lists them
//!   (segmentation itself is `kinergy_motion::segment`: it needs only motion types);
//! - [`segments_file`]: the segments file — clips, frames, arm, label, person — read and written;
//! - [`captured`]: a captured reach prepared for fitting — start posture, target, the person's
//!   arm, the captured torso motion the synthesized arm rides on — and its score, the
//!   joint-position motion distance;
//! - [`source`]: one path from a capture file — read options, arm, frames, selection or a
//!   segments-file row — to its captured reaches;
//! - [`objective`]: the mean distance of a parameter vector over a set of reaches, as a
//!   bounded [`CostFunction`];
//! - [`anneal`]: simulated annealing (population, adaptive steps, Metropolis acceptance,
//!   cooling; greedy at temperature zero), parallel and reproducible on any thread count,
//!   with checkpoints that resume bit for bit;
//! - [`fit`]: per-clip and per-person fits, richer models started from poorer ones;
//! - [`baseline`]: the same objective under argmin's Nelder–Mead and particle swarm;
//! - [`experiment`]: the paper's comparison of models and optimizers on a set of reaches,
//!   with annealing against the baselines and the field left one target out;
//! - [`field`]: parameters as a smooth function of the target, per person, and the field
//!   file that carries them;
//! - [`person`]: a person's parameters from a parameters file or a field file, for a target;
//! - [`synthetic`]: reaches made by the controller itself from known parameters;
//! - [`who`]: who moves in a take and which motion it is — the person rule of a library and
//!   of `compare --per person` (folder, file-name patterns, a pattern, a mapping file).
#![warn(clippy::print_stdout, clippy::print_stderr)]

pub mod anneal;
pub mod baseline;
pub mod captured;
pub mod error;
pub mod experiment;
pub mod fidelity;
pub mod field;
pub mod fit;
pub mod library;
pub mod limits;
pub mod listing;
pub mod objective;
pub mod person;
pub mod segments_file;
pub mod source;
pub mod style;
pub mod synthesize;
pub mod synthetic;
pub mod who;

pub use captured::{
    CapturedReach, MAX_TARGET_DISTANCE, ReachDrive, Replay, measured_arm, person_tempo,
    under_person_tempo,
};
pub use error::{Result, TrainError};
pub use objective::{CostFunction, Objective};
pub use person::PersonParams;
