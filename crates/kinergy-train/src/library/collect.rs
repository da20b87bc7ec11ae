//! [`collect`]: a library's shards' records checked against each other, against the takes
//! on disk and against the result files, then tabled.

use std::collections::{BTreeMap, BTreeSet, HashSet};
use std::path::{Component, Path, PathBuf};

use rayon::prelude::*;

use super::deal;
use super::identity::{TakeIdentity, hash_file, takes_changes};
use super::record::{
    RecordFile, RecordRow, ShardRecord, TakesCache, is_takes_file_name, load_shard,
    parse_record_name,
};
use super::table::{
    LIBRARY, LibraryError, LibraryRow, LibraryTable, SHARDS, SKIPPED, SkippedRow, write_csv,
};
use crate::who::{PersonRule, TakeAt};

/// What [`collect`] found and wrote.
#[derive(Debug, Clone, PartialEq)]
pub struct Collected {
    /// The tables written.
    pub table: LibraryTable,
    /// The summary in words (reaches, skipped takes, the files).
    pub text: String,
}

/// How many shards or takes a problem names (the rest are counted).
const NAMED: usize = 8;

/// Reads the shards' records in `dir` and checks them, then writes `library.csv` (one row
/// per reach, by clip, frames and arm) and `skipped.csv`. Idempotent.
///
/// Refused ([`LibraryError::Refused`], no table written), naming what differs: stray
/// records (`2-of-1.csv`, `01-of-1.csv`, `1-of-1000000.csv`) or records that cannot be read
/// (empty, a header alone, a byte-order mark, a column too many: file and line), records
/// of different shardings, shards run with different settings, takes added, removed,
/// grown, shrunk or edited between the shards or since they ran, a record whose takes are
/// not the ones the library deals it, and a result file that is not the one recorded (its
/// hash differs). Incomplete ([`LibraryError::Incomplete`]: the tables of what is there are
/// written) where pieces are only missing: a shard without a record, takes a shard did not
/// reach, results missing, and takes added to the library's folders since the shards walked
/// them.
pub fn collect(dir: &Path) -> Result<Collected, LibraryError> {
    collect_with(dir, None)
}

