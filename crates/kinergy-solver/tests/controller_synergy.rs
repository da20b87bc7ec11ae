//! The synergy models S_A–S_D shape the controller's motion exactly as their formulas say,
//! and the 6-D task's steps are the Moore–Penrose inverse's. Moved out of `tests/controller.rs`.
//!
//! Every case is drawn from a seeded generator, so a failure names a case that reproduces.

mod controller_support;

use approx::assert_relative_eq;
use kinergy_motion::nalgebra::{DMatrix, IsometryMatrix3, Point3, UnitQuaternion, Vector3};
use kinergy_motion::{Chain, Linearization};
use kinergy_solver::task::TaskError;
use kinergy_solver::{
    Base, Bounds, Controller, ControllerSettings, LimitHandling, Model, Optimizer, OptimizerKind,
    ParamSpace, PseudoInverse, StepScratch, StopReason, Synergy, Synthesis, Task, sig,
};
use rand::RngExt;

use controller_support::{
    DT, Rng, arm, assert_within_limits, controller, last, random_arm, random_base, random_config,
    rng, settings, synthesize,
};

fn dof_names(chain: &Chain) -> Vec<String> {
    chain.dof_names().map(String::from).collect()
}

/// A random reach of the middle half of the limits: chain, base, start, target.
fn random_reach(rng: &mut Rng) -> (Chain, IsometryMatrix3<f64>, Vec<f64>, Point3<f64>) {
    let chain = random_arm(rng);
    let base = random_base(rng);
    let goal = random_config(&chain, 0.5, rng);
    let start = random_config(&chain, 0.5, rng);
    let target = chain.end_position(&base, &goal).expect("fk");
    (chain, base, start, target)
}

fn bits(m: &Synthesis) -> (Vec<u64>, Vec<u64>) {
    (
        m.configurations.iter().map(|v| v.to_bits()).collect(),
        m.points
            .iter()
            .flat_map(|p| p.coords.iter().map(|v| v.to_bits()).collect::<Vec<_>>())
            .collect(),
    )
}

// Truth 4a: S_A with g = 1 is the raw optimizer, bit for bit.
#[test]
fn sa_with_unit_gain_is_bitwise_the_raw_optimizer() {
    let mut rng = rng(41);
    for kind in OptimizerKind::ALL {
        for _ in 0..10 {
            let (chain, base, start, target) = random_reach(&mut rng);
            let space =
                ParamSpace::new(Model::Sa, &dof_names(&chain), Bounds::default()).expect("space");
            let sa = Synergy::new(&space, &[1.0]).expect("S_A");
            let base = Base::Fixed(base);
            let raw = synthesize(
                &controller(kind, Synergy::identity(7)),
                &chain,
                &base,
                &start,
                Task::Position(target),
            );
            let one = synthesize(
                &controller(kind, sa),
                &chain,
                &base,
                &start,
                Task::Position(target),
            );
            assert!(raw.frame_count() > 1);
            assert_eq!(bits(&raw), bits(&one), "{kind}");
            assert_eq!(
                (raw.stop, raw.final_error.to_bits()),
                (one.stop, one.final_error.to_bits())
            );
        }
    }
}

// Truth 4b: a zero gain (φ·g = 0) freezes its DoF for the whole motion, bit for bit, in
// S_B and in S_D (whatever the other DoFs' gains and sigmoids), for every DoF.
#[test]
fn a_zero_gain_freezes_its_dof() {
    let mut rng = rng(42);
    for kind in OptimizerKind::ALL {
        for dof in 0..7 {
            let (chain, base, start, target) = random_reach(&mut rng);
            let names = dof_names(&chain);
            let sb = ParamSpace::new(Model::Sb, &names, Bounds::default()).expect("S_B");
            let sd = ParamSpace::new(Model::Sd, &names, Bounds::default()).expect("S_D");
            let mut gains: Vec<f64> = (0..7).map(|_| rng.random_range(0.5..3.0)).collect();
            gains[dof] = 0.0;
            let mut sd_values = gains.clone();
            sd_values.extend((0..7).map(|_| rng.random_range(1.0..10.0)));
            sd_values.extend((0..7).map(|_| rng.random_range(0.0..3.0)));
            for synergy in [Synergy::new(&sb, &gains), Synergy::new(&sd, &sd_values)] {
                let synergy = synergy.expect("synergy");
                let model = synergy.model();
                let m = synthesize(
                    &controller(kind, synergy),
                    &chain,
                    &Base::Fixed(base),
                    &start,
                    Task::Position(target),
                );
                assert!(
                    m.frame_count() > 10,
                    "{kind} {model}: {} frames",
                    m.frame_count()
                );
                for i in 0..m.frame_count() {
                    assert_eq!(
                        m.configuration(i)[dof].to_bits(),
                        start[dof].to_bits(),
                        "{kind} {model}: DoF {dof} moved on frame {i}"
                    );
                }
            }
        }
    }
}

