//! A library of captures: `fit --per clip --out-dir DIR` over a mixed folder —
//! takes with no reach, one arm, both arms — with `--arm auto`; `library.csv` and
//! `skipped.csv`; `--resume`; shards that give what one machine gives; `collect`.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use common::{fixture, kinergy, repo, s, shared, stderr, stdout};

/// The files of `dir` (recursively, relative) with their bytes.
fn files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(folder) = stack.pop() {
        for entry in std::fs::read_dir(&folder).expect("folder").flatten() {
            let path = entry.path();
            if path.is_dir() {
                stack.push(path);
            } else {
                let bytes = std::fs::read(&path).expect("file");
                out.insert(path.strip_prefix(dir).expect("inside").to_path_buf(), bytes);
            }
        }
    }
    out
}

/// The rows of a CSV file as maps from column to value.
fn rows(path: &Path) -> Vec<BTreeMap<String, String>> {
    let mut reader = csv::ReaderBuilder::new()
        .comment(Some(b'#'))
        .from_path(path)
        .expect("csv");
    let header = reader.headers().expect("header").clone();
    reader
        .records()
        .map(|r| {
            let r = r.expect("record");
            header
                .iter()
                .zip(r.iter())
                .map(|(h, v)| (h.to_string(), v.to_string()))
                .collect()
        })
        .collect()
}

/// The reaches rows name — (clip file name, arm, onset, end) — sorted.
fn reaches(rows: &[BTreeMap<String, String>]) -> Vec<(String, String, String, String)> {
    let mut out: Vec<_> = rows
        .iter()
        .map(|r| {
            let clip = Path::new(&r["clip"]).file_name().unwrap().to_string_lossy();
            let field = |k: &str| r[k].clone();
            (
                clip.into_owned(),
                field("arm"),
                field("onset"),
                field("end"),
            )
        })
        .collect();
    out.sort();
    out
}

/// `library.csv` without its `seconds` column (the one number a run's timing decides).
fn without_seconds(path: &Path) -> Vec<BTreeMap<String, String>> {
    let mut rows = rows(path);
    for row in &mut rows {
        row.remove("seconds");
    }
    rows
}

