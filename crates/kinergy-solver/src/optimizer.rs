//! The IK optimizers O of Aubry et al. (2009) §3.1: each turns the task error ΔX into a joint
//! step Δθ for one frame of the synthesized motion.
//!
//! Rates are per second and multiplied by the frame time, so a motion synthesized at 30 Hz
//! and at 120 Hz follows (to first order) the same path in the same time. The paper's
//! per-iteration λ is `rate · frame_time`.
//!
//! | optimizer | step |
//! |---|---|
//! | [`Transpose`] (`jt`) | Δθ = rate·dt · Jᵀ ΔX |
//! | [`NormalizedTranspose`] (`njt`) | Δθ = min(speed·dt, s*) · Jᵀ ΔX / ‖Jᵀ ΔX‖₂ |
//! | [`PseudoInverse`] (`svd`) | Δθ = rate·dt · J⁺ ΔX, singular values < threshold dropped |
//! | [`DampedLeastSquares`] (`dls`) | Δθ = rate·dt · Jᵀ (J Jᵀ + μ² I)⁻¹ ΔX |
//!
//! For a position task J is 3 × n and everything goes through the 3 × 3 matrix J Jᵀ: the
//! Moore–Penrose pseudo-inverse is J⁺ = Jᵀ (J Jᵀ)⁺, exact, with (J Jᵀ)⁺ from its
//! eigen-decomposition (eigenvalues are the squared singular values of J). When the
//! smallest eigenvalue is provably above threshold² (det / trace² bounds it from below) the
//! inverse is the adjugate over the determinant, with no decomposition at all.
//! A position + orientation task stacks the weighted angular rows under J (6 × n) and uses
//! the 6 × 6 Gram matrix's symmetric eigen-decomposition. (nalgebra's `svd(true, true)` is
//! avoided: it returns wrong singular values on some inputs, dimforge/nalgebra#1172.)
//!
//! Near full extension the radial direction of J vanishes; the controller then hands the
//! distance to the elbow by the law of cosines ([`crate::reachability`]) and gives these
//! formulas the rest of the error.

use std::fmt;
use std::str::FromStr;

use kinergy_io::InvalidSetting;
use kinergy_motion::Linearization;
use kinergy_motion::nalgebra::{DMatrix, DVector, Matrix3, SymmetricEigen, Vector3};
use serde::{Deserialize, Serialize};

use crate::error::{Result, SolverError};
use crate::task::TaskError;

/// `jt`: the Jacobian transpose, Δθ = rate·dt · Jᵀ ΔX.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Transpose {
    /// λ per second, in rad/(m²·s): the joint velocity per unit of Jᵀ ΔX.
    pub rate: f64,
}

/// `njt`: the normalized Jacobian transpose. The direction is Jᵀ ΔX; the step's Euclidean
/// norm in joint space (radians, all DoFs together) is `speed · dt`, capped at the exact
/// line minimum s* = (J d · ΔX) / ‖J d‖² along that direction d so the hand never
/// overshoots the target (without the cap a fixed-length step chatters around it).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct NormalizedTranspose {
    /// Joint-space speed, rad/s (Euclidean norm over the DoFs).
    pub speed: f64,
}

/// `svd`: the exact Moore–Penrose pseudo-inverse, Δθ = rate·dt · J⁺ ΔX, with singular
/// values below `threshold` dropped (rank-deficient Jacobians give the minimum-norm step
/// in the remaining directions).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PseudoInverse {
    /// Fraction of the error closed per second, 1/s.
    pub rate: f64,
    /// Singular values below this are treated as zero, m/rad.
    pub threshold: f64,
}

/// `dls`: damped least squares, Δθ = rate·dt · Jᵀ (J Jᵀ + μ² I)⁻¹ ΔX (Wampler 1986; Buss
/// 2004): the pseudo-inverse far from singularities, bounded steps near them.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DampedLeastSquares {
    /// Fraction of the error closed per second, 1/s.
    pub rate: f64,
    /// Damping μ, m/rad.
    pub damping: f64,
}

