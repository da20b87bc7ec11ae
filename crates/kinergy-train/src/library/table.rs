//! A fitted library's files: the shards' records, `library.csv` and `skipped.csv`, and
//! [`collect`], which checks the records against the result files and writes the tables.
//!
//! Layout of a library folder `DIR`: each reach's parameters file under its result name
//! (relative to `DIR`), `DIR/shards/I-of-N.csv` (what shard I of N was dealt and did: a
//! [`RecordRow`] per take dealt, then per reach fitted and per take skipped or failed),
//! `DIR/library.csv` (a [`LibraryRow`] per reach) and `DIR/skipped.csv` (a [`SkippedRow`]
//! per take with nothing to fit).

use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::path::{Path, PathBuf};

use kinergy_solver::{Model, ParamsFile};
use serde::{Deserialize, Serialize};

use crate::CapturedReach;
use crate::experiment::Stats;

/// The folder, inside a library folder, of the shards' records.
pub const SHARDS: &str = "shards";
/// One row per reach fitted: the library's results as a table.
pub const LIBRARY: &str = "library.csv";
/// One row per take skipped, with the reason.
pub const SKIPPED: &str = "skipped.csv";

/// Why a library's files could not be read, checked or written.
#[derive(Debug, thiserror::Error)]
pub enum LibraryError {
    /// A file or folder read as input is missing, unreadable or not what it should be
    /// (bad input).
    #[error("{}", naming(path, why))]
    Input {
        /// The file or folder.
        path: PathBuf,
        /// What is wrong.
        why: String,
    },
    /// The library is not complete: `summary` says what was tabled, `problems` what is
    /// missing and why (a task that is not done).
    #[error("{summary}the library in {} is not complete:\n  {}", dir.display(), problems.join("\n  "))]
    Incomplete {
        /// The library folder.
        dir: PathBuf,
        /// What was written (reaches and skipped takes).
        summary: String,
        /// Each thing missing, in words.
        problems: Vec<String>,
    },
    /// A table could not be written.
    #[error("{}", naming(path, why))]
    Write {
        /// The file.
        path: PathBuf,
        /// What went wrong.
        why: String,
    },
}

impl kinergy_io::Classify for LibraryError {
    /// A missing or damaged file given is the input's fault; an incomplete library a task
    /// not done; a table not written a failed write.
    fn kind(&self) -> kinergy_io::ErrorKind {
        match self {
            LibraryError::Input { .. } => kinergy_io::ErrorKind::Input,
            LibraryError::Incomplete { .. } => kinergy_io::ErrorKind::Task,
            LibraryError::Write { .. } => kinergy_io::ErrorKind::Io,
        }
    }
}

/// `why` naming `path` once (messages about files that already name them stay as they are).
fn naming(path: &Path, why: impl fmt::Display) -> String {
    let text = why.to_string();
    if text.contains(&*path.to_string_lossy()) {
        text
    } else {
        format!("{}: {text}", path.display())
    }
}

/// One line of a shard's record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecordRow {
    /// `take` (dealt to the shard), `reach` (fitted or found fitted), `skipped` (nothing to
    /// fit) or `failed` (the take could not be fitted).
    pub kind: String,
    /// The take, as the library's paths spell it.
    pub clip: String,
    /// The reach's person.
    pub person: String,
    /// The reach's arm side.
    pub arm: String,
    /// The reach's first frame.
    pub onset: String,
    /// The reach's end frame (excluded).
    pub end: String,
    /// The result file, relative to the library folder.
    pub result: String,
    /// Seconds the reach's fit took (empty when it was found already fitted).
    pub seconds: String,
    /// Why a take was skipped or failed.
    pub why: String,
}

