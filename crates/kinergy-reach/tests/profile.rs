//! The hand's speed profiles against their closed forms (Huang et al. §3.3, eqs. 1–4 and
//! Algorithm 1; minimum jerk; Kallmann's cubic).

use approx::assert_relative_eq;
use kinergy_reach::ReachError;
use kinergy_reach::profile::{
    BellTiming, CUBIC_PEAK_RATIO, MINIMUM_JERK_PEAK_RATIO, PAPER_START_RATIO, PAPER_START_SPEED,
    SpeedProfile,
};
use nalgebra::Point3;
use proptest::prelude::*;

const DISTANCES: [f64; 4] = [0.01, 0.36, 0.9, 1.7];

fn ease(v_s: f64, r_s: f64) -> SpeedProfile {
    SpeedProfile::ease_out(v_s, r_s).unwrap()
}

fn timings() -> Vec<BellTiming> {
    vec![
        BellTiming::default(),
        BellTiming::PeakSpeed { speed: 0.5 },
        BellTiming::Duration { seconds: 1.2 },
        BellTiming::Fitts {
            a: 0.2,
            b: 0.15,
            width: 0.02,
        },
    ]
}

fn all_profiles() -> Vec<SpeedProfile> {
    let mut all = vec![
        SpeedProfile::default(),
        ease(0.35, 0.5),
        ease(0.2, 1.0),
        ease(0.1, 0.05),
    ];
    for timing in timings() {
        all.push(SpeedProfile::minimum_jerk(timing).unwrap());
        all.push(SpeedProfile::cubic(timing).unwrap());
    }
    all
}

/// An upper bound on the speed, from the closed forms.
fn peak_speed(profile: &SpeedProfile, distance: f64) -> f64 {
    let total = profile.duration(distance);
    match *profile {
        SpeedProfile::EaseOut { v_s, .. } => v_s,
        SpeedProfile::MinimumJerk { .. } => MINIMUM_JERK_PEAK_RATIO * distance / total,
        SpeedProfile::Cubic { .. } => CUBIC_PEAK_RATIO * distance / total,
    }
}

/// Times where the speed or the acceleration is not differentiable.
fn kinks(profile: &SpeedProfile, distance: f64) -> Vec<f64> {
    let total = profile.duration(distance);
    match *profile {
        SpeedProfile::EaseOut { r_s, .. } => vec![0.0, r_s * total, total],
        _ => vec![0.0, total],
    }
}

fn setting_field(err: ReachError) -> String {
    match err {
        ReachError::Setting(e) => e.field,
        other => panic!("expected a Setting error, got {other:?}"),
    }
}

#[test]
fn progress_starts_at_zero_and_ends_exactly_at_the_distance() {
    for profile in all_profiles() {
        for distance in DISTANCES {
            let total = profile.duration(distance);
            assert!(total > 0.0, "{profile:?}");
            assert_eq!(profile.progress(distance, 0.0), 0.0, "{profile:?}");
            assert_eq!(profile.progress(distance, -1.0), 0.0, "{profile:?}");
            assert_eq!(profile.progress(distance, total), distance, "{profile:?}");
            assert_eq!(profile.progress(distance, total + 5.0), distance);
            assert_eq!(profile.speed(distance, total), 0.0);
            assert_eq!(profile.speed(distance, total + 5.0), 0.0);
            assert_eq!(profile.speed(distance, -1.0), 0.0);
        }
    }
}

#[test]
fn progress_is_monotone_and_lipschitz_continuous() {
    let n = 20_000;
    for profile in all_profiles() {
        for distance in DISTANCES {
            let total = profile.duration(distance);
            let bound = peak_speed(&profile, distance);
            let dt = 1.2 * total / n as f64;
            let mut previous = profile.progress(distance, -0.1 * total);
            for i in 1..=n {
                let t = -0.1 * total + i as f64 * dt;
                let s = profile.progress(distance, t);
                assert!(s >= previous, "{profile:?} decreases at t = {t}");
                assert!(
                    s - previous <= bound * dt * (1.0 + 1e-9) + 1e-15,
                    "{profile:?} jumps at t = {t}: {} over {dt} s",
                    s - previous
                );
                assert!((0.0..=distance).contains(&s));
                previous = s;
            }
        }
    }
}

