//! Where captured reaches come from: a capture file, read with the import options, its arm
//! found by side or by joint names, and its frames chosen — a window, the labelled segments of
//! the hand-speed series ([`kinergy_motion::segment`]) or the rows of a segments file
//! ([`crate::segments_file`]) — become [`CapturedReach`]es along one path, the one `fit`, `compare`
//! and `synthesize` take.
//!
//! - [`Capture::reaches`]: a clip's reaches by [`ArmChoice`] and [`ReachFrames`];
//! - [`segment_reaches`]: the reaches a segments file's rows give, each clip read once;
//! - [`FrameChoice`]: the one reach `synthesize` makes of a capture, its frames resolved
//!   against a parameters file's fit record.
//!
//! Errors say at which step a clip failed: [`TrainError::Clip`] (reading),
//! [`TrainError::Arm`] (the arm), [`TrainError::Row`] (a segments-file row, with its line),
//! [`TrainError::Frames`] (a window outside the clip); the segments and the reach themselves
//! fail as [`kinergy_motion::segment`] and [`CapturedReach::new`] do.
//!
//! ```no_run
//! use kinergy_motion::{ImportOptions, Side};
//! use kinergy_solver::BaseMode;
//! use kinergy_motion::segment::Selection;
//! use kinergy_train::source::{ArmChoice, Capture, ReachFrames};
//!
//! let capture = Capture::read("p01/r01.bvh".as_ref(), &ImportOptions::default())?;
//! let reaches = capture.reaches(
//!     &ArmChoice::side(Side::Right),
//!     &ReachFrames::Segments(Selection::Main),
//!     BaseMode::Replay,
//! )?;
//! assert_eq!(reaches.len(), 1);
//! # Ok::<(), kinergy_train::TrainError>(())
//! ```

mod query;

pub use query::{
    ArmRequest, ControllerKind, Found, FoundReach, ReachQuery, Skipped, Take, nothing_found,
};

use std::ops::Range;
use std::path::{Path, PathBuf};

use kinergy_io::InvalidSetting;
use kinergy_motion::nalgebra::Point3;
use kinergy_motion::{ArmJoints, Clip, ImportOptions, MotionError, Side};
use kinergy_solver::{BaseMode, FitRecord};

use crate::captured::CapturedReach;
use crate::error::{Result, TrainError};
use crate::segments_file::{SegmentRow, SegmentsFile};
use kinergy_motion::segment::{Segment, SegmentSettings, Selection, find_segments, select};

/// How a capture's arm is found.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ArmChoice {
    /// Which arm; searched for by the skeleton's joint names unless `joints` names them.
    pub side: Side,
    /// The arm's joints by name: clavicle, shoulder, elbow, wrist (or shoulder, elbow, wrist).
    pub joints: Option<Vec<String>>,
}

impl ArmChoice {
    /// The arm on `side`, found by the skeleton's joint names.
    pub fn side(side: Side) -> ArmChoice {
        ArmChoice { side, joints: None }
    }

    /// The arm in `clip`, read from `path` (which the error names). [`TrainError::Arm`]
    /// when it is not there, saying whether the skeleton has an arm on the other side.
    pub fn find(&self, clip: &Clip, path: &Path) -> Result<ArmJoints> {
        let found = match &self.joints {
            Some(names) => {
                let names: Vec<&str> = names.iter().map(String::as_str).collect();
                ArmJoints::from_names(clip.skeleton(), &names)
            }
            None => ArmJoints::find(clip.skeleton(), self.side),
        };
        found.map_err(|source| {
            let other = self.side.opposite();
            let other_side = (matches!(source, MotionError::ArmNotFound { .. })
                && ArmJoints::find(clip.skeleton(), other).is_ok())
            .then_some(other);
            TrainError::Arm {
                path: path.to_path_buf(),
                source,
                other_side,
            }
        })
    }
}

/// Which frames of a capture are its reaches.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ReachFrames {
    /// One window `A..B` (numbered from 0, end excluded).
    Window(Range<usize>),
    /// The labelled segments of the hand-speed series that the selection takes.
    Segments(Selection),
}

/// With `--arm auto`, an arm's reach counts when the hand moves at least this share of the
/// most any arm of the take moves over its reach.
pub const AUTO_ARM_SHARE: f64 = 0.5;

