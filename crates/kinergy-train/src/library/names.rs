//! Where a library's results go. A reach's result is named by its take's path from the
//! library's root (the takes' common folder), the take's whole file name kept, then
//! `.json`: `p01/r01.bvh.json`. A take that gives several reaches adds each one's frames
//! after an `@` — `p01/r01.bvh@120-245.json` — and, where two of them share their frames
//! (they differ by arm), the arm after another `@`: `r01.bvh@6-72@left.json`.
//!
//! The names are unique by construction: an `@` in a take's own file name is written twice
//! (`a@b.bvh` → `a@@b.bvh.json`), so the first single `@` of a result's name ends the take's
//! name; what follows it (frames, and an arm label whose characters other than letters,
//! digits, `-` and `_` are written `%XX`) has no `@` but the separators. Two different
//! (take, reach) pairs never get one name (a property test checks it).
//!
//! The folders of a take's path are kept as they are, but for three kinds of name, which
//! get an `@` added at their end ([`folder_name`]):
//! - a folder whose name ends in `.json` (any case), which a take's result could be named
//!   (`r.bvh.json/a.bvh` → `r.bvh.json@/a.bvh.json`, beside `r.bvh`'s `r.bvh.json`);
//! - at the root, the library's own names, [`RESERVED`]: `shards`, `library.csv` and
//!   `skipped.csv` (any case): `shards/a.bvh` → `shards@/a.bvh.json`;
//! - a folder whose name already ends in `@` (`x@/a.bvh` → `x@@/a.bvh.json`), so that no
//!   two folders are written alike.
//!
//! So a result file's name always ends in `.json` and a results folder's never does, no
//! results folder is one of the library's own files, and two folders of takes are never
//! one folder of results.

use std::collections::HashMap;
use std::ffi::{OsStr, OsString};
use std::ops::Range;
use std::path::{Component, Path, PathBuf};

use super::table::{LIBRARY, SHARDS, SKIPPED};
use crate::CapturedReach;
use crate::segments_file::{SegmentRow, SegmentsFile};

/// A library's takes, found once: each capture once (the first spelling kept), in the
/// library's order, their common folder (results are named from it) and, with a segments
/// file, its rows by clip.
#[derive(Debug)]
pub struct Takes<'a> {
    /// Each capture once.
    pub paths: Vec<PathBuf>,
    /// Their common folder (of their canonical paths).
    pub common: PathBuf,
    /// The segments file the reaches come from, if any.
    segments: Option<&'a SegmentsFile>,
    /// With a segments file, its rows by clip ([`SegmentsFile::rows_by_clip`]).
    rows: Option<HashMap<PathBuf, Vec<&'a SegmentRow>>>,
    /// The folders the takes were found in by walking them (canonical), where `collect`
    /// looks for takes added since ([`Takes::walked_from`]).
    pub folders: Vec<PathBuf>,
}

impl<'a> Takes<'a> {
    /// The takes of `paths` (a segments file may name one capture as `a/r01.bvh` and
    /// `a/../a/r01.bvh`: it is one take), with the rows of `segments` where given.
    pub fn of(paths: &[PathBuf], segments: Option<&'a SegmentsFile>) -> Takes<'a> {
        let paths = unique_takes(paths);
        let canonical: Vec<PathBuf> = paths.iter().map(|t| canonical(t)).collect();
        Takes {
            common: common_folder(&canonical),
            paths,
            segments,
            rows: segments.map(SegmentsFile::rows_by_clip),
            folders: Vec::new(),
        }
    }

    /// The same takes, found by walking the folders among `given` (the paths the user gave,
    /// files and folders): `collect` walks them again and names a take added since the
    /// shards ran.
    pub fn walked_from(self, given: &[PathBuf]) -> Takes<'a> {
        let mut folders: Vec<PathBuf> = given
            .iter()
            .filter(|p| p.is_dir())
            .map(|p| canonical(p))
            .collect();
        folders.sort();
        folders.dedup();
        Takes { folders, ..self }
    }