impl Default for Transpose {
    fn default() -> Transpose {
        Transpose { rate: 20.0 }
    }
}

impl Default for NormalizedTranspose {
    fn default() -> NormalizedTranspose {
        NormalizedTranspose { speed: 2.0 }
    }
}

impl Default for PseudoInverse {
    fn default() -> PseudoInverse {
        PseudoInverse {
            rate: 4.0,
            threshold: 1e-2,
        }
    }
}

impl Default for DampedLeastSquares {
    fn default() -> DampedLeastSquares {
        DampedLeastSquares {
            rate: 4.0,
            damping: 0.05,
        }
    }
}

/// Which optimizer, without its settings: `jt`, `njt`, `svd`, `dls`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum OptimizerKind {
    /// [`Transpose`].
    Jt,
    /// [`NormalizedTranspose`].
    Njt,
    /// [`PseudoInverse`].
    Svd,
    /// [`DampedLeastSquares`].
    Dls,
}

impl OptimizerKind {
    /// Every kind, in the paper's order then ours.
    pub const ALL: [OptimizerKind; 4] = [
        OptimizerKind::Jt,
        OptimizerKind::Njt,
        OptimizerKind::Svd,
        OptimizerKind::Dls,
    ];

    /// `jt`, `njt`, `svd` or `dls`.
    pub fn name(self) -> &'static str {
        match self {
            OptimizerKind::Jt => "jt",
            OptimizerKind::Njt => "njt",
            OptimizerKind::Svd => "svd",
            OptimizerKind::Dls => "dls",
        }
    }

    /// The optimizer of this kind with its default settings.
    pub fn default_optimizer(self) -> Optimizer {
        match self {
            OptimizerKind::Jt => Optimizer::Jt(Transpose::default()),
            OptimizerKind::Njt => Optimizer::Njt(NormalizedTranspose::default()),
            OptimizerKind::Svd => Optimizer::Svd(PseudoInverse::default()),
            OptimizerKind::Dls => Optimizer::Dls(DampedLeastSquares::default()),
        }
    }
}

impl fmt::Display for OptimizerKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for OptimizerKind {
    type Err = SolverError;

    fn from_str(s: &str) -> Result<OptimizerKind> {
        OptimizerKind::ALL
            .into_iter()
            .find(|k| k.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| {
                SolverError::Setting(InvalidSetting::new(
                    "optimizer",
                    format!("`{s}` is not one of jt, njt, svd, dls"),
                ))
            })
    }
}

/// An optimizer with its settings. Serialized as `{"kind": "svd", "rate": 4.0, …}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Optimizer {
    /// Jacobian transpose.
    Jt(Transpose),
    /// Normalized Jacobian transpose.
    Njt(NormalizedTranspose),
    /// SVD pseudo-inverse.
    Svd(PseudoInverse),
    /// Damped least squares.
    Dls(DampedLeastSquares),
}

impl Default for Optimizer {
    fn default() -> Optimizer {
        Optimizer::Svd(PseudoInverse::default())
    }
}

/// Scratch space for [`Optimizer::step`], reused between frames so stepping never
/// allocates for position tasks.
#[derive(Debug, Clone, Default)]
pub struct StepScratch {
    stacked: Option<DMatrix<f64>>,
    /// The plain optimizer's step of the frame (before the synergy), for the smooth
    /// controller's progress floor and finish.
    pub(crate) raw: Vec<f64>,
}

/// A pose task's error with its orientation part present, as [`Optimizer::step`] stacks it:
/// ΔX (meters), Δr (a world rotation vector, radians) and the meters per radian that put Δr
/// on ΔX's scale. Borrowed from the [`TaskError`], so handing it on copies nothing.
#[derive(Debug, Clone, Copy)]
struct PoseError<'a> {
    linear: &'a Vector3<f64>,
    angular: &'a Vector3<f64>,
    weight: f64,
}

