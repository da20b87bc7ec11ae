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

use std::fmt;

use kinergy_motion::nalgebra::{IsometryMatrix3, Matrix3, Point3, Rotation3, Unit, Vector3};
use kinergy_motion::rotation::{Axis, axis_rotation, swing_rotation, swing_twist, unwrap_near};
use kinergy_motion::{Chain, Motion};

/// Relative slack on the outer and inner reach: a goal made by FK of the stretched limb may
/// land a few ulps beyond `L1 + L2`; it is treated as on the boundary.
const REACH_SLACK: f64 = 1e-12;

/// Below this fraction of the reach, the shoulder–wrist axis is undefined and a fixed one is
/// used (only possible when both links have the same length).
const TINY: f64 = 1e-12;

/// What can go wrong in the analytic limb IK.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum AnalyticError {
    /// The wrist center (or, in position mode, the end effector) is outside the shell the
    /// limb reaches: farther than the outer radius or closer than the inner one.
    #[error(
        "the target is {distance} m from the shoulder; the limb reaches from {inner} to {reach} m"
    )]
    Unreachable {
        /// Distance from the shoulder, meters.
        distance: f64,
        /// Outer radius, meters (`L1 + L2` for the wrist center).
        reach: f64,
        /// Inner radius, meters (`|L1 − L2|` for the wrist center).
        inner: f64,
    },
    /// No orbit angle tried gives a posture within the joint limits.
    #[error(
        "no orbit angle of the {tried} tried gives a posture within limits; at the best, α = {best_alpha} rad, the {dof} exceeds its limit by {excess} rad"
    )]
    LimitsViolated {
        /// The orbit angle whose posture was closest to the limits (least total excess).
        best_alpha: f64,
        /// The DoF farthest outside its limits at `best_alpha`.
        dof: LimbDof,
        /// How far outside, radians (see [`Violation`]).
        excess: f64,
        /// Orbit angles tried.
        tried: usize,
    },
    /// Postures within limits were found but the caller's predicate rejected all of them
    /// (e.g. every one collides).
    #[error(
        "the {within_limits} postures within limits (of {tried} orbit angles tried) were all rejected"
    )]
    Rejected {
        /// Postures that were within limits and rejected.
        within_limits: usize,
        /// Orbit angles tried.
        tried: usize,
    },
    /// The chain is not a shoulder swing + twist, elbow flexion + twist, wrist swing limb.
    #[error("unsupported chain: {0}")]
    UnsupportedChain(String),
    /// A goal, target or angle has NaN or infinite values.
    #[error("{0} is not finite")]
    NonFinite(String),
    /// A setting is outside what it may be.
    #[error("invalid `{field}`: {why}")]
    Setting {
        /// The setting, e.g. `OrbitSearch::step`.
        field: &'static str,
        /// What was expected.
        why: String,
    },
}

/// One joint motion of the limb, as named in limit reports.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum LimbDof {
    /// Shoulder swing, configuration entries 0 and 1.
    ShoulderSwing,
    /// Shoulder twist, entry 2.
    ShoulderTwist,
    /// Elbow flexion, entry 3.
    ElbowFlexion,
    /// Elbow twist (pronation), entry 4.
    ElbowTwist,
    /// Wrist swing, entries 5 and 6.
    WristSwing,
}

impl LimbDof {
    /// All motions, proximal to distal.
    pub const ALL: [LimbDof; 5] = [
        LimbDof::ShoulderSwing,
        LimbDof::ShoulderTwist,
        LimbDof::ElbowFlexion,
        LimbDof::ElbowTwist,
        LimbDof::WristSwing,
    ];

    /// The index of its first entry in a configuration.
    pub fn first_index(self) -> usize {
        match self {
            LimbDof::ShoulderSwing => 0,
            LimbDof::ShoulderTwist => 2,
            LimbDof::ElbowFlexion => 3,
            LimbDof::ElbowTwist => 4,
            LimbDof::WristSwing => 5,
        }
    }

    /// A human-readable name, e.g. `"wrist swing"`.
    pub fn name(self) -> &'static str {
        match self {
            LimbDof::ShoulderSwing => "shoulder swing",
            LimbDof::ShoulderTwist => "shoulder twist",
            LimbDof::ElbowFlexion => "elbow flexion",
            LimbDof::ElbowTwist => "elbow twist",
            LimbDof::WristSwing => "wrist swing",
        }
    }
}

impl fmt::Display for LimbDof {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The limb's joint limits, radians, as read from the chain.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LimbLimits {
    /// Shoulder swing ellipse radii `(rx, ry)`: `(sx/rx)² + (sy/ry)² ≤ 1`.
    pub shoulder_swing: (f64, f64),
    /// Shoulder twist `(min, max)`.
    pub shoulder_twist: (f64, f64),
    /// Elbow flexion `(min, max)`.
    pub elbow_flexion: (f64, f64),
    /// Elbow twist `(min, max)`.
    pub elbow_twist: (f64, f64),
    /// Wrist swing ellipse radii `(rx, ry)`.
    pub wrist_swing: (f64, f64),
}

/// How far a configuration lies outside the limits.
///
/// A revolute DoF's excess is its distance to `[min, max]`; a swing's is the length by which
/// the swing vector overshoots the ellipse along its own direction, `|s| (1 − 1/√e)` with
/// `e = (sx/rx)² + (sy/ry)²` — both radians.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Violation {
    /// The DoF with the largest excess.
    pub dof: LimbDof,
    /// Its excess, radians.
    pub excess: f64,
    /// The sum of every DoF's excess, radians.
    pub total: f64,
}

