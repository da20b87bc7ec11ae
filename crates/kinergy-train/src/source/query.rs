//! A request for captured reaches, the one `fit`, `compare` and a library's shards make from
//! either front end: which frames (a window, or the labelled segments a selection takes, or
//! a segments file's rows), which arm (a side, joints by name, or every arm that reaches),
//! the base, the synergy controller and how the captures are read. A take that has nothing
//! to fit is [`Skipped`], saying why; everything else that goes wrong is an error.

use std::path::{Path, PathBuf};

use kinergy_io::{Classify, ErrorKind, InvalidSetting};
use kinergy_motion::ImportOptions;
use kinergy_motion::segment::Selection;
use kinergy_solver::BaseMode;
pub use kinergy_solver::ControllerKind;

use super::{ArmChoice, Capture, ReachFrames, rows_reaches, segment_reaches};
use crate::captured::CapturedReach;
use crate::error::{Result, TrainError};
use crate::segments_file::{SegmentRow, SegmentsFile};

/// Which arm of each take a query takes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ArmRequest {
    /// One arm, by side or by joint names.
    Arm(ArmChoice),
    /// Every arm that reaches ([`Capture::reaches_of_reaching_arms`]).
    Auto,
}

/// A take with nothing to fit: no reach on the arm asked for (or on any arm, with
/// [`ArmRequest::Auto`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Skipped {
    /// The capture.
    pub clip: PathBuf,
    /// Why, arm by arm.
    pub why: String,
}

/// A reach found, with the person a segments file's row names (`None` without one).
#[derive(Debug, Clone)]
pub struct FoundReach {
    /// The reach, its controller set.
    pub reach: CapturedReach,
    /// The person of its segments-file row.
    pub person: Option<String>,
}

/// What a query found in a set of takes: their reaches in order, and the takes skipped.
#[derive(Debug, Clone, Default)]
pub struct Found {
    /// Each take's reaches in time order (with a segments file, in its rows' order).
    pub reaches: Vec<FoundReach>,
    /// The takes that have nothing to fit.
    pub skipped: Vec<Skipped>,
}

impl Found {
    /// The reaches alone.
    pub fn into_reaches(self) -> Vec<CapturedReach> {
        self.reaches.into_iter().map(|f| f.reach).collect()
    }

    /// `Err(`[`TrainError::NothingFound`]`)` when no take gave a reach (every one skipped);
    /// the found reaches otherwise.
    pub fn require_some(self) -> Result<Found> {
        if self.reaches.is_empty() {
            return Err(nothing_found(&self.skipped));
        }
        Ok(self)
    }
}

/// How many skipped takes [`nothing_found`]'s message names.
const LISTED: usize = 5;

/// The error of a set of takes that gave no reach, every one of them `skipped`.
pub fn nothing_found(skipped: &[Skipped]) -> TrainError {
    match skipped {
        [one] => TrainError::NothingToFit {
            path: one.clip.clone(),
            why: one.why.clone(),
        },
        _ => {
            let mut listed = skipped
                .iter()
                .take(LISTED)
                .map(|s| {
                    format!(
                        "{}: {}",
                        s.clip.display(),
                        kinergy_io::clip_text(&s.why, 200)
                    )
                })
                .collect::<Vec<_>>()
                .join("; ");
            if skipped.len() > LISTED {
                listed.push_str(&format!("; … ({} more)", skipped.len() - LISTED));
            }
            TrainError::NothingFound {
                takes: skipped.len(),
                listed,
            }
        }
    }
}

/// Why every arm that reaches takes no window.
const AUTO_WINDOW: &str =
    "arm auto finds each take's reaches: drop the frames (one window for every take and arm)";

/// A request for the reaches of captures.
#[derive(Debug, Clone)]
pub struct ReachQuery {
    /// Which frames are reaches (ignored for takes with segments-file rows).
    pub frames: ReachFrames,
    /// Which arm (ignored for takes with segments-file rows, which name theirs).
    pub arm: ArmRequest,
    /// Whether the shoulder replays the capture's torso or stays where it starts.
    pub base: BaseMode,
    /// The synergy controller the reaches are synthesized with.
    pub controller: ControllerKind,
    /// How the captures are read.
    pub read: ImportOptions,
}

impl Default for ReachQuery {
    /// The main reach of the right arm, the torso replayed, the smooth controller.
    fn default() -> ReachQuery {
        ReachQuery {
            frames: ReachFrames::Segments(Selection::Main),
            arm: ArmRequest::Arm(ArmChoice::side(kinergy_motion::Side::Right)),
            base: BaseMode::Replay,
            controller: ControllerKind::Smooth,
            read: ImportOptions::default(),
        }
    }
}

impl ReachQuery {
    /// Checks, before any work, that the frames suit the arm: every arm that reaches finds
    /// its own reaches, so not with one window for every take, nor one numbered segment
    /// (of which arm?).
    pub fn validate(&self) -> std::result::Result<(), InvalidSetting> {
        if self.arm != ArmRequest::Auto {
            return Ok(());
        }
        match &self.frames {
            ReachFrames::Window(_) => Err(InvalidSetting::new("frames", AUTO_WINDOW)),
            ReachFrames::Segments(Selection::Nth(n)) => Err(InvalidSetting::new(
                "select",
                format!("{n}: one numbered segment names no arm: with arm auto select main or all"),
            )),
            ReachFrames::Segments(_) => Ok(()),
        }
    }

