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

/// Issue 45: a library with both-hands takes (`synth --both-hands`) gives one reach per arm
/// of such a take, and the same bytes on 1, 2 and 7 threads and split into shards.
#[test]
fn a_library_with_both_hands_takes_is_the_same_on_any_thread_count_and_in_shards() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lib = dir.path().join("lib");
    let o = kinergy(&[
        "synth",
        "-o",
        s(&lib),
        "--persons",
        "2",
        "--reaches",
        "3",
        "--frame-rate",
        "30",
        "--both-hands",
        "0.5",
        "--seed",
        "45",
        "-q",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let fit = |out: &Path, extra: &[&str]| {
        let mut args = vec![
            "fit",
            s(&lib),
            "--arm",
            "auto",
            "--per",
            "clip",
            "--model",
            "sd",
            "--budget",
            "48",
            "-q",
            "--out-dir",
            s(out),
        ];
        args.extend(extra);
        let o = kinergy(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    };
    let on = |threads: &str| {
        let out = dir.path().join(format!("threads-{threads}"));
        fit(&out, &["--threads", threads]);
        out
    };
    let one = on("1");
    let results = result_files(&one);
    // Takes 2 of each person reach with both hands: two results each, right arm then left.
    for person in ["p01", "p02"] {
        let take: Vec<&PathBuf> = results
            .keys()
            .filter(|p| p.starts_with(person) && p.to_string_lossy().contains("r02.bvh"))
            .collect();
        assert_eq!(take.len(), 2, "{person}/r02: {take:?}");
    }
    let table = without_seconds(&one.join("library.csv"));
    let arms: Vec<&str> = table.iter().map(|r| r["arm"].as_str()).collect();
    assert_eq!(arms.iter().filter(|a| **a == "left").count(), 2, "{arms:?}");
    for threads in ["2", "7"] {
        let other = on(threads);
        assert!(
            result_files(&other) == results,
            "{threads} threads: other results"
        );
        assert_eq!(
            without_seconds(&other.join("library.csv")),
            table,
            "{threads} threads"
        );
    }
    let sharded = dir.path().join("sharded");
    for i in 1..=2 {
        fit(&sharded, &["--shard", &format!("{i}/2")]);
    }
    let o = kinergy(&["collect", s(&sharded)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(result_files(&sharded) == results, "shards: other results");
    assert_eq!(without_seconds(&sharded.join("library.csv")), table);
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
            .filter(|(p, _)| !p.starts_with("shards") && p.extension().is_some_and(|x| x == "json"))
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
    for name in ["p01/r03.bvh.json", "p02/r07.bvh.json", "p02/r14.bvh.json"] {
        std::fs::remove_file(out.join(name)).expect("remove");
    }
    let cut = out.join("p01/r05.bvh.json");
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
    let (lib, lib_evaluations) = values(&library.join("r02.bvh.json"));
    let (one, one_evaluations) = values(&single_coarse);
    assert_eq!((&lib, lib_evaluations), (&one, one_evaluations));

    let library_fine = dir.path().join("library-fine");
    fit(&fine, &library_fine, true);
    let single = dir.path().join("single.json");
    fit(&[], &single, false);
    let (lib_fine, fine_evaluations) = values(&library_fine.join("r02.bvh.json"));
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
    assert!(
        out.join("r03.bvh@3-73@left.json").is_file()
            && out.join("r03.bvh@3-73@right.json").is_file()
    );
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

// ---- Issue 42: nothing lost in a library ----

/// A folder of `n` takes (copies of the synthetic set's first person's) in `dir/name`.
fn takes(dir: &Path, name: &str, n: usize) -> PathBuf {
    let folder = dir.join(name);
    std::fs::create_dir_all(&folder).expect("folder");
    for i in 1..=n {
        let take = format!("r{i:02}.bvh");
        std::fs::copy(
            repo().join("data-synthetic/p01").join(&take),
            folder.join(&take),
        )
        .expect("copy");
    }
    folder
}

/// `fit TAKES --per clip --model sa --budget 20 -q --out-dir OUT` and `extra` (whose
/// `--budget` replaces the 20).
fn fit_library(takes: &Path, out: &Path, extra: &[&str]) -> std::process::Output {
    let budget = if extra.contains(&"--budget") {
        &[][..]
    } else {
        &["--budget", "20"][..]
    };
    let mut args = vec![
        "fit",
        s(takes),
        "--per",
        "clip",
        "--model",
        "sa",
        "-q",
        "--out-dir",
        s(out),
    ];
    args.extend(budget);
    args.extend(extra);
    kinergy(&args)
}

/// The results of a library folder (its `.json` files outside `shards/`) with their bytes.
fn result_files(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    files(dir)
        .into_iter()
        .filter(|(p, _)| !p.starts_with("shards") && p.extension().is_some_and(|x| x == "json"))
        .collect()
}

/// The sweep's collision: a take with two reaches (`26_10.bvh`, both hands) and a take
/// renamed `26_10_4-66.bvh` in one folder; and, without the shared captures, a take with
/// two reaches from a segments file beside takes named like its reaches' results. Every
/// reach keeps its own result, and `collect` finds each.
#[test]
fn result_names_of_takes_named_like_another_take_s_reaches_never_collide() {
    let dir = tempfile::tempdir().expect("tempdir");
    let folder = dir.path().join("takes");
    std::fs::create_dir(&folder).expect("folder");
    let r03 = repo().join("data-synthetic/p01/r03.bvh");
    let names = ["r03.bvh", "r03_3-40.bvh", "r03.bvh@3-40", "r03.bvh@@3-40"];
    let mut rows = String::from("clip,onset,end,arm\n");
    for name in names {
        std::fs::copy(&r03, folder.join(name)).expect("copy");
        rows.push_str(&format!("{},3,40,right\n", folder.join(name).display()));
    }
    rows.push_str(&format!(
        "{},40,73,right\n",
        folder.join("r03.bvh").display()
    ));
    let segments = dir.path().join("segments.csv");
    std::fs::write(&segments, rows).expect("segments");
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
    let table = rows_of(&out.join("library.csv"));
    assert_eq!(table.len(), 5, "{table:?}");
    let results: std::collections::BTreeSet<&str> =
        table.iter().map(|r| r["result"].as_str()).collect();
    assert_eq!(
        results.into_iter().collect::<Vec<_>>(),
        [
            "r03.bvh@3-40.json",
            "r03.bvh@40-73.json",
            "r03.bvh@@3-40.json",
            "r03.bvh@@@@3-40.json",
            "r03_3-40.bvh.json",
        ]
    );
    // Each result records its own take and frames.
    for row in &table {
        let params: serde_json::Value =
            serde_json::from_slice(&std::fs::read(out.join(&row["result"])).expect("result"))
                .expect("json");
        let reach = &params["fit"]["reaches"][0];
        let clip = reach["clip"].as_str().expect("clip");
        assert!(clip.ends_with(&row["clip"]), "{clip} vs {row:?}");
        assert_eq!(reach["frames"][0].to_string(), row["onset"]);
    }

    // The sweep's own case, where the shared captures are.
    let (Some(lift), Some(raise)) = (
        shared("cmu-lift", "26_10.bvh"),
        shared("bandai-raise-left", "normal_001.bvh"),
    ) else {
        return;
    };
    let mixed = dir.path().join("mixed");
    std::fs::create_dir(&mixed).expect("folder");
    std::fs::copy(lift, mixed.join("26_10.bvh")).expect("copy");
    std::fs::copy(raise, mixed.join("26_10_4-66.bvh")).expect("copy");
    let out = dir.path().join("mixed-fits");
    let o = kinergy(&[
        "fit",
        s(&mixed),
        "--per",
        "clip",
        "--arm",
        "auto",
        "--model",
        "sa",
        "--budget",
        "20",
        "-q",
        "--out-dir",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let table = rows_of(&out.join("library.csv"));
    let results: std::collections::BTreeSet<&str> =
        table.iter().map(|r| r["result"].as_str()).collect();
    assert_eq!(results.len(), table.len(), "{table:?}");
    assert_eq!(result_files(&out).len(), table.len());
}

fn rows_of(path: &Path) -> Vec<BTreeMap<String, String>> {
    rows(path)
}

/// `--resume` finds the complete results however the folder and the takes are spelled:
/// `./D`, `D/../D`, an absolute path, or from another folder — nothing is fitted again.
#[test]
fn resume_finds_every_result_however_the_paths_are_spelled() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lib = takes(dir.path(), "D/p01", 3);
    let out = dir.path().join("fits");
    let o = fit_library(&lib, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let before = result_files(&out);
    assert_eq!(before.len(), 3);
    let run_in = |cwd: &Path, takes: &str, out: &str| {
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_kinergy"))
            .current_dir(cwd)
            .args([
                "fit",
                takes,
                "--per",
                "clip",
                "--model",
                "sa",
                "--budget",
                "20",
                "--out-dir",
                out,
                "--resume",
            ])
            .output()
            .expect("run kinergy");
        assert_eq!(o.status.code(), Some(0), "{takes}: {}", stderr(&o));
        let fitted = stdout(&o)
            .lines()
            .filter(|l| l.ends_with("(clip fit, svd):"))
            .count();
        assert_eq!(fitted, 0, "{takes} from {cwd:?}: refitted\n{}", stdout(&o));
    };
    let abs = lib.canonicalize().expect("canonical");
    run_in(dir.path(), "./D/p01", "fits");
    run_in(dir.path(), "D/../D/p01", "./fits");
    run_in(dir.path(), s(&abs), s(&out));
    let elsewhere = dir.path().join("D");
    run_in(&elsewhere, "p01", "../fits");
    run_in(&elsewhere.join("p01"), ".", "../../fits");
    assert_eq!(result_files(&out), before);
    let o = kinergy(&["collect", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// Shards run with different settings: `fit` refuses a shard whose settings differ from
/// another shard's record (before any work), and `collect` refuses shards that ran at once
/// with different settings, naming the setting; `compare --library` refuses a table of mixed
/// settings.
#[test]
fn shards_with_different_settings_are_refused_naming_the_setting() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lib = takes(dir.path(), "takes", 4);
    let out = dir.path().join("fits");
    let o = fit_library(&lib, &out, &["--shard", "1/2"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for (flags, named) in [
        (&["--seed", "7"][..], "seed 1 (this run: 7)"),
        (&["--budget", "24"][..], "budget 20 (this run: 24)"),
        (&["--optimizer", "dls"][..], "optimizer"),
        (
            &["--controller", "paper"][..],
            "controller smooth (this run: paper)",
        ),
        (&["--objective", "positions+speed"][..], "objective"),
        (&["--population", "4"][..], "population 8 (this run: 4)"),
        // The reading options, once printed as `read ImportOptions { unit: … }`.
        (&["--from-unit", "cm"][..], "unit auto (this run: cm)"),
        (&["--up", "z"][..], "up auto (this run: z)"),
        (
            &["--positions", "add"][..],
            "positions auto (this run: add)",
        ),
    ] {
        let mut args = vec!["--shard", "2/2"];
        args.extend(flags);
        let o = fit_library(&lib, &out, &args);
        assert_eq!(o.status.code(), Some(2), "{flags:?}: {}", stderr(&o));
        assert!(
            stderr(&o).contains("shard 1/2 of this library ran with other settings")
                && stderr(&o).contains(named),
            "{flags:?}: {}",
            stderr(&o)
        );
        assert!(!stderr(&o).contains("ImportOptions"), "{}", stderr(&o));
        assert!(!out.join("shards/2-of-2.csv").exists());
    }
    // --model sb: the models differ (sa, sb against sa).
    let o = kinergy(&[
        "fit",
        s(&lib),
        "--per",
        "clip",
        "--model",
        "sb",
        "--budget",
        "20",
        "-q",
        "--out-dir",
        s(&out),
        "--shard",
        "2/2",
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("model [\"sa\"] (this run: [\"sa\",\"sb\"])"),
        "{}",
        stderr(&o)
    );

    // Two shards that ran at once, each unaware of the other: collect names the seed.
    let other = dir.path().join("other");
    let o = fit_library(&lib, &other, &["--shard", "2/2", "--seed", "7"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for (name, bytes) in files(&other) {
        if !name.ends_with("library.csv") && !name.ends_with("skipped.csv") {
            let to = out.join(&name);
            std::fs::create_dir_all(to.parent().unwrap()).expect("folder");
            std::fs::write(to, bytes).expect("copy");
        }
    }
    let o = kinergy(&["collect", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(
            "shard 2/2 was fitted with other settings than shard 1/2: seed 7 (shard 1/2: 1)"
        ),
        "{}",
        stderr(&o)
    );
    assert!(
        !out.join("library.csv").exists(),
        "a table of mixed settings was written"
    );

    // compare --library reads library.csv alone: rows of two settings are refused.
    let a = dir.path().join("a");
    let b = dir.path().join("b");
    for (folder, seed) in [(&a, "1"), (&b, "2")] {
        let o = fit_library(&lib, folder, &["--seed", seed]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let mut mixed = std::fs::read_to_string(a.join("library.csv")).expect("table");
    let other_rows = std::fs::read_to_string(b.join("library.csv")).expect("table");
    mixed.push_str(other_rows.lines().nth(1).expect("a row"));
    mixed.push('\n');
    let table = dir.path().join("mixed.csv");
    std::fs::write(&table, mixed).expect("write");
    let report = dir.path().join("report");
    let o = kinergy(&["compare", "--library", s(&table), "-o", s(&report)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("row 6, column settings") && stderr(&o).contains("mixed settings"),
        "{}",
        stderr(&o)
    );
    assert!(!report.exists());
}

/// Takes added, removed, grown, shrunk or edited between two shards: `collect` names each
/// and the shards to run again; run again with --resume, the library is the one-machine
/// library of the takes as they are now.
#[test]
fn takes_changed_between_shards_are_named_and_a_resume_mends_the_library() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lib = takes(dir.path(), "takes", 6);
    let out = dir.path().join("fits");
    let o = fit_library(&lib, &out, &["--shard", "1/2"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = |name: &str| std::fs::read_to_string(lib.join(name)).expect("take");
    // Grown: a trailing blank line; shrunk: its last newline gone; edited: one digit
    // changed in its motion (same size); removed; added.
    std::fs::write(lib.join("r01.bvh"), text("r01.bvh") + "\n").expect("grow");
    let r02 = text("r02.bvh");
    std::fs::write(lib.join("r02.bvh"), r02.trim_end()).expect("shrink");
    let r03 = text("r03.bvh");
    let at = r03.rfind('1').expect("a digit");
    let edited = format!("{}2{}", &r03[..at], &r03[at + 1..]);
    std::fs::write(lib.join("r03.bvh"), edited).expect("edit");
    std::fs::remove_file(lib.join("r04.bvh")).expect("remove");
    std::fs::copy(
        repo().join("data-synthetic/p01/r07.bvh"),
        lib.join("r07.bvh"),
    )
    .expect("add");
    let o = fit_library(&lib, &out, &["--shard", "2/2"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = kinergy(&["collect", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let err = stderr(&o);
    for change in [
        "r01.bvh grown (",
        "r02.bvh shrunk (",
        "r03.bvh edited (same size, other content)",
        "r04.bvh removed",
        "r07.bvh added",
        "run it again with --resume",
        "the takes changed since shard 1/2 ran",
    ] {
        assert!(err.contains(change), "{change}: {err}");
    }
    // Both shards again, resumed: the library of the takes as they are now.
    for i in 1..=2 {
        let o = fit_library(&lib, &out, &["--shard", &format!("{i}/2"), "--resume"]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    }
    let o = kinergy(&["collect", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let one = dir.path().join("one");
    let o = fit_library(&lib, &one, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (now, whole) = (result_files(&out), result_files(&one));
    // r04's old result stays on disk, in no table.
    let mut stale = now.clone();
    stale.retain(|p, _| !p.starts_with("r04.bvh.json"));
    assert_eq!(stale, whole);
    assert_eq!(
        without_seconds(&out.join("library.csv")),
        without_seconds(&one.join("library.csv"))
    );

    // A take edited after every shard ran: collect says so.
    std::fs::write(lib.join("r05.bvh"), text("r05.bvh") + " ").expect("grow");
    let o = kinergy(&["collect", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("the takes changed since shard 1/2, shard 2/2 ran: r05.bvh grown"),
        "{}",
        stderr(&o)
    );
}

/// A result that is not the one recorded — another reach's copied over it, or an S_A fit
/// of its own reach put there — is refused by `collect` naming it; `--resume` fits it again.
#[test]
fn a_result_file_that_is_not_the_one_recorded_is_refused() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lib = takes(dir.path(), "takes", 4);
    let out = dir.path().join("fits");
    let fit_sb = |extra: &[&str]| {
        let mut args = vec![
            "fit",
            s(&lib),
            "--per",
            "clip",
            "--model",
            "sb",
            "--budget",
            "20",
            "-q",
            "--out-dir",
            s(&out),
        ];
        args.extend(extra);
        kinergy(&args)
    };
    let o = fit_sb(&[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let whole = result_files(&out);
    let sa = dir.path().join("sa.json");
    let o = kinergy(&[
        "fit",
        s(&lib.join("r02.bvh")),
        "--model",
        "sa",
        "--budget",
        "20",
        "-q",
        "-o",
        s(&sa),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    for (case, from) in [
        ("r04 over r03", out.join("r04.bvh.json")),
        ("an S_A fit", sa),
    ] {
        let target = if case == "an S_A fit" {
            "r02.bvh.json"
        } else {
            "r03.bvh.json"
        };
        std::fs::copy(&from, out.join(target)).expect("copy");
        let o = kinergy(&["collect", s(&out)]);
        assert_eq!(o.status.code(), Some(2), "{case}: {}", stderr(&o));
        assert!(
            stderr(&o).contains(&format!("{target}: not the result shard 1/1 recorded")),
            "{case}: {}",
            stderr(&o)
        );
        let o = fit_sb(&["--resume"]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        assert_eq!(result_files(&out), whole, "{case}");
    }
}

/// Stray records (`2-of-1.csv`, `0-of-1.csv`, `01-of-1.csv`), absurd counts
/// (`1-of-99999999999.csv` killed collect, `1-of-1000000.csv` printed 87 MB), and records
/// that cannot be true (empty, a header alone, a byte-order mark, a column too many): each
/// refused, naming the file (and the line), in a few lines.
#[test]
fn stray_absurd_and_damaged_records_are_refused_in_a_few_lines() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lib = takes(dir.path(), "takes", 2);
    let out = dir.path().join("fits");
    let o = fit_library(&lib, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let shards = out.join("shards");
    let record = std::fs::read(shards.join("1-of-1.csv")).expect("record");
    for stray in [
        "2-of-1.csv",
        "0-of-1.csv",
        "01-of-1.csv",
        "1-of-99999999999.csv",
        "1-of-1000000.csv",
    ] {
        std::fs::write(shards.join(stray), &record).expect("stray");
        let o = kinergy(&["collect", s(&out)]);
        assert_eq!(o.status.code(), Some(2), "{stray}: {}", stderr(&o));
        assert!(
            stderr(&o).contains(&format!("{stray}: a stray record")),
            "{stray}: {}",
            stderr(&o)
        );
        assert!(o.stderr.len() < 1000, "{stray}: {} bytes", o.stderr.len());
        std::fs::remove_file(shards.join(stray)).expect("remove");
    }
    let text = String::from_utf8(record.clone()).expect("utf-8");
    let (header, _) = text.split_once('\n').expect("a header line");
    for (case, bytes, said) in [
        ("empty", Vec::new(), "1-of-1.csv: empty"),
        (
            "header only",
            format!("{header}\n").into_bytes(),
            "1-of-1.csv: line 1: the header line and no row",
        ),
        (
            "a byte-order mark",
            [b"\xef\xbb\xbf".as_slice(), &record].concat(),
            "1-of-1.csv: line 1 starts with a byte-order mark",
        ),
        (
            "an extra column",
            text.replacen(",why\n", ",why,extra\n", 1).into_bytes(),
            "1-of-1.csv: line 1: the columns are",
        ),
        (
            "an extra field",
            text.replacen("\ntake,", "\ntake,x,", 1).into_bytes(),
            "1-of-1.csv: line 3: 12 fields where the header has 11",
        ),
        (
            "a 40-digit onset",
            huge_onset(&text).into_bytes(),
            "column onset: `999999999999999999999999…",
        ),
    ] {
        std::fs::write(shards.join("1-of-1.csv"), &bytes).expect("write");
        let o = kinergy(&["collect", s(&out)]);
        assert_eq!(o.status.code(), Some(2), "{case}: {}", stderr(&o));
        assert!(stderr(&o).contains(said), "{case}: {}", stderr(&o));
    }
    std::fs::write(shards.join("1-of-1.csv"), &record).expect("write");
    let o = kinergy(&["collect", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// A shard record whose first reach row's onset is 40 nines (collect once said only
/// "frame `999…`", naming no file or line).
fn huge_onset(record: &str) -> String {
    let mut lines: Vec<String> = record.lines().map(str::to_string).collect();
    let onset = lines[0]
        .split(',')
        .position(|c| c == "onset")
        .expect("an onset column");
    let reach = lines
        .iter_mut()
        .find(|l| l.starts_with("reach,"))
        .expect("a reach row");
    let mut fields: Vec<String> = reach.split(',').map(str::to_string).collect();
    fields[onset] = "9".repeat(40);
    *reach = fields.join(",");
    lines.join("\n") + "\n"
}

// ---- The sweep after issue 42 ----

/// The sweep's takes whose results fell on the library's own files or another take's:
/// under `shards/` (even `shards/1-of-1.bvh`), `library.csv/`, `skipped.csv/`, a folder
/// `r.bvh.json/` beside `r.bvh`, and a 240-character name whose result's temporary passed
/// 255 bytes. Every take keeps its own result, `collect` finds each, and `--resume` fits
/// nothing again.
#[test]
fn takes_named_like_the_library_s_files_or_a_result_keep_their_own_results() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lib = dir.path().join("LIB");
    let long = format!("{}.bvh", "L".repeat(240));
    let takes = [
        "shards/1-of-1.bvh",
        "shards/a.bvh",
        "library.csv/a.bvh",
        "skipped.csv/a.bvh",
        "r.bvh",
        "r.bvh.json/a.bvh",
        "x@/a.bvh",
        long.as_str(),
    ];
    for (i, take) in takes.iter().enumerate() {
        let path = lib.join(take);
        std::fs::create_dir_all(path.parent().unwrap()).expect("folder");
        let source = format!("data-synthetic/p01/r{:02}.bvh", i + 1);
        std::fs::copy(repo().join(source), &path).expect("copy");
    }
    let out = dir.path().join("D");
    let o = fit_library(&lib, &out, &["--arm", "auto"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = kinergy(&["collect", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let table = rows_of(&out.join("library.csv"));
    let mut results: Vec<&str> = table.iter().map(|r| r["result"].as_str()).collect();
    results.sort();
    let long_result = format!("{long}.json");
    let mut expected = vec![
        "library.csv@/a.bvh.json",
        "r.bvh.json",
        "r.bvh.json@/a.bvh.json",
        "shards@/1-of-1.bvh.json",
        "shards@/a.bvh.json",
        "skipped.csv@/a.bvh.json",
        "x@@/a.bvh.json",
        long_result.as_str(),
    ];
    expected.sort();
    assert_eq!(results, expected);
    assert!(out.join("library.csv").is_file() && out.join("skipped.csv").is_file());
    let before = result_files(&out);
    let o = fit_library(&lib, &out, &["--arm", "auto", "--resume"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(result_files(&out), before);
    let o = kinergy(&["collect", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// The sweep's result replaced by a symbolic link to another result: `collect` says run
/// again with `--resume`, which once refused ("would be written twice"). Now the resumed
/// run replaces the link itself with the result, the other result untouched, and the
/// library is whole again.
#[cfg(unix)]
#[test]
fn a_result_replaced_by_a_link_to_another_is_written_again_by_resume() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lib = takes(dir.path(), "takes", 3);
    let out = dir.path().join("fits");
    let o = fit_library(&lib, &out, &["--shard", "1/2"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = fit_library(&lib, &out, &["--shard", "2/2"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let whole = result_files(&out);
    std::fs::remove_file(out.join("r01.bvh.json")).expect("remove");
    std::os::unix::fs::symlink("r02.bvh.json", out.join("r01.bvh.json")).expect("link");
    let o = kinergy(&["collect", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--resume"), "{}", stderr(&o));
    for shard in ["1/2", "2/2"] {
        let o = fit_library(&lib, &out, &["--shard", shard, "--resume"]);
        assert_eq!(o.status.code(), Some(0), "{shard}: {}", stderr(&o));
    }
    let link = std::fs::symlink_metadata(out.join("r01.bvh.json")).expect("result");
    assert!(link.is_file(), "the link stayed");
    assert_eq!(result_files(&out), whole);
    let o = kinergy(&["collect", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// The sweep's file where a folder goes: `D/shards` or `D/p01` a file (once "File exists
/// (os error 17)"), `D/library.csv` a folder. Each refused
/// before any work, naming the path and what it is needed for, and left as it was.
#[test]
fn a_file_where_a_library_s_folder_goes_is_refused_before_any_work() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lib = dir.path().join("LIB");
    takes(&lib, "p01", 2);
    takes(&lib, "p02", 1);
    for (in_the_way, folder, said) in [
        (
            "shards",
            false,
            "a file where the folder of the shards' records is needed",
        ),
        ("p01", false, "a file where the folder of the results of"),
        ("library.csv", true, "exists and is a folder"),
    ] {
        let out = dir.path().join(format!("D-{in_the_way}"));
        std::fs::create_dir(&out).expect("folder");
        let path = out.join(in_the_way);
        if folder {
            std::fs::create_dir(&path).expect("folder");
        } else {
            std::fs::write(&path, "keep\n").expect("file");
        }
        let o = fit_library(&lib, &out, &[]);
        assert_eq!(o.status.code(), Some(2), "{in_the_way}: {}", stderr(&o));
        let err = stderr(&o);
        assert!(
            err.contains(&format!("{}: {said}", path.display())) && !err.contains("os error"),
            "{in_the_way}: {err}"
        );
        let left: Vec<_> = std::fs::read_dir(&out).expect("folder").collect();
        assert_eq!(left.len(), 1, "{in_the_way}: something was written");
    }
}

/// Shard counts from the environment or `--shard` beyond 100,000 are refused naming the
/// variable or flag, at once (2^63 overflowed the deal's allocation, 1e10 took 80 GB).
#[test]
fn absurd_shard_counts_are_refused_naming_the_variable() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lib = takes(dir.path(), "takes", 1);
    let out = dir.path().join("fits");
    for count in ["9223372036854775808", "1e10", "100001"] {
        let clock = std::time::Instant::now();
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_kinergy"))
            .args([
                "fit",
                s(&lib),
                "--per",
                "clip",
                "--model",
                "sa",
                "--budget",
                "20",
                "--out-dir",
                s(&out),
            ])
            .env("SLURM_ARRAY_TASK_ID", "1")
            .env("SLURM_ARRAY_TASK_MIN", "1")
            .env("SLURM_ARRAY_TASK_COUNT", count)
            .output()
            .expect("run kinergy");
        assert_eq!(o.status.code(), Some(2), "{count}: {}", stderr(&o));
        assert!(
            stderr(&o).contains(&format!(
                "SLURM_ARRAY_TASK_COUNT=`{count}` is not a whole number from 1 to 100000"
            )),
            "{}",
            stderr(&o)
        );
        assert!(clock.elapsed().as_secs() < 20);
        assert!(!out.exists());
    }
    let o = fit_library(&lib, &out, &["--shard", "1/100001"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--shard `1/100001`"), "{}", stderr(&o));
    // A task ID that is not UTF-8 is set, not absent (the sweep: it fitted the whole library
    // as shard 1 of 1).
    use std::os::unix::ffi::OsStrExt;
    let o = std::process::Command::new(env!("CARGO_BIN_EXE_kinergy"))
        .args([
            "fit",
            s(&lib),
            "--per",
            "clip",
            "--model",
            "sa",
            "--budget",
            "20",
        ])
        .args(["--out-dir", s(&out)])
        .env("SLURM_ARRAY_TASK_ID", std::ffi::OsStr::from_bytes(b"\xff"))
        .env("SLURM_ARRAY_TASK_MIN", "1")
        .env("SLURM_ARRAY_TASK_COUNT", "2")
        .output()
        .expect("run kinergy");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("SLURM_ARRAY_TASK_ID=`"),
        "{}",
        stderr(&o)
    );
    assert!(!out.exists());
}

/// The columns of a `library.csv` as `fit --out-dir` writes them.
const LIBRARY_HEADER: &str = "clip,person,arm,onset,end,frames,model,optimizer,distance_sa_m,\
    distance_sb_m,distance_sc_m,distance_sd_m,distance_se_m,evaluations,seconds,result,settings";

/// Writes `dir/library.csv` with [`LIBRARY_HEADER`] and `rows`; returns its path.
fn library_table(dir: &Path, rows: &[&str]) -> PathBuf {
    let table = dir.join("library.csv");
    std::fs::write(&table, format!("{LIBRARY_HEADER}\n{}\n", rows.join("\n"))).expect("write");
    table
}

/// `compare --library` refuses a table with NaN, ±inf, negative or absurd (> 1 km) distances,
/// or with every distance empty, naming the row and column; nothing is written.
#[test]
fn compare_library_refuses_distances_that_cannot_be_true() {
    let dir = tempfile::tempdir().expect("tempdir");
    let good = "r01.bvh,p01,right,0,10,10,sb,svd,0.02,0.01,,,,16,,r01.bvh.json,abc";
    for (bad, said) in [
        (
            "r02.bvh,p01,right,0,10,10,sb,svd,NaN,0.01,,,,16,,r02.bvh.json,abc",
            "row 3, column distance_sa_m: NaN",
        ),
        (
            "r02.bvh,p01,right,0,10,10,sb,svd,0.02,inf,,,,16,,r02.bvh.json,abc",
            "row 3, column distance_sb_m: inf",
        ),
        (
            "r02.bvh,p01,right,0,10,10,sb,svd,-inf,0.01,,,,16,,r02.bvh.json,abc",
            "row 3, column distance_sa_m: -inf",
        ),
        (
            "r02.bvh,p01,right,0,10,10,sb,svd,0.02,-0.01,,,,16,,r02.bvh.json,abc",
            "row 3, column distance_sb_m: -0.01",
        ),
        (
            "r02.bvh,p01,right,0,10,10,sb,svd,,,,,,16,,r02.bvh.json,abc",
            "row 3: every distance",
        ),
        // The sweep: 1e300 printed as 303 digits in summary.md, 1e308 made a mean of inf.
        (
            "r02.bvh,p01,right,0,10,10,sb,svd,1e300,0.01,,,,16,,r02.bvh.json,abc",
            "row 3, column distance_sa_m: 1e300 is not a distance (meters from 0 to 1000)",
        ),
        (
            "r02.bvh,p01,right,0,10,10,sb,svd,0.02,1e308,,,,16,,r02.bvh.json,abc",
            "row 3, column distance_sb_m: 1e308",
        ),
        // Cells that are no number, once "CSV deserialize error… field 8".
        (
            "r02.bvh,p01,right,0,10,10,sb,svd,abc,0.01,,,,16,,r02.bvh.json,abc",
            "row 3, column distance_sa_m: `abc` is not a number",
        ),
        (
            "r02.bvh,p01,right,0,10,10,sb,svd,0.02,1_0,,,,16,,r02.bvh.json,abc",
            "row 3, column distance_sb_m: `1_0` is not a number",
        ),
        (
            "r02.bvh,p01,right,x,10,10,sb,svd,0.02,0.01,,,,16,,r02.bvh.json,abc",
            "row 3, column onset: `x` is not a whole number",
        ),
    ] {
        let table = library_table(dir.path(), &[good, bad]);
        let report = dir.path().join("report");
        let o = kinergy(&["compare", "--library", s(&table), "-o", s(&report)]);
        assert_eq!(o.status.code(), Some(2), "{said}: {}", stderr(&o));
        assert!(stderr(&o).contains(said), "{said}: {}", stderr(&o));
        assert!(!report.exists());
    }
    // Every distance empty, in every row: no table of dashes.
    let table = dir.path().join("empty.csv");
    std::fs::write(
        &table,
        format!("{LIBRARY_HEADER}\nr01.bvh,p01,right,0,10,10,sb,svd,,,,,,16,,r01.bvh.json,abc\n"),
    )
    .expect("write");
    let o = kinergy(&[
        "compare",
        "--library",
        s(&table),
        "-o",
        s(&dir.path().join("r")),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("row 2: every distance"),
        "{}",
        stderr(&o)
    );
}

/// A model some reaches of a line lack (a stage below the fitted model) is not averaged
/// silently over fewer: its cell says how many reaches it covers (the sweep: S_C averaged over
/// 2 of 3 reaches without a word). A row without its own model's distance is refused.
#[test]
fn compare_library_says_when_a_model_covers_fewer_reaches() {
    let dir = tempfile::tempdir().expect("tempdir");
    let table = library_table(
        dir.path(),
        &[
            "r01.bvh,p01,right,0,10,10,sc,svd,0.02,0.01,0.01,,,16,,r01.bvh.json,abc",
            "r02.bvh,p01,right,0,10,10,sc,svd,0.03,,0.02,,,16,,r02.bvh.json,abc",
        ],
    );
    let report = dir.path().join("report");
    let o = kinergy(&["compare", "--library", s(&table), "-o", s(&report)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let summary = std::fs::read_to_string(report.join("summary.md")).expect("summary.md");
    assert!(summary.contains("1 of 2 reaches"), "{summary}");
}

/// The sweep (09_tables #40): a row of model S_C without an S_C distance was summarised; no
/// fit writes such a row, so `compare --library` refuses it, naming the row and the column.
#[test]
fn compare_library_refuses_a_row_without_its_own_models_distance() {
    let dir = tempfile::tempdir().expect("tempdir");
    let table = library_table(
        dir.path(),
        &[
            "r01.bvh,p01,right,0,10,10,sc,svd,0.02,0.01,0.01,,,16,,r01.bvh.json,abc",
            "r02.bvh,p01,right,0,10,10,sc,svd,0.03,0.02,,,,16,,r02.bvh.json,abc",
        ],
    );
    let report = dir.path().join("report");
    let o = kinergy(&["compare", "--library", s(&table), "-o", s(&report)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("row 3, column distance_sc_m: empty in a row of model sc"),
        "{}",
        stderr(&o)
    );
    assert!(!report.exists());
}

// ---- Issue 45: who, in the table ----

/// A folder `dir/name` of copies of the synthetic set's takes, each `(person, take)` of
/// `data-synthetic` under the new name given: several people in one folder, named as
/// datasets name them.
fn named_takes(dir: &Path, name: &str, takes: &[(&str, &str, &str)]) -> PathBuf {
    let folder = dir.join(name);
    for (person, take, to) in takes {
        let to = folder.join(to);
        std::fs::create_dir_all(to.parent().unwrap()).expect("folder");
        std::fs::copy(repo().join("data-synthetic").join(person).join(take), to).expect("copy");
    }
    folder
}

/// Each row's (clip, person, motion) in `library.csv`, by clip.
fn persons_of(library: &Path) -> Vec<(String, String, String)> {
    let mut out: Vec<_> = rows(&library.join("library.csv"))
        .into_iter()
        .map(|r| (r["clip"].clone(), r["person"].clone(), r["motion"].clone()))
        .collect();
    out.sort();
    out
}

/// Two people in one folder (`active_001.bvh`, `elderly_001.bvh`, …): `--person file` puts
/// each in library.csv's `person` column and `compare --library` gives a line to each; the
/// default (`auto`) trusts no numbered name and gives the folder. The rule is a recorded
/// setting — another shard's rule is refused — that changes no result: `collect --person`
/// and `--resume --person` name the persons anew without fitting anything again.
#[test]
fn persons_named_in_file_names_reach_the_table_and_its_summary() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lib = named_takes(
        dir.path(),
        "styles",
        &[
            ("p01", "r01.bvh", "active_001.bvh"),
            ("p01", "r02.bvh", "active_002.bvh"),
            ("p02", "r01.bvh", "elderly_001.bvh"),
            ("p02", "r02.bvh", "elderly_002.bvh"),
        ],
    );
    let by_file = dir.path().join("by-file");
    let o = fit_library(&lib, &by_file, &["--person", "file"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let expected = |people: [&str; 4]| -> Vec<(String, String, String)> {
        [
            "active_001.bvh",
            "active_002.bvh",
            "elderly_001.bvh",
            "elderly_002.bvh",
        ]
        .iter()
        .zip(people)
        .map(|(clip, person)| (clip.to_string(), person.to_string(), String::new()))
        .collect()
    };
    assert_eq!(
        persons_of(&by_file),
        expected(["active", "active", "elderly", "elderly"])
    );
    let report = dir.path().join("report");
    let o = kinergy(&["compare", "--library", s(&by_file), "-o", s(&report)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let summary = std::fs::read_to_string(report.join("summary.md")).expect("summary");
    for line in [
        "| `active` | 2 |",
        "| `elderly` | 2 |",
        "| **all** | 4 |",
        "4 takes, 2 persons",
    ] {
        assert!(summary.contains(line), "no `{line}` in {summary}");
    }
    assert!(!summary.contains("## Per motion"), "{summary}");
    // The old spelling of `file` still works, in compare --per person too.
    let old = dir.path().join("by-prefix");
    let o = fit_library(&lib, &old, &["--person", "prefix"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(persons_of(&old), persons_of(&by_file));

    // The default: numbered names say no one, the folder does.
    let by_default = dir.path().join("by-default");
    let o = fit_library(&lib, &by_default, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(
        persons_of(&by_default),
        expected(["styles", "styles", "styles", "styles"])
    );
    // The same results whatever the rule; the tables differ by their persons and settings.
    assert_eq!(result_files(&by_default), result_files(&by_file));

    // A recorded setting: a shard of another rule is refused, naming it.
    let sharded = dir.path().join("sharded");
    let o = fit_library(&lib, &sharded, &["--shard", "1/2", "--person", "file"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = fit_library(&lib, &sharded, &["--shard", "2/2"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("person file (this run: auto)"),
        "{}",
        stderr(&o)
    );

    // collect --person names them anew, records untouched; a pattern that misses takes is
    // refused naming them, no table written over.
    let records = files(&by_default.join("shards"));
    let o = kinergy(&["collect", s(&by_default), "--person", "regex:^([a-z]+)_"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(
        persons_of(&by_default),
        expected(["active", "active", "elderly", "elderly"])
    );
    assert_eq!(files(&by_default.join("shards")), records);
    let table = std::fs::read(by_default.join("library.csv")).expect("table");
    let o = kinergy(&["collect", s(&by_default), "--person", "regex:^(active)_"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains(
            "regex:^(active)_: 2 takes not matched (or with an empty person group): \
             elderly_001.bvh, elderly_002.bvh"
        ),
        "{}",
        stderr(&o)
    );
    assert_eq!(
        std::fs::read(by_default.join("library.csv")).expect("table"),
        table
    );
    let o = kinergy(&["collect", s(&by_default), "--person", "regex:(unclosed"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("unclosed group"), "{}", stderr(&o));

    // --resume with a mapping file: nothing fitted again (no reach has seconds), the persons
    // and motions the map says, in the record too; a map missing a take is refused before
    // any work, naming it.
    let map = dir.path().join("who.csv");
    std::fs::write(
        &map,
        "take,person,motion\nactive_001.bvh,ann,raise\nactive_002.bvh,ann,raise\n",
    )
    .expect("map");
    let rule = format!("map:{}", s(&map));
    let before = files(&by_default);
    let o = fit_library(&lib, &by_default, &["--resume", "--person", &rule]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("2 takes are not listed: elderly_001.bvh, elderly_002.bvh"),
        "{}",
        stderr(&o)
    );
    assert_eq!(files(&by_default), before);
    std::fs::write(
        &map,
        "take,person,motion\nactive_001.bvh,ann,raise\nactive_002.bvh,ann,raise\n\
         elderly_001.bvh,bea,raise\nelderly_002.bvh,bea,bow\n",
    )
    .expect("map");
    let o = fit_library(&lib, &by_default, &["--resume", "--person", &rule]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let table = rows(&by_default.join("library.csv"));
    assert!(table.iter().all(|r| r["seconds"].is_empty()), "{table:?}");
    assert_eq!(result_files(&by_default), result_files(&by_file));
    let people: Vec<(String, String)> = persons_of(&by_default)
        .into_iter()
        .map(|(_, p, m)| (p, m))
        .collect();
    let pair = |p: &str, m: &str| (p.to_string(), m.to_string());
    assert_eq!(
        people,
        [
            pair("ann", "raise"),
            pair("ann", "raise"),
            pair("bea", "raise"),
            pair("bea", "bow")
        ]
    );
    let record = rows(&by_default.join("shards/1-of-1.csv"));
    assert!(
        record
            .iter()
            .any(|r| r["person"] == "bea" && r["motion"] == "bow"),
        "{record:?}"
    );
    // Per motion, where motions are known.
    let o = kinergy(&["compare", "--library", s(&by_default), "-o", s(&report)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let summary = std::fs::read_to_string(report.join("summary.md")).expect("summary");
    for line in [
        "| `ann` | 2 |",
        "| `bea` | 2 |",
        "## Per motion",
        "| `raise` | 2 | 3 |",
        "| `bow` | 1 | 1 |",
    ] {
        assert!(summary.contains(line), "no `{line}` in {summary}");
    }
}

/// Bandai Namco's and CMU's file names say who performs: `auto` takes the person from them
/// (and Bandai's motion), the folder for the others; `compare --library --json` gives each
/// person's line its motions, and the `all` line the library's.
#[test]
fn auto_takes_bandai_and_cmu_performers_and_bandai_motions() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lib = named_takes(
        dir.path(),
        "mixed",
        &[
            (
                "p01",
                "r01.bvh",
                "dataset-2_raise-up-left-hand_active_001.bvh",
            ),
            ("p01", "r02.bvh", "dataset-2_bow_active_002.bvh"),
            (
                "p02",
                "r01.bvh",
                "dataset-2_raise-up-left-hand_elderly_001.bvh",
            ),
            ("p03", "r01.bvh", "64_26.bvh"),
            ("p04", "r01.bvh", "p04/r01.bvh"),
        ],
    );
    let out = dir.path().join("fits");
    let o = fit_library(&lib, &out, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let t = |c: &str, p: &str, m: &str| (c.to_string(), p.to_string(), m.to_string());
    assert_eq!(
        persons_of(&out),
        [
            t("64_26.bvh", "64", ""),
            t("dataset-2_bow_active_002.bvh", "active", "bow"),
            t(
                "dataset-2_raise-up-left-hand_active_001.bvh",
                "active",
                "raise-up-left-hand"
            ),
            t(
                "dataset-2_raise-up-left-hand_elderly_001.bvh",
                "elderly",
                "raise-up-left-hand"
            ),
            t("p04/r01.bvh", "p04", ""),
        ]
    );
    let report = dir.path().join("report");
    let o = kinergy(&["compare", "--library", s(&out), "-o", s(&report), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let lines: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    let all = lines
        .as_array()
        .expect("lines")
        .last()
        .expect("all")
        .clone();
    assert_eq!(all["person"], "all");
    let motions: Vec<(String, u64, u64)> = all["motions"]
        .as_array()
        .expect("motions")
        .iter()
        .map(|m| {
            (
                m["motion"].as_str().expect("name").to_string(),
                m["persons"].as_u64().expect("persons"),
                m["reaches"].as_u64().expect("reaches"),
            )
        })
        .collect();
    assert_eq!(
        motions,
        [
            ("bow".to_string(), 1, 1),
            ("raise-up-left-hand".to_string(), 2, 2),
            (String::new(), 2, 2)
        ]
    );
    let active = lines
        .as_array()
        .expect("lines")
        .iter()
        .find(|l| l["person"] == "active")
        .expect("active's line");
    assert_eq!(active["motions"].as_array().expect("motions").len(), 2);
    // compare --library names no persons itself: collect does.
    let o = kinergy(&[
        "compare",
        "--library",
        s(&out),
        "--person",
        "file",
        "-o",
        s(&report),
    ]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("collect"), "{}", stderr(&o));
}

/// `compare --per person --person RULE` reads the library's rule: a take a pattern misses,
/// or a map lacks, is refused before any fit, naming it; `--person` outside `--per person`
/// still says what it needs.
#[test]
fn compare_per_person_refuses_takes_its_rule_cannot_name() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lib = named_takes(
        dir.path(),
        "set",
        &[
            ("p01", "r01.bvh", "ann_001.bvh"),
            ("p01", "r02.bvh", "ann_002.bvh"),
            ("p02", "r01.bvh", "bea_001.bvh"),
        ],
    );
    let out = dir.path().join("out");
    let compare = |person: &str| {
        kinergy(&[
            "compare",
            s(&lib),
            "--per",
            "person",
            "--holdout",
            "1",
            "--person",
            person,
            "--budget",
            "20",
            "-o",
            s(&out),
        ])
    };
    let o = compare("regex:^(ann)_");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("1 take not matched (or with an empty person group): bea_001.bvh"),
        "{}",
        stderr(&o)
    );
    let map = dir.path().join("who.csv");
    std::fs::write(&map, "take,person\nann_001.bvh,ann\n").expect("map");
    let o = compare(&format!("map:{}", s(&map)));
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(
        stderr(&o).contains("2 takes are not listed: ann_002.bvh, bea_001.bvh"),
        "{}",
        stderr(&o)
    );
    let o = compare("nobody");
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("not a person rule"), "{}", stderr(&o));
    assert!(!out.exists());
}

/// `--warm-start`: each person's first take fitted as usual, the others from its vector (the
/// result says which); a recorded setting — a resume with it fits nothing again, a shard
/// without it is refused — that only a library takes.
#[test]
fn warm_starts_fit_a_persons_takes_from_the_first_and_are_a_library_setting() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lib = named_takes(
        dir.path(),
        "takes",
        &[
            ("p01", "r01.bvh", "ann/r01.bvh"),
            ("p01", "r02.bvh", "ann/r02.bvh"),
            ("p02", "r01.bvh", "bea/r01.bvh"),
            ("p02", "r02.bvh", "bea/r02.bvh"),
        ],
    );
    let plain = dir.path().join("plain");
    let o = fit_library(&lib, &plain, &[]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let warm = dir.path().join("warm");
    let o = fit_library(&lib, &warm, &["--warm-start"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (plain, fitted) = (result_files(&plain), result_files(&warm));
    let started_from = |bytes: &[u8]| -> Option<String> {
        let json: serde_json::Value = serde_json::from_slice(bytes).expect("json");
        json["fit"]["started_from"].as_str().map(String::from)
    };
    for (name, bytes) in &fitted {
        let name = name.to_string_lossy().replace('\\', "/");
        let person = name.split('/').next().expect("person");
        if name.ends_with("r01.bvh.json") {
            assert_eq!(Some(bytes), plain.get(Path::new(&name)), "{name}");
            assert_eq!(started_from(bytes), None, "{name}");
        } else {
            assert_eq!(
                started_from(bytes),
                Some(format!("{person}/r01.bvh.json")),
                "{name}"
            );
        }
    }
    assert_eq!(fitted.len(), 4);
    // library.csv's evaluations: every stage's, summed — S_A and S_B for the anchors, S_B
    // alone for the others.
    let two = dir.path().join("two-models");
    let o = kinergy(&[
        "fit",
        s(&lib),
        "--per",
        "clip",
        "--model",
        "sb",
        "--budget",
        "20",
        "--warm-start",
        "-q",
        "--out-dir",
        s(&two),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let two_fitted = result_files(&two);
    let mut counts = Vec::new();
    for row in rows(&two.join("library.csv")) {
        let json: serde_json::Value =
            serde_json::from_slice(&two_fitted[Path::new(&row["result"])]).expect("json");
        let stages: u64 = json["fit"]["nested"]
            .as_array()
            .expect("stages")
            .iter()
            .map(|s| s["evaluations"].as_u64().expect("evaluations"))
            .sum();
        assert_eq!(row["evaluations"], stages.to_string(), "{row:?}");
        counts.push(json["fit"]["nested"].as_array().expect("stages").len());
    }
    counts.sort();
    assert_eq!(counts, [1, 1, 2, 2]);
    // A resume with it finds everything fitted; a shard without it is refused, naming it.
    let o = fit_library(&lib, &warm, &["--warm-start", "--resume"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(
        rows(&warm.join("library.csv"))
            .iter()
            .all(|r| r["seconds"].is_empty())
    );
    assert_eq!(result_files(&warm), fitted);
    let sharded = dir.path().join("sharded");
    let o = fit_library(&lib, &sharded, &["--shard", "1/2", "--warm-start"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = fit_library(&lib, &sharded, &["--shard", "2/2"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("warm_start"), "{}", stderr(&o));
    // Only a library takes it.
    let take = lib.join("ann/r01.bvh");
    let out = dir.path().join("one.json");
    let o = kinergy(&["fit", s(&take), "--warm-start", "-o", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("--warm-start"), "{}", stderr(&o));
    assert!(!out.exists());
}

/// With `--warm-start` an unreadable take before a group's first readable one fails every
/// shard that needs that group (a fix of the take would change the group's anchor): its own
/// shard with the take's error as without warm starts, another shard saying why it read it.
/// Nothing is written.
#[test]
fn warm_starts_fail_on_an_unreadable_take_before_the_anchor_naming_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let lib = named_takes(
        dir.path(),
        "takes",
        &[
            ("p01", "r01.bvh", "ann/r01.bvh"),
            ("p01", "r02.bvh", "ann/r02.bvh"),
            ("p01", "r03.bvh", "ann/r03.bvh"),
        ],
    );
    let first = lib.join("ann/r01.bvh");
    let text = std::fs::read(&first).expect("take");
    std::fs::write(&first, &text[..3000]).expect("truncate");
    let plain = dir.path().join("plain");
    let o = fit_library(&lib, &plain, &[]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    // The take's error, without what the run wrote before it (timing decides that).
    let head = |e: &str| e.split(';').next().unwrap_or_default().to_string();
    let own = head(&stderr(&o));
    let (mut said_own, mut said_other) = (false, false);
    for shard in ["1/2", "2/2"] {
        let out = dir.path().join(format!("warm-{}", &shard[..1]));
        let o = fit_library(&lib, &out, &["--warm-start", "--shard", shard]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        let e = stderr(&o);
        assert!(
            e.contains("ann/r01.bvh") && e.contains("header declares"),
            "{e}"
        );
        said_other |= e.contains("read to find the warm start");
        said_own |= head(&e) == own;
        assert!(!out.exists() || result_files(&out).is_empty(), "{e}");
    }
    assert!(said_own && said_other, "{own}");
}
