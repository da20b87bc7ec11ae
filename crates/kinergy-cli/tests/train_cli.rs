//! End-to-end tests of `kinergy segment`, `fit` and `compare`: files written and their
//! content, determinism across thread counts, interrupt and resume, bad input.

mod common;
use common::{assert_bad_input, fixture, json, kinergy, repo, text};

use std::path::Path;
use std::process::{Command, Output};

use kinergy_solver::{Model, ParamsFile};

#[test]
fn segment_lists_the_reaches_and_marks_the_main_one() {
    let clip = fixture("006_14.bvh");
    let o = kinergy(&["segment", clip.to_str().expect("utf-8"), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let report = json(&o);
    let frames = report["frames"].as_u64().expect("frames");
    let segments = report["segments"].as_array().expect("segments");
    assert!(!segments.is_empty());
    assert_eq!(segments.iter().filter(|s| s["main"] == true).count(), 1);
    let mut last_end = None;
    for s in segments {
        let (a, p, b) = (
            s["onset"].as_u64().expect("onset"),
            s["peak"].as_u64().expect("peak"),
            s["end"].as_u64().expect("end"),
        );
        // Frames onset..end, end excluded: the last segment may end at the clip's end, and
        // the next one may start where one ends.
        assert!(a <= p && p < b && b <= frames, "{s}");
        if let Some(e) = last_end {
            assert!(a >= e, "segments overlap or are out of order");
        }
        last_end = Some(b);
    }
    let o = kinergy(&["segment", clip.to_str().expect("utf-8")]);
    assert!(
        text(&o.stdout).contains("main reach"),
        "{}",
        text(&o.stdout)
    );
}

/// `kinergy fit` on the fixture's main reach with a small budget.
fn fit(out: &Path, extra: &[&str]) -> Output {
    let clip = fixture("006_14.bvh");
    let mut args = vec![
        "fit",
        clip.to_str().expect("utf-8"),
        "--model",
        "sb",
        "--budget",
        "300",
        "--seed",
        "5",
        "-o",
        out.to_str().expect("utf-8"),
        "--json",
    ];
    args.extend(extra);
    kinergy(&args)
}

#[test]
fn fit_writes_a_valid_parameters_file_the_same_on_any_thread_count() {
    let dir = tempfile::tempdir().expect("tempdir");
    let one = dir.path().join("one.json");
    let two = dir.path().join("two.json");
    let o = fit(&one, &["--threads", "1"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let report = json(&o);
    let models = report["models"].as_array().expect("models");
    assert_eq!(models.len(), 2, "S_A then S_B (nested)");
    let score = |i: usize| models[i]["score_m"].as_f64().expect("score");
    assert!(
        score(1) <= score(0),
        "S_B {} worse than S_A {}",
        score(1),
        score(0)
    );

    let file = ParamsFile::read(&one).expect("params file");
    assert_eq!(file.model, Model::Sb);
    let space = file.space().expect("space");
    space
        .validate(&file.values().expect("values"))
        .expect("within bounds");
    let record = serde_json::to_value(file.fit.as_ref().expect("fit record")).expect("json");
    assert_eq!(
        record["reaches"][0]["clip"],
        fixture("006_14.bvh").to_str().expect("utf-8")
    );
    assert_eq!(record["per"], "person");
    assert_eq!(record["score_m"].as_f64(), Some(score(1)));

    // The synthesized motion with the fitted file reproduces the fit's score.
    let o = fit(&two, &["--threads", "2"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(
        std::fs::read(&one).expect("one"),
        std::fs::read(&two).expect("two"),
        "1 and 2 threads gave different parameters"
    );
}

#[test]
fn an_interrupted_fit_resumes_to_the_uninterrupted_result() {
    let dir = tempfile::tempdir().expect("tempdir");
    let whole = dir.path().join("whole.json");
    let resumed = dir.path().join("resumed.json");
    let checkpoint = dir.path().join("fit.ckpt.json");
    let clip = fixture("006_14.bvh");
    let args = |out: &Path| -> Vec<String> {
        [
            "fit",
            clip.to_str().expect("utf-8"),
            "--model",
            "sc",
            "--budget",
            "30000",
            "--temperature",
            "0",
            "--seed",
            "3",
            "-o",
            out.to_str().expect("utf-8"),
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let o = Command::new(env!("CARGO_BIN_EXE_kinergy"))
        .args(args(&whole))
        .output()
        .expect("run");
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));

    let mut first = args(&resumed);
    first.extend([
        "--checkpoint".into(),
        checkpoint.to_str().expect("utf-8").into(),
        "--checkpoint-every".into(),
        "5".into(),
    ]);
    let o = interrupted(&first, || {
        let clock = std::time::Instant::now();
        while !checkpoint.exists() && clock.elapsed().as_secs() < 60 {
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
    });
    if o.status.code() == Some(0) {
        // The fit finished before the signal arrived: nothing to resume on this machine.
        eprintln!("the fit ended before it could be interrupted; resume not exercised");
        return;
    }
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    assert!(text(&o.stderr).contains("--resume"), "{}", text(&o.stderr));
    assert!(!resumed.exists(), "an interrupted fit wrote parameters");

    let mut again = first.clone();
    again.push("--resume".into());
    let o = Command::new(env!("CARGO_BIN_EXE_kinergy"))
        .args(&again)
        .output()
        .expect("resume");
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(
        std::fs::read(&whole).expect("whole"),
        std::fs::read(&resumed).expect("resumed"),
        "the resumed fit differs from the uninterrupted one"
    );
}

// The same, deterministically: the hidden `--interrupt-after N` hook raises the Ctrl-C flag
// after N iterations (here inside S_B, then inside S_C); each part exits 1 and leaves no
// parameters; the last resume ends byte for byte where the uninterrupted fit does, and the
// CSV log of the three parts equals the uninterrupted log.
#[test]
fn interrupt_and_resume_at_fixed_iterations() {
    let dir = tempfile::tempdir().expect("tempdir");
    let clip = fixture("006_14.bvh");
    let checkpoint = dir.path().join("fit.ckpt.json");
    let base = |out: &Path, log: &Path| -> Vec<String> {
        [
            "fit",
            clip.to_str().expect("utf-8"),
            "--model",
            "sc",
            "--budget",
            "600",
            "--seed",
            "8",
            "-o",
            out.to_str().expect("utf-8"),
            "--log",
            log.to_str().expect("utf-8"),
        ]
        .iter()
        .map(|s| s.to_string())
        .collect()
    };
    let (whole, whole_log) = (dir.path().join("whole.json"), dir.path().join("whole.csv"));
    let o = Command::new(env!("CARGO_BIN_EXE_kinergy"))
        .args(base(&whole, &whole_log))
        .output()
        .expect("run");
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let (parts, parts_log) = (dir.path().join("parts.json"), dir.path().join("parts.csv"));
    let mut args = base(&parts, &parts_log);
    args.extend([
        "--checkpoint".into(),
        checkpoint.to_str().expect("utf-8").into(),
        "--checkpoint-every".into(),
        "4".into(),
    ]);
    for (i, stop) in ["90", "30"].iter().enumerate() {
        let mut a = args.clone();
        a.extend(["--interrupt-after".into(), stop.to_string()]);
        if i > 0 {
            a.push("--resume".into());
        }
        let o = Command::new(env!("CARGO_BIN_EXE_kinergy"))
            .args(&a)
            .output()
            .expect("part");
        assert_eq!(o.status.code(), Some(1), "part {i}: {}", text(&o.stderr));
        assert!(!parts.exists(), "an interrupted fit wrote parameters");
    }
    args.push("--resume".into());
    let o = Command::new(env!("CARGO_BIN_EXE_kinergy"))
        .args(&args)
        .output()
        .expect("last part");
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    assert_eq!(
        std::fs::read(&whole).expect("whole"),
        std::fs::read(&parts).expect("parts")
    );
    assert_eq!(
        std::fs::read_to_string(&whole_log).expect("log"),
        std::fs::read_to_string(&parts_log).expect("log")
    );
}

#[test]
fn compare_writes_results_and_a_summary() {
    let dir = tempfile::tempdir().expect("tempdir");
    let person = dir.path().join("person");
    std::fs::create_dir(&person).expect("mkdir");
    for name in ["a.bvh", "b.bvh"] {
        std::fs::copy(fixture("006_14.bvh"), person.join(name)).expect("copy");
    }
    let out = dir.path().join("out");
    let o = kinergy(&[
        "compare",
        person.to_str().expect("utf-8"),
        "--optimizers",
        "jt,svd",
        "--budget",
        "200",
        "-o",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let csv = std::fs::read_to_string(out.join("results.csv")).expect("results.csv");
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("clip,arm,onset,end,model,optimizer,method,distance_m,frames,evaluations,seconds")
    );
    // The reach's arm, onset and end (columns 1–3) aside, the columns as they always were.
    let rows: Vec<Vec<String>> = lines
        .map(|l| {
            let mut r: Vec<String> = l.split(',').map(String::from).collect();
            r.drain(1..4);
            r
        })
        .collect();
    // Per clip: 4 Fig. 3 fits (svd), 2 Fig. 4 fits (jt), 3 methods, 1 field row.
    assert_eq!(rows.len(), 2 * (4 + 2 + 3 + 1), "{csv}");
    for r in &rows {
        let d: f64 = r[4].parse().expect("distance");
        let evaluations: usize = r[6].parse().expect("evaluations");
        assert!(d.is_finite() && d > 0.0, "{r:?}");
        assert!(evaluations <= 200, "{r:?}");
    }
    // The two copies are the same clip: same fits, so the same distances.
    let get = |clip: &str, model: &str, optimizer: &str, method: &str| -> f64 {
        rows.iter()
            .find(|r| r[0].ends_with(clip) && r[1] == model && r[2] == optimizer && r[3] == method)
            .unwrap_or_else(|| panic!("no row {clip} {model} {optimizer} {method}"))[4]
            .parse()
            .expect("number")
    };
    assert_eq!(
        get("a.bvh", "sc", "svd", "sa"),
        get("b.bvh", "sc", "svd", "sa")
    );
    for clip in ["a.bvh", "b.bvh"] {
        assert!(get(clip, "sb", "svd", "sa") <= get(clip, "sa", "svd", "sa"));
        assert!(get(clip, "sd", "svd", "sa") <= get(clip, "sc", "svd", "sa"));
    }
    // Leave one target out with identical clips: the field gives the other copy's fit.
    assert!(
        (get("a.bvh", "sc", "svd", "field_loo") - get("a.bvh", "sc", "svd", "sa")).abs() < 1e-12
    );
    let summary = std::fs::read_to_string(out.join("summary.md")).expect("summary.md");
    for needle in [
        "## Fig. 3",
        "## Fig. 4",
        "| S_A |",
        "| JT |",
        "55 %",
        "nelder_mead",
        "Parameter field",
    ] {
        assert!(
            summary.contains(needle),
            "summary.md lacks `{needle}`:\n{summary}"
        );
    }
}

#[test]
fn training_commands_reject_bad_input_with_exit_2() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("p.json");
    let out_s = out.to_str().expect("utf-8");
    let clip = fixture("006_14.bvh");
    let clip = clip.to_str().expect("utf-8");
    let broken = dir.path().join("broken.ckpt.json");
    std::fs::write(&broken, "{ not json").expect("write");
    let broken = broken.to_str().expect("utf-8");
    let empty = dir.path().join("empty");
    std::fs::create_dir(&empty).expect("mkdir");
    let empty = empty.to_str().expect("utf-8");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["fit", "/nonexistent/x.bvh", "--model", "sa", "-o", out_s],
            "x.bvh",
        ),
        (vec!["fit", empty, "--model", "sa", "-o", out_s], "no .bvh"),
        (
            vec![
                "fit", clip, "--model", "sa", "--frames", "10..5", "-o", out_s,
            ],
            "--frames",
        ),
        (
            vec![
                "fit",
                clip,
                "--model",
                "sa",
                "--frames",
                "0..100000",
                "-o",
                out_s,
            ],
            "100000",
        ),
        (
            vec!["fit", clip, "--model", "sa", "--budget", "0", "-o", out_s],
            "--budget 0: expected 1 to",
        ),
        (vec!["fit", clip, "--model", "sf", "-o", out_s], "sf"),
        (
            vec![
                "fit",
                clip,
                "--model",
                "sa",
                "--checkpoint",
                broken,
                "--resume",
                "-o",
                out_s,
            ],
            "broken.ckpt.json",
        ),
        (
            vec!["fit", clip, "--model", "sa", "--threads", "0", "-o", out_s],
            "--threads",
        ),
        (vec!["segment", "/nonexistent/y.bvh"], "y.bvh"),
        (vec!["compare", empty, "-o", out_s], "no .bvh"),
    ];
    for (args, needle) in cases {
        assert_bad_input(&args, needle, &out);
    }
}

#[test]
fn synthesize_replays_by_default_the_frames_a_fit_scored() {
    let dir = tempfile::tempdir().expect("tempdir");
    let clip = repo().join("data-synthetic/p01/r09.bvh");
    let clip = clip.to_str().expect("utf-8");
    let params = dir.path().join("sc.json");
    let params = params.to_str().expect("utf-8");
    let o = kinergy(&[
        "fit", clip, "--model", "sc", "--per", "clip", "--budget", "60", "-o", params, "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(params).expect("params")).expect("json");
    let reach = &file["fit"]["reaches"][0];
    let out = dir.path().join("sc.bvh");
    let o = kinergy(&[
        "synthesize",
        "--from",
        clip,
        "--params",
        params,
        "-o",
        out.to_str().expect("utf-8"),
        "--json",
    ]);
    assert!(
        matches!(o.status.code(), Some(0 | 1)),
        "{}",
        text(&o.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(report["capture_frames"], reach["frames"]);
    let (a, b) = (
        report["distance_to_capture_m"].as_f64().expect("distance"),
        reach["distance_m"].as_f64().expect("score"),
    );
    assert!((a - b).abs() < 1e-12, "{a} vs {b}");
}

/// Two synthetic persons (folders) of two takes each, copied from `data-synthetic/`.
fn two_synthetic_persons(dir: &Path) -> std::path::PathBuf {
    let set = dir.join("set");
    for person in ["p01", "p02"] {
        std::fs::create_dir_all(set.join(person)).expect("mkdir");
        for take in ["r01.bvh", "r02.bvh"] {
            std::fs::copy(
                repo().join("data-synthetic").join(person).join(take),
                set.join(person).join(take),
            )
            .expect("copy");
        }
    }
    set
}

#[test]
fn compare_per_person_holdout_writes_both_tables() {
    let dir = tempfile::tempdir().expect("tempdir");
    let set = two_synthetic_persons(dir.path());
    let out = dir.path().join("out");
    let o = kinergy(&[
        "compare",
        set.to_str().expect("utf-8"),
        "--per",
        "person",
        "--holdout",
        "1",
        "--budget",
        "100",
        "-o",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let csv = std::fs::read_to_string(out.join("holdout.csv")).expect("holdout.csv");
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("person,clip,arm,onset,end,fitted_on,model,optimizer,distance_m,frames,params")
    );
    // The reach's arm, onset and end (columns 2–4) aside, the columns as they always were.
    let rows: Vec<Vec<&str>> = lines
        .map(|l| {
            let mut r: Vec<&str> = l.split(',').collect();
            r.drain(2..5);
            r
        })
        .collect();
    // Per person's held-out take (r02): neutral, own S_A–S_D, own field, the other's S_C.
    assert_eq!(rows.len(), 2 * (1 + 4 + 1 + 1), "{csv}");
    let kinds = |kind: &str| rows.iter().filter(|r| r[7] == kind).count();
    assert_eq!(
        (kinds("neutral"), kinds("vector"), kinds("field")),
        (2, 10, 2)
    );
    // One training take per person: the field is that take's own fit, everywhere.
    for r in rows.iter().filter(|r| r[7] == "field") {
        assert_eq!(r[3], "sc", "{r:?}");
        assert_eq!(r[2], r[0], "the person's own field: {r:?}");
    }
    for r in &rows {
        assert!(r[1].ends_with("r02.bvh"), "{r:?}");
        let d: f64 = r[5].parse().expect("distance");
        assert!(d.is_finite() && d > 0.0, "{r:?}");
    }
    assert_eq!(rows.iter().filter(|r| r[2].is_empty()).count(), 2);
    let md = std::fs::read_to_string(out.join("summary.md")).expect("summary.md");
    for section in [
        "## Own vector against neutral",
        "## Person × person",
        "## Parameter field against the single vector",
        "## In sample",
        "| **all** | 2 / 2 |",
    ] {
        assert!(md.contains(section), "no `{section}` in {md}");
    }
    assert!(!md.contains("NaN") && !md.contains("inf"), "{md}");
    // --json: the same tables, finite.
    let o = kinergy(&[
        "compare",
        set.to_str().expect("utf-8"),
        "--per",
        "person",
        "--holdout",
        "1",
        "--budget",
        "100",
        "--json",
        "-o",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let report = json(&o);
    let cross = report["cross"].as_array().expect("cross");
    assert_eq!(cross.len(), 2);
    for row in cross {
        for v in row.as_array().expect("row") {
            assert!(v.as_f64().expect("number").is_finite(), "{report}");
        }
    }
    assert_eq!(report["own"].as_array().expect("own").len(), 3);
    assert_eq!(report["cross_model"], "sc");
}

#[test]
fn compare_holdout_of_all_of_a_persons_takes_is_bad_input() {
    let dir = tempfile::tempdir().expect("tempdir");
    let set = two_synthetic_persons(dir.path());
    let out = dir.path().join("out");
    let (set, out_s) = (set.to_str().expect("utf-8"), out.to_str().expect("utf-8"));
    assert_bad_input(
        &[
            "compare",
            set,
            "--per",
            "person",
            "--holdout",
            "2",
            "-o",
            out_s,
        ],
        "p01` has 2 takes",
        &out,
    );
    assert_bad_input(
        &["compare", set, "--per", "person", "-o", out_s],
        "--holdout",
        &out,
    );
    assert_bad_input(
        &["compare", set, "--holdout", "1", "-o", out_s],
        "--per person",
        &out,
    );
}

#[test]
fn compare_holdout_takes_clips_and_persons_from_a_segments_file() {
    // Four takes in one folder; the segments file's person column says who moves, crossing
    // the folders they were copied from (p01's r01 with p02's r02 and vice versa).
    let dir = tempfile::tempdir().expect("tempdir");
    let set = dir.path().join("takes");
    std::fs::create_dir_all(&set).expect("mkdir");
    let segments = dir.path().join("segments.csv");
    let listing = dir.path().join("listing.csv");
    let mut clips = Vec::new();
    for (person, take) in [
        ("p01", "r01"),
        ("p01", "r02"),
        ("p02", "r01"),
        ("p02", "r02"),
    ] {
        let to = set.join(format!("{person}_{take}.bvh"));
        std::fs::copy(
            repo()
                .join("data-synthetic")
                .join(person)
                .join(format!("{take}.bvh")),
            &to,
        )
        .expect("copy");
        clips.push(to.to_str().expect("utf-8").to_string());
    }
    let mut args = vec!["segment", "--manifest", listing.to_str().expect("utf-8")];
    args.extend(clips.iter().map(String::as_str));
    let o = kinergy(&args);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let listed = std::fs::read_to_string(&listing).expect("segments file");
    let mut edited = String::new();
    for line in listed.lines() {
        let person = if line.contains("p01_r01") || line.contains("p02_r02") {
            "alice"
        } else {
            "bob"
        };
        match line.rsplit_once(',') {
            Some((row, _)) if line.contains(".bvh") => {
                edited.push_str(&format!("{row},{person}\n"));
            }
            _ => edited.push_str(&format!("{line}\n")),
        }
    }
    std::fs::write(&segments, &edited).expect("write segments");
    let out = dir.path().join("out");
    let o = kinergy(&[
        "compare",
        "--segments",
        segments.to_str().expect("utf-8"),
        "--per",
        "person",
        "--holdout",
        "1",
        "--models",
        "sa,sc",
        "--budget",
        "60",
        "-o",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(0), "{edited}\n{}", text(&o.stderr));
    let csv = std::fs::read_to_string(out.join("holdout.csv")).expect("holdout.csv");
    let rows: Vec<Vec<&str>> = csv
        .lines()
        .skip(1)
        .map(|l| l.split(',').collect())
        .collect();
    // Held out: the last take of each person in name order.
    let held: std::collections::BTreeSet<(&str, &str)> = rows
        .iter()
        .map(|r| (r[0], r[1].rsplit('/').next().unwrap_or("")))
        .collect();
    let expected: std::collections::BTreeSet<(&str, &str)> =
        [("alice", "p02_r02.bvh"), ("bob", "p02_r01.bvh")].into();
    assert_eq!(held, expected, "{csv}");
    // --person folder puts every take in one person: with 4 takes and K = 1 it still runs,
    // but names the folder.
    let o = kinergy(&[
        "compare",
        "--segments",
        segments.to_str().expect("utf-8"),
        "--per",
        "person",
        "--person",
        "folder",
        "--holdout",
        "1",
        "--models",
        "sa",
        "--budget",
        "30",
        "-o",
        out.to_str().expect("utf-8"),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let csv = std::fs::read_to_string(out.join("holdout.csv")).expect("holdout.csv");
    assert!(csv.lines().skip(1).all(|l| l.contains("takes,")), "{csv}");
    // Naming the column without a segments file is bad input.
    assert_bad_input(
        &[
            "compare",
            &clips[0],
            &clips[1],
            "--per",
            "person",
            "--person",
            "segments",
            "--holdout",
            "1",
            "-o",
            out.join("x").to_str().expect("utf-8"),
        ],
        "--person segments needs --segments",
        &out.join("x"),
    );
}

/// Ctrl-C during `fit --refine` stops the refinement at once (no evaluation starts
/// after it), exits 1 saying the fit was interrupted and writes nothing for it. Before, the
/// refinement ran on for its whole budget and the file was written as if finished.
#[test]
fn ctrl_c_during_refine_stops_it_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("p.json");
    let mut args: Vec<String> = ["fit", "--model", "sd", "--per", "person"]
        .iter()
        .map(|s| s.to_string())
        .collect();
    for p in ["p01", "p02", "p03", "p04"] {
        for r in 1..=14 {
            args.push(
                repo()
                    .join(format!("data-synthetic/{p}/r{r:02}.bvh"))
                    .to_string_lossy()
                    .into_owned(),
            );
        }
    }
    args.extend(
        ["--refine", "10000000", "--budget", "8", "-q", "-o"]
            .iter()
            .map(|s| s.to_string()),
    );
    args.push(out.to_string_lossy().into_owned());
    // The annealing (8 evaluations) is over within the first second; the refinement of the
    // 56 reaches runs far longer (8 s for half of them on 2 cores), so at 2 s it is running.
    let o = interrupted(&args, || {
        std::thread::sleep(std::time::Duration::from_secs(2))
    });
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("interrupted during --refine"),
        "{}",
        text(&o.stderr)
    );
    assert!(!out.exists(), "an interrupted refinement wrote its fit");
}

/// Runs `kinergy ARGS`, sends it SIGINT once `wait` returns, and collects its output.
fn interrupted(args: &[String], wait: impl FnOnce()) -> Output {
    let child = Command::new(env!("CARGO_BIN_EXE_kinergy"))
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("spawn");
    wait();
    let killed = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .expect("kill");
    assert!(killed.success());
    child.wait_with_output().expect("wait")
}

/// Ctrl-C in `fit --per clip --out-dir` after some results were written says
/// how many (it said "nothing saved" with 44 of 56 written); every result the run reported
/// is on disk and whole, and no temporary file is left.
#[test]
fn ctrl_c_in_a_per_clip_fit_says_which_results_were_written() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("fits");
    let clips = repo().join("data-synthetic/p01");
    let args: Vec<String> = [
        "fit",
        clips.to_str().expect("utf-8"),
        "--per",
        "clip",
        "--model",
        "sd",
        "--budget",
        "1500",
        "--out-dir",
        out.to_str().expect("utf-8"),
    ]
    .iter()
    .map(|s| s.to_string())
    .collect();
    // The 14 fits take about 6 s on 2 cores: interrupt once the first is written.
    let first = out.join("r01.bvh.json");
    let o = interrupted(&args, || {
        let start = std::time::Instant::now();
        while !first.exists() && start.elapsed().as_secs() < 120 {
            std::thread::sleep(std::time::Duration::from_millis(20));
        }
    });
    let err = text(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    let stdout = text(&o.stdout);
    let written: Vec<&str> = stdout
        .lines()
        .filter_map(|l| l.strip_suffix(" (clip fit, svd):"))
        .collect();
    assert!(
        !written.is_empty() && written.len() < 14,
        "{written:?} {err}"
    );
    assert!(
        err.contains(&format!(
            "interrupted: {} reaches fitted and written",
            written.len()
        )) && err.contains("--resume"),
        "{err}"
    );
    // The results and the shard's record (for --resume and collect); nothing else.
    let on_disk: Vec<String> = std::fs::read_dir(&out)
        .expect("folder")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n != "shards")
        .collect();
    assert_eq!(on_disk.len(), written.len(), "left: {on_disk:?}");
    for file in written {
        let params: serde_json::Value =
            serde_json::from_slice(&std::fs::read(file).expect("reported, written"))
                .expect("whole JSON");
        assert!(params["values"].is_object(), "{file}");
    }
}

#[test]
fn the_stopping_rule_is_the_one_asked_for() {
    let dir = tempfile::tempdir().expect("tempdir");
    let clip = fixture("006_14.bvh");
    let fit = |extra: &[&str]| -> serde_json::Value {
        let out = dir.path().join("p.json");
        let mut args = vec![
            "fit",
            clip.to_str().expect("utf-8"),
            "--model",
            "sa",
            "--no-nested",
            "-o",
            out.to_str().expect("utf-8"),
            "-q",
        ];
        args.extend(extra);
        let o = Command::new(env!("CARGO_BIN_EXE_kinergy"))
            .args(&args)
            .output()
            .expect("run");
        assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
        let params: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(&out).expect("params")).expect("json");
        params["fit"].clone()
    };
    // Any change within 100 % over one iteration is stable: the population (8) is evaluated,
    // one iteration runs, and the fit has converged.
    let quick = fit(&["--stable-change", "1", "--stable-window", "1"]);
    assert_eq!(quick["status"], "converged", "{quick}");
    assert_eq!(quick["iterations"], 1, "{quick}");
    assert_eq!(quick["evaluations"], 16, "{quick}");
    // The default rule runs at least its 25-iteration window.
    let default = fit(&[]);
    assert!(
        default["iterations"].as_u64().expect("iterations") > 25,
        "{default}"
    );
}

/// `--objective positions+speed` records what the fit minimized (the paper's metric records
/// nothing: files as before), scores at least the distance, and a checkpoint of one objective
/// is not resumed under the other.
#[test]
fn the_speed_objective_is_recorded_and_kept_apart() {
    let dir = tempfile::tempdir().expect("tempdir");
    let plain = dir.path().join("plain.json");
    let speed = dir.path().join("speed.json");
    assert!(fit(&plain, &[]).status.success());
    assert!(
        fit(
            &speed,
            &["--objective", "positions+speed", "--speed-weight", "0.1"]
        )
        .status
        .success()
    );
    let read = |p: &Path| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(p).expect("read")).expect("json")
    };
    assert!(read(&plain)["fit"].get("objective").is_none());
    let record = &read(&speed)["fit"];
    assert_eq!(record["objective"]["kind"], "positions+speed");
    assert_eq!(record["objective"]["speed_weight_s"], 0.1);
    // Its file reads back as parameters anyone can drive with.
    ParamsFile::read(&speed).expect("a valid parameters file");
    // A checkpoint of the plain fit is refused for the speed objective.
    let ckpt = dir.path().join("fit.ckpt");
    let first = fit(
        &dir.path().join("a.json"),
        &["--checkpoint", ckpt.to_str().expect("utf-8")],
    );
    assert!(first.status.success());
    let resumed = fit(
        &dir.path().join("b.json"),
        &[
            "--checkpoint",
            ckpt.to_str().expect("utf-8"),
            "--resume",
            "--objective",
            "positions+speed",
        ],
    );
    assert_eq!(resumed.status.code(), Some(2), "{}", text(&resumed.stderr));
    assert!(
        text(&resumed.stderr).contains("objective"),
        "{}",
        text(&resumed.stderr)
    );
    let bad = fit(&dir.path().join("c.json"), &["--speed-weight", "11"]);
    assert_eq!(bad.status.code(), Some(2));
    assert!(
        text(&bad.stderr).contains("--speed-weight"),
        "{}",
        text(&bad.stderr)
    );
    // A speed weight without the speed term would be ignored: it is refused, nothing written.
    let ignored = fit(&dir.path().join("d.json"), &["--speed-weight", "0.1"]);
    assert_eq!(ignored.status.code(), Some(2), "{}", text(&ignored.stderr));
    assert!(text(&ignored.stderr).contains("positions+speed"));
    assert!(!dir.path().join("d.json").exists());
}

/// Ctrl-C stops `compare` after the reaches in progress: a failed task (exit 1) that says so,
/// and no output folder (not a death by the signal, saying nothing).
#[cfg(unix)]
#[test]
fn an_interrupted_compare_says_so_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("report");
    let args = strings(&[
        "compare",
        &path(&repo().join("data-synthetic")),
        "-o",
        &path(&out),
    ]);
    let o = interrupted(&args, || sleep_ms(1500));
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    assert!(
        text(&o.stderr).contains("interrupted"),
        "{}",
        text(&o.stderr)
    );
    assert!(
        !out.exists(),
        "an interrupted compare wrote {}",
        out.display()
    );
}

/// Ctrl-C reaches inside a reach's fits and baselines: one reach with a budget that would
/// run for many minutes (an annealing that never stabilizes; the baselines on the same
/// budget) stops soon after the signal, as a failed task that says so. (Before, a compare
/// stopped only between reaches: this one ran 322 s after the signal and exited 0.)
#[cfg(unix)]
#[test]
fn ctrl_c_stops_a_long_reach_in_the_middle_of_its_fits() {
    for baselines in [false, true] {
        let dir = tempfile::tempdir().expect("tempdir");
        let out = dir.path().join("report");
        let clip = repo().join("data-synthetic/p01/r09.bvh");
        let mut args = strings(&[
            "compare",
            &path(&clip),
            "--models",
            "sd",
            "--optimizers",
            "svd",
            "--budget",
            "1000000",
            "--stable-window",
            "100000",
            "-o",
            &path(&out),
        ]);
        if !baselines {
            args.push("--no-baselines".into());
        }
        let signalled = std::cell::Cell::new(None);
        let o = interrupted(&args, || {
            sleep_ms(2000);
            signalled.set(Some(std::time::Instant::now()));
        });
        let after = signalled.get().expect("signalled").elapsed().as_secs_f64();
        assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
        assert!(
            text(&o.stderr).contains("interrupted"),
            "{}",
            text(&o.stderr)
        );
        // Generous for a loaded machine: the fits check the flag every iteration (ms).
        assert!(
            after < 30.0,
            "baselines {baselines}: {after:.1} s after Ctrl-C"
        );
        assert!(!out.exists());
    }
}

/// `items` as owned strings.
fn strings(items: &[&str]) -> Vec<String> {
    items.iter().map(|s| s.to_string()).collect()
}

/// `p` as text (test paths are UTF-8).
fn path(p: &Path) -> String {
    p.to_str().expect("utf-8 path").to_string()
}

/// Sleeps `ms` milliseconds.
fn sleep_ms(ms: u64) {
    std::thread::sleep(std::time::Duration::from_millis(ms));
}