#[test]
fn speed_and_acceleration_are_the_derivatives_by_finite_differences() {
    for profile in all_profiles() {
        for distance in DISTANCES {
            let total = profile.duration(distance);
            let h = 1e-6 * total;
            let peak = peak_speed(&profile, distance);
            let kinks = kinks(&profile, distance);
            for i in 1..200 {
                let t = total * i as f64 / 200.0;
                if kinks.iter().any(|k| (t - k).abs() < 4.0 * h) {
                    continue;
                }
                let fd_speed = (profile.progress(distance, t + h)
                    - profile.progress(distance, t - h))
                    / (2.0 * h);
                assert!(
                    (fd_speed - profile.speed(distance, t)).abs() <= 1e-6 * peak,
                    "{profile:?} d = {distance} t = {t}: {fd_speed} vs {}",
                    profile.speed(distance, t)
                );
                let fd_accel =
                    (profile.speed(distance, t + h) - profile.speed(distance, t - h)) / (2.0 * h);
                assert!(
                    (fd_accel - profile.acceleration(distance, t)).abs() <= 1e-5 * peak / total,
                    "{profile:?} d = {distance} t = {t}: {fd_accel} vs {}",
                    profile.acceleration(distance, t)
                );
            }
        }
    }
}

#[test]
fn ease_out_duration_is_eq_4_and_eqs_1_to_3_agree() {
    for (v_s, r_s) in [(0.2, 0.8), (0.35, 0.5), (0.1, 0.05), (0.2, 1.0)] {
        let profile = ease(v_s, r_s);
        for distance in DISTANCES {
            let t_t = profile.duration(distance);
            // Eq. 4.
            assert_relative_eq!(
                t_t,
                2.0 * distance / (v_s * (r_s + 1.0)),
                max_relative = 1e-15
            );
            // Rectangle + triangle under the speed.
            assert_relative_eq!(
                v_s * r_s * t_t + 0.5 * v_s * (1.0 - r_s) * t_t,
                distance,
                max_relative = 1e-14
            );
            if r_s < 1.0 {
                // Eq. 3 as printed, with eq. 2's (signed) a.
                let a = -v_s / (t_t * (1.0 - r_s));
                let eq3 = v_s * t_t + 0.5 * a * (t_t * (1.0 - r_s)).powi(2);
                assert_relative_eq!(eq3, distance, max_relative = 1e-14);
                assert_relative_eq!(
                    profile.acceleration(distance, 0.5 * (1.0 + r_s) * t_t),
                    a,
                    max_relative = 1e-14
                );
            }
        }
    }
}

#[test]
fn ease_out_speed_is_v_s_then_falls_linearly_to_zero_at_t_t() {
    for (v_s, r_s) in [(0.2, 0.8), (0.35, 0.5), (0.1, 0.05), (0.2, 1.0)] {
        let profile = ease(v_s, r_s);
        for distance in DISTANCES {
            let t_t = profile.duration(distance);
            for i in 0..1000 {
                let t = t_t * i as f64 / 1000.0;
                let speed = profile.speed(distance, t);
                if t < r_s * t_t {
                    assert_eq!(speed, v_s);
                    assert_eq!(profile.progress(distance, t), v_s * t);
                } else {
                    let linear = v_s * (t_t - t) / (t_t * (1.0 - r_s));
                    assert_relative_eq!(speed, linear, max_relative = 1e-12);
                }
            }
        }
    }
}

/// Composite Simpson on [a, b] with n (even) intervals.
fn simpson(f: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let inner: f64 = (1..n)
        .map(|i| f(a + i as f64 * h) * if i % 2 == 1 { 4.0 } else { 2.0 })
        .sum();
    (f(a) + f(b) + inner) * h / 3.0
}

