//! Integration tests of the synergy controller on the 7-DoF arm (DESIGN §1.1): every optimizer
//! reaches what is reachable and stops at the closest point of what is not, singular postures
//! stay finite, and the synergy models S_A–S_D shape the motion exactly as their formulas say.
//!
//! Every case is drawn from a seeded generator, so a failure names a case that reproduces.

use approx::assert_relative_eq;
use kinergy_motion::nalgebra::{
    DMatrix, IsometryMatrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3,
};
use kinergy_motion::rotation::swing_rotation;
use kinergy_motion::{Chain, Linearization, Motion, MotionError};
use kinergy_solver::task::TaskError;
use kinergy_solver::{
    ArmTask, Base, Bounds, Controller, ControllerSettings, LimitHandling, Model, Optimizer,
    OptimizerKind, ParamSpace, PseudoInverse, SolverError, StepScratch, StopReason, Synergy,
    Synthesis, Task, sig,
};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

/// 120 Hz, the CMU captures' rate.
const DT: f64 = 1.0 / 120.0;

type Rng = Xoshiro256PlusPlus;

fn rng(seed: u64) -> Rng {
    Rng::seed_from_u64(seed)
}

/// 120 Hz, ε = 5 mm, the default stall rule and limit handling, a 20-second budget.
fn settings() -> ControllerSettings {
    ControllerSettings {
        max_frames: (20.0 / DT) as usize,
        ..ControllerSettings::at_frame_time(DT)
    }
}

fn controller(kind: OptimizerKind, synergy: Synergy) -> Controller {
    Controller::new(kind.default_optimizer(), synergy, settings()).expect("controller")
}

fn arm() -> Chain {
    Chain::arm(0.30, 0.26, 0.09).expect("arm")
}

/// An arm with a random adult's bone lengths and the default limits.
fn random_arm(rng: &mut Rng) -> Chain {
    Chain::arm(
        rng.random_range(0.25..0.36),
        rng.random_range(0.22..0.30),
        rng.random_range(0.05..0.11),
    )
    .expect("arm")
}

/// Upper arm + forearm + hand.
fn reach_length(chain: &Chain) -> f64 {
    chain.joints()[1..]
        .iter()
        .map(|j| j.offset.norm())
        .sum::<f64>()
        + chain.end_effector().norm()
}

fn dof_names(chain: &Chain) -> Vec<String> {
    chain.dof_names().map(String::from).collect()
}

/// A configuration drawn uniformly from the middle `fraction` of every limit: each revolute
/// range shrunk about its center, each swing ellipse scaled about zero (1 = the whole range).
fn random_config(chain: &Chain, fraction: f64, rng: &mut Rng) -> Vec<f64> {
    let mut q = Vec::with_capacity(chain.dof_count());
    for m in chain.joints().iter().flat_map(|j| &j.motions) {
        match *m {
            Motion::Revolute { min, max, .. } => {
                let (c, h) = (0.5 * (min + max), 0.5 * (max - min) * fraction);
                q.push(rng.random_range(c - h..=c + h));
            }
            Motion::Swing { rx, ry } => loop {
                let (a, b): (f64, f64) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                if a * a + b * b <= 1.0 {
                    q.extend([a * rx * fraction, b * ry * fraction]);
                    break;
                }
            },
        }
    }
    assert!(chain.within_limits(&q), "{q:?}");
    q
}

/// A random rigid frame: any rotation, its origin within a 2 m cube.
fn random_base(rng: &mut Rng) -> IsometryMatrix3<f64> {
    let axis = Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    let rotation =
        Rotation3::from_scaled_axis(axis.normalize() * rng.random_range(0.0..std::f64::consts::PI));
    IsometryMatrix3::from_parts(
        Translation3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        ),
        rotation,
    )
}

fn synthesize(c: &Controller, chain: &Chain, base: &Base, start: &[f64], task: Task) -> Synthesis {
    c.synthesize(&ArmTask {
        chain,
        base,
        start,
        task,
    })
    .expect("synthesize")
}

