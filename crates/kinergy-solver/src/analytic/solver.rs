//! [`LimbIk`]: the limb read from its chain, and the solution at one α — the full pose
//! (steps 4–5 of the module docs on top of steps 1–3, whose data is in `placement.rs`) or the
//! position only — the orbit angle of a configuration, the limit test and Kallmann's search.

use kinergy_io::InvalidSetting;
use kinergy_motion::nalgebra::{IsometryMatrix3, Matrix3, Point3, Rotation3, Unit, Vector3};
use kinergy_motion::rotation::{Axis, axis_rotation, swing_rotation};
use kinergy_motion::{Chain, Motion};

use super::error::AnalyticError;
use super::limits::{LimbDof, LimbLimits, Violation, middle, revolute_excess, swing_excess};
use super::orbit::{OrbitSearch, OrbitSense};
use super::placement::{Link, Placement, Prepared, REACH_SLACK, TINY, fallback_for, tip};
use super::swing_twist::{atan2, fast_swing_twist, swing_twist_of_columns, wrap};

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
    pub(super) shoulder: Vector3<f64>,
    pub(super) upper: f64,
    pub(super) forearm: f64,
    pub(super) hand: Vector3<f64>,
    pub(super) limits: LimbLimits,
    pub(super) bend: f64,
    pub(super) down: Unit<Vector3<f64>>,
    pub(super) fallback: Unit<Vector3<f64>>,
    pub(super) sense: OrbitSense,
    pub(super) wrist_link: Link,
    /// Position mode: the end effector as the distal link's tip with the elbow twist at
    /// `rest_twist` and the wrist straight; `None` when that tip lies on the flexion axis.
    pub(super) reach_link: Option<Link>,
    pub(super) rest_twist: f64,
}

/// The limits of a revolute motion about `want`.
fn revolute(m: &Motion, want: Axis) -> Option<(f64, f64)> {
    match *m {
        Motion::Revolute { axis, min, max } if axis == want => Some((min, max)),
        _ => None,
    }
}

/// The ellipse radii of a swing motion.
fn swing(m: &Motion) -> Option<(f64, f64)> {
    match *m {
        Motion::Swing { rx, ry } => Some((rx, ry)),
        _ => None,
    }
}

/// The length of an offset along +z only.
fn along_z(v: &Vector3<f64>) -> Option<f64> {
    (v.x == 0.0 && v.y == 0.0 && v.z > 0.0).then_some(v.z)
}

/// `NonFinite` unless every entry of the goal frame is finite.
fn finite_goal(goal: &IsometryMatrix3<f64>) -> Result<(), AnalyticError> {
    let ok = goal.translation.vector.iter().all(|v| v.is_finite())
        && goal.rotation.matrix().iter().all(|v| v.is_finite());
    if ok {
        Ok(())
    } else {
        Err(AnalyticError::NonFinite("the goal frame".into()))
    }
}

