//! Per-frame cost of the synergy controller, a whole 1-s reach (to an ordinary target and
//! to one at 99% of the arm's reach), the 3 × 3 pseudo-inverse against a general SVD, and —
//! side by side in the same run — openrr's `k` `JacobianIkSolver` on the same 7-DoF arm and
//! the same 10,000 random reachable targets (TRAC-IK's protocol: success rate and mean time
//! per solve, failures included).
//!
//! `cargo bench -p kinergy-solver --bench synergy`
//!
//! The 10,000-target comparison is printed to stderr before criterion's groups run.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use kinergy_motion::nalgebra::{
    DMatrix, IsometryMatrix3, Point3, Translation3, UnitQuaternion, Vector3,
};
use kinergy_motion::{Chain, ChainJoint, Linearization, Motion};
use kinergy_solver::{
    ArmTask, Base, Controller, ControllerSettings, LimitHandling, Model, Optimizer, OptimizerKind,
    ParamSpace, PseudoInverse, Smoothing, StallRule, StepScratch, StopReason, Synergy, Task,
};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

mod common;
use common::{FORE, HAND, K_AXES as AXES, UPPER};

fn base() -> IsometryMatrix3<f64> {
    IsometryMatrix3::from_parts(
        Translation3::new(-0.2, 1.4, 0.0),
        UnitQuaternion::from_euler_angles(0.1, 0.2, 0.3).to_rotation_matrix(),
    )
}

/// An S_C synergy with every gain and the sigmoid switched on.
fn sc_synergy(arm: &Chain) -> Synergy {
    let names: Vec<String> = arm.dof_names().map(String::from).collect();
    let space = ParamSpace::new(Model::Sc, &names, Default::default()).expect("space");
    let mut v = vec![1.3; 7];
    v.extend([6.0, 0.5]);
    Synergy::new(&space, &v).expect("synergy")
}

/// One controller frame as `Controller::synthesize` does it: linearize, error, step with
/// limit deactivation off (the common case: no DoF on a limit), synergy, integrate, clamp.
fn frame(c: &mut Criterion) {
    let arm = Chain::arm(UPPER, FORE, HAND).expect("arm");
    let b = base();
    let synergy = sc_synergy(&arm);
    let target = Task::Position(Point3::new(0.1, 1.1, 0.4));
    let q0 = [0.3, -0.5, 0.2, 1.1, -0.4, 0.2, 0.1];
    let mut group = c.benchmark_group("frame");
    for kind in OptimizerKind::ALL {
        let optimizer = kind.default_optimizer();
        let mut lin = Linearization::default();
        let mut scratch = StepScratch::default();
        let mut step = [0.0; 7];
        group.bench_function(kind.name(), |bench| {
            bench.iter(|| {
                let mut q = q0;
                arm.linearize_into(&b, black_box(&q), &mut lin)
                    .expect("linearize");
                let error = target.error(&lin);
                optimizer.step(&lin, &error, 1.0 / 120.0, &mut scratch, &mut step);
                synergy.apply(0.5, &mut step);
                for (qi, d) in q.iter_mut().zip(&step) {
                    *qi += d;
                }
                arm.clamp(&mut q);
                black_box(q)
            })
        });
    }
    let mut lin = Linearization::default();
    group.bench_function("linearize_only", |bench| {
        bench.iter(|| {
            arm.linearize_into(&b, black_box(&q0), &mut lin)
                .expect("linearize");
            black_box(lin.end)
        })
    });
    group.finish();
}

/// A whole 1-s reach at 120 Hz (120 steps, 121 frames recorded) with S_C: to an ordinary
/// target (81% of the arm's reach away: the paper's loop), and to a stretched one (99%:
/// the controller guides every frame, `kinergy_solver::reachability`).
fn reach(c: &mut Criterion) {
    let near = Point3::new(0.1, -0.25, 0.45);
    let stretched = Point3::from(near.coords * (0.99 * (UPPER + FORE + HAND) / near.coords.norm()));
    reach_to(c, "reach_1s_120hz", near);
    reach_to(c, "reach_1s_120hz_stretched", stretched);
}

