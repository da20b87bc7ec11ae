//! What the CLI's end-to-end tests share: running the binary, the fixtures, its output.
#![allow(dead_code)] // each test file uses a subset

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

#[path = "../../../../tests/support/require_shared.rs"]
pub mod require_shared;
/// A file of the shared data folder (`../shared/data/FOLDER/NAME`; `NAME` empty: the folder),
/// or `None`, saying why, where it is absent (the Bandai Namco captures are never committed).
pub fn shared(folder: &str, name: &str) -> Option<PathBuf> {
    let p = repo().join("../shared/data").join(folder).join(name);
    if p.exists() {
        Some(p)
    } else {
        require_shared::shared_absent(&format!(
            "skipping: {} is absent (the Bandai Namco captures are never committed)",
            p.display()
        ));
        None
    }
}

/// A clip of the synthetic set's first person, canonical.
pub fn synthetic(name: &str) -> PathBuf {
    repo()
        .join("data-synthetic/p01")
        .join(name)
        .canonicalize()
        .expect("data-synthetic/p01 clip")
}

/// A path as an argument.
pub fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// Runs `kinergy` with `args`.
pub fn kinergy(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kinergy"))
        .args(args)
        .output()
        .expect("run kinergy")
}

/// The repository's root.
pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A committed test capture under `tests/data/`.
pub fn fixture(name: &str) -> PathBuf {
    repo().join("tests/data").join(name)
}

/// Bytes as (lossy) UTF-8.
pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// The command's standard output.
pub fn stdout(o: &Output) -> String {
    text(&o.stdout)
}

/// The command's standard error.
pub fn stderr(o: &Output) -> String {
    text(&o.stderr)
}

/// The command's standard output parsed as JSON.
pub fn json(o: &Output) -> serde_json::Value {
    serde_json::from_slice(&o.stdout).unwrap_or_else(|e| panic!("{e}: {}", stdout(o)))
}

/// Runs `kinergy args` expecting bad input: exit code 2, `needle` in the message, no panic,
/// and no file at `out`.
pub fn assert_bad_input(args: &[&str], needle: &str, out: &Path) {
    let o = kinergy(args);
    let err = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
    assert!(
        err.contains(needle),
        "{args:?}: `{err}` does not mention {needle}"
    );
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists(), "{args:?} left an output file");
}

/// `compare FOLDER --arm left --person prefix --per person --holdout 2 --seed SEED --json`
/// (plus `extra`) into `out`, on the shared Bandai takes: its JSON report.
pub fn held_out_per_person(
    folder: &Path,
    seed: &str,
    extra: &[&str],
    out: &Path,
) -> serde_json::Value {
    let mut args = vec![
        "compare",
        s(folder),
        "--arm",
        "left",
        "--person",
        "prefix",
        "--per",
        "person",
        "--holdout",
        "2",
        "--seed",
        seed,
        "--json",
        "-o",
        s(out),
    ];
    args.extend(extra);
    let o = kinergy(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    json(&o)
}

/// `fit` of the shared `person`'s `takes` (`PERSON_00T.bvh` in `folder`, left arm) with
/// `model` and `optimizer`, one vector per person, the annealer's seed `seed`, into `params`.
pub fn fit_person_seeded(
    folder: &Path,
    person: &str,
    takes: &[usize],
    model: &str,
    optimizer: &str,
    seed: u64,
    params: &Path,
) {
    let seed = seed.to_string();
    let takes: Vec<String> = takes
        .iter()
        .map(|t| s(&folder.join(format!("{person}_00{t}.bvh"))).to_string())
        .collect();
    let mut args = vec!["fit"];
    args.extend(takes.iter().map(String::as_str));
    args.extend([
        "--arm",
        "left",
        "--model",
        model,
        "--optimizer",
        optimizer,
        "--per",
        "person",
        "--seed",
        &seed,
        "-o",
        s(params),
        "-q",
    ]);
    let o = kinergy(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

/// `style`'s whole JSON report (the real-time `fidelity`, the time-normalized `summary` and
/// `rows`) of `params` toward the targets of `takes` of the shared `person` (left arm).
pub fn style_report(
    folder: &Path,
    person: &str,
    takes: &[usize],
    params: &Path,
    out: &Path,
) -> serde_json::Value {
    let mut args: Vec<String> = vec!["style".into()];
    args.extend(
        takes
            .iter()
            .map(|t| s(&folder.join(format!("{person}_00{t}.bvh"))).to_string()),
    );
    args.extend(["--arm", "left", "--params"].map(String::from));
    args.extend([s(params), "-o", s(out), "--json"].map(String::from));
    let o = kinergy(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    json(&o)
}

/// `predictor`'s real-time error in a `style` report (`fidelity.summaries`: "arm", "body",
/// "ceiling", "minimum_jerk", "profile"), mean over the takes, meters.
pub fn fidelity_error(report: &serde_json::Value, predictor: &str) -> f64 {
    report["fidelity"]["summaries"]
        .as_array()
        .expect("summaries")
        .iter()
        .find(|s| s["predictor"] == predictor)
        .and_then(|s| s["error"].as_f64())
        .unwrap_or_else(|| panic!("no {predictor} in {report}"))
}
