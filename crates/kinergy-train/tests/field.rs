//! The parameter field over targets: a constant from one sample, a known linear field
//! recovered at held-out targets, bounds never left, leave-one-out rows blind to their own
//! sample, a deterministic automatic bandwidth, typed errors, a field file's JSON round trip.

use approx::assert_relative_eq;
use kinergy_motion::nalgebra::{Point3, Vector3};
use kinergy_solver::ParamSpace;
use kinergy_train::TrainError;
use kinergy_train::field::{
    AUTO_FACTORS, Bandwidth, FALLBACK_BANDWIDTH, FieldSettings, ParamField, Regression,
    leave_one_out,
};
use proptest::prelude::*;

mod field_support;

use field_support::{
    CENTER, Lcg, Sample, all_settings, grid, linear_truth, noisy_samples, space, widths,
};

/// Targets strictly inside the grid's box, none on the grid.
fn held_out(count: usize) -> Vec<Point3<f64>> {
    let mut rng = Lcg(7);
    (0..count)
        .map(|_| {
            Point3::new(
                0.2 + 0.3 * (0.1 + 0.8 * rng.next()),
                -0.1 + 0.2 * (0.1 + 0.8 * rng.next()),
                1.0 + 0.2 * (0.1 + 0.8 * rng.next()),
            )
        })
        .collect()
}

/// Root mean square over targets and entries of (estimate − truth) / bound width.
fn normalized_rms(space: &ParamSpace, pairs: &[(Vec<f64>, Vec<f64>)]) -> f64 {
    let w = widths(space);
    let mut sum = 0.0;
    let mut n = 0;
    for (a, b) in pairs {
        for ((x, y), wi) in a.iter().zip(b).zip(&w) {
            sum += ((x - y) / wi).powi(2);
            n += 1;
        }
    }
    (sum / n as f64).sqrt()
}

fn setting_field(err: TrainError) -> String {
    match err {
        TrainError::Setting(s) => s.field,
        other => panic!("expected a Setting error, got {other:?}"),
    }
}

#[test]
fn one_sample_gives_its_vector_everywhere() {
    let space = space();
    let p = vec![-1.25, 3.5, 7.0, 0.5];
    let samples = vec![(Point3::new(0.4, -0.2, 1.3), p.clone())];
    for settings in all_settings() {
        let field = ParamField::fit(&space, &samples, &settings).expect("fit");
        for t in [
            Point3::new(0.4, -0.2, 1.3),
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(-3.0, 2.0, 0.5),
            Point3::new(1e6, -1e6, 1e6),
        ] {
            assert_eq!(field.evaluate(&t), p, "{settings:?} at {t}");
        }
        if settings.bandwidth == Bandwidth::Auto {
            assert_eq!(field.bandwidth(), FALLBACK_BANDWIDTH);
            assert!(field.selection().is_empty());
        }
    }
}

#[test]
fn a_linear_field_is_recovered_at_held_out_targets() {
    let space = space();
    let samples: Vec<Sample> = grid().into_iter().map(|t| (t, linear_truth(&t))).collect();
    let mean: Vec<f64> = (0..space.len())
        .map(|i| samples.iter().map(|s| s.1[i]).sum::<f64>() / samples.len() as f64)
        .collect();
    let targets = held_out(40);
    let truth: Vec<Vec<f64>> = targets.iter().map(linear_truth).collect();
    let mean_error = normalized_rms(
        &space,
        &truth
            .iter()
            .map(|p| (mean.clone(), p.clone()))
            .collect::<Vec<_>>(),
    );
    let mut errors = Vec::new();
    for (regression, tolerance) in [
        (Regression::NadarayaWatson, 0.005),
        (Regression::local_linear(), 5e-4),
        (Regression::LocalLinear { ridge: 0.0 }, 1e-9),
    ] {
        let settings = FieldSettings {
            bandwidth: Bandwidth::Auto,
            regression,
        };
        let field = ParamField::fit(&space, &samples, &settings).expect("fit");
        let pairs: Vec<(Vec<f64>, Vec<f64>)> = targets
            .iter()
            .zip(&truth)
            .map(|(t, p)| (field.evaluate(t), p.clone()))
            .collect();
        let error = normalized_rms(&space, &pairs);
        eprintln!(
            "{regression:?}: h = {:.4} m, held-out RMS error {error:.2e} of the bound width \
             (global mean: {mean_error:.2e})",
            field.bandwidth()
        );
        assert!(error < tolerance, "{regression:?}: {error} ≥ {tolerance}");
        errors.push(error);
    }
    assert!(
        errors.iter().all(|e| *e < 0.2 * mean_error),
        "{errors:?} vs mean {mean_error}"
    );
    // The truth for this test is not the samples: the global mean is far off.
    assert!(mean_error > 0.05, "{mean_error}");
}