    /// The reaches of `capture`, the controller set: `Ok(Err(skipped))` when it has
    /// nothing to fit. A numbered segment the take lacks is an error (a wrong selection),
    /// not an empty take.
    pub fn take(
        &self,
        capture: &Capture,
    ) -> Result<std::result::Result<Vec<CapturedReach>, Skipped>> {
        let found = match (&self.arm, &self.frames) {
            (ArmRequest::Auto, ReachFrames::Segments(selection)) => {
                capture.reaches_of_reaching_arms(*selection, self.base)
            }
            (ArmRequest::Auto, ReachFrames::Window(_)) => {
                Err(InvalidSetting::new("frames", AUTO_WINDOW).into())
            }
            (ArmRequest::Arm(arm), frames) => capture.reaches(arm, frames, self.base),
        };
        match found {
            Ok(reaches) => Ok(Ok(reaches
                .into_iter()
                .map(|r| r.under(self.controller))
                .collect())),
            Err(e)
                if e.kind() == ErrorKind::NothingToFit
                    && !matches!(self.frames, ReachFrames::Segments(Selection::Nth(_))) =>
            {
                Ok(Err(Skipped {
                    clip: capture.path().to_path_buf(),
                    why: skip_reason(&e),
                }))
            }
            Err(e) => Err(e),
        }
    }

    /// [`take`](Self::take) of the capture at `path`, read with the query's options.
    pub fn take_at(&self, path: &Path) -> Result<std::result::Result<Vec<CapturedReach>, Skipped>> {
        self.take(&Capture::read(path, &self.read)?)
    }

    /// The reaches the segments file's `rows` (all of the take at `path`) give, with the
    /// persons they name and the controller set; errors name the file and the line.
    pub fn rows(
        &self,
        segments: &SegmentsFile,
        rows: &[&SegmentRow],
        path: &Path,
    ) -> Result<Vec<FoundReach>> {
        let found = rows_reaches(segments, rows, path, &self.read, self.base)?;
        Ok(found
            .into_iter()
            .map(|(reach, row)| FoundReach {
                reach: reach.under(self.controller),
                person: Some(row.person.clone()),
            })
            .collect())
    }

    /// The reaches of `takes` in order (each a file to read, or a capture already read),
    /// and the takes skipped. Nothing is fitted here; an error stops at the first take
    /// that cannot be read or has no such arm.
    pub fn find(&self, takes: impl IntoIterator<Item = Take>) -> Result<Found> {
        let mut found = Found::default();
        for take in takes {
            let capture = match take {
                Take::File(path) => Capture::read(&path, &self.read)?,
                Take::Read(capture) => capture,
            };
            match self.take(&capture)? {
                Ok(reaches) => found
                    .reaches
                    .extend(reaches.into_iter().map(|reach| FoundReach {
                        reach,
                        person: None,
                    })),
                Err(skip) => found.skipped.push(skip),
            }
        }
        Ok(found)
    }

    /// The reaches the rows of the segments file `segments` give for `clips` (every row
    /// checked before anything is fitted: a clip that cannot be read, frames outside it, an
    /// arm its skeleton lacks, each named by its line), with their persons.
    pub fn find_rows(&self, segments: &SegmentsFile, clips: &[PathBuf]) -> Result<Found> {
        let reaches = segment_reaches(segments, clips, &self.read, self.base)?
            .into_iter()
            .map(|(reach, row)| FoundReach {
                reach: reach.under(self.controller),
                person: Some(row.person.clone()),
            })
            .collect();
        Ok(Found {
            reaches,
            skipped: Vec::new(),
        })
    }
}

/// A take a query reads: a file, or a capture already in memory.
#[derive(Debug, Clone)]
pub enum Take {
    /// A capture file, read with the query's options.
    File(PathBuf),
    /// A capture already read.
    Read(Capture),
}

/// The reason of a nothing-to-fit error, without the clip's name it starts with.
fn skip_reason(e: &TrainError) -> String {
    match e {
        TrainError::NothingToFit { why, .. } => why.clone(),
        TrainError::Motion(kinergy_motion::MotionError::Reach { why, .. }) => why.clone(),
        e => e.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arm_auto_refuses_one_window_and_one_numbered_segment() {
        let auto = |frames| ReachQuery {
            frames,
            arm: ArmRequest::Auto,
            ..ReachQuery::default()
        };
        assert_eq!(
            auto(ReachFrames::Window(1..9))
                .validate()
                .unwrap_err()
                .field,
            "frames"
        );
        assert_eq!(
            auto(ReachFrames::Segments(Selection::Nth(2)))
                .validate()
                .unwrap_err()
                .field,
            "select"
        );
        assert!(
            auto(ReachFrames::Segments(Selection::All))
                .validate()
                .is_ok()
        );
        assert!(ReachQuery::default().validate().is_ok());
    }

    #[test]
    fn takes_that_all_have_nothing_to_fit_are_one_error_of_that_kind() {
        let skip = |n: usize| Skipped {
            clip: PathBuf::from(format!("t{n}.bvh")),
            why: "no main reach".into(),
        };
        let one = Found {
            skipped: vec![skip(1)],
            ..Found::default()
        };
        let e = one.require_some().unwrap_err();
        assert_eq!(e.kind(), ErrorKind::NothingToFit);
        assert_eq!(e.to_string(), "t1.bvh: nothing to fit: no main reach");
        let many = Found {
            skipped: (1..=7).map(skip).collect(),
            ..Found::default()
        };
        let e = many.require_some().unwrap_err();
        assert_eq!(e.kind(), ErrorKind::NothingToFit);
        let text = e.to_string();
        assert!(
            text.starts_with("nothing to fit: all 7 takes were skipped"),
            "{text}"
        );
        assert!(
            text.contains("t5.bvh") && !text.contains("t6.bvh"),
            "{text}"
        );
    }
}
