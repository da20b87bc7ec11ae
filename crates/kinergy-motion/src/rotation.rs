//! Rotations: principal axes, Euler sequences in any channel order, and the swing
//! (exponential-map) parameterization with its derivative.

use nalgebra::{Matrix3, Rotation3, Unit, UnitQuaternion, Vector3};

/// A principal axis of a frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Axis {
    /// The X axis.
    X,
    /// The Y axis.
    Y,
    /// The Z axis.
    Z,
}

impl Axis {
    /// 0, 1 or 2.
    pub fn index(self) -> usize {
        match self {
            Axis::X => 0,
            Axis::Y => 1,
            Axis::Z => 2,
        }
    }

    /// The axis with index 0, 1 or 2 (other values give Z).
    pub fn from_index(i: usize) -> Axis {
        match i {
            0 => Axis::X,
            1 => Axis::Y,
            _ => Axis::Z,
        }
    }

    /// The unit vector along this axis.
    pub fn unit(self) -> Unit<Vector3<f64>> {
        match self {
            Axis::X => Vector3::x_axis(),
            Axis::Y => Vector3::y_axis(),
            Axis::Z => Vector3::z_axis(),
        }
    }

    /// The letter, `'X'`, `'Y'` or `'Z'`.
    pub fn letter(self) -> char {
        ['X', 'Y', 'Z'][self.index()]
    }
}

/// The rotation by `angle` radians about a principal axis, built from one `sin_cos`.
#[inline]
pub fn axis_rotation(axis: Axis, angle: f64) -> Rotation3<f64> {
    let (s, c) = crate::trig::sin_cos(angle);
    let m = match axis {
        Axis::X => Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c),
        Axis::Y => Matrix3::new(c, 0.0, s, 0.0, 1.0, 0.0, -s, 0.0, c),
        Axis::Z => Matrix3::new(c, -s, 0.0, s, c, 0.0, 0.0, 0.0, 1.0),
    };
    Rotation3::from_matrix_unchecked(m)
}

/// The rotation of an Euler sequence as BVH reads it: `R = R_a0(θ0) · R_a1(θ1) · …`,
/// the first listed channel outermost (intrinsic rotations in listed order).
pub fn euler_rotation(axes: &[Axis], angles: &[f64]) -> Rotation3<f64> {
    axes.iter()
        .zip(angles)
        .fold(Rotation3::identity(), |r, (&a, &t)| r * axis_rotation(a, t))
}

/// Angles `(θ0, θ1, θ2)` with `R = R_i(θ0) R_j(θ1) R_k(θ2)` for three distinct axes.
///
/// With ε = +1 when (i, j, k) is a cyclic permutation of (X, Y, Z) and −1 otherwise:
/// |cos θ1| = hypot(R_jk, R_kk), θ1 = atan2(ε R_ik, |cos θ1|), θ0 = atan2(−ε R_jk, R_kk),
/// θ2 = atan2(−ε R_ij, R_ii). At gimbal lock (|cos θ1| below [`GIMBAL_LOCK`]) θ2 is set to 0
/// and θ0 takes the whole remaining rotation. (|cos θ1| is read from the two entries that
/// carry it, not as √(1 − sin² θ1): a matrix one rounding off the lock has sin θ1 one ulp
/// below 1, where the square root says 3·10⁻⁸, and θ0, θ2 from entries of rounding noise are
/// arbitrary — a forearm written at its twist limit would flip 180° on single frames.) Returns
/// `None` when the axes are not three distinct ones.
pub fn euler_angles(axes: [Axis; 3], r: &Rotation3<f64>) -> Option<[f64; 3]> {
    let [i, j, k] = axes.map(Axis::index);
    if i == j || j == k || i == k {
        return None;
    }
    let eps = if (j + 3 - i) % 3 == 1 { 1.0 } else { -1.0 };
    let m = r.matrix();
    let c1 = m[(j, k)].hypot(m[(k, k)]);
    let t1 = (eps * m[(i, k)]).atan2(c1);
    if c1 > GIMBAL_LOCK {
        let t0 = (-eps * m[(j, k)]).atan2(m[(k, k)]);
        let t2 = (-eps * m[(i, j)]).atan2(m[(i, i)]);
        Some([t0, t1, t2])
    } else {
        // Gimbal lock: R_i(θ0) R_j(±π/2) fixes only θ0 ± θ2; put it all in θ0.
        // With θ2 = 0, R = R_i(θ0) R_j(θ1), whose column j is R_i(θ0) e_j.
        let t0 = (eps * m[(k, j)]).atan2(m[(j, j)]);
        Some([t0, t1, 0.0])
    }
}

