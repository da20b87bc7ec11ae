//! `fit --per clip` into a folder: a library of captures, one result per reach.
//!
//! The takes are weighed by their frame count and dealt to shards
//! ([`kinergy_train::library`]: `--shard I/N`, or the Slurm array's task; one shard on one
//! machine); a shard fits its takes in parallel, each reach's result written atomically as
//! soon as it is fitted, and keeps a record of what it did in `DIR/shards/I-of-N.csv` (the
//! takes it was dealt, then each reach fitted and each take skipped or failed). [`collect`]
//! turns the records and the result files into `DIR/library.csv` and `DIR/skipped.csv`, and
//! says what is missing; a one-shard run collects at its end. A result depends on its reach
//! and the seed only, so every number in it is the same whichever shard fitted it.

use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use kinergy_solver::{Model, ParamsFile};
use kinergy_train::CapturedReach;
use kinergy_train::fit::FitSettings;
use kinergy_train::library::{Shard, deal};
use kinergy_train::segments_file::{SegmentRow, SegmentsFile, default_person};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::{Args, INTERRUPTED, report, report_text, run_group};
use crate::common::{Bar, CaptureClips, Failure, Skipped, emit, report_skipped};

/// The folder, inside the output folder, of the shards' records.
pub const SHARDS: &str = "shards";
/// One row per reach fitted: the library's results as a table.
pub const LIBRARY: &str = "library.csv";
/// One row per take skipped, with the reason.
pub const SKIPPED: &str = "skipped.csv";

/// A library's takes, found once: each capture once (the first spelling kept), in the
/// library's order, their common folder (results are named from it) and, with a segments
/// file, its rows by clip.
pub struct Takes<'a> {
    /// Each capture once.
    pub paths: Vec<PathBuf>,
    /// Their common folder (of their canonical paths).
    pub common: PathBuf,
    /// With `--segments`, the file's rows by clip ([`SegmentsFile::rows_by_clip`]).
    rows: Option<HashMap<PathBuf, Vec<&'a SegmentRow>>>,
}

impl<'a> Takes<'a> {
    /// The takes of `clips`.
    pub fn of(clips: &'a CaptureClips) -> Takes<'a> {
        let paths = super::unique_takes(&clips.paths);
        let canonical: Vec<PathBuf> = paths
            .iter()
            .map(|t| std::fs::canonicalize(t).unwrap_or_else(|_| t.clone()))
            .collect();
        Takes {
            common: super::common_folder(&canonical),
            paths,
            rows: clips.segments().map(SegmentsFile::rows_by_clip),
        }
    }

    /// The segments file's rows of `take`, with a segments file.
    pub fn rows_of(&self, take: &Path) -> Option<&[&'a SegmentRow]> {
        let index = self.rows.as_ref()?;
        Some(
            index
                .get(&SegmentsFile::clip_key(take))
                .map_or(&[][..], Vec::as_slice),
        )
    }
}

/// One line of a shard's record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct RecordRow {
    /// `take` (dealt to the shard), `reach` (fitted or found fitted), `skipped` (nothing to
    /// fit) or `failed` (the take could not be fitted).
    kind: String,
    clip: String,
    person: String,
    arm: String,
    onset: String,
    end: String,
    /// The result file, relative to the output folder.
    result: String,
    /// Seconds the reach's fit took (empty when it was found already fitted).
    seconds: String,
    why: String,
}

impl RecordRow {
    fn take(clip: &Path) -> RecordRow {
        RecordRow {
            kind: "take".into(),
            clip: clip.display().to_string(),
            person: String::new(),
            arm: String::new(),
            onset: String::new(),
            end: String::new(),
            result: String::new(),
            seconds: String::new(),
            why: String::new(),
        }
    }
}

/// One row of `library.csv`.
#[derive(Debug, Clone, PartialEq, Serialize)]
struct LibraryRow {
    clip: String,
    person: String,
    arm: String,
    onset: usize,
    end: usize,
    frames: usize,
    model: &'static str,
    optimizer: &'static str,
    distance_sa_m: Option<f64>,
    distance_sb_m: Option<f64>,
    distance_sc_m: Option<f64>,
    distance_sd_m: Option<f64>,
    distance_se_m: Option<f64>,
    evaluations: usize,
    seconds: Option<f64>,
    result: String,
}

/// One row of `skipped.csv`.
#[derive(Debug, Clone, PartialEq, Serialize)]
struct SkippedRow<'a> {
    clip: &'a str,
    why: &'a str,
}

/// What a take came to in this run.
enum TakeOutcome {
    /// Its reaches' record rows (fitted or found fitted).
    Fitted(Vec<RecordRow>),
    /// Nothing to fit.
    Skipped(Skipped),
}

