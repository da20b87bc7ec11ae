//! `fit --per clip` into a folder: a library of captures, one result per reach.
//!
//! The takes are weighed by their frame count and dealt to shards
//! ([`kinergy_train::library`]: `--shard I/N`, or the Slurm array's task; one shard on one
//! machine); a shard fits its takes in parallel, each reach's result written atomically as
//! soon as it is fitted, and keeps a record of what it did in `DIR/shards/I-of-N.csv` (the
//! takes it was dealt, then each reach fitted and each take skipped or failed). [`collect`]
//! turns the records and the result files into `DIR/library.csv` and `DIR/skipped.csv`, and
//! says what is missing; a one-shard run collects at its end. The files and their checks are
//! the library's ([`kinergy_train::library`]); this is the CLI's run of a shard. A result depends on its reach
//! and the seed only, so every number in it is the same whichever shard fitted it.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use kinergy_solver::Model;
use kinergy_train::CapturedReach;
use kinergy_train::fit::FitSettings;
use kinergy_train::library::{RecordRow, SHARDS, Shard, collect, dealt_to, is_complete};
use kinergy_train::segments_file::{SegmentRow, SegmentsFile, default_person};
use rayon::prelude::*;

use super::{Args, INTERRUPTED, report, report_text, run_group};
use crate::common::{Bar, CaptureClips, Failure, Skipped, emit, report_skipped};

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
        Ok(kinergy_train::library::write_csv(&self.path, &rows)?)
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
    let mine = dealt_to(shard, &takes.paths);
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
            path: kinergy_train::library::record_path(dest, shard.index, shard.count),
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
        if summary.table.rows.is_empty() {
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
                self.record
                    .push(vec![RecordRow::skipped(take, &skip.why)])?;
                return Ok(TakeOutcome::Skipped(skip));
            }
        };
        let just: Vec<CapturedReach> = reaches.iter().map(|(r, _)| r.clone()).collect();
        let names = super::take_names(&self.takes.common, take, &just);
        let mut rows = Vec::with_capacity(reaches.len());
        for ((reach, person), name) in reaches.iter().zip(names) {
            let output = self.dest.join(&name);
            let person = person.clone().unwrap_or_else(|| default_person(take));
            let row = RecordRow::reach(take, reach, person, &name, String::new());
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
