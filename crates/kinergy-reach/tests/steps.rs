//! The leg controller's decisions and paths (Huang et al. §3.5): reaching cylinders, step
//! and half-step probabilities, eq. 9, foot and root arcs.

use approx::assert_relative_eq;
use kinergy_motion::Side;
use kinergy_reach::ReachError;
use kinergy_reach::steps::{
    self, CRR_PER_ARM_LENGTH, MRR_PER_ARM_LENGTH, PAPER_STEP_LENGTH, StepDecision, StepSettings,
};
use nalgebra::{Point3, Vector3};
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};

fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

/// d at position x ∈ [0, 1] of the CRR–MRR band.
fn at(settings: &StepSettings, x: f64) -> f64 {
    settings.d_c + x * (settings.d_max - settings.d_c)
}

/// Eq. 9 exactly as printed.
fn eq9(s: &StepSettings, d: f64, p: f64) -> f64 {
    if d <= s.d_c {
        s.l_min
    } else if d >= s.d_max {
        s.l_max
    } else {
        (s.l_max * (d - s.d_c).abs() * p + s.l_min * (d - s.d_max).abs() * (1.0 - p))
            / ((d - s.d_c).abs() * p + (d - s.d_max).abs() * (1.0 - p))
    }
}

fn setting_field(err: ReachError) -> String {
    match err {
        ReachError::Setting(e) => e.field,
        other => panic!("expected a Setting error, got {other:?}"),
    }
}

#[test]
fn targets_inside_the_crr_never_step() {
    let settings = StepSettings::default();
    for d in [
        0.0,
        0.1,
        0.5 * settings.d_c,
        settings.d_c - 1e-9,
        settings.d_c,
    ] {
        for seed in 0..2_000 {
            let decision = steps::decide(&settings, d, Side::Right, &mut rng(seed));
            assert_eq!(decision, StepDecision::NoStep, "d = {d}, seed {seed}");
        }
        assert_eq!(steps::step_probability(&settings, d), 0.0);
    }
    assert_eq!(
        steps::decide(&settings, f64::NAN, Side::Right, &mut rng(1)),
        StepDecision::NoStep
    );
}

#[test]
fn targets_beyond_the_mrr_always_step() {
    let settings = StepSettings::default();
    for d in [settings.d_max, settings.d_max + 1e-9, 1.5, 10.0] {
        for seed in 0..2_000 {
            let decision = steps::decide(&settings, d, Side::Left, &mut rng(seed));
            assert!(decision.steps(), "d = {d}, seed {seed}");
        }
        assert_eq!(steps::step_probability(&settings, d), 1.0);
    }
}

#[test]
fn step_frequency_between_the_cylinders_rises_linearly() {
    let settings = StepSettings::default();
    let mut generator = rng(2024);
    for x in [0.05, 0.1, 0.25, 0.5, 0.75, 0.9, 0.97] {
        let d = at(&settings, x);
        assert_relative_eq!(
            steps::step_probability(&settings, d),
            x,
            max_relative = 1e-12
        );
        let draws = 20_000;
        let stepped = (0..draws)
            .filter(|_| steps::decide(&settings, d, Side::Right, &mut generator).steps())
            .count();
        let frequency = stepped as f64 / draws as f64;
        assert!((frequency - x).abs() < 0.02, "x = {x}: stepped {frequency}");
    }
}

#[test]
fn half_step_frequency_falls_linearly_from_p_max_to_p_min() {
    for (p_max, p_min) in [(0.9, 0.1), (0.7, 0.2), (1.0, 0.0), (0.5, 0.5)] {
        let settings = StepSettings {
            p_max,
            p_min,
            ..StepSettings::default()
        };
        let mut generator = rng(99);
        for x in [0.1, 0.3, 0.5, 0.8, 1.0, 1.5] {
            let d = at(&settings, x);
            let expected = p_max + (p_min - p_max) * x.min(1.0);
            assert_relative_eq!(
                steps::half_step_probability(&settings, d),
                expected,
                epsilon = 1e-12
            );
            // 20,000 steps (not draws), so the frequency's standard error is ≤ 0.0036.
            let (mut taken, mut half) = (0, 0);
            while taken < 20_000 {
                match steps::decide(&settings, d, Side::Left, &mut generator) {
                    StepDecision::NoStep => {}
                    StepDecision::HalfStep { .. } => {
                        taken += 1;
                        half += 1;
                    }
                    StepDecision::FullStep => taken += 1,
                }
            }
            let frequency = half as f64 / taken as f64;
            assert!(
                (frequency - expected).abs() < 0.02,
                "P_max {p_max}, P_min {p_min}, x = {x}: half {frequency} vs {expected}"
            );
        }
    }
}

