//! Sines and cosines that are the same bits one angle at a time and many in lanes, on every
//! CPU: the trigonometry of the chain's walks ([`crate::Chain`]'s forward kinematics and
//! Jacobian, the rotations of [`crate::rotation`]).
//!
//! The platform's `sin_cos` (libm) is not the same function everywhere: glibc picks an FMA
//! or an SSE2 build at run time, macOS and Windows have their own, and none of them computes
//! several angles at once. These are:
//! - **the same bits on every CPU and platform** for |x| ≤ [`REDUCED_UP_TO`]: only IEEE
//!   additions, multiplications and bit operations, in a fixed order (no fused
//!   multiply-add, no tables, no branch that depends on the angle), so the chain's
//!   kinematics are the same bits wherever they run (a fit's other elementary functions,
//!   such as the sigmoid's `exp`, are still the platform's);
//! - **the same bits in lanes**: [`sin_cos_lanes`] runs the same operations on up to `N`
//!   angles in plain loops that the compiler turns into SIMD (two f64 a register on the
//!   x86-64 baseline, four with AVX2). A configuration's seven angles cost about half of
//!   seven calls of libm's `sincos`;
//! - **accurate**: within one unit in the last place of glibc's result, and the same bits
//!   for about 94 % of angles (this module's tests: 4 million angles up to ±10⁶ rad).
//!
//! The method is fdlibm's: x = k·π/2 + r with k the nearest integer to 2x/π (by adding and
//! subtracting 1.5·2⁵², so that k's two low bits are the quadrant); r = x − k·π/2 as a sum
//! hi + lo, by π/2 in parts whose products with k are exact for |k| < 2²⁰ (fdlibm's second
//! reduction step); then the minimax polynomials of fdlibm's `__kernel_sin` and
//! `__kernel_cos` on |r| ≤ π/4 with the tail lo; and the quadrant picks
//! and signs the two. Beyond [`REDUCED_UP_TO`] (never a joint angle) and for a
//! non-finite x, the result is the platform's `sin_cos`.

/// The largest |x| (radians) reduced here: 2²⁰ (π/2's parts then multiply by k exactly).
/// Beyond it, and for non-finite x, [`sin_cos`] is the platform's.
pub const REDUCED_UP_TO: f64 = 1_048_576.0;

/// π/2's first two parts of 33 significant bits (fdlibm's `pio2_1`, `pio2_2`). Every constant
/// here is fdlibm's, by its bits (its decimal beside).
const PIO2_1: f64 = f64::from_bits(0x3ff921fb54400000); // 1.57079632673412561417e0
const PIO2_2: f64 = f64::from_bits(0x3dd0b4611a600000); // 6.0771005063039659766e-11
/// What π/2 − `PIO2_1` − `PIO2_2` leaves (fdlibm's `pio2_2t`).
const PIO2_2T: f64 = f64::from_bits(0x3ba3198a2e037073); // 2.02226624879595063154e-21
/// 1.5·2⁵²: x + this rounds x to an integer held in the low bits of the sum.
const ROUND: f64 = 6_755_399_441_055_744.0;
/// sin r ≈ r + r³ (S1 + r² S2 + … + r¹⁰ S6) on |r| ≤ π/4 (fdlibm's `__kernel_sin`).
const S1: f64 = f64::from_bits(0xbfc5555555555549); // -1.66666666666666324348e-1
const S2: f64 = f64::from_bits(0x3f8111111110f8a6); // 8.33333333332248946124e-3
const S3: f64 = f64::from_bits(0xbf2a01a019c161d5); // -1.98412698298579493134e-4
const S4: f64 = f64::from_bits(0x3ec71de357b1fe7d); // 2.75573137070700676789e-6
const S5: f64 = f64::from_bits(0xbe5ae5e68a2b9ceb); // -2.50507602534068634195e-8
const S6: f64 = f64::from_bits(0x3de5d93a5acfd57c); // 1.58969099521155010221e-10
/// cos r ≈ 1 − r²/2 + r⁴ (C1 + r² C2 + … + r¹⁰ C6) on |r| ≤ π/4 (fdlibm's `__kernel_cos`).
const C1: f64 = f64::from_bits(0x3fa555555555554c); // 4.16666666666666019037e-2
const C2: f64 = f64::from_bits(0xbf56c16c16c15177); // -1.38888888888741095749e-3
const C3: f64 = f64::from_bits(0x3efa01a019cb1590); // 2.48015872894767294178e-5
const C4: f64 = f64::from_bits(0xbe927e4f809c52ad); // -2.75573143513906633035e-7
const C5: f64 = f64::from_bits(0x3e21ee9ebdb4b1c4); // 2.0875723212981748279e-9
const C6: f64 = f64::from_bits(0xbda8fae9be8838d4); // -1.13596475577881948265e-11