fn reach_to(c: &mut Criterion, group: &str, local_target: Point3<f64>) {
    let arm = Chain::arm(UPPER, FORE, HAND).expect("arm");
    let base = Base::Fixed(base());
    let start = [1.2, 0.3, 0.0, 0.6, 0.0, 0.0, 0.0];
    let settings = ControllerSettings {
        max_frames: 121,
        min_frames: 121,
        tolerance: 1e-9,
        ..ControllerSettings::at_frame_time(1.0 / 120.0)
    };
    let target = Task::Position(base.at(0) * local_target);
    let mut group = c.benchmark_group(group);
    for kind in OptimizerKind::ALL {
        let controller =
            Controller::new(kind.default_optimizer(), sc_synergy(&arm), settings).expect("ok");
        let reach = ArmTask {
            chain: &arm,
            base: &base,
            start: &start,
            task: target,
            start_velocity: None,
        };
        assert_eq!(
            controller.synthesize(&reach).expect("reach").frame_count(),
            121
        );
        group.bench_function(kind.name(), |bench| {
            bench.iter(|| controller.synthesize(black_box(&reach)).expect("reach"))
        });
        // The same reach with the smooth controller (bounds of a 1 m/s, 1 s reach).
        let smooth = Controller::new(
            kind.default_optimizer(),
            sc_synergy(&arm),
            ControllerSettings {
                smoothing: Some(Smoothing::for_reach(1.0, 1.0, UPPER + FORE + HAND)),
                ..settings
            },
        )
        .expect("ok");
        group.bench_function(format!("{}_smooth", kind.name()), |bench| {
            bench.iter(|| smooth.synthesize(black_box(&reach)).expect("reach"))
        });
    }
    group.finish();
}

/// The exact pseudo-inverse step through 3 × 3 algebra vs nalgebra's general SVD.
fn pseudo_inverse(c: &mut Criterion) {
    let arm = Chain::arm(UPPER, FORE, HAND).expect("arm");
    let mut lin = Linearization::default();
    arm.linearize_into(&base(), &[0.3, -0.5, 0.2, 1.1, -0.4, 0.2, 0.1], &mut lin)
        .expect("linearize");
    let dx = Vector3::new(0.01, -0.02, 0.005);
    let error = kinergy_solver::TaskError::position(dx);
    let svd = Optimizer::Svd(PseudoInverse {
        rate: 1.0,
        threshold: 1e-2,
    });
    let mut out = [0.0; 7];
    let mut scratch = StepScratch::default();
    let mut group = c.benchmark_group("pseudo_inverse_3x7");
    group.bench_function("gram_3x3", |bench| {
        bench.iter(|| {
            svd.step(black_box(&lin), &error, 1.0, &mut scratch, &mut out);
            black_box(out[0])
        })
    });
    let j = DMatrix::from_iterator(3, 7, lin.linear.iter().copied());
    group.bench_function("nalgebra_svd", |bench| {
        bench.iter(|| {
            let pinv = black_box(&j).clone().pseudo_inverse(1e-2).expect("svd");
            black_box(pinv * kinergy_motion::nalgebra::DVector::from_column_slice(dx.as_slice()))
        })
    });
    group.finish();
}

// ---------------------------------------------------------------------------------------
// The same arm for both solvers: shoulder X, Y, Z; elbow X, Z; wrist X, Y revolute joints
// (k has no swing joints), bones along +z, with box limits.

const LIMITS: [(f64, f64); 7] = [
    (-2.2, 2.2),
    (-1.7, 1.7),
    (-1.57, 1.57),
    (0.0, 2.6),
    (-1.57, 1.57),
    (-1.2, 1.2),
    (-0.5, 0.5),
];
const TOLERANCE: f64 = 1e-4;
const MAX_ITERATIONS: usize = 100;
const TARGETS: usize = 10_000;

fn revolute_arm() -> Chain {
    let rev = |i: usize| Motion::Revolute {
        axis: AXES[i],
        min: LIMITS[i].0,
        max: LIMITS[i].1,
    };
    Chain::new(
        vec![
            ChainJoint::new("shoulder", Vector3::zeros(), vec![rev(0), rev(1), rev(2)]),
            ChainJoint::new("elbow", Vector3::new(0.0, 0.0, UPPER), vec![rev(3), rev(4)]),
            ChainJoint::new("wrist", Vector3::new(0.0, 0.0, FORE), vec![rev(5), rev(6)]),
        ],
        Vector3::new(0.0, 0.0, HAND),
    )
    .expect("revolute arm")
}

struct Outcome {
    name: String,
    successes: usize,
    total: Duration,
}

impl Outcome {
    fn print(&self) {
        eprintln!(
            "  {:<42} success {:6.2} %   mean {:8.2} µs per solve",
            self.name,
            100.0 * self.successes as f64 / TARGETS as f64,
            self.total.as_secs_f64() * 1e6 / TARGETS as f64
        );
    }
}

/// Random configurations within the box limits → reachable targets; every solve starts
/// from the same nominal configuration.
fn targets() -> (Vec<Point3<f64>>, [f64; 7]) {
    let arm = revolute_arm();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(2026);
    let targets = (0..TARGETS)
        .map(|_| {
            let q: Vec<f64> = LIMITS
                .iter()
                .map(|&(lo, hi)| rng.random_range(lo..hi))
                .collect();
            arm.end_position(&IsometryMatrix3::identity(), &q)
                .expect("fk")
        })
        .collect();
    (targets, [0.3, 0.3, 0.0, 1.0, 0.0, 0.0, 0.0])
}

