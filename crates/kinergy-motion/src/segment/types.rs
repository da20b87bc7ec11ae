//! The segmentation's data: its settings ([`SegmentSettings`]) and what it finds
//! ([`Segment`], [`Label`]). The [parent module](super) re-exports them; they live here so
//! the signal, motion and labelling steps can use them without importing their parent.

use std::fmt;
use std::ops::Range;
use std::str::FromStr;

use kinergy_io::{InvalidSetting, Num};
use serde::Serialize;

use crate::error::Result;

/// How [`find_segments`](super::find_segments) reads the hand's motion (see the [module docs](super)).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SegmentSettings {
    /// Width of the centred moving average on the speed, seconds (0: no smoothing).
    /// Default 0.05 s.
    pub smoothing: f64,
    /// A frame is at rest when its speed is below this fraction of its motion's peak speed
    /// (or below [`SegmentSettings::rest_speed`], whichever is higher). In [0, 1); default 0.1.
    pub rest_fraction: f64,
    /// The absolute rest threshold, m/s. Default 0.05 m/s.
    pub rest_speed: f64,
    /// Peaks slower than this are not motion, m/s; above `rest_speed`. Default 0.2 m/s.
    pub min_peak_speed: f64,
    /// Motions and segments shorter than this (first to last frame) are dropped, seconds.
    /// Default 0.2 s.
    pub min_duration: f64,
    /// True (the default): the hand's motion relative to the shoulder, so walking and torso
    /// translation do not count — except a reach the trunk carries (a stoop or a squat to the
    /// floor), read in the world ([module docs](super), step 7). False: the hand's motion in
    /// the world.
    pub relative_to_shoulder: bool,
    /// A speed minimum inside a motion splits it into sub-movements when it is at most this
    /// fraction of the slower of the two peaks beside it. In (0, 1]; default 0.5.
    pub split_ratio: f64,
    /// A rest at least this long ends a movement, seconds; shorter pauses do not. Default 0.1 s
    /// (a basketball shot pauses 0.07 s between gather and release; the Bandai raise-hand
    /// takes hold their hand up for 0.2 s and more).
    pub hold: f64,
    /// Sub-movements that move the hand less than this fraction of the arm's length are small:
    /// corrections, the dither of a hold, the strokes of a waving hand. Default 0.1 (5 cm for
    /// a 50 cm arm).
    pub small_move: f64,
    /// A reach moves the hand at least this fraction of the arm's length. At least
    /// `small_move`; default 0.2.
    pub min_reach: f64,
}

impl Default for SegmentSettings {
    fn default() -> Self {
        SegmentSettings {
            smoothing: 0.05,
            rest_fraction: 0.1,
            rest_speed: 0.05,
            min_peak_speed: 0.2,
            min_duration: 0.2,
            relative_to_shoulder: true,
            split_ratio: 0.5,
            hold: 0.1,
            small_move: 0.1,
            min_reach: 0.2,
        }
    }
}

impl SegmentSettings {
    /// These settings with peaks slower than `speed` (m/s) not counting as motion, and the
    /// absolute rest threshold lowered with it where it would not stay below: a quarter of
    /// `speed`, the defaults' ratio (0.05 of 0.2 m/s). Any positive `speed` then makes valid
    /// settings, so that slow motions can be found as well as fast ones.
    pub fn with_min_peak_speed(self, speed: f64) -> SegmentSettings {
        SegmentSettings {
            min_peak_speed: speed,
            rest_speed: self.rest_speed.min(speed / 4.0),
            ..self
        }
    }

