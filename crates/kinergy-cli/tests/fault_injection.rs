//! Fault injection: files a user (or a crash) damaged, processes killed at random moments,
//! and mutated inputs of every JSON/CSV kind Kinergy reads. What Kinergy promises (README,
//! "What Kinergy promises"): a damaged input is refused with exit 2 naming the field, never
//! a panic, never a message that repeats an unbounded input, never a changed file that was
//! not an output; a fit killed at any moment resumes bit for bit.

mod common;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use common::{fixture, kinergy, repo, stderr, text};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngSeed, TestRunner};
use serde_json::Value;

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// The longest message a refusal may print, bytes: errors quote inputs, but only so much.
const MAX_MESSAGE: usize = 2000;

/// Asserts a run refused its input: exit 2, no panic, a bounded message containing `needle`.
fn assert_refused(o: &Output, needle: &str, what: &str) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(2), "{what}: {err}");
    assert!(!err.contains("panicked"), "{what}: {err}");
    assert!(
        err.len() < MAX_MESSAGE,
        "{what}: a {}-byte message: {}…",
        err.len(),
        &err[..300.min(err.len())]
    );
    assert!(
        err.contains(needle),
        "{what}: `{err}` does not name {needle}"
    );
}

// ---------------------------------------------------------------------------------------
// Damaged checkpoints, field by field.

/// The arguments of the checkpointed fit every checkpoint test runs (S_A → S_B → S_C on a
/// CMU reach, a small budget).
fn fit_args(out: &Path, checkpoint: &Path) -> Vec<String> {
    [
        "fit",
        s(&fixture("006_14.bvh")),
        "--model",
        "sc",
        "--budget",
        "600",
        "--seed",
        "8",
        "-o",
        s(out),
        "--checkpoint",
        s(checkpoint),
        "--checkpoint-every",
        "4",
    ]
    .map(String::from)
    .to_vec()
}

fn run(args: &[String]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kinergy"))
        .args(args)
        .output()
        .expect("run kinergy")
}

/// A real checkpoint: the fit interrupted inside its second stage (S_A done, S_B running).
fn interrupted_checkpoint(dir: &Path) -> (PathBuf, Value) {
    let checkpoint = dir.join("fit.ckpt.json");
    let mut args = fit_args(&dir.join("never.json"), &checkpoint);
    args.extend(["--interrupt-after".into(), "90".into()]);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let value: Value =
        serde_json::from_slice(&std::fs::read(&checkpoint).expect("checkpoint")).expect("json");
    assert_eq!(value["completed"].as_array().map(Vec::len), Some(1));
    assert!(value["current"].is_object());
    (checkpoint, value)
}

/// Sets the value at a JSON pointer.
fn set(v: &mut Value, pointer: &str, new: Value) {
    *v.pointer_mut(pointer)
        .unwrap_or_else(|| panic!("no {pointer} in the checkpoint")) = new;
}