/// Which way α turns the elbow about the shoulder→wrist axis `n`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OrbitSense {
    /// α is a right-handed rotation about `n`: `v̂ = n × û`. For a body that is Y-up and faces
    /// +z, this raises the elbow outward for the **left** arm.
    #[default]
    RightHanded,
    /// α is a left-handed rotation about `n`: `v̂ = û × n`; outward for the **right** arm of
    /// a Y-up body facing +z.
    LeftHanded,
}

/// Kallmann's orbit-angle search: the start angle, then `start ± Δ_k` (plus first, then
/// minus) with `Δ_1 = step` and `Δ_{k+1} = Δ_k + step · growth^k`, clipped to
/// `[min, max]` — each end of the range is tried once when a step overshoots it.
///
/// The default — start 20°, range [−15°, 130°], step 5°, growth 1.2 — follows the paper
/// (a growing increment, "greedy"); it tries at most 16 angles: 20, 25, 15, 31, 9, 38.2,
/// 1.8, 46.8, −6.8, 57.2, −15, 69.6, 84.6, 102.5, 124.0, 130 (degrees). Growth 1 gives a
/// uniform grid (30 angles at 5°), finer but slower when nothing fits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitSearch {
    /// First α tried, radians.
    pub start: f64,
    /// Smallest α tried, radians.
    pub min: f64,
    /// Largest α tried, radians.
    pub max: f64,
    /// First increment, radians (> 0).
    pub step: f64,
    /// Factor on the increment per iteration (≥ 1).
    pub growth: f64,
}

impl Default for OrbitSearch {
    fn default() -> OrbitSearch {
        OrbitSearch {
            start: 20f64.to_radians(),
            min: (-15f64).to_radians(),
            max: 130f64.to_radians(),
            step: 5f64.to_radians(),
            growth: 1.2,
        }
    }
}

impl OrbitSearch {
    /// Checks the settings: finite, `min ≤ start ≤ max`, `step > 0`, `growth ≥ 1`.
    pub fn validate(&self) -> Result<(), AnalyticError> {
        let fail = |field, why: &str| {
            Err(AnalyticError::Setting {
                field,
                why: why.into(),
            })
        };
        if ![self.start, self.min, self.max, self.step, self.growth]
            .iter()
            .all(|v| v.is_finite())
        {
            return fail("OrbitSearch", "every field finite");
        }
        if !(self.min <= self.start && self.start <= self.max) {
            return fail("OrbitSearch::start", "min ≤ start ≤ max");
        }
        if self.step <= 0.0 {
            return fail("OrbitSearch::step", "a positive angle");
        }
        if self.growth < 1.0 {
            return fail("OrbitSearch::growth", "at least 1");
        }
        Ok(())
    }

    /// The orbit angles the search tries, in order.
    pub fn alphas(&self) -> Result<OrbitAlphas, AnalyticError> {
        self.validate()?;
        Ok(OrbitAlphas {
            settings: *self,
            delta: self.step,
            increment: self.step,
            up: self.start < self.max,
            down: self.start > self.min,
            next_up: true,
            started: false,
        })
    }
}

/// The sequence of orbit angles of an [`OrbitSearch`].
#[derive(Debug, Clone)]
pub struct OrbitAlphas {
    settings: OrbitSearch,
    delta: f64,
    increment: f64,
    up: bool,
    down: bool,
    next_up: bool,
    started: bool,
}

impl Iterator for OrbitAlphas {
    type Item = f64;

    fn next(&mut self) -> Option<f64> {
        let s = &self.settings;
        if !self.started {
            self.started = true;
            return Some(s.start);
        }
        while self.up || self.down {
            if self.next_up {
                self.next_up = false;
                if self.up {
                    let a = (s.start + self.delta).min(s.max);
                    self.up = a < s.max;
                    return Some(a);
                }
            } else {
                self.next_up = true;
                let out = self.down.then(|| (s.start - self.delta).max(s.min));
                if let Some(a) = out {
                    self.down = a > s.min;
                }
                self.increment *= s.growth;
                self.delta += self.increment;
                if out.is_some() {
                    return out;
                }
            }
        }
        None
    }
}

/// The distal link seen from the upper-arm frame, as a planar two-link problem: the point
/// `p'(f) = L1 z + R_x(f) g` is placed at distance `d`, with
/// `|p'|² = L1² + |g|² + 2 L1 ρ cos(f − φ)`, `ρ = |(g_y, g_z)|`, `φ = atan2(g_y, g_z)`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Link {
    g: Vector3<f64>,
    rho: f64,
    phi: f64,
    sin_phi: f64,
    cos_phi: f64,
    /// `L1² + |g|²`.
    sum_sq: f64,
    inner: f64,
    outer: f64,
    /// `g_x` negligible: the elbow side is `σ p̂' × x`, exact and defined even when stretched.
    planar: bool,
}

impl Link {
    fn new(upper: f64, g: Vector3<f64>) -> Option<Link> {
        let rho = g.y.hypot(g.z);
        if rho <= 1e-12 * upper.max(g.norm()) {
            return None;
        }
        Some(Link {
            g,
            rho,
            phi: g.y.atan2(g.z),
            sin_phi: g.y / rho,
            cos_phi: g.z / rho,
            sum_sq: upper * upper + g.norm_squared(),
            inner: (upper - rho).hypot(g.x),
            outer: (upper + rho).hypot(g.x),
            planar: g.x.abs() <= 1e-9 * g.norm(),
        })
    }
}

