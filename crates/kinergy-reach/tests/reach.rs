//! Scenario tests of the full-body reach (Huang's Fig. 4 situations), checked on the output.

use kinergy_motion::nalgebra::{Point2, Point3};
use kinergy_reach::character::{Character, joint};
use kinergy_reach::controller::{ReachMotion, ReachSettings, ReachStop, reach_full_body};

fn character() -> Character {
    Character::from_height(1.75).expect("character")
}

fn run(target: [f64; 3], settings: &ReachSettings) -> ReachMotion {
    reach_full_body(
        &character(),
        Point3::new(target[0], target[1], target[2]),
        settings,
    )
    .expect("reach")
}

/// Checks every frame: limits, planted feet, balance; returns the largest planted-foot slide.
fn check_motion(c: &Character, m: &ReachMotion, what: &str) -> f64 {
    let mut slide: f64 = 0.0;
    let first = c.foot_points(&m.poses[0]);
    let mut prev = first;
    for (i, pose) in m.poses.iter().enumerate() {
        c.joint_limits_ok(pose)
            .unwrap_or_else(|e| panic!("{what}: frame {i}: {e}"));
        let feet = c.foot_points(pose);
        for k in 0..4 {
            // A foot point on the ground in two consecutive frames is planted: it must not slide.
            if feet[k].y.abs() < 1e-6 && prev[k].y.abs() < 1e-6 {
                slide = slide.max((feet[k] - prev[k]).norm());
            }
        }
        prev = feet;
        let com = c.com(pose);
        let margin = c.support_polygon(pose).margin(Point2::new(com.x, com.z));
        assert!(
            margin > -1e-9,
            "{what}: frame {i}: COM {margin} m outside the support polygon"
        );
    }
    slide
}

fn hand(c: &Character, m: &ReachMotion) -> Point3<f64> {
    let pose = m.poses.last().expect("frames");
    let p = c.world_positions(pose);
    if m.report.arm == "left_arm" {
        p[joint::LEFT_HAND_END]
    } else {
        p[joint::RIGHT_HAND_END]
    }
}

/// Every scenario's motion: within limits, planted feet still, COM over the support polygon.
fn checked(target: [f64; 3], settings: &ReachSettings, what: &str) -> ReachMotion {
    let c = character();
    let m = run(target, settings);
    let slide = check_motion(&c, &m, what);
    assert!(slide <= 1e-3, "{what}: a planted foot slid {slide} m");
    m
}

#[test]
fn a_target_inside_the_crr_needs_no_step() {
    for seed in 0..10 {
        let m = checked(
            [0.25, 1.1, 0.35],
            &ReachSettings {
                seed,
                ..ReachSettings::default()
            },
            "near",
        );
        assert_eq!(m.report.step, "none");
        assert_eq!(m.report.stop, ReachStop::Reached, "{:?}", m.report);
        assert!(m.report.final_error < 0.01);
    }
}

#[test]
fn a_target_beyond_the_mrr_makes_a_step_toward_it() {
    let c = character();
    for seed in 0..6 {
        let m = checked(
            [0.2, 1.0, 1.15],
            &ReachSettings {
                seed,
                ..ReachSettings::default()
            },
            "far",
        );
        assert_ne!(m.report.step, "none", "{:?}", m.report);
        assert!(m.report.step_length > 0.1);
        // The feet moved toward the target (+z).
        let (a, b) = (
            c.foot_points(&m.poses[0]),
            c.foot_points(m.poses.last().expect("frames")),
        );
        let mean_z = |f: &[Point3<f64>; 4]| f.iter().map(|p| p.z).sum::<f64>() / 4.0;
        assert!(mean_z(&b) > mean_z(&a) + 0.05, "{:?}", m.report);
    }
}

