//! Integration tests of the synergy controller on the 7-DoF arm (DESIGN §1.1): every optimizer
//! reaches what is reachable and stops at the closest point of what is not, singular postures
//! stay finite, and the synergy models S_A–S_D shape the motion exactly as their formulas say.
//!
//! Every case is drawn from a seeded generator, so a failure names a case that reproduces.

use approx::assert_relative_eq;
use kinergy_motion::nalgebra::{IsometryMatrix3, Point3, UnitQuaternion, Vector3};
use kinergy_motion::rotation::swing_rotation;
use kinergy_motion::{Chain, Motion, MotionError};
use kinergy_solver::{
    ArmTask, Base, Controller, OptimizerKind, SolverError, StopReason, Synergy, Synthesis, Task,
};
use rand::RngExt;

mod controller_support;

use controller_support::{
    arm, assert_within_limits, controller, last, random_arm, random_base, random_config, rng,
    settings, synthesize,
};
/// Upper arm + forearm + hand.
fn reach_length(chain: &Chain) -> f64 {
    chain.joints()[1..]
        .iter()
        .map(|j| j.offset.norm())
        .sum::<f64>()
        + chain.end_effector().norm()
}
fn all_finite(m: &Synthesis) -> bool {
    m.configurations.iter().all(|v| v.is_finite())
        && m.points
            .iter()
            .all(|p| p.coords.iter().all(|v| v.is_finite()))
        && m.final_error.is_finite()
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
// `LimitHandling::Clamp` instead: 273, 363, 358, 355; with swings on their ellipse blocked
// outright: 247, 298, 321, 316). The floors sit a little under the default's rates so a
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
            start_velocity: None,
        })
    };
    let three = controller(OptimizerKind::Svd, Synergy::identity(3));
    match run(&three, &start, target) {
        Err(SolverError::Setting(e)) => {
            assert_eq!(e.field, "synergy");
            assert!(e.why.contains('3') && e.why.contains('7'), "{}", e.why);
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
