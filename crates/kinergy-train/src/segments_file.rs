//! The segments file: which frames of which captures are a person's segments, one row per
//! segment, written by `kinergy segment CLIPS --manifest segments.csv`, edited by hand, read
//! by the commands that fit.
//!
//! CSV with a header naming the columns, in any order:
//!
//! | column | required | content |
//! |---|---|---|
//! | `clip` | yes | the capture: a path relative to the segments file's folder, or absolute (written relative when the two share a folder) |
//! | `onset`, `end` | yes | the frames `onset..end`: numbered from 0, end excluded — the convention of "Frames" in [`kinergy_motion::segment`], the `A..B` of `--frames` |
//! | `arm` | yes | `right` or `left` |
//! | `label` | no (`reach`) | `reach`, `return` or `other` |
//! | `person` | no (the performer the clip's file name gives — Bandai's STYLE, CMU's subject — else its folder's name: [`default_person`]) | who moves |
//! | `target_x`, `target_y`, `target_z` | no (all three or none) | the reach's target, world meters in the clip's frame (as imported, Y up): where the hand was aimed, when it is known and is not where the segment's last frame has it (a reach handed over before it arrived, a target a lab recorded); empty cells for a row without one. A fit aims there instead of at the hand's last position |
//! | `peak_speed_m_s`, `duration_s` | no (both or none) | the tempo the motion's smooth controller was bounded by (the peak hand speed relative to the shoulder, m/s, and the duration, s, of [`kinergy_solver::Smoothing::for_reach`]), when the segment was made by a known controller (`kinergy synth --params` writes them); empty cells for a row without one. A fit then bounds the synthesis by exactly this tempo instead of the capture's own or the person's law |
//!
//! One row per line (a field may be quoted, `"a, b"`, but not span lines); lines starting
//! with `#` are comments; blank lines and spaces around fields are ignored.
//! [`SegmentsFile::read`] checks everything it can without reading the captures — the columns,
//! that each clip exists, the numbers, the arm and the label, no row twice — and
//! [`SegmentsFile::resolve`] checks a row's frames against its clip once that is read. Every error
//! names the file and, for a row, its line.
//!
//! ```
//! use kinergy_train::segments_file::SegmentsFile;
//!
//! let dir = tempfile::tempdir()?;
//! std::fs::write(dir.path().join("take1.bvh"), "")?; // the file must exist
//! let path = dir.path().join("segments.csv");
//! std::fs::write(&path, "# mine\nclip,onset,end,arm\ntake1.bvh,3,40,left\n")?;
//! let file = SegmentsFile::read(&path)?;
//! let row = &file.rows()[0];
//! assert_eq!((row.frames.clone(), row.line), (3..40, Some(3)));
//! assert_eq!(row.label.as_str(), "reach");
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::collections::HashMap;
use std::fmt;
use std::ops::Range;
use std::path::{Component, Path, PathBuf};

use kinergy_motion::{Clip, Side};

use kinergy_motion::segment::Label;

/// One row: a segment of one clip.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentRow {
    /// The capture, as found on disk (relative paths joined to the segments file's folder).
    pub clip: PathBuf,
    /// The segment's frames, `onset..end`, end excluded.
    pub frames: Range<usize>,
    /// Which arm.
    pub arm: Side,
    /// Reach, return or other.
    pub label: Label,
    /// Who moves.
    pub person: String,
    /// The reach's target, world meters in the clip's frame, when the file gives it.
    pub target: Option<[f64; 3]>,
    /// The tempo the segment's smooth controller was bounded by, when the file gives it.
    pub tempo: Option<RowTempo>,
    /// The line of the segments file the row was read from (1-based), if it was read.
    pub line: Option<usize>,
}

impl SegmentRow {
    /// A row for `clip` whose person is the one its name or folder gives ([`default_person`]).
    pub fn new(clip: impl Into<PathBuf>, frames: Range<usize>, arm: Side, label: Label) -> Self {
        let clip = clip.into();
        SegmentRow {
            person: default_person(&clip),
            clip,
            frames,
            arm,
            label,
            target: None,
            tempo: None,
            line: None,
        }
    }

    /// The same row with the tempo its smooth controller was bounded by.
    pub fn with_tempo(self, tempo: RowTempo) -> Self {
        SegmentRow {
            tempo: Some(tempo),
            ..self
        }
    }