fn last(m: &Synthesis) -> &[f64] {
    m.configuration(m.frame_count() - 1)
}

fn all_finite(m: &Synthesis) -> bool {
    m.configurations.iter().all(|v| v.is_finite())
        && m.points
            .iter()
            .all(|p| p.coords.iter().all(|v| v.is_finite()))
        && m.final_error.is_finite()
}

fn assert_within_limits(chain: &Chain, m: &Synthesis, what: &str) {
    for i in 0..m.frame_count() {
        assert!(
            chain.within_limits(m.configuration(i)),
            "{what}: frame {i} {:?} is outside the limits",
            m.configuration(i)
        );
    }
}

/// A failed case: its index, why it stopped, the hand's error.
type Failure = (usize, StopReason, f64);

/// Reaches `cases` FK-made targets per optimizer with starts and goals drawn from the middle
/// `fraction` of the limits; every frame must stay within the limits. Returns, per optimizer,
/// the failed cases (case, stop, hand error).
fn reach_random_targets(
    cases: usize,
    fraction: f64,
    seed: u64,
) -> Vec<(OptimizerKind, Vec<Failure>)> {
    OptimizerKind::ALL
        .into_iter()
        .map(|kind| {
            let c = controller(kind, Synergy::identity(7));
            let mut rng = rng(seed);
            let mut failed = Vec::new();
            for case in 0..cases {
                let chain = random_arm(&mut rng);
                let base = random_base(&mut rng);
                let goal = random_config(&chain, fraction, &mut rng);
                let start = random_config(&chain, fraction, &mut rng);
                let target = chain.end_position(&base, &goal).expect("fk");
                let m = synthesize(
                    &c,
                    &chain,
                    &Base::Fixed(base),
                    &start,
                    Task::Position(target),
                );
                assert_within_limits(&chain, &m, &format!("{kind} case {case}"));
                // The hand error measured by FK, independently of the controller's own.
                let error = (chain.end_position(&base, last(&m)).expect("fk") - target).norm();
                assert_relative_eq!(error, m.final_error, epsilon = 1e-12);
                if !(m.stop == StopReason::Reached && error < settings().tolerance) {
                    failed.push((case, m.stop, error));
                }
            }
            (kind, failed)
        })
        .collect()
}

// Truth 1: from random starts, bases and bone lengths, every optimizer reaches targets made
// by FK of a configuration in the comfortable middle half of each joint range, within ε,
// inside the limits on every frame. SVD and DLS reach all 1000. JT and NJT get a floor of
// 99% (measured: JT 998, NJT 999 of 1000): JT, a plain gradient method at 20 rad/(m²·s),
// crawls along the valley of a badly conditioned Jacobian and runs out of its 20 s (case
// 300: 12 mm left); in case 892 both transpose methods drive the shoulder and the wrist
// swing onto their limit ellipses, where `LimitHandling::Deactivate` blocks both DoFs of a
// swing instead of letting it slide along the ellipse, and stall 35 mm short (the
// projected gradient is not zero there: not a true constrained minimum). SVD and DLS take
// another path to the same target.
#[test]
fn every_optimizer_reaches_reachable_targets_from_random_starts() {
    const CASES: usize = 1000;
    for (kind, failed) in reach_random_targets(CASES, 0.5, 8) {
        eprintln!(
            "middle half of the limits, {kind}: reached {}/{CASES}, failed {failed:?}",
            CASES - failed.len()
        );
        let allowed = match kind {
            OptimizerKind::Jt | OptimizerKind::Njt => CASES / 100,
            _ => 0,
        };
        assert!(
            failed.len() <= allowed,
            "{kind}: {} of {CASES} reaches failed (allowed {allowed}): {failed:?}",
            failed.len()
        );
    }
}

