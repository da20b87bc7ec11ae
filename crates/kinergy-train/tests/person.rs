//! A person's parameters as a product: the field file written and read back predicts what it
//! predicted before; targets in the arm's base frame do not depend on where the person stands
//! or which way they face; a field whose samples share one vector predicts it everywhere;
//! `PersonParams` takes a parameters file or a field file and names a file that is neither,
//! an older field format, or a damaged field.

use std::path::{Path, PathBuf};

use kinergy_motion::nalgebra::Point3;
use kinergy_motion::{ArmJoints, Clip, ImportOptions, Side, read_clip};
use kinergy_solver::{
    BaseMode, Bounds, FittedArm, FittedReach, Model, OptimizerKind, ParamSpace, ParamsFile,
};
use kinergy_train::anneal::AnnealSettings;
use kinergy_train::field::{Bandwidth, FieldFile, FieldSettings, ParamField, Regression};
use kinergy_train::fit::FitSettings;
use kinergy_train::synthetic::{Truth, made_reach};
use kinergy_train::{CapturedReach, PersonParams, TrainError};

fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(path)
}

/// Three reaches made by the controller from the fixture's first frame toward different
/// targets with one S_C vector.
fn made_reaches() -> Vec<CapturedReach> {
    let (clip, _) =
        read_clip(&repo("tests/data/006_14.bvh"), &ImportOptions::default()).expect("fixture");
    let arm = ArmJoints::find(clip.skeleton(), Side::Right).expect("arm");
    let truth = [1.4, 0.7, 1.1, 1.8, 0.6, 0.9, 1.2, 7.0, 1.5];
    let offsets: [[f64; 7]; 3] = [
        [0.35, -0.25, -0.3, -0.5, 0.2, 0.1, 0.05],
        [0.2, -0.4, 0.1, -0.7, 0.1, 0.0, 0.1],
        [0.45, -0.1, -0.2, -0.3, 0.3, 0.2, 0.0],
    ];
    offsets
        .iter()
        .enumerate()
        .map(|(k, offset)| {
            made_reach(
                &format!("made/r{k}"),
                &clip,
                &arm,
                40,
                Truth {
                    model: Model::Sc,
                    values: &truth,
                    optimizer: OptimizerKind::Svd.default_optimizer(),
                },
                offset,
            )
            .expect("made reach")
            .reach
        })
        .collect()
}

fn quick_fit() -> FitSettings {
    FitSettings {
        anneal: AnnealSettings {
            max_evaluations: 40,
            population: 8,
            seed: 3,
            ..AnnealSettings::default()
        },
        ..FitSettings::default()
    }
}

