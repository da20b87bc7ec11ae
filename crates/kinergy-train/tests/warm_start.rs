//! Warm starts in a library (`fit --warm-start`), on the shared people's raises: each
//! person's first take is fitted as without them, the others from its vector — in about a
//! third of the evaluations at a like distance, and the same bytes on any number of threads
//! and shards.

#[path = "../../../tests/support/require_shared.rs"]
mod require_shared;

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use kinergy_motion::Side;
use kinergy_solver::{Model, ParamsFile};
use kinergy_train::anneal::Observer;
use kinergy_train::fit::{FitJob, SearchOptions};
use kinergy_train::library::{Shard, ShardRun, Takes, collect};
use kinergy_train::source::{ArmChoice, ArmRequest, ReachQuery, capture_files};
use kinergy_train::who::PersonRule;

/// The shared people's takes 1–`per_person` of each style, copied into `dir/takes`, or `None`
/// (with a notice) where the folder is absent.
fn takes(dir: &Path, per_person: usize) -> Option<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/bandai-raise-left");
    if !root.is_dir() {
        require_shared::shared_absent(&format!(
            "skipping: {} is absent (the Bandai Namco captures are never committed)",
            root.display()
        ));
        return None;
    }
    let takes = dir.join("takes");
    std::fs::create_dir(&takes).expect("folder");
    for style in ["active", "elderly", "normal"] {
        for k in 1..=per_person {
            let name = format!("{style}_{k:03}.bvh");
            std::fs::copy(root.join(&name), takes.join(&name)).expect("copy");
        }
    }
    Some(takes)
}

/// The library's fit of the left arm's raise, S_D nested, the library's stopping rule.
fn job() -> (FitJob, ReachQuery) {
    let search = SearchOptions {
        seed: 3,
        library: true,
        ..SearchOptions::default()
    };
    let job = FitJob {
        models: FitJob::models_up_to(Model::Sd, true),
        optimizer: Default::default(),
        settings: search.settings().expect("settings"),
        refine: None,
    };
    let query = ReachQuery {
        arm: ArmRequest::Arm(ArmChoice::side(Side::Left)),
        ..ReachQuery::default()
    };
    (job, query)
}

/// Shard `shard` of the library of `takes_dir` into `out` on `threads` threads.
fn fit(takes_dir: &Path, out: &Path, warm_start: bool, shard: Shard, threads: usize) {
    let (job, query) = job();
    let paths = capture_files(&[takes_dir.to_path_buf()]).expect("takes");
    let takes = Takes::of(&paths, None).walked_from(&[takes_dir.to_path_buf()]);
    let interrupt = AtomicBool::new(false);
    let observer = || -> Box<dyn Observer> { Box::new(()) };
    let run = ShardRun {
        dir: out,
        takes: &takes,
        query: &query,
        job: &job,
        person: &PersonRule::File,
        shard,
        warm_start,
        resume: false,
        inputs: &paths,
        interrupt: &interrupt,
        observer: &observer,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("pool");
    let outcome = pool
        .install(|| run.plan().and_then(|plan| run.run(&plan, &|_| {})))
        .expect("run");
    assert!(outcome.failed.is_none(), "{:?}", outcome.failed);
    assert!(!outcome.interrupted);
}

/// Every result file of a library folder, by name, as bytes.
fn results(dir: &Path) -> BTreeMap<String, Vec<u8>> {
    std::fs::read_dir(dir)
        .expect("folder")
        .flatten()
        .map(|e| e.path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read(&p).expect("result"))
        })
        .collect()
}

fn params(bytes: &[u8]) -> ParamsFile {
    ParamsFile::from_json(std::str::from_utf8(bytes).expect("utf-8")).expect("params")
}

/// Evaluations of every stage of a result, and its S_D distance.
fn cost(file: &ParamsFile) -> (usize, f64) {
    let fit = file.fit.as_ref().expect("fit record");
    let stages = fit.nested.as_ref().expect("stages");
    (stages.iter().map(|s| s.evaluations).sum(), fit.score_m)
}