/// Issue 43: a low far target is reached by every body — the flexible one squats (after the
/// step the paper's state machine draws), the stiff one (which the paper has stoop) steps toward it, stoops, and squats only
/// as far as the step and the stoop leave it short (0.30 m for this one) — each within
/// a centimetre, feet planted, the balance held (`checked`). Before the posture search the
/// stiff body stooped 90°, took no step and ended 0.33 m short; at flexibility 0.7 it squatted
/// 0.18 m and ended 0.19 m short.
#[test]
fn a_low_far_target_squats_when_flexible_and_steps_and_stoops_when_stiff() {
    let reached = |m: &ReachMotion, what: &str| {
        assert_eq!(m.report.stop, ReachStop::Reached, "{what}: {:?}", m.report);
        assert!(m.report.final_error <= 0.01, "{what}: {:?}", m.report);
        assert!(m.report.min_balance_margin >= 0.0, "{what}: {:?}", m.report);
    };
    let flexible = checked(
        [0.2, 0.15, 0.8],
        &ReachSettings {
            flexibility: 3.0,
            seed: 1,
            ..ReachSettings::default()
        },
        "flexible",
    );
    assert_eq!(flexible.report.posture, "squat", "{:?}", flexible.report);
    assert!(flexible.report.squat_m > 0.1);
    reached(&flexible, "flexible");
    for flexibility in [0.5, 0.7] {
        let stiff = checked(
            [0.2, 0.15, 0.8],
            &ReachSettings {
                flexibility,
                seed: 1,
                ..ReachSettings::default()
            },
            "stiff",
        );
        reached(&stiff, &format!("flexibility {flexibility}"));
        assert_ne!(stiff.report.step, "none", "{:?}", stiff.report);
        assert!(stiff.report.swing_deg.abs() > 10.0);
    }
    // Lower and nearer: 0.095 m short before.
    let low = checked(
        [0.2, 0.3, 0.5],
        &ReachSettings {
            flexibility: 0.5,
            seed: 1,
            ..ReachSettings::default()
        },
        "low near",
    );
    reached(&low, "low near");
}

// A high lateral target (above the start swing distance, beyond a comfortable 90 % of the
// arm from the shoulder): the spine twists toward it. From where the paper's decisions leave
// the body the hand cannot reach it — the 0-DoF clavicle and the shoulder's 130° × 100° swing
// ellipse stop the arm short of overhead — so the posture search steps toward it (Huang's
// Fig. 4h, stepping and swinging up to a high apple), and the hand gets there.
#[test]
fn a_high_lateral_target_twists_steps_and_is_reached() {
    let m = checked(
        [0.7, 2.0, 0.2],
        &ReachSettings {
            seed: 2,
            ..ReachSettings::default()
        },
        "high lateral",
    );
    assert!(m.report.twist_deg > 1.0, "{:?}", m.report);
    assert_ne!(m.report.step, "none", "{:?}", m.report);
    assert_eq!(m.report.stop, ReachStop::Reached, "{:?}", m.report);
    assert!(m.report.final_error <= 0.01, "{:?}", m.report);
}

#[test]
fn reachable_targets_are_reached_within_a_centimeter() {
    let c = character();
    for (i, target) in [
        [0.25, 1.1, 0.35],
        [-0.3, 1.3, 0.3],
        [0.1, 0.9, 0.5],
        [0.4, 1.4, 0.2],
        [-0.3, 1.2, -0.4],
        [0.0, 1.5, 0.45],
    ]
    .into_iter()
    .enumerate()
    {
        let m = checked(
            target,
            &ReachSettings {
                seed: i as u64,
                ..ReachSettings::default()
            },
            "reachable",
        );
        let error = (hand(&c, &m) - Point3::new(target[0], target[1], target[2])).norm();
        assert!(
            error < 0.01,
            "target {target:?}: {error} m ({:?})",
            m.report
        );
        assert_eq!(m.report.stop, ReachStop::Reached);
        assert!((error - m.report.final_error).abs() < 1e-9);
    }
}

#[test]
fn an_unreachable_target_says_so() {
    let m = checked(
        [0.3, 3.5, 0.3],
        &ReachSettings {
            timeout: 4.0,
            ..ReachSettings::default()
        },
        "unreachable",
    );
    assert_ne!(m.report.stop, ReachStop::Reached);
    assert!(m.report.final_error > 1.0);
}

#[test]
fn the_same_seed_gives_the_same_bvh_byte_for_byte() {
    let c = character();
    let dir = tempfile::tempdir().expect("tempdir");
    let write = |seed: u64, name: &str| {
        let m = run(
            [0.2, 1.0, 1.0],
            &ReachSettings {
                seed,
                ..ReachSettings::default()
            },
        );
        let clip = c.to_clip(&m.poses, m.frame_time).expect("clip");
        let path = dir.path().join(name);
        kinergy_motion::write_clip(&path, &clip, &Default::default()).expect("write");
        std::fs::read(path).expect("read")
    };
    assert_eq!(write(7, "a.bvh"), write(7, "b.bvh"));
}

#[test]
fn bad_settings_name_the_field() {
    let c = character();
    let e = reach_full_body(
        &c,
        Point3::new(0.0, f64::NAN, 0.0),
        &ReachSettings::default(),
    )
    .expect_err("nan")
    .to_string();
    assert!(e.contains("target"), "{e}");
    let e = reach_full_body(
        &c,
        Point3::new(0.0, 1.0, 0.3),
        &ReachSettings {
            flexibility: 0.0,
            ..ReachSettings::default()
        },
    )
    .expect_err("flexibility")
    .to_string();
    assert!(e.contains("flexibility"), "{e}");
}