// A clamp after a step that scales a swing pushed out of its ellipse toward zero would move the
// swing's other DoF even when its gain is 0. Here shoulder_swing_y is frozen at 1.5 rad and the
// target pulls shoulder_swing_x onto the ellipse.
#[test]
fn a_frozen_swing_dof_stays_put_when_its_partner_hits_the_ellipse() {
    let chain = arm();
    let space = ParamSpace::new(Model::Sb, &dof_names(&chain), Bounds::default()).expect("S_B");
    let gains = [1.0, 0.0, 1.0, 1.0, 1.0, 1.0, 1.0];
    let start = [0.0, 1.5, 0.0, 0.5, 0.0, 0.0, 0.0];
    let base = IsometryMatrix3::identity();
    let target = chain
        .end_position(&base, &[2.0, 1.5, 0.0, 0.0, 0.0, 0.0, 0.0])
        .expect("fk");
    let (rx, ry) = (130f64.to_radians(), 100f64.to_radians());
    for limits in [LimitHandling::Clamp, LimitHandling::Deactivate] {
        for kind in OptimizerKind::ALL {
            let c = Controller::new(
                kind.default_optimizer(),
                Synergy::new(&space, &gains).expect("synergy"),
                ControllerSettings {
                    limits,
                    ..settings()
                },
            )
            .expect("controller");
            let m = synthesize(
                &c,
                &chain,
                &Base::Fixed(base),
                &start,
                Task::Position(target),
            );
            let on_ellipse = (0..m.frame_count()).any(|i| {
                let q = m.configuration(i);
                (q[0] / rx).powi(2) + (q[1] / ry).powi(2) >= 1.0 - 1e-9
            });
            assert!(
                on_ellipse,
                "{limits:?} {kind}: the swing never reached its ellipse"
            );
            for i in 0..m.frame_count() {
                assert_eq!(
                    m.configuration(i)[1].to_bits(),
                    1.5f64.to_bits(),
                    "{limits:?} {kind}: frame {i}"
                );
            }
            assert_within_limits(&chain, &m, &format!("{limits:?} {kind}"));
        }
    }
}

// Truth 4c: negating one DoF's gain negates that DoF's first step (same magnitude) and leaves
// every other DoF's first step unchanged.
#[test]
fn a_negative_gain_reverses_its_dofs_first_step() {
    let mut rng = rng(43);
    for kind in OptimizerKind::ALL {
        for dof in 0..7 {
            let (chain, base, start, target) = random_reach(&mut rng);
            let space =
                ParamSpace::new(Model::Sb, &dof_names(&chain), Bounds::default()).expect("S_B");
            let gains: Vec<f64> = (0..7).map(|_| rng.random_range(0.5..5.0)).collect();
            let mut flipped = gains.clone();
            flipped[dof] = -flipped[dof];
            let first_step = |g: &[f64]| {
                let synergy = Synergy::new(&space, g).expect("synergy");
                let m = synthesize(
                    &controller(kind, synergy),
                    &chain,
                    &Base::Fixed(base),
                    &start,
                    Task::Position(target),
                );
                assert!(m.frame_count() > 1);
                (0..7)
                    .map(|i| m.configuration(1)[i] - m.configuration(0)[i])
                    .collect::<Vec<f64>>()
            };
            let (plus, minus) = (first_step(&gains), first_step(&flipped));
            assert!(plus[dof].abs() > 1e-9, "{kind}: DoF {dof} did not move");
            // Equal up to the rounding of q + Δ − q.
            assert_relative_eq!(
                minus[dof],
                -plus[dof],
                epsilon = 1e-15,
                max_relative = 1e-12
            );
            for i in (0..7).filter(|&i| i != dof) {
                assert_eq!(minus[i].to_bits(), plus[i].to_bits(), "{kind}: DoF {i}");
            }
        }
    }
}

