//! The data of steps 1–3 of the analytic IK (see the `analytic` module docs), everything but
//! α: the distal link as a planar problem ([`Link`]), the flexion, elbow side and orbit circle
//! made once per goal ([`Placement`], [`Prepared`]) so that the orbit search repeats only
//! steps 3–5 per α. The steps themselves (the reach test, the law of cosines, the elbow's
//! side, the orbit basis) are methods of `LimbIk` in `solver.rs`, which reads the limb.

use kinergy_motion::nalgebra::{Matrix3, Unit, Vector3};

/// Relative slack on the outer and inner reach: a goal made by FK of the stretched limb may
/// land a few ulps beyond `L1 + L2`; it is treated as on the boundary.
pub(super) const REACH_SLACK: f64 = 1e-12;

/// Below this fraction of the reach, the shoulder–wrist axis is undefined and a fixed one is
/// used (only possible when both links have the same length).
pub(super) const TINY: f64 = 1e-12;

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
