//! Analytic IK of a 7-DoF limb with the orbit (swivel) angle, joint limits and Kallmann's
//! orbit-angle search (Kallmann 2005, "Inverse Kinematics and Extensions", after Tolani &
//! Badler 1996; DESIGN §1.3).
//!
//! The limb is the chain of [`Chain::arm`] — shoulder swing `(sx, sy)` + twist `t`, elbow
//! flexion `f` about x + twist `u` about z, wrist swing `(wx, wy)`, bones along +z, no rest
//! rotations — with any lengths, shoulder offset, end-effector offset and limits (a leg is the
//! same chain with other limits). Configurations are `[sx, sy, t, f, u, wx, wy]`, the chain's
//! own DoF order, so [`Chain::fk`] is the truth every answer is checked against.
//!
//! # The solution, given a goal frame and α
//!
//! With shoulder `s`, upper arm `L1`, forearm `L2`, end-effector offset `h` (in the wrist
//! frame) and goal `(R_g, p_g)`:
//!
//! 1. Wrist center `w = p_g − R_g h`, `d = |w − s|`, axis `n = (w − s)/d`. Reachable when
//!    `|L1 − L2| ≤ d ≤ L1 + L2`.
//! 2. Flexion from the law of cosines, `d² = L1² + L2² + 2 L1 L2 cos f`:
//!    `f = σ acos((d² − L1² − L2²) / (2 L1 L2))`, with the bend sign σ = the sign of the
//!    flexion limit farthest from zero (+1 for the arm's 0–150°).
//! 3. The elbow lies on the circle about `n`; its direction from the axis is
//!    `m(α) = cos α û + sin α v̂`, with `û` the reference "down" direction projected off `n`
//!    (so α = 0 is the lowest elbow) and `v̂ = ±n × û` ([`OrbitSense`]).
//! 4. Shoulder: in the upper-arm frame the wrist center is `p' = L1 z + R_x(f) L2 z` and the
//!    elbow lies on the side `e₁ = σ (p̂' × x)` of it; `R_s` is the rotation taking
//!    `(p̂', e₁, p̂' × e₁)` to `(n, m, n × m)`. Swing–twist: `R_s = swing(sx, sy) · R_z(t)`.
//! 5. Elbow twist and wrist swing: `M = (R_s R_x(f))ᵀ R_g = R_z(u) · swing(wx, wy)`, i.e.
//!    `Mᵀ = swing(−wx, −wy) · R_z(−u)`: one swing–twist decomposition of `Mᵀ` gives both.
//!    Every rotation has one, so the forearm twist and the 2-DoF wrist give every hand
//!    orientation relative to the forearm: for every reachable goal and every α the
//!    solution reproduces the whole 6-D goal (limits aside).
//!
//! The decompositions are unique while both swings stay below π (the swing–twist
//! singularity, Kallmann's "swing vector of norm π"); there [`swing_twist`] still returns a
//! valid swing of angle π about x, so the answer stays exact and finite. Angles produced by
//! `atan2` are moved by 2π toward the middle of their limits. The goal's rotation is used as
//! given (not re-orthonormalized).
//!
//! Steps 1–3 but the choice of `m` do not depend on α: the orbit search
//! ([`LimbIk::search`], [`OrbitSearch`]) does them once and repeats only steps 3–5 per α.
//! Position mode ([`LimbIk::solve_position`]) is the same construction with the hand held in
//! line with the forearm, the distal link then being `L2 z + h`.
//!
//! ```
//! use kinergy_motion::Chain;
//! use kinergy_motion::nalgebra::{IsometryMatrix3, Point3};
//! use kinergy_solver::analytic::{LimbIk, OrbitSearch};
//!
//! let arm = Chain::arm(0.30, 0.26, 0.09)?;
//! let ik = LimbIk::new(&arm)?;
//! // A goal made by forward kinematics, so it is reachable.
//! let q0 = [0.9, -0.3, 0.2, 1.2, 0.4, 0.3, -0.1];
//! let pose = arm.fk(&IsometryMatrix3::identity(), &q0)?;
//! let goal = IsometryMatrix3::from_parts(pose.end.coords.into(), pose.frames[2].rotation);
//!
//! // At the configuration's own orbit angle the solver gives the configuration back.
//! let q = ik.solve(&goal, ik.alpha_of(&q0))?;
//! assert!(q.iter().zip(&q0).all(|(a, b)| (a - b).abs() < 1e-9));
//!
//! // Kallmann's search: the first orbit angle from 20° on whose posture is within limits.
//! let (_alpha, q) = ik.search(&goal, &OrbitSearch::default())?;
//! assert!(arm.within_limits(&q));
//! let again = arm.fk(&IsometryMatrix3::identity(), &q)?;
//! assert!((again.end - pose.end).norm() < 1e-9);
//! assert!((again.frames[2].rotation.matrix() - pose.frames[2].rotation.matrix()).amax() < 1e-9);
//!
//! // Position only: the hand in line with the forearm.
//! let target = Point3::new(0.1, -0.3, 0.35);
//! let (_alpha, q) = ik.solve_position(&target, &OrbitSearch::default())?;
//! assert!((arm.end_position(&IsometryMatrix3::identity(), &q)? - target).norm() < 1e-9);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
//!
//! The files: `error.rs` ([`AnalyticError`]), `limits.rs` (the limits read from the chain and
//! how far a configuration violates them), `orbit.rs` ([`OrbitSearch`]: the angles the search
//! tries), `placement.rs` (the data of steps 1–3: everything but α), `solver.rs` ([`LimbIk`]
//! and all its methods: reading the chain, steps 1–5, the limit test and the search over α)
//! and `swing_twist.rs` (the fast swing–twist decomposition, `atan2` and angle wrapping the
//! solver runs on). Only `solver.rs` reads the others; none of them reads it.
//!
//! [`Chain::arm`]: kinergy_motion::Chain::arm
//! [`Chain::fk`]: kinergy_motion::Chain::fk
//! [`swing_twist`]: kinergy_motion::rotation::swing_twist

mod error;
mod limits;
mod orbit;
mod placement;
mod solver;
mod swing_twist;

pub use error::AnalyticError;
pub use limits::{LimbDof, LimbLimits, Violation};
pub use orbit::{OrbitAlphas, OrbitSearch, OrbitSense};
pub use solver::LimbIk;
