//! Simulated annealing over a bounded parameter space (DESIGN §1.1; the paper's Algorithm 1
//! made real).
//!
//! A population of parameter vectors evolves together. Each iteration every member proposes
//! a Gaussian move — each coordinate moves by `N(0, 1) · step · (upper − lower)`, reflected
//! back into the bounds — and the proposal replaces the member when its cost is not higher,
//! or, when higher by Δ, with the Metropolis probability `exp(−Δ / T)`. The temperature starts
//! at `T₀ = temperature × (the initial population's mean cost)` and falls geometrically by
//! `cooling` per iteration; `temperature = 0` is the paper's greedy rule (keep a change only
//! if the score did not get worse). Each member's step adapts: every `adapt_every` proposals
//! it grows by 1.3× when more than `target_acceptance` of them were accepted and shrinks by
//! 1.3× otherwise, within `[min_step, max_step]`. Every `share_best_every` iterations the
//! worst member jumps to the best vector found so far. The run stops when the population's mean
//! cost changed by at most `stable_tolerance` (relative) over the last `stable_window`
//! iterations, or when the next iteration would exceed `max_evaluations`. The best vector
//! ever evaluated is returned; member 0 starts at the given start vector, so the result is
//! never worse than the start.
//!
//! A proposal's acceptance draw is made before its cost, so the cost above which it will be
//! rejected is known beforehand: the annealer asks the cost function for the cost *within*
//! that limit ([`CostFunction::cost_within`](crate::objective::CostFunction::cost_within)),
//! and the trainer's objective stops synthesizing a motion once it is surely worse. A rejected
//! proposal's exact cost is never used, so the run is the same bit for bit.
//!
//! Split as argmin splits it (STYLE.md, "long-running work"): the problem is a
//! [`CostFunction`](crate::objective::CostFunction), the [`AnnealState`] holds everything that changes (serializable), the
//! [`Annealer`] is the executor, [`Observer`]s watch it, and [`Control`] says where to write
//! checkpoints and when to stop early.
//!
//! **Reproducibility.** Randomness never lives in the state: the generator of member `m` at
//! iteration `k` is a ChaCha8 seeded from `(seed, k, m)`. Members are evaluated in parallel
//! (rayon) but each one's draws depend only on its own generator, and results are combined
//! in member order — so the same seed gives the same result on any number of threads, and a
//! run resumed from a checkpoint ends bit for bit where an uninterrupted run does.

mod annealer;
mod observe;
mod settings;
mod state;

pub use annealer::Annealer;
pub use observe::{Checkpoint, Control, CsvLog, Observer, Progress};
pub use settings::{AnnealSettings, LIBRARY_STABLE_TOLERANCE, LIBRARY_STABLE_WINDOW};
pub use state::{AnnealState, CHECKPOINT_VERSION, Member, Status};

pub(crate) use state::read_checkpoint;
