//! Reaching the edge of the reach sphere: how the controller guides a position task whose
//! target lies near or beyond the arm's full extension (DESIGN §1.1; a departure from the
//! paper, whose optimizers see only the Cartesian error ΔX = X_d − H(Θ)).
//!
//! **Why.** For an arm with shoulder s, elbow hinge e and hand h, the distance r = |h − s| is
//! set by the joints past the shoulder alone; rotating the hinge by Δ gives
//!
//! ```text
//! r²(Δ) = C + R cos(Δ − ψ),   C = |a + b∥|² + |b⊥|²,   R = 2 |(a·b⊥, a·(ω × b))|,
//!                             ψ = atan2(a·(ω × b), a·b⊥),
//! ```
//!
//! with a = e − s, b = h − e, ω the hinge's unit axis, b∥ = (ω·b) ω and b⊥ = b − b∥ (for
//! [`Chain::arm`] with a straight wrist this is the law of cosines r² = u² + ℓ² + 2uℓ cos φ,
//! u the upper arm, ℓ forearm + hand, φ the flexion). Δ = ψ is the hinge's full extension,
//! where ∂r/∂φ = −R sin(Δ − ψ) / 2r vanishes: the Jacobian loses rank in the radial
//! direction, its radial singular value falls like the sine of the angle θ from extension,
//! and r_max − r grows like θ². A target on the reach sphere's edge is a point where every
//! linear step converges sub-linearly (JT's radial rate λσ² → 0: it runs out of frames), the
//! SVD threshold drops the radial direction, and the stall rule fires. Targets behind the
//! hand make it worse: the chord ΔX then points through the shoulder, and following it folds
//! the elbow until the shoulder's swing and twist sit on their limits, the hand far from the
//! target (measured on captured raises from a hanging arm to above the head).
//!
//! **What the controller does** (position tasks on a chain with a [`ReachSphere`]; pose
//! tasks and other chains run the paper's loop unchanged). With d = |t − s| the target's
//! distance and L the full reach, the radial goal is d' = min(d, L), the target pulled onto
//! the sphere t' = s + d' t̂, and θ* = arccos((d'² − u² − ℓ²) / 2uℓ) is how far from
//! extension the elbow of the straight-wristed arm is when it reaches d' (u shoulder →
//! elbow, ℓ elbow → hand). The guidance weight w = 1 − smoothstep((θ* − 30°) / 12°) depends
//! on the target's distance alone: 0 for targets nearer than the elbow bent by 42° reaches
//! (93% of the reach for a typical arm), 1 beyond 30° (97%). Ordinary reaches, nearer, run
//! exactly as the paper has them, frame for frame. With weight w, each frame:
//!
//! 1. *The distance goes to the hinge, by the law of cosines.* The hinge moves toward the
//!    exact angle Δ* with r(Δ*) = d' (of the two branches and the limits, the one whose
//!    distance is closest to d', then the nearest) at the optimizer's own law for a single
//!    DoF whose Jacobian column is the hinge's c = ω × b ([`Optimizer`]'s one-DoF step:
//!    JT λ·dt·|c|²·gap, NJT min(speed·dt, |gap|), SVD rate·dt·gap, DLS
//!    rate·dt·|c|²/(|c|² + μ²)·gap). Its step is (1 − w) × the optimizer's + w × this one,
//!    and the optimizer sees its column scaled by 1 − w.
//! 2. *Then the wrist.* When the hinge alone cannot reach d' (the wrist is bent), a wrist
//!    swing straightens toward the bend β* = arccos((d'² − A² − B²) / 2AB) that reaches d'
//!    with a straight elbow (A = shoulder–elbow + elbow–wrist, B = wrist–hand; the swing's
//!    bend is |(s_x, s_y)|), at the elbow's rate.
//! 3. *The shoulder cancels their side effect.* The hinge and wrist also move the hand
//!    across the radial direction; the shoulder's minimum-norm rotation J_sᵀ(J_s J_sᵀ)⁺
//!    undoes w × that tangential displacement in the same frame, so the pair moves the hand
//!    radially only (to first order).
//! 4. *The optimizer gets the rest:* E − w (E·ĥ − ρ) ĥ, the guided error E without the
//!    radial part the hinge and wrist take (ĥ the unit shoulder → hand direction; ρ the
//!    distance they cannot take, 0 when there is a wrist swing to straighten), which the
//!    shoulder and the other DoFs serve well conditioned. With w = 1 and ρ = 0 its Jacobian
//!    loses its radial row as well (J ← (I − ĥĥᵀ) J): no pseudo-inverse then amplifies the
//!    other DoFs' vanishing radial parts, and the SVD's Gram, exactly of rank 2, is
//!    inverted in closed form. E is the Cartesian error to the target on the sphere,
//!    t' − h (= ΔX for a target within reach), except:
//! 5. *for targets behind the hand* (α = ∠(ĥ, t̂) beyond 90°, fully from 120°; weight
//!    w_α = w · smoothstep((α − 90°) / 30°)), E = (1 − w_α)(t' − h) + w_α ((d' − r) ĥ + r σ ê):
//!    the hand goes around the sphere instead of along the chord. For a swing shoulder ê is
//!    the direction the straight-arm swing takes from the hand's direction to the target's
//!    along the straight line between them in swing coordinates (it stays inside the
//!    convex limit ellipse), σ that line's length; else the great circle, σ = α.
//! 6. *Beyond reach* (d > L) the arm straightens toward the target and the motion ends
//!    [`crate::StopReason::Stalled`] at the reachable point nearest it, t'. The stall rule
//!    measures progress on (1 − w_α)|t' − h| + w_α √((d' − r)² + (d'σ)²), which the guided
//!    motion decreases (the final error reported is still |t − h|).
//!
//! The smooth controller ([`crate::smoothing`]) also guides while the arm itself is near
//! straight, by the same weight of its own hinge angle (the larger of the two weights): a
//! reach from a hanging arm starts at the hinge's singularity whatever the target's distance.
//! While the synergy drives, that angle is read from the shoulder–hand distance as if the
//! wrist were straight; once the plain optimizer has the step (after the finish), from the
//! hinge itself, so that a bent wrist does not hide a straight elbow (`StraightArm`).
//!
//! Every step still goes through the synergy transform, the limit handling and the clamp,
//! so a zero gain still freezes its DoF.