/// |cos θ1| below which [`euler_angles`] treats a rotation as at gimbal lock: θ0 and θ2 from
/// entries of about |cos θ1| carrying rounding noise of 10⁻¹⁶ are good to 10⁻⁸, and putting
/// the whole turn into θ0 below it is off by about 3·|cos θ1|: either way a point a meter away
/// lands within 10⁻⁷ m (measured 2.8·10⁻⁸, `near_gimbal_lock_with_rounding_noise…`).
pub const GIMBAL_LOCK: f64 = 1e-8;

/// The swing rotation `exp([v]×)` for a swing vector `v = (sx, sy, 0)`: angle |v| about the
/// axis v/|v| lying in the x–y plane (DESIGN §1.2: twist about z, swing about an axis in x–y).
///
/// Rodrigues' formula with the unit axis u = (ux, uy, 0), angle θ = |v|:
/// `R = I + sin θ [u]× + (1 − cos θ)(u uᵀ − I)`, written out (no general axis–angle code).
#[inline]
pub fn swing_rotation(sx: f64, sy: f64) -> Rotation3<f64> {
    swing_rotation_with(sx, sy, crate::trig::sin_cos)
}

/// θ² = sx² + sy² of the swing `(sx, sy)`, computed once for every use: θ = its square root is
/// the angle whose sine and cosine a chain's memo keeps for the swing's rotation, so every
/// place that forms θ must form it alike, to the bit.
#[inline]
pub(crate) fn swing_angle_squared(sx: f64, sy: f64) -> f64 {
    sx * sx + sy * sy
}

/// [`swing_rotation`] with θ's sine and cosine from `sin_cos(θ)` (a memo of them: the same
/// values, the same bits); not called near zero, where the series needs neither.
#[inline]
pub(crate) fn swing_rotation_with(
    sx: f64,
    sy: f64,
    sin_cos: impl FnOnce(f64) -> (f64, f64),
) -> Rotation3<f64> {
    let t2 = swing_angle_squared(sx, sy);
    // sin θ / θ and (1 − cos θ) / θ², with their series near zero.
    let (a, b, c) = if t2 < 1e-12 {
        (1.0 - t2 / 6.0, 0.5 - t2 / 24.0, 1.0 - t2 / 2.0)
    } else {
        let t = t2.sqrt();
        let (s, c) = sin_cos(t);
        (s / t, (1.0 - c) / t2, c)
    };
    let m = Matrix3::new(
        1.0 - b * sy * sy,
        b * sx * sy,
        a * sy,
        b * sx * sy,
        1.0 - b * sx * sx,
        -a * sx,
        -a * sy,
        a * sx,
        c,
    );
    Rotation3::from_matrix_unchecked(m)
}

/// A swing's rotation and its two left-Jacobian columns from one `sin_cos`:
/// `(exp([v]×), J_l(v) e_x, J_l(v) e_y)` for `v = (sx, sy, 0)`.
///
/// With θ = |v|, a = (1 − cos θ)/θ², b = (θ − sin θ)/θ³ (series near 0):
/// `J_l e_x = (1 − b sy², b sx sy, −a sy)` and `J_l e_y = (b sx sy, 1 − b sx², a sx)`,
/// the columns of [`left_jacobian`] written out. Used by the fused FK + Jacobian pass.
#[inline]
pub fn swing_with_jacobian(sx: f64, sy: f64) -> (Matrix3<f64>, Vector3<f64>, Vector3<f64>) {
    swing_with_jacobian_with(sx, sy, crate::trig::sin_cos)
}