#[test]
fn damaged_checkpoints_are_refused_naming_the_field() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (checkpoint, good) = interrupted_checkpoint(dir.path());
    let members = good["current"]["members"]
        .as_array()
        .expect("members")
        .clone();
    let history = good["current"]["mean_history"]
        .as_array()
        .expect("history")
        .clone();
    type Damage = Box<dyn Fn(&mut Value)>;
    let cases: Vec<(&str, Damage, &str)> = vec![
        (
            "no members (was a panic)",
            Box::new(|v| set(v, "/current/members", Value::Array(vec![]))),
            "current.members",
        ),
        (
            "1,000 members for a population of 8",
            Box::new(move |v| {
                let many: Vec<Value> = members.iter().cycle().take(1000).cloned().collect();
                set(v, "/current/members", Value::Array(many));
            }),
            "current.members",
        ),
        (
            "iteration 1e19",
            Box::new(|v| {
                set(
                    v,
                    "/current/iteration",
                    Value::from(10_000_000_000_000_000_000u64),
                )
            }),
            "current.evaluations",
        ),
        (
            "evaluations beyond the budget",
            Box::new(|v| set(v, "/current/evaluations", Value::from(1_000_000u64))),
            "current.evaluations",
        ),
        (
            "a vector of length 3",
            Box::new(|v| {
                set(
                    v,
                    "/current/members/0/x",
                    serde_json::json!([1.0, 1.0, 1.0]),
                )
            }),
            "current.members[0].x",
        ),
        (
            "a value outside its bounds",
            Box::new(|v| set(v, "/current/members/1/x/0", Value::from(1e9))),
            "current.members[1].x[0]",
        ),
        (
            "temperature 1e308",
            Box::new(|v| set(v, "/current/temperature", Value::from(1e308))),
            "current.temperature",
        ),
        (
            "a negative best cost",
            Box::new(|v| set(v, "/current/best_cost", Value::from(-1.0))),
            "current.best_cost",
        ),
        (
            "a step of 7",
            Box::new(|v| set(v, "/current/members/2/step", Value::from(7.0))),
            "current.members[2].step",
        ),
        (
            "a history of 100,000 means",
            Box::new(move |v| {
                let long: Vec<Value> = history.iter().cycle().take(100_000).cloned().collect();
                set(v, "/current/mean_history", Value::Array(long));
            }),
            "current.mean_history",
        ),
        (
            "a finished stage's vector of the wrong length",
            Box::new(|v| set(v, "/completed/0/values", serde_json::json!([1.0, 1.0, 1.0]))),
            "completed[0].values",
        ),
        (
            "a finished stage's seed",
            Box::new(|v| set(v, "/completed/0/seed", Value::from(5u64))),
            "completed[0].seed",
        ),
        (
            "a finished stage still running",
            Box::new(|v| set(v, "/completed/0/status", Value::from("running"))),
            "completed[0].status",
        ),
        (
            "a population of 0",
            Box::new(|v| set(v, "/problem/anneal/population", Value::from(0u64))),
            "problem.anneal",
        ),
        (
            "a 10-MB tag",
            Box::new(|v| set(v, "/current/tag", Value::from("A".repeat(10_000_000)))),
            "another problem",
        ),
        (
            "a 10-MB string where a number belongs",
            Box::new(|v| {
                set(
                    v,
                    "/current/temperature",
                    Value::from("9".repeat(10_000_000)),
                )
            }),
            "current.temperature",
        ),
        (
            "another format version",
            Box::new(|v| set(v, "/format_version", Value::from(99u64))),
            "format_version",
        ),
    ];
    let out = dir.path().join("p.json");
    for (what, damage, needle) in cases {
        let mut v = good.clone();
        damage(&mut v);
        let bytes = serde_json::to_vec(&v).expect("encode");
        std::fs::write(&checkpoint, &bytes).expect("write checkpoint");
        let mut args = fit_args(&out, &checkpoint);
        args.push("--resume".into());
        let o = run(&args);
        assert_refused(&o, needle, what);
        assert!(
            stderr(&o).contains("fit.ckpt.json"),
            "{what}: {}",
            stderr(&o)
        );
        assert!(
            !out.exists(),
            "{what}: parameters written from a damaged checkpoint"
        );
        assert_eq!(
            std::fs::read(&checkpoint).expect("checkpoint"),
            bytes,
            "{what}: the refused checkpoint was changed"
        );
    }
    // The undamaged checkpoint still resumes.
    std::fs::write(&checkpoint, serde_json::to_vec(&good).expect("encode")).expect("write");
    let mut args = fit_args(&out, &checkpoint);
    args.push("--resume".into());
    let o = run(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

// ---------------------------------------------------------------------------------------
// kill -9 at random moments, then resume: bit for bit the uninterrupted fit.

#[test]
fn a_fit_killed_at_random_moments_resumes_bit_for_bit() {
    let dir = tempfile::tempdir().expect("tempdir");
    let whole = dir.path().join("whole.json");
    let args = |out: &Path, checkpoint: &Path| -> Vec<String> {
        [
            "fit",
            s(&fixture("006_14.bvh")),
            "--model",
            "sc",
            "--budget",
            "3000",
            "--seed",
            "5",
            "-o",
            s(out),
            "--checkpoint",
            s(checkpoint),
            "--checkpoint-every",
            "1",
        ]
        .map(String::from)
        .to_vec()
    };
    let o = run(&args(&whole, &dir.path().join("whole.ckpt")));
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let expected = std::fs::read(&whole).expect("whole");

    // Kill moments drawn from a fixed seed (milliseconds after the first checkpoint).
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut exercised = 0;
    for round in 0..4 {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        let delay = Duration::from_millis(5 + (state >> 33) % 400);
        let out = dir.path().join(format!("resumed{round}.json"));
        let checkpoint = dir.path().join(format!("fit{round}.ckpt"));
        let a = args(&out, &checkpoint);
        let mut child = Command::new(env!("CARGO_BIN_EXE_kinergy"))
            .args(&a)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .expect("spawn");
        let clock = Instant::now();
        while !checkpoint.exists() && clock.elapsed() < Duration::from_secs(60) {
            std::thread::sleep(Duration::from_millis(1));
        }
        std::thread::sleep(delay);
        let _ = child.kill(); // SIGKILL
        let status = child.wait().expect("wait");
        if status.success() {
            eprintln!("round {round}: the fit ended before the kill ({delay:?}); not exercised");
            continue;
        }
        exercised += 1;
        assert!(!out.exists(), "round {round}: a killed fit left parameters");
        let mut resume = a.clone();
        resume.push("--resume".into());
        let o = run(&resume);
        assert_eq!(o.status.code(), Some(0), "round {round}: {}", stderr(&o));
        assert_eq!(
            std::fs::read(&out).expect("resumed"),
            expected,
            "round {round} (killed {delay:?} after the first checkpoint) differs"
        );
    }
    assert!(exercised > 0, "no kill landed before the fit ended");
}

// ---------------------------------------------------------------------------------------
// kill -9 of a folder fit at 50 random moments: no result partial, none reported lost, no
// temporary outlives the next run.

/// The files of the library folder `dir` (recursively), relative, with their bytes: the
/// results and any temporary, not the tables and records (their `seconds` are the timing's).
fn files_in(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    for (path, bytes) in snapshot(dir) {
        let relative = path.strip_prefix(dir).expect("inside").to_path_buf();
        let table = relative.starts_with("shards")
            || (relative.extension().is_some_and(|x| x == "csv") && !is_temporary(&relative));
        if !table {
            out.insert(relative, bytes);
        }
    }
    out
}

/// Whether `name` is an atomic writer's temporary (`.<name>.<pid>.<n>.tmp`).
fn is_temporary(name: &Path) -> bool {
    name.file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| n.starts_with('.') && n.ends_with(".tmp"))
}

