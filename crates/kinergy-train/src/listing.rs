//! A capture's labelled segments — reach, return, other — arm by arm, as `kinergy segment`
//! and Python's `kinergy.segment` list them: the report each prints, and the segments-file
//! rows of the segments listed.
//!
//! Frames are `onset..end`, numbered from 0, end excluded ([`FRAMES`]).

use std::path::Path;

use kinergy_io::{Classify, ErrorKind, InvalidSetting};
use kinergy_motion::segment::{Segment, SegmentSettings, Selection, find_segments, main_index};
use kinergy_motion::{ArmJoints, Clip, MotionError, Side};
use serde::Serialize;

use crate::segments_file::{SegmentRow, default_person};
use crate::source::{Capture, Skipped};
use crate::{Result, TrainError};

/// The frame convention, said once in every listing.
pub const FRAMES: &str =
    "frames onset..end: numbered from 0, end excluded, as --frames A..B takes them";

/// What to list: which segments, and how the hand's speed is measured.
#[derive(Debug, Clone, Copy, Default)]
pub struct SegmentListing {
    /// The segments listed: every one (None), the main reach, every reach or one by number.
    pub selection: Option<Selection>,
    /// How segments are found.
    pub settings: SegmentSettings,
}

/// One segment as a listing shows it.
#[derive(Debug, Clone, Serialize)]
pub struct ListedSegment {
    /// Its number among the arm's segments, from 0.
    pub index: usize,
    /// `onset..end`.
    pub frames: String,
    /// First frame.
    pub onset: usize,
    /// The frame of peak speed.
    pub peak: usize,
    /// One past the last frame.
    pub end: usize,
    /// `reach`, `return` or `other`.
    pub label: &'static str,
    /// Cut by either end of the clip.
    pub truncated: bool,
    /// Cut by the clip's start.
    pub truncated_start: bool,
    /// Cut by the clip's end.
    pub truncated_end: bool,
    /// Onset, seconds.
    pub onset_s: f64,
    /// Peak, seconds.
    pub peak_s: f64,
    /// Duration, seconds.
    pub duration_s: f64,
    /// Peak hand speed, m/s.
    pub peak_speed_m_s: f64,
    /// How far the hand moves, meters.
    pub displacement_m: f64,
    /// The segment was read in the world although the listing is relative to the shoulder (a
    /// reach the trunk carries, `kinergy_motion::segment` step 7): its speed and `moves` are
    /// the world hand's.
    pub in_world: bool,
    /// The clip's main reach.
    pub main: bool,
}

/// One arm of one capture, listed.
#[derive(Debug, Clone, Serialize)]
pub struct ArmListing {
    /// The capture.
    pub clip: String,
    /// The person (the capture's folder name).
    pub person: String,
    /// The arm's side.
    pub side: Side,
    /// The arm's joints, shoulder first.
    pub arm: Vec<String>,
    /// The clip's frames.
    pub frames: usize,
    /// Seconds per frame.
    pub frame_time_s: f64,
    /// `world` or `relative to the shoulder`.
    pub speed: &'static str,
    /// [`FRAMES`].
    pub frame_convention: &'static str,
    /// The main reach's index, if any.
    pub main: Option<usize>,
    /// The segments listed.
    pub segments: Vec<ListedSegment>,
    /// The listed segments as segments-file rows.
    #[serde(skip)]
    pub rows: Vec<SegmentRow>,
}

impl SegmentListing {
    /// Checks the settings: the slowest peak within [`crate::limits::MIN_PEAK_SPEED`], then
    /// every segmentation setting.
    pub fn validate(&self) -> Result<()> {
        let speed = self.settings.min_peak_speed;
        InvalidSetting::in_range("min_peak_speed", speed, crate::limits::MIN_PEAK_SPEED)?;
        Ok(self.settings.validate()?)
    }

    /// The arm `arm` of `clip` (read from `path`): the selected segments, numbered as in the
    /// full list. `side` is the arm's side when its joints do not say (a chain named by
    /// joints).
    pub fn arm(&self, path: &Path, clip: &Clip, arm: &ArmJoints, side: Side) -> Result<ArmListing> {
        self.listed(path, clip, arm, side, None)
    }

