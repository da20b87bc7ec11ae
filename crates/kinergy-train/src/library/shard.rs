//! One shard of a library: its takes fitted in parallel, each reach's result written
//! atomically as soon as it is fitted, and a record of what it did in
//! `DIR/shards/I-of-N.csv` (the takes it was dealt, then each reach fitted and each take
//! skipped). A result depends on its reach and the seed only, so every number in it is the
//! same whichever shard fitted it.

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use kinergy_solver::FitGrouping;
use rayon::prelude::*;

use super::names::{Takes, take_names};
use super::table::{LibraryError, RecordRow, SHARDS, is_complete, record_path, write_csv};
use super::{Shard, dealt_to};
use crate::CapturedReach;
use crate::anneal::Observer;
use crate::error::TrainError;
use crate::fit::{FitJob, NestedFit};
use crate::segments_file::default_person;
use crate::source::{ReachQuery, Skipped};

/// A shard's run: where, which takes, how each is found and fitted.
pub struct ShardRun<'a> {
    /// The library folder (made if missing; its parent must exist).
    pub dir: &'a Path,
    /// The library's takes.
    pub takes: &'a Takes<'a>,
    /// How each take's reaches are found (takes with segments-file rows use their rows).
    pub query: &'a ReachQuery,
    /// How each reach is fitted.
    pub job: &'a FitJob,
    /// Which share of the takes this run fits.
    pub shard: Shard,
    /// Keep the results already complete (a reach's result file of the job's last model,
    /// recording its clip, frames and arm) and fit only the rest.
    pub resume: bool,
    /// Files no result may be written over (the captures, a segments file), as given: a
    /// result's name is known only once its take is segmented.
    pub inputs: &'a [PathBuf],
    /// Raised to stop: no new take or reach starts, and fits stop at their next iteration.
    pub interrupt: &'a AtomicBool,
    /// Makes the observer of each reach's fit (called once per reach, on its worker).
    pub observer: &'a (dyn Fn() -> Box<dyn Observer> + Sync),
}

/// What a shard's run says as it goes (from its worker threads).
#[derive(Debug)]
pub enum ShardEvent<'e> {
    /// A reach was fitted and its result written to `output`.
    Fitted {
        /// The result file.
        output: &'e Path,
        /// The reach.
        reach: &'e CapturedReach,
        /// Its fits, poorest model first.
        fits: &'e NestedFit,
    },
    /// A take is done: fitted, found fitted, skipped or failed.
    TakeDone,
}

/// How a shard's run ended.
#[derive(Debug)]
pub struct ShardOutcome {
    /// The takes dealt to the shard.
    pub dealt: usize,
    /// The reaches fitted or found fitted.
    pub fitted: usize,
    /// The takes with nothing to fit.
    pub skipped: Vec<Skipped>,
    /// The shard's record file.
    pub record: PathBuf,
    /// The first take that could not be fitted, and why (the others stopped).
    pub failed: Option<(PathBuf, TrainError)>,
    /// The interrupt flag stopped the run.
    pub interrupted: bool,
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
    fn write(&self) -> Result<(), LibraryError> {
        let rows = self.rows.lock().map_err(|_| poisoned(&self.path))?.clone();
        write_csv(&self.path, &rows)
    }

    fn push(&self, rows: Vec<RecordRow>) -> Result<(), LibraryError> {
        self.rows
            .lock()
            .map_err(|_| poisoned(&self.path))?
            .extend(rows);
        let due = {
            let mut last = self.last_write.lock().map_err(|_| poisoned(&self.path))?;
            let due = last.elapsed().as_secs_f64() >= RECORD_EVERY_S;
            if due {
                *last = Instant::now();
            }
            due
        };
        if due { self.write() } else { Ok(()) }
    }
}

fn poisoned(path: &Path) -> LibraryError {
    LibraryError::Write {
        path: path.to_path_buf(),
        why: "a worker of the library run failed".into(),
    }
}