use kinergy_motion::nalgebra::{IsometryMatrix3, Matrix3, Point3, Rotation3, Vector3};
use kinergy_motion::rotation::swing_to;
use kinergy_motion::{Chain, Linearization, Motion};

use crate::optimizer::{Optimizer, pseudo_inverse_3};
use crate::task::TaskError;

/// The hinge angle from extension below which the guidance is whole, radians (30°).
const FULL_BELOW: f64 = std::f64::consts::PI / 6.0;
/// The hinge angle from extension above which there is no guidance, radians (42°).
const NONE_ABOVE: f64 = 42.0 * std::f64::consts::PI / 180.0;
/// The angle between hand and target directions from which the hand starts to go around
/// the sphere, radians (90°).
const BEHIND_FROM: f64 = std::f64::consts::FRAC_PI_2;
/// … and from which it goes around entirely, radians (120°).
const BEHIND_FULLY: f64 = 2.0 * std::f64::consts::FRAC_PI_3;

/// How the smooth controller tells that the arm itself is near straight (module docs: it
/// guides then too, whatever the target's distance).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum StraightArm {
    /// Not at all (the paper's controller): the target's distance alone decides.
    Ignored,
    /// From the shoulder–hand distance, read as the elbow angle of an arm with a straight
    /// wrist: while the synergy drives. A bent wrist hides a straight elbow from it, but
    /// reading the hinge itself there guided many more frames of the person's own motion
    /// (replayed per clip on the synthetic set, the hand-speed correlation with the capture fell
    /// on 30 of 56 reaches, mean 0.78 → 0.71).
    FromDistance,
    /// From the hinge's own angle from its full extension: once the plain optimizer has the
    /// step (after the finish), where a bent wrist hid a straight elbow from the distance and
    /// the plain step stalled at the hinge's singularity (synthetic `p01/r03`'s per-clip S_D
    /// vector, 18.7 mm short with the elbow straight and the wrist on its limits).
    FromHinge,
}