    /// The same row with the reach's target (world meters in the clip's frame).
    pub fn with_target(self, target: [f64; 3]) -> Self {
        SegmentRow {
            target: Some(target),
            ..self
        }
    }
}

/// The tempo a segment's smooth controller was bounded by (the `peak_speed_m_s` and
/// `duration_s` columns): the reach [`kinergy_solver::Smoothing::for_reach`] made its bounds
/// for.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RowTempo {
    /// The hand's peak speed relative to the shoulder, m/s (positive).
    pub peak_speed_m_s: f64,
    /// The reach's duration, seconds (positive).
    pub duration_s: f64,
}

/// What went wrong with a segments file: the file, the line when a row is at fault, and what.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SegmentsFileError {
    /// The segments file.
    pub path: PathBuf,
    /// The line (1-based), when the error is about one.
    pub line: Option<usize>,
    /// What is wrong.
    pub why: String,
}

impl fmt::Display for SegmentsFileError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{} line {line}: {}", self.path.display(), self.why),
            None => write!(f, "{}: {}", self.path.display(), self.why),
        }
    }
}

impl std::error::Error for SegmentsFileError {}

impl From<SegmentsFileError> for crate::TrainError {
    fn from(e: SegmentsFileError) -> crate::TrainError {
        crate::TrainError::Segments {
            path: e.path,
            line: e.line,
            why: e.why,
        }
    }
}

/// A segments file: its path and its rows, in file order.
#[derive(Debug, Clone, PartialEq)]
pub struct SegmentsFile {
    path: PathBuf,
    rows: Vec<SegmentRow>,
}

const COLUMNS: [&str; 11] = [
    "clip",
    "onset",
    "end",
    "arm",
    "label",
    "person",
    "target_x",
    "target_y",
    "target_z",
    "peak_speed_m_s",
    "duration_s",
];

/// The target's columns.
const TARGET: [&str; 3] = ["target_x", "target_y", "target_z"];

/// The tempo's columns.
const TEMPO: [&str; 2] = ["peak_speed_m_s", "duration_s"];

impl SegmentsFile {
    /// A segments file to be written at `path`.
    pub fn new(path: impl Into<PathBuf>, rows: Vec<SegmentRow>) -> SegmentsFile {
        SegmentsFile {
            path: path.into(),
            rows,
        }
    }

    /// The file's path.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The rows, in file order.
    pub fn rows(&self) -> &[SegmentRow] {
        &self.rows
    }

    /// The rows of each clip, by the clip's file (its canonical path): each row's clip
    /// looked up once, so that a library of takes finds its rows in linear time.
    pub fn rows_by_clip(&self) -> HashMap<PathBuf, Vec<&SegmentRow>> {
        let mut index: HashMap<PathBuf, Vec<&SegmentRow>> = HashMap::new();
        for row in &self.rows {
            index.entry(file_key(&row.clip)).or_default().push(row);
        }
        index
    }

    /// The key [`rows_by_clip`](Self::rows_by_clip) finds `clip`'s rows under.
    pub fn clip_key(clip: &Path) -> PathBuf {
        file_key(clip)
    }