/// The shard's record, shared by the workers and written atomically now and then.
struct Record {
    path: PathBuf,
    rows: Mutex<Vec<RecordRow>>,
    last_write: Mutex<Instant>,
}

/// How often, at most, the record is rewritten while the shard runs (it is at its end).
const RECORD_EVERY_S: f64 = 5.0;

impl Record {
    fn write(&self) -> Result<(), Failure> {
        let rows = self.rows.lock().map_err(|_| poisoned())?.clone();
        crate::common::write_csv(&self.path, &rows)
    }

    fn push(&self, rows: Vec<RecordRow>) -> Result<(), Failure> {
        self.rows.lock().map_err(|_| poisoned())?.extend(rows);
        let due = {
            let mut last = self.last_write.lock().map_err(|_| poisoned())?;
            let due = last.elapsed().as_secs_f64() >= RECORD_EVERY_S;
            if due {
                *last = Instant::now();
            }
            due
        };
        if due { self.write() } else { Ok(()) }
    }
}

fn poisoned() -> Failure {
    Failure::Task("a worker of the library run failed".into())
}

/// What a run made before it fitted anything, so that a run that fails first undoes it.
struct Made {
    /// The output folder was made.
    dest: bool,
    /// Its `shards` folder was made.
    shards: bool,
}

impl Made {
    /// Removes the shard's `record` and the folders this run made, where empty (best
    /// effort: the run's error is what gets reported).
    fn undo(&self, dest: &Path, record: &Path) {
        let _ = std::fs::remove_file(record);
        if self.shards {
            let _ = std::fs::remove_dir(dest.join(SHARDS));
        }
        if self.dest {
            let _ = std::fs::remove_dir(dest);
        }
    }
}

/// Everything a shard's workers share.
struct Library<'a> {
    args: &'a Args,
    clips: &'a CaptureClips,
    models: &'a [Model],
    settings: &'a FitSettings,
    dest: &'a Path,
    /// The library's takes.
    takes: &'a Takes<'a>,
    /// The inputs' canonical paths: no result may be written over one (a result's name is
    /// known only once its take is segmented, after the output check).
    inputs: HashSet<PathBuf>,
    record: Record,
    /// Set on the first error: no worker starts another take.
    stop: AtomicBool,
    bar: Bar,
    /// With `--json`, the reports of the reaches fitted, printed at the end.
    reports: Mutex<Vec<super::FitReport>>,
}