#[test]
fn ease_out_integral_of_speed_is_the_distance() {
    for (v_s, r_s) in [(0.2, 0.8), (0.35, 0.5), (0.1, 0.05)] {
        let profile = ease(v_s, r_s);
        for distance in DISTANCES {
            let t_t = profile.duration(distance);
            let t_1 = r_s * t_t;
            // Each phase is a polynomial, so Simpson is exact up to rounding; stop just short
            // of the phase ends so every sample sees the phase's own formula.
            let e = 1e-12 * t_t;
            let start = simpson(|t| profile.speed(distance, t), 0.0, t_1 - e, 64);
            let brake = simpson(|t| profile.speed(distance, t), t_1, t_t - e, 64);
            assert_relative_eq!(start + brake, distance, max_relative = 1e-9);
            assert_relative_eq!(start, v_s * t_1, max_relative = 1e-9);
        }
    }
}

#[test]
fn ease_out_is_the_limit_of_algorithm_1s_update() {
    // Algorithm 1 literally (1-D along d_h): v_c = v_s before r_s t_t, else v_s + a (t_c −
    // r_s t_t); p_c += v_c Δt. Explicit Euler is first order, so the gap is O(Δt).
    for (v_s, r_s) in [(0.2, 0.8), (0.35, 0.5)] {
        let profile = ease(v_s, r_s);
        let distance = 0.6;
        for dt in [1e-2, 1e-3, 1e-4] {
            let t_t = 2.0 * distance / (v_s * (r_s + 1.0));
            let a = -v_s / (t_t * (1.0 - r_s));
            let (mut p_c, mut t_c, mut worst) = (0.0_f64, 0.0_f64, 0.0_f64);
            while t_c < t_t {
                let v_c = if t_c < t_t * r_s {
                    v_s
                } else {
                    v_s + a * (t_c - t_t * r_s)
                };
                p_c += v_c * dt;
                t_c += dt;
                worst = worst.max((p_c - profile.progress(distance, t_c)).abs());
            }
            assert!(worst <= v_s * dt, "Δt = {dt}: {worst}");
        }
    }
}

#[test]
fn minimum_jerk_is_a_symmetric_bell_peaking_at_1_875_d_over_t() {
    for timing in timings() {
        let profile = SpeedProfile::minimum_jerk(timing).unwrap();
        for distance in DISTANCES {
            let total = profile.duration(distance);
            let peak = profile.speed(distance, total / 2.0);
            assert_relative_eq!(peak, 1.875 * distance / total, max_relative = 1e-14);
            assert_relative_eq!(profile.progress(distance, total / 2.0), distance / 2.0);
            for i in 0..=500 {
                let t = total * i as f64 / 500.0;
                let h = t / total;
                let closed = distance * (10.0 * h.powi(3) - 15.0 * h.powi(4) + 6.0 * h.powi(5));
                assert_relative_eq!(
                    profile.progress(distance, t),
                    closed,
                    epsilon = 1e-15 * distance,
                    max_relative = 1e-12
                );
                let speed = profile.speed(distance, t);
                assert!(speed <= peak);
                assert_relative_eq!(
                    speed,
                    profile.speed(distance, total - t),
                    epsilon = 1e-12 * peak,
                    max_relative = 1e-9
                );
            }
            assert_eq!(profile.speed(distance, 0.0), 0.0);
            assert_eq!(profile.acceleration(distance, 0.0), 0.0);
            let end = total * (1.0 - 1e-9);
            assert!(profile.speed(distance, end) <= 1e-15 * peak);
            assert!(profile.acceleration(distance, end).abs() <= 1e-7 * peak / total);
        }
    }
}

#[test]
fn cubic_is_a_symmetric_bell_peaking_at_1_5_d_over_t() {
    for timing in timings() {
        let profile = SpeedProfile::cubic(timing).unwrap();
        for distance in DISTANCES {
            let total = profile.duration(distance);
            let peak = profile.speed(distance, total / 2.0);
            assert_relative_eq!(peak, 1.5 * distance / total, max_relative = 1e-14);
            for i in 0..=500 {
                let t = total * i as f64 / 500.0;
                let h = t / total;
                // Kallmann's time warp t = −2h³ + 3h².
                let closed = distance * (-2.0 * h.powi(3) + 3.0 * h.powi(2));
                assert_relative_eq!(
                    profile.progress(distance, t),
                    closed,
                    epsilon = 1e-15 * distance,
                    max_relative = 1e-12
                );
                let speed = profile.speed(distance, t);
                assert!(speed <= peak);
                assert_relative_eq!(
                    speed,
                    profile.speed(distance, total - t),
                    epsilon = 1e-12 * peak,
                    max_relative = 1e-9
                );
            }
            assert_eq!(profile.speed(distance, 0.0), 0.0);
            let end = total * (1.0 - 1e-9);
            assert!(profile.speed(distance, end) <= 1e-8 * peak);
            // Not zero: the cubic starts and stops with a finite acceleration.
            let accel = 6.0 * distance / (total * total);
            assert_relative_eq!(
                profile.acceleration(distance, 0.0),
                accel,
                max_relative = 1e-14
            );
            assert_relative_eq!(
                profile.acceleration(distance, end),
                -accel,
                max_relative = 1e-8
            );
        }
    }
}

