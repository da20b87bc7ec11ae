//! Integration tests of the analytic limb IK (DESIGN §1.3, Kallmann 2005 after Tolani &
//! Badler). The truth is always the chain's own forward kinematics ([`Chain::fk`]) and limit
//! test ([`Chain::within_limits`]), never the solver's algebra: goals are FK of random
//! in-limit configurations, answers go back through FK.
//!
//! Every case is drawn from a seeded generator, so a failure names a case that reproduces.

use std::f64::consts::{FRAC_PI_2, PI};

use approx::assert_relative_eq;
use kinergy_motion::nalgebra::{IsometryMatrix3, Point3, Rotation3, Translation3, Vector3};
use kinergy_motion::rotation::{Axis, axis_rotation, unwrap_near};
use kinergy_motion::{Chain, ChainJoint, Motion};
use kinergy_solver::analytic::{AnalyticError, LimbDof, LimbIk, OrbitSearch, OrbitSense};
use proptest::prelude::*;
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

type Rng = Xoshiro256PlusPlus;

const UPPER: f64 = 0.30;
const FORE: f64 = 0.26;
const HAND: f64 = 0.09;
/// The round-trip tolerance of the brief: meters and rotation-matrix entries.
const EXACT: f64 = 1e-9;

fn arm() -> Chain {
    Chain::arm(UPPER, FORE, HAND).expect("arm")
}

/// A leg: the arm's structure with a hip offset, a knee that flexes negatively, narrower
/// limits and a foot offset off the bone axis (so position mode takes the non-planar path).
fn leg() -> Chain {
    let rev = |axis, min: f64, max: f64| Motion::Revolute { axis, min, max };
    Chain::new(
        vec![
            ChainJoint::new(
                "hip",
                Vector3::new(0.09, -0.05, 0.02),
                vec![Motion::Swing { rx: 1.6, ry: 0.7 }, rev(Axis::Z, -0.7, 0.9)],
            ),
            ChainJoint::new(
                "knee",
                Vector3::new(0.0, 0.0, 0.44),
                vec![rev(Axis::X, -2.4, 0.0), rev(Axis::Z, -0.3, 0.3)],
            ),
            ChainJoint::new(
                "ankle",
                Vector3::new(0.0, 0.0, 0.41),
                vec![Motion::Swing { rx: 0.8, ry: 0.5 }],
            ),
        ],
        Vector3::new(0.02, 0.11, 0.06),
    )
    .expect("leg")
}

fn base() -> IsometryMatrix3<f64> {
    IsometryMatrix3::identity()
}

/// A random configuration within `ik`'s limits: swings uniform in their ellipse.
fn random_q(rng: &mut Rng, ik: &LimbIk) -> [f64; 7] {
    let l = ik.limits();
    let mut swing = |(rx, ry): (f64, f64)| loop {
        let (a, b): (f64, f64) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        if a * a + b * b <= 1.0 {
            break (a * rx, b * ry);
        }
    };
    let (sx, sy) = swing(l.shoulder_swing);
    let (wx, wy) = swing(l.wrist_swing);
    let mut rev = |(lo, hi): (f64, f64)| rng.random_range(lo..hi);
    [
        sx,
        sy,
        rev(l.shoulder_twist),
        rev(l.elbow_flexion),
        rev(l.elbow_twist),
        wx,
        wy,
    ]
}

/// The goal FK gives: end-effector position and wrist-frame orientation.
fn goal_of(chain: &Chain, q: &[f64]) -> IsometryMatrix3<f64> {
    let pose = chain.fk(&base(), q).expect("fk");
    IsometryMatrix3::from_parts(Translation3::from(pose.end.coords), pose.frames[2].rotation)
}

/// Position error (m) and largest rotation-matrix entry error between FK(q) and `goal`.
fn pose_error(chain: &Chain, q: &[f64], goal: &IsometryMatrix3<f64>) -> (f64, f64) {
    let reached = goal_of(chain, q);
    let dp = (reached.translation.vector - goal.translation.vector).norm();
    let dr = (reached.rotation.matrix() - goal.rotation.matrix()).amax();
    (dp, dr)
}