/// Runs `fit --per clip` into the folder `dest`: this run's shard of the library of
/// `clips`, then, with one shard, [`collect`].
pub fn run(
    args: &Args,
    clips: &CaptureClips,
    takes: Takes<'_>,
    models: &[Model],
    settings: &FitSettings,
    dest: &Path,
) -> Result<(), Failure> {
    let shard = match &args.shard {
        Some(text) => Shard::parse(text).map_err(|e| Failure::Input(format!("--shard {e}")))?,
        None => Shard::from_slurm(|name| std::env::var(name).ok())
            .map_err(Failure::Input)?
            .unwrap_or(Shard::ALL),
    };
    let weights: Vec<u64> = takes
        .paths
        .iter()
        .map(|t| {
            kinergy_bvh::header_frame_count(t)
                .ok()
                .flatten()
                .unwrap_or(1) as u64
        })
        .collect();
    let dealt = deal(&weights, shard.count);
    let mine: Vec<&PathBuf> = takes
        .paths
        .iter()
        .zip(&dealt)
        .filter(|(_, s)| **s == shard.index)
        .map(|(t, _)| t)
        .collect();
    let made = Made {
        dest: !dest.exists(),
        shards: !dest.join(SHARDS).exists(),
    };
    crate::common::make_folder(dest)?;
    let shards = dest.join(SHARDS);
    std::fs::create_dir_all(&shards).map_err(|e| Failure::input(&shards, e))?;
    let library = Library {
        args,
        clips,
        models,
        settings,
        dest,
        takes: &takes,
        inputs: clips
            .inputs()
            .into_iter()
            .chain(args.reach.segments.as_deref())
            .filter_map(|p| std::fs::canonicalize(p).ok())
            .collect(),
        record: Record {
            path: shards.join(format!("{}-of-{}.csv", shard.index, shard.count)),
            rows: Mutex::new(mine.iter().map(|t| RecordRow::take(t)).collect()),
            last_write: Mutex::new(Instant::now()),
        },
        stop: AtomicBool::new(false),
        bar: Bar::counting(mine.len() as u64, "takes"),
        reports: Mutex::new(Vec::new()),
    };
    library.record.write()?;
    let outcomes: Vec<Result<TakeOutcome, Failure>> = mine
        .par_iter()
        .map(|take| {
            if library.stop.load(Ordering::SeqCst) || INTERRUPTED.load(Ordering::SeqCst) {
                return Err(Failure::Task("stopped".into()));
            }
            let outcome = library.take(take);
            if outcome.is_err() {
                library.stop.store(true, Ordering::SeqCst);
            }
            library.bar.inc();
            outcome
        })
        .collect();
    library.bar.finish();
    let mut skipped = Vec::new();
    let mut first_error = None;
    let mut fitted = 0;
    for (take, outcome) in mine.iter().zip(outcomes) {
        match outcome {
            Ok(TakeOutcome::Fitted(rows)) => fitted += rows.len(),
            Ok(TakeOutcome::Skipped(skip)) => skipped.push(skip),
            Err(e) => {
                if first_error.is_none() && !matches!(&e, Failure::Task(m) if m == "stopped") {
                    first_error = Some((take.to_path_buf(), e));
                }
            }
        }
    }
    library.record.write()?;
    report_skipped(&skipped);
    if fitted == 0 && (first_error.is_some() || INTERRUPTED.load(Ordering::SeqCst)) {
        // Nothing written but the record: a failed run leaves the folder as it found it.
        made.undo(dest, &library.record.path);
    }
    if INTERRUPTED.load(Ordering::SeqCst) {
        return Err(Failure::Task(format!(
            "interrupted: {fitted} reaches fitted and written to {}; the rest were not: run \
             again with --resume to fit only those",
            dest.display()
        )));
    }
    if let Some((take, e)) = first_error {
        let note = format!(
            "{fitted} reaches were fitted and written to {} before it; run again with \
             --resume to fit only the rest",
            dest.display()
        );
        return Err(match e {
            Failure::Input(why) => Failure::Input(format!("{why}; {note}")),
            Failure::Task(why) => Failure::Task(format!("{}: {why}; {note}", take.display())),
        });
    }
    if args.json {
        let mut reports = library.reports.into_inner().map_err(|_| poisoned())?;
        reports.sort_by(|a, b| a.output.cmp(&b.output));
        if shard.count == 1 {
            collect(dest)?;
        }
        if reports.is_empty() && fitted == 0 {
            return Err(crate::common::nothing_to_fit(&skipped));
        }
        return crate::common::print_json(&reports);
    }
    if shard.count == 1 {
        let summary = collect(dest)?;
        emit(&summary.text)?;
        if summary.reaches == 0 {
            return Err(crate::common::nothing_to_fit(&skipped));
        }
    } else {
        emit(&format!(
            "shard {}/{}: {} takes, {fitted} reaches fitted, {} skipped; record {} (then \
             `kinergy collect {}`)\n",
            shard.index,
            shard.count,
            mine.len(),
            skipped.len(),
            library.record.path.display(),
            dest.display()
        ))?;
        if fitted == 0 && !mine.is_empty() {
            return Err(crate::common::nothing_to_fit(&skipped));
        }
    }
    Ok(())
}

impl Library<'_> {
    /// Fits the reaches of one take (or finds them fitted, with `--resume`) and records
    /// them.
    fn take(&self, take: &Path) -> Result<TakeOutcome, Failure> {
        let found = match (self.clips.segments(), self.takes.rows_of(take)) {
            (Some(segments), Some(rows)) => Ok(self.args.reach.take_rows(segments, rows, take)?),
            _ => self
                .args
                .reach
                .take(take)?
                .map(|r| r.into_iter().map(|r| (r, None)).collect()),
        };
        let reaches: Vec<(CapturedReach, Option<String>)> = match found {
            Ok(reaches) => reaches,
            Err(skip) => {
                self.record.push(vec![RecordRow {
                    kind: "skipped".into(),
                    why: skip.why.clone(),
                    ..RecordRow::take(take)
                }])?;
                return Ok(TakeOutcome::Skipped(skip));
            }
        };
        let just: Vec<CapturedReach> = reaches.iter().map(|(r, _)| r.clone()).collect();
        let names = super::take_names(&self.takes.common, take, &just);
        let mut rows = Vec::with_capacity(reaches.len());
        for ((reach, person), name) in reaches.iter().zip(names) {
            let output = self.dest.join(&name);
            let arm = reach
                .fitted_arm()
                .side
                .map_or_else(String::new, |s| s.to_string());
            let row = RecordRow {
                kind: "reach".into(),
                person: person.clone().unwrap_or_else(|| default_person(take)),
                arm,
                onset: reach.frames().start.to_string(),
                end: reach.frames().end.to_string(),
                result: name.display().to_string(),
                ..RecordRow::take(take)
            };
            if self.args.resume && is_complete(&output, reach, self.args.model) {
                rows.push(row);
                continue;
            }
            if INTERRUPTED.load(Ordering::SeqCst) {
                return Err(Failure::Task("stopped".into()));
            }
            let clock = Instant::now();
            let group = std::slice::from_ref(reach);
            let fits = run_group(self.args, group, self.models, self.settings, None, false)?;
            if let Some(parent) = output.parent() {
                std::fs::create_dir_all(parent).map_err(|e| Failure::input(parent, e))?;
            }
            self.check_not_input(&output)?;
            let file = fits
                .params_file(group, self.args.per.grouping())
                .map_err(Failure::from)?;
            file.write(&output).map_err(Failure::from)?;
            let seconds = clock.elapsed().as_secs_f64();
            let done = report(&output, self.args, group, &fits.fits, &fits.violations());
            if self.args.json {
                self.reports.lock().map_err(|_| poisoned())?.push(done);
            } else {
                emit(&report_text(&done))?;
            }
            rows.push(RecordRow {
                seconds: format!("{seconds:.3}"),
                ..row
            });
        }
        self.record.push(rows.clone())?;
        Ok(TakeOutcome::Fitted(rows))
    }
}