#[test]
fn plain_local_linear_reproduces_a_linear_field_even_outside_the_grid() {
    let space = space();
    let samples: Vec<Sample> = grid().into_iter().map(|t| (t, linear_truth(&t))).collect();
    let settings = FieldSettings {
        bandwidth: Bandwidth::Fixed(0.1),
        regression: Regression::LocalLinear { ridge: 0.0 },
    };
    let field = ParamField::fit(&space, &samples, &settings).expect("fit");
    // On a corner and 5 cm beyond the grid, where the truth is still inside the bounds.
    for t in [Point3::new(0.2, -0.1, 1.0), Point3::new(0.55, 0.15, 1.25)] {
        let p = field.evaluate(&t);
        for (a, b) in p.iter().zip(linear_truth(&t)) {
            assert_relative_eq!(*a, b, epsilon = 1e-9);
        }
    }
    // Nadaraya–Watson is biased toward the inside at a corner.
    let nw = ParamField::fit(
        &space,
        &samples,
        &FieldSettings {
            bandwidth: Bandwidth::Fixed(0.1),
            regression: Regression::NadarayaWatson,
        },
    )
    .expect("fit");
    let corner = Point3::new(0.2, -0.1, 1.0);
    assert!((nw.evaluate(&corner)[3] - linear_truth(&corner)[3]).abs() > 0.1);
}

#[test]
fn far_from_every_sample_the_field_is_the_nearest_sample_not_nan() {
    let space = space();
    let samples: Vec<Sample> = grid().into_iter().map(|t| (t, linear_truth(&t))).collect();
    // (Plain local-linear, λ = 0, keeps fitting slopes however small the weights: not here.)
    for regression in [Regression::NadarayaWatson, Regression::local_linear()] {
        let field = ParamField::fit(
            &space,
            &samples,
            &FieldSettings {
                bandwidth: Bandwidth::Fixed(0.01),
                regression,
            },
        )
        .expect("fit");
        // exp(−(3 m)² / 2h²) underflows to 0 for every sample: a naive ratio would be 0/0.
        for t in [
            Point3::new(0.505, 0.095, 4.0),
            Point3::new(-2.5, -0.095, 1.005),
            Point3::new(0.305, 3.0, 1.195),
            Point3::new(1e8, 1e8, -1e8),
        ] {
            let nearest = samples
                .iter()
                .min_by(|a, b| (a.0 - t).norm().total_cmp(&(b.0 - t).norm()))
                .expect("samples");
            let p = field.evaluate(&t);
            for (a, b) in p.iter().zip(&nearest.1) {
                assert!(
                    (a - b).abs() <= 1e-12,
                    "{regression:?} at {t}: {p:?} vs {:?}",
                    nearest.1
                );
            }
        }
    }
}

#[test]
fn a_large_ridge_gives_nadaraya_watson() {
    let space = space();
    let samples = noisy_samples(4, 0.1);
    let fit = |regression| {
        let settings = FieldSettings {
            bandwidth: Bandwidth::Fixed(0.08),
            regression,
        };
        ParamField::fit(&space, &samples, &settings).expect("fit")
    };
    let nw = fit(Regression::NadarayaWatson);
    let stiff = fit(Regression::LocalLinear { ridge: 1e9 });
    let plain = fit(Regression::LocalLinear { ridge: 0.0 });
    let mut differs = 0.0f64;
    for t in held_out(10) {
        let a = nw.evaluate(&t);
        for (x, y) in a.iter().zip(stiff.evaluate(&t)) {
            assert_relative_eq!(*x, y, epsilon = 1e-7);
        }
        for (x, y) in a.iter().zip(plain.evaluate(&t)) {
            differs = differs.max((x - y).abs());
        }
    }
    assert!(differs > 1e-3, "{differs}");
}