/// A capture file, read for its reaches.
#[derive(Debug, Clone)]
pub struct Capture {
    path: PathBuf,
    clip: Clip,
}

impl Capture {
    /// Reads the capture at `path` with `options`; [`TrainError::Clip`] when it cannot be
    /// read.
    pub fn read(path: &Path, options: &ImportOptions) -> Result<Capture> {
        let (clip, _) =
            kinergy_motion::read_clip(path, options).map_err(|source| TrainError::Clip {
                path: path.to_path_buf(),
                source,
            })?;
        Ok(Capture {
            path: path.to_path_buf(),
            clip,
        })
    }

    /// A capture of `clip`, already read from `path`.
    pub fn from_clip(path: &Path, clip: Clip) -> Capture {
        Capture {
            path: path.to_path_buf(),
            clip,
        }
    }

    /// The file it was read from.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The clip.
    pub fn clip(&self) -> &Clip {
        &self.clip
    }

    /// The name its reaches take in messages and records: the path as given.
    pub fn name(&self) -> String {
        self.path.display().to_string()
    }

    /// Its reaches, in time order: the arm `arm`, the frames `frames`, the base `mode`.
    pub fn reaches(
        &self,
        arm: &ArmChoice,
        frames: &ReachFrames,
        mode: BaseMode,
    ) -> Result<Vec<CapturedReach>> {
        let joints = arm.find(&self.clip, &self.path)?;
        let name = self.name();
        let windows = match frames {
            ReachFrames::Window(window) => vec![window.clone()],
            ReachFrames::Segments(selection) => {
                let segments = find_segments(&self.clip, &joints, &SegmentSettings::default())?;
                select(&segments, *selection, &name)?
                    .iter()
                    .map(Segment::frames)
                    .collect()
            }
        };
        windows
            .into_iter()
            .map(|window| CapturedReach::new(&name, &self.clip, &joints, window, mode))
            .collect()
    }

    /// The reaches of the arms that reach (`--arm auto`): for each arm the skeleton has,
    /// the segments `selection` takes (`main` or `all`), kept where the arm moves at least
    /// [`AUTO_ARM_SHARE`] of the most any arm of the take moves (the idle arm of a one-hand
    /// raise sways; a both-hands take gives one reach per arm). Right arm first, each in
    /// time order. [`TrainError::NothingToFit`], saying what each arm does, when no arm
    /// reaches; [`TrainError::Setting`] for a selection of one numbered segment (whose arm?).
    pub fn reaches_of_reaching_arms(
        &self,
        selection: Selection,
        mode: BaseMode,
    ) -> Result<Vec<CapturedReach>> {
        let name = self.name();
        let mut reaches = Vec::new();
        for (joints, segments) in self.reaching_segments(selection, &SegmentSettings::default())? {
            for segment in segments {
                reaches.push(CapturedReach::new(
                    &name,
                    &self.clip,
                    &joints,
                    segment.frames(),
                    mode,
                )?);
            }
        }
        Ok(reaches)
    }

    /// The segments behind [`reaches_of_reaching_arms`](Self::reaches_of_reaching_arms):
    /// each reaching arm with its kept segments (never empty), right arm first, segmented
    /// with `settings`.
    pub fn reaching_segments(
        &self,
        selection: Selection,
        settings: &SegmentSettings,
    ) -> Result<Vec<(ArmJoints, Vec<Segment>)>> {
        if let Selection::Nth(_) = selection {
            return Err(TrainError::Setting(InvalidSetting::new(
                "select",
                "one numbered segment names no arm: with the arm chosen per take, select \
                      main or all",
            )));
        }
        let name = self.name();
        let mut found: Vec<(ArmJoints, Vec<Segment>)> = Vec::new();
        let mut why = Vec::new();
        for side in [Side::Right, Side::Left] {
            let Ok(joints) = ArmJoints::find(self.clip.skeleton(), side) else {
                why.push(format!("no {side} arm found"));
                continue;
            };
            let segments = find_segments(&self.clip, &joints, settings)?;
            match select(&segments, selection, &name) {
                Ok(chosen) => found.push((joints, chosen)),
                Err(MotionError::Reach { why: reason, .. }) => {
                    why.push(format!("{side} arm: {reason}"));
                }
                Err(e) => return Err(e.into()),
            }
        }
        let largest = found
            .iter()
            .flat_map(|(_, segments)| segments)
            .map(|s| s.displacement)
            .fold(0.0_f64, f64::max);
        for (_, segments) in &mut found {
            segments.retain(|s| s.displacement >= AUTO_ARM_SHARE * largest);
        }
        found.retain(|(_, segments)| !segments.is_empty());
        if found.is_empty() {
            return Err(TrainError::NothingToFit {
                path: self.path.clone(),
                why: why.join("; "),
            });
        }
        Ok(found)
    }