/// What a take came to.
enum TakeOutcome {
    /// Its reaches' record rows (fitted or found fitted).
    Fitted(Vec<RecordRow>),
    /// Nothing to fit.
    Skipped(Skipped),
    /// Not started or stopped part way: the run was stopped.
    Stopped,
}

/// Why a take failed: the library's own files, or the take's reaches and fits.
enum TakeError {
    Library(LibraryError),
    Take(TrainError),
}

impl From<LibraryError> for TakeError {
    fn from(e: LibraryError) -> TakeError {
        TakeError::Library(e)
    }
}

impl From<TrainError> for TakeError {
    fn from(e: TrainError) -> TakeError {
        TakeError::Take(e)
    }
}

impl ShardRun<'_> {
    /// The takes dealt to this shard, in the library's order (each take's header read once
    /// for its weight): what [`run`](Self::run) fits.
    pub fn dealt(&self) -> Vec<&std::path::PathBuf> {
        dealt_to(self.shard, &self.takes.paths)
    }

    /// Runs the shard on the takes `mine` dealt to it ([`dealt`](Self::dealt)): makes the folder and its `shards` folder, writes the record of the
    /// takes dealt, fits them (each reach's result written as soon as it is fitted, each
    /// event told to `on_event`), and writes the record again at the end. A take that fails
    /// stops the others (its error is in the outcome); a failed or interrupted run that
    /// fitted nothing leaves the folder as it found it. An error here is about the library's
    /// own files (its folder or record could not be made or written).
    pub fn run(
        &self,
        mine: &[&std::path::PathBuf],
        on_event: &(dyn Fn(ShardEvent<'_>) + Sync),
    ) -> Result<ShardOutcome, LibraryError> {
        let made_dir = !self.dir.exists();
        let shards = self.dir.join(SHARDS);
        let made_shards = !shards.exists();
        std::fs::create_dir_all(self.dir).map_err(|e| LibraryError::Input {
            path: self.dir.to_path_buf(),
            why: format!("cannot create the folder: {e}"),
        })?;
        std::fs::create_dir_all(&shards).map_err(|e| LibraryError::Input {
            path: shards.clone(),
            why: e.to_string(),
        })?;
        let record = Record {
            path: record_path(self.dir, self.shard.index, self.shard.count),
            rows: Mutex::new(mine.iter().map(|t| RecordRow::take(t)).collect()),
            last_write: Mutex::new(Instant::now()),
        };
        record.write()?;
        let inputs: HashSet<PathBuf> = self
            .inputs
            .iter()
            .filter_map(|p| std::fs::canonicalize(p).ok())
            .collect();
        let failed = AtomicBool::new(false);
        let outcomes: Vec<Result<TakeOutcome, TakeError>> = mine
            .par_iter()
            .map(|take| {
                if failed.load(Ordering::SeqCst) || self.interrupt.load(Ordering::SeqCst) {
                    return Ok(TakeOutcome::Stopped);
                }
                let outcome = self.take(take, &record, &inputs, on_event);
                if outcome.is_err() {
                    failed.store(true, Ordering::SeqCst);
                }
                on_event(ShardEvent::TakeDone);
                outcome
            })
            .collect();
        let mut outcome = ShardOutcome {
            dealt: mine.len(),
            fitted: 0,
            skipped: Vec::new(),
            record: record.path.clone(),
            failed: None,
            interrupted: false,
        };
        let mut library_error = None;
        for (take, result) in mine.iter().zip(outcomes) {
            match result {
                Ok(TakeOutcome::Fitted(rows)) => outcome.fitted += rows.len(),
                Ok(TakeOutcome::Skipped(skip)) => outcome.skipped.push(skip),
                Ok(TakeOutcome::Stopped) => {}
                Err(TakeError::Take(TrainError::Interrupted { .. })) => {}
                Err(TakeError::Take(e)) => {
                    outcome
                        .failed
                        .get_or_insert_with(|| (take.to_path_buf(), e));
                }
                Err(TakeError::Library(e)) => {
                    library_error.get_or_insert(e);
                }
            }
        }
        outcome.interrupted = self.interrupt.load(Ordering::SeqCst);
        record.write()?;
        if let Some(e) = library_error {
            return Err(e);
        }
        if outcome.fitted == 0 && (outcome.failed.is_some() || outcome.interrupted) {
            // Nothing written but the record: a failed run leaves the folder as it found it
            // (best effort: the run's error is what gets reported).
            let _ = std::fs::remove_file(&record.path);
            if made_shards {
                let _ = std::fs::remove_dir(&shards);
            }
            if made_dir {
                let _ = std::fs::remove_dir(self.dir);
            }
        }
        Ok(outcome)
    }

    /// Fits the reaches of one take (or finds them fitted, resuming) and records them.
    fn take(
        &self,
        take: &Path,
        record: &Record,
        inputs: &HashSet<PathBuf>,
        on_event: &(dyn Fn(ShardEvent<'_>) + Sync),
    ) -> Result<TakeOutcome, TakeError> {
        let found: Vec<(CapturedReach, Option<String>)> = match self.takes.rows_of(take) {
            Some((segments, rows)) => self
                .query
                .rows(segments, rows, take)?
                .into_iter()
                .map(|f| (f.reach, f.person))
                .collect(),
            None => match self.query.take_at(take)? {
                Ok(reaches) => reaches.into_iter().map(|r| (r, None)).collect(),
                Err(skip) => {
                    record.push(vec![RecordRow::skipped(take, &skip.why)])?;
                    return Ok(TakeOutcome::Skipped(skip));
                }
            },
        };
        let reaches: Vec<CapturedReach> = found.iter().map(|(r, _)| r.clone()).collect();
        let names = take_names(&self.takes.common, take, &reaches);
        let last_model = self.job.models.iter().max().copied();
        let mut rows = Vec::with_capacity(found.len());
        for ((reach, person), name) in found.into_iter().zip(names) {
            let output = self.dir.join(&name);
            let person = person.unwrap_or_else(|| default_person(take));
            let row = RecordRow::reach(take, &reach, person, &name, String::new());
            if self.resume && last_model.is_some_and(|m| is_complete(&output, &reach, m)) {
                rows.push(row);
                continue;
            }
            if self.interrupt.load(Ordering::SeqCst) {
                return Ok(TakeOutcome::Stopped);
            }
            let clock = Instant::now();
            let group = std::slice::from_ref(&reach);
            let mut observer = (self.observer)();
            let fits = self
                .job
                .run_stoppable(group, &mut *observer, Some(self.interrupt))?;
            if let Some(parent) = output.parent() {
                std::fs::create_dir_all(parent).map_err(|e| LibraryError::Write {
                    path: parent.to_path_buf(),
                    why: e.to_string(),
                })?;
            }
            self.check_not_input(&output, inputs)?;
            fits.params_file(group, FitGrouping::Clip)?
                .write(&output)
                .map_err(TrainError::from)?;
            let seconds = clock.elapsed().as_secs_f64();
            on_event(ShardEvent::Fitted {
                output: &output,
                reach: &reach,
                fits: &fits,
            });
            rows.push(RecordRow {
                seconds: format!("{seconds:.3}"),
                ..row
            });
        }
        record.push(rows.clone())?;
        Ok(TakeOutcome::Fitted(rows))
    }

    /// Refuses to write the result `output` over one of the inputs (a segments file kept in
    /// the library folder under a result's name).
    fn check_not_input(
        &self,
        output: &Path,
        inputs: &HashSet<PathBuf>,
    ) -> Result<(), LibraryError> {
        let canonical = match (output.parent(), output.file_name()) {
            (Some(folder), Some(name)) => std::fs::canonicalize(folder).map(|f| f.join(name)),
            _ => std::fs::canonicalize(output),
        };
        match canonical {
            Ok(path) if inputs.contains(&path) => Err(LibraryError::Input {
                path: output.to_path_buf(),
                why: format!(
                    "a result would be written over this input: move it out of {}, or fit \
                     into another folder",
                    self.dir.display()
                ),
            }),
            _ => Ok(()),
        }
    }
}