    /// The segments file the takes came with, if any.
    pub fn segments(&self) -> Option<&'a SegmentsFile> {
        self.segments
    }

    /// The segments file, with its rows of `take`, when the takes came with one.
    pub fn rows_of(&self, take: &Path) -> Option<(&'a SegmentsFile, &[&'a SegmentRow])> {
        let (segments, index) = (self.segments?, self.rows.as_ref()?);
        let rows = index
            .get(&SegmentsFile::clip_key(take))
            .map_or(&[][..], Vec::as_slice);
        Some((segments, rows))
    }

    /// The result names known before any take is read: with a segments file every result's
    /// (its rows give the reaches), otherwise each take's first (a take's further reaches
    /// are named as they are found). For the check that no result is written over an input.
    pub fn first_names(&self) -> Vec<PathBuf> {
        let mut names = Vec::new();
        for take in &self.paths {
            match self.rows_of(take) {
                Some((_, rows)) => {
                    let keys: Vec<_> = rows
                        .iter()
                        .map(|r| (r.frames.clone(), r.arm.to_string()))
                        .collect();
                    names.extend(names_of(&self.common, take, &keys));
                }
                None => names.extend(result_names(
                    &relative_name(&self.common, take),
                    &[(0..0, String::new())],
                )),
            }
        }
        names
    }
}

/// The takes `paths` name, each file once (the first spelling kept).
pub fn unique_takes(paths: &[PathBuf]) -> Vec<PathBuf> {
    let mut seen = std::collections::HashSet::new();
    paths
        .iter()
        .filter(|p| seen.insert(canonical(p)))
        .cloned()
        .collect()
}

pub(crate) fn canonical(path: &Path) -> PathBuf {
    std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf())
}

/// The capture `take`'s path from the folder `common` (canonical paths; plain names only,
/// never `..`): where its results go in the output folder.
pub fn relative_name(common: &Path, take: &Path) -> PathBuf {
    let path = canonical(take);
    let relative = path.strip_prefix(common).unwrap_or(&path);
    relative
        .components()
        .filter(|c| matches!(c, Component::Normal(_)))
        .collect()
}

/// The result names of the reaches of the capture `take` (in order), relative to the
/// output folder (see [`Takes`] and the library folder layout).
pub fn take_names<'r>(
    common: &Path,
    take: &Path,
    reaches: impl IntoIterator<Item = &'r CapturedReach>,
) -> Vec<PathBuf> {
    let keys: Vec<(Range<usize>, String)> = reaches
        .into_iter()
        .map(|r| (r.frames().clone(), arm_label(r)))
        .collect();
    names_of(common, take, &keys)
}

/// [`take_names`] for reaches given by their frames and arm labels.
pub fn names_of(common: &Path, take: &Path, reaches: &[(Range<usize>, String)]) -> Vec<PathBuf> {
    result_names(&relative_name(common, take), reaches)
}

/// The library's own names at its root, which no folder of results may have (compared
/// without regard to case, for file systems that ignore it).
pub const RESERVED: [&str; 3] = [SHARDS, LIBRARY, SKIPPED];

/// How a folder of a take's path from the root is named among the results: `name` as it
/// is, or with an `@` added where it ends in `.json`, in `@`, or (at the root, `top`) is one
/// of the [`RESERVED`] names (see the [module docs](self)).
pub fn folder_name(name: &OsStr, top: bool) -> OsString {
    // The tests are on ASCII, which a lossy conversion keeps; the name itself is kept whole.
    let lower = name.to_string_lossy().to_ascii_lowercase();
    let reserved = top && RESERVED.iter().any(|r| lower == *r);
    let mut out = name.to_os_string();
    if reserved || lower.ends_with(".json") || lower.ends_with('@') {
        out.push("@");
    }
    out
}