/// `NonFinite` unless the orbit angle is finite.
fn finite_alpha(alpha: f64) -> Result<(), AnalyticError> {
    if alpha.is_finite() {
        Ok(())
    } else {
        Err(AnalyticError::NonFinite("the orbit angle".into()))
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
            return Err(AnalyticError::Setting(InvalidSetting::new(
                "LimbIk::down",
                "a non-zero vector",
            )));
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
    pub(super) fn prepare_goal(
        &self,
        goal: &IsometryMatrix3<f64>,
    ) -> Result<Prepared, AnalyticError> {
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
    pub(super) fn prepare_target(&self, target: &Point3<f64>) -> Result<Placement, AnalyticError> {
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
    pub(super) fn full_at(&self, prepared: &Prepared, alpha: f64) -> [f64; 7] {
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
    pub(super) fn position_at(&self, pl: &Placement, alpha: f64) -> [f64; 7] {
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
        self.alpha_about(&self.wrist_link, q)
    }

    /// The orbit angle of a configuration of position mode ([`LimbIk::solve_position_at`]:
    /// the wrist straight, the elbow twist at its rest value), radians in [−π, π]: the direction
    /// of its elbow about the shoulder→end-effector axis, the axis position mode turns the elbow
    /// about. `solve_position_at(tip(q), position_alpha_of(q))` gives `q` back.
    /// ([`LimbIk::alpha_of`] measures about the shoulder→wrist-center axis, which differs where
    /// the hand is off the forearm's line: near a hanging arm, where the reference direction
    /// `down` runs almost along the axis, the two angles can lie half a turn apart.) `None`
    /// for a chain without position mode.
    pub fn position_alpha_of(&self, q: &[f64; 7]) -> Option<f64> {
        self.reach_link
            .as_ref()
            .map(|link| self.alpha_about(link, q))
    }

    /// The orbit angle of `q` about the axis of `link` (as [`LimbIk::alpha_of`] describes).
    fn alpha_about(&self, link: &Link, q: &[f64; 7]) -> f64 {
        let rs = *(swing_rotation(q[0], q[1]) * axis_rotation(Axis::Z, q[2])).matrix();
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
}

// The limit test, steps 1–3 and the orbit search read the limb's fields, so they are methods
// here beside the type (the files holding their data — limits.rs, placement.rs, orbit.rs — then
// need nothing from this one: no import circle).

impl LimbIk {
    /// True when `q` is within the limits — the same test as [`Chain::within_limits`].
    ///
    /// [`Chain::within_limits`]: kinergy_motion::Chain::within_limits
    pub fn within_limits(&self, q: &[f64; 7]) -> bool {
        // [`LimbIk::violation`]'s test, stopping at the first DoF outside (each excess is zero
        // exactly where its DoF is within, and they sum to zero only where all are).
        let l = &self.limits;
        swing_excess(q[0], q[1], l.shoulder_swing) == 0.0
            && revolute_excess(q[2], l.shoulder_twist) == 0.0
            && revolute_excess(q[3], l.elbow_flexion) == 0.0
            && revolute_excess(q[4], l.elbow_twist) == 0.0
            && swing_excess(q[5], q[6], l.wrist_swing) == 0.0
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
}

impl LimbIk {
    /// Step 1's test: `Unreachable` unless `d` lies within the link's shell.
    #[inline]
    pub(super) fn check_reach(link: &Link, d: f64) -> Result<(), AnalyticError> {
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
    pub(super) fn place(&self, link: &Link, rel: &Vector3<f64>, d: f64) -> Placement {
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
    pub(super) fn axis(&self, rel: &Vector3<f64>, d: f64, link: &Link) -> Vector3<f64> {
        if d > TINY * link.outer {
            rel * d.recip()
        } else {
            -self.down.into_inner()
        }
    }

    /// In the upper-arm frame: the tip's direction `p̂'` and the unit direction `e₁ ⟂ p̂'`
    /// toward the elbow, on side `side` (±1) of the flexion plane.
    #[inline]
    pub(super) fn elbow_side(
        &self,
        link: &Link,
        p: &Vector3<f64>,
        side: f64,
    ) -> (Vector3<f64>, Vector3<f64>) {
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
    pub(super) fn orbit_basis(&self, n: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
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

impl LimbIk {
    /// Kallmann's orbit-angle search: the first α of `settings` ([`OrbitSearch::alphas`])
    /// whose posture is within limits.
    pub fn search(
        &self,
        goal: &IsometryMatrix3<f64>,
        settings: &OrbitSearch,
    ) -> Result<(f64, [f64; 7]), AnalyticError> {
        self.search_with(goal, settings, &|_| true)
    }

    /// The first orbit angle of `alphas` whose posture for `goal` lies within the limits, with
    /// the posture: [`LimbIk::solve`] at each angle in turn, the goal prepared once, without
    /// [`LimbIk::search`]'s diagnosis of a failure. `None` when the goal is out of reach or
    /// no angle gives a posture within the limits.
    pub fn first_within_limits(
        &self,
        goal: &IsometryMatrix3<f64>,
        alphas: impl IntoIterator<Item = f64>,
    ) -> Option<(f64, [f64; 7])> {
        let prepared = self.prepare_goal(goal).ok()?;
        alphas
            .into_iter()
            .filter(|a| a.is_finite())
            .map(|a| (a, self.full_at(&prepared, a)))
            .find(|(_, q)| self.within_limits(q))
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
}