/// Analytic IK of one 7-DoF limb (arm or leg), built once from its [`Chain`].
///
/// Conventions:
/// - Goals are in the chain's **base frame**: the goal's translation is the end effector's
///   position, its rotation the wrist frame's orientation (the chain's last joint frame,
///   [`kinergy_motion::Linearization::end_rotation`]).
/// - α = 0 puts the elbow lowest: its direction from the shoulder→wrist axis has the most
///   negative component along "up", i.e. points most along `down` (default: the base
///   frame's −y, Y-up; [`LimbIk::with_down`] for legs or other frames). With the axis along
///   `down` itself, the projection of `down × x` (or `down × z` when `down` is near x) is
///   used instead. The elbow's height `−down · elbow` grows with |α| up to π; the sign of α
///   is set by [`OrbitSense`].
#[derive(Debug, Clone, PartialEq)]
pub struct LimbIk {
    shoulder: Vector3<f64>,
    upper: f64,
    forearm: f64,
    hand: Vector3<f64>,
    limits: LimbLimits,
    bend: f64,
    down: Unit<Vector3<f64>>,
    fallback: Unit<Vector3<f64>>,
    sense: OrbitSense,
    wrist_link: Link,
    /// Position mode: the end effector as the distal link's tip with the elbow twist at
    /// `rest_twist` and the wrist straight; `None` when that tip lies on the flexion axis.
    reach_link: Option<Link>,
    rest_twist: f64,
}

fn revolute(m: &Motion, want: Axis) -> Option<(f64, f64)> {
    match *m {
        Motion::Revolute { axis, min, max } if axis == want => Some((min, max)),
        _ => None,
    }
}

fn swing(m: &Motion) -> Option<(f64, f64)> {
    match *m {
        Motion::Swing { rx, ry } => Some((rx, ry)),
        _ => None,
    }
}

fn along_z(v: &Vector3<f64>) -> Option<f64> {
    (v.x == 0.0 && v.y == 0.0 && v.z > 0.0).then_some(v.z)
}

fn finite_goal(goal: &IsometryMatrix3<f64>) -> Result<(), AnalyticError> {
    let ok = goal.translation.vector.iter().all(|v| v.is_finite())
        && goal.rotation.matrix().iter().all(|v| v.is_finite());
    if ok {
        Ok(())
    } else {
        Err(AnalyticError::NonFinite("the goal frame".into()))
    }
}

fn finite_alpha(alpha: f64) -> Result<(), AnalyticError> {
    if alpha.is_finite() {
        Ok(())
    } else {
        Err(AnalyticError::NonFinite("the orbit angle".into()))
    }
}

/// Where angles from `atan2` are moved toward: the middle of the limits, or π inside a
/// one-sided infinite range.
fn middle((min, max): (f64, f64)) -> f64 {
    match (min.is_finite(), max.is_finite()) {
        (true, true) => 0.5 * (min + max),
        (true, false) => min + std::f64::consts::PI,
        (false, true) => max - std::f64::consts::PI,
        (false, false) => 0.0,
    }
}

fn revolute_excess(x: f64, (min, max): (f64, f64)) -> f64 {
    if (min..=max).contains(&x) {
        0.0
    } else if x < min {
        min - x
    } else if x > max {
        x - max
    } else {
        f64::INFINITY // NaN
    }
}

/// The same test as [`Chain::within_limits`], so both agree on every configuration.
fn swing_excess(sx: f64, sy: f64, (rx, ry): (f64, f64)) -> f64 {
    let e = (sx / rx).powi(2) + (sy / ry).powi(2);
    if e <= 1.0 + 1e-12 {
        0.0
    } else if e.is_finite() {
        (sx * sx + sy * sy).sqrt() * (1.0 - 1.0 / e.sqrt())
    } else {
        f64::INFINITY
    }
}

