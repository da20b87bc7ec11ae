//! Where a library's results go: a take's result is named by its path from the library's
//! common folder, with `.json` — `p01/r01.json`; `p01/r01_<onset>-<end>.json` when the take
//! gives several reaches, and `_<arm>` after the frames when two of them share their frames
//! (they differ by arm).

use std::collections::HashMap;
use std::ops::Range;
use std::path::{Component, Path, PathBuf};

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
        }
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
                None => names.push(relative_name(&self.common, take).with_extension("json")),
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

fn canonical(path: &Path) -> PathBuf {
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
pub fn take_names(common: &Path, take: &Path, reaches: &[CapturedReach]) -> Vec<PathBuf> {
    let keys: Vec<(Range<usize>, String)> = reaches
        .iter()
        .map(|r| (r.frames().clone(), arm_label(r)))
        .collect();
    names_of(common, take, &keys)
}

/// [`take_names`] for reaches given by their frames and arm labels.
pub fn names_of(common: &Path, take: &Path, reaches: &[(Range<usize>, String)]) -> Vec<PathBuf> {
    let relative = relative_name(common, take);
    let stem = relative
        .file_stem()
        .map_or_else(|| "clip".into(), |s| s.to_string_lossy().into_owned());
    reaches
        .iter()
        .map(|(frames, arm)| {
            let same_frames = reaches.iter().filter(|(f, _)| f == frames).count() > 1;
            let (start, end) = (frames.start, frames.end);
            let name = match (reaches.len() > 1, same_frames) {
                (false, _) => format!("{stem}.json"),
                (true, false) => format!("{stem}_{start}-{end}.json"),
                (true, true) => format!("{stem}_{start}-{end}_{arm}.json"),
            };
            relative.with_file_name(name)
        })
        .collect()
}

/// The arm of a reach as a result name says it: its side, or its first joint's name where
/// the side is unclear (joints named by hand), made safe for a file name.
fn arm_label(reach: &CapturedReach) -> String {
    let arm = reach.fitted_arm();
    match (arm.side, arm.joints.first()) {
        (Some(side), _) => side.to_string(),
        (None, Some(joint)) => joint
            .chars()
            .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
            .collect(),
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

    #[test]
    fn several_reaches_of_a_take_are_named_by_frames_and_by_arm_where_frames_repeat() {
        let common = Path::new("/lib");
        let take = Path::new("/lib/p01/r01.bvh");
        let one = names_of(common, take, &[(3..40, "right".into())]);
        assert_eq!(one, [PathBuf::from("p01/r01.json")]);
        let two = names_of(
            common,
            take,
            &[(3..40, "right".into()), (50..90, "right".into())],
        );
        assert_eq!(
            two,
            [
                PathBuf::from("p01/r01_3-40.json"),
                PathBuf::from("p01/r01_50-90.json")
            ]
        );
        let both_hands = names_of(
            common,
            take,
            &[(3..40, "right".into()), (3..40, "left".into())],
        );
        assert_eq!(
            both_hands,
            [
                PathBuf::from("p01/r01_3-40_right.json"),
                PathBuf::from("p01/r01_3-40_left.json")
            ]
        );
    }

    #[test]
    fn the_common_folder_is_the_deepest_shared_one() {
        let paths = [PathBuf::from("/a/b/c/x.bvh"), PathBuf::from("/a/b/d/y.bvh")];
        assert_eq!(common_folder(&paths), PathBuf::from("/a/b"));
        assert_eq!(common_folder(&paths[..1]), PathBuf::from("/a/b/c"));
    }
}
