//! The field file: its JSON round trip is exact and loading checks it; an anchored field is
//! its anchor plus how the samples vary with the target.

mod field_support;

use kinergy_motion::Side;
use kinergy_motion::nalgebra::Point3;
use kinergy_solver::{FittedArm, FittedReach, OptimizerKind};
use kinergy_train::field::{Bandwidth, FieldFile, FieldSettings, ParamField};

use field_support::{Sample, all_settings, grid, noisy_samples, space};

/// One fitted reach per sample, as a field file records them.
fn reaches(count: usize) -> Vec<FittedReach> {
    (0..count)
        .map(|k| FittedReach {
            clip: format!("p01/r{k:02}.bvh"),
            frames: [k, k + 40],
            distance_m: 0.01 + 0.001 * k as f64,
            arm: Some(FittedArm {
                side: Some(Side::Right),
                joints: vec!["RightArm".into(), "RightForeArm".into(), "RightHand".into()],
                upper_arm_m: 0.3,
                forearm_m: 0.25,
                hand_m: 0.0,
            }),
            tempo: None,
        })
        .collect()
}

#[test]
fn json_round_trip_is_exact_and_loading_checks() {
    let space = space();
    let samples = noisy_samples(9, 0.05);
    let optimizer = OptimizerKind::Njt.default_optimizer();
    for settings in all_settings() {
        let field = ParamField::fit(&space, &samples, &settings).expect("fit");
        let file = FieldFile::new(field.clone(), optimizer, reaches(samples.len())).expect("file");
        let back = FieldFile::from_json(&file.to_json()).expect("from json");
        assert_eq!(back, file);
        let t = Point3::new(0.37, 0.02, 1.13);
        assert_eq!(back.field().evaluate(&t), field.evaluate(&t));
        assert_eq!(back.field().space(), &space);
        assert_eq!(back.optimizer(), optimizer);
    }
    let field = ParamField::fit(&space, &samples, &FieldSettings::default()).expect("fit");
    let file = FieldFile::new(field, optimizer, reaches(samples.len())).expect("file");
    let mut json: serde_json::Value = serde_json::from_str(&file.to_json()).expect("value");
    assert_eq!(json["format_version"], 3);
    assert!(json.get("anchor").is_none());
    assert_eq!(json["model"], "sc");
    assert_eq!(json["optimizer"]["kind"], "njt");
    assert_eq!(json["names"][3], "o");
    assert_eq!(json["settings"]["bandwidth"], "auto");
    assert_eq!(json["samples"][0]["target"][0], 0.2);
    assert_eq!(json["samples"][1]["clip"], "p01/r01.bvh");
    assert_eq!(json["samples"][1]["arm"]["side"], "right");

    let load = |v: &serde_json::Value| FieldFile::from_json(&v.to_string());
    let mut outside = json.clone();
    outside["samples"][4]["values"][0] = serde_json::json!(6.0);
    let err = load(&outside).expect_err("outside");
    assert!(err.to_string().contains("`samples[4].values`"), "{err}");

    let mut bad_h = json.clone();
    bad_h["bandwidth"] = serde_json::json!(-1.0);
    let err = load(&bad_h).expect_err("bandwidth");
    assert!(err.to_string().contains("`bandwidth` is -1"), "{err}");

    // A flat bandwidth (null) is an anchored field's only.
    let mut flat = json.clone();
    flat["bandwidth"] = serde_json::Value::Null;
    let err = load(&flat).expect_err("flat without anchor");
    assert!(err.to_string().contains("needs an anchor"), "{err}");

    let mut old = json.clone();
    old["format_version"] = serde_json::json!(2);
    let err = load(&old).expect_err("format 2");
    assert!(err.to_string().contains("no anchor"), "{err}");

    json["extra"] = serde_json::json!(1);
    let err = load(&json).expect_err("extra");
    assert!(err.to_string().contains("extra"), "{err}");
}

/// An anchored field is its anchor plus how the samples vary with the target: samples with
/// one vector everywhere give the anchor everywhere, exactly (and the flat bandwidth, ∞,
/// chosen on the tie, written as null and read back); samples with a linear dependence give
/// the anchor moved by exactly what the plain field moves between two targets (within the
/// bounds); a bad anchor is refused by name; files round-trip.
#[test]
fn an_anchored_field_is_its_anchor_plus_the_dependence_on_the_target() {
    let space = space();
    let optimizer = OptimizerKind::Njt.default_optimizer();
    let anchor = vec![0.5, -0.25, 4.0, 8.0];
    let same: Vec<Sample> = grid()
        .into_iter()
        .map(|t| (t, vec![1.0, 1.0, 5.0, 10.0]))
        .collect();
    let flat = ParamField::fit(&space, &same, &FieldSettings::default())
        .expect("fit")
        .anchored(anchor.clone())
        .expect("anchored");
    assert_eq!(flat.bandwidth(), f64::INFINITY);
    for t in [Point3::new(0.3, 0.1, 1.0), Point3::new(-4.0, 2.0, 9.0)] {
        assert_eq!(flat.evaluate(&t), anchor);
    }
    let file = FieldFile::new(flat, optimizer, reaches(same.len())).expect("file");
    let json: serde_json::Value = serde_json::from_str(&file.to_json()).expect("json");
    assert!(json["bandwidth"].is_null(), "{}", json["bandwidth"]);
    assert_eq!(json["anchor"][2], 4.0);
    assert_eq!(FieldFile::from_json(&file.to_json()).expect("back"), file);

    let samples = noisy_samples(3, 0.0);
    for settings in all_settings() {
        let plain = ParamField::fit(&space, &samples, &settings).expect("fit");
        let anchored = plain.anchored(anchor.clone()).expect("anchored");
        let (a, b) = (Point3::new(0.25, 0.0, 1.05), Point3::new(0.4, 0.05, 1.1));
        let h = anchored.bandwidth();
        assert!(h.is_finite(), "a linear field is not flat: {h}");
        let fixed = FieldSettings {
            bandwidth: Bandwidth::Fixed(h),
            ..settings
        };
        let plain = ParamField::fit(&space, &samples, &fixed).expect("fit");
        let (pa, pb) = (plain.evaluate(&a), plain.evaluate(&b));
        let (qa, qb) = (anchored.evaluate(&a), anchored.evaluate(&b));
        for i in 0..anchor.len() {
            let (lo, hi) = (space.lower()[i], space.upper()[i]);
            if qa[i] > lo && qa[i] < hi && qb[i] > lo && qb[i] < hi {
                assert!(
                    ((qb[i] - qa[i]) - (pb[i] - pa[i])).abs() < 1e-9,
                    "{settings:?} entry {i}"
                );
            }
        }
        let file =
            FieldFile::new(anchored.clone(), optimizer, reaches(samples.len())).expect("file");
        let back = FieldFile::from_json(&file.to_json()).expect("back");
        assert_eq!(back.field().evaluate(&a), qa);
    }
    let err = ParamField::fit(&space, &samples, &FieldSettings::default())
        .expect("fit")
        .anchored(vec![9.0, 0.0, 5.0, 10.0])
        .expect_err("outside");
    assert!(err.to_string().contains("`anchor`"), "{err}");
}
