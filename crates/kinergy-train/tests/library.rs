//! The library's property (issue 42): a generated library of 200 small takes, fitted in a
//! random sharding with random interruptions, resumes and take edits between the runs
//! (seeded), is either collected into exactly one whole result per take — each byte for
//! byte the result a direct fit of the take as it is now gives — or `collect` names what is
//! missing or changed.
//!
//! Each fit is tiny (S_A, a population of 2, 4 evaluations, a 16-frame window): the test
//! checks the library's bookkeeping, not the fits. It takes about 10 s with `cargo test
//! --release` (what CI runs) on 2 cores, and minutes without optimizations, where it is
//! ignored (run it with `--include-ignored`).

use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

use kinergy_solver::{FitGrouping, Model};
use kinergy_train::anneal::{AnnealSettings, Observer};
use kinergy_train::fit::{FitJob, FitSettings};
use kinergy_train::library::{
    LibraryError, Shard, ShardEvent, ShardRun, Takes, collect, hash_file,
};
use kinergy_train::source::{ReachFrames, ReachQuery, capture_files};
use kinergy_train::who::PersonRule;
use rand::rngs::ChaCha8Rng;
use rand::{RngExt, SeedableRng};

const TAKES: usize = 200;
const TRIALS: u64 = 6;

/// The synthetic set's takes (4 persons × 14), the sources of the generated ones.
fn sources() -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../data-synthetic");
    (1..=4)
        .flat_map(|p| (1..=14).map(move |r| (p, r)))
        .map(|(p, r)| root.join(format!("p{p:02}/r{r:02}.bvh")))
        .collect()
}

/// A BVH text's header (through `MOTION`) and its frame lines.
fn split(text: &str) -> (String, Vec<String>) {
    let at = text.find("MOTION").expect("a MOTION section");
    let (head, motion) = text.split_at(at);
    let frames = motion
        .lines()
        .skip(3)
        .filter(|l| !l.trim().is_empty())
        .map(str::to_string)
        .collect();
    let time = motion.lines().nth(2).expect("Frame Time").to_string();
    (format!("{head}MOTION\n{{FRAMES}}\n{time}\n"), frames)
}

fn join(head: &str, frames: &[String]) -> String {
    let mut out = head.replace("{FRAMES}", &format!("Frames: {}", frames.len()));
    for f in frames {
        out.push_str(f);
        out.push('\n');
    }
    out
}

/// Take `k` of the generated pool: a source cut to 20–32 frames.
fn generated(sources: &[PathBuf], k: usize) -> (String, String) {
    let source = &sources[k % sources.len()];
    let length = 20 + 4 * (k / sources.len());
    let text = std::fs::read_to_string(source).expect("source");
    let (head, frames) = split(&text);
    let person = source
        .parent()
        .unwrap()
        .file_name()
        .unwrap()
        .to_string_lossy();
    let name = format!(
        "{person}/{}_{length}.bvh",
        source.file_stem().unwrap().to_string_lossy()
    );
    (name, join(&head, &frames[..length.min(frames.len())]))
}

/// How a take is edited between two runs.
#[derive(Debug, Clone, Copy)]
enum Edit {
    /// One frame more (a copy of its last).
    Grow,
    /// One frame fewer.
    Shrink,
    /// Every value of its first 16 frames changed in its last digit (same size).
    Touch,
    /// Gone.
    Remove,
    /// A take of the pool not in the library.
    Add,
}

fn edit(dir: &Path, name: &str, how: Edit) {
    let path = dir.join(name);
    let text = std::fs::read_to_string(&path).expect("take");
    let (head, mut frames) = split(&text);
    match how {
        Edit::Grow => frames.push(frames.last().unwrap().clone()),
        // Never below the 16 frames fitted.
        Edit::Shrink if frames.len() > 17 => {
            frames.pop();
        }
        Edit::Shrink => frames.push(frames.last().unwrap().clone()),
        Edit::Touch => {
            for line in frames.iter_mut().take(16) {
                *line = line
                    .split(' ')
                    .map(|v| {
                        let mut v = v.to_string();
                        if let Some(d) = v.pop() {
                            let d = d
                                .to_digit(10)
                                .map_or(d, |d| char::from_digit((d + 1) % 10, 10).unwrap());
                            v.push(d);
                        }
                        v
                    })
                    .collect::<Vec<_>>()
                    .join(" ");
            }
        }
        Edit::Remove | Edit::Add => unreachable!(),
    }
    std::fs::write(&path, join(&head, &frames)).expect("edit");
}