#[test]
fn a_field_file_read_back_predicts_what_it_predicted() {
    let reaches = made_reaches();
    let (file, nested) = FieldFile::fit(
        &reaches,
        &[Model::Sa, Model::Sc],
        OptimizerKind::Svd.default_optimizer(),
        &quick_fit(),
        &FieldSettings::default(),
    )
    .expect("field");
    // Each reach its own nested fit; the field holds the richest model's vectors at the
    // reaches' targets in the arm's base frame, with their clips, frames and arms.
    assert_eq!(nested.len(), 3);
    assert_eq!(file.model(), Model::Sc);
    for (k, (reach, fits)) in reaches.iter().zip(&nested).enumerate() {
        let last = fits.fits.last().expect("fits");
        assert_eq!(file.field().values()[k], last.values);
        assert_eq!(file.field().targets()[k], reach.local_target());
        let record = &file.reaches()[k];
        assert_eq!(record.clip, reach.name());
        assert_eq!(record.frames, [reach.frames().start, reach.frames().end]);
        assert_eq!(record.distance_m, last.score);
        assert_eq!(record.arm.as_ref(), Some(reach.fitted_arm()));
    }
    // The base frame keeps distances: the target is as far from the origin (the shoulder)
    // as it is from the captured shoulder in the world.
    for reach in &reaches {
        let shoulder = reach.captured().frame(0)[0];
        approx::assert_relative_eq!(
            reach.local_target().coords.norm(),
            (reach.target() - shoulder).norm(),
            epsilon = 1e-12
        );
    }

    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("field.json");
    file.write(&path).expect("write");
    let read = PersonParams::read(&path).expect("read");
    let Some(back) = read.field() else {
        panic!("read as a single vector: {read:?}");
    };
    assert_eq!(back, &file);
    assert_eq!(read.model(), Model::Sc);
    let targets = [
        Point3::new(0.1, -0.4, 0.3),
        file.field().targets()[1],
        Point3::new(-2.0, 5.0, 0.0),
    ];
    for t in targets {
        let before = file.params_for(&t).expect("before");
        let after = read.params_for(&t).expect("after");
        assert_eq!(after, before);
        assert_eq!(after.values().expect("values"), file.field().evaluate(&t));
        assert_eq!(after.optimizer, file.optimizer());
        assert_eq!(after.dof_names, reaches[0].dof_names());
        // The predicted file carries the arms the field was fitted on.
        let record = after.fit.as_ref().expect("record");
        assert_eq!(record.method, kinergy_solver::FitMethod::ParameterField);
        assert_eq!(
            record.arm(|c| c == "made/r2"),
            Some(reaches[2].fitted_arm())
        );
        // And it reads back as a plain parameters file.
        assert_eq!(
            ParamsFile::from_json(&after.to_json()).expect("plain"),
            after
        );
    }
    let err = read
        .params_for(&Point3::new(f64::NAN, 0.0, 0.0))
        .expect_err("nan");
    assert!(err.to_string().contains("`target`"), "{err}");
}

/// `clip` with the whole body turned by `yaw` about the vertical through the root and moved
/// by (dx, dz) on the floor, for a skeleton whose root's outermost rotation is about Y.
fn moved(clip: &Clip, yaw: f64, dx: f64, dz: f64) -> Clip {
    let skeleton = clip.skeleton();
    let names: Vec<String> = (0..4).filter_map(|d| skeleton.dof_name(d)).collect();
    assert!(
        names[0].ends_with("Xposition")
            && names[2].ends_with("Zposition")
            && names[3].ends_with("Yrotation"),
        "{names:?}"
    );
    let n = skeleton.dof_count();
    let mut values = clip.values().to_vec();
    for frame in values.chunks_mut(n) {
        let (x, z) = (frame[0], frame[2]);
        // A yaw about the world origin turns the root's position too.
        frame[0] = yaw.cos() * x + yaw.sin() * z + dx;
        frame[2] = -yaw.sin() * x + yaw.cos() * z + dz;
        frame[3] += yaw;
    }
    Clip::new(skeleton.clone(), clip.frame_time(), values).expect("moved clip")
}

#[test]
fn targets_in_the_base_frame_do_not_depend_on_where_the_person_stands() {
    let (clip, _) = read_clip(
        &repo("data-synthetic/p01/r01.bvh"),
        &ImportOptions::default(),
    )
    .expect("clip");
    let arm = ArmJoints::find(clip.skeleton(), Side::Right).expect("arm");
    let frames = 4..72;
    let here =
        CapturedReach::new("here", &clip, &arm, frames.clone(), BaseMode::Replay).expect("reach");
    let there = CapturedReach::new(
        "there",
        &moved(&clip, 1.1, 2.0, -3.0),
        &arm,
        frames,
        BaseMode::Replay,
    )
    .expect("moved reach");
    // The world target moved by meters; the target for the arm did not.
    assert!((here.target() - there.target()).norm() > 1.0);
    approx::assert_relative_eq!(here.local_target(), there.local_target(), epsilon = 1e-9);
}

fn space() -> ParamSpace {
    let dofs: Vec<String> = ["a", "b"].map(String::from).to_vec();
    ParamSpace::new(Model::Sc, &dofs, Bounds::default()).expect("space")
}