#[test]
fn warm_starts_fit_a_persons_repeats_from_their_first_take_in_fewer_evaluations() {
    let dir = tempfile::tempdir().expect("tempdir");
    let Some(takes_dir) = takes(dir.path(), 5) else {
        return;
    };
    let (cold, warm) = (dir.path().join("cold"), dir.path().join("warm"));
    fit(&takes_dir, &cold, false, Shard::ALL, 2);
    fit(&takes_dir, &warm, true, Shard::ALL, 2);
    let (cold, warm) = (results(&cold), results(&warm));
    assert_eq!(cold.len(), 15);
    assert_eq!(
        cold.keys().collect::<Vec<_>>(),
        warm.keys().collect::<Vec<_>>()
    );
    let (mut cold_cost, mut warm_cost) = ((0, 0.0), (0, 0.0));
    for (name, bytes) in &warm {
        let file = params(bytes);
        let record = file.fit.as_ref().expect("fit record");
        let style = name.split('_').next().expect("style");
        let anchor = format!("{style}_001.bvh.json");
        if *name == anchor {
            // The anchor: fitted as without warm starts, to the byte.
            assert_eq!(bytes, &cold[name], "{name}");
            assert_eq!(record.started_from, None);
        } else {
            // The others: S_D alone, from the anchor's vector.
            assert_eq!(
                record.started_from.as_deref(),
                Some(anchor.as_str()),
                "{name}"
            );
            let stages = record.nested.as_ref().expect("stages");
            assert_eq!(stages.len(), 1, "{name}");
            assert_eq!(stages[0].model, Model::Sd);
            assert!(record.score_m <= record.start_score_m, "{name}");
            // Its start is the anchor's vector: scored on this reach anew, the same number.
            let take = takes_dir.join(name.trim_end_matches(".json"));
            let (job, query) = job();
            let reach = query
                .take_at(&take)
                .expect("take")
                .expect("a reach")
                .remove(0);
            let objective = job
                .settings
                .objective(&[reach], Model::Sd, job.optimizer)
                .expect("objective");
            let start = params(&warm[&anchor]).values().expect("anchor's values");
            assert_eq!(
                objective.score(&start).expect("score"),
                record.start_score_m,
                "{name}"
            );
        }
        if *name != anchor {
            let (e, d) = cost(&file);
            let (ce, cd) = cost(&params(&cold[name]));
            warm_cost = (warm_cost.0 + e, warm_cost.1 + d);
            cold_cost = (cold_cost.0 + ce, cold_cost.1 + cd);
        }
    }
    // The twelve takes fitted from their anchors.
    let n = 12.0;
    eprintln!(
        "cold: {} evaluations, {:.2} mm; warm: {} evaluations, {:.2} mm",
        cold_cost.0,
        1000.0 * cold_cost.1 / n,
        warm_cost.0,
        1000.0 * warm_cost.1 / n
    );
    assert!(
        (warm_cost.0 as f64) < 0.45 * cold_cost.0 as f64,
        "warm {} against cold {} evaluations",
        warm_cost.0,
        cold_cost.0
    );
    assert!(
        warm_cost.1 <= 1.05 * cold_cost.1,
        "warm {:.2} mm against cold {:.2} mm",
        1000.0 * warm_cost.1 / n,
        1000.0 * cold_cost.1 / n
    );
}

#[test]
fn warm_starts_give_the_same_bytes_on_any_threads_and_shards() {
    let dir = tempfile::tempdir().expect("tempdir");
    let Some(takes_dir) = takes(dir.path(), 3) else {
        return;
    };
    let one = dir.path().join("one");
    fit(&takes_dir, &one, true, Shard::ALL, 1);
    let expected = results(&one);
    for threads in [2, 7] {
        let out = dir.path().join(format!("t{threads}"));
        fit(&takes_dir, &out, true, Shard::ALL, threads);
        assert_eq!(results(&out), expected, "{threads} threads");
    }
    // Three shards: each fits the anchors of its groups itself, and writes only its own.
    let sharded = dir.path().join("sharded");
    for index in 1..=3 {
        fit(&takes_dir, &sharded, true, Shard { index, count: 3 }, 2);
    }
    collect(&sharded).expect("collect");
    assert_eq!(results(&sharded), expected, "3 shards");
}