impl LimbIk {
    /// Reads the limb from `chain`: three joints without rest rotations — shoulder
    /// `[Swing, Revolute Z]` at any offset, elbow `[Revolute X, Revolute Z]` at `(0, 0, L1)`,
    /// wrist `[Swing]` at `(0, 0, L2)` — and any end-effector offset.
    pub fn new(chain: &Chain) -> Result<LimbIk, AnalyticError> {
        let unsupported = |why: String| Err(AnalyticError::UnsupportedChain(why));
        let joints = chain.joints();
        if joints.len() != 3 {
            return unsupported(format!(
                "expected 3 joints (shoulder, elbow, wrist), found {}",
                joints.len()
            ));
        }
        if let Some(j) = joints.iter().find(|j| j.rest != Rotation3::identity()) {
            return unsupported(format!("joint `{}` has a rest rotation", j.name));
        }
        let (sh, el, wr) = (&joints[0], &joints[1], &joints[2]);
        let shoulder = match &sh.motions[..] {
            [a, b] => swing(a).zip(revolute(b, Axis::Z)),
            _ => None,
        };
        let Some((shoulder_swing, shoulder_twist)) = shoulder else {
            return unsupported(format!(
                "`{}` must be a swing then a twist about z",
                sh.name
            ));
        };
        let elbow = match &el.motions[..] {
            [a, b] => revolute(a, Axis::X).zip(revolute(b, Axis::Z)),
            _ => None,
        };
        let Some((elbow_flexion, elbow_twist)) = elbow else {
            return unsupported(format!(
                "`{}` must be a revolute about x then one about z",
                el.name
            ));
        };
        let wrist_swing = match &wr.motions[..] {
            [a] => swing(a),
            _ => None,
        };
        let Some(wrist_swing) = wrist_swing else {
            return unsupported(format!("`{}` must be a single swing", wr.name));
        };
        let (Some(upper), Some(forearm)) = (along_z(&el.offset), along_z(&wr.offset)) else {
            return unsupported(
                "the elbow and wrist offsets must lie along +z of the previous joint".into(),
            );
        };
        let limits = LimbLimits {
            shoulder_swing,
            shoulder_twist,
            elbow_flexion,
            elbow_twist,
            wrist_swing,
        };
        let bend = if elbow_flexion.1.abs() >= elbow_flexion.0.abs() {
            1.0
        } else {
            -1.0
        };
        let hand = chain.end_effector();
        let rest_twist = 0f64.clamp(elbow_twist.0, elbow_twist.1);
        let Some(wrist_link) = Link::new(upper, Vector3::new(0.0, 0.0, forearm)) else {
            return unsupported(format!(
                "the forearm ({forearm} m) is negligible next to the upper limb ({upper} m)"
            ));
        };
        let reach_link = Link::new(
            upper,
            Vector3::new(0.0, 0.0, forearm) + axis_rotation(Axis::Z, rest_twist) * hand,
        );
        let down = -Vector3::y_axis();
        Ok(LimbIk {
            shoulder: sh.offset,
            upper,
            forearm,
            hand,
            limits,
            bend,
            down,
            fallback: fallback_for(&down),
            sense: OrbitSense::default(),
            wrist_link,
            reach_link,
            rest_twist,
        })
    }

    /// The same limb with another "down" direction (base frame) for α = 0; e.g. a leg whose
    /// base is Z-up takes `−z`.
    pub fn with_down(mut self, down: Vector3<f64>) -> Result<LimbIk, AnalyticError> {
        if !down.iter().all(|v| v.is_finite()) {
            return Err(AnalyticError::NonFinite("the down direction".into()));
        }
        let Some(down) = Unit::try_new(down, 1e-12) else {
            return Err(AnalyticError::Setting {
                field: "LimbIk::down",
                why: "a non-zero vector".into(),
            });
        };
        self.down = down;
        self.fallback = fallback_for(&down);
        Ok(self)
    }

    /// The same limb with α turning the other way ([`OrbitSense`]).
    pub fn with_sense(mut self, sense: OrbitSense) -> LimbIk {
        self.sense = sense;
        self
    }

    /// The limits read from the chain.
    pub fn limits(&self) -> &LimbLimits {
        &self.limits
    }

    /// Upper and lower link lengths `(L1, L2)`, meters.
    pub fn lengths(&self) -> (f64, f64) {
        (self.upper, self.forearm)
    }

    /// The bend sign σ: +1 when the elbow flexes positively (the arm's 0–150°), −1 when its
    /// flexion limits lie mostly below zero (a knee modeled as −150–0°).
    pub fn bend_sign(&self) -> f64 {
        self.bend
    }

    /// The "down" direction of α = 0, base frame.
    pub fn down(&self) -> Unit<Vector3<f64>> {
        self.down
    }

    /// The distances from the shoulder between which the wrist center is reachable,
    /// `(|L1 − L2|, L1 + L2)`.
    pub fn wrist_reach(&self) -> (f64, f64) {
        (self.wrist_link.inner, self.wrist_link.outer)
    }

    /// The distances from the shoulder between which position mode
    /// ([`LimbIk::solve_position`]: the end effector, wrist straight) reaches, or `None`
    /// when the chain has no position mode.
    pub fn position_reach(&self) -> Option<(f64, f64)> {
        self.reach_link.as_ref().map(|l| (l.inner, l.outer))
    }

    /// The configuration reaching `goal` (end-effector position + wrist orientation, base
    /// frame) with orbit angle `alpha` radians, limits not checked. Reproduces the whole goal
    /// for every reachable goal and every α (module docs, steps 1–5).
    pub fn solve(
        &self,
        goal: &IsometryMatrix3<f64>,
        alpha: f64,
    ) -> Result<[f64; 7], AnalyticError> {
        finite_alpha(alpha)?;
        finite_goal(goal)?;
        let rg = goal.rotation.matrix();
        let w = goal.translation.vector - rg * self.hand - self.shoulder;
        let d = w.norm();
        Self::check_reach(&self.wrist_link, d)?;
        let prepared = Prepared {
            placement: self.place(&self.wrist_link, &w, d),
            rg_t: rg.transpose(),
        };
        Ok(self.full_at(&prepared, alpha))
    }

    /// Position mode at a given α: the end effector at `target` (base frame) with the hand
    /// continuing the forearm — wrist swing zero, elbow twist zero (or the value nearest zero
    /// within its limits), so the palm's orientation follows the elbow plane. The orbit is
    /// about the shoulder→`target` axis, α = 0 again the lowest elbow. With the wrist held
    /// straight the reach is that of the links `L1` and `L2 z + h`: a target that needs the
    /// wrist bent to be reached is `Unreachable` here.
    pub fn solve_position_at(
        &self,
        target: &Point3<f64>,
        alpha: f64,
    ) -> Result<[f64; 7], AnalyticError> {
        finite_alpha(alpha)?;
        Ok(self.position_at(&self.prepare_target(target)?, alpha))
    }