    /// The reach a row of the segments `file` gives of this capture: the row's frames
    /// (checked against the clip: [`TrainError::Segments`]), arm and, where it has one,
    /// target and tempo ([`CapturedReach::with_known_tempo`]). Other errors come as [`TrainError::Row`], naming the file and the row's line.
    pub fn row_reach(
        &self,
        file: &SegmentsFile,
        row: &SegmentRow,
        mode: BaseMode,
    ) -> Result<CapturedReach> {
        let frames = file.resolve(row, &self.clip)?;
        let in_row = |e: TrainError| in_row(file, row, &self.path, e);
        let joints = ArmChoice::side(row.arm)
            .find(&self.clip, &self.path)
            .map_err(in_row)?;
        let reach =
            CapturedReach::new(&self.name(), &self.clip, &joints, frames, mode).map_err(in_row)?;
        let reach = match row.tempo {
            Some(t) => reach
                .with_known_tempo(t.peak_speed_m_s, t.duration_s)
                .map_err(in_row)?,
            None => reach,
        };
        Ok(match row.target {
            Some(t) => reach.with_target(Point3::from(t)).map_err(in_row)?,
            None => reach,
        })
    }

    /// The one reach `choice` takes of this capture with the arm `joints` (see
    /// [`FrameChoice::resolve`]).
    pub fn reach(
        &self,
        joints: &ArmJoints,
        choice: &FrameChoice,
        record: Option<&FitRecord>,
        mode: BaseMode,
    ) -> Result<CapturedReach> {
        let frames = choice.resolve(&self.clip, &self.path, joints, record)?;
        CapturedReach::new(&self.name(), &self.clip, joints, frames, mode)
    }
}

/// A row's error `e` about the capture at `clip`, named by the segments file and the line.
fn in_row(file: &SegmentsFile, row: &SegmentRow, clip: &Path, e: TrainError) -> TrainError {
    TrainError::Row {
        file: file.path().to_path_buf(),
        line: row.line,
        clip: clip.to_path_buf(),
        source: Box::new(e),
    }
}

/// The clips a segments file names, in the order they first appear.
pub fn segment_clips(file: &SegmentsFile) -> Vec<PathBuf> {
    // One entry per file, however the rows spell it (`a/r01.bvh`, `a/../a/r01.bvh`).
    let mut seen = std::collections::HashSet::new();
    file.rows()
        .iter()
        .filter(|row| seen.insert(SegmentsFile::clip_key(&row.clip)))
        .map(|row| row.clip.clone())
        .collect()
}

/// The reaches the rows of the segments `file` give for `clips` (see
/// [`Capture::row_reach`]), in the order of `clips`, then of the rows, each with its row.
/// Each clip with rows is read once, with `options`; a clip without rows is skipped. A clip
/// that cannot be read is a [`TrainError::Row`] of its first row; [`TrainError::NoRows`] when
/// no row names any of the clips.
pub fn segment_reaches<'a>(
    file: &'a SegmentsFile,
    clips: &[PathBuf],
    options: &ImportOptions,
    mode: BaseMode,
) -> Result<Vec<(CapturedReach, &'a SegmentRow)>> {
    let mut out = Vec::new();
    let index = file.rows_by_clip();
    let mut seen = std::collections::HashSet::new();
    for path in clips {
        let key = SegmentsFile::clip_key(path);
        if !seen.insert(key.clone()) {
            continue; // the same file given twice: its rows once
        }
        let rows = index.get(&key).map_or(&[][..], Vec::as_slice);
        out.extend(rows_reaches(file, rows, path, options, mode)?);
    }
    if out.is_empty() {
        return Err(TrainError::NoRows {
            file: file.path().to_path_buf(),
        });
    }
    Ok(out)
}

