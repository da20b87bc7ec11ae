//! A fitted library's tables: `library.csv` ([`LibraryRow`] per reach, read back as a
//! [`LibraryTable`], refused where it cannot be true) and `skipped.csv` ([`SkippedRow`] per
//! take with nothing to fit), and the library's errors.
//!
//! Layout of a library folder `DIR`: each reach's parameters file under its result name
//! (relative to `DIR`, see [`names`](super::names)), the shards' records in `DIR/shards`
//! (see [`record`](super::record)), `DIR/library.csv` and `DIR/skipped.csv`.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt;
use std::path::{Path, PathBuf};

use kinergy_solver::{Model, ParamsFile};
use serde::{Deserialize, Serialize};

use super::record::RecordRow;
use crate::experiment::Stats;
use crate::who::WhoError;

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
    #[error("{summary}the library in {} is not complete:\n  {}", dir.display(), listed(problems))]
    Incomplete {
        /// The library folder.
        dir: PathBuf,
        /// What was written (reaches and skipped takes).
        summary: String,
        /// Each thing missing, in words.
        problems: Vec<String>,
    },
    /// The library's files contradict each other or themselves — shards of other settings
    /// or other takes, results that are not the ones recorded, stray records — so no table
    /// is written: `problems` says what differs (bad input).
    #[error("the library in {} cannot be collected:\n  {}", dir.display(), listed(problems))]
    Refused {
        /// The library folder.
        dir: PathBuf,
        /// Each thing wrong, in words.
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
    /// The person rule could not say who moves in some takes (a pattern that does not
    /// match them, a mapping file that does not list them): bad input.
    #[error(transparent)]
    Person(#[from] WhoError),
}

impl kinergy_io::Classify for LibraryError {
    /// A missing or damaged file given is the input's fault; an incomplete library a task
    /// not done; a table not written a failed write.
    fn kind(&self) -> kinergy_io::ErrorKind {
        match self {
            LibraryError::Input { .. } | LibraryError::Refused { .. } | LibraryError::Person(_) => {
                kinergy_io::ErrorKind::Input
            }
            LibraryError::Incomplete { .. } => kinergy_io::ErrorKind::Task,
            LibraryError::Write { .. } => kinergy_io::ErrorKind::Io,
        }
    }
}

/// How many problems an error lists (the rest are counted).
const LISTED: usize = 20;

/// `problems`, one a line, at most [`LISTED`] of them.
fn listed(problems: &[String]) -> String {
    let mut out = problems
        .iter()
        .take(LISTED)
        .map(|p| kinergy_io::clip_text(p, 1000).into_owned())
        .collect::<Vec<_>>()
        .join("\n  ");
    if problems.len() > LISTED {
        out.push_str(&format!("\n  … and {} more", problems.len() - LISTED));
    }
    out
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
/// of each model its nested fit passed through. Written by [`collect`](super::collect), read by
/// [`LibraryTable::read`] (columns a library of an older version lacks read as empty).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LibraryRow {
    /// The take.
    pub clip: String,
    /// The reach's person (by the library's person rule, [`crate::who`]).
    pub person: String,
    /// The reach's motion, where the person rule or the take's name says it (empty
    /// otherwise, and in tables of older versions).
    #[serde(default)]
    pub motion: String,
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
    /// The fit's evaluations: every nested model's, summed (what the reach cost; a warm
    /// start's reach has one model).
    #[serde(default)]
    pub evaluations: usize,
    /// Seconds the fit took (empty when it was found already fitted).
    #[serde(default)]
    pub seconds: Option<f64>,
    /// The result file, relative to the library folder.
    #[serde(default)]
    pub result: String,
    /// The fingerprint of the settings the library was fitted with
    /// ([`Settings::fingerprint`](super::Settings::fingerprint); empty in tables of older
    /// versions): one value in a whole table.
    #[serde(default)]
    pub settings: String,
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

    /// The row of a record's reach, from its result file `path` (already checked to be the
    /// one recorded), fitted with the settings of fingerprint `settings`.
    pub fn of_record(path: &Path, row: &RecordRow, settings: &str) -> Result<LibraryRow, String> {
        let file = ParamsFile::read(path).map_err(|e| format!("result {}: {e}", path.display()))?;
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
        // A record's rows are checked as it is read (`read_record`); this names the result
        // should one reach here unchecked.
        let number = |column: &str, s: &str| {
            s.parse::<usize>().map_err(|_| {
                format!(
                    "result {}: its record's {column} `{}` is no frame (a whole number, 0 or \
                     more)",
                    path.display(),
                    kinergy_io::clip_text(s, 24)
                )
            })
        };
        let (onset, end) = (number("onset", &row.onset)?, number("end", &row.end)?);
        let mut out = LibraryRow {
            clip: row.clip.clone(),
            person: row.person.clone(),
            motion: row.motion.clone(),
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
            evaluations: record.nested.as_ref().map_or(record.evaluations, |stages| {
                stages.iter().map(|s| s.evaluations).sum()
            }),
            seconds: row.seconds.parse().ok(),
            result: row.result.clone(),
            settings: settings.to_string(),
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

/// A library's table: what [`collect`](super::collect) wrote, or what
/// [`LibraryTable::read`] read.
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
    /// Their reaches per motion, by name (empty when no reach's motion is known; reaches of
    /// no known motion, where others have one, under an empty name, last).
    pub motions: Vec<MotionLine>,
}

/// One motion's line of a library's summary: its reaches, of one person or of everyone.
#[derive(Debug, Clone, PartialEq)]
pub struct MotionLine {
    /// The motion (empty: reaches whose motion is not known).
    pub motion: String,
    /// The persons whose reaches these are.
    pub persons: usize,
    /// The reaches.
    pub reaches: usize,
    /// Their takes.
    pub takes: usize,
    /// Each model fitted on any of them: its distances, millimeters.
    pub models: Vec<(Model, Stats)>,
}

impl LibraryTable {
    /// Reads `library.csv` (the file, or a library folder holding it), refusing a table
    /// that cannot be true ([`LibraryTable::check`]).
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
        let header = reader
            .headers()
            .map_err(|e| input(format!("line 1: {e}")))?
            .clone();
        // Every table Kinergy wrote has the four papers' models' columns (S_E's came later):
        // one missing is a table edited by hand, whose rows would lose that model unsaid.
        for column in [
            "distance_sa_m",
            "distance_sb_m",
            "distance_sc_m",
            "distance_sd_m",
        ] {
            if !header.iter().any(|h| h == column) {
                return Err(input(format!(
                    "line 1: no column `{column}`: not a table Kinergy wrote (edited by hand?)"
                )));
            }
        }
        let mut rows = Vec::new();
        for (i, record) in reader.records().enumerate() {
            let record = record.map_err(|e| input(csv_error(&e, i + 2)))?;
            let line = record.position().map_or(i + 2, |p| p.line() as usize);
            let row: LibraryRow = record
                .deserialize(Some(&header))
                .map_err(|e| input(cell_error(&e, &header, &record, line)))?;
            rows.push(row);
        }
        let read = LibraryTable {
            rows,
            skipped: Vec::new(),
        };
        read.check().map_err(input)?;
        Ok(read)
    }

    /// Checks that the table can be true: every distance a number of meters from 0 to 1000,
    /// each row with at least one, and
    /// one model, optimizer and settings fingerprint in the whole table (a table of mixed
    /// settings compares unlike fits). Rows are numbered as lines
    /// of `library.csv` (the header is line 1).
    pub fn check(&self) -> Result<(), String> {
        /// The largest distance a row may hold, meters: a joint-position distance beyond a
        /// kilometre is no fit's (and a mean of such numbers overflows to ∞).
        const MAX_DISTANCE_M: f64 = 1e3;
        const COLUMNS: [&str; 5] = [
            "distance_sa_m",
            "distance_sb_m",
            "distance_sc_m",
            "distance_sd_m",
            "distance_se_m",
        ];
        let Some(first) = self.rows.first() else {
            return Ok(());
        };
        for (i, row) in self.rows.iter().enumerate() {
            let line = i + 2;
            for (value, column) in row.distances().iter().zip(COLUMNS) {
                if let Some(d) = value
                    && !(d.is_finite() && (0.0..=MAX_DISTANCE_M).contains(d))
                {
                    return Err(format!(
                        "row {line}, column {column}: {} is not a distance (meters from 0 to \
                         {MAX_DISTANCE_M})",
                        kinergy_io::quote_number(*d)
                    ));
                }
            }
            if row.distances().iter().all(Option::is_none) {
                return Err(format!(
                    "row {line}: every distance ({}) is empty: no fit to summarise",
                    COLUMNS.join(", ")
                ));
            }
            // A fit's own model always has its distance (a richer one's stages may not).
            if let Some(k) = ["sa", "sb", "sc", "sd", "se"]
                .iter()
                .position(|m| row.model.eq_ignore_ascii_case(m))
                && row.distances()[k].is_none()
            {
                return Err(format!(
                    "row {line}, column {}: empty in a row of model {}: the fit's own distance \
                     is missing (the row was edited or cut short)",
                    COLUMNS[k], row.model
                ));
            }
            let mixed = [
                ("model", &row.model, &first.model),
                ("optimizer", &row.optimizer, &first.optimizer),
                ("settings", &row.settings, &first.settings),
            ]
            .into_iter()
            .find(|(_, a, b)| a != b);
            if let Some((column, value, was)) = mixed {
                return Err(format!(
                    "row {line}, column {column}: `{}` where row 2 has `{}`: a table of \
                     mixed settings (collect refuses shards fitted with different settings; \
                     refit the library with one set)",
                    kinergy_io::clip_text(value, 40),
                    kinergy_io::clip_text(was, 40)
                ));
            }
        }
        Ok(())
    }

    /// The models any reach was fitted with, in [`Model::ALL`]'s order.
    pub fn models(&self) -> Vec<Model> {
        Model::ALL
            .into_iter()
            .filter(|&m| self.rows.iter().any(|r| r.distance(m).is_some()))
            .collect()
    }

    /// One line per person (by name), then `all`; each with its reaches per motion where
    /// motions are known (`all`'s: the library per motion).
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

/// A CSV error of row `line` of `library.csv`, in words: the row, and what is wrong.
fn csv_error(e: &csv::Error, line: usize) -> String {
    match e.kind() {
        csv::ErrorKind::UnequalLengths {
            pos,
            expected_len,
            len,
        } => format!(
            "row {}: {len} fields where the header has {expected_len}",
            pos.as_ref().map_or(line as u64, csv::Position::line)
        ),
        csv::ErrorKind::Utf8 { .. } => format!("row {line}: not UTF-8 text"),
        _ => format!("row {line}: {e}"),
    }
}

/// A cell of `library.csv` that cannot be read, in words: its row (as a line of the file)
/// and column, the value as written (shortened), and what it should be.
fn cell_error(
    e: &csv::Error,
    header: &csv::StringRecord,
    record: &csv::StringRecord,
    line: usize,
) -> String {
    let csv::ErrorKind::Deserialize { err, .. } = e.kind() else {
        return csv_error(e, line);
    };
    let Some(field) = err.field().and_then(|f| usize::try_from(f).ok()) else {
        return format!("row {line}: {}", err.kind());
    };
    let column = header.get(field).unwrap_or("?");
    let value = kinergy_io::clip_text(record.get(field).unwrap_or(""), 40);
    let should = match err.kind() {
        csv::DeserializeErrorKind::ParseFloat(_) => {
            "is not a number (a decimal such as 0.0123, or empty)".to_string()
        }
        csv::DeserializeErrorKind::ParseInt(_) => {
            "is not a whole number (0 or more, digits only)".to_string()
        }
        kind => format!("cannot be read: {kind}"),
    };
    format!("row {line}, column {column}: `{value}` {should}")
}

fn person_line(person: &str, rows: &[&LibraryRow]) -> PersonLine {
    let takes: BTreeSet<&str> = rows.iter().map(|r| r.clip.as_str()).collect();
    let mut motions: BTreeMap<&str, Vec<&LibraryRow>> = BTreeMap::new();
    if rows.iter().any(|r| !r.motion.is_empty()) {
        for row in rows {
            motions.entry(&row.motion).or_default().push(row);
        }
    }
    // The reaches of no known motion after the known ones.
    let (unknown, known): (Vec<_>, Vec<_>) = motions.into_iter().partition(|(m, _)| m.is_empty());
    PersonLine {
        person: person.to_string(),
        reaches: rows.len(),
        takes: takes.len(),
        models: model_stats(rows),
        motions: known
            .into_iter()
            .chain(unknown)
            .map(|(motion, rows)| MotionLine {
                motion: motion.to_string(),
                persons: rows
                    .iter()
                    .map(|r| &r.person)
                    .collect::<BTreeSet<_>>()
                    .len(),
                reaches: rows.len(),
                takes: rows.iter().map(|r| &r.clip).collect::<BTreeSet<_>>().len(),
                models: model_stats(&rows),
            })
            .collect(),
    }
}

/// Each model fitted on any of `rows`: its distances, millimeters.
fn model_stats(rows: &[&LibraryRow]) -> Vec<(Model, Stats)> {
    Model::ALL
        .into_iter()
        .filter_map(|m| {
            let stats = Stats::of(rows.iter().filter_map(|r| r.distance(m)).map(|d| d * 1e3))?;
            Some((m, stats))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(person: &str, clip: &str, sa: f64, sc: Option<f64>) -> LibraryRow {
        LibraryRow {
            clip: clip.into(),
            person: person.into(),
            motion: String::new(),
            arm: "right".into(),
            onset: 0,
            end: 10,
            frames: 10,
            model: "sa".into(),
            optimizer: "svd".into(),
            distance_sa_m: Some(sa),
            distance_sb_m: None,
            distance_sc_m: sc,
            distance_sd_m: None,
            distance_se_m: None,
            evaluations: 7,
            seconds: Some(0.5),
            result: format!("{clip}.json"),
            settings: "0123456789abcdef".into(),
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
        std::fs::write(
            &bad,
            "clip,person,distance_sa_m,distance_sb_m,distance_sc_m,distance_sd_m\na,p1,x,,,\n",
        )
        .unwrap();
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
    fn the_summary_is_per_motion_where_motions_are_known() {
        let with = |motion: &str, r: LibraryRow| LibraryRow {
            motion: motion.into(),
            ..r
        };
        let table = LibraryTable {
            rows: vec![
                with("bow", row("active", "a", 0.02, None)),
                with("bow", row("elderly", "b", 0.04, None)),
                with("raise", row("elderly", "c", 0.03, None)),
                row("elderly", "d", 0.05, None),
            ],
            skipped: vec![],
        };
        let lines = table.by_person();
        let all = lines.last().unwrap();
        let motions: Vec<(&str, usize, usize)> = all
            .motions
            .iter()
            .map(|m| (m.motion.as_str(), m.persons, m.reaches))
            .collect();
        // Known motions by name, then the reaches of none.
        assert_eq!(motions, [("bow", 2, 2), ("raise", 1, 1), ("", 1, 1)]);
        approx::assert_abs_diff_eq!(all.motions[0].models[0].1.mean, 30.0, epsilon = 1e-9);
        let active = &lines[0];
        assert_eq!(active.person, "active");
        assert_eq!(active.motions.len(), 1);
        // No motion known anywhere: no motion lines.
        let plain = LibraryTable {
            rows: vec![row("p1", "a", 0.02, None)],
            skipped: vec![],
        };
        assert!(plain.by_person().iter().all(|l| l.motions.is_empty()));
    }

    /// The sweep's tables that cannot be true, each refused naming its row and column.
    #[test]
    fn tables_that_cannot_be_true_are_refused_naming_the_row_and_column() {
        let good = || LibraryTable {
            rows: vec![row("p1", "a", 0.02, Some(0.01)), row("p1", "b", 0.04, None)],
            skipped: vec![],
        };
        assert_eq!(good().check(), Ok(()));
        type Spoil = dyn Fn(&mut LibraryRow);
        let cases: [(&Spoil, &str); 8] = [
            (
                &|r| r.distance_sa_m = Some(f64::NAN),
                "row 3, column distance_sa_m: NaN",
            ),
            (
                &|r| r.distance_sa_m = Some(f64::INFINITY),
                "row 3, column distance_sa_m: inf",
            ),
            (
                &|r| r.distance_sc_m = Some(f64::NEG_INFINITY),
                "row 3, column distance_sc_m: -inf",
            ),
            (
                &|r| r.distance_sa_m = Some(-0.001),
                "row 3, column distance_sa_m: -0.001",
            ),
            (&|r| r.set_distances([None; 5]), "row 3: every distance"),
            (
                &|r| r.model = "sc".into(),
                "row 3, column distance_sc_m: empty in a row of model sc",
            ),
            (
                &|r| {
                    r.model = "sb".into();
                    r.distance_sb_m = Some(0.03);
                },
                "row 3, column model: `sb` where row 2 has `sa`",
            ),
            (
                &|r| r.settings = "ffff".into(),
                "row 3, column settings: `ffff`",
            ),
        ];
        for (spoil, expected) in cases {
            let mut table = good();
            spoil(&mut table.rows[1]);
            let e = table.check().unwrap_err();
            assert!(e.starts_with(expected), "{expected}: {e}");
        }
        // Through the file, as `compare --library` reads it: NaN and -inf as the CSV spells
        // them, and a table with every distance empty; and the sweep's cells that are no
        // number (`abc`, `1_0`, ` 0.05`, `0x10`), once "CSV deserialize error… field 8".
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join(LIBRARY);
        let header = "clip,person,distance_sa_m,distance_sb_m,distance_sc_m,distance_sd_m";
        for (body, expected) in [
            ("a,p1,NaN,,,", "row 2, column distance_sa_m: NaN"),
            ("a,p1,0.02,-inf,,", "row 2, column distance_sb_m: -inf"),
            ("a,p1,,,,\nb,p1,,,,", "row 2: every distance"),
            (
                "a,p1,0.02,,,\nb,p1,abc,,,",
                "row 3, column distance_sa_m: `abc` is not a number",
            ),
            (
                "a,p1,0.02,1_0,,",
                "row 2, column distance_sb_m: `1_0` is not a number",
            ),
            (
                "a,p1,0.02,,,\nb,p1,0.02,, 0.05,",
                "row 3, column distance_sc_m: ` 0.05` is not a number",
            ),
            (
                "a,p1,0.02,,,0x10",
                "row 2, column distance_sd_m: `0x10` is not a number",
            ),
            ("a,p1,0.02,,", "row 2: 5 fields where the header has 6"),
        ] {
            std::fs::write(&path, format!("{header}\n{body}\n")).unwrap();
            let e = LibraryTable::read(&path).unwrap_err();
            assert!(kinergy_io::Classify::kind(&e).is_input(), "{e}");
            assert!(e.to_string().contains(expected), "{expected}: {e}");
        }
        // A paper's model's column missing (the sweep's `missing-column`): refused by name.
        for column in ["distance_sa_m", "distance_sd_m"] {
            let short = header.replace(&format!(",{column}"), "");
            let body = "a,p1,0.02,0.02,0.02";
            std::fs::write(&path, format!("{short}\n{body}\n")).unwrap();
            let expected = format!("line 1: no column `{column}`");
            let e = LibraryTable::read(&path).unwrap_err();
            assert!(kinergy_io::Classify::kind(&e).is_input(), "{e}");
            assert!(e.to_string().contains(&expected), "{expected}: {e}");
        }
    }
}