    /// The rows of one clip (compared as files on disk), in file order.
    pub fn rows_for<'a>(&'a self, clip: &Path) -> impl Iterator<Item = &'a SegmentRow> + 'a {
        let key = file_key(clip);
        self.rows.iter().filter(move |r| file_key(&r.clip) == key)
    }

    /// Reads and checks the segments file at `path` (see the [module docs](self)).
    pub fn read(path: &Path) -> Result<SegmentsFile, SegmentsFileError> {
        let text =
            kinergy_io::read_to_string_limited(path, kinergy_io::MAX_JSON_BYTES).map_err(|e| {
                SegmentsFileError {
                    path: path.to_path_buf(),
                    line: None,
                    why: e.to_string(),
                }
            })?;
        SegmentsFile::parse(&text, path)
    }

    /// Reads and checks segments-file `text` as if it were the file at `path` (clips are found
    /// relative to its folder; errors name it).
    pub fn parse(text: &str, path: &Path) -> Result<SegmentsFile, SegmentsFileError> {
        let fail = |line: Option<usize>, why: String| SegmentsFileError {
            path: path.to_path_buf(),
            line,
            why,
        };
        let folder = path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        // The csv crate splits the records (quotes, doubled quotes, a quoted line break in a
        // clip's name) and says where each one starts; lines ended by CR LF or CR alone are
        // read as lines ended by LF. Comment lines (`#` first, after any spaces, not in
        // quotes) and blank lines are skipped.
        let text = text.replace("\r\n", "\n").replace('\r', "\n");
        let mut records = Vec::new();
        let mut reader = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let mut record = csv::StringRecord::new();
        loop {
            let line = reader.position().line() as usize;
            match reader.read_record(&mut record) {
                Ok(false) => break,
                Ok(true) => {}
                Err(e) => {
                    let at = e.position().map_or(line, |p| p.line() as usize);
                    return Err(fail(Some(at), format!("unreadable: {e}")));
                }
            }
            let (at, raw) = match record.position() {
                Some(p) => record_start(&text, p.byte() as usize, p.line() as usize),
                None => (line, ""),
            };
            if raw.starts_with('#') || (record.len() == 1 && record.get(0) == Some("")) {
                continue;
            }
            records.push((at, record.iter().map(str::to_string).collect::<Vec<_>>()));
        }
        let mut lines = records.into_iter();
        let Some((header_at, header)) = lines.next() else {
            return Err(fail(
                None,
                format!("no header: expected the columns {}", COLUMNS.join(",")),
            ));
        };
        let header_line = Some(header_at);
        let mut column: HashMap<&str, usize> = HashMap::new();
        for (i, name) in header.iter().enumerate() {
            let known = COLUMNS.iter().find(|c| c.eq_ignore_ascii_case(name));
            let Some(&known) = known else {
                return Err(fail(
                    header_line,
                    format!(
                        "unknown column `{}`: expected {}",
                        quote(name),
                        COLUMNS.join(", ")
                    ),
                ));
            };
            if column.insert(known, i).is_some() {
                return Err(fail(header_line, format!("column `{known}` appears twice")));
            }
        }
        for required in &COLUMNS[..4] {
            if !column.contains_key(required) {
                return Err(fail(
                    header_line,
                    format!("no `{required}` column (required: clip, onset, end, arm)"),
                ));
            }
        }
        let targets = TARGET.iter().filter(|c| column.contains_key(*c)).count();
        if targets != 0 && targets != 3 {
            return Err(fail(
                header_line,
                "the target's columns come together: target_x, target_y and target_z".into(),
            ));
        }
        let tempos = TEMPO.iter().filter(|c| column.contains_key(*c)).count();
        if tempos == 1 {
            return Err(fail(
                header_line,
                "the tempo's columns come together: peak_speed_m_s and duration_s".into(),
            ));
        }

        let mut rows = Vec::new();
        let mut seen: HashMap<(PathBuf, Side, usize, usize), usize> = HashMap::new();
        for (at, record) in lines {
            let line = Some(at);
            if record.len() != header.len() {
                return Err(fail(
                    line,
                    format!(
                        "{} fields where the header has {}",
                        record.len(),
                        header.len()
                    ),
                ));
            }
            let cell = |name: &str| {
                column
                    .get(name)
                    .and_then(|&i| record.get(i))
                    .map_or("", String::as_str)
            };
            let bad = |why: String| fail(line, why);

            let text = cell("clip");
            if text.is_empty() {
                return Err(bad("empty `clip`".into()));
            }
            let clip = folder.join(text);
            if !clip.is_file() {
                return Err(bad(format!(
                    "clip `{}`: no such file ({})",
                    quote(text),
                    quote(&clip.display().to_string())
                )));
            }
            let frame = |name: &str| {
                let v = cell(name);
                v.parse::<usize>().map_err(|_| {
                    bad(format!(
                        "{name} `{}` is not a frame number (0, 1, 2, …)",
                        quote(v)
                    ))
                })
            };
            let (onset, end) = (frame("onset")?, frame("end")?);
            if onset >= end {
                return Err(bad(format!(
                    "frames {onset}..{end} are empty: the end is excluded, so it must be above \
                     the onset"
                )));
            }
            let arm: Side = cell("arm").parse().map_err(|_| {
                bad(format!(
                    "arm `{}`: expected right or left",
                    quote(cell("arm"))
                ))
            })?;
            let label = match cell("label") {
                "" => Label::Reach,
                l => l.parse().map_err(|_| {
                    bad(format!(
                        "label `{}`: expected reach, return or other",
                        quote(l)
                    ))
                })?,
            };
            let person = match cell("person") {
                "" => default_person(&clip),
                p => p.to_string(),
            };
            let cells = TARGET.map(cell);
            let target = if cells.iter().all(|c| c.is_empty()) {
                None
            } else {
                let mut t = [0.0; 3];
                for ((v, name), text) in t.iter_mut().zip(TARGET).zip(cells) {
                    *v = text
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite())
                        .ok_or_else(|| {
                            bad(format!(
                                "{name} `{}` is not a finite number of meters (all three target \
                                 cells, or none)",
                                quote(text)
                            ))
                        })?;
                }
                Some(t)
            };
            let cells = TEMPO.map(cell);
            let tempo = if cells.iter().all(|c| c.is_empty()) {
                None
            } else {
                let mut t = [0.0; 2];
                for ((v, name), text) in t.iter_mut().zip(TEMPO).zip(cells) {
                    *v = text
                        .parse::<f64>()
                        .ok()
                        .filter(|v| v.is_finite() && *v > 0.0)
                        .ok_or_else(|| {
                            bad(format!(
                                "{name} `{}` is not a positive number (both tempo cells, or \
                                 none)",
                                quote(text)
                            ))
                        })?;
                }
                Some(RowTempo {
                    peak_speed_m_s: t[0],
                    duration_s: t[1],
                })
            };
            if let Some(first) = seen.insert((file_key(&clip), arm, onset, end), at) {
                return Err(bad(format!(
                    "repeats line {first}: the same clip, arm and frames {onset}..{end}"
                )));
            }
            rows.push(SegmentRow {
                clip,
                frames: onset..end,
                arm,
                label,
                person,
                target,
                tempo,
                line,
            });
        }
        Ok(SegmentsFile {
            path: path.to_path_buf(),
            rows,
        })
    }

    /// The frames of `row` in `clip` (the capture the row names, read), checked: they must lie
    /// inside the clip. The error names the segments file and the row's line.
    pub fn resolve(
        &self,
        row: &SegmentRow,
        clip: &Clip,
    ) -> Result<Range<usize>, SegmentsFileError> {
        let n = clip.frame_count();
        if row.frames.end > n {
            return Err(SegmentsFileError {
                path: self.path.clone(),
                line: row.line,
                why: format!(
                    "frames {}..{} are outside {}, which has {n} frames (0..{n})",
                    row.frames.start,
                    row.frames.end,
                    row.clip.display()
                ),
            });
        }
        Ok(row.frames.clone())
    }

    /// The file's text: a comment saying the frame convention, the header, one line per row,
    /// clips relative to the file's folder where they can be.
    pub fn to_csv(&self) -> String {
        let folder = self
            .path
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        let mut writer = csv::Writer::from_writer(Vec::new());
        let mut out = String::from(
            "# kinergy segments: frames onset..end are numbered from 0, end excluded (--frames A..B)\n",
        );
        // The target's columns only when a row has one (shortest round-trip numbers).
        let targets = self.rows.iter().any(|r| r.target.is_some());
        let tempos = self.rows.iter().any(|r| r.tempo.is_some());
        let mut columns = COLUMNS[..6].to_vec();
        if targets {
            columns.extend(TARGET);
        }
        if tempos {
            columns.extend(TEMPO);
        }
        let mut write = || -> csv::Result<()> {
            writer.write_record(&columns)?;
            for r in &self.rows {
                let mut clip = relative_to(folder, &r.clip).to_string_lossy().into_owned();
                // A name the reader would take for a comment (`#` first) or trim (spaces
                // first) is written from `./`, which reads back as the same file.
                if clip.starts_with(['#', ' ', '\t']) {
                    clip.insert_str(0, "./");
                }
                let mut record = vec![
                    clip,
                    r.frames.start.to_string(),
                    r.frames.end.to_string(),
                    r.arm.to_string(),
                    r.label.as_str().to_string(),
                    r.person.clone(),
                ];
                if targets {
                    record.extend(
                        r.target
                            .map_or([const { String::new() }; 3], |t| t.map(|v| v.to_string())),
                    );
                }
                if tempos {
                    record.extend(r.tempo.map_or([const { String::new() }; 2], |t| {
                        [t.peak_speed_m_s, t.duration_s].map(|v| v.to_string())
                    }));
                }
                writer.write_record(&record)?;
            }
            writer.flush()?;
            Ok(())
        };
        // Writing to memory fails only on a bug; the rows are plain strings.
        let written = write().is_ok();
        debug_assert!(written);
        if let Ok(bytes) = writer.into_inner() {
            out.push_str(&String::from_utf8_lossy(&bytes));
        }
        out
    }

    /// Writes [`SegmentsFile::to_csv`] to the file's path, atomically.
    pub fn write(&self) -> Result<(), SegmentsFileError> {
        kinergy_io::write_atomic(&self.path, self.to_csv().as_bytes()).map_err(|e| {
            SegmentsFileError {
                path: self.path.clone(),
                line: None,
                why: e.to_string(),
            }
        })
    }
}