/// What a direct fit of each take gives, by path and content hash.
struct Truth {
    job: FitJob,
    query: ReachQuery,
    scratch: tempfile::TempDir,
    known: HashMap<(PathBuf, String), Vec<u8>>,
}

impl Truth {
    fn result(&mut self, take: &Path) -> Vec<u8> {
        let (_, hash) = hash_file(take).expect("take");
        let key = (take.to_path_buf(), hash);
        if let Some(bytes) = self.known.get(&key) {
            return bytes.clone();
        }
        let reaches = self.query.take_at(take).expect("read").expect("a reach");
        assert_eq!(reaches.len(), 1);
        let fits = self
            .job
            .run_stoppable(&reaches, &mut (), None)
            .expect("fit");
        let path = self.scratch.path().join("truth.json");
        fits.params_file(&reaches, FitGrouping::Clip)
            .expect("file")
            .write(&path)
            .expect("write");
        let bytes = std::fs::read(&path).expect("read back");
        self.known.insert(key, bytes.clone());
        bytes
    }
}

/// Generated take `k` written under `takes_dir`; its path from there.
fn write_take(sources: &[PathBuf], takes_dir: &Path, k: usize) -> String {
    let (name, text) = generated(sources, k);
    let path = takes_dir.join(&name);
    std::fs::create_dir_all(path.parent().unwrap()).expect("folder");
    std::fs::write(path, text).expect("take");
    name
}

/// The tiny fit every take gets (S_A, a population of 2, 4 evaluations, seeded) and the
/// 16-frame window it is fitted on.
fn tiny(seed: u64) -> (FitJob, ReachQuery) {
    let job = FitJob {
        models: vec![Model::Sa],
        optimizer: Default::default(),
        settings: FitSettings {
            anneal: AnnealSettings {
                population: 2,
                max_evaluations: 4,
                seed,
                ..AnnealSettings::default()
            },
            ..FitSettings::default()
        },
        refine: None,
    };
    let query = ReachQuery {
        frames: ReachFrames::Window(0..16),
        ..ReachQuery::default()
    };
    (job, query)
}

/// Shard `shard` of the library in `takes_dir`, into `out`; interrupted after `stop_after`
/// takes are done, if given. Returns whether it ran whole (every take dealt fitted or found
/// fitted, uninterrupted).
fn run_shard(
    takes_dir: &Path,
    out: &Path,
    job: &FitJob,
    query: &ReachQuery,
    shard: Shard,
    resume: bool,
    stop_after: Option<usize>,
) -> bool {
    let paths = capture_files(&[takes_dir.to_path_buf()]).expect("takes");
    let takes = Takes::of(&paths, None).walked_from(&[takes_dir.to_path_buf()]);
    let interrupt = AtomicBool::new(false);
    let observer = || -> Box<dyn Observer> { Box::new(()) };
    let run = ShardRun {
        dir: out,
        takes: &takes,
        query,
        job,
        person: &PersonRule::Auto,
        shard,
        warm_start: false,
        resume,
        inputs: &paths,
        interrupt: &interrupt,
        observer: &observer,
    };
    let done = AtomicUsize::new(0);
    let on_event = |event: ShardEvent<'_>| {
        if let ShardEvent::TakeDone = event {
            let n = done.fetch_add(1, Ordering::SeqCst) + 1;
            if stop_after.is_some_and(|k| n >= k) {
                interrupt.store(true, Ordering::SeqCst);
            }
        }
    };
    let plan = run.plan().expect("plan");
    let outcome = run.run(&plan, &on_event).expect("run");
    assert!(outcome.failed.is_none(), "{:?}", outcome.failed);
    !outcome.interrupted && outcome.fitted == outcome.dealt
}