#[test]
fn a_folder_fit_killed_at_50_random_moments_loses_nothing_reported_and_leaves_no_debris() {
    let dir = tempfile::tempdir().expect("tempdir");
    let clips = repo().join("data-synthetic/p01");
    let args = |out: &Path| -> Vec<String> {
        [
            "fit",
            s(&clips),
            "--per",
            "clip",
            "--model",
            "sb",
            "--budget",
            "300",
            "--out-dir",
            s(out),
        ]
        .map(String::from)
        .to_vec()
    };
    let reference = dir.path().join("reference");
    let clock = Instant::now();
    let o = run(&args(&reference));
    let whole_run = clock.elapsed();
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let expected = files_in(&reference);
    assert_eq!(expected.len(), 14);

    let out = dir.path().join("fits");
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let (mut killed, mut debris_seen) = (0, 0);
    for round in 0..50 {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        // Anywhere from the start to a little past the uninterrupted run's end.
        let span = whole_run.as_micros() as u64 * 11 / 10 + 1;
        let delay = Duration::from_micros((state >> 33) % span);
        let mut child = Command::new(env!("CARGO_BIN_EXE_kinergy"))
            .args(args(&out))
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("spawn");
        std::thread::sleep(delay);
        let _ = child.kill(); // SIGKILL
        let o = child.wait_with_output().expect("wait");
        killed += usize::from(!o.status.success());
        let now = files_in(&out);
        // Nothing partial: every result on disk is the uninterrupted run's, byte for byte.
        for (name, bytes) in &now {
            if is_temporary(name) {
                debris_seen += 1;
                continue;
            }
            assert_eq!(
                Some(bytes),
                expected.get(name),
                "round {round} (killed after {delay:?}): {name:?} is not a whole result"
            );
        }
        // Nothing reported lost: every result the run said it wrote is there.
        for line in text(&o.stdout).lines() {
            if let Some(file) = line.strip_suffix(" (clip fit, svd):") {
                let name = Path::new(file).strip_prefix(&out).expect("in the folder");
                assert!(
                    now.contains_key(name),
                    "round {round}: {file} reported, not written"
                );
            }
        }
        // Every tenth round, a run to the end: it cleans what the killed ones left.
        if round % 10 == 9 {
            let o = run(&args(&out));
            assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
            assert_eq!(
                files_in(&out),
                expected,
                "round {round}: debris or a wrong result"
            );
        }
    }
    eprintln!(
        "{killed} of 50 runs killed before their end; {debris_seen} temporaries seen after kills"
    );
    assert!(killed >= 25, "only {killed} kills landed before the end");
}

// ---------------------------------------------------------------------------------------
// Mutated inputs of every JSON/CSV kind: exit 0, 1 or 2, never a panic, never an input
// changed.

/// Every JSON pointer of `v` (containers and leaves), in document order.
fn pointers(v: &Value, at: String, out: &mut Vec<String>) {
    match v {
        Value::Object(map) => {
            for (k, child) in map {
                let p = format!("{at}/{}", k.replace('~', "~0").replace('/', "~1"));
                out.push(p.clone());
                pointers(child, p, out);
            }
        }
        Value::Array(items) => {
            for (i, child) in items.iter().enumerate() {
                let p = format!("{at}/{i}");
                out.push(p.clone());
                pointers(child, p, out);
            }
        }
        _ => {}
    }
}

