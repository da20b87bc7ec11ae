//! Cost of the analytic limb IK (DESIGN §1.3): one solve at a given orbit angle, the orbit
//! search with limits, `alpha_of` — and, side by side in the same run, openrr's `k`
//! `JacobianIkSolver` on the same 7-DoF arm (revolute joints, since `k` has no swing joints)
//! and the same 10,000 random reachable 6-D goals: success rate and mean time per solve,
//! failures included (TRAC-IK's protocol, as in `benches/synergy.rs`).
//!
//! `cargo bench -p kinergy-solver --bench analytic`
//!
//! The comparison is printed to stderr before criterion's groups run.

use std::hint::black_box;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use kinergy_motion::nalgebra::{IsometryMatrix3, Rotation3, Translation3};
use kinergy_motion::rotation::{Axis, axis_rotation, euler_angles, swing_rotation};
use kinergy_motion::{Chain, Linearization};
use kinergy_solver::analytic::{LimbIk, OrbitSearch};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

mod common;
use common::{FORE, HAND, UPPER};
const TARGETS: usize = 10_000;
/// k's acceptance: meters and radians (ours is checked at 1e-9).
const K_DISTANCE: f64 = 1e-4;
const K_ANGLE: f64 = 1e-3;
const K_ITERATIONS: usize = 100;

fn arm() -> Chain {
    Chain::arm(UPPER, FORE, HAND).expect("arm")
}

/// Random configurations within the arm's limits (swings uniform in their ellipse).
fn configurations(seed: u64, n: usize) -> Vec<[f64; 7]> {
    let ik = LimbIk::new(&arm()).expect("ik");
    let l = *ik.limits();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            let mut swing = |(rx, ry): (f64, f64)| loop {
                let (a, b): (f64, f64) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                if a * a + b * b <= 1.0 {
                    break (a * rx, b * ry);
                }
            };
            let (sx, sy) = swing(l.shoulder_swing);
            let (wx, wy) = swing(l.wrist_swing);
            let mut rev = |(lo, hi): (f64, f64)| rng.random_range(lo..hi);
            let (t, f, u) = (
                rev(l.shoulder_twist),
                rev(l.elbow_flexion),
                rev(l.elbow_twist),
            );
            [sx, sy, t, f, u, wx, wy]
        })
        .collect()
}

/// FK goal: end-effector position and wrist orientation.
fn goal_of(chain: &Chain, q: &[f64; 7], lin: &mut Linearization) -> IsometryMatrix3<f64> {
    chain
        .linearize_into(&IsometryMatrix3::identity(), q, lin)
        .expect("fk");
    IsometryMatrix3::from_parts(Translation3::from(lin.end.coords), lin.end_rotation)
}

fn goals(seed: u64, n: usize) -> Vec<IsometryMatrix3<f64>> {
    let chain = arm();
    let mut lin = Linearization::default();
    configurations(seed, n)
        .iter()
        .map(|q| goal_of(&chain, q, &mut lin))
        .collect()
}

/// Position error (m) and largest rotation-matrix entry error (≈ radians; `angle()` of the
/// relative rotation goes through `acos` and cannot resolve below ~1e-8).
fn pose_error(chain: &Chain, q: &[f64; 7], goal: &IsometryMatrix3<f64>) -> (f64, f64) {
    let mut lin = Linearization::default();
    let reached = goal_of(chain, q, &mut lin);
    let dp = (reached.translation.vector - goal.translation.vector).norm();
    let dr = (reached.rotation.matrix() - goal.rotation.matrix()).amax();
    (dp, dr)
}