fn ours(name: &str, optimizer: Optimizer, limits: LimitHandling) -> Outcome {
    let arm = revolute_arm();
    let (targets, start) = targets();
    let base = Base::Fixed(IsometryMatrix3::identity());
    // One frame per iteration with λ = 1 (rate × frame time): Newton steps.
    let settings = ControllerSettings {
        frame_time: 1.0,
        max_frames: MAX_ITERATIONS + 1,
        tolerance: TOLERANCE,
        min_frames: 0,
        stall: StallRule {
            window: 10.0,
            min_progress: 1e-9,
        },
        limits,
        smoothing: None,
    };
    let controller = Controller::new(optimizer, Synergy::identity(7), settings).expect("ok");
    let mut successes = 0;
    let clock = Instant::now();
    for t in &targets {
        let reach = ArmTask {
            chain: &arm,
            base: &base,
            start: &start,
            task: Task::Position(*t),
            start_velocity: None,
        };
        let motion = controller.synthesize(&reach).expect("solve");
        successes += usize::from(motion.stop == StopReason::Reached);
    }
    Outcome {
        name: name.into(),
        successes,
        total: clock.elapsed(),
    }
}

fn theirs(multiplier: f64) -> Outcome {
    use k::InverseKinematicsSolver;
    use k::nalgebra as kn;
    let arm = common::k_arm(Some(&LIMITS));
    let (targets, start) = targets();
    let solver = k::JacobianIkSolver::new(TOLERANCE, 1.0, multiplier, MAX_ITERATIONS);
    let constraints = k::Constraints {
        rotation_x: false,
        rotation_y: false,
        rotation_z: false,
        ..Default::default()
    };
    let mut successes = 0;
    let clock = Instant::now();
    for t in &targets {
        arm.set_joint_positions_clamped(&start);
        arm.update_transforms();
        let pose = kn::Isometry3::from_parts(
            kn::Translation3::new(t.x, t.y, t.z),
            kn::UnitQuaternion::identity(),
        );
        if solver
            .solve_with_constraints(&arm, &pose, &constraints)
            .is_ok()
        {
            // Count only real successes: k reports success by its own distance test.
            let end = arm.end_transform().translation.vector;
            let err =
                ((end.x - t.x).powi(2) + (end.y - t.y).powi(2) + (end.z - t.z).powi(2)).sqrt();
            successes += usize::from(err < TOLERANCE * 1.0001);
        }
    }
    Outcome {
        name: format!("k 0.32 JacobianIkSolver (multiplier {multiplier})"),
        successes,
        total: clock.elapsed(),
    }
}

fn versus_k(_: &mut Criterion) {
    // Agreement of the two arms first: same FK at random configurations.
    let ours_arm = revolute_arm();
    let k_arm = common::k_arm(Some(&LIMITS));
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    for _ in 0..100 {
        let q: Vec<f64> = LIMITS
            .iter()
            .map(|&(lo, hi)| rng.random_range(lo..hi))
            .collect();
        k_arm.set_joint_positions_clamped(&q);
        k_arm.update_transforms();
        let a = ours_arm
            .end_position(&IsometryMatrix3::identity(), &q)
            .expect("fk");
        let b = k_arm.end_transform().translation.vector;
        assert!(
            (a.x - b.x).abs() + (a.y - b.y).abs() + (a.z - b.z).abs() < 1e-12,
            "the two arms differ"
        );
    }
    eprintln!(
        "\n7-DoF arm, {TARGETS} random reachable targets (seed 2026), tolerance {} mm, ≤ {MAX_ITERATIONS} iterations, same start:",
        TOLERANCE * 1e3
    );
    let svd = Optimizer::Svd(PseudoInverse {
        rate: 1.0,
        threshold: 1e-4,
    });
    let dls = Optimizer::Dls(kinergy_solver::DampedLeastSquares {
        rate: 1.0,
        damping: 0.01,
    });
    for outcome in [
        ours(
            "kinergy svd (λ = 1, limit deactivation)",
            svd,
            LimitHandling::Deactivate,
        ),
        ours(
            "kinergy svd (λ = 1, clamp only, as k)",
            svd,
            LimitHandling::Clamp,
        ),
        ours(
            "kinergy dls (λ = 1, μ = 0.01, deactivation)",
            dls,
            LimitHandling::Deactivate,
        ),
        ours(
            "kinergy svd (λ = 0.5, limit deactivation)",
            Optimizer::Svd(PseudoInverse {
                rate: 0.5,
                threshold: 1e-4,
            }),
            LimitHandling::Deactivate,
        ),
        ours(
            "kinergy dls (λ = 0.5, μ = 0.01, deactivation)",
            Optimizer::Dls(kinergy_solver::DampedLeastSquares {
                rate: 0.5,
                damping: 0.01,
            }),
            LimitHandling::Deactivate,
        ),
        theirs(1.0),
        theirs(0.5),
    ] {
        outcome.print();
    }
}

criterion_group!(benches, versus_k, frame, reach, pseudo_inverse);
criterion_main!(benches);