/// Where a record that the csv reader says starts at `byte` (on `line`) really starts: past
/// the blank lines and spaces before it. Its line and its text from there.
fn record_start(text: &str, byte: usize, line: usize) -> (usize, &str) {
    let mut rest = text.get(byte..).unwrap_or("");
    let mut line = line;
    loop {
        rest = rest.trim_start_matches([' ', '\t']);
        match rest.strip_prefix('\n') {
            Some(after) => {
                rest = after;
                line += 1;
            }
            None => return (line, rest),
        }
    }
}

/// A cell as an error may quote it (at most [`kinergy_io::MAX_QUOTED_CHARS`] characters).
fn quote(cell: &str) -> std::borrow::Cow<'_, str> {
    kinergy_io::clip_text(cell, kinergy_io::MAX_QUOTED_CHARS)
}

/// Who moves in `clip` when nobody says: the performer its file name gives (Bandai's
/// `dataset-N_MOTION_STYLE_NNN` → STYLE, CMU's `SS_TT` → SS), else the name of the folder
/// holding it (empty when there is none) — [`crate::who::guess_person`].
pub fn default_person(clip: &Path) -> String {
    crate::who::guess_person(clip)
}

/// The file `path` names, for comparing paths: canonical when it exists, absolute otherwise.
fn file_key(path: &Path) -> PathBuf {
    std::fs::canonicalize(path)
        .or_else(|_| std::path::absolute(path))
        .unwrap_or_else(|_| path.to_path_buf())
}