    /// Checks every setting; the error names the first bad field.
    pub fn validate(&self) -> Result<()> {
        let nonneg = |v: f64| v.is_finite() && v >= 0.0;
        let seconds = |v: f64| format!("{} is not a finite number of seconds ≥ 0", Num(v));
        InvalidSetting::require(
            nonneg(self.smoothing),
            "segment.smoothing",
            seconds(self.smoothing),
        )?;
        InvalidSetting::require(
            self.rest_fraction.is_finite() && (0.0..1.0).contains(&self.rest_fraction),
            "segment.rest_fraction",
            format!("{} is not in [0, 1)", self.rest_fraction),
        )?;
        InvalidSetting::require(
            nonneg(self.rest_speed),
            "segment.rest_speed",
            format!("{} is not a finite speed ≥ 0 m/s", Num(self.rest_speed)),
        )?;
        InvalidSetting::require(
            self.min_peak_speed.is_finite() && self.min_peak_speed > self.rest_speed,
            "segment.min_peak_speed",
            format!(
                "{} is not a finite speed above rest_speed ({} m/s)",
                Num(self.min_peak_speed),
                Num(self.rest_speed)
            ),
        )?;
        InvalidSetting::require(
            nonneg(self.min_duration),
            "segment.min_duration",
            seconds(self.min_duration),
        )?;
        InvalidSetting::require(
            self.split_ratio > 0.0 && self.split_ratio <= 1.0,
            "segment.split_ratio",
            format!("{} is not in (0, 1]", self.split_ratio),
        )?;
        InvalidSetting::require(nonneg(self.hold), "segment.hold", seconds(self.hold))?;
        InvalidSetting::require(
            nonneg(self.small_move),
            "segment.small_move",
            format!(
                "{} is not a finite fraction of the arm's length ≥ 0",
                Num(self.small_move)
            ),
        )?;
        InvalidSetting::require(
            self.min_reach.is_finite() && self.min_reach >= self.small_move,
            "segment.min_reach",
            format!(
                "{} is not a finite fraction of the arm's length ≥ small_move ({})",
                Num(self.min_reach),
                Num(self.small_move)
            ),
        )?;
        Ok(())
    }
}

/// What a segment is (see the [module docs](super)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Label {
    /// The hand leaves where it was and ends held somewhere away from it.
    Reach,
    /// The hand goes back toward where an earlier reach started, or to the arm's rest.
    Return,
    /// Anything else: oscillation, small moves, moves that do not end held.
    Other,
}

impl Label {
    /// The label as `kinergy segment` and the segments file write it.
    pub fn as_str(self) -> &'static str {
        match self {
            Label::Reach => "reach",
            Label::Return => "return",
            Label::Other => "other",
        }
    }
}

impl fmt::Display for Label {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

impl FromStr for Label {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "reach" => Ok(Label::Reach),
            "return" => Ok(Label::Return),
            "other" => Ok(Label::Other),
            _ => Err(format!(
                "unknown label `{s}`: expected reach, return or other"
            )),
        }
    }
}

/// One labelled segment of a clip: frames `onset..end`, end excluded (see "Frames" in the
/// [module docs](super)).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Segment {
    /// The first frame: the hand starts leaving (the last frame at rest before the motion, or
    /// the clip's first frame).
    pub onset: usize,
    /// The frame of highest (smoothed) hand speed.
    pub peak: usize,
    /// One past the last frame: the hand has arrived on frame `end − 1` (the first frame at
    /// rest after the motion, or the clip's last frame).
    pub end: usize,
    /// The smoothed hand speed at `peak`, m/s.
    pub peak_speed: f64,
    /// Reach, return or other.
    pub label: Label,
    /// The hand is already moving on the clip's first frame, which is `onset`.
    pub truncated_start: bool,
    /// The hand is still moving on the clip's last frame, which is `end − 1`.
    pub truncated_end: bool,
    /// How far the hand moves from `onset` to `end − 1`, meters (relative to the shoulder by
    /// default, like the speed; in the world for a segment [`from_world`](Self::from_world)).
    pub displacement: f64,
    /// Measured in the world although the segmentation is relative to the shoulder (module
    /// docs, step 7): its `displacement` is the world hand's. A reach or return the trunk
    /// carries, or a reach the relative reading misses, is the world reading's segment (its
    /// frames, label, peak and peak speed too) — but where a relative reach has all of a
    /// reach the trunk carries, that one keeps its frames and peak. Always false when the
    /// whole segmentation is in the world ([`SegmentSettings::relative_to_shoulder`] false).
    pub from_world: bool,
}

impl Segment {
    /// The frames of the segment, `onset..end`: what `--frames A..B` takes.
    pub fn frames(&self) -> Range<usize> {
        self.onset..self.end
    }

    /// Seconds from the first frame to the last at `frame_time` seconds per frame.
    pub fn duration(&self, frame_time: f64) -> f64 {
        self.end.saturating_sub(self.onset + 1) as f64 * frame_time
    }

    /// Cut by the clip's start or end.
    pub fn truncated(&self) -> bool {
        self.truncated_start || self.truncated_end
    }
}