/// The reach sphere of an arm-like chain: its shoulder (the first joint, at the sphere's
/// center), the hinge that sets the distance (the elbow), the wrist swing and the full
/// reach. See the [module documentation](self).
#[derive(Debug, Clone, PartialEq)]
pub struct ReachSphere {
    /// DoFs of the first joint (the shoulder).
    shoulder_dofs: usize,
    /// The shoulder's first motion is a swing about its frame's x–y plane.
    swing_shoulder: bool,
    hinge: usize,
    hinge_joint: usize,
    hinge_limits: (f64, f64),
    /// First DoF and joint of the wrist swing.
    wrist: Option<(usize, usize)>,
    /// Shoulder → hinge and hinge → end effector, with the arm straight.
    upper: f64,
    lower: f64,
    reach: f64,
}

impl ReachSphere {
    /// The reach sphere of `chain`, or `None` when it has none: the chain must be straight
    /// at q = 0 (every joint and the end effector on one ray from the first joint, in order,
    /// and q = 0 within the limits, as in [`Chain::arm`]), and a joint past the first must
    /// start with a revolute DoF across the bone (the hinge). A wrist is a later joint
    /// made of one swing with its bone along its z axis.
    pub fn of(chain: &Chain) -> Option<ReachSphere> {
        let zero = vec![0.0; chain.dof_count()];
        if !chain.within_limits(&zero) {
            return None;
        }
        let mut lin = Linearization::default();
        chain
            .linearize_into(&IsometryMatrix3::identity(), &zero, &mut lin)
            .ok()?;
        let p0 = lin.joints[0];
        let reach = (lin.end - p0).norm();
        if reach <= 0.0 {
            return None;
        }
        let dir = (lin.end - p0) / reach;
        let mut along = 0.0;
        for p in lin.joints.iter().skip(1).chain(std::iter::once(&lin.end)) {
            let v = p - p0;
            let t = v.dot(&dir);
            if (v - dir * t).norm() > 1e-9 * reach || t < along - 1e-12 * reach {
                return None;
            }
            along = t;
        }
        let joints = chain.joints();
        let first_dof = |j: usize| -> usize {
            joints[..j]
                .iter()
                .flat_map(|j| &j.motions)
                .map(Motion::dof_count)
                .sum()
        };
        let (hinge, hinge_joint, hinge_limits) =
            joints.iter().enumerate().skip(1).find_map(|(j, joint)| {
                let &Motion::Revolute { min, max, .. } = joint.motions.first()? else {
                    return None;
                };
                let k = first_dof(j);
                let lever = lin.end - lin.joints[j];
                let across = lin.angular.column(k).cross(&lever).norm();
                (lever.norm() > 0.0 && across >= 0.9 * lever.norm()).then_some((k, j, (min, max)))
            })?;
        let upper = (lin.joints[hinge_joint] - p0).norm();
        if upper <= 1e-9 * reach {
            return None;
        }
        let wrist = (hinge_joint + 1..joints.len())
            .find(|&j| {
                // The bone after the swing, in the wrist's own frame, along +z.
                let bone = joints
                    .get(j + 1)
                    .map_or(chain.end_effector(), |next| next.offset);
                matches!(joints[j].motions.as_slice(), [Motion::Swing { .. }])
                    && joints[j].rest == Rotation3::identity()
                    && bone.z > 0.0
                    && bone.x.hypot(bone.y) <= 1e-12 * bone.z
            })
            .map(|j| (first_dof(j), j));
        Some(ReachSphere {
            shoulder_dofs: first_dof(1),
            swing_shoulder: matches!(joints[0].motions.first(), Some(Motion::Swing { .. }))
                && joints[0].rest == Rotation3::identity(),
            hinge,
            hinge_joint,
            hinge_limits,
            wrist,
            upper,
            lower: (lin.end - lin.joints[hinge_joint]).norm(),
            reach,
        })
    }

