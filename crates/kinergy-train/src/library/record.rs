//! A shard's record, in the `shards` folder of a library: three files, each written
//! atomically.
//!
//! - `I-of-N.json`, the shard's header ([`ShardHeader`]): which shard of how many, the
//!   library's root, the run's [`Settings`] and the name and hash of the takes list. Written
//!   as the shard starts.
//! - `takes-<hash>.json`, the library's takes ([`TakeIdentity`] each), named by the first
//!   16 hexadecimal digits of its own hash: the shards that saw the same takes share one.
//! - `I-of-N.csv`, what the shard did ([`RecordRow`]s): first a `shard` row naming the
//!   header and its hash (so a record is never read with another run's header), then a
//!   `take` row per take dealt, then a `reach` row per reach fitted or found fitted (with its
//!   result file's hash) and a `skipped` row per take with nothing to fit. Rewritten as the
//!   shard goes.
//!
//! Reading is strict: a record that is empty, has only its header line, starts with a
//! byte-order mark, has a column too many or too few, or a reach whose frames are not whole
//! numbers (or end before they start) is refused, naming the file and the line. Record names are `I-of-N` with 1 ≤ I ≤ N ≤ 100,000 and no leading zero.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use super::identity::{Settings, TakeIdentity, hash_bytes};
use super::table::{LibraryError, SHARDS, write_csv};
use crate::CapturedReach;
use crate::who::Who;

/// The version of the record's files this library writes (`kinergy_library`).
pub const FORMAT: u32 = 1;

/// A record's columns, in order.
pub const COLUMNS: [&str; 11] = [
    "kind", "clip", "person", "motion", "arm", "onset", "end", "result", "blake3", "seconds", "why",
];

/// The columns of records written before a reach's motion was recorded: read, their
/// motions empty.
pub const COLUMNS_WITHOUT_MOTION: [&str; 10] = [
    "kind", "clip", "person", "arm", "onset", "end", "result", "blake3", "seconds", "why",
];

/// The largest record file read, bytes.
const MAX_RECORD_BYTES: u64 = 1 << 30;

/// One line of a shard's record.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RecordRow {
    /// `shard` (the first row: `result` names the header, `blake3` its hash), `take` (dealt
    /// to the shard), `reach` (fitted or found fitted) or `skipped` (nothing to fit).
    pub kind: String,
    /// The take: its path from the library's root (as its [`TakeIdentity`] names it).
    pub clip: String,
    /// The reach's person (by the library's person rule).
    pub person: String,
    /// The reach's motion, where known (empty in records of older versions).
    #[serde(default)]
    pub motion: String,
    /// The reach's arm side.
    pub arm: String,
    /// The reach's first frame.
    pub onset: String,
    /// The reach's end frame (excluded).
    pub end: String,
    /// The result file, relative to the library folder (`shard`: the header's file name).
    pub result: String,
    /// The BLAKE3 hash of the result file as written (`shard`: of the header).
    pub blake3: String,
    /// Seconds the reach's fit took (empty when it was found already fitted).
    pub seconds: String,
    /// Why a take was skipped.
    pub why: String,
}

impl RecordRow {
    fn empty(kind: &str, clip: &str) -> RecordRow {
        RecordRow {
            kind: kind.into(),
            clip: clip.into(),
            person: String::new(),
            motion: String::new(),
            arm: String::new(),
            onset: String::new(),
            end: String::new(),
            result: String::new(),
            blake3: String::new(),
            seconds: String::new(),
            why: String::new(),
        }
    }

    /// The first row: the record's header `name`, of hash `blake3`.
    pub fn shard(name: &str, blake3: &str) -> RecordRow {
        RecordRow {
            result: name.into(),
            blake3: blake3.into(),
            ..RecordRow::empty("shard", "")
        }
    }

    /// The row saying take `clip` (its path from the root) was dealt to the shard.
    pub fn take(clip: &str) -> RecordRow {
        RecordRow::empty("take", clip)
    }

    /// The row saying take `clip` was skipped, and why.
    pub fn skipped(clip: &str, why: &str) -> RecordRow {
        RecordRow {
            why: why.to_string(),
            ..RecordRow::empty("skipped", clip)
        }
    }

