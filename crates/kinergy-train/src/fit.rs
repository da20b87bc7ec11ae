//! Fitting a synergy model to captured reaches: per clip (the paper's experiment: one reach,
//! one vector) or per person (one vector for all of a person's reaches), and the nested
//! sequence S_A → S_B → S_C → S_D (→ S_E) in which each richer model starts from the poorer
//! one's solution.
//!
//! **The nested guarantee.** A richer model starts from the poorer one's solution carried
//! into its space ([`ParamSpace::extend_to`]), and its fit keeps that vector unless its
//! search finds a better one, so a richer fit never scores worse than the carried vector.
//! Every carry-over is exact, the same motion bit for bit: S_A → S_B copies the gain,
//! S_C → S_D the shared sigmoid, S_D → S_E adds no growth and tempo factors 1, and S_A or
//! S_B → S_C adds a sigmoid already on before the motion starts (o at the default bounds'
//! lower end, [`kinergy_solver::OFFSET_ON`], where φ = 1 to double precision). The search
//! itself covers the paper's offsets, o ≥ 0 (below, moving an offset changes nothing it
//! could follow), and starts such a sigmoid switching on at the start. So with the default
//! bounds no richer model ends worse than a poorer one; with the paper's o ≥ 0 the sigmoid
//! starts at ½ and S_B → S_C is not exact. [`NestedFit::violations`] lists any richer fit
//! that ended worse than its poorer model, so a report can say so.
//!
//! One function runs a model's fit (a *stage*): [`ModelRun`] runs one ([`fit_model`] from the
//! neutral vector, unwatched), [`NestedRun`] runs them in sequence with checkpoints that name
//! the problem by value ([`FitProblem`]) and resume bit for bit. Each stage's annealer draws
//! from the user's seed mixed with the model ([`model_seed`], applied by
//! [`FitSettings::anneal_for`]).
//!
//! [`ParamSpace::extend_to`]: kinergy_solver::ParamSpace::extend_to

mod job;
mod nested;
mod refine;
mod search;
mod single;

pub use job::{FitJob, Interrupted};
pub use nested::{
    ClipFrames, FitProblem, NestedCheckpoint, NestedFit, NestedOutcome, NestedRun, Stage,
    fit_nested,
};
pub use refine::{RefineSettings, Refinement, refine, refine_until};
pub use search::{OBJECTIVES, SearchOptions};
pub(crate) use single::unobserved_names;
pub use single::{Fit, FitSettings, ModelRun, fit_model, model_seed};