/// Values a damaged file might hold where something else belongs.
fn replacements() -> Vec<Value> {
    vec![
        Value::Null,
        Value::from(-1),
        Value::from(0),
        Value::from(1.5),
        Value::from(1e308),
        Value::from(-1e308),
        Value::from(u64::MAX),
        Value::from(""),
        Value::from("x".repeat(100_000)),
        serde_json::json!([]),
        serde_json::json!({}),
        serde_json::json!([1, 2, 3]),
        Value::from(true),
    ]
}

/// One mutation: replace the value at a pointer, remove it, or (text mode) cut the file.
#[derive(Debug, Clone)]
enum Mutation {
    Replace(usize, usize),
    Remove(usize),
    Truncate(u16),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        4 => (any::<usize>(), any::<usize>()).prop_map(|(p, r)| Mutation::Replace(p, r)),
        1 => any::<usize>().prop_map(Mutation::Remove),
        1 => any::<u16>().prop_map(Mutation::Truncate),
    ]
}

fn mutate_json(text: &str, m: &Mutation) -> String {
    let mut v: Value = serde_json::from_str(text).expect("valid json");
    let mut all = Vec::new();
    pointers(&v, String::new(), &mut all);
    match *m {
        Mutation::Replace(p, r) => {
            let pointer = &all[p % all.len()];
            let rs = replacements();
            if let Some(slot) = v.pointer_mut(pointer) {
                *slot = rs[r % rs.len()].clone();
            }
            v.to_string()
        }
        Mutation::Remove(p) => {
            let pointer = &all[p % all.len()];
            let (parent, key) = pointer.rsplit_once('/').expect("pointer");
            match v.pointer_mut(parent) {
                Some(Value::Object(map)) => {
                    map.remove(&key.replace("~1", "/").replace("~0", "~"));
                }
                Some(Value::Array(items)) => {
                    if let Ok(i) = key.parse::<usize>() {
                        items.remove(i);
                    }
                }
                _ => {}
            }
            v.to_string()
        }
        Mutation::Truncate(n) => text[..(n as usize) % text.len()].to_string(),
    }
}

/// Every file under `dir` with its content.
fn snapshot(dir: &Path) -> BTreeMap<PathBuf, Vec<u8>> {
    let mut out = BTreeMap::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("read_dir").flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else {
                out.insert(p.clone(), std::fs::read(&p).expect("read"));
            }
        }
    }
    out
}

/// Runs `args` (the input `input` mutated by `m`) in `dir`, and checks the promise:
/// exit 0, 1 or 2, no panic, a bounded message, no file changed but `outputs`.
fn check_mutated(
    dir: &Path,
    input: &Path,
    good: &str,
    m: &Mutation,
    args: &[String],
    outputs: &[&Path],
) {
    let damaged = mutate_json(good, m);
    std::fs::write(input, &damaged).expect("write input");
    let before = snapshot(dir);
    let o = run(args);
    let err = stderr(&o);
    let what = format!("{m:?} on {}", input.display());
    assert!(
        matches!(o.status.code(), Some(0..=2)),
        "{what}: exit {:?}: {err}",
        o.status.code()
    );
    assert!(!err.contains("panicked"), "{what}: {err}");
    assert!(
        err.len() < MAX_MESSAGE,
        "{what}: a {}-byte message",
        err.len()
    );
    let after = snapshot(dir);
    for (path, bytes) in &before {
        if outputs.contains(&path.as_path()) {
            continue;
        }
        assert_eq!(
            after.get(path),
            Some(bytes),
            "{what}: {} changed",
            path.display()
        );
    }
    for path in after.keys() {
        assert!(
            before.contains_key(path) || outputs.contains(&path.as_path()),
            "{what}: {} appeared",
            path.display()
        );
    }
    for out in outputs {
        let _ = std::fs::remove_file(out);
    }
}

fn runner(seed: u64, cases: u32) -> TestRunner {
    TestRunner::new(Config {
        cases,
        failure_persistence: None,
        rng_seed: RngSeed::Fixed(seed),
        ..Config::default()
    })
}

