//! One shard of a library: its takes fitted in parallel, each reach's result written
//! atomically as soon as it is fitted, and a record of what it did in `DIR/shards`
//! ([`record`](super::record): the header `I-of-N.json` with the run's settings and the
//! library's takes, and `I-of-N.csv`, the takes it was dealt, then each reach fitted, with
//! its result's hash, and each take skipped). A result depends on its reach and the
//! settings only (with [warm starts](super#warm-starts), on its group's first reach too), so
//! every number in it is the same whichever shard fitted it.
//!
//! Resuming trusts the records, not the files' names: a reach is found fitted when a
//! record of the same settings (the person rule aside: it changes no result), whose take
//! had the same content as now, lists its result with the hash the file has now — however
//! the takes' paths are spelled, from whichever folder the run starts.

use std::collections::HashMap;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use kinergy_solver::FitGrouping;
use rayon::prelude::*;

use super::deal;
use super::identity::{Settings, TakeIdentity, hash_file, slash_path};
use super::names::{Takes, relative_name, result_folder, take_names};
use super::record::{
    FORMAT, RecordFile, RecordRow, ShardHeader, ShardRecord, TakesCache, header_path, load_shard,
    parse_record_name, record_path, write_header, write_record, write_takes,
};
use super::table::{LIBRARY, LibraryError, SHARDS, SKIPPED};
use super::{Shard, collect::safe_relative};
use crate::CapturedReach;
use crate::anneal::Observer;
use crate::error::TrainError;
use crate::fit::{FitJob, NestedFit};
use crate::source::{ReachQuery, Skipped};
use crate::who::{PersonRule, TakeAt, Who};

mod warm;
use warm::{Group, ReadTake, ReadTakes, WarmError, WarmStarts};

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
    /// Who moves in each take ([`crate::who`]): each reach's person and motion in the
    /// record and `library.csv`; recorded among the settings.
    pub person: &'a PersonRule,
    /// Which share of the takes this run fits.
    pub shard: Shard,
    /// [Warm starts](crate::library#warm-starts): each group of reaches of one person, motion
    /// and arm is fitted from its first reach's fit, the model asked for alone; recorded
    /// among the settings.
    pub warm_start: bool,
    /// Keep the results already complete (recorded, with the same settings, for the take as
    /// it is now, the file as recorded) and fit only the rest.
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

/// What a shard will do, worked out before it starts ([`ShardRun::plan`]): the library's
/// takes and settings as its record will say them, the takes dealt to it, and (resuming)
/// the results found fitted.
#[derive(Debug)]
pub struct ShardPlan {
    /// Each take's identity, in the library's order.
    identities: Vec<TakeIdentity>,
    /// The run's settings.
    settings: Settings,
    /// The takes dealt to the shard (indices into the library's takes).
    mine: Vec<usize>,
    /// Results found fitted, by take and result name (resuming).
    fitted: HashMap<(String, String), RecordRow>,
    /// The rows of the takes found wholly fitted, for the new record from its start.
    carried: Vec<RecordRow>,
    /// The interrupt flag stopped the planning.
    interrupted: bool,
}

impl ShardPlan {
    /// How many takes are dealt to the shard.
    pub fn dealt(&self) -> usize {
        self.mine.len()
    }

    /// The run's settings.
    pub fn settings(&self) -> &Settings {
        &self.settings
    }
}

/// The shard's record, shared by the workers and written atomically now and then.
struct Record {
    path: PathBuf,
    rows: Mutex<RecordRows>,
    last_write: Mutex<Instant>,
}

/// A record's rows, each reach's and each skipped take's once (a take found fitted at the
/// start and again as it is done is recorded once).
#[derive(Default)]
struct RecordRows {
    rows: Vec<RecordRow>,
    at: HashMap<(String, String, String), usize>,
}

impl RecordRows {
    fn push(&mut self, row: RecordRow) {
        let key = match row.kind.as_str() {
            "reach" => ("reach".to_string(), String::new(), row.result.clone()),
            "skipped" => ("skipped".to_string(), row.clip.clone(), String::new()),
            _ => {
                self.rows.push(row);
                return;
            }
        };
        match self.at.get(&key) {
            Some(&i) => self.rows[i] = row,
            None => {
                self.at.insert(key, self.rows.len());
                self.rows.push(row);
            }
        }
    }
}