/// [`swing_with_jacobian`] with θ's sine and cosine from `sin_cos(θ)` (a memo of them: the
/// same values, the same bits); not called near zero, where the series needs neither.
#[inline]
pub(crate) fn swing_with_jacobian_with(
    sx: f64,
    sy: f64,
    sin_cos: impl FnOnce(f64) -> (f64, f64),
) -> (Matrix3<f64>, Vector3<f64>, Vector3<f64>) {
    let t2 = swing_angle_squared(sx, sy);
    // sin θ / θ, (1 − cos θ)/θ², cos θ, (θ − sin θ)/θ³.
    let (s, a, c, b) = if t2 < 1e-4 {
        (
            1.0 - t2 / 6.0 + t2 * t2 / 120.0,
            0.5 - t2 / 24.0 + t2 * t2 / 720.0,
            1.0 - t2 / 2.0 + t2 * t2 / 24.0,
            1.0 / 6.0 - t2 / 120.0 + t2 * t2 / 5040.0,
        )
    } else {
        let t = t2.sqrt();
        let (sn, cs) = sin_cos(t);
        (sn / t, (1.0 - cs) / t2, cs, (t - sn) / (t2 * t))
    };
    let r = Matrix3::new(
        1.0 - a * sy * sy,
        a * sx * sy,
        s * sy,
        a * sx * sy,
        1.0 - a * sx * sx,
        -s * sx,
        -s * sy,
        s * sx,
        c,
    );
    let jx = Vector3::new(1.0 - b * sy * sy, b * sx * sy, -a * sy);
    let jy = Vector3::new(b * sx * sy, 1.0 - b * sx * sx, a * sx);
    (r, jx, jy)
}

/// The swing vector `(sx, sy)` and twist angle `τ` with `R = swing(sx, sy) · R_z(τ)`.
///
/// The swing takes the z axis to R·z by the shortest arc; the twist is what remains about z.
/// Undefined (returns the swing of angle π about x) when R·z = −z.
pub fn swing_twist(r: &Rotation3<f64>) -> (f64, f64, f64) {
    let z = r * Vector3::z();
    let (sx, sy) = swing_to(&z);
    let swing = swing_rotation(sx, sy);
    let twist = swing.inverse() * r;
    let m = twist.matrix();
    let tau = m[(1, 0)].atan2(m[(0, 0)]);
    (sx, sy, tau)
}

/// The swing vector `(sx, sy)` whose rotation takes `+z` to the unit direction `d` by the
/// shortest arc.
pub fn swing_to(d: &Vector3<f64>) -> (f64, f64) {
    let d = d.normalize();
    let axis = Vector3::z().cross(&d); // = (-d.y, d.x, 0)
    let s = axis.norm();
    let angle = s.atan2(d.z);
    if s < 1e-12 {
        if d.z > 0.0 {
            (0.0, 0.0)
        } else {
            (std::f64::consts::PI, 0.0)
        }
    } else {
        (axis.x / s * angle, axis.y / s * angle)
    }
}

/// The left Jacobian of SO(3) at `v`: `d/dt exp([v]×) = [J_l(v) v̇]× exp([v]×)`.
///
/// `J_l(v) = I + (1 − cos θ)/θ² [v]× + (θ − sin θ)/θ³ [v]×²` with θ = |v| (series near 0).
pub fn left_jacobian(v: &Vector3<f64>) -> Matrix3<f64> {
    let t2 = v.norm_squared();
    let k = v.cross_matrix();
    let (a, b) = if t2 < 1e-8 {
        (0.5 - t2 / 24.0, 1.0 / 6.0 - t2 / 120.0)
    } else {
        let t = t2.sqrt();
        ((1.0 - t.cos()) / t2, (t - t.sin()) / (t2 * t))
    };
    Matrix3::identity() + k * a + k * k * b
}

/// Spherical interpolation between two rotations, `t ∈ [0, 1]`, the short way round.
pub fn slerp(a: &Rotation3<f64>, b: &Rotation3<f64>, t: f64) -> Rotation3<f64> {
    let qa = UnitQuaternion::from_rotation_matrix(a);
    let qb = UnitQuaternion::from_rotation_matrix(b);
    // nalgebra's slerp takes the shortest path; it fails only for opposite quaternions,
    // which the sign flip below rules out.
    let qb = if qa.coords.dot(&qb.coords) < 0.0 {
        UnitQuaternion::new_unchecked(-qb.into_inner())
    } else {
        qb
    };
    qa.try_slerp(&qb, t, 1e-12)
        .unwrap_or_else(|| qa.nlerp(&qb, t))
        .to_rotation_matrix()
}