#[test]
#[cfg_attr(
    debug_assertions,
    ignore = "minutes without optimizations: CI runs it with --release"
)]
fn a_library_fitted_in_random_shards_with_kills_resumes_and_edits_is_whole_or_says_why() {
    let sources = sources();
    let clock = std::time::Instant::now();
    let mut outcomes: BTreeMap<&str, usize> = BTreeMap::new();
    for trial in 0..TRIALS {
        let mut rng = ChaCha8Rng::seed_from_u64(0x4c1b_0000 + trial);
        let dir = tempfile::tempdir().expect("tempdir");
        let takes_dir = dir.path().join("takes");
        let mut present: BTreeSet<usize> = (0..TAKES).collect();
        for &k in &present {
            let (name, text) = generated(&sources, k);
            let path = takes_dir.join(&name);
            std::fs::create_dir_all(path.parent().unwrap()).expect("folder");
            std::fs::write(path, text).expect("take");
        }
        let (job, query) = tiny(trial);
        let mut truth = Truth {
            job: job.clone(),
            query: query.clone(),
            scratch: tempfile::tempdir().expect("tempdir"),
            known: HashMap::new(),
        };
        let out = dir.path().join("fits");
        let count = rng.random_range(1..=6usize);
        // The library's version each shard's last run saw, and whether it reached every
        // take; the takes each version changed.
        let mut version = 0usize;
        let mut seen: Vec<Option<(usize, bool)>> = vec![None; count];
        let mut changed: Vec<Vec<String>> = vec![Vec::new()];
        let runs = rng.random_range(count..=3 * count);
        for _ in 0..runs {
            let index = rng.random_range(1..=count);
            let stop_after = rng
                .random_bool(0.35)
                .then(|| rng.random_range(1..=TAKES / count));
            let resume = seen[index - 1].is_some() && rng.random_bool(0.9);
            let shard = Shard { index, count };
            let whole = run_shard(&takes_dir, &out, &job, &query, shard, resume, stop_after);
            seen[index - 1] = Some((version, whole));
            if rng.random_bool(0.3) {
                let how = [
                    Edit::Grow,
                    Edit::Shrink,
                    Edit::Touch,
                    Edit::Remove,
                    Edit::Add,
                ][rng.random_range(0..5)];
                let name = match how {
                    Edit::Add => {
                        let k = (0..TAKES + 24)
                            .find(|k| !present.contains(k))
                            .expect("a take to add");
                        present.insert(k);
                        let (name, text) = generated(&sources, k);
                        std::fs::write(takes_dir.join(&name), text).expect("add");
                        name
                    }
                    _ => {
                        let k = *present
                            .iter()
                            .nth(rng.random_range(0..present.len()))
                            .unwrap();
                        let (name, _) = generated(&sources, k);
                        if let Edit::Remove = how {
                            present.remove(&k);
                            std::fs::remove_file(takes_dir.join(&name)).expect("remove");
                        } else {
                            edit(&takes_dir, &name, how);
                        }
                        name
                    }
                };
                version += 1;
                changed.push(vec![name]);
            }
        }
        // Half the trials end with every shard run again, resumed, after the last edit.
        let finished = rng.random_bool(0.5);
        if finished {
            for index in 1..=count {
                let shard = Shard { index, count };
                let whole = run_shard(&takes_dir, &out, &job, &query, shard, true, None);
                assert!(whole, "trial {trial}: shard {index}/{count} did not finish");
                seen[index - 1] = Some((version, true));
            }
        }
        let all_fresh = seen.iter().all(|s| *s == Some((version, true)));
        match collect(&out) {
            Ok(collected) => {
                // Exactly one whole result per take, each the direct fit's.
                let paths = capture_files(std::slice::from_ref(&takes_dir)).expect("takes");
                let mut by_clip: BTreeMap<String, Vec<&str>> = BTreeMap::new();
                for row in &collected.table.rows {
                    by_clip
                        .entry(row.clip.clone())
                        .or_default()
                        .push(&row.result);
                }
                assert_eq!(by_clip.len(), paths.len(), "trial {trial}: takes vs rows");
                for take in &paths {
                    let relative = take.strip_prefix(&takes_dir).unwrap();
                    let clip = relative.to_string_lossy().into_owned();
                    let results = &by_clip
                        .get(&clip)
                        .unwrap_or_else(|| panic!("trial {trial}: {clip} has no result"));
                    assert_eq!(results.len(), 1, "trial {trial}: {clip}: {results:?}");
                    let bytes = std::fs::read(out.join(results[0])).expect("result");
                    assert!(
                        bytes == truth.result(take),
                        "trial {trial}: {clip}: the result is not the direct fit's"
                    );
                }
                *outcomes.entry("collected").or_default() += 1;
            }
            Err(e) => {
                let text = e.to_string();
                assert!(
                    !all_fresh,
                    "trial {trial}: every shard ran whole on the takes as they are: {text}"
                );
                assert!(
                    matches!(
                        e,
                        LibraryError::Refused { .. } | LibraryError::Incomplete { .. }
                    ),
                    "trial {trial}: {text}"
                );
                // Each shard that saw older takes is named with a take changed since.
                let stale: Vec<(usize, usize)> = seen
                    .iter()
                    .enumerate()
                    .filter_map(|(i, s)| s.and_then(|(v, _)| (v != version).then_some((i + 1, v))))
                    .collect();
                for (index, saw) in &stale {
                    let since: BTreeSet<&String> = changed[saw + 1..].iter().flatten().collect();
                    assert!(
                        text.contains(&format!("shard {index}/{count}"))
                            && since.iter().any(|t| text.contains(t.as_str())),
                        "trial {trial}: shard {index}/{count} saw version {saw} of {version} \
                         (changed since: {since:?}): {text}"
                    );
                }
                if stale.is_empty() {
                    // Only pieces missing: a shard that never ran or did not finish.
                    let named = (1..=count).any(|i| {
                        seen[i - 1].is_none_or(|(_, whole)| !whole)
                            && text.contains(&format!("{i}/{count}"))
                    });
                    assert!(named, "trial {trial}: {text}");
                    assert!(
                        text.contains("--resume") || text.contains("did not run"),
                        "{text}"
                    );
                }
                *outcomes.entry("refused or incomplete").or_default() += 1;
            }
        }
    }
    eprintln!(
        "{TRIALS} trials of {TAKES} takes in {:.1} s: {outcomes:?}",
        clock.elapsed().as_secs_f64()
    );
    assert!(
        outcomes.get("collected").is_some_and(|&n| n > 0),
        "{outcomes:?}"
    );
}