fn solve(c: &mut Criterion) {
    let ik = LimbIk::new(&arm()).expect("ik");
    let goals = goals(1, 1024);
    let alpha = 20f64.to_radians();
    let mut group = c.benchmark_group("analytic");
    let mut i = 0;
    group.bench_function("solve_at_alpha", |b| {
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(ik.solve(black_box(&goals[i]), alpha).expect("reachable"))
        })
    });
    let qs = configurations(1, 1024);
    group.bench_function("alpha_of", |b| {
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(ik.alpha_of(black_box(&qs[i])))
        })
    });
    let settings = OrbitSearch::default();
    // Every random goal, found or not (a failure runs the whole search: 16 solves).
    group.bench_function("search_all_goals", |b| {
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(ik.search(black_box(&goals[i]), &settings).ok())
        })
    });
    let found: Vec<_> = goals
        .iter()
        .filter(|g| ik.search(g, &settings).is_ok())
        .copied()
        .collect();
    let mut j = 0;
    group.bench_function("search_found_goals", |b| {
        b.iter(|| {
            j = (j + 1) % found.len();
            black_box(ik.search(black_box(&found[j]), &settings).expect("found"))
        })
    });
    let targets: Vec<_> = goals.iter().map(|g| g.translation.vector.into()).collect();
    group.bench_function("solve_position_search", |b| {
        b.iter(|| {
            i = (i + 1) & 1023;
            black_box(ik.solve_position(black_box(&targets[i]), &settings).ok())
        })
    });
    group.finish();
}

// ---------------------------------------------------------------------------------------
// k's arm: the same bones with revolute joints — shoulder X, Y, Z; elbow X, Z; wrist X, Y —
// and no joint limits, so every goal of our arm is reachable by it.

/// Our configuration in k's joints with the same FK: shoulder `swing · R_z(t)` as XYZ Euler
/// angles, flexion as is, and the distal `R_z(u) · swing(wx, wy)` as ZXY Euler angles.
fn to_k(q: &[f64; 7]) -> [f64; 7] {
    let shoulder = swing_rotation(q[0], q[1]) * axis_rotation(Axis::Z, q[2]);
    let [a, b, c] = euler_angles([Axis::X, Axis::Y, Axis::Z], &shoulder).expect("axes");
    let distal = axis_rotation(Axis::Z, q[4]) * swing_rotation(q[5], q[6]);
    let [u, x, y] = euler_angles([Axis::Z, Axis::X, Axis::Y], &distal).expect("axes");
    [a, b, c, q[3], u, x, y]
}

fn k_pose(arm: &k::SerialChain<f64>) -> IsometryMatrix3<f64> {
    let t = arm.end_transform();
    let r = t.rotation.to_rotation_matrix();
    let m = r.matrix();
    let v = t.translation.vector;
    IsometryMatrix3::from_parts(
        Translation3::new(v.x, v.y, v.z),
        Rotation3::from_matrix_unchecked(kinergy_motion::nalgebra::Matrix3::from_fn(|i, j| {
            m[(i, j)]
        })),
    )
}

struct Outcome {
    name: String,
    successes: usize,
    total: Duration,
}

impl Outcome {
    fn mean_us(&self) -> f64 {
        self.total.as_secs_f64() * 1e6 / TARGETS as f64
    }

    fn print(&self) {
        eprintln!(
            "  {:<52} success {:6.2} %   mean {:9.3} µs per solve",
            self.name,
            100.0 * self.successes as f64 / TARGETS as f64,
            self.mean_us()
        );
    }
}

fn ours_at_alpha(goals: &[IsometryMatrix3<f64>]) -> Outcome {
    let chain = arm();
    let ik = LimbIk::new(&chain).expect("ik");
    let alpha = 20f64.to_radians();
    let clock = Instant::now();
    let answers: Vec<_> = goals
        .iter()
        .map(|g| ik.solve(black_box(g), alpha))
        .collect();
    let total = clock.elapsed();
    let successes = answers
        .iter()
        .zip(goals)
        .filter(|(a, g)| {
            a.as_ref().is_ok_and(|q| {
                let (dp, dr) = pose_error(&chain, q, g);
                dp < 1e-9 && dr < 1e-9
            })
        })
        .count();
    Outcome {
        name: "kinergy analytic solve, α = 20° (no limits), 1e-9".into(),
        successes,
        total,
    }
}

fn ours_search(goals: &[IsometryMatrix3<f64>]) -> Outcome {
    let chain = arm();
    let ik = LimbIk::new(&chain).expect("ik");
    let settings = OrbitSearch::default();
    let clock = Instant::now();
    let answers: Vec<_> = goals
        .iter()
        .map(|g| ik.search(black_box(g), &settings))
        .collect();
    let total = clock.elapsed();
    let successes = answers
        .iter()
        .zip(goals)
        .filter(|(a, g)| {
            a.as_ref().is_ok_and(|(_, q)| {
                let (dp, dr) = pose_error(&chain, q, g);
                chain.within_limits(q) && dp < 1e-9 && dr < 1e-9
            })
        })
        .count();
    Outcome {
        name: "kinergy analytic orbit search (within limits), 1e-9".into(),
        successes,
        total,
    }
}