fn records(count: usize, side: Side) -> Vec<FittedReach> {
    (0..count)
        .map(|k| FittedReach {
            clip: format!("takes/t{k}.bvh"),
            frames: [2 * k, 2 * k + 30],
            distance_m: 0.02,
            arm: Some(FittedArm {
                side: Some(side),
                joints: vec!["LeftArm".into(), "LeftForeArm".into(), "LeftHand".into()],
                upper_arm_m: 0.29,
                forearm_m: 0.24,
                hand_m: 0.0,
            }),
            tempo: None,
        })
        .collect()
}

/// A field file of five samples at scattered targets.
fn field_file(values: impl Fn(usize) -> Vec<f64>, settings: FieldSettings) -> FieldFile {
    let targets = [
        [0.1, -0.5, 0.2],
        [0.3, 0.1, 0.1],
        [-0.2, 0.4, 0.3],
        [0.0, 0.6, -0.1],
        [0.25, -0.2, 0.45],
    ];
    let samples: Vec<(Point3<f64>, Vec<f64>)> = targets
        .iter()
        .enumerate()
        .map(|(k, t)| (Point3::from(*t), values(k)))
        .collect();
    let field = ParamField::fit(&space(), &samples, &settings).expect("field");
    FieldFile::new(
        field,
        OptimizerKind::Svd.default_optimizer(),
        records(5, Side::Left),
    )
    .expect("file")
}

#[test]
fn a_field_whose_samples_share_one_vector_predicts_it_everywhere() {
    let shared = vec![1.25, -0.75, 4.5, 2.0];
    for bandwidth in [
        Bandwidth::Auto,
        Bandwidth::Fixed(0.01),
        Bandwidth::Fixed(5.0),
    ] {
        for regression in [Regression::NadarayaWatson, Regression::local_linear()] {
            let settings = FieldSettings {
                bandwidth,
                regression,
            };
            let person = PersonParams::Field(field_file(|_| shared.clone(), settings));
            for t in [
                [0.0, 0.0, 0.0],
                [0.3, 0.1, 0.1],
                [0.12, -0.31, 0.27],
                [40.0, -9.0, 3.0],
            ] {
                let file = person.params_for(&Point3::from(t)).expect("params");
                assert_eq!(file.values().expect("values"), shared, "{settings:?} {t:?}");
            }
        }
    }
}

#[test]
fn person_params_reads_a_parameters_file_as_one_vector_for_every_target() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("me.json");
    let file = ParamsFile::new(
        &space(),
        OptimizerKind::Dls.default_optimizer(),
        &[1.0, 2.0, 3.0, 4.0],
    )
    .expect("file");
    file.write(&path).expect("write");
    let person = PersonParams::read(&path).expect("read");
    assert!(person.field().is_none());
    assert_eq!(person.optimizer(), file.optimizer);
    for t in [[0.0, 0.0, 0.0], [1.0, -2.0, 0.5]] {
        assert_eq!(person.params_for(&Point3::from(t)).expect("params"), file);
    }
}

/// The error of reading `text` as a person's parameters from a file named `name`.
fn read_error(dir: &Path, name: &str, text: &str) -> String {
    let path = dir.join(name);
    std::fs::write(&path, text).expect("write");
    let err = PersonParams::read(&path).expect_err(name);
    assert!(matches!(err, TrainError::File { .. }), "{err:?}");
    let shown = err.to_string();
    assert!(shown.starts_with(&path.display().to_string()), "{shown}");
    shown
}

