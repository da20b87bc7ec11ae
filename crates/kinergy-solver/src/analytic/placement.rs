//! Steps 1–3 of the analytic IK (see the `analytic` module docs), everything but α: the
//! reach test, the flexion from the law of cosines, the elbow's side in the upper-arm frame,
//! and the orbit circle's axis and basis ([`Placement`]), made once per goal so that the
//! orbit search repeats only steps 3–5 per α.

use kinergy_motion::nalgebra::{Matrix3, Unit, Vector3};

use super::error::AnalyticError;
use super::orbit::OrbitSense;
use super::solver::LimbIk;

/// Relative slack on the outer and inner reach: a goal made by FK of the stretched limb may
/// land a few ulps beyond `L1 + L2`; it is treated as on the boundary.
const REACH_SLACK: f64 = 1e-12;

/// Below this fraction of the reach, the shoulder–wrist axis is undefined and a fixed one is
/// used (only possible when both links have the same length).
const TINY: f64 = 1e-12;

/// The distal link seen from the upper-arm frame, as a planar two-link problem: the point
/// `p'(f) = L1 z + R_x(f) g` is placed at distance `d`, with
/// `|p'|² = L1² + |g|² + 2 L1 ρ cos(f − φ)`, `ρ = |(g_y, g_z)|`, `φ = atan2(g_y, g_z)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Link {
    pub(super) g: Vector3<f64>,
    pub(super) rho: f64,
    pub(super) phi: f64,
    pub(super) sin_phi: f64,
    pub(super) cos_phi: f64,
    /// `L1² + |g|²`.
    pub(super) sum_sq: f64,
    pub(super) inner: f64,
    pub(super) outer: f64,
    /// `g_x` negligible: the elbow side is `σ p̂' × x`, exact and defined even when stretched.
    pub(super) planar: bool,
}

impl Link {
    pub(super) fn new(upper: f64, g: Vector3<f64>) -> Option<Link> {
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

/// The part of a solution that does not depend on α (steps 1–3 of the module docs).
#[derive(Debug, Clone, Copy)]
pub(super) struct Placement {
    pub(super) f: f64,
    pub(super) sf: f64,
    pub(super) cf: f64,
    /// Rows `p̂'`, `e₁`, `p̂' × e₁`: the upper-arm frame's side of `R_s`.
    pub(super) local_t: Matrix3<f64>,
    pub(super) n: Vector3<f64>,
    pub(super) u: Vector3<f64>,
    pub(super) v: Vector3<f64>,
}

impl Placement {
    /// `R_s = [n, m, n × m] · [p̂', e₁, p̂' × e₁]ᵀ` with `m = cos α û + sin α v̂`.
    #[inline]
    pub(super) fn shoulder(&self, alpha: f64) -> Matrix3<f64> {
        let (sa, ca) = alpha.sin_cos();
        let m = self.u * ca + self.v * sa;
        Matrix3::from_columns(&[self.n, m, self.n.cross(&m)]) * self.local_t
    }
}

/// A full-pose goal made ready for any α.
#[derive(Debug, Clone, Copy)]
pub(super) struct Prepared {
    pub(super) placement: Placement,
    pub(super) rg_t: Matrix3<f64>,
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

/// `p'(f) = L1 z + R_x(f) g` from `sin f`, `cos f`.
#[inline]
pub(super) fn tip(upper: f64, g: &Vector3<f64>, sf: f64, cf: f64) -> Vector3<f64> {
    Vector3::new(g.x, cf * g.y - sf * g.z, upper + sf * g.y + cf * g.z)
}

/// The fallback reference for α = 0 when the axis lies along `down`: `down × x`, or `down × z`
/// when `down` is near x.
pub(super) fn fallback_for(down: &Unit<Vector3<f64>>) -> Unit<Vector3<f64>> {
    let c = down.cross(&Vector3::x());
    let c = if c.norm() > 0.5 {
        c
    } else {
        down.cross(&Vector3::z())
    };
    Unit::new_normalize(c)
}