/// A take added to the library's folder after every shard ran is named by `collect` (the
/// library is incomplete, not "complete" without it), and a resumed run of every shard fits
/// it alone, after which the library is whole.
#[test]
fn a_take_added_after_every_shard_ran_is_named_then_fitted_on_resume() {
    let sources = sources();
    let dir = tempfile::tempdir().expect("tempdir");
    let takes_dir = dir.path().join("takes");
    let write = |k: usize| write_take(&sources, &takes_dir, k);
    for k in 0..6 {
        write(k);
    }
    let (job, query) = tiny(7);
    let out = dir.path().join("fits");
    for index in 1..=2 {
        let shard = Shard { index, count: 2 };
        assert!(run_shard(
            &takes_dir, &out, &job, &query, shard, false, None
        ));
    }
    let whole = collect(&out).expect("a whole library");
    let added = write(6);
    let e = collect(&out).expect_err("a take was added");
    let text = e.to_string();
    assert!(matches!(e, LibraryError::Incomplete { .. }), "{text}");
    assert!(
        text.contains("1 take(s) in the library's folders were added since shard 1/2, shard 2/2")
            && text.contains(&added)
            && text.contains("--resume"),
        "{text}"
    );
    for index in 1..=2 {
        let shard = Shard { index, count: 2 };
        assert!(run_shard(&takes_dir, &out, &job, &query, shard, true, None));
    }
    let now = collect(&out).expect("whole again");
    assert_eq!(
        now.table.rows.len(),
        whole.table.rows.len() + 1,
        "{:?}",
        now.table.rows
    );
}

/// The sweep's data loss (issue 42): a library whose takes are all in one subfolder has that
/// subfolder as its root; a take added in another subfolder between the shards moves the root,
/// and each shard's takes are still on disk as it saw them. `collect` said complete (a take
/// without a result, another listed twice); it refuses, naming what each shard saw.
#[test]
fn shards_that_saw_different_takes_under_different_roots_are_refused() {
    let sources = sources();
    let dir = tempfile::tempdir().expect("tempdir");
    let takes_dir = dir.path().join("takes");
    let write = |k: usize| write_take(&sources, &takes_dir, k);
    for k in 0..6 {
        write(k);
    }
    let (job, query) = tiny(11);
    let out = dir.path().join("fits");
    let shard = |index| Shard { index, count: 3 };
    assert!(run_shard(
        &takes_dir,
        &out,
        &job,
        &query,
        shard(1),
        false,
        None
    ));
    let added = write(20);
    assert!(!added.starts_with("p01/"), "{added}");
    for index in 2..=3 {
        assert!(run_shard(
            &takes_dir,
            &out,
            &job,
            &query,
            shard(index),
            false,
            None
        ));
    }
    let e = collect(&out).expect_err("the shards saw different takes");
    let text = e.to_string();
    assert!(matches!(e, LibraryError::Refused { .. }), "{text}");
    assert!(
        text.contains("the shards saw different takes (")
            && text.contains("shard 1/3 saw 6 takes under")
            && text.contains("shard 2/3, shard 3/3 saw 7 takes under")
            && text.contains(&format!(
                "not seen by every shard: {}",
                takes_dir.join(&added).display()
            ))
            && text.contains("--resume"),
        "{text}"
    );
    for index in 1..=3 {
        assert!(run_shard(
            &takes_dir,
            &out,
            &job,
            &query,
            shard(index),
            true,
            None
        ));
    }
    let whole = collect(&out).expect("whole after every shard ran again");
    assert_eq!(whole.table.rows.len(), 7, "{:?}", whole.table.rows);
}