    #[inline]
    fn prepare_goal(&self, goal: &IsometryMatrix3<f64>) -> Result<Prepared, AnalyticError> {
        finite_goal(goal)?;
        let rg = *goal.rotation.matrix();
        let w = goal.translation.vector - rg * self.hand - self.shoulder;
        let d = w.norm();
        Self::check_reach(&self.wrist_link, d)?;
        Ok(Prepared {
            placement: self.place(&self.wrist_link, &w, d),
            rg_t: rg.transpose(),
        })
    }

    #[inline]
    fn prepare_target(&self, target: &Point3<f64>) -> Result<Placement, AnalyticError> {
        if !target.iter().all(|v| v.is_finite()) {
            return Err(AnalyticError::NonFinite("the target".into()));
        }
        let Some(link) = &self.reach_link else {
            return Err(AnalyticError::UnsupportedChain(
                "position mode: the end effector lies on the elbow's flexion axis".into(),
            ));
        };
        let rel = target.coords - self.shoulder;
        let d = rel.norm();
        Self::check_reach(link, d)?;
        Ok(self.place(link, &rel, d))
    }

    /// Steps 3–5 of the module docs at one α.
    #[inline]
    fn full_at(&self, prepared: &Prepared, alpha: f64) -> [f64; 7] {
        let pl = &prepared.placement;
        let rs = pl.shoulder(alpha);
        let (sx, sy, t) = fast_swing_twist(&rs);
        // R_f = R_s R_x(f): only its columns x and z are needed.
        let fx = rs.column(0).into_owned();
        let fz = rs.column(2) * pl.cf - rs.column(1) * pl.sf;
        // Mᵀ = R_gᵀ R_f = swing(−w) R_z(−u) when M = R_z(u) swing(w): one swing–twist.
        let mt_x = prepared.rg_t * fx;
        let mt_z = prepared.rg_t * fz;
        let (wx, wy, u) = swing_twist_of_columns(&mt_x, &mt_z);
        let l = &self.limits;
        [
            sx,
            sy,
            wrap(t, middle(l.shoulder_twist)),
            wrap(pl.f, middle(l.elbow_flexion)),
            wrap(-u, middle(l.elbow_twist)),
            -wx,
            -wy,
        ]
    }

    /// Position mode at one α.
    #[inline]
    fn position_at(&self, pl: &Placement, alpha: f64) -> [f64; 7] {
        let (sx, sy, t) = fast_swing_twist(&pl.shoulder(alpha));
        let l = &self.limits;
        [
            sx,
            sy,
            wrap(t, middle(l.shoulder_twist)),
            wrap(pl.f, middle(l.elbow_flexion)),
            self.rest_twist,
            0.0,
            0.0,
        ]
    }

    /// The orbit angle of a configuration, radians in [−π, π]: the direction of its elbow
    /// about the shoulder→wrist-center axis (with a straight elbow, the direction the elbow
    /// would move to when flexing by σ). `solve(FK(q), alpha_of(q))` gives `q` back.
    pub fn alpha_of(&self, q: &[f64; 7]) -> f64 {
        let rs = *(swing_rotation(q[0], q[1]) * axis_rotation(Axis::Z, q[2])).matrix();
        let link = &self.wrist_link;
        let (sf, cf) = q[3].sin_cos();
        let p = tip(self.upper, &link.g, sf, cf);
        // The elbow's side of the axis: +1 when the forearm bends toward −y (p'_y < 0).
        let side = if p.y < 0.0 {
            1.0
        } else if p.y > 0.0 {
            -1.0
        } else {
            self.bend
        };
        let (_, e1) = self.elbow_side(link, &p, side);
        let rel = rs * p;
        let n = self.axis(&rel, rel.norm(), link);
        let m = rs * e1;
        let (u, v) = self.orbit_basis(&n);
        atan2(m.dot(&v), m.dot(&u))
    }

    /// True when `q` is within the limits — the same test as [`Chain::within_limits`].
    pub fn within_limits(&self, q: &[f64; 7]) -> bool {
        self.violation(q).is_none()
    }

    /// How far `q` lies outside the limits; `None` when within them.
    pub fn violation(&self, q: &[f64; 7]) -> Option<Violation> {
        let l = &self.limits;
        let excess = [
            swing_excess(q[0], q[1], l.shoulder_swing),
            revolute_excess(q[2], l.shoulder_twist),
            revolute_excess(q[3], l.elbow_flexion),
            revolute_excess(q[4], l.elbow_twist),
            swing_excess(q[5], q[6], l.wrist_swing),
        ];
        let total: f64 = excess.iter().sum();
        if total == 0.0 {
            return None;
        }
        let (i, &worst) = excess
            .iter()
            .enumerate()
            .max_by(|a, b| a.1.total_cmp(b.1))
            .expect("five entries");
        Some(Violation {
            dof: LimbDof::ALL[i],
            excess: worst,
            total,
        })
    }