/// The reaches `rows` (rows of the segments `file`, all of the capture at `path`) give:
/// the capture read once, each row's reach in the rows' order (see [`segment_reaches`]).
pub fn rows_reaches<'a>(
    file: &SegmentsFile,
    rows: &[&'a SegmentRow],
    path: &Path,
    options: &ImportOptions,
    mode: BaseMode,
) -> Result<Vec<(CapturedReach, &'a SegmentRow)>> {
    let Some(first) = rows.first() else {
        return Ok(Vec::new());
    };
    let capture = Capture::read(path, options).map_err(|e| in_row(file, first, path, e))?;
    rows.iter()
        .map(|row| Ok((capture.row_reach(file, row, mode)?, *row)))
        .collect()
}

/// Whether a fit record's clip `name` names the capture at `path`: the same path, or the same
/// file on disk.
pub fn names_clip(name: &str, path: &Path) -> bool {
    let clip = Path::new(name);
    clip == path
        || matches!(
            (clip.canonicalize(), path.canonicalize()),
            (Ok(a), Ok(b)) if a == b
        )
}

/// Which frames of a capture one reach covers.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum FrameChoice {
    /// The frames a parameters file's fit record holds for this capture (so a synthesis
    /// replays what the fit scored); all of them without such a record.
    Fitted,
    /// All the frames.
    All,
    /// The main reach of the hand-speed series ([`Selection::Main`]).
    Main,
    /// Segment N of the list [`find_segments`] returns, counted from 0, whatever its label.
    Nth(usize),
    /// The frames `A..B` (numbered from 0, end excluded).
    Window(Range<usize>),
}

impl FrameChoice {
    /// The frames this choice takes of `clip` (read from `path`) with the arm `joints`;
    /// `record`, the fit record of a parameters file, for [`FrameChoice::Fitted`] (its reach
    /// on the clip [`names_clip`] recognizes). [`TrainError::Frames`] unless they lie in the
    /// clip and hold at least 2 frames; a segment that is not there fails as
    /// [`select`] does.
    pub fn resolve(
        &self,
        clip: &Clip,
        path: &Path,
        joints: &ArmJoints,
        record: Option<&FitRecord>,
    ) -> Result<Range<usize>> {
        let all = 0..clip.frame_count();
        let segment = |selection: Selection| -> Result<Range<usize>> {
            let segments = find_segments(clip, joints, &SegmentSettings::default())?;
            let picked = select(&segments, selection, &path.display().to_string())?;
            Ok(picked[0].frames())
        };
        let frames = match self {
            FrameChoice::Fitted => record
                .and_then(|r| r.reach(|name| names_clip(name, path)))
                .map_or(all, |r| r.frames()),
            FrameChoice::All => all,
            FrameChoice::Main => segment(Selection::Main)?,
            FrameChoice::Nth(n) => segment(Selection::Nth(*n))?,
            FrameChoice::Window(window) => window.clone(),
        };
        if frames.end > clip.frame_count() || frames.len() < 2 {
            return Err(TrainError::Frames {
                clip: path.display().to_string(),
                frames,
                available: clip.frame_count(),
            });
        }
        Ok(frames)
    }
}

/// The captures `paths` name, as [`walk_captures`] finds them (the links it did not follow
/// dropped silently; [`walk_captures`] says which).
pub fn capture_files(paths: &[PathBuf]) -> Result<Vec<PathBuf>> {
    walk_captures(paths).map(|walk| walk.files)
}

/// What a walk of captures found: the files, and the links it did not follow.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct CaptureWalk {
    /// The capture files, each once, folder by folder in name order.
    pub files: Vec<PathBuf>,
    /// Each link, or second path, to a folder or file the walk had already taken, said as
    /// "`link`: the same folder as `first`, taken once".
    pub repeats: Vec<String>,
}