#[test]
fn bell_timings_follow_their_rules() {
    for distance in DISTANCES {
        // The default bell takes as long as the paper's ease-out.
        let paper = SpeedProfile::default().duration(distance);
        for make in [SpeedProfile::minimum_jerk, SpeedProfile::cubic] {
            assert_relative_eq!(
                make(BellTiming::default()).unwrap().duration(distance),
                paper,
                max_relative = 1e-14
            );
            let matched = BellTiming::matching_ease_out(0.35, 0.5);
            assert_relative_eq!(
                make(matched).unwrap().duration(distance),
                ease(0.35, 0.5).duration(distance),
                max_relative = 1e-14
            );
            let mean = make(BellTiming::MeanSpeed { speed: 0.3 }).unwrap();
            assert_relative_eq!(
                mean.duration(distance),
                distance / 0.3,
                max_relative = 1e-15
            );
            let fixed = make(BellTiming::Duration { seconds: 1.2 }).unwrap();
            assert_eq!(fixed.duration(distance), 1.2);
            let fitts = make(BellTiming::Fitts {
                a: 0.2,
                b: 0.15,
                width: 0.02,
            })
            .unwrap();
            assert_relative_eq!(
                fitts.duration(distance),
                0.2 + 0.15 * (1.0 + distance / 0.02).log2(),
                max_relative = 1e-15
            );
            let top = make(BellTiming::PeakSpeed { speed: 0.5 }).unwrap();
            let total = top.duration(distance);
            assert_relative_eq!(top.speed(distance, total / 2.0), 0.5, max_relative = 1e-14);
        }
    }
    assert_relative_eq!(
        BellTiming::PAPER_MEAN_SPEED,
        PAPER_START_SPEED * (1.0 + PAPER_START_RATIO) / 2.0
    );
}

/// `time_at` inverts `progress`: the time at which the hand has covered s meters covers s,
/// at both ends too, for every profile.
#[test]
fn time_at_is_the_inverse_of_progress() {
    for profile in all_profiles() {
        for distance in DISTANCES {
            let total = profile.duration(distance);
            assert_eq!(profile.time_at(distance, 0.0), 0.0, "{profile:?}");
            assert_eq!(profile.time_at(distance, -1.0), 0.0, "{profile:?}");
            assert_eq!(profile.time_at(distance, distance), total, "{profile:?}");
            for k in 1..50 {
                let s = distance * k as f64 / 50.0;
                let t = profile.time_at(distance, s);
                assert!(
                    (0.0..=total).contains(&t),
                    "{profile:?} {distance} {s}: {t}"
                );
                assert_relative_eq!(
                    profile.progress(distance, t),
                    s,
                    epsilon = 1e-9 * distance.max(1.0)
                );
            }
        }
    }
}

#[test]
fn a_zero_distance_reach_does_not_move() {
    let start = Point3::new(0.1, 1.2, 0.3);
    for profile in all_profiles() {
        for t in [-1.0, 0.0, 0.5, 10.0] {
            assert_eq!(profile.progress(0.0, t), 0.0);
            assert_eq!(profile.speed(0.0, t), 0.0);
            assert_eq!(profile.position(&start, &start, t), start);
        }
    }
    assert_eq!(SpeedProfile::default().duration(0.0), 0.0);
}