    /// The row of `reach` of take `clip`, by `who` (its person and motion), its result
    /// under `result` (relative to the library folder) of hash `blake3`; `seconds` empty
    /// when it was found already fitted.
    pub fn reach(
        clip: &str,
        reach: &CapturedReach,
        who: Who,
        result: &Path,
        blake3: String,
        seconds: String,
    ) -> RecordRow {
        RecordRow {
            person: who.person,
            motion: who.motion.unwrap_or_default(),
            arm: reach
                .fitted_arm()
                .side
                .map_or_else(String::new, |s| s.to_string()),
            onset: reach.frames().start.to_string(),
            end: reach.frames().end.to_string(),
            result: super::identity::slash_path(result),
            blake3,
            seconds,
            ..RecordRow::empty("reach", clip)
        }
    }
}

/// A shard's header, `I-of-N.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardHeader {
    /// The version of the record's files ([`FORMAT`]).
    pub kinergy_library: u32,
    /// Shard I of N, `[I, N]`.
    pub shard: [usize; 2],
    /// The library's root (the takes' common folder) on the machine that ran the shard.
    pub root: String,
    /// The run's settings.
    pub settings: Settings,
    /// The takes list's file name, in the `shards` folder.
    pub takes: String,
    /// Its hash.
    pub takes_blake3: String,
    /// How many takes it lists.
    pub take_count: usize,
    /// The folders the takes were found in by walking them, canonical, on the machine that
    /// ran the shard (absent: the takes were given one by one). `collect` walks them again
    /// and names a take no shard saw.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub folders: Vec<String>,
}

/// The takes list, `takes-<hash>.json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TakesList {
    /// The version of the record's files ([`FORMAT`]).
    pub kinergy_library: u32,
    /// Every take of the library, in its order.
    pub takes: Vec<TakeIdentity>,
}

/// Which of a record's files a name is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecordFile {
    /// `I-of-N.csv`.
    Rows,
    /// `I-of-N.json`.
    Header,
}

/// A shard's record file `I-of-N.csv`, in the `shards` folder of `dir`.
pub fn record_path(dir: &Path, index: usize, count: usize) -> PathBuf {
    dir.join(SHARDS).join(format!("{index}-of-{count}.csv"))
}

/// A shard's header `I-of-N.json`, in the `shards` folder of `dir`.
pub fn header_path(dir: &Path, index: usize, count: usize) -> PathBuf {
    dir.join(SHARDS).join(format!("{index}-of-{count}.json"))
}

/// What a file name in the `shards` folder is: `None` when it is not named like a record
/// (`*-of-*.csv` or `.json`); `Some(Err(why))` when it is but names no shard that can be (an
/// index of 0 or above its count, a count above 100,000, a leading zero, not a number).
pub fn parse_record_name(name: &str) -> Option<Result<(usize, usize, RecordFile), String>> {
    let (stem, file) = match (name.strip_suffix(".csv"), name.strip_suffix(".json")) {
        (Some(stem), _) => (stem, RecordFile::Rows),
        (_, Some(stem)) => (stem, RecordFile::Header),
        _ => return None,
    };
    let (i, n) = stem.split_once("-of-")?;
    let max = super::MAX_SHARDS;
    let count = super::bounded_plain(n).ok_or_else(|| {
        format!(
            "a stray record: `{}` is no shard count (a whole number from 1 to {max}, no \
             leading zero)",
            kinergy_io::clip_text(n, 24)
        )
    });
    let index = count.and_then(|count| {
        super::bounded_plain(i)
            .filter(|&i| i <= count)
            .map(|i| (i, count))
            .ok_or_else(|| {
                format!(
                    "a stray record: `{}` is no shard of {count} (1 to {count}, no leading \
                     zero)",
                    kinergy_io::clip_text(i, 24)
                )
            })
    });
    Some(index.map(|(i, n)| (i, n, file)))
}

/// The takes list's file name for a list of hash `blake3`.
pub fn takes_file_name(blake3: &str) -> String {
    format!("takes-{}.json", &blake3[..16.min(blake3.len())])
}

/// Whether `name` is a takes list's file name (`takes-` and 16 hexadecimal digits).
pub fn is_takes_file_name(name: &str) -> bool {
    name.strip_prefix("takes-")
        .and_then(|s| s.strip_suffix(".json"))
        .is_some_and(|h| h.len() == 16 && h.bytes().all(|b| b.is_ascii_hexdigit()))
}