impl Library<'_> {
    /// Refuses to write the result `output` over one of the inputs (a segments file kept
    /// in the output folder under a result's name).
    fn check_not_input(&self, output: &Path) -> Result<(), Failure> {
        let canonical = match (output.parent(), output.file_name()) {
            (Some(folder), Some(name)) => std::fs::canonicalize(folder).map(|f| f.join(name)),
            _ => std::fs::canonicalize(output),
        };
        match canonical {
            Ok(path) if self.inputs.contains(&path) => Err(Failure::Input(format!(
                "{}: a result would be written over this input: move it out of {}, or fit \
                 into another folder",
                output.display(),
                self.dest.display()
            ))),
            _ => Ok(()),
        }
    }
}

/// Whether `path` holds a complete result for `reach` fitted up to `model`: a parameters
/// file that reads, of that model, recording this reach's clip, frames and arm.
fn is_complete(path: &Path, reach: &CapturedReach, model: Model) -> bool {
    let Ok(file) = ParamsFile::read(path) else {
        return false;
    };
    let Some(record) = &file.fit else {
        return false;
    };
    file.model == model
        && record.reaches.len() == 1
        && record.reaches[0].clip == reach.name()
        && record.reaches[0].frames == [reach.frames().start, reach.frames().end]
        && record.reaches[0].arm.as_ref().map(|a| a.side) == Some(reach.fitted_arm().side)
}

/// What [`collect`] found.
#[derive(Debug)]
pub struct Collected {
    /// Reaches in library.csv.
    pub reaches: usize,
    /// The summary said to the user.
    pub text: String,
}