    /// The full reach L: the distance from the shoulder to the end effector with the arm
    /// straight, meters.
    pub fn reach(&self) -> f64 {
        self.reach
    }

    /// The guidance for one frame (configuration `q`, its linearization, the target, the
    /// base frame's rotation; the hinge and wrist driven at the optimizer's `pace`), or
    /// `None` when the target is not near the sphere's edge (and, as `straight_arm` reads
    /// it, the arm is not near straight either).
    pub(crate) fn guide(
        &self,
        q: &[f64],
        lin: &Linearization,
        target: &Point3<f64>,
        base_rotation: &Rotation3<f64>,
        pace: Pace<'_>,
        straight_arm: StraightArm,
    ) -> Option<Guidance> {
        let s = lin.joints[0];
        let h = lin.end;
        let (hv, tv) = (h - s, target - s);
        let (r, d) = (hv.norm(), tv.norm());
        // How far from extension the straight-wristed arm's elbow is when it reaches d'.
        let d_goal = d.min(self.reach);
        let (u, l) = (self.upper, self.lower);
        let cos_needed = (d_goal * d_goal - u * u - l * l) / (2.0 * u * l);
        let tiny = 1e-9 * self.reach;
        let weight_at = |cos: f64| {
            if cos >= FULL_BELOW.cos() {
                1.0
            } else if cos < NONE_ABOVE.cos() {
                0.0
            } else {
                1.0 - smoothstep(cos.acos(), FULL_BELOW, NONE_ABOVE)
            }
        };
        // The smooth controller guides also while the arm itself is near straight: a hanging
        // arm's start, where the radial direction has no singular value.
        // The hinge's sinusoid, computed once a frame where it is needed.
        let mut sinusoid: Option<(f64, f64, f64)> = None;
        let now = match straight_arm {
            StraightArm::Ignored => 0.0,
            StraightArm::FromDistance => weight_at((r * r - u * u - l * l) / (2.0 * u * l)),
            StraightArm::FromHinge => {
                let (_, amp, psi) = *sinusoid.get_or_insert_with(|| self.hinge_sinusoid(lin));
                if amp > tiny * tiny {
                    weight_at(psi.cos())
                } else {
                    0.0
                }
            }
        };
        let weight = weight_at(cos_needed).max(now);
        if weight <= 0.0 || r <= tiny || d <= tiny {
            return None;
        }
        let (c0, amp, psi) = sinusoid.unwrap_or_else(|| self.hinge_sinusoid(lin));
        if amp <= tiny * tiny {
            return None;
        }
        let e = lin.joints[self.hinge_joint];
        let w = lin.angular.column(self.hinge).into_owned();
        let b = h - e;
        let b_perp = b - w * w.dot(&b);

        // 1. The hinge: the law-of-cosines angle nearest where it is, within its limits; when
        // both lie beyond them, the limit whose distance is closest to d'.
        let phi = q[self.hinge];
        let (lo, hi) = (self.hinge_limits.0 - phi, self.hinge_limits.1 - phi);
        let c = (d_goal * d_goal - c0) / amp;
        let half = c.clamp(-1.0, 1.0).acos();
        let wrap = |x: f64| {
            use std::f64::consts::{PI, TAU};
            if x > PI {
                x - TAU
            } else if x <= -PI {
                x + TAU
            } else {
                x
            }
        };
        let within = [wrap(psi + half), wrap(psi - half)]
            .into_iter()
            .filter(|x| (lo..=hi).contains(x))
            .min_by(|a, b| a.abs().total_cmp(&b.abs()));
        let r_at = |delta: f64| (c0 + amp * (delta - psi).cos()).max(0.0).sqrt();
        let (gap, r_hinge) = match within {
            Some(delta) if c.abs() <= 1.0 => (delta, d_goal),
            Some(delta) => (delta, r_at(delta)),
            None => {
                let (r_lo, r_hi) = (r_at(lo), r_at(hi));
                if (r_lo - d_goal).abs() <= (r_hi - d_goal).abs() {
                    (lo, r_lo)
                } else {
                    (hi, r_hi)
                }
            }
        };
        let column_sq = b_perp.norm_squared();
        let hinge_step = pace.step(column_sq, gap);
        // Rodrigues: the hand turned about the hinge by w × its step.
        let (sin, cos) = (weight * hinge_step).sin_cos();
        let mut moved = b_perp * (cos - 1.0) + w.cross(&b) * sin;

        // 2. The wrist, when the hinge alone falls short; without one the optimizer keeps
        // that part of the distance.
        let mut wrist_step = [0.0; 2];
        let mut residual = d_goal - r_hinge;
        if let Some((k, j)) = self.wrist
            && r_hinge < d_goal - tiny
        {
            residual = 0.0;
            let pw = lin.joints[j];
            let (big_a, big_b) = ((e - s).norm() + (pw - e).norm(), (h - pw).norm());
            let bend = q[k].hypot(q[k + 1]);
            let bend_goal = ((d_goal * d_goal - big_a * big_a - big_b * big_b)
                / (2.0 * big_a * big_b))
                .clamp(-1.0, 1.0)
                .acos();
            if bend > bend_goal {
                let step = pace.step(column_sq, bend_goal - bend) / bend;
                wrist_step = [q[k] * step, q[k + 1] * step];
                moved += (lin.linear.column(k) * wrist_step[0]
                    + lin.linear.column(k + 1) * wrist_step[1])
                    * weight;
            }
        }

        // 5. The direction, around the sphere for targets behind the hand.
        let h_hat = hv / r;
        let t_hat = tv / d;
        let cos_alpha = h_hat.dot(&t_hat).clamp(-1.0, 1.0);
        let toward = t_hat - h_hat * cos_alpha;
        // α = ∠(ĥ, t̂) matters from 90° on, where cos α < 0.
        let alpha = if cos_alpha < 0.0 {
            toward.norm().atan2(cos_alpha)
        } else {
            0.0
        };
        let behind = weight * smoothstep(alpha, BEHIND_FROM, BEHIND_FULLY);
        // The target pulled onto the reach sphere when it lies beyond.
        let cartesian = tv * (d_goal / d) - hv;
        let (guided, progress) = if behind > 0.0 {
            let (e_hat, sigma) = self
                .swing_direction(base_rotation, &h_hat, &t_hat)
                .unwrap_or_else(|| (great_circle(&h_hat, &toward), alpha));
            let around = h_hat * (d_goal - r) + e_hat * (r * sigma);
            (
                cartesian + (around - cartesian) * behind,
                cartesian.norm() * (1.0 - behind) + (d_goal - r).hypot(d_goal * sigma) * behind,
            )
        } else {
            (cartesian, cartesian.norm())
        };

        Some(Guidance {
            hinge: self.hinge,
            wrist: self.wrist.map(|(k, _)| k),
            shoulder_dofs: self.shoulder_dofs,
            weight,
            hinge_step,
            wrist_step,
            // 4. The optimizer's share: the error without the radial part the hinge and
            // wrist take.
            error: guided - h_hat * ((guided.dot(&h_hat) - residual) * weight),
            // 3. What the shoulder cancels.
            side: moved - h_hat * moved.dot(&h_hat),
            radial: h_hat,
            residual,
            progress,
        })
    }