#[test]
fn older_versions_damaged_fields_and_other_files_are_named() {
    let dir = tempfile::tempdir().expect("tempdir");
    let good = field_file(
        |k| vec![k as f64 * 0.5, 1.0, 5.0, 2.0],
        FieldSettings::default(),
    );
    let json: serde_json::Value = serde_json::from_str(&good.to_json()).expect("json");
    let edited = |edit: &dyn Fn(&mut serde_json::Value)| {
        let mut v = json.clone();
        edit(&mut v);
        v.to_string()
    };

    // Format 1 held world targets and no optimizer: refused, saying what to do.
    let e = read_error(
        dir.path(),
        "v1.json",
        &edited(&|v| v["format_version"] = 1.into()),
    );
    assert!(
        e.contains("`format_version` is 1") && e.contains("kinergy fit --field"),
        "{e}"
    );
    // Format 2 has no anchor.
    let e = read_error(
        dir.path(),
        "v2.json",
        &edited(&|v| v["format_version"] = 2.into()),
    );
    assert!(
        e.contains("`format_version` is 2") && e.contains("no anchor"),
        "{e}"
    );
    let e = read_error(
        dir.path(),
        "v4.json",
        &edited(&|v| v["format_version"] = 4.into()),
    );
    assert!(e.contains("format_version") && e.contains("reads 3"), "{e}");

    // Damage is named by its field.
    for (edit, field) in [
        (
            &(|v: &mut serde_json::Value| v["samples"][2]["values"][1] = 7.5.into())
                as &dyn Fn(&mut serde_json::Value),
            "`samples[2].values`",
        ),
        (
            &|v: &mut serde_json::Value| v["samples"][1]["target"] = serde_json::json!([0, 1]),
            "samples[1].target",
        ),
        (
            &|v: &mut serde_json::Value| v["samples"][3]["frames"] = serde_json::json!([9, 4]),
            "`samples[3].frames` is [9, 4]",
        ),
        (
            &|v: &mut serde_json::Value| v["samples"][0]["arm"]["forearm_m"] = 0.into(),
            "`samples[0].arm.forearm_m` is 0",
        ),
        (
            &|v: &mut serde_json::Value| v["samples"][4]["arm"]["side"] = "right".into(),
            "`samples[4].arm.side` is right but sample 0's is left",
        ),
        (
            &|v: &mut serde_json::Value| v["samples"] = serde_json::json!([]),
            "`samples` is empty",
        ),
        (
            &|v: &mut serde_json::Value| v["bandwidth"] = 0.into(),
            "`bandwidth` is 0",
        ),
        (
            &|v: &mut serde_json::Value| v["names"][0] = "g_c".into(),
            "`names`",
        ),
        (
            &|v: &mut serde_json::Value| v["optimizer"]["rate"] = (-1.0).into(),
            "optimizer.rate",
        ),
        (
            &|v: &mut serde_json::Value| {
                v["samples"][0]
                    .as_object_mut()
                    .expect("sample")
                    .remove("arm");
            },
            "samples[0]",
        ),
    ] {
        let e = read_error(dir.path(), "damaged.json", &edited(edit));
        assert!(e.contains(field), "expected {field} in: {e}");
    }

    // Neither kind, or not JSON at all.
    let e = read_error(
        dir.path(),
        "other.json",
        r#"{"format_version": 1, "objects": []}"#,
    );
    assert!(e.contains("neither a parameters file"), "{e}");
    let e = read_error(dir.path(), "text.json", "hello");
    assert!(e.contains("not JSON") && e.contains("line 1"), "{e}");
    // A damaged parameters file is named the same way.
    let params = ParamsFile::new(
        &space(),
        OptimizerKind::Svd.default_optimizer(),
        &[1.0, 1.0, 2.0, 0.0],
    )
    .expect("params")
    .to_json()
    .replace("\"s\": 2.0", "\"s\": 20.0");
    let e = read_error(dir.path(), "params.json", &params);
    assert!(e.contains("`s` = 20"), "{e}");
    let missing = dir.path().join("absent.json");
    let e = PersonParams::read(&missing)
        .expect_err("absent")
        .to_string();
    assert!(
        e.contains("absent.json") && e.contains("cannot read"),
        "{e}"
    );
}