impl RecordRow {
    /// The row saying take `clip` was dealt to the shard.
    pub fn take(clip: &Path) -> RecordRow {
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

    /// The row saying take `clip` was skipped, and why.
    pub fn skipped(clip: &Path, why: &str) -> RecordRow {
        RecordRow {
            kind: "skipped".into(),
            why: why.to_string(),
            ..RecordRow::take(clip)
        }
    }

    /// The row of `reach` of take `clip`, by `person`, its result under `result` (relative
    /// to the library folder); `seconds` empty when it was found already fitted.
    pub fn reach(
        clip: &Path,
        reach: &CapturedReach,
        person: String,
        result: &Path,
        seconds: String,
    ) -> RecordRow {
        RecordRow {
            kind: "reach".into(),
            person,
            arm: reach
                .fitted_arm()
                .side
                .map_or_else(String::new, |s| s.to_string()),
            onset: reach.frames().start.to_string(),
            end: reach.frames().end.to_string(),
            result: result.display().to_string(),
            seconds,
            ..RecordRow::take(clip)
        }
    }
}

/// A shard's record file, `I-of-N.csv`, in the `shards` folder of `dir`.
pub fn record_path(dir: &Path, index: usize, count: usize) -> PathBuf {
    dir.join(SHARDS).join(format!("{index}-of-{count}.csv"))
}

/// Reads a shard's record.
pub fn read_record(path: &Path) -> Result<Vec<RecordRow>, LibraryError> {
    let text =
        kinergy_io::read_to_string_limited(path, 1 << 30).map_err(|e| LibraryError::Input {
            path: path.to_path_buf(),
            why: e.to_string(),
        })?;
    let mut reader = csv::Reader::from_reader(text.as_bytes());
    reader
        .deserialize()
        .collect::<Result<Vec<RecordRow>, _>>()
        .map_err(|e| LibraryError::Input {
            path: path.to_path_buf(),
            why: format!("not a shard record: {e}"),
        })
}

/// Writes `rows` as CSV to `path`, atomically.
pub fn write_csv<T: Serialize>(
    path: &Path,
    rows: impl IntoIterator<Item = T>,
) -> Result<(), LibraryError> {
    let failed = |why: String| LibraryError::Write {
        path: path.to_path_buf(),
        why,
    };
    let mut w = csv::Writer::from_writer(Vec::new());
    for row in rows {
        w.serialize(row).map_err(|e| failed(e.to_string()))?;
    }
    let bytes = w.into_inner().map_err(|e| failed(e.to_string()))?;
    kinergy_io::write_atomic(path, &bytes).map_err(|e| failed(e.to_string()))
}

/// One row of `library.csv`: a reach, its fit's model and optimizer, and the motion distance
/// of each model its nested fit passed through. Written by [`collect`], read by
/// [`LibraryTable::read`] (columns a library of an older version lacks read as empty).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LibraryRow {
    /// The take.
    pub clip: String,
    /// The reach's person.
    pub person: String,
    /// The reach's arm side.
    #[serde(default)]
    pub arm: String,
    /// The reach's first frame.
    #[serde(default)]
    pub onset: usize,
    /// The reach's end frame (excluded).
    #[serde(default)]
    pub end: usize,
    /// Its frame count.
    #[serde(default)]
    pub frames: usize,
    /// The richest model fitted.
    #[serde(default)]
    pub model: String,
    /// The IK optimizer.
    #[serde(default)]
    pub optimizer: String,
    /// S_A's distance, meters (its stage of the nested fit).
    pub distance_sa_m: Option<f64>,
    /// S_B's.
    pub distance_sb_m: Option<f64>,
    /// S_C's.
    pub distance_sc_m: Option<f64>,
    /// S_D's.
    pub distance_sd_m: Option<f64>,
    /// S_E's (absent from libraries written before S_E).
    #[serde(default)]
    pub distance_se_m: Option<f64>,
    /// The fit's evaluations.
    #[serde(default)]
    pub evaluations: usize,
    /// Seconds the fit took (empty when it was found already fitted).
    #[serde(default)]
    pub seconds: Option<f64>,
    /// The result file, relative to the library folder.
    #[serde(default)]
    pub result: String,
}

impl LibraryRow {
    /// The distance of `model`, meters, where its stage was fitted.
    pub fn distance(&self, model: Model) -> Option<f64> {
        self.distances()[model_index(model)]
    }

    /// Every model's distance, in [`Model::ALL`]'s order.
    pub fn distances(&self) -> [Option<f64>; 5] {
        [
            self.distance_sa_m,
            self.distance_sb_m,
            self.distance_sc_m,
            self.distance_sd_m,
            self.distance_se_m,
        ]
    }

    /// Sets every model's distance, in [`Model::ALL`]'s order.
    pub fn set_distances(&mut self, [sa, sb, sc, sd, se]: [Option<f64>; 5]) {
        self.distance_sa_m = sa;
        self.distance_sb_m = sb;
        self.distance_sc_m = sc;
        self.distance_sd_m = sd;
        self.distance_se_m = se;
    }

    /// The row of a record's reach, from its result file in `dir`.
    pub fn of_record(dir: &Path, row: &RecordRow) -> Result<LibraryRow, String> {
        let path = dir.join(&row.result);
        let file =
            ParamsFile::read(&path).map_err(|e| format!("result {}: {e}", path.display()))?;
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
        let number = |s: &str| s.parse::<usize>().map_err(|_| format!("frame `{s}`"));
        let (onset, end) = (number(&row.onset)?, number(&row.end)?);
        let mut out = LibraryRow {
            clip: row.clip.clone(),
            person: row.person.clone(),
            arm: row.arm.clone(),
            onset,
            end,
            frames: end.saturating_sub(onset),
            model: file.model.name().to_string(),
            optimizer: file.optimizer.kind().name().to_string(),
            distance_sa_m: None,
            distance_sb_m: None,
            distance_sc_m: None,
            distance_sd_m: None,
            distance_se_m: None,
            evaluations: record.evaluations,
            seconds: row.seconds.parse().ok(),
            result: row.result.clone(),
        };
        out.set_distances(Model::ALL.map(distance));
        Ok(out)
    }
}