/// `(sin x, cos x)`: the same bits as [`sin_cos_lanes`] gives in any lane.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if reduces(x) { reduced(x) } else { x.sin_cos() }
}

/// `(sin xᵢ, cos xᵢ)` of `N` angles at once, each lane the bits [`sin_cos`] gives. On an
/// x86-64 CPU with AVX2 the lanes run four to a register (found at run time; the same
/// additions and multiplications, so the same bits), else two (SSE2).
#[multiversion::multiversion(targets("x86_64+avx2"))]
pub fn sin_cos_lanes<const N: usize>(x: &[f64; N]) -> ([f64; N], [f64; N]) {
    let (mut s, mut c) = ([0.0; N], [0.0; N]);
    // One branch-free loop (the compiler's SIMD), then the rare lanes beyond the reduction.
    for i in 0..N {
        (s[i], c[i]) = reduced(x[i]);
    }
    for i in 0..N {
        if !reduces(x[i]) {
            (s[i], c[i]) = x[i].sin_cos();
        }
    }
    (s, c)
}

/// True when [`reduced`] computes x's sine and cosine: |x| ≤ [`REDUCED_UP_TO`] (false for NaN).
#[inline(always)]
fn reduces(x: f64) -> bool {
    x.abs() <= REDUCED_UP_TO
}