/// [`collect`], each reach's person and motion named by `person` where given
/// (`collect --person RULE`) instead of as the records say: the records stay as they are,
/// and `library.csv`'s settings fingerprint is that of the records' settings with this
/// rule — the table a fit with `--person RULE` writes. A rule that reads a segments file's
/// persons (`auto` or `segments`, for a library fitted with a segments file) takes them from
/// the records, which hold them only where the library was fitted with such a rule (or by a
/// version before the rule was recorded); otherwise it is refused (fit again with `--resume
/// --person RULE`: nothing is fitted again). Takes the rule cannot name are refused
/// ([`LibraryError::Person`]), no table written.
pub fn collect_with(dir: &Path, person: Option<&PersonRule>) -> Result<Collected, LibraryError> {
    let shards = dir.join(SHARDS);
    let entries = std::fs::read_dir(&shards).map_err(|e| LibraryError::Input {
        path: shards.clone(),
        why: format!("no shard records here ({e}): is this a `fit --out-dir` folder?"),
    })?;
    let mut wrong: Vec<String> = Vec::new();
    let mut missing: Vec<String> = Vec::new();
    // Each shard's files found: its rows, its header.
    let mut found: BTreeMap<(usize, usize), [bool; 2]> = BTreeMap::new();
    for entry in entries {
        let entry = entry.map_err(|e| LibraryError::Input {
            path: shards.clone(),
            why: e.to_string(),
        })?;
        let name = entry.file_name().to_string_lossy().into_owned();
        // Hidden files: the temporaries of atomic writes, a system's own.
        if name.starts_with('.') {
            continue;
        }
        match parse_record_name(&name) {
            Some(Ok((i, n, file))) => {
                found.entry((i, n)).or_default()[(file == RecordFile::Header) as usize] = true;
            }
            Some(Err(why)) => wrong.push(format!("{}: {why}: remove it", entry.path().display())),
            None if is_takes_file_name(&name) => {}
            None => wrong.push(format!(
                "{}: not a shard's record (I-of-N.csv), header (I-of-N.json) or takes list: \
                 remove it",
                entry.path().display()
            )),
        }
    }
    if found.is_empty() && wrong.is_empty() {
        return Err(LibraryError::Input {
            path: shards.clone(),
            why: format!(
                "{}: no shard record (I-of-N.csv): nothing was fitted into {} yet",
                shards.display(),
                dir.display()
            ),
        });
    }
    let counts: BTreeSet<usize> = found.keys().map(|&(_, n)| n).collect();
    if counts.len() > 1 {
        wrong.push(format!(
            "records of different shardings ({}): remove the old ones from {}",
            counts
                .iter()
                .map(|n| format!("of {n}"))
                .collect::<Vec<_>>()
                .join(", "),
            shards.display()
        ));
    }
    let count = counts.last().copied().unwrap_or(0);
    let mut cache = TakesCache::new();
    let mut records: Vec<ShardRecord> = Vec::new();
    for (&(i, n), &[rows, header]) in &found {
        if n != count {
            continue;
        }
        match (rows, header) {
            (true, _) => match load_shard(dir, i, n, &mut cache) {
                Ok(Ok(record)) => records.push(record),
                Ok(Err(why)) => missing.push(why),
                Err(e) => wrong.push(e.to_string()),
            },
            (false, _) => missing.push(format!(
                "shard {i}/{n} has no record, only its header {i}-of-{n}.json: it was stopped as \
                 it started, or its record was removed: run it again with --resume"
            )),
        }
    }
    // (A shard with a header alone is said above.)
    let absent: Vec<usize> = (1..=count)
        .filter(|&i| !found.contains_key(&(i, count)))
        .collect();
    match absent.as_slice() {
        [] => {}
        [one] => missing.push(format!(
            "shard {one}/{count} has no record: it did not run (or was killed before it started)"
        )),
        _ => {
            // Named by at most NAMED: a count is at most MAX_SHARDS, and said in one line.
            let named: Vec<String> = absent
                .iter()
                .map(|i| format!("{i}/{count}"))
                .take(NAMED)
                .collect();
            missing.push(format!(
                "{} of the {count} shards have no record ({}{}): they did not run (or were \
                 killed before they started)",
                absent.len(),
                named.join(", "),
                if absent.len() > NAMED { ", …" } else { "" }
            ));
        }
    }
    check_settings(&records, &mut wrong);
    let takes_agree = check_takes(&records, &mut wrong);
    if takes_agree {
        check_deal(&records, count, &mut wrong);
        check_added(&records, &mut missing);
    }
    let (mut library, roots, mut skipped) =
        tabled(dir, &records, takes_agree, person, &mut wrong, &mut missing);
    if !wrong.is_empty() {
        return Err(LibraryError::Refused {
            dir: dir.to_path_buf(),
            problems: wrong,
        });
    }
    if let Some(rule) = person {
        relabel(dir, &mut library, &roots, &records, rule)?;
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
    if !missing.is_empty() {
        return Err(LibraryError::Incomplete {
            dir: dir.to_path_buf(),
            summary: text,
            problems: missing,
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

fn shard_name(record: &ShardRecord) -> String {
    format!("shard {}/{}", record.shard.0, record.shard.1)
}

/// Every shard must have run with the first one's settings.
fn check_settings(records: &[ShardRecord], wrong: &mut Vec<String>) {
    let Some(first) = records.first() else {
        return;
    };
    for record in &records[1..] {
        let differences = first
            .header
            .settings
            .differences(&record.header.settings, &shard_name(first));
        if !differences.is_empty() {
            wrong.push(format!(
                "{} was fitted with other settings than {}: {}: fit every shard with the same \
                 settings",
                shard_name(record),
                shard_name(first),
                differences.join(", ")
            ));
        }
    }
}

/// The takes in the folders the shards walked that no shard's takes list has: added since.
fn check_added(records: &[ShardRecord], missing: &mut Vec<String>) {
    let Some(first) = records.first() else {
        return;
    };
    let folders: Vec<PathBuf> = first.header.folders.iter().map(PathBuf::from).collect();
    if folders.is_empty() || !folders.iter().all(|f| f.is_dir()) {
        return;
    }
    // A walk that fails now (an unreadable folder) says nothing new: the takes were checked.
    let Ok(walk) = crate::source::walk_captures(&folders) else {
        return;
    };
    let root = Path::new(&first.header.root);
    let known: HashSet<PathBuf> = first
        .takes
        .iter()
        .filter_map(|t| safe_relative(&t.path))
        .map(|relative| super::names::canonical(&root.join(relative)))
        .collect();
    let added: Vec<String> = walk
        .files
        .iter()
        .filter(|f| !known.contains(&super::names::canonical(f)))
        .map(|f| f.display().to_string())
        .collect();
    if !added.is_empty() {
        let shards: Vec<String> = records.iter().map(shard_name).take(NAMED).collect();
        missing.push(format!(
            "{} take(s) in the library's folders were added since {}{} walked them: {}: fit \
             every shard again with --resume (the results of the unchanged takes are kept)",
            added.len(),
            shards.join(", "),
            if records.len() > NAMED { ", …" } else { "" },
            kinergy_io::list_some(&added, NAMED)
        ));
    }
}

/// Every shard must have seen the same takes, and they must be the takes on disk now.
/// Returns whether they were.
fn check_takes(records: &[ShardRecord], wrong: &mut Vec<String>) -> bool {
    // The takes on disk, under each root the shards recorded.
    let mut agree = true;
    let mut groups: BTreeMap<(&str, &str), Vec<&ShardRecord>> = BTreeMap::new();
    for record in records {
        groups
            .entry((
                record.header.root.as_str(),
                record.header.takes_blake3.as_str(),
            ))
            .or_default()
            .push(record);
    }
    let mut roots: BTreeMap<&str, BTreeSet<&str>> = BTreeMap::new();
    for record in records {
        let paths = roots.entry(record.header.root.as_str()).or_default();
        paths.extend(record.takes.iter().map(|t| t.path.as_str()));
    }
    let mut disk: BTreeMap<&str, Vec<TakeIdentity>> = BTreeMap::new();
    for (root, paths) in &roots {
        if !Path::new(root).is_dir() {
            wrong.push(format!(
                "the takes' folder {root}, where the shards found them, is not here: collect \
                 where the takes are"
            ));
            return false;
        }
        let paths: Vec<&str> = paths.iter().copied().collect();
        let now: Vec<TakeIdentity> = paths
            .par_iter()
            .filter_map(|p| {
                let relative = safe_relative(p)?;
                TakeIdentity::of(&Path::new(root).join(&relative), &relative).ok()
            })
            .collect();
        disk.insert(root, now);
    }
    let distinct: BTreeSet<&str> = records
        .iter()
        .map(|r| r.header.takes_blake3.as_str())
        .collect();
    for ((root, _), members) in &groups {
        let changes = takes_changes(&members[0].takes, &disk[*root]);
        if changes.is_empty() {
            continue;
        }
        agree = false;
        let names: Vec<String> = members.iter().map(|r| shard_name(r)).collect();
        wrong.push(format!(
            "the takes changed since {} ran{}: {}: run {} again with --resume",
            kinergy_io::list_some(&names, NAMED),
            if distinct.len() > 1 {
                " (the shards saw different takes)"
            } else {
                ""
            },
            some(&changes),
            if names.len() == 1 { "it" } else { "them" },
        ));
    }
    if agree && distinct.len() > 1 {
        // Each shard's takes are still on disk as it saw them, yet the shards saw different
        // lists (a take added or moved between them changed the library's root): no shard's
        // list is the library's.
        let seen: Vec<String> = groups
            .iter()
            .map(|((root, _), members)| {
                let names: Vec<String> = members.iter().map(|r| shard_name(r)).collect();
                format!(
                    "{} saw {} takes under {root}",
                    kinergy_io::list_some(&names, NAMED),
                    members[0].takes.len()
                )
            })
            .collect();
        // The takes not every shard saw, by their full paths (the roots differ).
        let lists: Vec<BTreeSet<String>> = groups
            .iter()
            .map(|((root, _), members)| {
                members[0]
                    .takes
                    .iter()
                    .map(|t| format!("{}/{}", root.trim_end_matches('/'), t.path))
                    .collect()
            })
            .collect();
        let every: BTreeSet<&String> = lists.iter().flatten().collect();
        let differ: Vec<String> = every
            .into_iter()
            .filter(|t| !lists.iter().all(|l| l.contains(*t)))
            .cloned()
            .collect();
        wrong.push(format!(
            "the shards saw different takes ({}; not seen by every shard: {}): a take was \
             added, removed or moved between them: run every shard again with --resume",
            seen.join("; "),
            some(&differ)
        ));
        agree = false;
    }
    agree && distinct.len() == 1
}

/// `items`, at most [`NAMED`] of them, then how many more.
fn some(items: &[String]) -> String {
    let mut out = items
        .iter()
        .take(NAMED)
        .cloned()
        .collect::<Vec<_>>()
        .join(", ");
    if items.len() > NAMED {
        out.push_str(&format!(", … ({} more)", items.len() - NAMED));
    }
    out
}

/// Each record must list the takes the library deals its shard.
fn check_deal(records: &[ShardRecord], count: usize, wrong: &mut Vec<String>) {
    let Some(first) = records.first() else {
        return;
    };
    let weights: Vec<u64> = first.takes.iter().map(TakeIdentity::weight).collect();
    let shard_of = deal(&weights, count);
    for record in records {
        let expected: BTreeSet<&str> = first
            .takes
            .iter()
            .zip(&shard_of)
            .filter(|(_, s)| **s == record.shard.0)
            .map(|(t, _)| t.path.as_str())
            .collect();
        let listed = listed_takes(record);
        if listed != expected {
            let odd: Vec<String> = listed
                .symmetric_difference(&expected)
                .map(|s| s.to_string())
                .collect();
            wrong.push(format!(
                "{}'s record lists other takes than the library deals it ({}): run it again \
                 with --resume",
                shard_name(record),
                some(&odd)
            ));
        }
    }
}

/// The takes a shard's record lists as dealt to it.
fn listed_takes(record: &ShardRecord) -> BTreeSet<&str> {
    record
        .rows
        .iter()
        .filter(|r| r.kind == "take")
        .map(|r| r.clip.as_str())
        .collect()
}

/// The rows of `library.csv` and `skipped.csv` the records give, each result checked
/// against the hash recorded for it (and, where the shards saw the same takes, recorded
/// once), with the root of each reach's record; fingerprinted with the person rule
/// `person` where given.
fn tabled<'r>(
    dir: &Path,
    records: &'r [ShardRecord],
    takes_agree: bool,
    person: Option<&PersonRule>,
    wrong: &mut Vec<String>,
    missing: &mut Vec<String>,
) -> (Vec<LibraryRow>, Vec<&'r str>, Vec<SkippedRow>) {
    let mut library = Vec::new();
    let mut roots = Vec::new();
    let mut skipped = Vec::new();
    let mut results: HashSet<&str> = HashSet::new();
    for record in records {
        let shard = shard_name(record);
        let settings = match person {
            Some(rule) => record.header.settings.clone().with_person(rule),
            None => record.header.settings.clone(),
        }
        .fingerprint();
        let dealt = listed_takes(record);
        let mut done: BTreeSet<&str> = BTreeSet::new();
        for row in &record.rows {
            match row.kind.as_str() {
                "skipped" => {
                    done.insert(&row.clip);
                    skipped.push(SkippedRow {
                        clip: row.clip.clone(),
                        why: row.why.clone(),
                    });
                }
                "reach" => {
                    done.insert(&row.clip);
                    if !dealt.contains(row.clip.as_str()) {
                        wrong.push(format!(
                            "{shard} records a reach of {}, a take it was not dealt",
                            row.clip
                        ));
                        continue;
                    }
                    // Shards that saw different takes may deal one take twice: said above.
                    if !results.insert(&row.result) && takes_agree {
                        wrong.push(format!(
                            "{}: recorded twice, for two reaches",
                            dir.join(&row.result).display()
                        ));
                        continue;
                    }
                    match reach_row(dir, row, &settings, &shard) {
                        Ok(r) => {
                            library.push(r);
                            roots.push(record.header.root.as_str());
                        }
                        Err(Problem::Missing(why)) => missing.push(why),
                        Err(Problem::Wrong(why)) => wrong.push(why),
                    }
                }
                _ => {}
            }
        }
        let not_done: Vec<&str> = dealt.difference(&done).copied().collect();
        if !not_done.is_empty() {
            missing.push(format!(
                "{shard}: {} of its takes not fitted ({}): run it again with --resume",
                not_done.len(),
                kinergy_io::list_some(&not_done, 5)
            ));
        }
    }
    (library, roots, skipped)
}

/// Names the person and motion of each of `rows` (of the records `records`, each row's
/// under `roots`) by `rule` instead of as the records say (see [`collect_with`]).
fn relabel(
    dir: &Path,
    rows: &mut [LibraryRow],
    roots: &[&str],
    records: &[ShardRecord],
    rule: &PersonRule,
) -> Result<(), LibraryError> {
    let Some(first) = records.first() else {
        return Ok(());
    };
    let settings = &first.header.settings;
    let recorded = settings.person();
    if recorded == Some(rule.to_string().as_str()) {
        return Ok(());
    }
    // A segments file's persons are in the records where the library was fitted by a rule
    // that reads them (or before the rule was recorded, when the records always took them).
    let segments = settings.get("segments").is_some_and(|v| !v.is_null());
    let listed = segments && rule.uses_segments();
    if listed && !matches!(recorded, None | Some("auto" | "segments")) {
        return Err(LibraryError::Input {
            path: dir.join(SHARDS),
            why: format!(
                "--person {rule}: the segments file's persons are not in this library's \
                 records (it was fitted with --person {}): fit it again with --resume \
                 --person {rule} (nothing is fitted again)",
                recorded.unwrap_or("auto")
            ),
        });
    }
    let whos = rule.who_all(rows.iter().zip(roots).map(|(row, root)| {
        (
            TakeAt::new(Path::new(root), Path::new(&row.clip)),
            listed.then_some(row.person.as_str()),
        )
    }))?;
    for (row, who) in rows.iter_mut().zip(whos) {
        row.person = who.person;
        row.motion = who.motion.unwrap_or_default();
    }
    Ok(())
}

enum Problem {
    Missing(String),
    Wrong(String),
}

/// The table's row of a record's reach, its result checked against the recorded hash.
fn reach_row(
    dir: &Path,
    row: &RecordRow,
    settings: &str,
    shard: &str,
) -> Result<LibraryRow, Problem> {
    let reach = format!(
        "reach {}..{} ({} arm) of {}",
        row.onset, row.end, row.arm, row.clip
    );
    let Some(relative) = safe_relative(&row.result) else {
        return Err(Problem::Wrong(format!(
            "{shard} records the result `{}` of its {reach}: not a path inside the library",
            row.result
        )));
    };
    let path = dir.join(relative);
    match hash_file(&path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Err(Problem::Missing(format!(
            "{}: the result of {shard}'s {reach} is missing: run it again with --resume",
            path.display()
        ))),
        Err(e) => Err(Problem::Missing(format!(
            "{}: the result of {shard}'s {reach} cannot be read ({e})",
            path.display()
        ))),
        Ok((_, hash)) if hash != row.blake3 => Err(Problem::Wrong(format!(
            "{}: not the result {shard} recorded for its {reach} (its content changed since it \
             was written): run {shard} again with --resume to fit it again",
            path.display()
        ))),
        Ok(_) => LibraryRow::of_record(&path, row, settings).map_err(Problem::Wrong),
    }
}

/// `path` (`/`-separated) as a relative path of plain names, or `None` (empty, absolute,
/// `.` or `..` in it).
pub(crate) fn safe_relative(path: &str) -> Option<PathBuf> {
    let relative = Path::new(path);
    let plain = !path.is_empty()
        && relative
            .components()
            .all(|c| matches!(c, Component::Normal(_)));
    plain.then(|| relative.to_path_buf())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn collect_names_a_folder_that_is_not_a_library() {
        let e = collect(Path::new("/nonexistent/kinergy-library")).unwrap_err();
        assert!(kinergy_io::Classify::kind(&e).is_input(), "{e}");
        assert!(
            e.to_string().contains("is this a `fit --out-dir` folder?"),
            "{e}"
        );
    }

    #[test]
    fn paths_in_records_stay_inside_the_library() {
        assert_eq!(
            safe_relative("p01/r01.bvh.json"),
            Some("p01/r01.bvh.json".into())
        );
        for bad in ["", "/etc/passwd", "../x.json", "p01/../../x", "./x"] {
            assert_eq!(safe_relative(bad), None, "{bad}");
        }
    }

    /// A record named for a sharding of a million or 10^11 shards is refused by its name:
    /// nothing is allocated or said per shard.
    #[test]
    fn absurd_record_names_are_refused_without_a_word_per_shard() {
        let dir = tempfile::tempdir().unwrap();
        let shards = dir.path().join(SHARDS);
        std::fs::create_dir(&shards).unwrap();
        for name in [
            "1-of-99999999999.csv",
            "1-of-1000000.csv",
            "2-of-1.csv",
            "0-of-1.csv",
            "01-of-1.csv",
        ] {
            std::fs::write(shards.join(name), "").unwrap();
        }
        let e = collect(dir.path()).unwrap_err();
        let text = e.to_string();
        assert!(matches!(e, LibraryError::Refused { .. }), "{text}");
        for name in [
            "1-of-99999999999.csv",
            "1-of-1000000.csv",
            "2-of-1.csv",
            "0-of-1.csv",
            "01-of-1.csv",
        ] {
            assert!(text.contains(name), "{name}: {text}");
        }
        assert!(text.len() < 2000, "{} bytes", text.len());
        assert!(!dir.path().join(LIBRARY).exists());
    }
}