/// Reads the shards' records in `dir`, checks that every take dealt was fitted or skipped
/// and every result is there and complete, and writes `library.csv` (one row per reach, by
/// clip, frames and arm) and `skipped.csv`. Idempotent. Incomplete — a shard without a
/// record, takes no shard finished, results missing or damaged, takes that failed — it
/// still writes what is there, then fails (exit 1) naming what is missing and why.
pub fn collect(dir: &Path) -> Result<Collected, Failure> {
    let shards = dir.join(SHARDS);
    let entries = std::fs::read_dir(&shards).map_err(|e| {
        Failure::input(
            &shards,
            format!("no shard records here ({e}): is this a `fit --out-dir` folder?"),
        )
    })?;
    let mut records: BTreeMap<(usize, usize), Vec<RecordRow>> = BTreeMap::new();
    for entry in entries.flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        let Some(shard) = name
            .strip_suffix(".csv")
            .and_then(|s| s.split_once("-of-"))
            .and_then(|(i, n)| Some((i.parse::<usize>().ok()?, n.parse::<usize>().ok()?)))
        else {
            continue;
        };
        records.insert(shard, read_record(&entry.path())?);
    }
    let Some(&(_, count)) = records.keys().max_by_key(|(_, n)| *n) else {
        return Err(Failure::Input(format!(
            "{}: no shard record (I-of-N.csv): nothing was fitted into {} yet",
            shards.display(),
            dir.display()
        )));
    };
    let mut problems = Vec::new();
    let counts: std::collections::BTreeSet<usize> = records.keys().map(|(_, n)| *n).collect();
    if counts.len() > 1 {
        problems.push(format!(
            "records of different shardings ({}): remove the old ones from {}",
            counts
                .iter()
                .map(|n| format!("of {n}"))
                .collect::<Vec<_>>()
                .join(", "),
            shards.display()
        ));
    }
    for index in 1..=count {
        if !records.contains_key(&(index, count)) {
            problems.push(format!(
                "shard {index}/{count} has no record: it did not run (or was killed before \
                 it started)"
            ));
        }
    }
    let mut library = Vec::new();
    let mut skipped: Vec<(String, String)> = Vec::new();
    for ((index, n), rows) in &records {
        if *n != count {
            continue;
        }
        let mut done: BTreeMap<&str, bool> = BTreeMap::new();
        for row in rows {
            match row.kind.as_str() {
                "take" => {
                    done.entry(&row.clip).or_insert(false);
                }
                "skipped" => {
                    done.insert(&row.clip, true);
                    skipped.push((row.clip.clone(), row.why.clone()));
                }
                "reach" => {
                    done.insert(&row.clip, true);
                    match library_row(dir, row) {
                        Ok(r) => library.push(r),
                        Err(why) => problems.push(format!(
                            "{}: reach {}..{} ({} arm): {why}",
                            row.clip, row.onset, row.end, row.arm
                        )),
                    }
                }
                _ => {}
            }
        }
        let missing: Vec<&str> = done.iter().filter(|(_, d)| !**d).map(|(c, _)| *c).collect();
        if !missing.is_empty() {
            problems.push(format!(
                "shard {index}/{count}: {} of its takes not fitted ({}): run it again with \
                 --resume",
                missing.len(),
                kinergy_io::list_some(&missing, 5)
            ));
        }
    }
    library.sort_by(|a, b| {
        (&a.clip, a.onset, &a.arm)
            .cmp(&(&b.clip, b.onset, &b.arm))
            .then(a.result.cmp(&b.result))
    });
    skipped.sort();
    crate::common::write_csv(&dir.join(LIBRARY), &library)?;
    let skipped_rows: Vec<SkippedRow<'_>> = skipped
        .iter()
        .map(|(clip, why)| SkippedRow { clip, why })
        .collect();
    crate::common::write_csv(&dir.join(SKIPPED), &skipped_rows)?;
    let text = format!(
        "{} reaches in {}; {} takes skipped, listed in {}\n",
        library.len(),
        dir.join(LIBRARY).display(),
        skipped.len(),
        dir.join(SKIPPED).display()
    );
    if !problems.is_empty() {
        return Err(Failure::Task(format!(
            "{text}the library in {} is not complete:\n  {}",
            dir.display(),
            problems.join("\n  ")
        )));
    }
    Ok(Collected {
        reaches: library.len(),
        text,
    })
}

/// A shard's record.
fn read_record(path: &Path) -> Result<Vec<RecordRow>, Failure> {
    let text =
        kinergy_io::read_to_string_limited(path, 1 << 30).map_err(|e| Failure::input(path, e))?;
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    reader
        .deserialize()
        .collect::<Result<Vec<RecordRow>, _>>()
        .map_err(|e| Failure::input(path, format!("not a shard record: {e}")))
}

/// The library row of a record's reach, from its result file.
fn library_row(dir: &Path, row: &RecordRow) -> Result<LibraryRow, String> {
    let path = dir.join(&row.result);
    let file = ParamsFile::read(&path).map_err(|e| format!("result {}: {e}", path.display()))?;
    let record = file
        .fit
        .as_ref()
        .ok_or_else(|| format!("result {}: no fit record", path.display()))?;
    let distance = |model: Model| -> Option<f64> {
        match &record.nested {
            Some(stages) => stages.iter().find(|s| s.model == model).map(|s| s.score_m),
            None => (file.model == model).then_some(record.score_m),
        }
    };
    let [sa, sb, sc, sd, se] = Model::ALL.map(distance);
    let number = |s: &str| s.parse::<usize>().map_err(|_| format!("frame `{s}`"));
    let (onset, end) = (number(&row.onset)?, number(&row.end)?);
    Ok(LibraryRow {
        clip: row.clip.clone(),
        person: row.person.clone(),
        arm: row.arm.clone(),
        onset,
        end,
        frames: end.saturating_sub(onset),
        model: file.model.name(),
        optimizer: file.optimizer.kind().name(),
        distance_sa_m: sa,
        distance_sb_m: sb,
        distance_sc_m: sc,
        distance_sd_m: sd,
        distance_se_m: se,
        evaluations: record.evaluations,
        seconds: row.seconds.parse().ok(),
        result: row.result.clone(),
    })
}