/// How often, at most, the record is rewritten while the shard runs (it is at its end).
const RECORD_EVERY_S: f64 = 5.0;

impl Record {
    fn write(&self) -> Result<(), LibraryError> {
        let rows = self
            .rows
            .lock()
            .map_err(|_| poisoned(&self.path))?
            .rows
            .clone();
        write_record(&self.path, &rows)
    }

    fn push(&self, rows: Vec<RecordRow>) -> Result<(), LibraryError> {
        {
            let mut all = self.rows.lock().map_err(|_| poisoned(&self.path))?;
            for row in rows {
                all.push(row);
            }
        }
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

/// What every take of a running shard shares: the plan, the record, the files no result may
/// be written over, where events go, and the warm starts (with them).
#[derive(Clone, Copy)]
struct Running<'r> {
    plan: &'r ShardPlan,
    record: &'r Record,
    inputs: &'r HashSet<PathBuf>,
    on_event: &'r (dyn Fn(ShardEvent<'_>) + Sync),
    warm: Option<&'r WarmStarts>,
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
    /// Works out the shard's run before it starts: every take's identity (each read and
    /// hashed once), the settings, the takes dealt to this shard and, resuming, the results
    /// found fitted. Refuses, before any work, a library whose other shards' records say
    /// they ran with other settings. An error here is about a take that cannot be read or
    /// the library's own files.
    pub fn plan(&self) -> Result<ShardPlan, LibraryError> {
        let root = &self.takes.common;
        let identities: Vec<Option<Result<TakeIdentity, LibraryError>>> = self
            .takes
            .paths
            .par_iter()
            .map(|take| {
                if self.interrupt.load(Ordering::SeqCst) {
                    return None;
                }
                Some(TakeIdentity::of(take, &relative_name(root, take)))
            })
            .collect();
        let settings = Settings::of(
            self.job,
            self.query,
            self.takes.segments().map(|s| s.path()),
        )?
        .with_person(self.person)
        .with_warm_start(self.warm_start);
        let mut plan = ShardPlan {
            identities: Vec::with_capacity(identities.len()),
            settings,
            mine: Vec::new(),
            fitted: HashMap::new(),
            carried: Vec::new(),
            interrupted: false,
        };
        for identity in identities {
            match identity {
                Some(identity) => plan.identities.push(identity?),
                None => {
                    plan.interrupted = true;
                    return Ok(plan);
                }
            }
        }
        self.check_persons(&plan.identities)?;
        let weights: Vec<u64> = plan.identities.iter().map(TakeIdentity::weight).collect();
        plan.mine = deal(&weights, self.shard.count)
            .into_iter()
            .enumerate()
            .filter(|(_, s)| *s == self.shard.index)
            .map(|(i, _)| i)
            .collect();
        self.check_folders(&plan.mine)?;
        let records = self.records();
        self.check_settings(&plan.settings, &records)?;
        if self.resume {
            self.found_fitted(&mut plan, &records);
        }
        Ok(plan)
    }

    /// Refuses, before any work, takes the person rule cannot name — a pattern that does
    /// not match them, a mapping file that does not list them, `segments` without a
    /// segments file — all of them in one error. (`auto` names every take; `segments` names
    /// every row of a segments file.)
    fn check_persons(&self, identities: &[TakeIdentity]) -> Result<(), LibraryError> {
        let listed = self.takes.segments().is_some();
        if matches!(self.person, PersonRule::Auto) || (listed && self.person.uses_segments()) {
            return Ok(());
        }
        let root = &self.takes.common;
        self.person.who_all(
            identities
                .iter()
                .map(|t| (TakeAt::new(root, Path::new(&t.path)), None)),
        )?;
        Ok(())
    }

    /// Refuses, before any work, a library folder where something is in the way of what the
    /// run writes: a file (or anything but a folder) where the `shards` folder or a folder
    /// of the results of one of the takes `mine` goes, or anything but a regular file where
    /// `library.csv` or `skipped.csv` goes.
    fn check_folders(&self, mine: &[usize]) -> Result<(), LibraryError> {
        let kind = |m: &std::fs::Metadata| match kinergy_io::describe_file_type(m) {
            "a regular file" => "a file",
            other => other,
        };
        let not_folder = |path: &Path| {
            std::fs::metadata(path)
                .ok()
                .filter(|m| !m.is_dir())
                .map(|m| kind(&m))
        };
        let in_the_way = |path: PathBuf, kind: &str, needed: String| LibraryError::Input {
            path,
            why: format!("{kind} where {needed}: move it away, or fit into another folder"),
        };
        let shards = self.dir.join(SHARDS);
        if let Some(kind) = not_folder(&shards) {
            return Err(in_the_way(
                shards,
                kind,
                "the folder of the shards' records is needed".into(),
            ));
        }
        for table in [LIBRARY, SKIPPED] {
            let path = self.dir.join(table);
            if let Ok(m) = std::fs::metadata(&path)
                && !m.is_file()
            {
                return Err(in_the_way(path, kind(&m), "the table is written".into()));
            }
        }
        let mut checked = HashSet::new();
        for &i in mine {
            let take = &self.takes.paths[i];
            let folder = result_folder(&relative_name(&self.takes.common, take));
            let mut path = self.dir.to_path_buf();
            for part in folder.components() {
                path.push(part);
                if !checked.insert(path.clone()) {
                    continue;
                }
                if let Some(kind) = not_folder(&path) {
                    return Err(in_the_way(
                        path,
                        kind,
                        format!("the folder of the results of {} is needed", take.display()),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The records of this library already in its folder that can be read (the others
    /// are `collect`'s to name).
    fn records(&self) -> Vec<ShardRecord> {
        let Ok(entries) = std::fs::read_dir(self.dir.join(SHARDS)) else {
            return Vec::new();
        };
        let mut cache = TakesCache::new();
        let mut records = Vec::new();
        for entry in entries.flatten() {
            let name = entry.file_name().to_string_lossy().into_owned();
            if let Some(Ok((i, n, RecordFile::Rows))) = parse_record_name(&name)
                && let Ok(Ok(record)) = load_shard(self.dir, i, n, &mut cache)
            {
                records.push(record);
            }
        }
        records.sort_by_key(|r| r.shard);
        records
    }

    /// Refuses settings other than those of the other shards of this sharding.
    fn check_settings(
        &self,
        settings: &Settings,
        records: &[ShardRecord],
    ) -> Result<(), LibraryError> {
        let other = records.iter().find(|r| {
            r.shard.1 == self.shard.count
                && r.shard.0 != self.shard.index
                && r.header.settings != *settings
        });
        let Some(other) = other else {
            return Ok(());
        };
        let differences = settings.differences(&other.header.settings, "this run");
        Err(LibraryError::Input {
            path: header_path(self.dir, other.shard.0, other.shard.1),
            why: format!(
                "shard {}/{} of this library ran with other settings: {}: run every shard with \
                 the same settings, or remove {} to fit the library anew",
                other.shard.0,
                other.shard.1,
                differences.join(", "),
                self.dir.join(SHARDS).display()
            ),
        })
    }

    /// The results the records say were fitted with these settings for the takes as they
    /// are now, each file as recorded; and the rows of the takes dealt to this shard whose
    /// every reach is among them.
    fn found_fitted(&self, plan: &mut ShardPlan, records: &[ShardRecord]) {
        let now: HashMap<&str, &TakeIdentity> = plan
            .identities
            .iter()
            .map(|t| (t.path.as_str(), t))
            .collect();
        let mut hashes: HashMap<String, Option<String>> = HashMap::new();
        // Each record's rows of each take, when every one of them holds.
        let mut whole: HashMap<&str, Vec<RecordRow>> = HashMap::new();
        // The person rule changes no result: a resume with another one fits nothing again
        // and names the persons anew — each take's as it is reached; those carried into the
        // record from its start now, where the takes' paths say them (a rule that reads a
        // segments file's persons says them only as each take is reached: until then they
        // are not carried).
        let from_paths = self.takes.segments().is_none() || !self.person.uses_segments();
        for record in records
            .iter()
            .filter(|r| r.header.settings.same_fits(&plan.settings))
        {
            let same_rule = record.header.settings.person() == plan.settings.person();
            let then: HashMap<&str, &TakeIdentity> =
                record.takes.iter().map(|t| (t.path.as_str(), t)).collect();
            let mut by_take: HashMap<&str, (bool, Vec<RecordRow>)> = HashMap::new();
            for row in record.rows.iter().filter(|r| r.kind == "reach") {
                let same_take = match (then.get(row.clip.as_str()), now.get(row.clip.as_str())) {
                    (Some(a), Some(b)) => a == b,
                    _ => false,
                };
                let hash = hashes.entry(row.result.clone()).or_insert_with(|| {
                    let path = self.dir.join(safe_relative(&row.result)?);
                    hash_file(&path).ok().map(|(_, h)| h)
                });
                let holds = same_take && hash.as_deref() == Some(row.blake3.as_str());
                let entry = by_take
                    .entry(row.clip.as_str())
                    .or_insert((true, Vec::new()));
                entry.0 &= holds;
                let mut found = RecordRow {
                    seconds: String::new(),
                    ..row.clone()
                };
                if !same_rule {
                    let at = TakeAt::new(&self.takes.common, Path::new(&row.clip));
                    match self.person.who(at, None) {
                        Ok(who) if from_paths => {
                            found.person = who.person;
                            found.motion = who.motion.unwrap_or_default();
                        }
                        _ => entry.0 = false,
                    }
                }
                if holds {
                    plan.fitted
                        .insert((row.clip.clone(), row.result.clone()), found.clone());
                }
                entry.1.push(found);
            }
            for (clip, (holds, rows)) in by_take {
                if holds {
                    whole.entry(clip).or_insert(rows);
                }
            }
        }
        for &i in &plan.mine {
            if let Some(rows) = whole.remove(plan.identities[i].path.as_str()) {
                plan.carried.extend(rows);
            }
        }
    }

    /// Runs the shard as `plan` says ([`plan`](Self::plan)): makes the folder and its
    /// `shards` folder, writes the record's header, takes list and first rows (the takes
    /// dealt, and those found fitted), fits the takes (each reach's result written as soon
    /// as it is fitted, each event told to `on_event`), and writes the record again at the
    /// end. A take that fails stops the others (its error is in the outcome); a failed or
    /// interrupted run that fitted nothing leaves the folder as it found it. An error here
    /// is about the library's own files (its folder or record could not be made or
    /// written).
    pub fn run(
        &self,
        plan: &ShardPlan,
        on_event: &(dyn Fn(ShardEvent<'_>) + Sync),
    ) -> Result<ShardOutcome, LibraryError> {
        let record_file = record_path(self.dir, self.shard.index, self.shard.count);
        if plan.interrupted {
            return Ok(ShardOutcome {
                dealt: plan.mine.len(),
                fitted: 0,
                skipped: Vec::new(),
                record: record_file,
                failed: None,
                interrupted: true,
            });
        }
        let made_dir = !self.dir.exists();
        let shards = self.dir.join(SHARDS);
        let made_shards = !shards.exists();
        let header_file = header_path(self.dir, self.shard.index, self.shard.count);
        let made_record = !record_file.exists() && !header_file.exists();
        kinergy_io::create_folder(self.dir).map_err(|e| LibraryError::Input {
            path: self.dir.to_path_buf(),
            why: format!("cannot create the folder: {e}"),
        })?;
        kinergy_io::create_folder(&shards).map_err(|e| LibraryError::Input {
            path: shards.clone(),
            why: format!("cannot create the folder of the shards' records: {e}"),
        })?;
        let (takes_name, takes_blake3) = write_takes(&shards, &plan.identities)?;
        let header = ShardHeader {
            kinergy_library: FORMAT,
            shard: [self.shard.index, self.shard.count],
            root: self.takes.common.display().to_string(),
            settings: plan.settings.clone(),
            takes: takes_name.clone(),
            takes_blake3,
            take_count: plan.identities.len(),
            folders: self
                .takes
                .folders
                .iter()
                .map(|f| f.display().to_string())
                .collect(),
        };
        let header_hash = write_header(&header_file, &header)?;
        let mut rows = RecordRows::default();
        rows.push(RecordRow::shard(
            &format!("{}-of-{}.json", self.shard.index, self.shard.count),
            &header_hash,
        ));
        for &i in &plan.mine {
            rows.push(RecordRow::take(&plan.identities[i].path));
        }
        for row in &plan.carried {
            rows.push(row.clone());
        }
        let record = Record {
            path: record_file,
            rows: Mutex::new(rows),
            last_write: Mutex::new(Instant::now()),
        };
        record.write()?;
        let inputs: HashSet<PathBuf> = self
            .inputs
            .iter()
            .filter_map(|p| std::fs::canonicalize(p).ok())
            .collect();
        let failed = AtomicBool::new(false);
        // With warm starts, the takes read and the groups' anchors fitted first; where that
        // fails, no take is fitted.
        let mut warm_failed = None;
        let (read, warm) = if self.warm_start {
            match self.warm_starts(plan) {
                Ok((read, warm)) => (read, Some(warm)),
                Err(e) => {
                    failed.store(true, Ordering::SeqCst);
                    warm_failed = Some(e);
                    (ReadTakes::new(), None)
                }
            }
        } else {
            (ReadTakes::new(), None)
        };
        let running = Running {
            plan,
            record: &record,
            inputs: &inputs,
            on_event,
            warm: warm.as_ref(),
        };
        let outcomes: Vec<Result<TakeOutcome, TakeError>> = plan
            .mine
            .par_iter()
            .map(|&i| {
                if failed.load(Ordering::SeqCst) || self.interrupt.load(Ordering::SeqCst) {
                    return Ok(TakeOutcome::Stopped);
                }
                let read = read.get(&i).and_then(|r| r.lock().ok()?.take());
                let outcome = self.take(i, &running, read);
                if outcome.is_err() {
                    failed.store(true, Ordering::SeqCst);
                }
                on_event(ShardEvent::TakeDone);
                outcome
            })
            .collect();
        let mut outcome = ShardOutcome {
            dealt: plan.mine.len(),
            fitted: 0,
            skipped: Vec::new(),
            record: record.path.clone(),
            failed: None,
            interrupted: false,
        };
        let mut library_error = None;
        for (&i, result) in plan.mine.iter().zip(outcomes) {
            match result {
                Ok(TakeOutcome::Fitted(rows)) => outcome.fitted += rows.len(),
                Ok(TakeOutcome::Skipped(skip)) => outcome.skipped.push(skip),
                Ok(TakeOutcome::Stopped) => {}
                Err(TakeError::Take(TrainError::Interrupted { .. })) => {}
                Err(TakeError::Take(e)) => {
                    outcome
                        .failed
                        .get_or_insert_with(|| (self.takes.paths[i].clone(), e));
                }
                Err(TakeError::Library(e)) => {
                    library_error.get_or_insert(e);
                }
            }
        }
        match warm_failed {
            Some(WarmError::Take(failure))
                if !matches!(failure.1, TrainError::Interrupted { .. }) =>
            {
                outcome.failed = Some(*failure);
            }
            Some(WarmError::Library(e)) => library_error = Some(e),
            Some(WarmError::Take(_)) | None => {}
        }
        outcome.interrupted = self.interrupt.load(Ordering::SeqCst);
        record.write()?;
        if let Some(e) = library_error {
            return Err(e);
        }
        if outcome.fitted == 0 && (outcome.failed.is_some() || outcome.interrupted) && made_record {
            // Nothing written but the record: a failed run leaves the folder as it found it
            // (best effort: the run's error is what gets reported). A record there before
            // stays, with the rows it carried.
            let _ = std::fs::remove_file(&record.path);
            let _ = std::fs::remove_file(&header_file);
            if made_shards {
                let _ = std::fs::remove_file(shards.join(&takes_name));
                let _ = std::fs::remove_dir(&shards);
            }
            if made_dir {
                let _ = std::fs::remove_dir(self.dir);
            }
        }
        Ok(outcome)
    }

    /// The record row of a reach found fitted (resuming: recorded with these settings, its
    /// result as recorded, the same frames and arm), named anew by `who`.
    fn found_fitted_reach(
        &self,
        plan: &ShardPlan,
        clip: &str,
        reach: &CapturedReach,
        who: &Who,
        name: &Path,
    ) -> Option<RecordRow> {
        if !self.resume {
            return None;
        }
        let done = plan.fitted.get(&(clip.to_string(), slash_path(name)))?;
        let fresh = RecordRow::reach(
            clip,
            reach,
            who.clone(),
            name,
            done.blake3.clone(),
            String::new(),
        );
        ((&fresh.onset, &fresh.end, &fresh.arm) == (&done.onset, &done.end, &done.arm))
            .then_some(fresh)
    }

    /// The result names of the reaches `found` in take `i`.
    fn names(&self, i: usize, found: &[(CapturedReach, Option<String>)]) -> Vec<PathBuf> {
        take_names(
            &self.takes.common,
            &self.takes.paths[i],
            found.iter().map(|(r, _)| r),
        )
    }

    /// The reaches of take `index`, each with the person a segments file lists for it (the
    /// takes with segments-file rows use their rows), or why it has none to fit.
    fn read_take(&self, index: usize) -> ReadTake {
        let take = self.takes.paths[index].as_path();
        Ok(match self.takes.rows_of(take) {
            Some((segments, rows)) => Ok(self
                .query
                .rows(segments, rows, take)?
                .into_iter()
                .map(|f| (f.reach, f.person))
                .collect()),
            None => self
                .query
                .take_at(take)?
                .map(|reaches| reaches.into_iter().map(|r| (r, None)).collect()),
        })
    }

    /// Fits the reaches of take `index` (or finds them fitted, resuming) and records them;
    /// `read` is the take already read ([`read_take`](Self::read_take)), if it was.
    fn take(
        &self,
        index: usize,
        run: &Running<'_>,
        read: Option<ReadTake>,
    ) -> Result<TakeOutcome, TakeError> {
        let Running {
            plan,
            record,
            inputs,
            on_event,
            warm,
        } = *run;
        let take = self.takes.paths[index].as_path();
        let clip = plan.identities[index].path.as_str();
        let read = match read {
            Some(read) => read,
            None => self.read_take(index),
        };
        let found = match read? {
            Ok(found) => found,
            Err(skip) => {
                record.push(vec![RecordRow::skipped(clip, &skip.why)])?;
                return Ok(TakeOutcome::Skipped(skip));
            }
        };
        let names = self.names(index, &found);
        if let Some(twice) = repeated(&names) {
            return Err(LibraryError::Input {
                path: take.to_path_buf(),
                why: format!(
                    "two of its reaches are one ({}): a segments file lists it twice?",
                    twice.display()
                ),
            }
            .into());
        }
        let mut rows = Vec::with_capacity(found.len());
        let at = TakeAt::new(&self.takes.common, Path::new(clip));
        for (j, ((reach, listed), name)) in found.into_iter().zip(names).enumerate() {
            let output = self.dir.join(&name);
            let who = self
                .person
                .who(at, listed.as_deref())
                .map_err(LibraryError::from)?;
            if let Some(done) = self.found_fitted_reach(plan, clip, &reach, &who, &name) {
                rows.push(done);
                continue;
            }
            if self.interrupt.load(Ordering::SeqCst) {
                return Ok(TakeOutcome::Stopped);
            }
            let clock = Instant::now();
            let group = std::slice::from_ref(&reach);
            let mut observer = (self.observer)();
            let anchor = warm.and_then(|w| w.anchor(&Group::of(&who, &reach)));
            // Seconds spent on this reach's fit before this take (its group's first reach's).
            let mut before = 0.0;
            let (fits, started_from) = match anchor {
                // The group's first reach: its fit, made before the takes.
                Some(anchor) if (anchor.take, anchor.reach) == (index, j) => {
                    before = anchor.seconds;
                    (anchor.fit.clone(), None)
                }
                Some(anchor) => (
                    self.job.run_from(
                        group,
                        anchor.start(),
                        &mut *observer,
                        Some(self.interrupt),
                    )?,
                    Some(anchor.result.clone()),
                ),
                None => (
                    self.job
                        .run_stoppable(group, &mut *observer, Some(self.interrupt))?,
                    None,
                ),
            };
            if let Some(parent) = output.parent() {
                kinergy_io::create_folder(parent).map_err(|e| LibraryError::Write {
                    path: parent.to_path_buf(),
                    why: format!("cannot create the folder of the results of {clip}: {e}"),
                })?;
            }
            self.check_not_input(&output, inputs)?;
            let mut file = fits.params_file(group, FitGrouping::Clip)?;
            if let Some(record) = file.fit.as_mut() {
                record.started_from = started_from;
            }
            file.write(&output).map_err(TrainError::from)?;
            let (_, blake3) = hash_file(&output).map_err(|e| LibraryError::Write {
                path: output.clone(),
                why: format!("cannot read the result back to record it: {e}"),
            })?;
            let seconds = before + clock.elapsed().as_secs_f64();
            on_event(ShardEvent::Fitted {
                output: &output,
                reach: &reach,
                fits: &fits,
            });
            rows.push(RecordRow::reach(
                clip,
                &reach,
                who,
                &name,
                blake3,
                format!("{seconds:.3}"),
            ));
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

/// A name `names` has twice, if any.
fn repeated(names: &[PathBuf]) -> Option<&PathBuf> {
    let mut seen = HashSet::new();
    names.iter().find(|n| !seen.insert(*n))
}