/// The sweep's file where a folder goes (once "File exists (os error 17)" part way): the
/// plan refuses it before any work, naming the path and what it is needed for, and a
/// take's results that would land on the library's own `shards` go to `shards@` instead.
#[test]
fn a_file_where_a_folder_of_the_library_goes_is_refused_by_the_plan() {
    let sources = sources();
    let dir = tempfile::tempdir().expect("tempdir");
    let takes_dir = dir.path().join("takes");
    for (i, name) in ["p01/a.bvh", "shards/b.bvh"].iter().enumerate() {
        let path = takes_dir.join(name);
        std::fs::create_dir_all(path.parent().unwrap()).expect("folder");
        std::fs::copy(&sources[i], path).expect("take");
    }
    let (job, query) = tiny(3);
    let paths = capture_files(std::slice::from_ref(&takes_dir)).expect("takes");
    let takes = Takes::of(&paths, None);
    let interrupt = AtomicBool::new(false);
    let observer = || -> Box<dyn Observer> { Box::new(()) };
    for in_the_way in ["shards", "p01"] {
        let out = dir.path().join(format!("fits-{in_the_way}"));
        std::fs::create_dir(&out).expect("folder");
        std::fs::write(out.join(in_the_way), "keep").expect("file");
        let run = ShardRun {
            dir: &out,
            takes: &takes,
            query: &query,
            job: &job,
            person: &PersonRule::Auto,
            shard: Shard::ALL,
            warm_start: false,
            resume: false,
            inputs: &paths,
            interrupt: &interrupt,
            observer: &observer,
        };
        let e = run.plan().expect_err("a file in the way");
        let text = e.to_string();
        assert!(
            matches!(e, LibraryError::Input { .. })
                && text.starts_with(&format!(
                    "{}: a file where ",
                    out.join(in_the_way).display()
                )),
            "{text}"
        );
        assert_eq!(std::fs::read_dir(&out).expect("folder").count(), 1);
    }
    let out = dir.path().join("fits");
    assert!(run_shard(
        &takes_dir,
        &out,
        &job,
        &query,
        Shard::ALL,
        false,
        None
    ));
    assert!(out.join("shards@/b.bvh.json").is_file());
    let collected = collect(&out).expect("whole");
    assert_eq!(collected.table.rows.len(), 2);
}