/// The capture files `paths` name: files as given, folders expanded to the `*.bvh` files in
/// them and in their subfolders (sorted by path). An empty result, a missing path or one that
/// is neither a file nor a folder (a device, a FIFO: reading it could block or never end) is
/// a [`TrainError::File`] naming it.
pub fn walk_captures(paths: &[PathBuf]) -> Result<CaptureWalk> {
    let bad = |path: &Path, why: String| TrainError::File {
        path: Some(path.to_path_buf()),
        why,
    };
    let mut walk = Walk::default();
    for p in paths {
        if p.is_dir() {
            let before = (walk.found.files.len(), walk.found.repeats.len());
            walk.folder(p)?;
            walk.found.files[before.0..].sort();
            if (walk.found.files.len(), walk.found.repeats.len()) == before {
                return Err(bad(p, "no .bvh files in this folder".into()));
            }
        } else if p.is_file() {
            walk.file(p);
        } else {
            return Err(bad(p, not_a_capture(p)));
        }
    }
    if walk.found.files.is_empty() {
        if walk.links.is_empty() {
            return Err(TrainError::File {
                path: None,
                why: "no clips given".into(),
            });
        }
        // Folders whose only ways on are links back (a folder holding a link to itself).
        let links: Vec<String> = walk.links.iter().map(|l| l.display().to_string()).collect();
        let why = match links.as_slice() {
            [link] => format!(
                "no captures (no .bvh file; its link {link} leads back to a folder already \
                 walked, taken once)"
            ),
            _ => format!(
                "no captures (no .bvh file; its links {} lead back to folders already walked, \
                 each taken once)",
                kinergy_io::list_some(&links, 5)
            ),
        };
        return Err(match paths {
            [folder] => bad(folder, why),
            _ => TrainError::File {
                path: None,
                why: format!(
                    "{}: {why}",
                    kinergy_io::list_some(
                        &paths
                            .iter()
                            .map(|p| p.display().to_string())
                            .collect::<Vec<_>>(),
                        5
                    )
                ),
            },
        });
    }
    Ok(walk.found)
}

/// A walk of folders that takes each folder and each file once, by what it is (its
/// canonical path), however many links lead to it: a link back to a parent neither loops
/// nor weighs one capture many times.
#[derive(Default)]
struct Walk {
    found: CaptureWalk,
    seen_dirs: std::collections::HashMap<PathBuf, PathBuf>,
    seen_files: std::collections::HashMap<PathBuf, PathBuf>,
    /// The paths to a folder already taken, as found (for the message when nothing else is).
    links: Vec<PathBuf>,
}

impl Walk {
    /// Takes the file `path` unless it was taken before.
    fn file(&mut self, path: &Path) {
        let key = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        match self.seen_files.get(&key) {
            Some(first) => self.found.repeats.push(format!(
                "{}: the same file as {}, taken once",
                path.display(),
                first.display()
            )),
            None => {
                self.seen_files.insert(key, path.to_path_buf());
                self.found.files.push(path.to_path_buf());
            }
        }
    }

    /// Every `*.bvh` file under `dir`, each folder once.
    fn folder(&mut self, dir: &Path) -> Result<()> {
        let bad = |e: std::io::Error| TrainError::File {
            path: Some(dir.to_path_buf()),
            why: e.to_string(),
        };
        let key = std::fs::canonicalize(dir).map_err(bad)?;
        if let Some(first) = self.seen_dirs.get(&key) {
            self.links.push(dir.to_path_buf());
            self.found.repeats.push(format!(
                "{}: the same folder as {}, taken once",
                dir.display(),
                first.display()
            ));
            return Ok(());
        }
        self.seen_dirs.insert(key, dir.to_path_buf());
        let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
            .map_err(bad)?
            .map(|e| e.map(|e| e.path()))
            .collect::<std::io::Result<_>>()
            .map_err(bad)?;
        // Name order, so that of two paths to one folder or file the first is the same on
        // every machine.
        entries.sort();
        for path in entries {
            if path.is_dir() {
                self.folder(&path)?;
            } else if path
                .extension()
                .is_some_and(|x| x.eq_ignore_ascii_case("bvh"))
            {
                self.file(&path);
            }
        }
        Ok(())
    }
}