// Across the whole range of every limit (starts and goals uniform inside the limits) the
// motion stays inside the limits on every frame, always; fewer reaches succeed than in the
// middle of the range (measured on these 400 with the default limit handling, swings
// sliding along their ellipse: JT 278, NJT 373, SVD 373, DLS 375; with
// `LimitHandling::Clamp` instead: 273, 363, 358, 355; when swings on their ellipse were
// blocked outright: 247, 298, 321, 316). The floors sit a little under today's rates so a
// change that loses reaches is caught.
#[test]
fn reaches_across_the_whole_joint_range_stay_within_limits() {
    const CASES: usize = 400;
    for (kind, failed) in reach_random_targets(CASES, 1.0, 9) {
        let reached = CASES - failed.len();
        eprintln!("whole range of the limits, {kind}: reached {reached}/{CASES}");
        let floor = match kind {
            OptimizerKind::Jt => 265,
            OptimizerKind::Njt => 360,
            OptimizerKind::Svd => 360,
            OptimizerKind::Dls => 360,
        };
        assert!(reached >= floor, "{kind}: reached {reached} < {floor}");
    }
}

// Truth 2: a target beyond reach, in a direction the shoulder can point to, ends Stalled with
// the hand at the closest point of the workspace: the arm fully stretched along the
// shoulder → target line, c = shoulder + L·unit(target − shoulder). Starts are drawn from the
// middle 30% of every range, targets 1.2–2 L from the shoulder.
//
// Tolerance, per case: the stall rule stops once the error |target − hand| improves by less
// than `min_progress` (10 µm) per 0.25 s, and a lateral miss δ of the line costs only
// ≈ δ²/(2 e) of error (e = |target − c|): so δ up to √(2 e · min_progress) (2–4 mm here) is
// invisible to it (measured: at most 0.77 of that bound, SVD; DLS 0.28). Along the line the
// hand stays short of full extension by at most 1.5 mm (measured 0.83 mm, SVD: once the
// vanishing radial singular value drops below its 0.01 m/rad threshold the pseudo-inverse
// stops straightening the arm; DLS 2e-7 m).
//
// Success counts (measured, 200 cases each): DLS 200, JT 199, NJT 198, SVD 181. The SVD's
// failures are the pseudo-inverse's instability near the singular stretched arm: as the
// radial singular value σ crosses the threshold, the step rate·dt·e/σ jumps by up to
// 0.7 rad and the arm thrashes until the stall rule stops it (Buss 2004, the reason DLS
// exists). JT's and NJT's (cases 18, 111) swing the arm the long way round, away from the
// target, and stop with the shoulder on its swing ellipse and the elbow flexed.
#[test]
fn unreachable_targets_stall_at_the_closest_reachable_point() {
    const CASES: usize = 200;
    let min_progress = settings().stall.min_progress;
    for kind in OptimizerKind::ALL {
        let c = controller(kind, Synergy::identity(7));
        let mut rng = rng(21);
        let (mut failed, mut worst_lateral, mut worst_radial) = (Vec::new(), 0.0f64, 0.0f64);
        for case in 0..CASES {
            let chain = random_arm(&mut rng);
            let base = random_base(&mut rng);
            // A pointing direction inside 80% of the shoulder's swing ellipse.
            let swing = random_config(&chain, 0.8, &mut rng);
            let direction = base.rotation * (swing_rotation(swing[0], swing[1]) * Vector3::z());
            let shoulder = Point3::from(base.translation.vector);
            let length = reach_length(&chain);
            let target = shoulder + direction * length * rng.random_range(1.2..2.0);
            let start = random_config(&chain, 0.3, &mut rng);
            let m = synthesize(
                &c,
                &chain,
                &Base::Fixed(base),
                &start,
                Task::Position(target),
            );
            assert_within_limits(&chain, &m, &format!("{kind} case {case}"));
            let gap = (target - shoulder).norm() - length;
            // Nothing the arm does gets closer than the gap.
            assert!(m.final_error >= gap - 1e-9, "{kind} case {case}");
            let closest = shoulder + direction * length;
            let miss = m.end(m.frame_count() - 1) - closest;
            let radial = miss.dot(&direction).abs();
            let lateral = (miss - direction * miss.dot(&direction)).norm();
            let lateral_bound = (2.0 * gap * min_progress).sqrt();
            if m.stop == StopReason::Stalled && lateral <= lateral_bound && radial <= 1.5e-3 {
                worst_lateral = worst_lateral.max(lateral / lateral_bound);
                worst_radial = worst_radial.max(radial);
            } else {
                failed.push((case, m.stop, miss.norm()));
            }
        }
        eprintln!(
            "unreachable, {kind}: {}/{CASES} at the closest point (worst lateral {worst_lateral:.2} of its bound, radial {worst_radial:.1e} m); failed {failed:?}",
            CASES - failed.len()
        );
        let allowed = match kind {
            OptimizerKind::Dls => 0,
            OptimizerKind::Jt | OptimizerKind::Njt => CASES / 50,
            OptimizerKind::Svd => CASES * 15 / 100,
        };
        assert!(
            failed.len() <= allowed,
            "{kind}: {} of {CASES} missed the closest point (allowed {allowed}): {failed:?}",
            failed.len()
        );
    }
}