fn assert_reaches(chain: &Chain, q: &[f64], goal: &IsometryMatrix3<f64>, what: &str) {
    assert!(q.iter().all(|v| v.is_finite()), "{what}: {q:?}");
    let (dp, dr) = pose_error(chain, q, goal);
    assert!(
        dp <= EXACT && dr <= EXACT,
        "{what}: position {dp:e} m, rotation {dr:e}"
    );
}

/// The joint positions (shoulder, elbow, wrist, end) of `q`, by FK.
fn joints(chain: &Chain, q: &[f64]) -> [Point3<f64>; 4] {
    let pose = chain.fk(&base(), q).expect("fk");
    [
        pose.joint_position(0),
        pose.joint_position(1),
        pose.joint_position(2),
        pose.end,
    ]
}

/// The orbit angle of a posture measured from its FK joint positions alone: the elbow's
/// direction about the shoulder→`tip` axis (2: wrist, 3: end effector), from the projection
/// of `down`, right-handed.
fn measured_alpha(chain: &Chain, q: &[f64], down: &Vector3<f64>, tip: usize) -> f64 {
    let [s, e, ..] = joints(chain, q);
    let w = joints(chain, q)[tip];
    let n = (w - s).normalize();
    let project = |r: Vector3<f64>| (r - n * n.dot(&r)).normalize();
    let m = project(e - s);
    let u = project(*down);
    let v = n.cross(&u);
    m.dot(&v).atan2(m.dot(&u))
}

fn angle_gap(a: f64, b: f64) -> f64 {
    (unwrap_near(a, b) - b).abs()
}