/// The folder of the results of the take at `relative` (its path from the library's root),
/// relative to the library folder: its folders, each named by [`folder_name`].
pub fn result_folder(relative: &Path) -> PathBuf {
    let folders = relative.parent().unwrap_or(Path::new(""));
    folders
        .components()
        .enumerate()
        .map(|(i, c)| folder_name(c.as_os_str(), i == 0))
        .collect()
}

/// The result names of the reaches `reaches` (frames and arm label, each pair once) of the
/// take at `relative` (its path from the library's root), as the module docs describe.
pub fn result_names(relative: &Path, reaches: &[(Range<usize>, String)]) -> Vec<PathBuf> {
    let folder = result_folder(relative);
    let file = relative
        .file_name()
        .map_or_else(|| "clip".into(), |s| s.to_string_lossy().into_owned())
        .replace('@', "@@");
    reaches
        .iter()
        .map(|(frames, arm)| {
            let same_frames = reaches.iter().filter(|(f, _)| f == frames).count() > 1;
            let (start, end) = (frames.start, frames.end);
            let suffix = match (reaches.len() > 1, same_frames) {
                (false, _) => ".json".to_string(),
                (true, false) => format!("@{start}-{end}.json"),
                (true, true) => format!("@{start}-{end}@{}.json", label(arm)),
            };
            folder.join(within_name_limit(&file, &suffix))
        })
        .collect()
}

/// The longest file name most file systems take, bytes.
pub const NAME_LIMIT: usize = 255;

/// `file` (a take's escaped name) followed by `suffix`, shortened where the two pass
/// [`NAME_LIMIT`]: the name cut at a character boundary, then `~` and 16 hexadecimal digits of
/// the BLAKE3 hash of the whole name, then the suffix — so a take whose name fills the limit
/// still has results, and two long names that share their first bytes stay apart.
fn within_name_limit(file: &str, suffix: &str) -> String {
    let whole = format!("{file}{suffix}");
    if whole.len() <= NAME_LIMIT {
        return whole;
    }
    let hash = blake3::hash(whole.as_bytes()).to_hex();
    let mut keep = NAME_LIMIT.saturating_sub(suffix.len() + 17).min(file.len());
    while !file.is_char_boundary(keep) {
        keep -= 1;
    }
    format!("{}~{}{suffix}", &file[..keep], &hash[..16])
}