/// Reads a shard's record `I-of-N.csv`, strictly: UTF-8 without a byte-order mark, the
/// header line [`COLUMNS`] exactly (or an older record's [`COLUMNS_WITHOUT_MOTION`]), every
/// line of as many fields, a `shard` row first, and only the kinds a record has. Errors
/// name the file and the line.
pub fn read_record(path: &Path) -> Result<Vec<RecordRow>, LibraryError> {
    let refuse = |why: String| LibraryError::Input {
        path: path.to_path_buf(),
        why,
    };
    let bytes =
        kinergy_io::read_limited(path, MAX_RECORD_BYTES).map_err(|e| refuse(e.to_string()))?;
    if bytes.starts_with(b"\xef\xbb\xbf") {
        return Err(refuse(
            "line 1 starts with a byte-order mark: not a record Kinergy wrote (edited by \
             hand?)"
                .into(),
        ));
    }
    let text = String::from_utf8(bytes).map_err(|e| {
        refuse(format!(
            "not UTF-8 text (a byte at {} is not): not a record Kinergy wrote",
            e.utf8_error().valid_up_to()
        ))
    })?;
    if text.trim().is_empty() {
        return Err(refuse(
            "empty: not a shard record (a shard writes its record as it starts): remove it and \
             run the shard again with --resume"
                .into(),
        ));
    }
    let mut reader = csv::ReaderBuilder::new()
        .flexible(false)
        .from_reader(text.as_bytes());
    let header = reader
        .headers()
        .map_err(|e| refuse(format!("line 1: {e}")))?
        .clone();
    if header.iter().ne(COLUMNS) && header.iter().ne(COLUMNS_WITHOUT_MOTION) {
        return Err(refuse(format!(
            "line 1: the columns are `{}`, where a shard record has `{}`",
            kinergy_io::clip_text(&header.iter().collect::<Vec<_>>().join(","), 200),
            COLUMNS.join(",")
        )));
    }
    let mut rows = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| refuse(csv_error(&e)))?;
        let line = record.position().map_or(0, |p| p.line());
        let row: RecordRow = record
            .deserialize(Some(&header))
            .map_err(|e| refuse(format!("line {line}: {e}")))?;
        let first = rows.is_empty();
        match (first, row.kind.as_str()) {
            (true, "shard") | (false, "take" | "reach" | "skipped") => {}
            (true, _) => {
                return Err(refuse(format!(
                    "line {line}: a record starts with its `shard` row, not `{}`",
                    kinergy_io::clip_text(&row.kind, 24)
                )));
            }
            (false, kind) => {
                return Err(refuse(format!(
                    "line {line}: `{}` is no kind of record row (take, reach or skipped)",
                    kinergy_io::clip_text(kind, 24)
                )));
            }
        }
        if row.kind == "reach" {
            check_frames(&row).map_err(|why| refuse(format!("line {line}, {why}")))?;
        }
        rows.push(row);
    }
    if rows.is_empty() {
        return Err(refuse(
            "line 1: the header line and no row: not a whole record (it starts with its \
             `shard` row)"
                .into(),
        ));
    }
    Ok(rows)
}

/// Checks a `reach` row's arm (right, left or empty) and frames: `onset` and `end` whole
/// numbers (a `usize`), the end after the onset. Says which column is wrong otherwise.
fn check_frames(row: &RecordRow) -> Result<(), String> {
    let frame =
        |column: &str, text: &str| {
            let plain = !text.is_empty() && text.bytes().all(|b| b.is_ascii_digit());
            plain.then(|| text.parse::<usize>().ok()).flatten().ok_or_else(|| {
            format!(
                "column {column}: `{}` is no frame (a whole number, 0 or more): not a record \
                 Kinergy wrote (edited by hand?)",
                kinergy_io::clip_text(text, 24)
            )
        })
        };
    // The arm: a side, or empty for an arm named by its joints whose side is unclear.
    if !matches!(row.arm.as_str(), "" | "right" | "left") {
        return Err(format!(
            "column arm: `{}` is no arm (right, left, or empty): not a record Kinergy wrote \
             (edited by hand?)",
            kinergy_io::clip_text(&row.arm, 24)
        ));
    }
    let (onset, end) = (frame("onset", &row.onset)?, frame("end", &row.end)?);
    if end <= onset {
        return Err(format!(
            "columns onset, end: the reach ends (frame {end}) before it starts (frame \
             {onset}): not a record Kinergy wrote (edited by hand?)"
        ));
    }
    Ok(())
}