#[test]
fn half_steps_move_the_foot_on_the_targets_side() {
    let settings = StepSettings::default();
    let d = at(&settings, 0.3);
    for side in [Side::Left, Side::Right] {
        let mut generator = rng(5);
        let mut seen = 0;
        for _ in 0..2_000 {
            if let StepDecision::HalfStep { foot } =
                steps::decide(&settings, d, side, &mut generator)
            {
                assert_eq!(foot, side);
                seen += 1;
            }
        }
        assert!(seen > 100);
    }
}

#[test]
fn the_same_seed_gives_the_same_decisions_and_draws_two_numbers_each() {
    let settings = StepSettings::default();
    let targets: Vec<f64> = (0..200).map(|i| 0.3 + 0.004 * i as f64).collect();
    let run = |seed: u64| {
        let mut generator = rng(seed);
        targets
            .iter()
            .map(|&d| {
                (
                    steps::decide(&settings, d, Side::Right, &mut generator),
                    steps::draw_p(&settings, &mut generator),
                )
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(run(11), run(11));
    assert_ne!(run(11), run(12));
    // Two uniform draws whatever the outcome: what follows does not depend on d.
    for d in [0.0, at(&settings, 0.5), 5.0] {
        let mut used = rng(3);
        steps::decide(&settings, d, Side::Right, &mut used);
        let mut fresh = rng(3);
        let _: (f64, f64) = (fresh.random(), fresh.random());
        assert_eq!(used.random::<u64>(), fresh.random::<u64>(), "d = {d}");
    }
}

#[test]
fn step_length_is_eq_9() {
    let settings = StepSettings::default();
    for x in [0.01, 0.2, 0.5, 0.77, 0.99] {
        let d = at(&settings, x);
        assert_eq!(steps::step_length(&settings, d, 0.0), settings.l_min);
        assert_eq!(steps::step_length(&settings, d, 1.0), settings.l_max);
        // p = ½: the linear interpolation in d.
        assert_relative_eq!(
            steps::step_length(&settings, d, 0.5),
            settings.l_min + x * (settings.l_max - settings.l_min),
            max_relative = 1e-12
        );
        for p in [0.0, 0.1, 0.3, 0.5, 0.64, 0.9, 1.0] {
            let l = steps::step_length(&settings, d, p);
            assert_relative_eq!(l, eq9(&settings, d, p), max_relative = 1e-14);
            assert!((settings.l_min..=settings.l_max).contains(&l));
        }
    }
    for p in [0.0, 0.5, 1.0] {
        assert_eq!(steps::step_length(&settings, 0.0, p), settings.l_min);
        assert_eq!(
            steps::step_length(&settings, settings.d_c, p),
            settings.l_min
        );
        assert_eq!(
            steps::step_length(&settings, settings.d_max, p),
            settings.l_max
        );
        assert_eq!(steps::step_length(&settings, 3.0, p), settings.l_max);
    }
}

#[test]
fn step_length_is_monotone_in_d_and_in_p() {
    let settings = StepSettings::default();
    for p in [0.0, 0.2, 0.5, 0.8, 1.0] {
        let mut previous = 0.0;
        for i in 0..=1_000 {
            let d = 1.2 * settings.d_max * i as f64 / 1_000.0;
            let l = steps::step_length(&settings, d, p);
            assert!(l >= previous, "p = {p}, d = {d}");
            previous = l;
        }
    }
    let d = at(&settings, 0.4);
    let mut previous = 0.0;
    for i in 0..=100 {
        let l = steps::step_length(&settings, d, i as f64 / 100.0);
        assert!(l >= previous);
        previous = l;
    }
}

#[test]
fn the_default_step_is_the_papers_0_433_m() {
    let settings = StepSettings::default();
    assert_eq!(PAPER_STEP_LENGTH, 0.433);
    // Mid band, mean p: eq. 9 gives the paper's default length.
    let mid = at(&settings, 0.5);
    assert_relative_eq!(
        steps::step_length(&settings, mid, settings.p_mean),
        0.433,
        max_relative = 1e-12
    );
    assert_relative_eq!(
        (settings.l_min + settings.l_max) / 2.0,
        0.433,
        max_relative = 1e-12
    );
}

#[test]
fn p_is_clamped_to_0_1() {
    let settings = StepSettings::default();
    for x in [0.2, 0.5, 0.8] {
        let d = at(&settings, x);
        assert_eq!(
            steps::step_length(&settings, d, -3.0),
            steps::step_length(&settings, d, 0.0)
        );
        assert_eq!(
            steps::step_length(&settings, d, 7.0),
            steps::step_length(&settings, d, 1.0)
        );
        for p in [-5.0, -0.5, 1.5, 5.0] {
            let l = steps::step_length(&settings, d, p);
            assert!((settings.l_min..=settings.l_max).contains(&l));
        }
    }
    // Why: unclamped, eq. 9 leaves [l_min, l_max]; at p = 1.5 its denominator
    // 1.5 |d − d_c| − 0.5 |d − d_max| changes sign at x = ¼.
    assert!(eq9(&settings, at(&settings, 0.2), 1.5) < 0.0);
    assert!(eq9(&settings, at(&settings, 0.8), 1.5) > settings.l_max);
}

#[test]
fn draw_p_is_a_clamped_normal() {
    let settings = StepSettings::default();
    let mut generator = rng(8);
    let n = 20_000;
    let draws: Vec<f64> = (0..n)
        .map(|_| steps::draw_p(&settings, &mut generator))
        .collect();
    assert!(draws.iter().all(|p| (0.0..=1.0).contains(p)));
    let mean = draws.iter().sum::<f64>() / n as f64;
    let std = (draws.iter().map(|p| (p - mean).powi(2)).sum::<f64>() / n as f64).sqrt();
    assert!((mean - 0.5).abs() < 0.01, "mean {mean}");
    assert!((std - 1.0 / 6.0).abs() < 0.01, "std {std}");
    let wide = StepSettings {
        p_std: 1.0,
        ..settings
    };
    let clamped = (0..n)
        .map(|_| steps::draw_p(&wide, &mut generator))
        .filter(|&p| p == 0.0 || p == 1.0)
        .count();
    // P(|N(0.5, 1) − 0.5| > 0.5) = 0.617.
    assert!((clamped as f64 / n as f64 - 0.617).abs() < 0.02);
    let fixed = StepSettings {
        p_std: 0.0,
        p_mean: 0.3,
        ..settings
    };
    assert_eq!(steps::draw_p(&fixed, &mut generator), 0.3);
    assert_eq!(
        steps::draw_p(&settings, &mut rng(4)),
        steps::draw_p(&settings, &mut rng(4))
    );
}

#[test]
fn horizontal_distance_and_direction_ignore_height() {
    let shoulder = Point3::new(0.2, 1.4, -0.1);
    let target = Point3::new(0.5, 0.3, 0.3);
    assert_relative_eq!(
        steps::horizontal_distance(&shoulder, &target),
        0.5,
        max_relative = 1e-15
    );
    let above = Point3::new(0.2, 2.0, -0.1);
    assert_eq!(steps::horizontal_distance(&shoulder, &above), 0.0);
    let direction = steps::step_direction(&shoulder, &target).unwrap();
    assert_relative_eq!(
        direction.into_inner(),
        Vector3::new(0.6, 0.0, 0.8),
        epsilon = 1e-15
    );
    assert!(steps::step_direction(&shoulder, &above).is_none());
}

#[test]
fn target_side_is_the_side_of_the_sagittal_plane() {
    let root = Point3::new(0.0, 1.0, 0.0);
    let facing = Vector3::z();
    // Facing +Z with Y up, the character's left is +X.
    let left = Point3::new(0.3, 0.5, 0.6);
    let right = Point3::new(-0.3, 0.5, 0.6);
    let ahead = Point3::new(0.0, 0.5, 0.6);
    assert_eq!(
        steps::target_side(&root, &facing, &left, Side::Right),
        Side::Left
    );
    assert_eq!(
        steps::target_side(&root, &facing, &right, Side::Left),
        Side::Right
    );
    assert_eq!(
        steps::target_side(&root, &facing, &ahead, Side::Left),
        Side::Left
    );
    assert_eq!(
        steps::target_side(&root, &facing, &ahead, Side::Right),
        Side::Right
    );
    // Facing −X, the left is +Z.
    let facing = -Vector3::x();
    assert_eq!(
        steps::target_side(&root, &facing, &Point3::new(-1.0, 0.0, 0.2), Side::Right),
        Side::Left
    );
    assert_eq!(Side::Left.opposite(), Side::Right);
}

fn chord(from: Point3<f64>, to: Point3<f64>, s: f64) -> Point3<f64> {
    from + (to - from) * s
}

fn path_cases() -> Vec<(Point3<f64>, Point3<f64>)> {
    vec![
        (Point3::new(0.1, 0.0, 0.0), Point3::new(0.1, 0.0, 0.433)),
        (Point3::new(-0.12, 0.03, 0.2), Point3::new(0.17, 0.0, 0.71)),
        (Point3::new(0.0, 0.95, 0.0), Point3::new(0.0, 0.9, 0.25)),
        (Point3::new(0.3, 0.2, 0.3), Point3::new(0.3, 0.2, 0.3)),
    ]
}

#[test]
fn paths_start_and_end_exactly_at_their_ends() {
    for (from, to) in path_cases() {
        for height in [0.0, 0.03, 0.08] {
            assert_eq!(steps::foot_path(from, to, height, 0.0), from);
            assert_eq!(steps::foot_path(from, to, height, 1.0), to);
            assert_eq!(steps::root_path(from, to, height, 0.0), from);
            assert_eq!(steps::root_path(from, to, height, 1.0), to);
            // s is clamped.
            assert_eq!(steps::foot_path(from, to, height, -0.5), from);
            assert_eq!(steps::root_path(from, to, height, 1.5), to);
        }
    }
}

#[test]
fn the_foot_arcs_above_its_chord_and_the_root_dips_below() {
    let (lift, dip) = (0.08, 0.03);
    for (from, to) in path_cases() {
        for i in 0..=1_000 {
            let s = i as f64 / 1_000.0;
            let line = chord(from, to, s);
            let foot = steps::foot_path(from, to, lift, s);
            let root = steps::root_path(from, to, dip, s);
            // Only the height leaves the chord.
            assert_relative_eq!(foot.x, line.x, epsilon = 1e-15);
            assert_relative_eq!(foot.z, line.z, epsilon = 1e-15);
            assert_relative_eq!(root.x, line.x, epsilon = 1e-15);
            assert_relative_eq!(root.z, line.z, epsilon = 1e-15);
            assert!(foot.y >= line.y - 1e-15, "s = {s}");
            assert!(root.y <= line.y + 1e-15, "s = {s}");
            assert!(foot.y - line.y <= lift + 1e-15);
            assert!(line.y - root.y <= dip + 1e-15);
        }
        let mid = chord(from, to, 0.5);
        assert_relative_eq!(
            steps::foot_path(from, to, lift, 0.5).y,
            mid.y + lift,
            epsilon = 1e-15
        );
        assert_relative_eq!(
            steps::root_path(from, to, dip, 0.5).y,
            mid.y - dip,
            epsilon = 1e-15
        );
    }
}

#[test]
fn the_arcs_are_convex_and_piecewise_linear() {
    let (from, to) = (Point3::new(0.0, 0.0, 0.0), Point3::new(0.0, 0.0, 0.5));
    let lift = 0.1;
    let height = |s: f64| steps::foot_path(from, to, lift, s).y;
    let depth = |s: f64| -steps::root_path(from, to, lift, s).y;
    // The foot's height over the chord is a concave function (the arc bulges up, "convex"
    // in the animator's sense); the root's is its mirror image.
    for i in 0..=40 {
        for j in i..=40 {
            let (a, b) = (i as f64 / 40.0, j as f64 / 40.0);
            let m = 0.5 * (a + b);
            assert!(height(m) >= 0.5 * (height(a) + height(b)) - 1e-15);
            assert!(depth(m) >= 0.5 * (depth(a) + depth(b)) - 1e-15);
        }
    }
    // Piecewise linear: the second difference vanishes away from the knots at ¼, ½, ¾,
    // and the knots lie on the parabola 4s(1 − s).
    let h = 1e-3;
    for i in 1..1_000 {
        let s = i as f64 / 1_000.0;
        let near_knot = [0.25, 0.5, 0.75].iter().any(|k| (s - k).abs() <= h * 1.5);
        if !near_knot {
            let second = height(s - h) - 2.0 * height(s) + height(s + h);
            assert!(second.abs() < 1e-15, "s = {s}: {second}");
        }
    }
    for k in [0.25, 0.5, 0.75] {
        assert_relative_eq!(height(k), lift * 4.0 * k * (1.0 - k), epsilon = 1e-15);
    }
}

#[test]
fn the_paths_are_continuous() {
    let (lift, dip) = (0.08, 0.03);
    for (from, to) in path_cases() {
        // Lipschitz: the chord moves |to − from| per unit s, the polygon's steepest
        // segment 3 × height.
        let n = 10_000;
        let ds = 1.0 / n as f64;
        let chord_rate = (to - from).norm();
        let mut foot = steps::foot_path(from, to, lift, 0.0);
        let mut root = steps::root_path(from, to, dip, 0.0);
        for i in 1..=n {
            let s = i as f64 * ds;
            let (f, r) = (
                steps::foot_path(from, to, lift, s),
                steps::root_path(from, to, dip, s),
            );
            assert!((f - foot).norm() <= (chord_rate + 3.0 * lift) * ds * (1.0 + 1e-9) + 1e-15);
            assert!((r - root).norm() <= (chord_rate + 3.0 * dip) * ds * (1.0 + 1e-9) + 1e-15);
            (foot, root) = (f, r);
        }
    }
}

#[test]
fn settings_scale_with_arm_length() {
    let settings = StepSettings::for_arm_length(0.6).unwrap();
    assert_relative_eq!(settings.d_c, CRR_PER_ARM_LENGTH * 0.6);
    assert_relative_eq!(settings.d_max, MRR_PER_ARM_LENGTH * 0.6);
    assert_eq!(
        StepSettings::for_arm_length(0.70).unwrap(),
        StepSettings::default()
    );
    assert!(StepSettings::default().validate().is_ok());
    for bad in [0.0, -0.7, f64::NAN, f64::INFINITY] {
        assert_eq!(
            setting_field(StepSettings::for_arm_length(bad).unwrap_err()),
            "arm_length"
        );
    }
}

#[test]
fn bad_settings_name_their_field() {
    let base = StepSettings::default();
    let cases: Vec<(StepSettings, &str)> = vec![
        (StepSettings { d_c: 0.0, ..base }, "steps.d_c"),
        (
            StepSettings {
                d_c: f64::NAN,
                ..base
            },
            "steps.d_c",
        ),
        (
            StepSettings {
                d_max: base.d_c,
                ..base
            },
            "steps.d_max",
        ),
        (
            StepSettings {
                d_max: f64::INFINITY,
                ..base
            },
            "steps.d_max",
        ),
        (StepSettings { p_max: 1.1, ..base }, "steps.p_max"),
        (
            StepSettings {
                p_max: f64::NAN,
                ..base
            },
            "steps.p_max",
        ),
        (
            StepSettings {
                p_min: -0.1,
                ..base
            },
            "steps.p_min",
        ),
        (
            StepSettings {
                p_min: 0.95,
                ..base
            },
            "steps.p_min",
        ),
        (StepSettings { l_min: 0.0, ..base }, "steps.l_min"),
        (StepSettings { l_max: 0.2, ..base }, "steps.l_max"),
        (
            StepSettings {
                l_max: f64::NAN,
                ..base
            },
            "steps.l_max",
        ),
        (
            StepSettings {
                p_mean: 1.5,
                ..base
            },
            "steps.p_mean",
        ),
        (
            StepSettings {
                p_std: -0.1,
                ..base
            },
            "steps.p_std",
        ),
        (
            StepSettings {
                p_std: f64::INFINITY,
                ..base
            },
            "steps.p_std",
        ),
        (
            StepSettings {
                foot_lift: -0.01,
                ..base
            },
            "steps.foot_lift",
        ),
        (
            StepSettings {
                root_dip: f64::NAN,
                ..base
            },
            "steps.root_dip",
        ),
    ];
    for (settings, field) in cases {
        assert_eq!(setting_field(settings.validate().unwrap_err()), field);
    }
}

#[test]
fn settings_and_decisions_round_trip_through_json() {
    let settings = StepSettings::default();
    let json = serde_json::to_string(&settings).unwrap();
    assert_eq!(
        serde_json::from_str::<StepSettings>(&json).unwrap(),
        settings
    );
    for decision in [
        StepDecision::NoStep,
        StepDecision::HalfStep { foot: Side::Left },
        StepDecision::FullStep,
    ] {
        let json = serde_json::to_string(&decision).unwrap();
        assert_eq!(
            serde_json::from_str::<StepDecision>(&json).unwrap(),
            decision
        );
    }
    assert_eq!(
        serde_json::to_string(&StepDecision::HalfStep { foot: Side::Right }).unwrap(),
        r#"{"kind":"half_step","foot":"right"}"#
    );
}