    /// Kallmann's orbit-angle search: the first α of `settings` ([`OrbitSearch::alphas`])
    /// whose posture is within limits.
    pub fn search(
        &self,
        goal: &IsometryMatrix3<f64>,
        settings: &OrbitSearch,
    ) -> Result<(f64, [f64; 7]), AnalyticError> {
        self.search_with(goal, settings, &|_| true)
    }

    /// [`LimbIk::search`] where a posture must also pass `accept` (e.g. no collision).
    pub fn search_with(
        &self,
        goal: &IsometryMatrix3<f64>,
        settings: &OrbitSearch,
        accept: &dyn Fn(&[f64; 7]) -> bool,
    ) -> Result<(f64, [f64; 7]), AnalyticError> {
        let prepared = self.prepare_goal(goal)?;
        self.orbit_search(settings, |a| self.full_at(&prepared, a), accept)
    }

    /// Position mode ([`LimbIk::solve_position_at`]) with the orbit-angle search; the
    /// end effector lands on `target`.
    pub fn solve_position(
        &self,
        target: &Point3<f64>,
        settings: &OrbitSearch,
    ) -> Result<(f64, [f64; 7]), AnalyticError> {
        self.solve_position_with(target, settings, &|_| true)
    }

    /// [`LimbIk::solve_position`] where a posture must also pass `accept`.
    pub fn solve_position_with(
        &self,
        target: &Point3<f64>,
        settings: &OrbitSearch,
        accept: &dyn Fn(&[f64; 7]) -> bool,
    ) -> Result<(f64, [f64; 7]), AnalyticError> {
        let placement = self.prepare_target(target)?;
        self.orbit_search(settings, |a| self.position_at(&placement, a), accept)
    }

    fn orbit_search(
        &self,
        settings: &OrbitSearch,
        posture: impl Fn(f64) -> [f64; 7],
        accept: &dyn Fn(&[f64; 7]) -> bool,
    ) -> Result<(f64, [f64; 7]), AnalyticError> {
        let mut tried = 0;
        let mut within_limits = 0;
        let mut best: Option<(f64, Violation)> = None;
        for alpha in settings.alphas()? {
            let q = posture(alpha);
            tried += 1;
            match self.violation(&q) {
                None => {
                    if accept(&q) {
                        return Ok((alpha, q));
                    }
                    within_limits += 1;
                }
                Some(v) => {
                    if best.is_none_or(|(_, b)| v.total < b.total) {
                        best = Some((alpha, v));
                    }
                }
            }
        }
        match best {
            Some((best_alpha, v)) if within_limits == 0 => Err(AnalyticError::LimitsViolated {
                best_alpha,
                dof: v.dof,
                excess: v.excess,
                tried,
            }),
            _ => Err(AnalyticError::Rejected {
                within_limits,
                tried,
            }),
        }
    }

    /// Step 1's test: `Unreachable` unless `d` lies within the link's shell.
    #[inline]
    fn check_reach(link: &Link, d: f64) -> Result<(), AnalyticError> {
        let slack = REACH_SLACK * link.outer;
        if d <= link.outer + slack && d >= link.inner - slack {
            Ok(())
        } else {
            Err(AnalyticError::Unreachable {
                distance: d,
                reach: link.outer,
                inner: link.inner,
            })
        }
    }

    /// Steps 1–3 of the module docs, everything but α: the link's tip goes to `rel`
    /// (relative to the shoulder, base frame), `d = |rel|` already checked by
    /// [`LimbIk::check_reach`]. Infallible, so the 170-byte result is built in place rather
    /// than moved out of a `Result`.
    #[inline]
    fn place(&self, link: &Link, rel: &Vector3<f64>, d: f64) -> Placement {
        // cos(f − φ) = k, sin(f − φ) = σ √((1 − k)(1 + k)): no sin_cos of f needed.
        let k = ((d * d - link.sum_sq) / (2.0 * self.upper * link.rho)).clamp(-1.0, 1.0);
        let (s, c) = (self.bend * ((1.0 - k) * (1.0 + k)).sqrt(), k);
        let f = link.phi + self.bend * k.acos();
        let (sf, cf) = (
            s * link.cos_phi + c * link.sin_phi,
            c * link.cos_phi - s * link.sin_phi,
        );
        let p = tip(self.upper, &link.g, sf, cf);
        let (p_hat, e1) = self.elbow_side(link, &p, self.bend);
        let n = self.axis(rel, d, link);
        let (u, v) = self.orbit_basis(&n);
        Placement {
            f,
            sf,
            cf,
            local_t: Matrix3::from_rows(&[
                p_hat.transpose(),
                e1.transpose(),
                p_hat.cross(&e1).transpose(),
            ]),
            n,
            u,
            v,
        }
    }

    /// The unit shoulder→tip axis; a fixed one (`−down`) when the tip is at the shoulder.
    #[inline]
    fn axis(&self, rel: &Vector3<f64>, d: f64, link: &Link) -> Vector3<f64> {
        if d > TINY * link.outer {
            rel * d.recip()
        } else {
            -self.down.into_inner()
        }
    }