#[test]
fn plain_local_linear_on_a_plane_has_no_slope_across_it() {
    // Targets on the plane z = 1 and a field linear in x, y: off the plane, the value is the
    // one at the foot of the perpendicular (no slope in z), not a blow-up.
    let space = space();
    let samples: Vec<Sample> = grid()
        .into_iter()
        .filter(|t| t.z == 1.0)
        .map(|t| (t, linear_truth(&Point3::new(t.x, t.y, CENTER[2]))))
        .collect();
    let field = ParamField::fit(
        &space,
        &samples,
        &FieldSettings {
            bandwidth: Bandwidth::Fixed(0.1),
            regression: Regression::LocalLinear { ridge: 0.0 },
        },
    )
    .expect("fit");
    let t = Point3::new(0.33, 0.04, 1.2);
    let p = field.evaluate(&t);
    for (a, b) in p
        .iter()
        .zip(linear_truth(&Point3::new(t.x, t.y, CENTER[2])))
    {
        assert_relative_eq!(*a, b, epsilon = 1e-9);
    }
}

#[test]
fn a_huge_bandwidth_gives_the_mean() {
    let space = space();
    let samples: Vec<Sample> = grid().into_iter().map(|t| (t, linear_truth(&t))).collect();
    let field = ParamField::fit(
        &space,
        &samples,
        &FieldSettings {
            bandwidth: Bandwidth::Fixed(1e4),
            regression: Regression::NadarayaWatson,
        },
    )
    .expect("fit");
    let p = field.evaluate(&Point3::new(0.9, 0.4, 0.3));
    for (i, v) in p.iter().enumerate() {
        let mean = samples.iter().map(|s| s.1[i]).sum::<f64>() / samples.len() as f64;
        assert_relative_eq!(*v, mean, epsilon = 1e-6);
    }
}

#[test]
fn the_auto_bandwidth_is_near_the_best_in_hindsight_on_noisy_fits() {
    let space = space();
    let targets = held_out(40);
    let truth: Vec<Vec<f64>> = targets.iter().map(linear_truth).collect();
    let held_out_error = |field: &ParamField| {
        let pairs: Vec<(Vec<f64>, Vec<f64>)> = targets
            .iter()
            .zip(&truth)
            .map(|(t, p)| (field.evaluate(t), p.clone()))
            .collect();
        normalized_rms(&space, &pairs)
    };
    for amplitude in [0.05, 0.2] {
        let samples = noisy_samples(3, amplitude);
        for regression in [Regression::NadarayaWatson, Regression::local_linear()] {
            let settings = FieldSettings {
                bandwidth: Bandwidth::Auto,
                regression,
            };
            let auto = ParamField::fit(&space, &samples, &settings).expect("fit");
            let best = AUTO_FACTORS
                .iter()
                .map(|f| {
                    let fixed = FieldSettings {
                        bandwidth: Bandwidth::Fixed(f * 0.1),
                        regression,
                    };
                    held_out_error(&ParamField::fit(&space, &samples, &fixed).expect("fit"))
                })
                .fold(f64::INFINITY, f64::min);
            let error = held_out_error(&auto);
            eprintln!(
                "noise ±{:.0}%, {regression:?}: auto h = {:.4} m, held-out error {error:.2e}, \
                 best candidate in hindsight {best:.2e}",
                50.0 * amplitude,
                auto.bandwidth()
            );
            assert!(error <= 1.25 * best, "{error} vs {best}");
        }
    }
}

