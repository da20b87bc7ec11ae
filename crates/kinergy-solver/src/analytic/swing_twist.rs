//! The swing–twist math the solver runs on: the decomposition `R = swing(sx, sy) · R_z(τ)`
//! from two columns of `R` ([`swing_twist_of_columns`], the same answer as
//! [`swing_twist`] with two `atan2` and no `sin_cos`), a faster [`atan2`], and [`wrap`]
//! moving an angle by 2π toward the middle of its limits.

use kinergy_motion::nalgebra::{Matrix3, Rotation3, Vector3};
use kinergy_motion::rotation::{swing_twist, unwrap_near};

/// [`swing_twist`] of a rotation matrix, from its columns x and z.
#[inline]
pub(super) fn fast_swing_twist(r: &Matrix3<f64>) -> (f64, f64, f64) {
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
pub(super) fn swing_twist_of_columns(rx: &Vector3<f64>, d: &Vector3<f64>) -> (f64, f64, f64) {
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
pub(super) fn atan2(y: f64, x: f64) -> f64 {
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
pub(super) fn wrap(angle: f64, middle: f64) -> f64 {
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

#[cfg(test)]
mod tests {
    use super::*;
    use kinergy_motion::rotation::{Axis, axis_rotation, swing_rotation};

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
}