/// `angle` moved by a multiple of 2π to lie within π of `reference`.
pub fn unwrap_near(angle: f64, reference: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    angle - ((angle - reference) / tau).round() * tau
}

/// Of the two Tait–Bryan solutions (α, β, γ) and (α + π, π − β, γ + π) of one rotation
/// (from [`euler_angles`]), each unwrapped toward `near` ([`unwrap_near`]), the one closest
/// to `near` (least squared distance); `angles` as given when neither compares (NaN).
/// Frame to frame, this keeps Euler angles from jumping by 2π or flipping solution.
pub fn nearest_euler(angles: [f64; 3], near: [f64; 3]) -> [f64; 3] {
    use std::f64::consts::PI;
    let [a, b, c] = angles;
    let mut best = angles;
    let mut best_d = f64::INFINITY;
    for cand in [[a, b, c], [a + PI, PI - b, c + PI]] {
        let un = [0, 1, 2].map(|i| unwrap_near(cand[i], near[i]));
        let d: f64 = un.iter().zip(&near).map(|(x, y)| (x - y).powi(2)).sum();
        if d < best_d {
            best_d = d;
            best = un;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    const ORDERS: [[Axis; 3]; 6] = [
        [Axis::X, Axis::Y, Axis::Z],
        [Axis::X, Axis::Z, Axis::Y],
        [Axis::Y, Axis::X, Axis::Z],
        [Axis::Y, Axis::Z, Axis::X],
        [Axis::Z, Axis::X, Axis::Y],
        [Axis::Z, Axis::Y, Axis::X],
    ];

    #[test]
    fn nearest_euler_takes_the_solution_and_turn_closest_to_the_previous_frame() {
        use std::f64::consts::{PI, TAU};
        let order = [Axis::Y, Axis::X, Axis::Z];
        let angles = [0.1, 0.2, 0.3];
        // Near the other solution, two turns away: that one, unwrapped.
        let flipped = [0.1 + PI + 2.0 * TAU, PI - 0.2, 0.3 + PI - TAU];
        let near = nearest_euler(angles, [flipped[0] + 0.01, flipped[1], flipped[2]]);
        for (a, b) in near.iter().zip(&flipped) {
            assert_relative_eq!(a, b, epsilon = 1e-12);
        }
        let same = euler_rotation(&order, &near).inverse() * euler_rotation(&order, &angles);
        assert_relative_eq!(same.angle(), 0.0, epsilon = 1e-12);
        assert_eq!(nearest_euler(angles, angles), angles);
    }

    #[test]
    fn axis_rotation_matches_nalgebra() {
        for axis in [Axis::X, Axis::Y, Axis::Z] {
            let ours = axis_rotation(axis, 0.7);
            let theirs = Rotation3::from_axis_angle(&axis.unit(), 0.7);
            assert_relative_eq!(ours, theirs, epsilon = 1e-15);
        }
    }

    #[test]
    fn gimbal_lock_still_round_trips() {
        for order in ORDERS {
            let angles = [0.3, std::f64::consts::FRAC_PI_2, -0.4];
            let r = euler_rotation(&order, &angles);
            let back = euler_angles(order, &r).expect("distinct axes");
            assert_relative_eq!(euler_rotation(&order, &back), r, epsilon = 1e-9);
        }
    }

    /// A rotation at (or within 10⁻⁶ rad of) gimbal lock carrying rounding noise, as one
    /// composed from other rotations is: the angles give back the rotation within 10⁻⁷
    /// (the trap: sin θ1 one ulp below 1 gives |cos θ1| = 3·10⁻⁸, and θ0, θ2 taken from it are
    /// noise).
    #[test]
    fn near_gimbal_lock_with_rounding_noise_still_round_trips() {
        let turn = Rotation3::from_euler_angles(0.7, -1.1, 2.3);
        let mut worst: f64 = 0.0;
        for order in ORDERS {
            for d in [0.0, 1e-12, 1e-9, 1e-8, 1e-7, 1e-6] {
                for (a, c) in [(0.3, -0.4), (2.0, -1.0), (-2.5, 2.9), (0.6, 0.0)] {
                    let exact = euler_rotation(&order, &[a, std::f64::consts::FRAC_PI_2 - d, c]);
                    let noisy = turn.inverse() * (turn * exact);
                    let back = euler_angles(order, &noisy).expect("distinct axes");
                    let again = euler_rotation(&order, &back);
                    let err = (again.matrix() - noisy.matrix()).norm();
                    worst = worst.max(err);
                }
            }
        }
        assert!(worst < 1e-7, "worst {worst:e}");
    }

    proptest! {
        #[test]
        fn swing_rotation_matches_the_exponential_map(sx in -3.0f64..3.0, sy in -3.0f64..3.0, tiny in -1e-7f64..1e-7) {
            assert_relative_eq!(swing_rotation(sx, sy), Rotation3::new(Vector3::new(sx, sy, 0.0)), epsilon = 1e-14);
            assert_relative_eq!(swing_rotation(tiny, -tiny), Rotation3::new(Vector3::new(tiny, -tiny, 0.0)), epsilon = 1e-15);
        }

        #[test]
        fn fused_swing_matches_rotation_and_left_jacobian(sx in -2.5f64..2.5, sy in -2.5f64..2.5, tiny in -1e-3f64..1e-3) {
            for (x, y) in [(sx, sy), (tiny, -0.5 * tiny), (0.0, 0.0)] {
                let (r, jx, jy) = swing_with_jacobian(x, y);
                assert_relative_eq!(r, *swing_rotation(x, y).matrix(), epsilon = 1e-14);
                let jl = left_jacobian(&Vector3::new(x, y, 0.0));
                assert_relative_eq!(jx, jl.column(0).into_owned(), epsilon = 1e-12);
                assert_relative_eq!(jy, jl.column(1).into_owned(), epsilon = 1e-12);
            }
        }

        #[test]
        fn euler_round_trip(order in 0usize..6, a in -3.1f64..3.1, b in -1.5f64..1.5, c in -3.1f64..3.1) {
            let order = ORDERS[order];
            let r = euler_rotation(&order, &[a, b, c]);
            let back = euler_angles(order, &r).expect("distinct axes");
            assert_relative_eq!(back[0], a, epsilon = 1e-9);
            assert_relative_eq!(back[1], b, epsilon = 1e-9);
            assert_relative_eq!(back[2], c, epsilon = 1e-9);
        }

        #[test]
        fn swing_twist_round_trip(sx in -2.0f64..2.0, sy in -2.0f64..2.0, tau in -3.1f64..3.1) {
            prop_assume!((sx * sx + sy * sy).sqrt() < 3.0);
            let r = swing_rotation(sx, sy) * axis_rotation(Axis::Z, tau);
            let (bx, by, bt) = swing_twist(&r);
            assert_relative_eq!(bx, sx, epsilon = 1e-9);
            assert_relative_eq!(by, sy, epsilon = 1e-9);
            assert_relative_eq!(bt, tau, epsilon = 1e-9);
        }

        #[test]
        fn left_jacobian_matches_finite_differences(
            x in -2.5f64..2.5, y in -2.5f64..2.5, z in -2.5f64..2.5,
            dx in -1.0f64..1.0, dy in -1.0f64..1.0, dz in -1.0f64..1.0,
        ) {
            let v = Vector3::new(x, y, z) * 0.5;
            let dv = Vector3::new(dx, dy, dz);
            let h = 1e-6;
            let r = Rotation3::new(v);
            let rp = Rotation3::new(v + dv * h);
            let rm = Rotation3::new(v - dv * h);
            // (R(v+h dv) - R(v-h dv)) / 2h · Rᵀ = [ω]×
            let w = (rp.matrix() - rm.matrix()) / (2.0 * h) * r.matrix().transpose();
            let omega = Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)]);
            assert_relative_eq!(left_jacobian(&v) * dv, omega, epsilon = 1e-6);
        }
    }
}