#[test]
fn a_leave_one_out_row_ignores_its_own_sample() {
    let space = space();
    let samples = noisy_samples(3, 0.05);
    // The score: the normalized distance to the (known) truth at the reach's target.
    let w = widths(&space);
    let truth: Vec<Vec<f64>> = samples.iter().map(|s| linear_truth(&s.0)).collect();
    let score = |k: usize, p: &[f64]| -> kinergy_train::Result<f64> {
        Ok(p.iter()
            .zip(&truth[k])
            .zip(&w)
            .map(|((a, b), wi)| ((a - b) / wi).powi(2))
            .sum::<f64>()
            .sqrt())
    };
    for settings in [
        FieldSettings::default(),
        FieldSettings {
            bandwidth: Bandwidth::Auto,
            regression: Regression::local_linear(),
        },
    ] {
        let rows = leave_one_out(&space, &samples, &settings, score).expect("loo");
        assert_eq!(rows.len(), samples.len());
        let one_thread = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .expect("pool")
            .install(|| leave_one_out(&space, &samples, &settings, score).expect("loo"));
        assert_eq!(one_thread, rows);
        for k in [0, 13, 35] {
            let row = &rows[k];
            assert_eq!(row.index, k);
            let t = samples[k].0;
            assert_eq!(row.target, [t.x, t.y, t.z]);
            // The same as a field fitted on the others by hand.
            let others: Vec<Sample> = samples
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != k)
                .map(|(_, s)| s.clone())
                .collect();
            let by_hand = ParamField::fit(&space, &others, &settings).expect("fit");
            let all = ParamField::fit(&space, &samples, &settings).expect("fit");
            assert_eq!(all.without(k).expect("without"), by_hand);
            assert_eq!(row.field_params, by_hand.evaluate(&t));
            assert_eq!(row.bandwidth, by_hand.bandwidth());
            assert_eq!(
                row.field_distance,
                score(k, &row.field_params).expect("score")
            );
            // Sample k's own value changed to a bound: row k is bit for bit the same, while
            // the rows of its neighbours (which see it) change.
            let mut changed = samples.clone();
            changed[k].1 = space.upper();
            let again = leave_one_out(&space, &changed, &settings, score).expect("loo");
            assert_eq!(&again[k], row, "{settings:?} row {k}");
            let moved = (0..samples.len())
                .filter(|&j| j != k && again[j].field_params != rows[j].field_params)
                .count();
            assert!(moved > 0, "no other row saw sample {k}");
        }
        let field_mean: f64 =
            rows.iter().map(|r| r.field_distance).sum::<f64>() / rows.len() as f64;
        eprintln!(
            "{:?}: leave-one-out mean normalized distance to the truth {field_mean:.4}",
            settings.regression
        );
    }
}