// Truth 5: with S_C's sigmoid switched on late (s = 1/s, o = 20: φ(0) = sig(20) ≈ 2e-9) the
// first step is φ(0)·g_i times the raw optimizer's step, and the hand barely moves during
// the first second. (`min_frames` keeps that second: without it the stall rule ends such a
// motion after 0.25 s, before the sigmoid has switched on.)
#[test]
fn a_late_sigmoid_scales_the_first_step_by_phi() {
    let mut rng = rng(5);
    for kind in OptimizerKind::ALL {
        for _ in 0..10 {
            let (chain, base, start, target) = random_reach(&mut rng);
            let space =
                ParamSpace::new(Model::Sc, &dof_names(&chain), Bounds::default()).expect("S_C");
            let mut values: Vec<f64> = (0..7).map(|_| rng.random_range(-5.0..5.0)).collect();
            values.extend([1.0, 20.0]);
            let synergy = Synergy::new(&space, &values).expect("synergy");
            let phi0 = sig(20.0);
            assert_eq!(synergy.phi(0, 0.0), phi0);
            // The raw step, straight from the optimizer.
            let mut lin = Linearization::default();
            chain
                .linearize_into(&base, &start, &mut lin)
                .expect("linearize");
            let mut raw = vec![0.0; 7];
            kind.default_optimizer().step(
                &lin,
                &TaskError::position(target - lin.end),
                DT,
                &mut StepScratch::default(),
                &mut raw,
            );
            let c = Controller::new(
                kind.default_optimizer(),
                synergy,
                ControllerSettings {
                    min_frames: 121,
                    ..settings()
                },
            )
            .expect("controller");
            let m = synthesize(
                &c,
                &chain,
                &Base::Fixed(base),
                &start,
                Task::Position(target),
            );
            assert!(
                m.frame_count() >= 121,
                "{kind}: {} after {} frames",
                m.stop,
                m.frame_count()
            );
            for i in 0..7 {
                let step = m.configuration(1)[i] - start[i];
                // Exact up to the rounding of q + Δ − q (an ulp of q).
                assert_relative_eq!(
                    step,
                    phi0 * values[i] * raw[i],
                    epsilon = 4.0 * f64::EPSILON
                );
            }
            // φ(t ≤ 1 s) ≤ sig(19) ≈ 6e-9: nanometers over the first second.
            let moved = (m.end(120) - m.end(0)).norm();
            assert!(
                moved < 1e-6,
                "{kind}: the hand moved {moved} m in the first second"
            );
        }
    }
}

// Truth 6a: with the 6-D task (position + orientation of the hand's frame), SVD and DLS
// reach poses made by FK of a random configuration from random starts: position within
// ε = 1 mm and, at 0.2 m/rad, orientation within 5 mrad. With the paper's clamp they reach
// all 200; with the default `LimitHandling::Deactivate` both miss case 181 (measured: stalled
// 0.27 m away; with swings on their ellipse blocked instead of sliding, they miss 9).
// Floor: 99%.
#[test]
fn svd_and_dls_reach_reachable_poses() {
    const CASES: usize = 200;
    const WEIGHT: f64 = 0.2;
    for limits in [LimitHandling::Clamp, LimitHandling::Deactivate] {
        let settings = ControllerSettings {
            tolerance: 1e-3,
            limits,
            ..settings()
        };
        for kind in [OptimizerKind::Svd, OptimizerKind::Dls] {
            let c = Controller::new(kind.default_optimizer(), Synergy::identity(7), settings)
                .expect("controller");
            let mut rng = rng(61);
            let mut failed = Vec::new();
            let (mut worst_position, mut worst_angle) = (0.0f64, 0.0f64);
            for case in 0..CASES {
                let chain = random_arm(&mut rng);
                let base = random_base(&mut rng);
                let goal = random_config(&chain, 0.5, &mut rng);
                let start = random_config(&chain, 0.5, &mut rng);
                let mut lin = Linearization::default();
                chain.linearize_into(&base, &goal, &mut lin).expect("fk");
                let task = Task::Pose {
                    position: lin.end,
                    orientation: UnitQuaternion::from_rotation_matrix(&lin.end_rotation),
                    weight: WEIGHT,
                };
                let m = synthesize(&c, &chain, &Base::Fixed(base), &start, task);
                assert_within_limits(&chain, &m, &format!("{kind} case {case}"));
                let mut reached = Linearization::default();
                chain
                    .linearize_into(&base, last(&m), &mut reached)
                    .expect("fk");
                let position = (reached.end - lin.end).norm();
                let angle = (reached.end_rotation.inverse() * lin.end_rotation).angle();
                if m.stop == StopReason::Reached {
                    // ε bounds √(|Δx|² + (w·Δr)²), so each part on its own.
                    assert!(
                        position < 1e-3 && angle * WEIGHT < 1e-3,
                        "{kind} case {case}"
                    );
                    worst_position = worst_position.max(position);
                    worst_angle = worst_angle.max(angle);
                } else {
                    failed.push((case, m.stop, position, angle));
                }
            }
            eprintln!(
                "6-D, {limits:?}, {kind}: reached {}/{CASES} (worst {worst_position:.1e} m, {worst_angle:.1e} rad); failed {failed:?}",
                CASES - failed.len()
            );
            let allowed = match limits {
                LimitHandling::Clamp => 0,
                _ => CASES / 100,
            };
            assert!(
                failed.len() <= allowed,
                "{limits:?} {kind}: {} of {CASES} poses missed (allowed {allowed})",
                failed.len()
            );
        }
    }
}