fn model_index(model: Model) -> usize {
    Model::ALL
        .iter()
        .position(|&m| m == model)
        .unwrap_or_default()
}

/// One row of `skipped.csv`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkippedRow {
    /// The take.
    pub clip: String,
    /// Why nothing of it was fitted.
    pub why: String,
}

/// Whether `path` holds a complete result for `reach` fitted up to `model`: a parameters
/// file that reads, of that model, recording this reach's clip, frames and arm.
pub fn is_complete(path: &Path, reach: &CapturedReach, model: Model) -> bool {
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

/// A library's table: what [`collect`] wrote, or what [`LibraryTable::read`] read.
#[derive(Debug, Clone, PartialEq)]
pub struct LibraryTable {
    /// One row per reach, by clip, onset and arm.
    pub rows: Vec<LibraryRow>,
    /// The takes skipped, by clip (empty when read from `library.csv` alone).
    pub skipped: Vec<SkippedRow>,
}

/// One person's (or everyone's) line of a library's summary.
#[derive(Debug, Clone, PartialEq)]
pub struct PersonLine {
    /// The person (`all` for the whole library).
    pub person: String,
    /// Their reaches.
    pub reaches: usize,
    /// Their takes.
    pub takes: usize,
    /// Each model fitted on any of their reaches: its distances, millimeters.
    pub models: Vec<(Model, Stats)>,
}

impl LibraryTable {
    /// Reads `library.csv` (the file, or a library folder holding it).
    pub fn read(path: &Path) -> Result<LibraryTable, LibraryError> {
        let table = if path.is_dir() {
            path.join(LIBRARY)
        } else {
            path.to_path_buf()
        };
        let input = |why: String| LibraryError::Input {
            path: table.clone(),
            why,
        };
        let text = kinergy_io::read_to_string_limited(&table, 1 << 30)
            .map_err(|e| input(e.to_string()))?;
        let mut reader = csv::Reader::from_reader(text.as_bytes());
        let rows = reader
            .deserialize()
            .enumerate()
            .map(|(i, r)| r.map_err(|e| input(format!("row {}: {e}", i + 2))))
            .collect::<Result<Vec<LibraryRow>, LibraryError>>()?;
        Ok(LibraryTable {
            rows,
            skipped: Vec::new(),
        })
    }

    /// The models any reach was fitted with, in [`Model::ALL`]'s order.
    pub fn models(&self) -> Vec<Model> {
        Model::ALL
            .into_iter()
            .filter(|&m| self.rows.iter().any(|r| r.distance(m).is_some()))
            .collect()
    }

    /// One line per person (by name), then `all`.
    pub fn by_person(&self) -> Vec<PersonLine> {
        let mut persons: BTreeMap<&str, Vec<&LibraryRow>> = BTreeMap::new();
        for row in &self.rows {
            persons.entry(&row.person).or_default().push(row);
        }
        let mut lines: Vec<PersonLine> = persons
            .iter()
            .map(|(person, rows)| person_line(person, rows))
            .collect();
        lines.push(person_line("all", &self.rows.iter().collect::<Vec<_>>()));
        lines
    }
}

fn person_line(person: &str, rows: &[&LibraryRow]) -> PersonLine {
    let takes: BTreeSet<&str> = rows.iter().map(|r| r.clip.as_str()).collect();
    PersonLine {
        person: person.to_string(),
        reaches: rows.len(),
        takes: takes.len(),
        models: Model::ALL
            .into_iter()
            .filter_map(|m| {
                let stats = Stats::of(rows.iter().filter_map(|r| r.distance(m)).map(|d| d * 1e3))?;
                Some((m, stats))
            })
            .collect(),
    }
}

/// What [`collect`] found and wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Collected {
    /// The tables written.
    pub table: LibraryTable,
    /// The summary in words (reaches, skipped takes, the files).
    pub text: String,
}