/// Why `path`, neither a file nor a folder, is no capture: what it is (a device, a FIFO),
/// a symbolic link that leads nowhere or in a loop, or nothing at all; else the system's
/// reason it cannot be looked at.
fn not_a_capture(path: &Path) -> String {
    match std::fs::metadata(path) {
        Ok(metadata) => format!(
            "not a regular file ({})",
            kinergy_io::describe_file_type(&metadata)
        ),
        Err(e) if std::fs::symlink_metadata(path).is_ok() => {
            // The link itself is there: its target is not, or links lead back to it.
            if e.kind() == std::io::ErrorKind::NotFound {
                "a symbolic link to a missing file".into()
            } else if e.to_string().contains("symbolic links") {
                // ELOOP, said so by every Unix ("Too many levels of symbolic links").
                "a symbolic link loop (too many levels of symbolic links)".into()
            } else {
                format!("a symbolic link that cannot be followed: {e}")
            }
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => "no such file or folder".into(),
        Err(e) => format!("cannot be read: {e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::capture_files;
    use std::path::PathBuf;

    fn why(path: PathBuf) -> String {
        match capture_files(&[path]) {
            Err(crate::TrainError::File { why, .. }) => why,
            other => panic!("expected a file error, got {other:?}"),
        }
    }

    /// A folder with a link to itself, and two folders linking to each other, are walked
    /// once: each capture found once, the links said, nothing hangs.
    #[cfg(unix)]
    #[test]
    fn links_back_are_taken_once_and_said() {
        use std::os::unix::fs::symlink;
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a"), dir.path().join("b"));
        std::fs::create_dir_all(&a).unwrap();
        std::fs::create_dir_all(&b).unwrap();
        std::fs::write(a.join("r1.bvh"), "x").unwrap();
        std::fs::write(b.join("r2.bvh"), "x").unwrap();
        symlink(&a, a.join("self")).unwrap();
        symlink(&b, a.join("to-b")).unwrap();
        symlink(&a, b.join("to-a")).unwrap();
        symlink(a.join("r1.bvh"), b.join("same.bvh")).unwrap();
        let walk = super::walk_captures(&[dir.path().to_path_buf()]).unwrap();
        let names: Vec<_> = walk
            .files
            .iter()
            .map(|p| p.strip_prefix(dir.path()).unwrap().to_path_buf())
            .collect();
        assert_eq!(
            names,
            [PathBuf::from("a/r1.bvh"), PathBuf::from("a/to-b/r2.bvh")]
        );
        assert_eq!(walk.repeats.len(), 4, "{:?}", walk.repeats);
        assert!(
            walk.repeats
                .iter()
                .any(|r| r.contains("same.bvh: the same file as"))
        );
    }

    /// The sweep's folder holding only a link to itself, once "no clips given" naming
    /// neither: the folder and the link are named.
    #[cfg(unix)]
    #[test]
    fn a_folder_holding_only_a_link_back_names_the_folder_and_the_link() {
        let dir = tempfile::tempdir().unwrap();
        let folder = dir.path().join("selfloopdir");
        std::fs::create_dir(&folder).unwrap();
        std::os::unix::fs::symlink(&folder, folder.join("self")).unwrap();
        match capture_files(std::slice::from_ref(&folder)) {
            Err(crate::TrainError::File {
                path: Some(path),
                why,
            }) => {
                assert_eq!(path, folder);
                assert!(
                    why.starts_with("no captures")
                        && why.contains(&folder.join("self").display().to_string())
                        && why.contains("leads back to a folder already walked"),
                    "{why}"
                );
            }
            other => panic!("expected a file error, got {other:?}"),
        }
    }

    /// Issue 27 #11: each kind of non-capture is said as what it is ("no such file" was said
    /// of a symbolic link loop).
    #[cfg(unix)]
    #[test]
    fn what_is_not_a_capture_is_said_as_what_it_is() {
        let dir = tempfile::tempdir().unwrap();
        let (a, b) = (dir.path().join("a"), dir.path().join("b"));
        std::os::unix::fs::symlink(&b, &a).unwrap();
        std::os::unix::fs::symlink(&a, &b).unwrap();
        assert!(why(a).contains("symbolic link loop"));
        let dangling = dir.path().join("dangling");
        std::os::unix::fs::symlink(dir.path().join("gone"), &dangling).unwrap();
        assert!(why(dangling).contains("link to a missing file"));
        assert!(why(dir.path().join("nothing")).contains("no such file or folder"));
        assert!(why("/dev/zero".into()).contains("not a regular file (a character device)"));
        let empty = dir.path().join("empty");
        std::fs::create_dir(&empty).unwrap();
        assert!(why(empty).contains("no .bvh files"));
    }
}