    /// In the upper-arm frame: the tip's direction `p̂'` and the unit direction `e₁ ⟂ p̂'`
    /// toward the elbow, on side `side` (±1) of the flexion plane.
    #[inline]
    fn elbow_side(&self, link: &Link, p: &Vector3<f64>, side: f64) -> (Vector3<f64>, Vector3<f64>) {
        let norm = p.norm();
        if link.planar {
            // Folded onto the shoulder: the limit of p̂' as f → ±π.
            let p_hat = if norm > TINY * link.outer {
                p * norm.recip()
            } else {
                Vector3::new(0.0, -side, 0.0)
            };
            // side · (p̂' × x), unit whenever p̂' ⟂ x.
            let e1 = Vector3::new(0.0, p_hat.z, -p_hat.y);
            let e1 = if p_hat.x == 0.0 { e1 } else { e1.normalize() } * side;
            (p_hat, e1)
        } else {
            // |g_x| > 0 keeps p̂' off the z axis: the elbow's own direction.
            let p_hat = p * norm.recip();
            (p_hat, (Vector3::z() - p_hat * p_hat.z).normalize())
        }
    }

    /// `(û, v̂)`: the reference direction `down` projected off `n`, and the direction α turns
    /// it toward.
    #[inline]
    fn orbit_basis(&self, n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
        let project = |r: &Vector3<f64>| r - n * n.dot(r);
        let mut u = project(&self.down);
        let len = u.norm();
        if len > 1e-9 {
            u *= len.recip();
        } else {
            u = project(&self.fallback).normalize();
        }
        let v = match self.sense {
            OrbitSense::RightHanded => n.cross(&u),
            OrbitSense::LeftHanded => u.cross(n),
        };
        (u, v)
    }
}

/// The part of a solution that does not depend on α (steps 1–3 of the module docs).
#[derive(Debug, Clone, Copy)]
struct Placement {
    f: f64,
    sf: f64,
    cf: f64,
    /// Rows `p̂'`, `e₁`, `p̂' × e₁`: the upper-arm frame's side of `R_s`.
    local_t: Matrix3<f64>,
    n: Vector3<f64>,
    u: Vector3<f64>,
    v: Vector3<f64>,
}

impl Placement {
    /// `R_s = [n, m, n × m] · [p̂', e₁, p̂' × e₁]ᵀ` with `m = cos α û + sin α v̂`.
    #[inline]
    fn shoulder(&self, alpha: f64) -> Matrix3<f64> {
        let (sa, ca) = alpha.sin_cos();
        let m = self.u * ca + self.v * sa;
        Matrix3::from_columns(&[self.n, m, self.n.cross(&m)]) * self.local_t
    }
}

/// A full-pose goal made ready for any α.
#[derive(Debug, Clone, Copy)]
struct Prepared {
    placement: Placement,
    rg_t: Matrix3<f64>,
}

/// [`swing_twist`] of a rotation matrix, from its columns x and z.
#[inline]
fn fast_swing_twist(r: &Matrix3<f64>) -> (f64, f64, f64) {
    swing_twist_of_columns(&r.column(0).into_owned(), &r.column(2).into_owned())
}

/// `(sx, sy, τ)` with `R = swing(sx, sy) · R_z(τ)` from `R x` and `R z`: the same answer as
/// [`swing_twist`] with two `atan2` and no `sin_cos`.
///
/// With `d = R z = (dx, dy, c)`, the shortest arc S from z to d has
/// `S x = (1 − dx²/(1+c), −dx dy/(1+c), −dx)`, `S y = (−dx dy/(1+c), 1 − dy²/(1+c), −dy)`
/// (Rodrigues with axis z × d), so `τ = atan2(R x · S y, R x · S x)`; the swing vector is
/// `(−dy, dx) · atan2(|d_xy|, c) / |d_xy|`. Near a swing of π (`c` → −1) the general
/// routine takes over.
#[inline]
fn swing_twist_of_columns(rx: &Vector3<f64>, d: &Vector3<f64>) -> (f64, f64, f64) {
    let c = d.z;
    if c < -0.9 {
        let r = Matrix3::from_columns(&[*rx, d.cross(rx), *d]);
        return swing_twist(&Rotation3::from_matrix_unchecked(r));
    }
    let (dx, dy) = (d.x, d.y);
    let s = (dx * dx + dy * dy).sqrt();
    let ratio = if s > 1e-150 { atan2(s, c) / s } else { 1.0 };
    let k = 1.0 / (1.0 + c);
    let sxx = (1.0 - dx * dx * k, -dx * dy * k, -dx);
    let syy = (-dx * dy * k, 1.0 - dy * dy * k, -dy);
    let dot = |a: (f64, f64, f64)| rx.x * a.0 + rx.y * a.1 + rx.z * a.2;
    let tau = atan2(dot(syy), dot(sxx));
    (-dy * ratio, dx * ratio, tau)
}

/// `atan2` through `atan` of the smaller ratio (glibc's `atan2` costs twice its `atan`);
/// within an ulp or two of `f64::atan2`, result in [−π, π].
#[inline]
fn atan2(y: f64, x: f64) -> f64 {
    use std::f64::consts::{FRAC_PI_2, PI};
    let (ay, ax) = (y.abs(), x.abs());
    if ay <= ax {
        if ax == 0.0 {
            return y.atan2(x);
        }
        let a = (y / x).atan();
        if x > 0.0 {
            a
        } else if y >= 0.0 {
            a + PI
        } else {
            a - PI
        }
    } else {
        // Also NaN, which the atan propagates.
        let a = (x / y).atan();
        if y > 0.0 {
            FRAC_PI_2 - a
        } else {
            -FRAC_PI_2 - a
        }
    }
}

