//! Fitting a synergy model to captured reaches: per clip (the paper's experiment: one reach,
//! one vector) or per person (one vector for all of a person's reaches), and the nested
//! sequence S_A → S_B → S_C → S_D (→ S_E) in which each richer model starts from the poorer
//! one's solution.
//!
//! **The nested guarantee.** The annealer's member 0 starts at the poorer solution carried
//! into the richer space ([`ParamSpace::extend_to`]) and the best vector ever evaluated is
//! returned, so a richer fit never scores worse than that carried-over vector. S_A → S_B
//! and S_C → S_D carry over exactly (the same motion), and so does S_D → S_E (no growth,
//! the tempo factors 1). S_B → S_C does not: the paper's
//! sigmoid sig(−s·t + o) with o ≥ 0 is at most ½ at t = 0, so S_C cannot reproduce S_B's
//! constant φ = 1; the carried vector switches the sigmoid on as early as the bounds allow
//! (s = s_max, o = o_min: φ > 0.95 after 0.3 s). [`NestedFit::violations`] lists any richer
//! fit that still ended worse than its poorer model, so a report can say so.
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