#[test]
fn leave_one_out_reports_the_first_failing_row() {
    let space = space();
    let samples = noisy_samples(5, 0.02);
    let err = leave_one_out(&space, &samples, &FieldSettings::default(), |k, _| {
        if k == 7 || k == 20 {
            Err(TrainError::Reach {
                clip: format!("reach {k}"),
                why: "synthesis failed".into(),
            })
        } else {
            Ok(0.0)
        }
    })
    .expect_err("failing score");
    match err {
        TrainError::Reach { clip, .. } => assert_eq!(clip, "reach 7"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_auto_bandwidth_is_a_deterministic_candidate_that_follows_the_data() {
    let space = space();
    // The grid's nearest-neighbour distance is 0.1 m for every target.
    let nn = 0.1;
    let candidates: Vec<f64> = AUTO_FACTORS.iter().map(|f| f * nn).collect();
    assert_relative_eq!(candidates[0], 0.05, epsilon = 1e-15);
    assert_relative_eq!(candidates[8], 0.8, epsilon = 1e-15);

    let pick = |samples: &[Sample]| {
        let field = ParamField::fit(&space, samples, &FieldSettings::default()).expect("fit");
        let h = field.bandwidth();
        assert!(
            candidates.iter().any(|c| (c - h).abs() < 1e-12),
            "{h} not a candidate"
        );
        assert_eq!(field.selection().len(), AUTO_FACTORS.len());
        let best = field
            .selection()
            .iter()
            .map(|s| s.loo_error)
            .fold(f64::INFINITY, f64::min);
        let chosen = field
            .selection()
            .iter()
            .find(|s| s.bandwidth == h)
            .expect("chosen in selection");
        assert_eq!(chosen.loo_error, best);
        h
    };

    // Noiseless and smooth: a narrow kernel; pure noise around a constant: the widest.
    let clean: Vec<Sample> = grid().into_iter().map(|t| (t, linear_truth(&t))).collect();
    let mut rng = Lcg(11);
    let noise: Vec<Sample> = grid()
        .into_iter()
        .map(|t| {
            let p = vec![
                4.0 * (rng.next() - 0.5),
                4.0 * (rng.next() - 0.5),
                5.0 + 4.0 * (rng.next() - 0.5),
                10.0 + 8.0 * (rng.next() - 0.5),
            ];
            (t, p)
        })
        .collect();
    let h_clean = pick(&clean);
    let h_noise = pick(&noise);
    let h_noisy = pick(&noisy_samples(3, 0.05));
    eprintln!("auto h: clean {h_clean:.4}, 5% noise {h_noisy:.4}, pure noise {h_noise:.4} m");
    assert!(h_clean <= nn, "{h_clean}");
    assert_relative_eq!(h_noise, 0.8, epsilon = 1e-12);

    // The same bits again, on one thread, and for the samples in another order.
    let a = ParamField::fit(&space, &clean, &FieldSettings::default()).expect("fit");
    let b = ParamField::fit(&space, &clean, &FieldSettings::default()).expect("fit");
    assert_eq!(a, b);
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("pool")
        .install(|| ParamField::fit(&space, &clean, &FieldSettings::default()).expect("fit"));
    assert_eq!(a, one_thread);
    let mut reversed = clean.clone();
    reversed.reverse();
    assert_eq!(pick(&reversed), h_clean);
}

#[test]
fn errors_name_the_field() {
    let space = space();
    let ok = |x: f64| (Point3::new(x, 0.0, 1.0), vec![0.0, 0.0, 5.0, 5.0]);
    let fit = |samples: &[Sample], settings: FieldSettings| {
        setting_field(ParamField::fit(&space, samples, &settings).expect_err("error"))
    };
    let d = FieldSettings::default();

    assert_eq!(fit(&[], d), "samples");

    let mut short = vec![ok(0.1), ok(0.2), ok(0.3)];
    short[2].1.pop();
    let err = ParamField::fit(&space, &short, &d).expect_err("short");
    assert!(
        err.to_string().contains("needs 4 parameters, got 3"),
        "{err}"
    );
    assert_eq!(setting_field(err), "samples[2].params");

    let mut outside = vec![ok(0.1), ok(0.2)];
    outside[1].1[1] = 5.5;
    let err = ParamField::fit(&space, &outside, &d).expect_err("outside");
    assert!(err.to_string().contains("`g_b` = 5.5"), "{err}");
    assert_eq!(setting_field(err), "samples[1].params");

    let mut nan_value = vec![ok(0.1), ok(0.2)];
    nan_value[0].1[3] = f64::NAN;
    assert_eq!(fit(&nan_value, d), "samples[0].params");

    let mut nan_target = vec![ok(0.1), ok(0.2)];
    nan_target[0].0.y = f64::NAN;
    assert_eq!(fit(&nan_target, d), "samples[0].target");
    let mut inf_target = vec![ok(0.1), ok(0.2)];
    inf_target[1].0.z = f64::INFINITY;
    assert_eq!(fit(&inf_target, d), "samples[1].target");
    // A target no arm reaches, whose kernel weights overflowed into NaN parameters.
    let mut far_target = vec![ok(0.1), ok(0.2)];
    far_target[1].0.y = 1e308;
    let err = ParamField::fit(&space, &far_target, &d).expect_err("far");
    assert!(err.to_string().contains("is 1e308"), "{err}");
    assert_eq!(setting_field(err), "samples[1].target[1]");

    for h in [0.0, -0.1, f64::NAN, f64::INFINITY] {
        let s = FieldSettings {
            bandwidth: Bandwidth::Fixed(h),
            ..d
        };
        assert_eq!(fit(&[ok(0.1)], s), "field.bandwidth", "{h}");
    }
    for ridge in [-1e-3, f64::NAN] {
        let s = FieldSettings {
            regression: Regression::LocalLinear { ridge },
            ..d
        };
        assert_eq!(fit(&[ok(0.1)], s), "field.ridge", "{ridge}");
    }

    let one = ParamField::fit(&space, &[ok(0.1)], &d).expect("fit");
    assert_eq!(setting_field(one.without(0).expect_err("one")), "samples");
    let two = ParamField::fit(&space, &[ok(0.1), ok(0.2)], &d).expect("fit");
    assert_eq!(setting_field(two.without(2).expect_err("index")), "k");
    assert_eq!(
        setting_field(
            two.try_evaluate(&Point3::new(f64::NAN, 0.0, 0.0))
                .expect_err("nan")
        ),
        "target"
    );
    let loo = leave_one_out(&space, &[ok(0.1)], &d, |_, _| Ok(0.0)).expect_err("one");
    assert_eq!(setting_field(loo), "samples");
    let loo = leave_one_out(&space, &nan_target, &d, |_, _| Ok(0.0)).expect_err("nan");
    assert_eq!(setting_field(loo), "samples[0].target");
}

#[test]
fn a_non_finite_target_gets_the_mean_within_bounds() {
    let space = space();
    let samples = vec![
        (Point3::new(0.1, 0.0, 1.0), vec![-5.0, 1.0, 1.0, 0.0]),
        (Point3::new(0.3, 0.0, 1.0), vec![5.0, 3.0, 10.0, 20.0]),
    ];
    let field = ParamField::fit(&space, &samples, &FieldSettings::default()).expect("fit");
    let p = field.evaluate(&Point3::new(f64::NAN, 0.0, f64::INFINITY));
    assert_eq!(p, vec![0.0, 2.0, 5.5, 10.0]);
}

fn arb_value(lower: f64, upper: f64) -> impl Strategy<Value = f64> {
    prop_oneof![
        1 => Just(lower),
        1 => Just(upper),
        4 => lower..=upper,
    ]
}

fn arb_params() -> impl Strategy<Value = Vec<f64>> {
    (
        arb_value(-5.0, 5.0),
        arb_value(-5.0, 5.0),
        arb_value(1.0, 10.0),
        arb_value(0.0, 20.0),
    )
        .prop_map(|(a, b, c, d)| vec![a, b, c, d])
}

fn arb_point(span: f64) -> impl Strategy<Value = Point3<f64>> {
    prop_oneof![
        // Some targets on a coarse lattice, so that duplicates and coplanar sets occur.
        3 => (-2i32..=2, -2i32..=2, 0i32..=1)
            .prop_map(|(x, y, z)| Point3::new(0.1 * x as f64, 0.1 * y as f64, 1.0 + 0.1 * z as f64)),
        5 => (-span..span, -span..span, -span..span).prop_map(|(x, y, z)| Point3::new(x, y, z)),
    ]
}

fn arb_settings() -> impl Strategy<Value = FieldSettings> {
    let bandwidth = prop_oneof![
        Just(Bandwidth::Auto),
        (1e-4f64..10.0).prop_map(Bandwidth::Fixed),
    ];
    let regression = prop_oneof![
        Just(Regression::NadarayaWatson),
        (0.0f64..1.0).prop_map(|ridge| Regression::LocalLinear { ridge }),
        Just(Regression::LocalLinear { ridge: 0.0 }),
    ];
    (bandwidth, regression).prop_map(|(bandwidth, regression)| FieldSettings {
        bandwidth,
        regression,
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    #[test]
    fn the_field_never_leaves_the_bounds(
        samples in prop::collection::vec((arb_point(1.0), arb_params()), 1..12),
        settings in arb_settings(),
        targets in prop::collection::vec(arb_point(1e3), 1..8),
    ) {
        let space = space();
        let field = ParamField::fit(&space, &samples, &settings).expect("fit");
        prop_assert!(field.bandwidth() > 0.0 && field.bandwidth().is_finite());
        let extra = [Point3::new(1e300, -1e300, 0.0), samples[0].0 + Vector3::new(0.0, 0.0, 1e-9)];
        for t in targets.iter().chain(&extra) {
            let p = field.evaluate(t);
            prop_assert!(space.validate(&p).is_ok(), "{:?} at {} is out of bounds", p, t);
            if settings.regression == Regression::NadarayaWatson {
                // A convex combination: within the samples' range of every entry.
                for (i, v) in p.iter().enumerate() {
                    let lo = samples.iter().map(|s| s.1[i]).fold(f64::INFINITY, f64::min);
                    let hi = samples.iter().map(|s| s.1[i]).fold(f64::NEG_INFINITY, f64::max);
                    prop_assert!(lo <= *v && *v <= hi, "entry {} = {} outside [{}, {}]", i, v, lo, hi);
                }
            }
        }
    }
}