fn theirs(goals: &[IsometryMatrix3<f64>], multiplier: f64) -> Outcome {
    use k::InverseKinematicsSolver;
    use k::nalgebra as kn;
    let arm = common::k_arm(None);
    let start = [0.3, 0.3, 0.0, 1.0, 0.0, 0.0, 0.0];
    let solver = k::JacobianIkSolver::new(K_DISTANCE, K_ANGLE, multiplier, K_ITERATIONS);
    let constraints = k::Constraints::default();
    let mut successes = 0;
    let mut total = Duration::ZERO;
    for g in goals {
        let t = g.translation.vector;
        let q = kinergy_motion::nalgebra::UnitQuaternion::from_rotation_matrix(&g.rotation);
        let pose = kn::Isometry3::from_parts(
            kn::Translation3::new(t.x, t.y, t.z),
            kn::UnitQuaternion::from_quaternion(kn::Quaternion::new(q.w, q.i, q.j, q.k)),
        );
        let clock = Instant::now();
        arm.set_joint_positions_clamped(&start);
        arm.update_transforms();
        let ok = solver
            .solve_with_constraints(&arm, &pose, &constraints)
            .is_ok();
        total += clock.elapsed();
        if ok {
            // Count only real successes, by our own measure of the pose error.
            let reached = k_pose(&arm);
            let dp = (reached.translation.vector - t).norm();
            let dr = (reached.rotation.inverse() * g.rotation).angle();
            successes += usize::from(dp < K_DISTANCE * 1.0001 && dr < K_ANGLE * 1.0001);
        }
    }
    Outcome {
        name: format!("k 0.32 JacobianIkSolver (multiplier {multiplier}), 1e-4 m/1e-3 rad"),
        successes,
        total,
    }
}

fn versus_k(_: &mut Criterion) {
    // The two arms agree: the same FK at random configurations, ours mapped to k's joints.
    let ours = arm();
    let k_arm = common::k_arm(None);
    let mut lin = Linearization::default();
    for q in configurations(7, 100) {
        k_arm.set_joint_positions(&to_k(&q)).expect("no limits");
        k_arm.update_transforms();
        let (a, b) = (goal_of(&ours, &q, &mut lin), k_pose(&k_arm));
        let dp = (a.translation.vector - b.translation.vector).norm();
        let dr = (a.rotation.matrix() - b.rotation.matrix()).amax();
        assert!(dp < 1e-12 && dr < 1e-12, "the two arms differ");
    }
    let goals = goals(2026, TARGETS);
    eprintln!(
        "\n7-DoF arm, {TARGETS} random reachable 6-D goals (FK of in-limit configurations, seed 2026); k: ≤ {K_ITERATIONS} iterations from the same start, no joint limits:"
    );
    let at_alpha = ours_at_alpha(&goals);
    let search = ours_search(&goals);
    // The search samples [−15°, 130°] only: how it does on goals whose generating posture
    // has its orbit angle there (the posture itself proves one fitting α exists).
    let ik = LimbIk::new(&ours).expect("ik");
    let settings = OrbitSearch::default();
    let (mut inside, mut found) = (0, 0);
    for q in configurations(2026, TARGETS) {
        if (settings.min..=settings.max).contains(&ik.alpha_of(&q)) {
            inside += 1;
            found += usize::from(ik.search(&goal_of(&ours, &q, &mut lin), &settings).is_ok());
        }
    }
    let k1 = theirs(&goals, 1.0);
    let k05 = theirs(&goals, 0.5);
    for o in [&at_alpha, &search, &k1, &k05] {
        o.print();
    }
    eprintln!(
        "  orbit search on the {inside} goals whose generating α lies in [−15°, 130°]: {found} found ({:.2} %)",
        100.0 * found as f64 / inside as f64
    );
    for k in [&k1, &k05] {
        eprintln!(
            "  speed-up vs {}: solve {:.0}×, search {:.0}×",
            k.name,
            k.mean_us() / at_alpha.mean_us(),
            k.mean_us() / search.mean_us()
        );
    }
}

criterion_group!(benches, versus_k, solve);
criterion_main!(benches);