/// A CSV error as a record's refusal says it: the line, and what is wrong.
fn csv_error(e: &csv::Error) -> String {
    match e.kind() {
        csv::ErrorKind::UnequalLengths {
            pos,
            expected_len,
            len,
        } => format!(
            "line {}: {len} fields where the header has {expected_len}",
            pos.as_ref().map_or(0, |p| p.line())
        ),
        _ => e.to_string(),
    }
}

/// Reads a shard's header `I-of-N.json` and the hash of its bytes.
pub fn read_header(path: &Path) -> Result<(ShardHeader, String), LibraryError> {
    let refuse = |why: String| LibraryError::Input {
        path: path.to_path_buf(),
        why,
    };
    let bytes = read_limited(path).map_err(refuse)?;
    let header: ShardHeader =
        serde_json::from_slice(&bytes).map_err(|e| refuse(format!("not a shard's header: {e}")))?;
    if header.kinergy_library != FORMAT {
        return Err(refuse(format!(
            "a record of version {} (this Kinergy reads version {FORMAT})",
            header.kinergy_library
        )));
    }
    Ok((header, hash_bytes(&bytes)))
}

fn read_limited(path: &Path) -> Result<Vec<u8>, String> {
    kinergy_io::read_limited(path, MAX_RECORD_BYTES).map_err(|e| e.to_string())
}

/// Reads the takes list `header` names, in the `shards` folder `shards`, checking its hash.
pub fn read_takes(shards: &Path, header: &ShardHeader) -> Result<Vec<TakeIdentity>, LibraryError> {
    let path = shards.join(&header.takes);
    let refuse = |why: String| LibraryError::Input {
        path: path.clone(),
        why,
    };
    if !is_takes_file_name(&header.takes) {
        return Err(refuse("not a takes list's name".into()));
    }
    let bytes = read_limited(&path).map_err(refuse)?;
    if hash_bytes(&bytes) != header.takes_blake3 {
        return Err(refuse(format!(
            "not the takes list shard {}/{} recorded (its hash differs)",
            header.shard[0], header.shard[1]
        )));
    }
    let list: TakesList =
        serde_json::from_slice(&bytes).map_err(|e| refuse(format!("not a takes list: {e}")))?;
    if list.takes.len() != header.take_count {
        return Err(refuse(format!(
            "{} takes where the header says {}",
            list.takes.len(),
            header.take_count
        )));
    }
    Ok(list.takes)
}

/// Writes the takes list of `takes` into `shards` (unless it is there already): returns
/// its file name and hash.
pub fn write_takes(
    shards: &Path,
    takes: &[TakeIdentity],
) -> Result<(String, String), LibraryError> {
    let list = TakesList {
        kinergy_library: FORMAT,
        takes: takes.to_vec(),
    };
    let bytes = to_json(&list, shards)?;
    let hash = hash_bytes(&bytes);
    let name = takes_file_name(&hash);
    let path = shards.join(&name);
    let same = std::fs::read(&path).is_ok_and(|old| old == bytes);
    if !same {
        write_bytes(&path, &bytes)?;
    }
    Ok((name, hash))
}

/// Writes a shard's header to `path`: returns its hash.
pub fn write_header(path: &Path, header: &ShardHeader) -> Result<String, LibraryError> {
    let bytes = to_json(header, path)?;
    write_bytes(path, &bytes)?;
    Ok(hash_bytes(&bytes))
}

fn to_json<T: Serialize>(value: &T, path: &Path) -> Result<Vec<u8>, LibraryError> {
    let mut bytes = serde_json::to_vec_pretty(value).map_err(|e| LibraryError::Write {
        path: path.to_path_buf(),
        why: e.to_string(),
    })?;
    bytes.push(b'\n');
    Ok(bytes)
}