/// The reduction and the kernels, branch-free, for |x| ≤ [`REDUCED_UP_TO`].
#[inline(always)]
fn reduced(x: f64) -> (f64, f64) {
    let rounded = x * std::f64::consts::FRAC_2_PI + ROUND;
    let quadrant = rounded.to_bits();
    let k = rounded - ROUND;
    // r = x − k·π/2 as hi + lo (fdlibm's second reduction step: π/2 to 119 bits).
    let exact = x - k * PIO2_1;
    let part = k * PIO2_2;
    let r = exact - part;
    let w = k * PIO2_2T - ((exact - r) - part);
    let hi = r - w;
    let lo = (r - hi) - w;
    let z = hi * hi;
    // sin(hi + lo) (fdlibm's `__kernel_sin` with its tail).
    let v = z * hi;
    let p = S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)));
    let sin = hi - ((z * (0.5 * lo - v * p) - lo) - v * S1);
    // cos(hi + lo) (fdlibm's `__kernel_cos`).
    let w = z * z;
    let q = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    let half = 0.5 * z;
    let rest = 1.0 - half;
    let cos = rest + (((1.0 - rest) - half) + (z * q - hi * lo));
    // Quadrant q = k mod 4 (the sum's low bits): sin x = ±sin r or ±cos r.
    let swap = (quadrant & 1).wrapping_neg();
    let (sb, cb) = (sin.to_bits(), cos.to_bits());
    let s = (sb & !swap) | (cb & swap);
    let c = (cb & !swap) | (sb & swap);
    let sin_sign = (quadrant & 2) << 62;
    let cos_sign = (quadrant.wrapping_add(1) & 2) << 62;
    (f64::from_bits(s ^ sin_sign), f64::from_bits(c ^ cos_sign))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Units in the last place between two finite doubles of the same sign (or zeros).
    fn ulps(a: f64, b: f64) -> u64 {
        if a == b {
            return 0;
        }
        let key = |v: f64| {
            let bits = v.to_bits() as i64;
            if bits < 0 { i64::MIN - bits } else { bits }
        };
        key(a).abs_diff(key(b))
    }

    /// A reproducible stream of doubles in [0, 1) (xorshift64).
    fn stream(mut state: u64) -> impl FnMut() -> f64 {
        move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        }
    }

    #[test]
    fn within_one_unit_in_the_last_place_of_libm() {
        let mut next = stream(45);
        let (mut worst, mut differ) = (0, 0);
        for i in 0..4_000_000 {
            let span = [8.0, 200.0, 2e6][i % 3];
            let x = (next() - 0.5) * span;
            let (s, c) = sin_cos(x);
            let (ls, lc) = x.sin_cos();
            let u = ulps(s, ls).max(ulps(c, lc));
            worst = worst.max(u);
            differ += usize::from(u > 0);
        }
        assert!(worst <= 1, "{worst} ulps");
        // The same bits as libm's for nearly every angle (about 6 % differ).
        assert!(differ < 400_000, "{differ} of 4,000,000 differ");
    }

    #[test]
    fn known_values_and_symmetries() {
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        let (s, c) = sin_cos(std::f64::consts::FRAC_PI_6);
        assert!(ulps(s, 0.5) <= 1 && ulps(c, 3f64.sqrt() / 2.0) <= 1);
        let (s, c) = sin_cos(std::f64::consts::FRAC_PI_2);
        assert!(ulps(s, 1.0) <= 1 && (c - 6.123_233_995_736_766e-17).abs() < 1e-30);
        let (s, c) = sin_cos(std::f64::consts::PI);
        assert!((s - 1.224_646_799_147_353_2e-16).abs() < 1e-30 && c == -1.0);
        let mut next = stream(7);
        for _ in 0..100_000 {
            let x = (next() - 0.5) * 50.0;
            let (s, c) = sin_cos(x);
            let (ns, nc) = sin_cos(-x);
            assert_eq!((ns.to_bits(), nc.to_bits()), ((-s).to_bits(), c.to_bits()));
            assert!((s * s + c * c - 1.0).abs() <= 4.0 * f64::EPSILON, "{x}");
        }
    }

    #[test]
    fn lanes_are_the_scalar_bits() {
        let mut next = stream(3);
        for _ in 0..20_000 {
            let mut x = [0.0; 8];
            for v in &mut x {
                *v = (next() - 0.5) * 20.0;
            }
            let (s, c) = sin_cos_lanes(&x);
            for i in 0..8 {
                let (ss, cs) = sin_cos(x[i]);
                assert_eq!(
                    (s[i].to_bits(), c[i].to_bits()),
                    (ss.to_bits(), cs.to_bits())
                );
            }
            let (s3, c3) = sin_cos_lanes(&[x[0], x[1], x[2]]);
            assert_eq!(
                (s3[2].to_bits(), c3[2].to_bits()),
                (s[2].to_bits(), c[2].to_bits())
            );
        }
    }

    #[test]
    fn beyond_the_reduction_and_non_finite_angles_are_the_platforms() {
        for x in [3e6, -1e12, f64::MAX] {
            assert_eq!(sin_cos(x), x.sin_cos());
            let (s, c) = sin_cos_lanes(&[0.5, x]);
            assert_eq!((s[1], c[1]), x.sin_cos());
            assert_eq!((s[0], c[0]), sin_cos(0.5));
        }
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let (s, c) = sin_cos(x);
            assert!(s.is_nan() && c.is_nan());
            let (s, c) = sin_cos_lanes(&[x, 1.0]);
            assert!(s[0].is_nan() && c[0].is_nan() && s[1] == sin_cos(1.0).0);
        }
    }
}