// Truth 3: the straight arm (q = 0) is singular (no radial motion); targets on its line
// beyond reach, short of it, behind the shoulder, or exactly at the tip never produce NaN or
// infinity with any optimizer, on an axis-aligned base (exact singularity) or rotated ones
// (singular up to rounding). Not asserted, seen: a target on the line short of reach is a
// stationary point of the error (Jᵀ ΔX = 0, and ΔX lies in J⁺'s dropped direction), so
// every optimizer stalls after 0.25 s without moving, even for the reachable 0.95 L.
#[test]
fn a_stretched_singular_arm_stays_finite() {
    let chain = arm();
    let length = reach_length(&chain);
    let mut rng = rng(3);
    let mut bases = vec![IsometryMatrix3::identity()];
    bases.extend((0..5).map(|_| random_base(&mut rng)));
    let straight = [0.0; 7];
    for kind in OptimizerKind::ALL {
        let c = controller(kind, Synergy::identity(7));
        for (b, base) in bases.iter().enumerate() {
            for along in [1.5, 1.05, 1.0, 0.95, 0.5, 0.0, -0.5] {
                let target = base * Point3::new(0.0, 0.0, length * along);
                let m = synthesize(
                    &c,
                    &chain,
                    &Base::Fixed(*base),
                    &straight,
                    Task::Position(target),
                );
                let what = format!("{kind}, base {b}, target at {along} L");
                assert_ne!(m.stop, StopReason::NonFinite, "{what}");
                assert!(all_finite(&m), "{what}");
                assert_within_limits(&chain, &m, &what);
                if along == 1.0 {
                    assert_eq!(
                        (m.stop, m.frame_count()),
                        (StopReason::Reached, 1),
                        "{what}"
                    );
                }
                if along > 1.0 {
                    // Already at the closest point: the hand stays at the tip.
                    let tip = base * Point3::new(0.0, 0.0, length);
                    assert!((m.end(m.frame_count() - 1) - tip).norm() < 1e-3, "{what}");
                }
            }
        }
    }
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

// Regression: the clamp after a step scaled a swing pushed out of its ellipse toward zero,
// which moved the swing's other DoF even when its gain was 0. Here shoulder_swing_y is
// frozen at 1.5 rad and the target pulls shoulder_swing_x onto the ellipse.
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
// 0.27 m away; when swings on their ellipse were blocked instead of sliding, they missed 9).
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
#[test]
fn bad_inputs_are_typed_errors() {
    let chain = arm();
    let base = Base::Fixed(IsometryMatrix3::identity());
    let start = [0.3, -0.2, 0.1, 1.0, 0.2, 0.1, 0.0];
    let target = Task::Position(Point3::new(0.1, -0.2, 0.45));
    let run = |c: &Controller, start: &[f64], task: Task| {
        c.synthesize(&ArmTask {
            chain: &chain,
            base: &base,
            start,
            task,
        })
    };
    let three = controller(OptimizerKind::Svd, Synergy::identity(3));
    match run(&three, &start, target) {
        Err(SolverError::Setting { field, why }) => {
            assert_eq!(field, "synergy");
            assert!(why.contains('3') && why.contains('7'), "{why}");
        }
        other => panic!("expected a Setting error, got {other:?}"),
    }
    let c = controller(OptimizerKind::Svd, Synergy::identity(7));
    let nan = Task::Position(Point3::new(0.1, f64::NAN, 0.45));
    assert!(matches!(
        run(&c, &start, nan),
        Err(SolverError::NonFinite(_))
    ));
    let nan_pose = Task::Pose {
        position: Point3::new(0.1, -0.2, 0.45),
        orientation: UnitQuaternion::new_unchecked(kinergy_motion::nalgebra::Quaternion::new(
            f64::NAN,
            0.0,
            0.0,
            0.0,
        )),
        weight: 0.2,
    };
    assert!(matches!(
        run(&c, &start, nan_pose),
        Err(SolverError::NonFinite(_))
    ));
    assert!(matches!(
        run(&c, &start[..6], target),
        Err(SolverError::Motion(MotionError::PoseLength {
            expected: 7,
            found: 6
        }))
    ));
    let mut nan_start = start;
    nan_start[3] = f64::NAN;
    assert!(matches!(
        run(&c, &nan_start, target),
        Err(SolverError::NonFinite(_))
    ));
    assert!(run(&c, &start, target).is_ok());
}

// Truth 7: a swing on its ellipse, pushed further out by a target beyond its limit, slides
// along the ellipse (default `LimitHandling::Deactivate`) to the reachable point closest to
// the target — found independently by sampling the ellipse densely — instead of freezing
// where it first touched the limit.
#[test]
fn a_swing_on_its_limit_slides_to_the_closest_reachable_point() {
    let (rx, ry) = (1.0, 0.5);
    let chain = Chain::new(
        vec![kinergy_motion::ChainJoint::new(
            "shoulder",
            Vector3::zeros(),
            vec![Motion::Swing { rx, ry }],
        )],
        Vector3::new(0.0, 0.0, 0.5),
    )
    .expect("chain");
    let base = IsometryMatrix3::identity();
    let on_ellipse = |a: f64| [rx * a.cos(), ry * a.sin()];
    let hand = |q: &[f64]| chain.end_position(&base, q).expect("fk");
    let start = on_ellipse(0.2);
    for (b, beyond) in [(1.2, 1.3), (2.0, 1.2), (-0.9, 1.25)] {
        let g = on_ellipse(b);
        let target = hand(&[g[0] * beyond, g[1] * beyond]);
        let closest = (0..20_000)
            .map(|i| {
                (hand(&on_ellipse(i as f64 * std::f64::consts::TAU / 20_000.0)) - target).norm()
            })
            .fold(f64::INFINITY, f64::min);
        for kind in [OptimizerKind::Njt, OptimizerKind::Svd, OptimizerKind::Dls] {
            let m = synthesize(
                &controller(kind, Synergy::identity(2)),
                &chain,
                &Base::Fixed(base),
                &start,
                Task::Position(target),
            );
            assert_within_limits(&chain, &m, &format!("{kind} b = {b}"));
            let end = last(&m);
            let e = (end[0] / rx).powi(2) + (end[1] / ry).powi(2);
            assert!(
                m.final_error < closest + 1e-3,
                "{kind} b = {b}: ended {} m from the target, {closest} m is reachable ({:?}, e = {e})",
                m.final_error,
                m.stop
            );
            assert!(
                (e - 1.0).abs() < 1e-6,
                "{kind} b = {b}: ended off the ellipse (e = {e})"
            );
        }
    }
}