impl Optimizer {
    /// Which optimizer this is.
    pub fn kind(&self) -> OptimizerKind {
        match self {
            Optimizer::Jt(_) => OptimizerKind::Jt,
            Optimizer::Njt(_) => OptimizerKind::Njt,
            Optimizer::Svd(_) => OptimizerKind::Svd,
            Optimizer::Dls(_) => OptimizerKind::Dls,
        }
    }

    /// Checks that every setting is finite and in range, naming the field otherwise.
    pub fn validate(&self) -> Result<()> {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        match *self {
            Optimizer::Jt(o) => {
                InvalidSetting::require(positive(o.rate), "optimizer.rate", "a positive number")?
            }
            Optimizer::Njt(o) => {
                InvalidSetting::require(positive(o.speed), "optimizer.speed", "a positive number")?
            }
            Optimizer::Svd(o) => {
                InvalidSetting::require(positive(o.rate), "optimizer.rate", "a positive number")?;
                InvalidSetting::require(
                    positive(o.threshold),
                    "optimizer.threshold",
                    "a positive number (m/rad)",
                )?
            }
            Optimizer::Dls(o) => {
                InvalidSetting::require(positive(o.rate), "optimizer.rate", "a positive number")?;
                InvalidSetting::require(
                    positive(o.damping),
                    "optimizer.damping",
                    "a positive number (m/rad)",
                )?
            }
        }
        Ok(())
    }

    /// The joint step for one frame of duration `dt` into `out` (one value per DoF), from
    /// the chain's linearization and the task error.
    pub fn step(
        &self,
        lin: &Linearization,
        error: &TaskError,
        dt: f64,
        scratch: &mut StepScratch,
        out: &mut [f64],
    ) {
        match error.angular {
            None => self.step_position(lin, &error.linear, dt, out),
            Some(angular) => self.step_pose(
                lin,
                PoseError {
                    linear: &error.linear,
                    angular: &angular,
                    weight: error.weight,
                },
                dt,
                scratch,
                out,
            ),
        }
    }

    fn step_position(&self, lin: &Linearization, dx: &Vector3<f64>, dt: f64, out: &mut [f64]) {
        let j = &lin.linear;
        match *self {
            Optimizer::Jt(o) => transpose_into(j, dx, o.rate * dt, out),
            Optimizer::Njt(o) => {
                // d = Jᵀ ΔX / ‖Jᵀ ΔX‖; J d · ΔX = ‖Jᵀ ΔX‖.
                transpose_into(j, dx, 1.0, out);
                let norm = norm(out);
                if norm <= f64::MIN_POSITIVE {
                    out.fill(0.0);
                    return;
                }
                let jd = mul_into(j, out) / norm;
                let line_min = norm / jd.norm_squared().max(f64::MIN_POSITIVE);
                let s = (o.speed * dt).min(line_min);
                out.iter_mut().for_each(|v| *v *= s / norm);
            }
            Optimizer::Svd(o) => {
                let y = pseudo_inverse_3(&gram(j), dx, o.threshold);
                transpose_into(j, &y, o.rate * dt, out);
            }
            Optimizer::Dls(o) => {
                let damped = gram(j) + Matrix3::identity() * (o.damping * o.damping);
                // Positive definite: the adjugate inverse is exact and well conditioned
                // (its smallest eigenvalue is at least μ²).
                let y = adjugate_solve(&damped, dx).unwrap_or_else(Vector3::zeros);
                transpose_into(j, &y, o.rate * dt, out);
            }
        }
    }

    /// The optimizer's step for a single DoF whose Jacobian column c has squared norm
    /// `column_sq` and which should move by `gap` radians (ΔX = c·gap): exactly what
    /// [`Optimizer::step`] gives on that one-column problem — JT rate·dt·|c|²·gap, NJT
    /// min(speed·dt, |gap|) toward the gap (the line minimum is the gap itself), SVD
    /// rate·dt·gap (0 when |c| is below the threshold), DLS rate·dt·|c|²/(|c|² + μ²)·gap.
    /// The controller moves the elbow and wrist by it near the reach sphere's edge
    /// ([`crate::reachability`]), so they keep the optimizer's pace.
    pub(crate) fn drive_step(&self, column_sq: f64, gap: f64, dt: f64) -> f64 {
        match *self {
            Optimizer::Jt(o) => o.rate * dt * column_sq * gap,
            Optimizer::Njt(o) => gap.signum() * (o.speed * dt).min(gap.abs()),
            Optimizer::Svd(o) => {
                if column_sq >= o.threshold * o.threshold {
                    o.rate * dt * gap
                } else {
                    0.0
                }
            }
            Optimizer::Dls(o) => {
                o.rate * dt * column_sq / (column_sq + o.damping * o.damping) * gap
            }
        }
    }