    /// The hinge's sinusoid (C, R, ψ): r²(Δ) = C + R cos(Δ − ψ) is the squared shoulder →
    /// end distance with the hinge turned by Δ from where `lin` has it.
    fn hinge_sinusoid(&self, lin: &Linearization) -> (f64, f64, f64) {
        let s = lin.joints[0];
        let e = lin.joints[self.hinge_joint];
        let w = lin.angular.column(self.hinge).into_owned();
        let (a, b) = (e - s, lin.end - e);
        let b_par = w * w.dot(&b);
        let b_perp = b - b_par;
        let (rc, rs) = (2.0 * a.dot(&b_perp), 2.0 * a.dot(&w.cross(&b)));
        let c0 = (a + b_par).norm_squared() + b_perp.norm_squared();
        (c0, rc.hypot(rs), rs.atan2(rc))
    }

    /// The tangent at ĥ along which the straight-arm swing moves from pointing at ĥ to
    /// pointing at t̂ on the straight line in swing coordinates, and that line's length.
    fn swing_direction(
        &self,
        base_rotation: &Rotation3<f64>,
        h_hat: &Vector3<f64>,
        t_hat: &Vector3<f64>,
    ) -> Option<(Vector3<f64>, f64)> {
        if !self.swing_shoulder {
            return None;
        }
        let local = base_rotation.inverse() * h_hat;
        let (hx, hy) = swing_to(&local);
        let (tx, ty) = swing_to(&(base_rotation.inverse() * t_hat));
        let (v, ds) = (
            Vector3::new(hx, hy, 0.0),
            Vector3::new(tx - hx, ty - hy, 0.0),
        );
        // d/dε exp([v + ε ds]×) z = (J_l(v) ds) × exp([v]×) z, with
        // J_l(v) x = x + a v × x + b v × (v × x), a = (1 − cos θ)/θ², b = (θ − sin θ)/θ³.
        let t2 = v.norm_squared();
        let (a, b) = if t2 < 1e-8 {
            (0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0)
        } else {
            let t = t2.sqrt();
            let (sin, cos) = t.sin_cos();
            ((1.0 - cos) / t2, (t - sin) / (t2 * t))
        };
        let vx = v.cross(&ds);
        let moved = base_rotation * (ds + vx * a + v.cross(&vx) * b).cross(&local);
        let tangent = moved - h_hat * moved.dot(h_hat);
        let norm = tangent.norm();
        (norm > 1e-9).then(|| (tangent / norm, ds.norm()))
    }
}