fn write_bytes(path: &Path, bytes: &[u8]) -> Result<(), LibraryError> {
    kinergy_io::write_atomic(path, bytes).map_err(|e| LibraryError::Write {
        path: path.to_path_buf(),
        why: e.to_string(),
    })
}

/// A shard's record as a whole: its header, the takes it saw and its rows.
#[derive(Debug, Clone)]
pub struct ShardRecord {
    /// Shard I of N.
    pub shard: (usize, usize),
    /// The header.
    pub header: ShardHeader,
    /// The takes the shard saw (shared among the records that saw the same).
    pub takes: Arc<Vec<TakeIdentity>>,
    /// The rows, the `shard` row first.
    pub rows: Vec<RecordRow>,
}

/// Takes lists already read, by hash.
pub type TakesCache = HashMap<String, Arc<Vec<TakeIdentity>>>;

/// Reads shard `index` of `count`'s record in the library `dir`: its rows, its header and
/// its takes list, checked against each other. `Ok(Err(why))` when the rows belong to
/// another run of the shard than the header (a shard started again and stopped before it
/// wrote its rows): the shard is to be run again, nothing is wrong with the files.
pub fn load_shard(
    dir: &Path,
    index: usize,
    count: usize,
    cache: &mut TakesCache,
) -> Result<Result<ShardRecord, String>, LibraryError> {
    let rows_path = record_path(dir, index, count);
    let rows = read_record(&rows_path)?;
    let head_path = header_path(dir, index, count);
    if !head_path.is_file() {
        return Err(LibraryError::Input {
            path: rows_path,
            why: format!(
                "has no header {}: a record of an older Kinergy, or its header was removed \
                 (run the shard again with --resume)",
                head_path.display()
            ),
        });
    }
    let (header, hash) = read_header(&head_path)?;
    if header.shard != [index, count] {
        return Err(LibraryError::Input {
            path: head_path,
            why: format!(
                "the header of shard {}/{} under the name of shard {index}/{count}",
                header.shard[0], header.shard[1]
            ),
        });
    }
    let name = format!("{index}-of-{count}.json");
    if rows[0].result != name || rows[0].blake3 != hash {
        return Ok(Err(format!(
            "shard {index}/{count} was started again and stopped before it wrote its record: \
             run it again with --resume"
        )));
    }
    let shards = dir.join(SHARDS);
    let takes = match cache.get(&header.takes_blake3) {
        Some(takes) => takes.clone(),
        None => {
            let takes = Arc::new(read_takes(&shards, &header)?);
            cache.insert(header.takes_blake3.clone(), takes.clone());
            takes
        }
    };
    Ok(Ok(ShardRecord {
        shard: (index, count),
        header,
        takes,
        rows,
    }))
}