    /// Every arm of `clip` that reaches, as `fit --arm auto` finds them (the main reach or
    /// every reach), or why none does.
    pub fn reaching_arms(
        &self,
        path: &Path,
        clip: &Clip,
    ) -> Result<std::result::Result<Vec<ArmListing>, Skipped>> {
        // `fit --arm auto` finds the arms that reach by the hand's speed relative to the
        // shoulder; in the world a walk's swinging arms would "reach".
        InvalidSetting::require(
            self.settings.relative_to_shoulder,
            "world",
            "the arms that reach are found as `fit --arm auto` finds them, by the hand's speed \
             relative to the shoulder (in the world, walking and torso motion count as \
             reaching): choose an arm to list its world-speed segments",
        )?;
        let capture = Capture::from_clip(path, clip.clone());
        match capture.reaching_segments(self.selection.unwrap_or_default(), &self.settings) {
            Ok(arms) => arms
                .iter()
                .map(|(arm, kept)| {
                    let side = arm.side.unwrap_or(Side::Right);
                    self.listed(path, clip, arm, side, Some(kept))
                })
                .collect::<Result<Vec<_>>>()
                .map(Ok),
            Err(e) if e.kind() == ErrorKind::NothingToFit => Ok(Err(Skipped {
                clip: path.to_path_buf(),
                why: match e {
                    TrainError::NothingToFit { why, .. } => why,
                    e => e.to_string(),
                },
            })),
            Err(e) => Err(e),
        }
    }

    fn listed(
        &self,
        path: &Path,
        clip: &Clip,
        arm: &ArmJoints,
        side: Side,
        kept: Option<&[Segment]>,
    ) -> Result<ArmListing> {
        let name = path.display().to_string();
        // Bad input, naming the capture: the settings or the selection do not fit it.
        let refused = |e: MotionError| match e {
            MotionError::Reach { clip, why } => TrainError::Reach { clip, why },
            e => TrainError::Reach {
                clip: name.clone(),
                why: e.to_string(),
            },
        };
        let found = find_segments(clip, arm, &self.settings).map_err(refused)?;
        let main = main_index(&found);
        let chosen: Vec<Segment> = match (kept, self.selection) {
            (Some(kept), _) => kept.to_vec(),
            (None, None) => found.clone(),
            (None, Some(selection)) => {
                kinergy_motion::segment::select(&found, selection, &name).map_err(refused)?
            }
        };
        let picked: Vec<(usize, Segment)> = found
            .iter()
            .copied()
            .enumerate()
            .filter(|(_, s)| chosen.contains(s))
            .collect();
        let dt = clip.frame_time();
        Ok(ArmListing {
            clip: name,
            person: default_person(path),
            side: arm.side.unwrap_or(side),
            arm: arm
                .names(clip.skeleton())
                .into_iter()
                .map(String::from)
                .collect(),
            frames: clip.frame_count(),
            frame_time_s: dt,
            speed: if self.settings.relative_to_shoulder {
                "relative to the shoulder"
            } else {
                "world"
            },
            frame_convention: FRAMES,
            main,
            segments: picked
                .iter()
                .map(|&(i, s)| ListedSegment {
                    index: i,
                    frames: format!("{}..{}", s.onset, s.end),
                    onset: s.onset,
                    peak: s.peak,
                    end: s.end,
                    label: s.label.as_str(),
                    truncated: s.truncated(),
                    truncated_start: s.truncated_start,
                    truncated_end: s.truncated_end,
                    onset_s: s.onset as f64 * dt,
                    peak_s: s.peak as f64 * dt,
                    duration_s: s.duration(dt),
                    peak_speed_m_s: s.peak_speed,
                    displacement_m: s.displacement,
                    in_world: s.from_world,
                    main: main == Some(i),
                })
                .collect(),
            rows: picked
                .iter()
                .map(|(_, s)| SegmentRow::new(path, s.frames(), arm.side.unwrap_or(side), s.label))
                .collect(),
        })
    }
}