/// The pace at which the guidance drives the hinge and the wrist: the controller's optimizer's
/// law for a single DoF over one frame of `dt` seconds ([`Optimizer`]'s one-DoF step, module
/// docs step 1), so they keep the optimizer's pace.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pace<'a> {
    /// The controller's optimizer.
    pub(crate) optimizer: &'a Optimizer,
    /// The frame time, seconds.
    pub(crate) dt: f64,
}

impl Pace<'_> {
    /// The step of a DoF whose Jacobian column has squared norm `column_sq` and which should
    /// move by `gap` radians.
    #[inline]
    fn step(&self, column_sq: f64, gap: f64) -> f64 {
        self.optimizer.drive_step(column_sq, gap, self.dt)
    }
}

/// One frame's guidance (see the [module documentation](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Guidance {
    hinge: usize,
    wrist: Option<usize>,
    shoulder_dofs: usize,
    /// w: how much of the distance the hinge and wrist take from the optimizer.
    weight: f64,
    hinge_step: f64,
    wrist_step: [f64; 2],
    /// The optimizer's share of the task error.
    error: Vector3<f64>,
    /// The tangential hand displacement of the weighted hinge and wrist steps.
    side: Vector3<f64>,
    /// ĥ, the unit shoulder → hand direction.
    radial: Vector3<f64>,
    /// The distance the hinge and wrist cannot take, left in the optimizer's error.
    residual: f64,
    progress: f64,
}

impl Guidance {
    /// The size of the guided error, meters: what the stall rule watches.
    pub(crate) fn progress(&self) -> f64 {
        self.progress
    }

    /// The hinge's DoF.
    pub(crate) fn hinge(&self) -> usize {
        self.hinge
    }

    /// The task error the optimizer sees.
    pub(crate) fn optimizer_error(&self) -> TaskError {
        TaskError::position(self.error)
    }