#[test]
fn position_runs_on_the_segment_and_lands_exactly_on_the_target() {
    let start = Point3::new(0.13, 1.21, 0.07);
    let end = Point3::new(-0.31, 0.93, 0.58);
    let distance = (end - start).norm();
    for profile in all_profiles() {
        let total = profile.duration(distance);
        assert_eq!(profile.position(&start, &end, 0.0), start);
        assert_eq!(profile.position(&start, &end, total), end);
        assert_eq!(profile.position(&start, &end, total + 1.0), end);
        for i in 1..50 {
            let t = total * i as f64 / 50.0;
            let p = profile.position(&start, &end, t);
            assert_relative_eq!(
                (p - start).norm(),
                profile.progress(distance, t),
                epsilon = 1e-12
            );
            assert_relative_eq!(
                (p - start).norm() + (end - p).norm(),
                distance,
                epsilon = 1e-12
            );
        }
    }
}

#[test]
fn bad_settings_name_their_field() {
    let cases: Vec<(Result<SpeedProfile, ReachError>, &str)> = vec![
        (SpeedProfile::ease_out(0.0, 0.8), "profile.v_s"),
        (SpeedProfile::ease_out(-0.2, 0.8), "profile.v_s"),
        (SpeedProfile::ease_out(f64::NAN, 0.8), "profile.v_s"),
        (SpeedProfile::ease_out(f64::INFINITY, 0.8), "profile.v_s"),
        (SpeedProfile::ease_out(0.2, 0.0), "profile.r_s"),
        (SpeedProfile::ease_out(0.2, 1.01), "profile.r_s"),
        (SpeedProfile::ease_out(0.2, f64::NAN), "profile.r_s"),
        (
            SpeedProfile::minimum_jerk(BellTiming::MeanSpeed { speed: -1.0 }),
            "profile.timing.speed",
        ),
        (
            SpeedProfile::cubic(BellTiming::PeakSpeed { speed: 0.0 }),
            "profile.timing.speed",
        ),
        (
            SpeedProfile::cubic(BellTiming::Duration { seconds: 0.0 }),
            "profile.timing.seconds",
        ),
        (
            SpeedProfile::minimum_jerk(BellTiming::Fitts {
                a: -0.1,
                b: 0.1,
                width: 0.02,
            }),
            "profile.timing.a",
        ),
        (
            SpeedProfile::minimum_jerk(BellTiming::Fitts {
                a: 0.1,
                b: 0.0,
                width: 0.02,
            }),
            "profile.timing.b",
        ),
        (
            SpeedProfile::minimum_jerk(BellTiming::Fitts {
                a: 0.1,
                b: 0.1,
                width: 0.0,
            }),
            "profile.timing.width",
        ),
    ];
    for (result, field) in cases {
        assert_eq!(setting_field(result.unwrap_err()), field);
    }
    assert!(SpeedProfile::default().validate().is_ok());
    assert!(SpeedProfile::ease_out(0.2, 1.0).is_ok());
}

#[test]
fn profiles_round_trip_through_json() {
    let json = serde_json::to_string(&SpeedProfile::default()).unwrap();
    assert_eq!(json, r#"{"kind":"ease_out","v_s":0.2,"r_s":0.8}"#);
    for profile in all_profiles() {
        let json = serde_json::to_string(&profile).unwrap();
        let back: SpeedProfile = serde_json::from_str(&json).unwrap();
        assert_eq!(back, profile);
    }
}

proptest! {
    #[test]
    fn ease_out_progress_stays_in_range_and_never_goes_back(
        v_s in 0.01..2.0f64,
        r_s in 0.01..=1.0f64,
        distance in 1e-4..3.0f64,
        a in -0.2..1.2f64,
        b in -0.2..1.2f64,
    ) {
        let profile = ease(v_s, r_s);
        let total = profile.duration(distance);
        let (t0, t1) = if a <= b { (a * total, b * total) } else { (b * total, a * total) };
        let (s0, s1) = (profile.progress(distance, t0), profile.progress(distance, t1));
        prop_assert!((0.0..=distance).contains(&s0));
        prop_assert!(s0 <= s1);
        prop_assert!(s1 - s0 <= v_s * (t1 - t0) * (1.0 + 1e-12) + 1e-15);
    }
}