/// `target` relative to the folder `base` (with `..` as needed); absolute when they share no
/// folder.
fn relative_to(base: &Path, target: &Path) -> PathBuf {
    let (base, target) = (file_key(base), file_key(target));
    let (b, t): (Vec<Component<'_>>, Vec<Component<'_>>) =
        (base.components().collect(), target.components().collect());
    let common = b.iter().zip(&t).take_while(|(x, y)| x == y).count();
    if !b[..common]
        .iter()
        .any(|c| matches!(c, Component::Normal(_)))
    {
        return target;
    }
    let mut out = PathBuf::new();
    for _ in common..b.len() {
        out.push("..");
    }
    out.extend(&t[common..]);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_climb_where_needed() {
        let dir = tempfile::tempdir().expect("tempdir");
        let a = dir.path().join("a");
        let b = dir.path().join("b/c");
        std::fs::create_dir_all(&a).expect("a");
        std::fs::create_dir_all(&b).expect("b");
        std::fs::write(b.join("x.bvh"), "").expect("x");
        assert_eq!(relative_to(&a, &b.join("x.bvh")), Path::new("../b/c/x.bvh"));
        assert_eq!(
            relative_to(dir.path(), &b.join("x.bvh")),
            Path::new("b/c/x.bvh")
        );
    }

    #[test]
    fn the_person_is_the_folder_name() {
        assert_eq!(default_person(Path::new("/data/p01/r01.bvh")), "p01");
        let row = SegmentRow::new("/data/p01/r01.bvh", 1..9, Side::Left, Label::Reach);
        assert_eq!(row.person, "p01");
    }
}