    fn step_pose(
        &self,
        lin: &Linearization,
        error: PoseError<'_>,
        dt: f64,
        scratch: &mut StepScratch,
        out: &mut [f64],
    ) {
        let PoseError {
            linear: dx,
            angular: dr,
            weight,
        } = error;
        let n = lin.linear.ncols();
        let stacked = scratch.stacked.get_or_insert_with(|| DMatrix::zeros(6, n));
        if stacked.ncols() != n {
            *stacked = DMatrix::zeros(6, n);
        }
        stacked.rows_mut(0, 3).copy_from(&lin.linear);
        stacked
            .rows_mut(3, 3)
            .copy_from(&(lin.angular.clone() * weight));
        let e = DVector::from_iterator(6, dx.iter().copied().chain(dr.iter().map(|v| v * weight)));
        let step: DVector<f64> = match *self {
            Optimizer::Jt(o) => stacked.transpose() * e * (o.rate * dt),
            Optimizer::Njt(o) => {
                let u = stacked.transpose() * &e;
                let norm = u.norm();
                if norm <= f64::MIN_POSITIVE {
                    DVector::zeros(n)
                } else {
                    let jd = &*stacked * &u / norm;
                    let s = (o.speed * dt).min(norm / jd.norm_squared().max(f64::MIN_POSITIVE));
                    u * (s / norm)
                }
            }
            Optimizer::Svd(o) => {
                // Jᵀ (J Jᵀ)⁺ e through the symmetric eigen-decomposition of the 6 × 6 Gram
                // matrix (not nalgebra's `svd(true, true)`, which returns wrong singular
                // values on some inputs: dimforge/nalgebra#1172).
                let g = &*stacked * stacked.transpose();
                let eig = g.symmetric_eigen();
                let t2 = o.threshold * o.threshold;
                let mut y = DVector::zeros(6);
                for (i, &l) in eig.eigenvalues.iter().enumerate() {
                    if l >= t2 {
                        let v = eig.eigenvectors.column(i);
                        y += v * (v.dot(&e) / l);
                    }
                }
                stacked.transpose() * y * (o.rate * dt)
            }
            Optimizer::Dls(o) => {
                let g = &*stacked * stacked.transpose()
                    + DMatrix::identity(6, 6) * (o.damping * o.damping);
                match g.cholesky() {
                    Some(c) => stacked.transpose() * c.solve(&e) * (o.rate * dt),
                    None => DVector::zeros(n),
                }
            }
        };
        out.copy_from_slice(step.as_slice());
    }
}

impl fmt::Display for Optimizer {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Optimizer::Jt(o) => write!(f, "jt (rate {} rad/(m²·s))", o.rate),
            Optimizer::Njt(o) => write!(f, "njt (speed {} rad/s)", o.speed),
            Optimizer::Svd(o) => write!(
                f,
                "svd (rate {}/s, threshold {} m/rad)",
                o.rate, o.threshold
            ),
            Optimizer::Dls(o) => write!(f, "dls (rate {}/s, damping {} m/rad)", o.rate, o.damping),
        }
    }
}

/// `out = scale · Jᵀ v`.
#[inline]
fn transpose_into(
    j: &kinergy_motion::nalgebra::Matrix3xX<f64>,
    v: &Vector3<f64>,
    scale: f64,
    out: &mut [f64],
) {
    for (o, c) in out.iter_mut().zip(j.column_iter()) {
        *o = scale * c.dot(v);
    }
}