#[test]
fn a_mixed_folder_fits_every_reach_of_whichever_arm_and_lists_what_it_skips() {
    let (Some(raise_left), Some(lift)) = (
        shared("bandai-raise-left", "normal_001.bvh"),
        shared("cmu-lift", "26_10.bvh"),
    ) else {
        return;
    };
    let dir = tempfile::tempdir().expect("tempdir");
    let takes = dir.path().join("takes");
    std::fs::create_dir(&takes).expect("folder");
    for (from, name) in [
        (repo().join("data-synthetic/p01/r01.bvh"), "right.bvh"),
        (raise_left, "left.bvh"),
        (lift, "both.bvh"),
        (fixture("cmu_12_01_walk.bvh"), "walk.bvh"),
    ] {
        std::fs::copy(from, takes.join(name)).expect("copy");
    }
    let out = dir.path().join("fits");
    let o = kinergy(&[
        "fit",
        s(&takes),
        "--arm",
        "auto",
        "--per",
        "clip",
        "--model",
        "sb",
        "--budget",
        "40",
        "--out-dir",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // The walk is skipped, saying what each arm does, on stderr and in skipped.csv.
    assert!(
        stderr(&o).contains("walk.bvh") && stderr(&o).contains("no main reach"),
        "{}",
        stderr(&o)
    );
    let skipped = rows(&out.join("skipped.csv"));
    assert_eq!(skipped.len(), 1, "{skipped:?}");
    assert!(skipped[0]["clip"].ends_with("walk.bvh") && skipped[0]["why"].contains("left arm"));
    // One reach per reaching arm: the both-hands lift gives two.
    let library = rows(&out.join("library.csv"));
    let arms: Vec<(String, String)> = library
        .iter()
        .map(|r| {
            let clip = Path::new(&r["clip"]).file_name().unwrap().to_string_lossy();
            (clip.into_owned(), r["arm"].clone())
        })
        .collect();
    let expected = [
        ("both.bvh", "left"),
        ("both.bvh", "right"),
        ("left.bvh", "left"),
        ("right.bvh", "right"),
    ];
    let mut sorted = arms.clone();
    sorted.sort();
    assert_eq!(
        sorted,
        expected.map(|(c, a)| (c.to_string(), a.to_string())),
        "{library:?}"
    );
    for row in &library {
        assert_eq!(
            (row["model"].as_str(), row["optimizer"].as_str()),
            ("sb", "svd")
        );
        assert_eq!(row["person"], "takes");
        let (sa, sb): (f64, f64) = (
            row["distance_sa_m"].parse().unwrap(),
            row["distance_sb_m"].parse().unwrap(),
        );
        assert!(sb <= sa + 1e-12 && sb > 0.0, "{row:?}");
        assert!(row["distance_sc_m"].is_empty() && row["distance_sd_m"].is_empty());
        let result = out.join(&row["result"]);
        let params: serde_json::Value =
            serde_json::from_slice(&std::fs::read(&result).expect("result")).expect("json");
        assert_eq!(
            params["fit"]["reaches"][0]["arm"]["side"],
            row["arm"].as_str()
        );
    }

    // `segment --arm auto --manifest` lists the same reaches for the folder.
    let manifest = dir.path().join("segments.csv");
    let o = kinergy(&[
        "segment",
        s(&takes),
        "--arm",
        "auto",
        "--manifest",
        s(&manifest),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stderr(&o).contains("walk.bvh"), "{}", stderr(&o));
    assert_eq!(reaches(&rows(&manifest)), reaches(&library));

    // Nothing to fit anywhere: exit 1, saying why; a malformed take: exit 2, as ever.
    let walks = dir.path().join("walks");
    std::fs::create_dir(&walks).expect("folder");
    std::fs::copy(fixture("cmu_12_01_walk.bvh"), walks.join("walk.bvh")).expect("copy");
    let fit_sa = |takes: &Path, out: &Path| {
        let args = [
            "fit",
            s(takes),
            "--arm",
            "auto",
            "--per",
            "clip",
            "--model",
            "sa",
        ];
        let mut args = args.to_vec();
        args.extend(["--out-dir", s(out)]);
        kinergy(&args)
    };
    let o = fit_sa(&walks, &dir.path().join("none"));
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("nothing to fit"), "{}", stderr(&o));
    std::fs::write(takes.join("broken.bvh"), "HIERARCHY\nROOT x {").expect("write");
    let o = fit_sa(&takes, &dir.path().join("bad"));
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("broken.bvh"), "{}", stderr(&o));
}

/// `--arm auto` finds each take's reaches itself: with one `--frames` window or one numbered
/// segment it is refused before any work (exit 2), nothing written.
#[test]
fn arm_auto_refuses_a_window_or_a_numbered_segment_before_any_work() {
    let dir = tempfile::tempdir().expect("tempdir");
    let clip = repo().join("data-synthetic/p01/r01.bvh");
    let out = dir.path().join("fits");
    for (flag, value) in [("--frames", "5..40"), ("--select", "1")] {
        let o = kinergy(&[
            "fit",
            s(&clip),
            "--arm",
            "auto",
            flag,
            value,
            "--per",
            "clip",
            "--model",
            "sa",
            "--out-dir",
            s(&out),
        ]);
        assert_eq!(o.status.code(), Some(2), "{flag}: {}", stderr(&o));
        assert!(stderr(&o).contains(flag), "{}", stderr(&o));
        assert!(!out.exists(), "{flag}: wrote {out:?}");
    }
    let o = kinergy(&["segment", s(&clip), "--arm", "auto", "--select", "1"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
}

/// The synthetic set's first two persons (28 takes) as a library.
fn library_args(out: &Path) -> Vec<String> {
    let takes = repo().join("data-synthetic");
    [
        "fit",
        s(&takes.join("p01")),
        s(&takes.join("p02")),
        "--per",
        "clip",
        "--model",
        "sb",
        "--budget",
        "60",
        "-q",
        "--out-dir",
        s(out),
    ]
    .map(String::from)
    .to_vec()
}

fn run(args: &[String]) -> std::process::Output {
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    kinergy(&args)
}

#[test]
fn shards_give_what_one_machine_gives_and_collect_names_a_missing_shard() {
    let dir = tempfile::tempdir().expect("tempdir");
    let one = dir.path().join("one");
    let o = run(&library_args(&one));
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let sharded = dir.path().join("sharded");
    for i in 1..=3 {
        let mut args = library_args(&sharded);
        args.extend(["--shard".into(), format!("{i}/3")]);
        let o = run(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let o = kinergy(&["collect", s(&sharded)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // Every result byte for byte; the table but for the seconds.
    let (a, b) = (files(&one), files(&sharded));
    let results = |f: &BTreeMap<PathBuf, Vec<u8>>| -> BTreeMap<PathBuf, Vec<u8>> {
        f.iter()
            .filter(|(p, _)| p.extension().is_some_and(|x| x == "json"))
            .map(|(p, b)| (p.clone(), b.clone()))
            .collect()
    };
    assert_eq!(results(&a).len(), 28);
    assert_eq!(results(&a), results(&b));
    assert_eq!(
        without_seconds(&one.join("library.csv")),
        without_seconds(&sharded.join("library.csv"))
    );
    // Each shard fitted a share balanced by frames: none more than half the takes.
    for i in 1..=3 {
        let record = rows(&sharded.join(format!("shards/{i}-of-3.csv")));
        let takes = record.iter().filter(|r| r["kind"] == "take").count();
        assert!((5..=14).contains(&takes), "shard {i}: {takes} takes");
    }
    // The library as a whole, from library.csv alone: the all row's S_A mean is the
    // table's.
    let report = dir.path().join("report");
    let o = kinergy(&["compare", "--library", s(&sharded), "-o", s(&report)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let table = rows(&sharded.join("library.csv"));
    let mean_sa = table
        .iter()
        .map(|r| r["distance_sa_m"].parse::<f64>().unwrap() * 1e3)
        .sum::<f64>()
        / table.len() as f64;
    let summary = std::fs::read_to_string(report.join("summary.md")).expect("summary");
    let all = summary
        .lines()
        .find(|l| l.starts_with("| **all** | 28 |"))
        .unwrap_or_else(|| panic!("{summary}"));
    assert!(
        all.contains(&format!(" {mean_sa:.2} (")),
        "{all} vs {mean_sa:.2}"
    );
    assert!(summary.contains("| `p01` | 14 |") && summary.contains("| `p02` | 14 |"));
    assert!(report.join("fig3.svg").is_file() && report.join("fig3.png").is_file());

    // collect is idempotent, and names a missing shard (exit 1).
    let before = files(&sharded);
    let o = kinergy(&["collect", s(&sharded)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(files(&sharded), before);
    std::fs::remove_file(sharded.join("shards/2-of-3.csv")).expect("remove");
    let o = kinergy(&["collect", s(&sharded)]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("shard 2/3 has no record"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn resume_fits_only_the_reaches_without_a_complete_result() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("fits");
    let args = library_args(&out);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let whole = files(&out);
    // Three results lost, one cut in half (as by a crash of something else).
    for name in ["p01/r03.json", "p02/r07.json", "p02/r14.json"] {
        std::fs::remove_file(out.join(name)).expect("remove");
    }
    let cut = out.join("p01/r05.json");
    let text = std::fs::read(&cut).expect("read");
    std::fs::write(&cut, &text[..text.len() / 2]).expect("cut");
    let mut resume = args.clone();
    resume.retain(|a| a != "-q");
    resume.push("--resume".into());
    let o = run(&resume);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let printed = stdout(&o);
    let refitted: Vec<&str> = printed
        .lines()
        .filter(|l| l.ends_with("(clip fit, svd):"))
        .collect();
    assert_eq!(refitted.len(), 4, "{}", stdout(&o));
    let now = files(&out);
    for (name, bytes) in &whole {
        if name.starts_with("shards") || name.ends_with("library.csv") {
            continue;
        }
        assert_eq!(now.get(name), Some(bytes), "{name:?}");
    }
    assert_eq!(
        without_seconds(&out.join("library.csv")).len(),
        28,
        "every reach in the table"
    );
}

/// A library stops coarser by default (0.1 % over 15 iterations, halving the
/// evaluations): each reach's result is what a single fit of its take gives with that rule
/// asked for, and the single fit's rule asked for in a library gives the single fit's result.
#[test]
fn a_library_stops_by_the_library_rule_and_either_rule_is_one_flag_away() {
    let dir = tempfile::tempdir().expect("tempdir");
    let take = repo().join("data-synthetic/p01/r02.bvh");
    let values = |path: &Path| -> (serde_json::Value, u64) {
        let v: serde_json::Value =
            serde_json::from_slice(&std::fs::read(path).expect("result")).expect("json");
        let evaluations = v["fit"]["evaluations"].as_u64().expect("evaluations");
        (v["values"].clone(), evaluations)
    };
    let fit = |extra: &[&str], out: &Path, library: bool| {
        let mut args = vec!["fit", s(&take), "--per", "clip", "--model", "sb", "-q"];
        args.extend([if library { "--out-dir" } else { "-o" }, s(out)]);
        args.extend(extra);
        let o = kinergy(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    };
    let coarse = ["--stable-change", "0.001", "--stable-window", "15"];
    let fine = ["--stable-change", "0.0001", "--stable-window", "25"];
    let library = dir.path().join("library");
    fit(&[], &library, true);
    let single_coarse = dir.path().join("coarse.json");
    fit(&coarse, &single_coarse, false);
    let (lib, lib_evaluations) = values(&library.join("r02.json"));
    let (one, one_evaluations) = values(&single_coarse);
    assert_eq!((&lib, lib_evaluations), (&one, one_evaluations));

    let library_fine = dir.path().join("library-fine");
    fit(&fine, &library_fine, true);
    let single = dir.path().join("single.json");
    fit(&[], &single, false);
    let (lib_fine, fine_evaluations) = values(&library_fine.join("r02.json"));
    let (one_fine, single_evaluations) = values(&single);
    assert_eq!(
        (&lib_fine, fine_evaluations),
        (&one_fine, single_evaluations)
    );
    assert!(
        lib_evaluations < single_evaluations,
        "the library rule stopped after {lib_evaluations} evaluations, the single fit's after \
         {single_evaluations}"
    );
}

/// The sweep's findings: a segments file naming one capture under two spellings,
/// once per arm, is one take with two reaches (it was refused as two results of one name),
/// and `compare`'s results.csv tells the two reaches apart by arm and frames.
#[test]
fn one_capture_spelled_twice_is_one_take_and_its_arms_stay_apart() {
    let dir = tempfile::tempdir().expect("tempdir");
    let clip = repo().join("data-synthetic/p01/r03.bvh");
    let respelled = repo().join("data-synthetic/p01/../p01/r03.bvh");
    let segments = dir.path().join("s.csv");
    std::fs::write(
        &segments,
        format!(
            "clip,onset,end,arm\n{},3,73,left\n{},3,73,right\n",
            clip.display(),
            respelled.display()
        ),
    )
    .expect("write");
    let out = dir.path().join("fits");
    let o = kinergy(&[
        "fit",
        "--segments",
        s(&segments),
        "--per",
        "clip",
        "--model",
        "sa",
        "--budget",
        "20",
        "-q",
        "--out-dir",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(out.join("r03_3-73_left.json").is_file() && out.join("r03_3-73_right.json").is_file());
    let cmp = dir.path().join("cmp");
    let o = kinergy(&[
        "compare",
        "--segments",
        s(&segments),
        "--models",
        "sa",
        "--optimizers",
        "svd",
        "--no-baselines",
        "--budget",
        "20",
        "-q",
        "-o",
        s(&cmp),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let results = rows(&cmp.join("results.csv"));
    // Each row names its reach; the file is read once (not once per spelling).
    let arms: std::collections::BTreeSet<&str> =
        results.iter().map(|r| r["arm"].as_str()).collect();
    assert_eq!(arms.into_iter().collect::<Vec<_>>(), ["left", "right"]);
    let clips: std::collections::BTreeSet<&str> =
        results.iter().map(|r| r["clip"].as_str()).collect();
    assert_eq!(clips.len(), 1, "{results:?}");
    let left = results.iter().find(|r| r["arm"] == "left").unwrap();
    let right = results
        .iter()
        .find(|r| r["arm"] == "right" && r["model"] == left["model"]);
    assert_ne!(left["distance_m"], right.unwrap()["distance_m"]);
}