fn limbs() -> [(&'static str, Chain, LimbIk); 2] {
    let arm = arm();
    let leg = leg();
    let arm_ik = LimbIk::new(&arm).expect("arm ik");
    let leg_ik = LimbIk::new(&leg)
        .expect("leg ik")
        .with_down(Vector3::new(0.0, 0.0, -1.0))
        .expect("down");
    [("arm", arm, arm_ik), ("leg", leg, leg_ik)]
}

#[test]
fn solve_at_alpha_of_gives_back_the_configuration() {
    for (name, chain, ik) in limbs() {
        let mut rng = Rng::seed_from_u64(11);
        let (mut worst_pose, mut worst_q) = (0.0f64, 0.0f64);
        for case in 0..5000 {
            let q = random_q(&mut rng, &ik);
            let goal = goal_of(&chain, &q);
            let back = ik.solve(&goal, ik.alpha_of(&q)).expect("reachable");
            let what = format!("{name} case {case}, q = {q:?}");
            assert_reaches(&chain, &back, &goal, &what);
            let (dp, dr) = pose_error(&chain, &back, &goal);
            worst_pose = worst_pose.max(dp).max(dr);
            // Unique away from the singularities: swings below π (the limits keep them there)
            // and a bent elbow (the flexion's acos loses digits as f → 0).
            if q[3].abs() > 1e-3 {
                for (a, b) in back.iter().zip(&q) {
                    worst_q = worst_q.max((a - b).abs());
                    assert!((a - b).abs() <= EXACT, "{what}: got {back:?}");
                }
            }
            for (a, b) in joints(&chain, &back).iter().zip(joints(&chain, &q)) {
                assert!((a - b).norm() <= EXACT, "{what}: joints differ");
            }
        }
        eprintln!("{name}: worst pose error {worst_pose:e}, worst joint error {worst_q:e}");
    }
}

#[test]
fn a_flexion_against_the_bend_sign_keeps_the_joint_positions() {
    // An arm whose elbow may also bend the other way (−30°…150°, σ = +1): a posture with a
    // negative flexion comes back as its mirror (shoulder twisted by π, flexion positive)
    // with the elbow, wrist and hand where they were.
    let mut joints_ = arm().joints().to_vec();
    joints_[1].motions[0] = Motion::Revolute {
        axis: Axis::X,
        min: -0.5,
        max: 2.6,
    };
    let chain = Chain::new(joints_, Vector3::new(0.0, 0.0, HAND)).expect("chain");
    let ik = LimbIk::new(&chain).expect("ik");
    assert_eq!(ik.bend_sign(), 1.0);
    let q = [0.4, -0.3, 0.2, -0.45, 0.3, 0.2, 0.1];
    let goal = goal_of(&chain, &q);
    let back = ik.solve(&goal, ik.alpha_of(&q)).expect("reachable");
    assert_reaches(&chain, &back, &goal, "mirrored elbow");
    assert_relative_eq!(back[3], 0.45, epsilon = 1e-12);
    for (a, b) in joints(&chain, &back).iter().zip(joints(&chain, &q)) {
        assert!((a - b).norm() <= EXACT, "{a} vs {b}");
    }
}

#[test]
fn every_alpha_reproduces_the_goal_with_the_elbow_at_alpha() {
    for (name, chain, ik) in limbs() {
        let mut rng = Rng::seed_from_u64(12);
        let down = ik.down().into_inner();
        for case in 0..3000 {
            let q = random_q(&mut rng, &ik);
            let goal = goal_of(&chain, &q);
            let alpha = rng.random_range(-PI..PI);
            let back = ik.solve(&goal, alpha).expect("reachable at every α");
            let what = format!("{name} case {case}, α = {alpha}, q = {q:?}");
            assert_reaches(&chain, &back, &goal, &what);
            assert!(angle_gap(ik.alpha_of(&back), alpha) <= 1e-9, "{what}");
            // Where the elbow is off the axis, FK's own elbow says the same.
            if back[3].abs() > 1e-3 {
                let measured = measured_alpha(&chain, &back, &down, 2);
                assert!(
                    angle_gap(measured, alpha) <= 1e-8,
                    "{what}: elbow at {measured}"
                );
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 512,
        failure_persistence: Some(Box::new(proptest::test_runner::FileFailurePersistence::WithSource("proptest-regressions"))),
        ..ProptestConfig::default()
    })]
    #[test]
    fn fk_of_ik_is_the_identity_on_reachable_goals(
        s in (-1.0f64..1.0, -1.0f64..1.0), t in -1.5f64..1.5, f in 0.0f64..2.6, u in -1.5f64..1.5,
        w in (-1.0f64..1.0, -1.0f64..1.0), alpha in -3.1f64..3.1,
    ) {
        // Limits do not matter to `solve`: the whole box, ellipses or not.
        let chain = arm();
        let ik = LimbIk::new(&chain).expect("ik");
        let q = [2.2 * s.0, 1.7 * s.1, t, f, u, 1.2 * w.0, 0.5 * w.1];
        let goal = goal_of(&chain, &q);
        let back = ik.solve(&goal, alpha).expect("reachable");
        let (dp, dr) = pose_error(&chain, &back, &goal);
        prop_assert!(dp <= EXACT && dr <= EXACT, "position {dp:e}, rotation {dr:e}");
    }
}

#[test]
fn search_returns_only_postures_within_the_chain_limits() {
    let settings = OrbitSearch::default();
    let tried: Vec<f64> = settings.alphas().expect("valid").collect();
    for (name, chain, ik) in limbs() {
        let mut rng = Rng::seed_from_u64(13);
        let (mut found, mut in_range, mut found_in_range) = (0, 0, 0);
        const N: usize = 4000;
        for case in 0..N {
            let q = random_q(&mut rng, &ik);
            let goal = goal_of(&chain, &q);
            let alpha_q = ik.alpha_of(&q);
            let range = (settings.min..=settings.max).contains(&alpha_q);
            in_range += usize::from(range);
            match ik.search(&goal, &settings) {
                Ok((alpha, back)) => {
                    let what = format!("{name} case {case}, α = {alpha}");
                    // The first angle, in the search's order, whose posture the chain accepts.
                    let first = tried
                        .iter()
                        .copied()
                        .find(|&a| chain.within_limits(&ik.solve(&goal, a).expect("reachable")));
                    assert_eq!(Some(alpha), first, "{what}");
                    assert!(chain.within_limits(&back), "{what}: {back:?}");
                    assert!(ik.within_limits(&back), "{what}");
                    assert!(tried.contains(&alpha), "{what}: not a searched angle");
                    assert_reaches(&chain, &back, &goal, &what);
                    found += 1;
                    found_in_range += usize::from(range);
                }
                Err(AnalyticError::LimitsViolated {
                    best_alpha,
                    dof,
                    excess,
                    tried: n,
                }) => {
                    assert_eq!(n, tried.len());
                    assert!(tried.contains(&best_alpha));
                    assert!(excess > 0.0);
                    let best = ik.solve(&goal, best_alpha).expect("reachable");
                    let v = ik.violation(&best).expect("violated");
                    assert_eq!((v.dof, v.excess), (dof, excess));
                    assert!(!chain.within_limits(&best));
                    // No searched angle was within limits, by the chain's own test.
                    for &a in &tried {
                        let p = ik.solve(&goal, a).expect("reachable");
                        assert!(!chain.within_limits(&p), "{name} case {case}: α = {a} fits");
                    }
                }
                Err(e) => panic!("{name} case {case}: {e}"),
            }
        }
        eprintln!(
            "{name}: search found {found}/{N}; {found_in_range}/{in_range} of the goals whose generating α lies in [−15°, 130°]"
        );
        // The generating posture fits at its own α; the search samples the range only.
        assert!(found_in_range as f64 >= 0.9 * in_range as f64, "{name}");
    }
}

/// The first goal (FK of a random in-limit arm posture) whose postures are within the chain's
/// limits at `want` or more of the default search's angles, with those angles in order.
fn goal_fitting_at(want: usize) -> (IsometryMatrix3<f64>, Vec<f64>) {
    let chain = arm();
    let ik = LimbIk::new(&chain).expect("ik");
    let alphas: Vec<f64> = OrbitSearch::default().alphas().expect("valid").collect();
    let mut rng = Rng::seed_from_u64(16);
    loop {
        let goal = goal_of(&chain, &random_q(&mut rng, &ik));
        let fits: Vec<f64> = alphas
            .iter()
            .copied()
            .filter(|&a| chain.within_limits(&ik.solve(&goal, a).expect("reachable")))
            .collect();
        if fits.len() >= want && (want > 1 || fits[0] == alphas[0]) {
            return (goal, fits);
        }
    }
}

#[test]
fn search_starts_at_twenty_degrees_when_that_fits() {
    let ik = LimbIk::new(&arm()).expect("ik");
    let (goal, _) = goal_fitting_at(1);
    let (alpha, back) = ik.search(&goal, &OrbitSearch::default()).expect("found");
    assert_eq!(alpha, 20f64.to_radians());
    assert_eq!(back, ik.solve(&goal, alpha).expect("reachable"));
}

#[test]
fn search_with_a_predicate_skips_rejected_postures() {
    let chain = arm();
    let ik = LimbIk::new(&chain).expect("ik");
    let (goal, fits) = goal_fitting_at(3);
    let settings = OrbitSearch::default();
    // Reject the first posture that fits: the search goes on to the second.
    let first = ik.solve(&goal, fits[0]).expect("reachable");
    let accept = |p: &[f64; 7]| *p != first;
    let (alpha, back) = ik.search_with(&goal, &settings, &accept).expect("found");
    assert_eq!(alpha, fits[1]);
    assert!(chain.within_limits(&back));
    match ik.search_with(&goal, &settings, &|_| false) {
        Err(AnalyticError::Rejected {
            within_limits,
            tried,
        }) => {
            assert_eq!(within_limits, fits.len());
            assert_eq!(tried, settings.alphas().expect("valid").count());
        }
        other => panic!("expected Rejected, got {other:?}"),
    }
}

#[test]
fn alpha_zero_is_the_lowest_elbow_and_it_rises_with_alpha() {
    for (name, chain, ik) in limbs() {
        let up = -ik.down().into_inner();
        let mut rng = Rng::seed_from_u64(14);
        for case in 0..200 {
            let q = random_q(&mut rng, &ik);
            if q[3].abs() < 0.2 {
                continue; // a nearly straight elbow barely moves
            }
            let goal = goal_of(&chain, &q);
            let height = |alpha: f64| {
                let p = ik.solve(&goal, alpha).expect("reachable");
                joints(&chain, &p)[1].coords.dot(&up)
            };
            let steps = 180;
            let rising: Vec<f64> = (0..=steps)
                .map(|i| height(PI * i as f64 / steps as f64))
                .collect();
            let falling: Vec<f64> = (0..=steps)
                .map(|i| height(-PI * i as f64 / steps as f64))
                .collect();
            for h in [&rising, &falling] {
                for w in h.windows(2) {
                    assert!(
                        w[1] > w[0] - 1e-12,
                        "{name} case {case}: the elbow drops: {h:?}"
                    );
                }
                assert!(h[steps] > h[0] + 1e-3, "{name} case {case}");
            }
            // Symmetric about α = 0: mirror angles give the same height.
            for (a, b) in rising.iter().zip(&falling) {
                assert_relative_eq!(a, b, epsilon = 1e-9);
            }
        }
    }
}

#[test]
fn positive_alpha_turns_the_elbow_outward_by_the_chosen_sense() {
    // Y-up, facing +z, arm forward along +z: +x is the body's left.
    let chain = arm();
    let q = [0.0, 0.0, 0.0, FRAC_PI_2, 0.0, 0.0, 0.0];
    let goal = goal_of(&chain, &q);
    let left = LimbIk::new(&chain).expect("ik");
    let right = left.clone().with_sense(OrbitSense::LeftHanded);
    let elbow = |ik: &LimbIk, alpha| joints(&chain, &ik.solve(&goal, alpha).expect("ok"))[1];
    let (l0, l90) = (elbow(&left, 0.0), elbow(&left, FRAC_PI_2));
    let r90 = elbow(&right, FRAC_PI_2);
    assert!(
        l0.y < 0.0 && l0.x.abs() < 1e-12,
        "α = 0 is straight down: {l0}"
    );
    assert!(l90.x > 0.1, "left arm: outward is +x, got {l90}");
    assert!(r90.x < -0.1, "right arm: outward is −x, got {r90}");
}

#[test]
fn unreachable_goals_say_how_far_they_are() {
    let chain = arm();
    let ik = LimbIk::new(&chain).expect("ik");
    let rot = Rotation3::identity();
    // Wrist center 1 m away, then 1 cm from the shoulder (inside |L1 − L2| = 4 cm).
    for (wrist, far) in [(1.0, true), (0.01, false)] {
        let goal = IsometryMatrix3::from_parts(Translation3::new(0.0, 0.0, wrist + HAND), rot);
        for result in [
            ik.solve(&goal, 0.3).map(|q| (0.3, q)),
            ik.search(&goal, &OrbitSearch::default()),
        ] {
            match result {
                Err(AnalyticError::Unreachable {
                    distance,
                    reach,
                    inner,
                }) => {
                    assert_relative_eq!(distance, wrist, epsilon = 1e-12);
                    assert_relative_eq!(reach, UPPER + FORE, epsilon = 1e-15);
                    assert_relative_eq!(inner, UPPER - FORE, epsilon = 1e-15);
                    assert_eq!(distance > reach, far);
                }
                other => panic!("expected Unreachable, got {other:?}"),
            }
        }
    }
    let far = Point3::new(0.0, 1.0, 0.0);
    assert!(matches!(
        ik.solve_position(&far, &OrbitSearch::default()),
        Err(AnalyticError::Unreachable { reach, .. }) if (reach - (UPPER + FORE + HAND)).abs() < 1e-15
    ));
}

#[test]
fn a_too_close_target_violates_the_elbow_flexion_at_every_alpha() {
    let chain = arm();
    let ik = LimbIk::new(&chain).expect("ik");
    // Position mode, hand in line with the forearm (a 35 cm distal link): a target 12 cm
    // below the shoulder needs ≈ 160° of flexion, past the 150° limit, whatever α.
    let d = 0.12;
    let target = Point3::new(0.0, -d, 0.0);
    let g = FORE + HAND;
    let flexion = ((d * d - UPPER * UPPER - g * g) / (2.0 * UPPER * g)).acos();
    assert!(flexion > 150f64.to_radians() + 0.1);
    match ik.solve_position(&target, &OrbitSearch::default()) {
        Err(AnalyticError::LimitsViolated { dof, excess, .. }) => {
            assert_eq!(dof, LimbDof::ElbowFlexion);
            assert_relative_eq!(excess, flexion - 150f64.to_radians(), epsilon = 1e-9);
        }
        other => panic!("expected LimitsViolated, got {other:?}"),
    }
}

#[test]
fn a_hand_turned_back_violates_the_wrist_swing() {
    let chain = arm();
    let ik = LimbIk::new(&chain).expect("ik");
    // Wrist center nearly stretched ahead, the hand pointing back at the shoulder: the wrist
    // would swing ≈ 180°, far past its 70° × 30° ellipse, at every α.
    let wrist = Vector3::new(0.0, 0.0, 0.54);
    let rot = axis_rotation(Axis::X, PI);
    let goal =
        IsometryMatrix3::from_parts(Translation3::from(wrist + rot * Vector3::z() * HAND), rot);
    match ik.search(&goal, &OrbitSearch::default()) {
        Err(AnalyticError::LimitsViolated { dof, .. }) => assert_eq!(dof, LimbDof::WristSwing),
        other => panic!("expected LimitsViolated, got {other:?}"),
    }
}

#[test]
fn the_stretched_limb_stays_finite_and_exact() {
    for (name, chain, ik) in limbs() {
        let q = [0.0; 7];
        let goal = goal_of(&chain, &q);
        for alpha in [-PI, -1.0, 0.0, 0.35, 2.0, PI] {
            let back = ik.solve(&goal, alpha).expect("on the boundary");
            assert_reaches(
                &chain,
                &back,
                &goal,
                &format!("{name} stretched, α = {alpha}"),
            );
            assert!(angle_gap(ik.alpha_of(&back), alpha) < 1e-9, "{name}");
        }
        // A few ulps beyond the reach still counts as the boundary; a micrometer does not.
        let mut beyond = goal;
        beyond.translation.vector += goal.rotation * Vector3::z() * 1e-14;
        assert!(ik.solve(&beyond, 0.0).is_ok(), "{name}");
        beyond.translation.vector += goal.rotation * Vector3::z() * 1e-6;
        assert!(
            matches!(
                ik.solve(&beyond, 0.0),
                Err(AnalyticError::Unreachable { .. })
            ),
            "{name}"
        );
        let stretched_target = joints(&chain, &q)[3];
        for alpha in [0.0, 1.0] {
            let p = ik
                .solve_position_at(&stretched_target, alpha)
                .expect("on the boundary");
            assert!(
                (joints(&chain, &p)[3] - stretched_target).norm() <= EXACT,
                "{name}"
            );
        }
    }
}

#[test]
fn a_target_at_the_shoulder_stays_finite() {
    // Equal links fold onto the shoulder: the axis is undefined, the answer still exact.
    let chain = Chain::arm(0.28, 0.28, 0.0).expect("arm");
    let ik = LimbIk::new(&chain).expect("ik");
    for rot in [Rotation3::identity(), axis_rotation(Axis::Y, 0.7)] {
        let goal = IsometryMatrix3::from_parts(Translation3::identity(), rot);
        for alpha in [0.0, 0.4, -2.0] {
            let q = ik.solve(&goal, alpha).expect("reachable: folded");
            assert_reaches(&chain, &q, &goal, "at the shoulder");
            assert!(ik.alpha_of(&q).is_finite());
        }
        // Folded by 180°, past the 150° flexion limit, at every α.
        assert!(matches!(
            ik.search(&goal, &OrbitSearch::default()),
            Err(AnalyticError::LimitsViolated { .. })
        ));
    }
    let origin = Point3::origin();
    let q = ik.solve_position_at(&origin, 0.0).expect("folded");
    assert!(joints(&chain, &q)[3].coords.norm() <= EXACT);
    // Unequal links: the shoulder is inside the inner radius.
    let ik = LimbIk::new(&arm()).expect("ik");
    let goal =
        IsometryMatrix3::from_parts(Translation3::new(0.0, 0.0, HAND), Rotation3::identity());
    assert!(matches!(
        ik.solve(&goal, 0.0),
        Err(AnalyticError::Unreachable { .. })
    ));
    assert!(matches!(
        ik.solve_position_at(&origin, 0.0),
        Err(AnalyticError::Unreachable { .. })
    ));
}

#[test]
fn an_axis_along_down_and_swings_of_pi_stay_exact() {
    let chain = arm();
    let ik = LimbIk::new(&chain).expect("ik");
    // Shoulder→wrist axis straight down: α = 0 falls back to a fixed reference.
    let down_q = [FRAC_PI_2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
    let goal = goal_of(&chain, &down_q);
    assert_relative_eq!(
        joints(&chain, &down_q)[2],
        Point3::new(0.0, -0.56, 0.0),
        epsilon = 1e-12
    );
    for alpha in [0.0, 1.0, -2.5] {
        let q = ik.solve(&goal, alpha).expect("reachable");
        assert_reaches(&chain, &q, &goal, "axis along down");
    }
    let bent_down = [FRAC_PI_2 + 0.5, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0];
    let goal = goal_of(&chain, &bent_down);
    for alpha in [0.0, 2.0] {
        let q = ik.solve(&goal, alpha).expect("reachable");
        assert_reaches(&chain, &q, &goal, "bent, axis near down");
    }
    // The shoulder swung by π (upper arm along −z) and the wrist folded back by π.
    for q in [
        [PI, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 0.0, 0.0, PI, 0.0],
        [0.0, PI, 0.3, 0.0, 0.2, 0.0, -PI],
    ] {
        let goal = goal_of(&chain, &q);
        for alpha in [0.0, 0.8] {
            let back = ik.solve(&goal, alpha).expect("reachable");
            assert_reaches(&chain, &back, &goal, &format!("swing π, q = {q:?}"));
        }
    }
}

/// `position_alpha_of` is position mode's own angle: solving a target again at the angle it
/// reads off a posture of position mode gives the posture back, for either sense of the orbit
/// (the reaching arm's orbit search starts there; `alpha_of`, about the wrist's axis, does
/// not give it back where the end effector is off the forearm's line).
#[test]
fn solve_position_at_position_alpha_of_gives_back_the_configuration() {
    for (name, chain, ik) in limbs() {
        for sense in [OrbitSense::RightHanded, OrbitSense::LeftHanded] {
            let ik = ik.clone().with_sense(sense);
            let mut rng = Rng::seed_from_u64(17);
            for case in 0..2000 {
                let mut q = random_q(&mut rng, &ik);
                q[4..].fill(0.0);
                let target = joints(&chain, &q)[3];
                let alpha = rng.random_range(-PI..PI);
                let p = ik.solve_position_at(&target, alpha).expect("reachable");
                let what = format!("{name} {sense:?} case {case}");
                let read = ik.position_alpha_of(&p).expect("position mode");
                let back = ik.solve_position_at(&target, read).expect("reachable");
                for (a, b) in joints(&chain, &back).iter().zip(joints(&chain, &p)) {
                    assert!((a - b).norm() <= EXACT, "{what}: joints differ");
                }
                // The angle itself, away from the straight limb where it has none.
                if p[3].abs() > 1e-3 {
                    assert!(angle_gap(read, alpha) < 1e-8, "{what}: {read} vs {alpha}");
                }
            }
        }
    }
}

#[test]
fn position_mode_lands_on_the_target_within_limits() {
    for (name, chain, ik) in limbs() {
        let mut rng = Rng::seed_from_u64(15);
        let down = ik.down().into_inner();
        let settings = OrbitSearch::default();
        let (mut found, n, mut in_range, mut found_in_range) = (0, 3000, 0, 0);
        for case in 0..n {
            // Reachable in position mode: the distal DoFs at their rest (zero).
            let mut q = random_q(&mut rng, &ik);
            q[4..].fill(0.0);
            let target = joints(&chain, &q)[3];
            let what = format!("{name} case {case}");
            // At any α (limits aside) the end effector lands exactly.
            let alpha = rng.random_range(-PI..PI);
            let p = ik.solve_position_at(&target, alpha).expect("reachable");
            assert!((joints(&chain, &p)[3] - target).norm() <= EXACT, "{what}");
            assert_eq!(&p[4..], &[0.0; 3], "{what}: the hand continues the forearm");
            assert!(
                angle_gap(measured_alpha(&chain, &p, &down, 3), alpha) < 1e-8,
                "{what}: α is the elbow's angle about the shoulder→target axis"
            );
            let range =
                (settings.min..=settings.max).contains(&measured_alpha(&chain, &q, &down, 3));
            in_range += usize::from(range);
            match ik.solve_position(&target, &settings) {
                Ok((_, p)) => {
                    assert!(chain.within_limits(&p), "{what}");
                    assert!((joints(&chain, &p)[3] - target).norm() <= EXACT, "{what}");
                    found += 1;
                    found_in_range += usize::from(range);
                }
                Err(AnalyticError::LimitsViolated { .. } | AnalyticError::Unreachable { .. }) => {}
                Err(e) => panic!("{what}: {e}"),
            }
        }
        eprintln!(
            "{name}: position mode found {found}/{n}; {found_in_range}/{in_range} of the targets whose generating α lies in [−15°, 130°]"
        );
        assert!(found_in_range as f64 >= 0.9 * in_range as f64, "{name}");
    }
}

#[test]
fn chains_of_another_structure_are_refused() {
    let rev = |axis| Motion::Revolute {
        axis,
        min: -1.0,
        max: 1.0,
    };
    let swing = || Motion::Swing { rx: 1.0, ry: 1.0 };
    let z = |l| Vector3::new(0.0, 0.0, l);
    let make = |shoulder: Vec<Motion>, elbow: Vec<Motion>, wrist: Vec<Motion>, elbow_at| {
        Chain::new(
            vec![
                ChainJoint::new("shoulder", Vector3::zeros(), shoulder),
                ChainJoint::new("elbow", elbow_at, elbow),
                ChainJoint::new("wrist", z(0.25), wrist),
            ],
            z(0.1),
        )
        .expect("chain")
    };
    let cases = [
        // k-style revolute shoulder.
        make(
            vec![rev(Axis::X), rev(Axis::Y), rev(Axis::Z)],
            vec![rev(Axis::X), rev(Axis::Z)],
            vec![swing()],
            z(0.3),
        ),
        // Elbow axes swapped.
        make(
            vec![swing(), rev(Axis::Z)],
            vec![rev(Axis::Z), rev(Axis::X)],
            vec![swing()],
            z(0.3),
        ),
        // Wrist with a twist.
        make(
            vec![swing(), rev(Axis::Z)],
            vec![rev(Axis::X), rev(Axis::Z)],
            vec![swing(), rev(Axis::Z)],
            z(0.3),
        ),
        // Elbow off the upper arm's axis.
        make(
            vec![swing(), rev(Axis::Z)],
            vec![rev(Axis::X), rev(Axis::Z)],
            vec![swing()],
            Vector3::new(0.01, 0.0, 0.3),
        ),
    ];
    for chain in cases {
        assert!(
            matches!(LimbIk::new(&chain), Err(AnalyticError::UnsupportedChain(_))),
            "{chain:?}"
        );
    }
    let two = Chain::new(
        vec![ChainJoint::new("a", Vector3::zeros(), vec![swing()])],
        z(0.1),
    )
    .expect("chain");
    assert!(matches!(
        LimbIk::new(&two),
        Err(AnalyticError::UnsupportedChain(_))
    ));
    let mut rested = arm().joints().to_vec();
    rested[1].rest = axis_rotation(Axis::Y, 0.1);
    let rested = Chain::new(rested, z(HAND)).expect("chain");
    assert!(matches!(
        LimbIk::new(&rested),
        Err(AnalyticError::UnsupportedChain(_))
    ));
}

#[test]
fn non_finite_inputs_are_refused() {
    let chain = arm();
    let ik = LimbIk::new(&chain).expect("ik");
    let goal = goal_of(&chain, &[0.3, 0.1, 0.0, 1.0, 0.0, 0.0, 0.0]);
    assert!(matches!(
        ik.solve(&goal, f64::NAN),
        Err(AnalyticError::NonFinite(_))
    ));
    let mut bad = goal;
    bad.translation.vector.x = f64::INFINITY;
    assert!(matches!(
        ik.solve(&bad, 0.0),
        Err(AnalyticError::NonFinite(_))
    ));
    assert!(matches!(
        ik.search(&bad, &OrbitSearch::default()),
        Err(AnalyticError::NonFinite(_))
    ));
    assert!(matches!(
        ik.solve_position_at(&Point3::new(f64::NAN, 0.0, 0.0), 0.0),
        Err(AnalyticError::NonFinite(_))
    ));
    assert!(matches!(
        ik.clone().with_down(Vector3::zeros()),
        Err(AnalyticError::Setting(_))
    ));
    assert!(matches!(
        ik.with_down(Vector3::new(0.0, f64::NAN, 0.0)),
        Err(AnalyticError::NonFinite(_))
    ));
}