/// Issue 45: the person rule names each reach in the record and the table, is one of the
/// recorded settings, and `collect_with` names the persons anew by another rule — from the
/// takes' paths, or from the records where the rule reads a segments file's persons (which
/// only a library fitted by such a rule holds: otherwise refused, saying how to mend it).
#[test]
fn the_person_rule_names_the_reaches_and_collect_names_them_anew() {
    use kinergy_train::library::collect_with;
    use kinergy_train::segments_file::SegmentsFile;
    use kinergy_train::who::WhoError;

    let sources = sources();
    let dir = tempfile::tempdir().expect("tempdir");
    let takes_dir = dir.path().join("takes");
    std::fs::create_dir(&takes_dir).expect("folder");
    let names = ["active_001.bvh", "active_002.bvh", "elderly_001.bvh"];
    for (i, name) in names.iter().enumerate() {
        // p01's r01 and r02, then p02's r01.
        let source = &sources[if i < 2 { i } else { 14 }];
        std::fs::copy(source, takes_dir.join(name)).expect("take");
    }
    let segments_path = dir.path().join("segments.csv");
    std::fs::write(
        &segments_path,
        "clip,onset,end,arm,person\ntakes/active_001.bvh,0,16,right,ann\n\
         takes/active_002.bvh,0,16,right,ann\ntakes/elderly_001.bvh,0,16,right,bea\n",
    )
    .expect("segments");
    let segments = SegmentsFile::read(&segments_path).expect("segments file");
    let (job, query) = tiny(5);
    let paths = capture_files(std::slice::from_ref(&takes_dir)).expect("takes");
    let interrupt = AtomicBool::new(false);
    let observer = || -> Box<dyn Observer> { Box::new(()) };
    let fit = |out: &Path, person: &PersonRule, with_segments: bool| {
        let takes = Takes::of(&paths, with_segments.then_some(&segments));
        let run = ShardRun {
            dir: out,
            takes: &takes,
            query: &query,
            job: &job,
            person,
            shard: Shard::ALL,
            warm_start: false,
            resume: false,
            inputs: &paths,
            interrupt: &interrupt,
            observer: &observer,
        };
        let plan = run.plan()?;
        let outcome = run.run(&plan, &|_| {})?;
        assert!(outcome.failed.is_none(), "{:?}", outcome.failed);
        Ok::<_, LibraryError>(())
    };
    let persons = |table: &kinergy_train::library::LibraryTable| -> Vec<String> {
        table.rows.iter().map(|r| r.person.clone()).collect()
    };

    // By file name, without a segments file.
    let by_file = dir.path().join("by-file");
    fit(&by_file, &PersonRule::File, false).expect("fitted");
    let collected = collect(&by_file).expect("whole");
    assert_eq!(persons(&collected.table), ["active", "active", "elderly"]);
    // Named anew by folder: the root's own takes get the root's name; the fingerprint is
    // a fit's with that rule, not the records'.
    let by_folder = collect_with(&by_file, Some(&PersonRule::Folder)).expect("whole");
    assert_eq!(persons(&by_folder.table), ["takes", "takes", "takes"]);
    assert_ne!(
        by_folder.table.rows[0].settings,
        collected.table.rows[0].settings
    );
    // Resumed with another rule and stopped before any take is reached: the record carries
    // every reach found fitted, already named by the new rule.
    {
        let takes = Takes::of(&paths, None);
        let stop = AtomicBool::new(false);
        let run = ShardRun {
            dir: &by_file,
            takes: &takes,
            query: &query,
            job: &job,
            person: &PersonRule::Folder,
            shard: Shard::ALL,
            warm_start: false,
            resume: true,
            inputs: &paths,
            interrupt: &stop,
            observer: &observer,
        };
        let plan = run.plan().expect("plan");
        stop.store(true, Ordering::SeqCst);
        let outcome = run.run(&plan, &|_| {}).expect("run");
        assert!(outcome.interrupted);
        let record = kinergy_train::library::read_record(&by_file.join("shards/1-of-1.csv"))
            .expect("record");
        let reaches: Vec<&str> = record
            .iter()
            .filter(|r| r.kind == "reach")
            .map(|r| r.person.as_str())
            .collect();
        assert_eq!(reaches, ["takes", "takes", "takes"]);
        assert_eq!(
            persons(&collect(&by_file).expect("whole").table),
            ["takes", "takes", "takes"]
        );
    }
    fit(&by_file, &PersonRule::File, false).expect("fitted");

    // `segments` without a segments file: refused, naming the takes.
    let e = collect_with(&by_file, Some(&PersonRule::Segments)).unwrap_err();
    assert!(
        matches!(e, LibraryError::Person(WhoError::NoSegments { ref takes }) if takes.len() == 3),
        "{e}"
    );
    let e = fit(&dir.path().join("none"), &PersonRule::Segments, false).unwrap_err();
    assert!(matches!(e, LibraryError::Person(_)), "{e}");
    assert!(!dir.path().join("none").exists());

    // With a segments file, auto takes its persons; collect under `segments` finds them in
    // the records.
    let by_auto = dir.path().join("by-auto");
    fit(&by_auto, &PersonRule::Auto, true).expect("fitted");
    assert_eq!(
        persons(&collect(&by_auto).expect("whole").table),
        ["ann", "ann", "bea"]
    );
    let by_segments = collect_with(&by_auto, Some(&PersonRule::Segments)).expect("whole");
    assert_eq!(persons(&by_segments.table), ["ann", "ann", "bea"]);
    // A library fitted by folder with the same segments file does not hold them.
    let by_folder = dir.path().join("by-folder");
    fit(&by_folder, &PersonRule::Folder, true).expect("fitted");
    assert_eq!(
        persons(&collect(&by_folder).expect("whole").table),
        ["takes", "takes", "takes"]
    );
    let e = collect_with(&by_folder, Some(&PersonRule::Segments)).unwrap_err();
    assert!(
        e.to_string()
            .contains("fit it again with --resume --person segments"),
        "{e}"
    );
    let by_name = collect_with(&by_folder, Some(&PersonRule::File)).expect("whole");
    assert_eq!(persons(&by_name.table), ["active", "active", "elderly"]);
}