/// `angle` moved by 2π toward `middle` when that brings it within π of it
/// ([`unwrap_near`] without the division and `round`, for angles from [`atan2`]).
#[inline]
fn wrap(angle: f64, middle: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let off = angle - middle;
    if off > PI {
        let a = angle - TAU;
        if a - middle > PI {
            unwrap_near(angle, middle)
        } else {
            a
        }
    } else if off < -PI {
        let a = angle + TAU;
        if a - middle < -PI {
            unwrap_near(angle, middle)
        } else {
            a
        }
    } else {
        angle
    }
}

/// `p'(f) = L1 z + R_x(f) g` from `sin f`, `cos f`.
#[inline]
fn tip(upper: f64, g: &Vector3<f64>, sf: f64, cf: f64) -> Vector3<f64> {
    Vector3::new(g.x, cf * g.y - sf * g.z, upper + sf * g.y + cf * g.z)
}

fn fallback_for(down: &Unit<Vector3<f64>>) -> Unit<Vector3<f64>> {
    let c = down.cross(&Vector3::x());
    let c = if c.norm() > 0.5 {
        c
    } else {
        down.cross(&Vector3::z())
    };
    Unit::new_normalize(c)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_search_visits_the_documented_angles() {
        let alphas: Vec<f64> = OrbitSearch::default()
            .alphas()
            .expect("valid")
            .map(f64::to_degrees)
            .collect();
        let expected = [
            20.0,
            25.0,
            15.0,
            31.0,
            9.0,
            38.2,
            1.8,
            46.84,
            -6.84,
            57.208,
            -15.0,
            69.6496,
            84.57952,
            102.495424,
            123.9945088,
            130.0,
        ];
        assert_eq!(alphas.len(), expected.len(), "{alphas:?}");
        for (a, e) in alphas.iter().zip(expected) {
            assert!((a - e).abs() < 1e-9, "{alphas:?}");
        }
    }

    #[test]
    fn fast_swing_twist_matches_the_general_one() {
        // A grid over swing directions and angles up to π (both branches) and twists.
        for i in 0..24 {
            for j in 0..=40 {
                for tau in [-3.0, -1.0, 0.0, 0.5, 2.9] {
                    let dir = i as f64 * std::f64::consts::TAU / 24.0;
                    let angle = std::f64::consts::PI * j as f64 / 40.0;
                    let (sx, sy) = (angle * dir.cos(), angle * dir.sin());
                    let r = swing_rotation(sx, sy) * axis_rotation(Axis::Z, tau);
                    let ours = fast_swing_twist(r.matrix());
                    let theirs = swing_twist(&r);
                    // Recomposition is the invariant (the swing of exactly π has two forms).
                    let back = swing_rotation(ours.0, ours.1) * axis_rotation(Axis::Z, ours.2);
                    assert!((back.matrix() - r.matrix()).amax() < 1e-14, "{i} {j} {tau}");
                    if angle < 3.0 {
                        assert!((ours.0 - theirs.0).abs() < 1e-13, "{i} {j} {tau}");
                        assert!((ours.1 - theirs.1).abs() < 1e-13, "{i} {j} {tau}");
                        assert!((ours.2 - theirs.2).abs() < 1e-13, "{i} {j} {tau}");
                    }
                }
            }
        }
    }

    #[test]
    fn atan2_matches_the_standard_one() {
        use std::f64::consts::PI;
        let values = [
            -3.0,
            -1.0,
            -0.7,
            -1e-9,
            -1e-300,
            0.0,
            1e-300,
            1e-9,
            0.3,
            1.0,
            1.0 + 1e-15,
            2.5,
        ];
        for &y in &values {
            for &x in &values {
                let (ours, theirs) = (atan2(y, x), y.atan2(x));
                // The branch cut (y = ±0, x < 0) may give π for −π.
                let gap = (ours - theirs).abs();
                let gap = gap.min((gap - 2.0 * PI).abs());
                assert!(
                    gap <= 4.5e-16 * theirs.abs().max(1e-300),
                    "{y} {x}: {ours} {theirs}"
                );
            }
        }
        for i in 0..10_000 {
            let t = -PI + 2.0 * PI * (i as f64 + 0.5) / 10_000.0;
            let (y, x) = (1.3 * t.sin(), 1.3 * t.cos());
            let (ours, theirs) = (atan2(y, x), y.atan2(x));
            assert!(
                (ours - theirs).abs() <= 4.5e-16 * theirs.abs().max(1e-300),
                "{t}"
            );
        }
        assert!(atan2(f64::NAN, 1.0).is_nan() && atan2(1.0, f64::NAN).is_nan());
    }

    #[test]
    fn wrap_moves_toward_the_middle() {
        use std::f64::consts::PI;
        assert_eq!(wrap(3.0, 0.0), 3.0);
        assert!((wrap(-3.0, 2.0) - (-3.0 + 2.0 * PI)).abs() < 1e-15);
        assert!((wrap(3.0, -2.0) - (3.0 - 2.0 * PI)).abs() < 1e-15);
        assert!((wrap(3.0, -9.0) - unwrap_near(3.0, -9.0)).abs() < 1e-15);
    }

    #[test]
    fn invalid_search_settings_are_named() {
        let bad = OrbitSearch {
            step: 0.0,
            ..OrbitSearch::default()
        };
        assert!(matches!(
            bad.alphas(),
            Err(AnalyticError::Setting {
                field: "OrbitSearch::step",
                ..
            })
        ));
    }
}
