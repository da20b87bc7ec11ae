//! End-to-end tests of the parameter field as a product: `fit --field` fits each reach on its
//! own, as `--per clip` does, and writes a field file whose targets are in the arm's base
//! frame; `synthesize --params` takes it and says the vector came from a field; an older,
//! damaged or mixed-arm field is bad input that names what is wrong.

mod common;

use std::path::{Path, PathBuf};

use common::{assert_bad_input, json, kinergy, s, shared, stderr, synthetic};
use kinergy_motion::{ArmJoints, ImportOptions, Side, read_clip};

/// `kinergy fit CLIPS --model MODEL --budget BUDGET --seed 2 EXTRA…`, which must succeed; its
/// `--json` report when asked for.
fn fit(clips: &[&Path], model: &str, budget: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["fit"];
    args.extend(clips.iter().map(|c| s(c)));
    args.extend(["--model", model, "--budget", budget, "--seed", "2"]);
    args.extend(extra);
    let o = kinergy(&args);
    assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
    if extra.contains(&"--json") {
        json(&o)
    } else {
        serde_json::Value::Null
    }
}

fn read_json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).expect("read")).expect("json")
}

/// The distance from the right shoulder on `frames[0]` to the right hand point on the
/// frame before `frames[1]`, from the capture itself: what a target's distance from the
/// base frame's origin must be.
fn shoulder_to_hand(clip: &Path, frames: [u64; 2]) -> f64 {
    let (clip, _) = read_clip(clip, &ImportOptions::default()).expect("clip");
    let arm = ArmJoints::find(clip.skeleton(), Side::Right).expect("arm");
    let at = |frame: u64| {
        clip.skeleton()
            .world_positions(clip.frame(frame as usize).expect("frame"))
            .expect("positions")
    };
    let first = at(frames[0]);
    let last = at(frames[1] - 1);
    (last[arm.hand.expect("hand point")] - first[arm.shoulder]).norm()
}