    /// Hands the hinge over: its Jacobian columns scaled by 1 − w. When the distance is
    /// wholly the hinge's and wrist's (w = 1, nothing left over) the optimizer works across
    /// ĥ only: the radial row is removed from its Jacobian (J ← (I − ĥĥᵀ) J) as from its
    /// error, so no pseudo-inverse amplifies the other DoFs' vanishing radial parts.
    pub(crate) fn hand_over(&self, lin: &mut Linearization) {
        let keep = 1.0 - self.weight;
        lin.linear.column_mut(self.hinge).scale_mut(keep);
        lin.angular.column_mut(self.hinge).scale_mut(keep);
        if self.weight >= 1.0 && self.residual == 0.0 {
            let radial = self.radial;
            for mut c in lin.linear.column_iter_mut() {
                let along = radial.dot(&c);
                c -= radial * along;
            }
        }
    }

    /// Adds the hinge and wrist steps and the shoulder's compensation to the optimizer's
    /// `step` (computed on the handed-over `lin`).
    pub(crate) fn drive(&self, lin: &Linearization, step: &mut [f64]) {
        let w = self.weight;
        step[self.hinge] = (1.0 - w) * step[self.hinge] + w * self.hinge_step;
        if let Some(k) = self.wrist {
            step[k] += w * self.wrist_step[0];
            step[k + 1] += w * self.wrist_step[1];
        }
        // The shoulder's columns ω × (h − s) span the plane across ĥ: its minimum-norm step
        // for the tangential −side is J_sᵀ (J_s J_sᵀ)⁺ (−side), and on that plane
        // (J_s J_sᵀ)⁺ is the inverse of J_s J_sᵀ + κ ĥ ĥᵀ (any κ > 0): a closed-form 3 × 3
        // inverse instead of an eigen-decomposition.
        let mut g = Matrix3::zeros();
        for c in lin.linear.column_iter().take(self.shoulder_dofs) {
            g.ger(1.0, &c, &c, 1.0);
        }
        let kappa = g.trace();
        let filled = g + self.radial * self.radial.transpose() * kappa;
        let y = match filled.try_inverse() {
            Some(inverse) if filled.determinant() > 1e-9 * kappa.powi(3) => inverse * -self.side,
            // A shoulder that no longer spans the plane (a DoF locked on its limit).
            _ => pseudo_inverse_3(&g, &(-self.side), 1e-3),
        };
        for (s, c) in step
            .iter_mut()
            .zip(lin.linear.column_iter())
            .take(self.shoulder_dofs)
        {
            *s += c.dot(&y);
        }
    }
}