/// Reads the shards' records in `dir`, checks that every take dealt was fitted or skipped
/// and every result is there and complete, and writes `library.csv` (one row per reach, by
/// clip, frames and arm) and `skipped.csv`. Idempotent. Incomplete — a shard without a
/// record, takes no shard finished, results missing or damaged, takes that failed — it
/// still writes what is there, then fails ([`LibraryError::Incomplete`]) naming what is
/// missing and why.
pub fn collect(dir: &Path) -> Result<Collected, LibraryError> {
    let shards = dir.join(SHARDS);
    let entries = std::fs::read_dir(&shards).map_err(|e| LibraryError::Input {
        path: shards.clone(),
        why: format!("no shard records here ({e}): is this a `fit --out-dir` folder?"),
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
        return Err(LibraryError::Input {
            path: shards.clone(),
            why: format!(
                "{}: no shard record (I-of-N.csv): nothing was fitted into {} yet",
                shards.display(),
                dir.display()
            ),
        });
    };
    let mut problems = Vec::new();
    let counts: BTreeSet<usize> = records.keys().map(|(_, n)| *n).collect();
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
    let mut skipped: Vec<SkippedRow> = Vec::new();
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
                    skipped.push(SkippedRow {
                        clip: row.clip.clone(),
                        why: row.why.clone(),
                    });
                }
                "reach" => {
                    done.insert(&row.clip, true);
                    match LibraryRow::of_record(dir, row) {
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
    skipped.sort_by(|a, b| (&a.clip, &a.why).cmp(&(&b.clip, &b.why)));
    write_csv(&dir.join(LIBRARY), &library)?;
    write_csv(&dir.join(SKIPPED), &skipped)?;
    let text = format!(
        "{} reaches in {}; {} takes skipped, listed in {}\n",
        library.len(),
        dir.join(LIBRARY).display(),
        skipped.len(),
        dir.join(SKIPPED).display()
    );
    if !problems.is_empty() {
        return Err(LibraryError::Incomplete {
            dir: dir.to_path_buf(),
            summary: text,
            problems,
        });
    }
    Ok(Collected {
        table: LibraryTable {
            rows: library,
            skipped,
        },
        text,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(person: &str, clip: &str, sa: f64, sc: Option<f64>) -> LibraryRow {
        LibraryRow {
            clip: clip.into(),
            person: person.into(),
            arm: "right".into(),
            onset: 0,
            end: 10,
            frames: 10,
            model: "sc".into(),
            optimizer: "svd".into(),
            distance_sa_m: Some(sa),
            distance_sb_m: None,
            distance_sc_m: sc,
            distance_sd_m: None,
            distance_se_m: None,
            evaluations: 7,
            seconds: Some(0.5),
            result: format!("{clip}.json"),
        }
    }

    #[test]
    fn library_rows_round_trip_through_the_csv_and_old_tables_read() {
        let dir = std::env::temp_dir().join(format!("kinergy-library-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let table = LibraryTable {
            rows: vec![
                row("p1", "a", 0.02, Some(0.01)),
                row("p1", "b", 0.04, None),
                row("p2", "c", 0.03, Some(0.02)),
            ],
            skipped: vec![],
        };
        write_csv(&dir.join(LIBRARY), &table.rows).unwrap();
        assert_eq!(LibraryTable::read(&dir).unwrap(), table);
        // A table of an older version: no S_E column, and only the columns a summary reads.
        let old = dir.join("old.csv");
        std::fs::write(
            &old,
            "clip,person,distance_sa_m,distance_sb_m,distance_sc_m,distance_sd_m\na,p1,0.02,,,\n",
        )
        .unwrap();
        let read = LibraryTable::read(&old).unwrap();
        assert_eq!(read.rows[0].distance(Model::Sa), Some(0.02));
        assert_eq!(read.rows[0].distance(Model::Se), None);
        let bad = dir.join("bad.csv");
        std::fs::write(&bad, "clip,person,distance_sa_m\na,p1,x\n").unwrap();
        let e = LibraryTable::read(&bad).unwrap_err();
        assert!(
            kinergy_io::Classify::kind(&e).is_input() && e.to_string().contains("row 2"),
            "{e}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn the_summary_is_per_person_then_all_in_millimeters() {
        let table = LibraryTable {
            rows: vec![
                row("p1", "a", 0.02, Some(0.01)),
                row("p1", "a", 0.04, None),
                row("p2", "c", 0.03, Some(0.02)),
            ],
            skipped: vec![],
        };
        assert_eq!(table.models(), vec![Model::Sa, Model::Sc]);
        let lines = table.by_person();
        let names: Vec<&str> = lines.iter().map(|l| l.person.as_str()).collect();
        assert_eq!(names, ["p1", "p2", "all"]);
        assert_eq!((lines[0].reaches, lines[0].takes), (2, 1));
        let (model, sa) = &lines[2].models[0];
        assert_eq!(*model, Model::Sa);
        approx::assert_abs_diff_eq!(sa.mean, 30.0, epsilon = 1e-9);
        assert_eq!(lines[0].models[1].1.count, 1);
    }

    #[test]
    fn collect_names_a_folder_that_is_not_a_library() {
        let e = collect(Path::new("/nonexistent/kinergy-library")).unwrap_err();
        assert!(kinergy_io::Classify::kind(&e).is_input(), "{e}");
        assert!(
            e.to_string().contains("is this a `fit --out-dir` folder?"),
            "{e}"
        );
    }
}