/// `J x`.
#[inline]
fn mul_into(j: &kinergy_motion::nalgebra::Matrix3xX<f64>, x: &[f64]) -> Vector3<f64> {
    j.column_iter()
        .zip(x)
        .fold(Vector3::zeros(), |acc, (c, &v)| acc + c * v)
}

#[inline]
fn norm(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// `J Jᵀ`, summed column by column.
#[inline]
pub(crate) fn gram(j: &kinergy_motion::nalgebra::Matrix3xX<f64>) -> Matrix3<f64> {
    let mut g = Matrix3::zeros();
    for c in j.column_iter() {
        g.ger(1.0, &c, &c, 1.0);
    }
    g
}

/// `A⁻¹ b` by the adjugate, `None` when `A` is singular to working precision.
#[inline]
fn adjugate_solve(a: &Matrix3<f64>, b: &Vector3<f64>) -> Option<Vector3<f64>> {
    let c0 = a.column(1).cross(&a.column(2));
    let c1 = a.column(2).cross(&a.column(0));
    let c2 = a.column(0).cross(&a.column(1));
    let det = a.column(0).dot(&c0);
    if det.abs() <= f64::MIN_POSITIVE {
        return None;
    }
    // Rows of the inverse are the cross products over det.
    Some(Vector3::new(c0.dot(b), c1.dot(b), c2.dot(b)) / det)
}

/// `(J Jᵀ)⁺ ΔX` for the Gram matrix `g = J Jᵀ`, dropping singular values of J below
/// `threshold` (eigenvalues of g below threshold²). So `Jᵀ (J Jᵀ)⁺ ΔX = J⁺ ΔX` exactly.
pub(crate) fn pseudo_inverse_3(
    g: &Matrix3<f64>,
    dx: &Vector3<f64>,
    threshold: f64,
) -> Vector3<f64> {
    let t2 = threshold * threshold;
    let trace = g.trace();
    if trace <= t2 {
        // Every eigenvalue is below threshold² (they are ≥ 0 and sum to the trace).
        return Vector3::zeros();
    }
    // λ_min = det / (λ_mid λ_max) ≥ det / trace²: when that bound clears threshold², the
    // matrix is invertible with every singular value kept.
    let det = g.determinant();
    if det / (trace * trace) > t2
        && let Some(y) = adjugate_solve(g, dx)
    {
        return y;
    }
    if let Some(y) = rank_two_solve(g, dx, trace, t2) {
        return y;
    }
    let eig = SymmetricEigen::new(*g);
    let mut y = Vector3::zeros();
    for (i, &l) in eig.eigenvalues.iter().enumerate() {
        if l >= t2 {
            let v = eig.eigenvectors.column(i);
            y += v * (v.dot(dx) / l);
        }
    }
    y
}

/// `G⁺ ΔX` in closed form when `g` is exactly of rank 2 (to rounding) with both non-zero
/// eigenvalues at least `t2`: a Jacobian whose radial row the controller removed near full
/// extension ([`crate::reachability`]), or the exactly stretched arm. The adjugate of such a
/// G is λ₁λ₂ n nᵀ for its unit null vector n, and on the plane across n,
/// G⁺ = (G + κ n nᵀ)⁻¹ − n nᵀ / κ for any κ > 0 (here the trace). `None` otherwise.
fn rank_two_solve(
    g: &Matrix3<f64>,
    dx: &Vector3<f64>,
    trace: f64,
    t2: f64,
) -> Option<Vector3<f64>> {
    let adjugate = [
        g.column(1).cross(&g.column(2)),
        g.column(2).cross(&g.column(0)),
        g.column(0).cross(&g.column(1)),
    ];
    // λ₁λ₂: the adjugate's trace, the sum of the principal 2 × 2 minors.
    let product = adjugate[0].x + adjugate[1].y + adjugate[2].z;
    let widest = adjugate
        .iter()
        .max_by(|a, b| a.norm_squared().total_cmp(&b.norm_squared()))?;
    let norm = widest.norm();
    if norm <= f64::MIN_POSITIVE || product <= 0.0 {
        return None;
    }
    let n = widest / norm;
    if (g * n).norm() > 1e-12 * trace {
        return None;
    }
    // The smaller kept eigenvalue, λ = (tr − √(tr² − 4p)) / 2 written without cancellation.
    let smaller = 2.0 * product / (trace + (trace * trace - 4.0 * product).max(0.0).sqrt());
    if smaller < t2 {
        return None;
    }
    let y = adjugate_solve(&(g + n * n.transpose() * trace), dx)?;
    Some(y - n * (n.dot(dx) / trace))
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use kinergy_motion::nalgebra::Matrix3xX;
    use proptest::prelude::*;

    fn lin_of(j: Matrix3xX<f64>) -> Linearization {
        Linearization {
            angular: Matrix3xX::zeros(j.ncols()),
            linear: j,
            ..Default::default()
        }
    }

    fn step(o: Optimizer, j: &Matrix3xX<f64>, dx: Vector3<f64>, dt: f64) -> Vec<f64> {
        let mut out = vec![0.0; j.ncols()];
        o.step(
            &lin_of(j.clone()),
            &TaskError::position(dx),
            dt,
            &mut StepScratch::default(),
            &mut out,
        );
        out
    }

    /// The pseudo-inverse as the optimizer applies it: column i is the step for ΔX = e_i.
    fn pinv_by_steps(o: Optimizer, j: &Matrix3xX<f64>) -> DMatrix<f64> {
        let mut x = DMatrix::zeros(j.ncols(), 3);
        for i in 0..3 {
            let s = step(o, j, Vector3::ith(i, 1.0), 1.0);
            x.set_column(i, &DVector::from_vec(s));
        }
        x
    }

    /// The four Penrose conditions, which define the Moore–Penrose inverse uniquely:
    /// J X J = J, X J X = X, (J X)ᵀ = J X, (X J)ᵀ = X J.
    fn assert_penrose(j: &DMatrix<f64>, x: &DMatrix<f64>, tol: f64) {
        let jx = j * x;
        let xj = x * j;
        assert_relative_eq!(&jx * j, j.clone(), epsilon = tol);
        assert_relative_eq!(&xj * x, x.clone(), epsilon = tol);
        assert_relative_eq!(jx.transpose(), jx.clone(), epsilon = tol);
        assert_relative_eq!(xj.transpose(), xj.clone(), epsilon = tol);
    }

    prop_compose! {
        fn jacobian()(v in proptest::collection::vec(-1.0f64..1.0, 21)) -> Matrix3xX<f64> {
            Matrix3xX::from_column_slice(&v)
        }
    }

    proptest! {
        #[test]
        fn svd_step_equals_the_normal_equations_on_full_rank(j in jacobian(), e in proptest::collection::vec(-1.0f64..1.0, 3)) {
            let dx = Vector3::from_column_slice(&e);
            let g = gram(&j);
            prop_assume!(g.symmetric_eigenvalues().min() > 1e-3);
            let got = step(Optimizer::Svd(PseudoInverse { rate: 1.0, threshold: 1e-6 }), &j, dx, 1.0);
            // Jᵀ (J Jᵀ)⁻¹ ΔX by a general LU solve.
            let y = g.lu().solve(&dx).expect("invertible");
            let expected = j.transpose() * y;
            for (a, b) in got.iter().zip(expected.iter()) {
                assert_relative_eq!(*a, *b, epsilon = 1e-9, max_relative = 1e-9);
            }
            let x = pinv_by_steps(Optimizer::Svd(PseudoInverse { rate: 1.0, threshold: 1e-6 }), &j);
            assert_penrose(&DMatrix::from_iterator(3, 7, j.iter().copied()), &x, 1e-9);
        }

        #[test]
        fn svd_step_equals_the_svd_pseudo_inverse_on_rank_deficient(
            j in jacobian(), e in proptest::collection::vec(-1.0f64..1.0, 3),
            a in -2.0f64..2.0, b in -2.0f64..2.0, rank_one in any::<bool>(),
        ) {
            // Make row 2 a combination of rows 0 and 1 (rank 2), or rows 1 and 2 multiples of
            // row 0 (rank 1).
            let mut j = j;
            if rank_one {
                let r0 = j.row(0).into_owned();
                j.set_row(1, &(r0.clone() * a));
                j.set_row(2, &(r0 * b));
            } else {
                let r = j.row(0) * a + j.row(1) * b;
                j.set_row(2, &r);
            }
            // The Gram route squares singular values: exact in exact arithmetic, and in
            // floating point to ~ε·σ_max²/σ² relative; structural zeros stay ~1e-16, far
            // below the threshold. The reference is the Penrose conditions of the
            // *truncated* Jacobian, i.e. of J itself when its dropped values are structural.
            let _ = e;
            let threshold = 1e-3;
            let x = pinv_by_steps(Optimizer::Svd(PseudoInverse { rate: 1.0, threshold }), &j);
            let jd = DMatrix::from_iterator(3, 7, j.iter().copied());
            // Skip near-threshold cases: there "dropped or kept" is a coin toss for any method.
            let g = gram(&j).symmetric_eigenvalues();
            prop_assume!(g.iter().all(|&l| !(1e-12..=1e-4).contains(&l)));
            assert_penrose(&jd, &x, 1e-8);
            // Rank deficiency is preserved: X has the rank of J.
            let rank = |m: &DMatrix<f64>| (m.transpose() * m).symmetric_eigenvalues().iter().filter(|&&l| l > 1e-10).count();
            assert_eq!(rank(&x), if rank_one { 1 } else { 2 });
        }

        #[test]
        fn dls_matches_its_closed_form(j in jacobian(), e in proptest::collection::vec(-1.0f64..1.0, 3), mu in 0.01f64..1.0) {
            let dx = Vector3::from_column_slice(&e);
            let got = step(Optimizer::Dls(DampedLeastSquares { rate: 2.0, damping: mu }), &j, dx, 0.5);
            // Jᵀ (J Jᵀ + μ² I)⁻¹ = (JᵀJ + μ² I)⁻¹ Jᵀ (push-through identity).
            let jt = DMatrix::from_iterator(3, 7, j.iter().copied()).transpose();
            let lhs = &jt * jt.transpose() + DMatrix::identity(7, 7) * (mu * mu);
            let expected = lhs.lu().solve(&(jt * DVector::from_column_slice(dx.as_slice()))).expect("spd");
            for (x, y) in got.iter().zip(expected.iter()) {
                assert_relative_eq!(*x, *y, epsilon = 1e-9, max_relative = 1e-8);
            }
        }

        #[test]
        fn njt_steps_along_the_transpose_and_never_overshoots(j in jacobian(), e in proptest::collection::vec(-1.0f64..1.0, 3), speed in 0.1f64..100.0) {
            let dx = Vector3::from_column_slice(&e);
            let dt = 0.01;
            let got = step(Optimizer::Njt(NormalizedTranspose { speed }), &j, dx, dt);
            let jt = step(Optimizer::Jt(Transpose { rate: 1.0 }), &j, dx, 1.0);
            let n = norm(&got);
            prop_assume!(norm(&jt) > 1e-9);
            assert!(n <= speed * dt * (1.0 + 1e-12));
            // Parallel to Jᵀ ΔX.
            let cos = got.iter().zip(&jt).map(|(a, b)| a * b).sum::<f64>() / (n * norm(&jt));
            assert_relative_eq!(cos, 1.0, epsilon = 1e-9);
            // The linearized error never grows.
            let after = dx - mul_into(&j, &got);
            assert!(after.norm() <= dx.norm() * (1.0 + 1e-12));
        }
    }

    proptest! {
        #[test]
        fn the_rank_two_closed_form_is_the_pseudo_inverse(
            j in jacobian(),
            n in proptest::collection::vec(-1.0f64..1.0, 3),
            e in proptest::collection::vec(-1.0f64..1.0, 3),
        ) {
            // J with its row along n removed: G = J Jᵀ is exactly of rank 2.
            let n = Vector3::from_column_slice(&n);
            prop_assume!(n.norm() > 0.1);
            let n = n.normalize();
            let mut j = j;
            for mut c in j.column_iter_mut() {
                let along = n.dot(&c);
                c -= n * along;
            }
            let g = gram(&j);
            let dx = Vector3::from_column_slice(&e);
            let t2 = 1e-6;
            let eig = SymmetricEigen::new(g);
            prop_assume!(eig.eigenvalues.iter().filter(|&&l| l >= 1e-3).count() == 2);
            let mut want = Vector3::zeros();
            for (i, &l) in eig.eigenvalues.iter().enumerate() {
                if l >= t2 {
                    let v = eig.eigenvectors.column(i);
                    want += v * (v.dot(&dx) / l);
                }
            }
            let got = rank_two_solve(&g, &dx, g.trace(), t2).expect("rank 2");
            assert_relative_eq!(got, want, epsilon = 1e-9, max_relative = 1e-9);
            // A full-rank G is never taken for rank 2.
            let full = g + n * n.transpose() * 1e-3;
            prop_assert!(rank_two_solve(&full, &dx, full.trace(), t2).is_none());
        }

        #[test]
        fn drive_step_is_the_step_on_a_single_column(
            c in proptest::collection::vec(-1.0f64..1.0, 3),
            gap in -2.0f64..2.0,
            dt in 0.001f64..0.1,
        ) {
            let j = Matrix3xX::from_column_slice(&c);
            let column_sq = j.column(0).norm_squared();
            prop_assume!(column_sq > 1e-6);
            let dx = j.column(0) * gap;
            for kind in OptimizerKind::ALL {
                let o = kind.default_optimizer();
                let got = o.drive_step(column_sq, gap, dt);
                let want = step(o, &j, dx, dt)[0];
                assert_relative_eq!(got, want, epsilon = 1e-12, max_relative = 1e-9);
            }
        }
    }

    #[test]
    fn jt_is_lambda_j_transpose() {
        let j = Matrix3xX::from_column_slice(&[1.0, 2.0, 3.0, -1.0, 0.5, 0.0]);
        let got = step(
            Optimizer::Jt(Transpose { rate: 10.0 }),
            &j,
            Vector3::new(1.0, 1.0, 1.0),
            0.1,
        );
        assert_eq!(got, vec![6.0, -0.5]);
    }

    #[test]
    fn zero_jacobian_gives_zero_step_for_every_optimizer() {
        let j = Matrix3xX::zeros(7);
        for kind in OptimizerKind::ALL {
            let got = step(
                kind.default_optimizer(),
                &j,
                Vector3::new(1.0, 0.0, 0.0),
                0.01,
            );
            assert!(got.iter().all(|v| *v == 0.0), "{kind}: {got:?}");
        }
    }

    #[test]
    fn kinds_parse_and_validate() {
        assert_eq!(
            "SVD".parse::<OptimizerKind>().expect("svd"),
            OptimizerKind::Svd
        );
        let err = "lm".parse::<OptimizerKind>().expect_err("unknown");
        assert!(err.to_string().contains("optimizer"), "{err}");
        let bad = Optimizer::Svd(PseudoInverse {
            rate: 1.0,
            threshold: f64::NAN,
        });
        let err = bad.validate().expect_err("NaN threshold");
        assert!(err.to_string().contains("optimizer.threshold"), "{err}");
        for kind in OptimizerKind::ALL {
            kind.default_optimizer()
                .validate()
                .expect("defaults are valid");
        }
        let json = serde_json::to_string(&OptimizerKind::Dls.default_optimizer()).expect("json");
        assert_eq!(json, r#"{"kind":"dls","rate":4.0,"damping":0.05}"#);
        let back: Optimizer = serde_json::from_str(&json).expect("back");
        assert_eq!(back, OptimizerKind::Dls.default_optimizer());
    }
}