#[test]
fn fit_field_writes_a_field_file_of_per_reach_fits_that_synthesize_reads() {
    let dir = tempfile::tempdir().expect("tempdir");
    let clips = [
        synthetic("r01.bvh"),
        synthetic("r02.bvh"),
        synthetic("r09.bvh"),
    ];
    let clips: Vec<&Path> = clips.iter().map(PathBuf::as_path).collect();
    let out = dir.path().join("field.json");
    let report = fit(&clips, "sc", "60", &["--field", "-o", s(&out), "--json"]);

    // The report: kind, bandwidth (null: flat) and leave-one-out, one row per reach.
    assert_eq!(report["kind"], "field");
    assert_eq!(report["model"], "sc");
    let h = report["bandwidth_m"].as_f64();
    assert!(h.is_none_or(|h| h > 0.0 && h.is_finite()), "{report}");
    assert!(report["loo_error"].as_f64().expect("loo error") >= 0.0);
    let rows = report["samples"].as_array().expect("samples");
    assert_eq!(rows.len(), 3);
    let loo: Vec<f64> = rows
        .iter()
        .map(|r| r["loo_distance_m"].as_f64().expect("loo distance"))
        .collect();
    let mean = loo.iter().sum::<f64>() / 3.0;
    approx::assert_relative_eq!(
        report["loo_distance_m"].as_f64().expect("mean"),
        mean,
        max_relative = 1e-12
    );

    // The file: format 3, the optimizer, the anchor, per sample its clip, frames, arm and
    // target.
    let file = read_json(&out);
    assert_eq!(file["format_version"], 3);
    assert_eq!(file["optimizer"]["kind"], "svd");
    assert_eq!(file["bandwidth"].as_f64(), h);
    let samples = file["samples"].as_array().expect("samples");
    assert_eq!(samples.len(), 3);
    // The anchor is the person's single vector: what `fit --per person` fits on the same
    // reaches with the same search.
    let person = dir.path().join("person.json");
    fit(&clips, "sc", "60", &["--per", "person", "-o", s(&person)]);
    let person = read_json(&person);
    let names = file["names"].as_array().expect("names");
    for (name, v) in names.iter().zip(file["anchor"].as_array().expect("anchor")) {
        let name = name.as_str().expect("name");
        assert_eq!(person["values"][name], *v, "anchor {name}");
    }
    let anchor_distance = report["anchor_distance_m"]
        .as_f64()
        .expect("anchor distance");
    assert_eq!(
        person["fit"]["score_m"].as_f64(),
        Some(anchor_distance),
        "{report}"
    );
    // One controller: the field runs under the person's tempo law, the law the person's
    // single vector was fitted under and records.
    assert!(file["tempo_law"].is_object(), "{file}");
    assert_eq!(file["tempo_law"], person["fit"]["tempo_law"]);
    // Each reach was fitted on its own, as `--per clip` fits it with the same search, but
    // under the person's law rather than its own capture's speed: the same reach and frames,
    // other bounds, so other values.
    let per_clip = dir.path().join("clips/");
    fit(&clips, "sc", "60", &["--per", "clip", "-o", s(&per_clip)]);
    for (k, (sample, clip)) in samples.iter().zip(&clips).enumerate() {
        assert_eq!(sample["clip"], rows[k]["clip"]);
        assert_eq!(sample["arm"]["side"], "right");
        // A result is named by its take's whole file name (`r01.bvh.json`).
        let own = read_json(&per_clip.join(format!(
            "{}.json",
            clip.file_name().expect("name").to_string_lossy()
        )));
        assert_eq!(sample["frames"], own["fit"]["reaches"][0]["frames"]);
        assert_eq!(sample["tempo"], own["fit"]["reaches"][0]["tempo"]);
        // The target is in the arm's base frame: as far from its origin as the captured hand
        // ends from the captured shoulder where the reach starts.
        let frames: Vec<u64> = sample["frames"]
            .as_array()
            .expect("frames")
            .iter()
            .map(|f| f.as_u64().expect("frame"))
            .collect();
        let t: Vec<f64> = sample["target"]
            .as_array()
            .expect("target")
            .iter()
            .map(|c| c.as_f64().expect("coordinate"))
            .collect();
        approx::assert_relative_eq!(
            (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt(),
            shoulder_to_hand(clip, [frames[0], frames[1]]),
            epsilon = 1e-6
        );
    }

    // synthesize takes the field where it takes a parameters file, and says so.
    let motion = dir.path().join("r01.bvh");
    let o = kinergy(&[
        "synthesize",
        s(clips[0]),
        "--params",
        s(&out),
        "-o",
        s(&motion),
        "--json",
    ]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    let r = json(&o);
    assert_eq!(r["params_from"], "field");
    assert_eq!(r["model"], "sc");
    assert_eq!(r["field"]["bandwidth_m"].as_f64(), h);
    assert_eq!(r["field"]["samples"], 3);
    // The fitted frames of r01 (the field records them), and its own target: the sample's.
    assert_eq!(r["capture_frames"], samples[0]["frames"]);
    for i in 0..3 {
        approx::assert_relative_eq!(
            r["field"]["target_in_base_m"][i]
                .as_f64()
                .expect("coordinate"),
            samples[0]["target"][i].as_f64().expect("coordinate"),
            epsilon = 1e-12
        );
    }
    assert!(motion.exists());
    let o = kinergy(&[
        "synthesize",
        s(clips[0]),
        "--params",
        s(&out),
        "-o",
        s(&motion),
    ]);
    assert!(matches!(o.status.code(), Some(0 | 1)), "{}", stderr(&o));
    let shown = common::stdout(&o);
    assert!(
        shown.contains("predicted by the field of 3 reaches (bandwidth")
            || shown.contains("predicted by the field of 3 reaches (flat"),
        "{shown}"
    );
}

#[test]
fn old_damaged_and_misused_field_files_are_bad_input_naming_the_field() {
    let dir = tempfile::tempdir().expect("tempdir");
    let clips = [synthetic("r01.bvh"), synthetic("r02.bvh")];
    let clips: Vec<&Path> = clips.iter().map(PathBuf::as_path).collect();
    let good = dir.path().join("field.json");
    fit(&clips, "sa", "20", &["--field", "-o", s(&good)]);
    let out = dir.path().join("out.bvh");
    let write = |name: &str, edit: &dyn Fn(&mut serde_json::Value)| {
        let mut v = read_json(&good);
        edit(&mut v);
        let path = dir.path().join(name);
        std::fs::write(&path, v.to_string()).expect("write");
        path
    };
    let synthesize = |params: &Path, needle: &str| {
        assert_bad_input(
            &[
                "synthesize",
                s(clips[0]),
                "--params",
                s(params),
                "-o",
                s(&out),
            ],
            needle,
            &out,
        );
    };
    let damaged = write("damaged.json", &|v| {
        v["samples"][1]["values"][0] = serde_json::json!(99.0)
    });
    synthesize(&damaged, "damaged.json: `samples[1].values`");
    let arm = write("arm.json", &|v| {
        v["samples"][0]["arm"]["upper_arm_m"] = serde_json::json!(-0.3)
    });
    synthesize(&arm, "`samples[0].arm.upper_arm_m` is -0.3");
    // The sweep's target of 1e308 m, once "synergy parameter `g` = NaN is outside its
    // bounds": the value in the file, short.
    let far = write("far.json", &|v| {
        v["samples"][0]["target"][0] = serde_json::json!(1e308)
    });
    synthesize(&far, "far.json: `samples[0].target[0]` is 1e308");
    let old = write("old.json", &|v| v["format_version"] = serde_json::json!(1));
    synthesize(&old, "run `kinergy fit --field` again");
    let neither = write("neither.json", &|v| {
        *v = serde_json::json!({"format_version": 2, "model": "sa"});
    });
    synthesize(&neither, "neither a parameters file");

    // --field makes one field of one arm's reaches: not per clip, not to a folder, not of
    // both arms.
    let to = dir.path().join("f.json");
    let fit_args = |extra: &[&'static str]| -> Vec<String> {
        let mut a: Vec<String> = ["fit", s(clips[0]), s(clips[1]), "--model", "sa", "--field"]
            .map(String::from)
            .to_vec();
        a.extend(extra.iter().map(|x| x.to_string()));
        a
    };
    let run = |args: Vec<String>, needle: &str, out: &Path| {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        assert_bad_input(&args, needle, out);
    };
    let mut per_clip = fit_args(&["--per", "clip", "-o"]);
    per_clip.push(s(&to).to_string());
    run(per_clip, "drop --per clip", &to);
    let folder = dir.path().join("fields");
    let mut to_folder = fit_args(&["-o"]);
    to_folder.push(format!("{}/", folder.display()));
    run(to_folder, "one field file", &folder);
    let segments = dir.path().join("segments.csv");
    std::fs::write(
        &segments,
        format!(
            "clip,onset,end,arm\n{},4,72,right\n{},1,54,left\n",
            clips[0].display(),
            clips[1].display()
        ),
    )
    .expect("segments");
    run(
        [
            "fit",
            "--segments",
            s(&segments),
            "--model",
            "sa",
            "--field",
            "-o",
            s(&to),
        ]
        .map(String::from)
        .to_vec(),
        "a field holds one arm's reaches",
        &to,
    );
}

/// On held-out takes the person's field is at least as good as their single vector.
/// Bandai raise-left, each style a person, fitted on takes 1–6 and scored on 7–8 (`compare
/// --per person --holdout 2 --seed 1`): the field, anchored to the single vector, at least as
/// good for every person and over all (measured: active equal — its field is flat, the vector
/// itself —, elderly 32.00 vs 32.26 mm, normal 27.58 vs 27.92 mm). Skipped where the shared
/// data are absent.
#[test]
fn on_held_out_bandai_takes_the_field_is_at_least_as_good_as_the_single_vector() {
    let Some(folder) = shared("bandai-raise-left", "") else {
        return;
    };
    let dir = tempfile::tempdir().expect("tempdir");
    let report = common::held_out_per_person(&folder, "1", &[], dir.path());
    let lines = report["field"].as_array().expect("field lines");
    assert_eq!(lines.len(), 4, "three persons and all: {report}");
    for line in lines {
        let mean = |k: &str| line[k]["mean"].as_f64().expect("mean");
        let (field, vector) = (mean("field"), mean("vector"));
        println!(
            "{}: field {:.2} mm, vector {:.2} mm",
            line["person"],
            field * 1e3,
            vector * 1e3
        );
        assert!(
            field <= vector,
            "{}: field {field} > vector {vector}",
            line["person"]
        );
        assert_eq!(line["field_at_least_as_good"], true);
    }
    let splits = report["splits"].as_array().expect("splits");
    for split in splits {
        if split["field_flat"] == true {
            // A flat field is the single vector: the same distances, exactly.
            let person = split["person"].as_str().expect("person");
            let line = lines.iter().find(|l| l["person"] == person).expect("line");
            assert_eq!(line["field"], line["vector"], "{person}");
        }
    }
}