#[test]
fn mutated_params_files_never_panic_nor_touch_inputs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let clip = dir.path().join("r01.bvh");
    std::fs::copy(repo().join("data-synthetic/p01/r01.bvh"), &clip).expect("copy");
    let params = dir.path().join("p.json");
    let o = kinergy(&[
        "fit",
        s(&clip),
        "--model",
        "sc",
        "--budget",
        "60",
        "-o",
        s(&params),
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let good = std::fs::read_to_string(&params).expect("params");
    let out = dir.path().join("out.bvh");
    let args: Vec<String> = [
        "synthesize",
        s(&clip),
        "--params",
        s(&params),
        "-o",
        s(&out),
        "--max-seconds",
        "3",
    ]
    .map(String::from)
    .to_vec();
    let mut args = args;
    args.insert(1, "--from".into());
    runner(11, 48)
        .run(&mutation(), |m| {
            check_mutated(dir.path(), &params, &good, &m, &args, &[&out]);
            Ok(())
        })
        .expect("mutated params files");
}

#[test]
fn mutated_scenes_never_panic_nor_touch_inputs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = dir.path().join("scene.json");
    let good =
        std::fs::read_to_string(repo().join("examples/bookshelf/scene.json")).expect("scene");
    std::fs::copy(
        repo().join("examples/bookshelf/shelf.obj"),
        dir.path().join("shelf.obj"),
    )
    .expect("copy mesh");
    let out = dir.path().join("out.bvh");
    let args: Vec<String> = [
        "plan",
        "--scene",
        s(&scene),
        "--target",
        "0.25,1.1,0.35",
        "--budget-ms",
        "200",
        "-o",
        s(&out),
    ]
    .map(String::from)
    .to_vec();
    runner(12, 32)
        .run(&mutation(), |m| {
            check_mutated(dir.path(), &scene, &good, &m, &args, &[&out]);
            Ok(())
        })
        .expect("mutated scenes");
}

#[test]
fn mutated_checkpoints_never_panic_nor_touch_inputs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let work = dir.path().join("work");
    std::fs::create_dir(&work).expect("mkdir");
    let (checkpoint, good) = interrupted_checkpoint(&work);
    let good = good.to_string();
    let out = work.join("p.json");
    let mut args = fit_args(&out, &checkpoint);
    args.push("--resume".into());
    // Resuming rewrites the checkpoint: it is an output of the run (when it is accepted).
    runner(13, 24)
        .run(&mutation(), |m| {
            check_mutated(&work, &checkpoint, &good, &m, &args, &[&out, &checkpoint]);
            Ok(())
        })
        .expect("mutated checkpoints");
}

#[test]
fn mutated_segments_files_never_panic_nor_touch_inputs() {
    let dir = tempfile::tempdir().expect("tempdir");
    for take in ["r01", "r02"] {
        std::fs::copy(
            repo().join(format!("data-synthetic/p01/{take}.bvh")),
            dir.path().join(format!("{take}.bvh")),
        )
        .expect("copy");
    }
    let segments = dir.path().join("segments.csv");
    let good = "clip,onset,end,arm,label,person\nr01.bvh,4,72,right,reach,p01\nr02.bvh,7,102,right,reach,p01\n";
    let out = dir.path().join("p.json");
    let args: Vec<String> = [
        "fit",
        "--segments",
        s(&segments),
        "--model",
        "sa",
        "--budget",
        "16",
        "-o",
        s(&out),
    ]
    .map(String::from)
    .to_vec();
    // CSV is not JSON: mutate it as text (a byte replaced, a cut, a cell made huge).
    let cells = prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| (i, vec![b])),
        (any::<usize>(), Just(vec![b'9'; 100_000])),
        (any::<usize>(), Just(b",,,".to_vec())),
        (any::<usize>(), Just(b"\r".to_vec())),
        (any::<usize>(), Just(b"-1".to_vec())),
    ];
    runner(14, 48)
        .run(&cells, |(at, bytes)| {
            let mut damaged = good.as_bytes().to_vec();
            let i = at % damaged.len();
            damaged.splice(i..i + 1, bytes.iter().copied());
            std::fs::write(&segments, &damaged).expect("write");
            let before = snapshot(dir.path());
            let o = run(&args);
            let err = stderr(&o);
            let what = text(&damaged[..damaged.len().min(200)]);
            prop_assert!(matches!(o.status.code(), Some(0..=2)), "{}: {}", what, err);
            prop_assert!(!err.contains("panicked"), "{}: {}", what, err);
            prop_assert!(
                err.len() < MAX_MESSAGE,
                "{}: a {}-byte message",
                what,
                err.len()
            );
            let after = snapshot(dir.path());
            for (path, bytes) in &before {
                if path != &out {
                    prop_assert_eq!(after.get(path), Some(bytes), "{} changed", path.display());
                }
            }
            let _ = std::fs::remove_file(&out);
            Ok(())
        })
        .expect("mutated segments files");
}