/// Writes the rows of a shard's record to `path`.
pub fn write_record(path: &Path, rows: &[RecordRow]) -> Result<(), LibraryError> {
    write_csv(path, rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn record_names_are_bounded_and_spelled_one_way() {
        assert_eq!(
            parse_record_name("2-of-8.csv"),
            Some(Ok((2, 8, RecordFile::Rows)))
        );
        assert_eq!(
            parse_record_name("100000-of-100000.json"),
            Some(Ok((100_000, 100_000, RecordFile::Header)))
        );
        for stray in [
            "2-of-1.csv",
            "0-of-1.csv",
            "01-of-1.csv",
            "1-of-01.csv",
            "1-of-99999999999.csv",
            "1-of-1000000.csv",
            "1-of-100001.json",
            "x-of-2.csv",
            "-of-.csv",
        ] {
            let parsed = parse_record_name(stray);
            assert!(matches!(parsed, Some(Err(_))), "{stray}: {parsed:?}");
        }
        let e = parse_record_name("1-of-99999999999.csv")
            .unwrap()
            .unwrap_err();
        assert!(e.contains("`99999999999` is no shard count"), "{e}");
        assert_eq!(parse_record_name("notes.txt"), None);
        assert_eq!(parse_record_name("library.csv"), None);
        assert!(is_takes_file_name("takes-0123456789abcdef.json"));
        assert!(!is_takes_file_name("takes-0123.json"));
    }

    fn write(dir: &Path, name: &str, text: &[u8]) -> PathBuf {
        let path = dir.join(name);
        std::fs::write(&path, text).unwrap();
        path
    }

    /// The sweep's records that cannot be true: empty, a header line alone, a byte-order
    /// mark, a column too many (in the header or in a row).
    #[test]
    fn records_that_cannot_be_true_are_refused_naming_the_file_and_line() {
        let dir = tempfile::tempdir().unwrap();
        // In the older layout, without `motion`: such records are read as they are.
        let header = COLUMNS_WITHOUT_MOTION.join(",");
        let good = format!("{header}\nshard,,,,,,1-of-1.json,abc,,\ntake,a.bvh,,,,,,,,\n");
        let path = write(dir.path(), "good.csv", good.as_bytes());
        assert_eq!(read_record(&path).unwrap().len(), 2);
        let huge = format!(
            "{header}\nshard,,,,,,1-of-1.json,abc,,\nreach,a.bvh,p,right,{},9,a.bvh.json,h,,\n",
            "9".repeat(40)
        );
        let backwards = format!(
            "{header}\nshard,,,,,,1-of-1.json,abc,,\nreach,a.bvh,p,right,9,3,a.bvh.json,h,,\n"
        );
        let no_arm = format!(
            "{header}\nshard,,,,,,1-of-1.json,abc,,\nreach,a.bvh,p,{},3,9,a.bvh.json,h,,\n",
            "9".repeat(40)
        );
        let cases: [(&str, Vec<u8>, &str); 9] = [
            (
                "no-arm.csv",
                no_arm.into_bytes(),
                "line 3, column arm: `999999999999999999999999…",
            ),
            (
                "huge-onset.csv",
                huge.into_bytes(),
                "line 3, column onset: `999999999999999999999999…",
            ),
            (
                "backwards.csv",
                backwards.into_bytes(),
                "line 3, columns onset, end: the reach ends (frame 3) before it starts",
            ),
            ("empty.csv", vec![], "empty"),
            (
                "header.csv",
                format!("{header}\n").into_bytes(),
                "line 1: the header line and no row",
            ),
            (
                "bom.csv",
                [b"\xef\xbb\xbf".as_slice(), good.as_bytes()].concat(),
                "line 1 starts with a byte-order mark",
            ),
            (
                "extra-column.csv",
                good.replacen("why", "why,extra", 1).into_bytes(),
                "line 1: the columns are",
            ),
            (
                "extra-field.csv",
                good.replace("take,a.bvh,,,,,,,,", "take,a.bvh,,,,,,,,,x")
                    .into_bytes(),
                "line 3: 11 fields where the header has 10",
            ),
            (
                "take-first.csv",
                format!("{header}\ntake,a.bvh,,,,,,,,\n").into_bytes(),
                "line 2: a record starts with its `shard` row",
            ),
        ];
        for (name, bytes, expected) in cases {
            let path = write(dir.path(), name, &bytes);
            let e = read_record(&path).unwrap_err().to_string();
            assert!(e.contains(name) && e.contains(expected), "{name}: {e}");
        }
    }

    /// A record of this version keeps each reach's motion; one written before motions were
    /// recorded reads with the motions empty.
    #[test]
    fn records_keep_motions_and_older_records_read_without() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("1-of-1.csv");
        let reach = RecordRow {
            person: "elderly".into(),
            motion: "raise-up-right-hand".into(),
            arm: "right".into(),
            onset: "3".into(),
            end: "40".into(),
            result: "a.bvh.json".into(),
            blake3: "h".into(),
            ..RecordRow::empty("reach", "a.bvh")
        };
        let rows = vec![RecordRow::shard("1-of-1.json", "abc"), reach];
        write_record(&path, &rows).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.starts_with(&COLUMNS.join(",")), "{text}");
        assert_eq!(read_record(&path).unwrap(), rows);
        let old = format!(
            "{}\nshard,,,,,,1-of-1.json,abc,,\nreach,a.bvh,p01,right,3,40,a.bvh.json,h,,\n",
            COLUMNS_WITHOUT_MOTION.join(",")
        );
        std::fs::write(&path, old).unwrap();
        let read = read_record(&path).unwrap();
        assert_eq!(
            (read[1].person.as_str(), read[1].motion.as_str()),
            ("p01", "")
        );
        assert_eq!((read[1].onset.as_str(), read[1].end.as_str()), ("3", "40"));
    }
}