/// `arm` as a result name writes it: letters, digits, `-` and `_` as they are, every other
/// byte `%XX` (so no `@`, `/` or `.` is left, and two labels never write alike).
fn label(arm: &str) -> String {
    let mut out = String::with_capacity(arm.len());
    for b in arm.bytes() {
        if b.is_ascii_alphanumeric() || b == b'-' || b == b'_' {
            out.push(char::from(b));
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

/// The arm of a reach as a result name tells it apart: its side, or `joint-` and its first
/// joint's name where the side is unclear (joints named by hand).
fn arm_label(reach: &CapturedReach) -> String {
    let arm = reach.fitted_arm();
    match (arm.side, arm.joints.first()) {
        (Some(side), _) => side.to_string(),
        (None, Some(joint)) => format!("joint-{joint}"),
        (None, None) => "arm".into(),
    }
}

/// The deepest folder that holds every one of `paths`.
pub fn common_folder(paths: &[PathBuf]) -> PathBuf {
    let mut common: Option<PathBuf> = None;
    for path in paths {
        let folder = path.parent().unwrap_or(Path::new(""));
        common = Some(match common {
            None => folder.to_path_buf(),
            Some(c) => c
                .components()
                .zip(folder.components())
                .take_while(|(a, b)| a == b)
                .map(|(a, _)| a)
                .collect(),
        });
    }
    common.unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::collections::{BTreeSet, HashSet};

    #[test]
    fn several_reaches_of_a_take_are_named_by_frames_and_by_arm_where_frames_repeat() {
        let take = Path::new("p01/r01.bvh");
        let one = result_names(take, &[(3..40, "right".into())]);
        assert_eq!(one, [PathBuf::from("p01/r01.bvh.json")]);
        let two = result_names(take, &[(3..40, "right".into()), (50..90, "right".into())]);
        assert_eq!(
            two,
            [
                PathBuf::from("p01/r01.bvh@3-40.json"),
                PathBuf::from("p01/r01.bvh@50-90.json")
            ]
        );
        let both_hands = result_names(take, &[(3..40, "right".into()), (3..40, "left".into())]);
        assert_eq!(
            both_hands,
            [
                PathBuf::from("p01/r01.bvh@3-40@right.json"),
                PathBuf::from("p01/r01.bvh@3-40@left.json")
            ]
        );
    }

    /// The sweep's collision: `26_10.bvh` with two reaches and a take renamed
    /// `26_10_4-66.bvh` (or `26_10.bvh@4-66`) in one folder.
    #[test]
    fn a_take_named_like_another_take_s_reach_gets_its_own_result() {
        let lift = result_names(
            Path::new("26_10.bvh"),
            &[(4..66, "left".into()), (4..66, "right".into())],
        );
        let mut names: HashSet<PathBuf> = lift.into_iter().collect();
        for renamed in ["26_10_4-66.bvh", "26_10.bvh@4-66", "26_10.bvh@4-66@left"] {
            let one = result_names(Path::new(renamed), &[(4..66, "left".into())]);
            assert!(names.insert(one[0].clone()), "{renamed} collides: {one:?}");
        }
        assert!(names.contains(Path::new("26_10.bvh@@4-66@@left.json")));
    }

    #[test]
    fn the_common_folder_is_the_deepest_shared_one() {
        let paths = [PathBuf::from("/a/b/c/x.bvh"), PathBuf::from("/a/b/d/y.bvh")];
        assert_eq!(common_folder(&paths), PathBuf::from("/a/b"));
        assert_eq!(common_folder(&paths[..1]), PathBuf::from("/a/b/c"));
    }

    /// File names made of the characters that could fool a name: the separators, digits,
    /// dots, the escape, and a few others.
    fn file_name() -> impl Strategy<Value = String> {
        prop_oneof![
            "[a1@._%-]{1,4}(\\.bvh|@[0-9]-[0-9]|@[0-9]-[0-9]@(left|%40)|\\.json)?",
            // Names near the file systems' 255 bytes, alike but for their ends.
            "[L@]{0,2}L{236,246}[a@]{0,2}(\\.bvh|@[0-9]-[0-9])?",
        ]
        .prop_filter("a file's name", |n| {
            n != "." && n != ".." && n.len() <= NAME_LIMIT
        })
    }

    /// A take's reaches: distinct (frames, arm label) keys, labels of any characters.
    fn reach_keys() -> impl Strategy<Value = Vec<(Range<usize>, String)>> {
        prop::collection::btree_set(
            (0usize..4, 1usize..4, "(left|right|l@f|%4|[a@%.-]{0,3})"),
            1..5,
        )
        .prop_map(|keys: BTreeSet<(usize, usize, String)>| {
            keys.into_iter()
                .map(|(s, len, arm)| (s..s + len, arm))
                .collect()
        })
    }

    /// The sweep's takes whose results fell on the library's own files or on another take's
    /// results: under `shards/`, `library.csv/`, a folder named like a result.
    #[test]
    fn takes_in_folders_named_like_the_library_s_files_or_a_result_get_their_own_folder() {
        let name = |take: &str| result_names(Path::new(take), &[(1..2, "right".into())]);
        assert_eq!(name("shards/a.bvh"), [PathBuf::from("shards@/a.bvh.json")]);
        assert_eq!(
            name("Library.CSV/a.bvh"),
            [PathBuf::from("Library.CSV@/a.bvh.json")]
        );
        assert_eq!(
            name("skipped.csv/a.bvh"),
            [PathBuf::from("skipped.csv@/a.bvh.json")]
        );
        // Below the root, the library's names are anybody's.
        assert_eq!(
            name("x/shards/a.bvh"),
            [PathBuf::from("x/shards/a.bvh.json")]
        );
        assert_eq!(
            name("r.bvh.json/a.bvh"),
            [PathBuf::from("r.bvh.json@/a.bvh.json")]
        );
        assert_eq!(
            name("p/r.bvh@1-2.JSON/a.bvh"),
            [PathBuf::from("p/r.bvh@1-2.JSON@/a.bvh.json")]
        );
        assert_eq!(name("x@/a.bvh"), [PathBuf::from("x@@/a.bvh.json")]);
        assert_eq!(name("p01/r01.bvh"), [PathBuf::from("p01/r01.bvh.json")]);
        // The file next to the folder keeps its name.
        assert_eq!(name("r.bvh"), [PathBuf::from("r.bvh.json")]);
    }

    /// Folders of takes: plain, with `@`, and named like the library's files or a result.
    fn folders() -> impl Strategy<Value = String> {
        prop::collection::vec(
            "(p1|sub|p@|p@@|shards|SHARDS|library\\.csv|skipped\\.csv|r\\.bvh\\.json|a\\.JSON@?|[a.@]{1,3}\\.json@{0,2}|a@1-2\\.json)",
            0..3,
        )
        .prop_map(|parts| parts.iter().map(|p| format!("{p}/")).collect())
    }

    proptest! {
        /// No two (take, reach) pairs of a library map to one result name, no result file is
        /// a folder of other results, and none is, or is in, one of the library's own names.
        #[test]
        fn result_names_are_unique_over_takes_and_reaches(
            takes in prop::collection::btree_map(
                (folders(), file_name()).prop_map(|(d, f)| format!("{d}{f}")),
                reach_keys(),
                1..8,
            )
        ) {
            let mut seen: HashSet<PathBuf> = HashSet::new();
            let mut folders: HashSet<PathBuf> = HashSet::new();
            let mut pairs = 0;
            for (take, keys) in &takes {
                let names = result_names(Path::new(take), keys);
                prop_assert_eq!(names.len(), keys.len());
                for name in names {
                    pairs += 1;
                    // In the take's results folder, starting with its escaped file name.
                    let folder = result_folder(Path::new(take));
                    prop_assert_eq!(name.parent(), Some(folder.as_path()));
                    let file = Path::new(take).file_name().unwrap().to_string_lossy();
                    let escaped = file.replace('@', "@@");
                    let written = name.file_name().unwrap().to_string_lossy().into_owned();
                    prop_assert!(written.len() <= NAME_LIMIT, "{:?} is too long", name);
                    if written.contains('~') && !escaped.contains('~') {
                        // Shortened: a prefix of the escaped name.
                        let cut = written.split('~').next().unwrap();
                        prop_assert!(escaped.starts_with(cut));
                    } else {
                        prop_assert!(written.starts_with(&escaped));
                    }
                    prop_assert!(name.to_string_lossy().ends_with(".json"));
                    let first = name.components().next().unwrap().as_os_str().to_string_lossy();
                    let first = first.to_ascii_lowercase();
                    prop_assert!(!RESERVED.contains(&first.as_str()), "{:?} is the library's", name);
                    prop_assert!(seen.insert(name.clone()), "{:?} twice in {:?}", name, takes);
                    folders.extend(name.ancestors().skip(1).map(Path::to_path_buf));
                }
            }
            prop_assert_eq!(seen.len(), pairs);
            for name in &seen {
                prop_assert!(!folders.contains(name), "{:?} is a file and a folder in {:?}", name, takes);
            }
        }

        /// Two folders of takes are never one folder of results.
        #[test]
        fn folders_of_results_are_one_to_one(a in folders(), b in folders()) {
            let (fa, fb) = (result_folder(&Path::new(&a).join("t.bvh")), result_folder(&Path::new(&b).join("t.bvh")));
            prop_assert_eq!(a == b, fa == fb, "{:?} {:?} -> {:?} {:?}", a, b, fa, fb);
        }
    }
}