/// Issue 43, item 2: a step is eq. 9's, with its random p, wherever the body holds it, and the
/// balance model shortens only the steps it cannot hold — no fixed cap. Between the cylinders
/// the steps vary as eq. 9 draws them (near the paper's 0.433 m on average); beyond the MRR
/// eq. 9 asks for l_max (0.633 m), which the balance model shortens to the longest the body
/// holds for the kind of step — longer than the old static cap (0.39 m) — every frame balanced
/// (`checked`). For this body: 18 steps in 40 seeds at mid-band, 15 as drawn (0.315–0.492 m),
/// 3 full steps shortened to 0.426 m, 0.408 m on average; beyond the MRR full steps of 0.425 m
/// and half steps of 0.564 m.
#[test]
fn steps_are_eq_9_s_where_the_body_holds_them_and_no_cap_shortens_them() {
    use kinergy_motion::Side;
    use kinergy_reach::steps::{self, StepSettings};
    use rand::SeedableRng;
    use rand::rngs::ChaCha8Rng;

    let c = character();
    let rest = c.world_positions(&c.rest_pose());
    let shoulder = rest[joint::LEFT_ARM];
    let a = c.proportions().arm(Side::Left);
    let settings = StepSettings::for_arm_length(a.upper_arm + a.forearm + a.hand).expect("steps");
    let hips = rest[joint::HIPS];
    // (target, whether eq. 9 asks for more than the body holds)
    let middle = 0.5 * (settings.d_c + settings.d_max);
    let targets = [
        (Point3::new(shoulder.x, 1.2, shoulder.z + middle), false),
        (Point3::new(shoulder.x, 1.0, shoulder.z + 1.3), true),
    ];
    for (target, beyond) in targets {
        let (mut drawn, mut shortened) = (Vec::new(), Vec::new());
        for seed in 0..40 {
            let settings_seeded = ReachSettings {
                seed,
                ..ReachSettings::default()
            };
            let m = checked([target.x, target.y, target.z], &settings_seeded, "eq. 9");
            assert_eq!(m.report.stop, ReachStop::Reached, "{:?}", m.report);
            let d = m.report.horizontal_distance;
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let side = steps::target_side(
                &hips,
                &Point3::new(0.0, 0.0, 1.0).coords,
                &target,
                Side::Left,
            );
            let decision = steps::decide(&settings, d, side, &mut rng);
            let p = steps::draw_p(&settings, &mut rng);
            assert_eq!(m.report.step, decision, "seed {seed}: {:?}", m.report);
            if !decision.steps() {
                continue;
            }
            let eq9 = steps::step_length(&settings, d, p).min(d - 0.5 * settings.d_c);
            let l = m.report.step_length;
            assert!(
                l <= eq9 + 1e-9,
                "seed {seed}: {l} m, longer than eq. 9's {eq9}"
            );
            if (l - eq9).abs() < 1e-9 {
                drawn.push(l);
            } else {
                shortened.push((m.report.step.name(), l));
            }
        }
        let all: Vec<f64> = drawn
            .iter()
            .copied()
            .chain(shortened.iter().map(|s| s.1))
            .collect();
        // The balance's limit: one length per kind of step (to the bisection's 5 mm; a half
        // step keeps the root over the planted foot longer), longer than the old static cap.
        for kind in ["full", "half_left", "half_right"] {
            let of: Vec<f64> = shortened
                .iter()
                .filter(|s| s.0 == kind)
                .map(|s| s.1)
                .collect();
            let (lo, hi) = of
                .iter()
                .fold((f64::INFINITY, 0.0f64), |(a, b), &l| (a.min(l), b.max(l)));
            assert!(
                of.is_empty() || (lo > 0.40 && hi - lo < 0.01),
                "{kind}: {of:?}"
            );
        }
        if beyond {
            assert_eq!((drawn.len(), shortened.len()), (0, 40), "{all:?}");
        } else {
            let mut distinct: Vec<i64> = drawn.iter().map(|l| (l * 1e4).round() as i64).collect();
            distinct.sort_unstable();
            distinct.dedup();
            assert!(all.len() >= 10, "{} steps in 40 seeds", all.len());
            assert!(
                drawn.len() * 5 >= all.len() * 3,
                "{drawn:?} as drawn, {shortened:?} shortened"
            );
            assert!(distinct.len() >= 8, "{drawn:?}");
            // Eq. 9 at the middle of the band is the paper's default on average.
            let mean = all.iter().sum::<f64>() / all.len() as f64;
            assert!(
                (mean - steps::PAPER_STEP_LENGTH).abs() < 0.04,
                "mean {mean}: {all:?}"
            );
        }
    }
}