/// The four Penrose conditions, which define the Moore–Penrose inverse uniquely:
/// J X J = J, X J X = X, (J X)ᵀ = J X, (X J)ᵀ = X J.
fn assert_penrose(j: &DMatrix<f64>, x: &DMatrix<f64>, tol: f64, what: &str) {
    let (jx, xj) = (j * x, x * j);
    let scale = 1.0 + x.norm();
    assert!((&jx * j - j).norm() <= tol * scale, "{what}: J X J ≠ J");
    assert!(
        (&xj * x - x).norm() <= tol * scale * scale,
        "{what}: X J X ≠ X"
    );
    assert!(
        (jx.transpose() - &jx).norm() <= tol * scale,
        "{what}: J X not symmetric"
    );
    assert!(
        (xj.transpose() - &xj).norm() <= tol * scale,
        "{what}: X J not symmetric"
    );
}

// Truth 6b: the SVD optimizer's 6-D step is J_w⁺ e, J_w = [J_linear; w·J_angular] the
// weighted pose Jacobian: the matrix built column by column from `Optimizer::step` with unit
// error vectors (rate·dt = 1) satisfies the four Penrose conditions, on random
// configurations and on the singular stretched arm (where it drops the radial direction).
#[test]
fn the_svd_pose_step_is_the_moore_penrose_inverse() {
    let svd = Optimizer::Svd(PseudoInverse {
        rate: 1.0,
        threshold: 1e-3,
    });
    let mut rng = rng(62);
    let mut configurations: Vec<Vec<f64>> = vec![vec![0.0; 7]];
    let chain = arm();
    configurations.extend((0..50).map(|_| random_config(&chain, 1.0, &mut rng)));
    for (c, q) in configurations.iter().enumerate() {
        let base = random_base(&mut rng);
        let mut lin = Linearization::default();
        chain.linearize_into(&base, q, &mut lin).expect("linearize");
        for weight in [1.0, 0.25] {
            let mut j = DMatrix::zeros(6, 7);
            j.rows_mut(0, 3).copy_from(&lin.linear);
            j.rows_mut(3, 3).copy_from(&(&lin.angular * weight));
            // Skip near-threshold singular values: kept or dropped is a coin toss there.
            let eigen = (&j * j.transpose()).symmetric_eigenvalues();
            if eigen.iter().any(|&l| (1e-7..=1e-5).contains(&l)) {
                continue;
            }
            let mut x = DMatrix::zeros(7, 6);
            let mut scratch = StepScratch::default();
            let mut out = vec![0.0; 7];
            for i in 0..6 {
                let e = Vector3::ith(i % 3, 1.0);
                let error = if i < 3 {
                    TaskError {
                        linear: e,
                        angular: Some(Vector3::zeros()),
                        weight,
                    }
                } else {
                    // The optimizer weighs the angular error: feed e/w to get e in J_w's rows.
                    TaskError {
                        linear: Vector3::zeros(),
                        angular: Some(e / weight),
                        weight,
                    }
                };
                svd.step(&lin, &error, 1.0, &mut scratch, &mut out);
                x.set_column(
                    i,
                    &kinergy_motion::nalgebra::DVector::from_column_slice(&out),
                );
            }
            assert_penrose(&j, &x, 1e-9, &format!("configuration {c}, weight {weight}"));
            if c == 0 {
                // The stretched arm: rank 5 (no radial motion), and X has that rank too.
                let rank = |m: &DMatrix<f64>| {
                    (m.transpose() * m)
                        .symmetric_eigenvalues()
                        .iter()
                        .filter(|&&l| l > 1e-9)
                        .count()
                };
                assert_eq!((rank(&j), rank(&x)), (5, 5));
            }
        }
    }
}

// Errors users hit: a synergy made for another chain, a NaN target, a start of the wrong
// length.