/// smoothstep from 0 at `from` to 1 at `to`.
fn smoothstep(x: f64, from: f64, to: f64) -> f64 {
    let x = ((x - from) / (to - from)).clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// The unit tangent at ĥ toward t̂ on their great circle (`toward` = t̂ − (t̂·ĥ) ĥ); any
/// tangent when t̂ = ±ĥ.
fn great_circle(h_hat: &Vector3<f64>, toward: &Vector3<f64>) -> Vector3<f64> {
    let norm = toward.norm();
    if norm > 1e-9 {
        return toward / norm;
    }
    let any = if h_hat.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    (any - h_hat * any.dot(h_hat)).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use kinergy_motion::ChainJoint;
    use kinergy_motion::nalgebra::{Translation3, UnitQuaternion};
    use proptest::prelude::*;

    fn arm() -> Chain {
        Chain::arm(0.30, 0.26, 0.09).expect("arm")
    }

    fn base() -> IsometryMatrix3<f64> {
        IsometryMatrix3::from_parts(
            Translation3::new(0.2, 1.4, -0.1),
            UnitQuaternion::from_euler_angles(0.3, -1.2, 0.5).to_rotation_matrix(),
        )
    }

    fn linearize(chain: &Chain, q: &[f64]) -> Linearization {
        let mut lin = Linearization::default();
        chain
            .linearize_into(&base(), q, &mut lin)
            .expect("linearize");
        lin
    }

    #[test]
    fn the_arm_has_a_sphere_with_its_elbow_and_wrist() {
        let sphere = ReachSphere::of(&arm()).expect("sphere");
        assert_eq!(
            (sphere.shoulder_dofs, sphere.hinge, sphere.wrist),
            (3, 3, Some((5, 2)))
        );
        assert!(sphere.swing_shoulder);
        assert_relative_eq!(sphere.reach(), 0.65, epsilon = 1e-12);
        // A lone swing has no hinge; a chain bent at zero has no sphere.
        let swing = Chain::new(
            vec![ChainJoint::new(
                "shoulder",
                Vector3::zeros(),
                vec![Motion::Swing { rx: 1.0, ry: 0.5 }],
            )],
            Vector3::new(0.0, 0.0, 0.5),
        )
        .expect("chain");
        assert!(ReachSphere::of(&swing).is_none());
        let mut joints = arm().joints().to_vec();
        joints[2].offset = Vector3::new(0.05, 0.0, 0.26);
        let bent = Chain::new(joints, Vector3::new(0.0, 0.0, 0.09)).expect("chain");
        assert!(ReachSphere::of(&bent).is_none());
    }

    proptest! {
        // The hinge's sinusoid is forward kinematics: r(Δ) = √(C + R cos(Δ − ψ)) is the
        // shoulder → hand distance FK gives with the elbow turned by Δ, wrist and all.
        #[test]
        fn the_hinge_sinusoid_is_forward_kinematics(
            q in proptest::collection::vec(-1.2f64..1.2, 7),
            delta in -3.0f64..3.0,
        ) {
            let chain = arm();
            let sphere = ReachSphere::of(&chain).expect("sphere");
            let lin = linearize(&chain, &q);
            let (c0, amp, psi) = sphere.hinge_sinusoid(&lin);
            let mut turned = q.clone();
            turned[3] += delta;
            let end = chain.end_position(&base(), &turned).expect("fk");
            let r = (end - lin.joints[0]).norm();
            assert_relative_eq!((c0 + amp * (delta - psi).cos()).sqrt(), r, epsilon = 1e-12);
            // ψ is the extension: no Δ gets farther.
            assert!((c0 + amp).sqrt() >= r - 1e-12);
        }

        // The shoulder cancels the elbow's and wrist's sideways motion: with it, the guided
        // step moves the hand (by FK) across the shoulder → hand line only by second-order
        // terms, a small fraction of what the elbow and wrist steps alone do.
        #[test]
        fn the_distal_drive_moves_the_hand_radially(
            swing in proptest::collection::vec(-1.0f64..1.0, 3),
            flexion in 0.05f64..0.5,
            wrist in proptest::collection::vec(-0.4f64..0.4, 3),
            beyond in 0.97f64..1.1,
        ) {
            let chain = arm();
            let sphere = ReachSphere::of(&chain).expect("sphere");
            let q = [swing[0], swing[1], swing[2], flexion, wrist[0], wrist[1], wrist[2] * 0.5];
            let lin = linearize(&chain, &q);
            let s = lin.joints[0];
            let radial = (lin.end - s).normalize();
            let target = s + radial * (beyond * sphere.reach());
            let optimizer = crate::OptimizerKind::Svd.default_optimizer();
            let pace = Pace { optimizer: &optimizer, dt: 1.0 / 120.0 };
            let guidance = sphere
                .guide(&q, &lin, &target, &base().rotation, pace, StraightArm::Ignored)
                .expect("near the edge");
            let mut step = [0.0; 7];
            let mut handed = lin.clone();
            guidance.hand_over(&mut handed);
            guidance.drive(&handed, &mut step);
            let across = |step: &[f64]| {
                let moved: Vec<f64> = q.iter().zip(step).map(|(a, b)| a + b).collect();
                let d = chain.end_position(&base(), &moved).expect("fk") - lin.end;
                (d - radial * d.dot(&radial)).norm()
            };
            let with = across(&step);
            let mut distal = step;
            distal[..3].fill(0.0);
            let without = across(&distal);
            prop_assume!(without > 1e-9);
            let second_order = sphere.reach() * step.iter().map(|v| v * v).sum::<f64>();
            assert!(
                with <= 0.05 * without + second_order,
                "{with:e} across with the shoulder, {without:e} without"
            );
        }
    }
}
