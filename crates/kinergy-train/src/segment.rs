//! Reach segmentation: where in a clip an arm reaches, from the hand's speed (DESIGN §1.1).
//!
//! Aubry et al. (2009) fit synergy parameters to whole clips that each hold one seated reach;
//! real captures hold rests, several reaches, gestures and walking around them. This module
//! finds the reaches so a fit can take one (`kinergy segment CLIP.bvh` prints them).
//!
//! # The speed signal
//!
//! [`hand_speed`] is the speed of the arm's end effector ([`ArmJoints::end_effector`]), m/s,
//! one value per frame:
//!
//! 1. the path is the hand's world position minus the shoulder's
//!    ([`SegmentSettings::relative_to_shoulder`], the default) or the hand's world position;
//! 2. speed by central differences, |p_{i+1} − p_{i−1}| / 2Δt, one-sided at the two ends
//!    ([`speed_series`]);
//! 3. a centred moving average over [`SegmentSettings::smoothing`] seconds (an odd number of
//!    frames, at least one; near the ends the window is cut to the frames that exist), a
//!    low-pass that removes capture jitter without moving a symmetric bell's peak.
//!
//! Relative to the shoulder, walking, stepping and the translation of the torso (sway,
//! bending) do not count as reaching: only what the arm itself does moves the hand relative
//! to the shoulder. The difference is taken in world axes, so a rotation of the whole torso
//! about the shoulder still moves the hand (a torso twist is part of many reaches).
//!
//! # Segments
//!
//! With s the smoothed speed, [`find_segments`] repeats, until no frame is left:
//!
//! 1. the peak p is the frame of highest s among the frames no segment holds yet (it is the
//!    maximum of its stretch of free frames); stop when s_p < [`SegmentSettings::min_peak_speed`].
//!    When a neighbour of p is faster, p is the tail of a motion already taken, slowing below
//!    that segment's rest threshold but not yet below `min_peak_speed` (a slow drift after a
//!    fast reach): p is set aside, belonging to no segment, and the next frame is tried;
//! 2. the rest threshold is r = max(`rest_fraction` · s_p, `rest_speed`): a frame is *at rest*
//!    when s < r. With the default fraction 0.1, a minimum-jerk reach of duration T
//!    (speed ∝ 30τ²(1 − τ)², peak 1.875 d/T) is "moving" from τ ≈ 0.086 to τ ≈ 0.914, that is
//!    for 83% of its true duration; the absolute floor keeps slow drift at the noise level from
//!    counting when the peak itself is small;
//! 3. the onset is, walking back from p, the first frame at rest (the last rest frame before
//!    the motion), or frame 0, or the first free frame after another segment;
//! 4. the end is, walking forward from p, the first frame at rest (the hand has come to rest at
//!    the target), or the last frame, or the last free frame before another segment;
//! 5. frames onset..=end are taken; the segment is kept when (end − onset)·Δt ≥
//!    [`SegmentSettings::min_duration`].
//!
//! The segments are returned in time order; they never overlap (each frame belongs to at
//! most one). [`main_segment`] picks the one whose hand moves farthest from onset to end
//! (in the same frame as the speed, shoulder-relative by default).
//!
//! Empty, one-frame and motionless clips give no segment (never a panic).
//!
//! ```
//! use kinergy_motion::{clip_from_bvh, ArmJoints, ImportOptions, Side};
//! use kinergy_train::segment::{find_segments, SegmentSettings};
//!
//! // A clip at rest: no reach.
//! let text = "HIERARCHY\nROOT Chest\n{\n OFFSET 0 140 0\n CHANNELS 3 Zrotation Xrotation Yrotation\n \
//!     JOINT RightShoulder\n {\n  OFFSET -5 10 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n  \
//!     JOINT RightArm\n  {\n   OFFSET -15 0 0\n   CHANNELS 3 Zrotation Xrotation Yrotation\n   \
//!     JOINT RightForeArm\n   {\n    OFFSET -28 0 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n    \
//!     JOINT RightHand\n    {\n     OFFSET -26 0 0\n     CHANNELS 3 Zrotation Xrotation Yrotation\n     \
//!     End Site\n     {\n      OFFSET -9 0 0\n     }\n    }\n   }\n  }\n }\n}\n\
//!     MOTION\nFrames: 2\nFrame Time: 0.0333333\n\
//!     0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n0 0 0 0 0 0 0 0 0 0 0 0 0 0 0\n";
//! let bvh = kinergy_motion::kinergy_bvh::parse(text)?;
//! let options = ImportOptions { unit: "cm".parse()?, ..Default::default() };
//! let (clip, _report) = clip_from_bvh(&bvh, &options)?;
//! let arm = ArmJoints::find(clip.skeleton(), Side::Right)?;
//! assert!(find_segments(&clip, &arm, &SegmentSettings::default())?.is_empty());
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```

use std::ops::Range;

use kinergy_motion::nalgebra::Point3;
use kinergy_motion::{ArmJoints, Clip, speed_series};
use serde::Serialize;

use crate::error::{Result, TrainError, require};

/// How [`find_segments`] reads the hand's speed (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SegmentSettings {
    /// Width of the centred moving average on the speed, seconds (0: no smoothing).
    /// Default 0.05 s.
    pub smoothing: f64,
    /// A frame is at rest when its speed is below this fraction of its segment's peak speed
    /// (or below [`SegmentSettings::rest_speed`], whichever is higher). In [0, 1); default 0.1.
    pub rest_fraction: f64,
    /// The absolute rest threshold, m/s. Default 0.05 m/s.
    pub rest_speed: f64,
    /// Peaks slower than this are not reaches, m/s; above `rest_speed`. Default 0.2 m/s.
    pub min_peak_speed: f64,
    /// Segments shorter than this (onset to end) are dropped, seconds. Default 0.2 s.
    pub min_duration: f64,
    /// True (the default): the hand's speed relative to the shoulder, so walking and torso
    /// translation do not count as reaching. False: the hand's world speed.
    pub relative_to_shoulder: bool,
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
        }
    }
}

impl SegmentSettings {
    /// Checks every setting; the error names the first bad field.
    pub fn validate(&self) -> Result<()> {
        let nonneg = |v: f64| v.is_finite() && v >= 0.0;
        require(
            nonneg(self.smoothing),
            "segment.smoothing",
            format!("{} is not a finite number of seconds ≥ 0", self.smoothing),
        )?;
        require(
            self.rest_fraction.is_finite() && (0.0..1.0).contains(&self.rest_fraction),
            "segment.rest_fraction",
            format!("{} is not in [0, 1)", self.rest_fraction),
        )?;
        require(
            nonneg(self.rest_speed),
            "segment.rest_speed",
            format!("{} is not a finite speed ≥ 0 m/s", self.rest_speed),
        )?;
        require(
            self.min_peak_speed.is_finite() && self.min_peak_speed > self.rest_speed,
            "segment.min_peak_speed",
            format!(
                "{} is not a finite speed above rest_speed ({} m/s)",
                self.min_peak_speed, self.rest_speed
            ),
        )?;
        require(
            nonneg(self.min_duration),
            "segment.min_duration",
            format!(
                "{} is not a finite number of seconds ≥ 0",
                self.min_duration
            ),
        )
    }
}

/// One reach: frames of a clip, end inclusive.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Segment {
    /// The last frame at rest before the motion (or the first frame of the clip).
    pub onset: usize,
    /// The frame of highest (smoothed) hand speed.
    pub peak: usize,
    /// The first frame at rest after the motion (or the last frame of the clip).
    pub end: usize,
    /// The smoothed hand speed at `peak`, m/s.
    pub peak_speed: f64,
}

impl Segment {
    /// Seconds from onset to end at `frame_time` seconds per frame.
    pub fn duration(&self, frame_time: f64) -> f64 {
        (self.end - self.onset) as f64 * frame_time
    }

    /// The frames of the segment, `onset..end + 1`.
    pub fn frames(&self) -> Range<usize> {
        self.onset..self.end + 1
    }
}

/// The hand path the speed is measured on: hand − shoulder, or the hand, per frame.
fn hand_path(clip: &Clip, arm: &ArmJoints, relative: bool) -> Result<Vec<Point3<f64>>> {
    if clip.frame_count() == 0 {
        return Ok(Vec::new());
    }
    let hand = arm.end_effector();
    if relative {
        let t = clip.trajectory(&[hand, arm.shoulder])?;
        Ok(t.frames().map(|f| Point3::from(f[0] - f[1])).collect())
    } else {
        Ok(clip.trajectory(&[hand])?.path(0))
    }
}

/// A centred moving average over `width` frames (odd), cut at the ends.
fn moving_average(values: &[f64], width: usize) -> Vec<f64> {
    let half = width / 2;
    let n = values.len();
    let mut prefix = Vec::with_capacity(n + 1);
    prefix.push(0.0);
    for v in values {
        prefix.push(prefix.last().copied().unwrap_or(0.0) + v);
    }
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(half), (i + half + 1).min(n));
            // Clamped at 0 so rounding in the prefix sums never gives a negative speed.
            ((prefix[b] - prefix[a]) / (b - a) as f64).max(0.0)
        })
        .collect()
}

fn smoothed_speed(path: &[Point3<f64>], frame_time: f64, smoothing: f64) -> Vec<f64> {
    let raw = speed_series(path, frame_time);
    let frames = (smoothing / frame_time).round();
    // Odd width of about `smoothing` seconds; capped by the clip length (the cast saturates).
    let width = (frames as usize).min(raw.len()) | 1;
    if width <= 1 {
        raw
    } else {
        moving_average(&raw, width)
    }
}

/// The smoothed speed of the arm's hand (m/s), one value per frame of `clip`; empty for an
/// empty clip. See the [module docs](self) for the signal.
pub fn hand_speed(clip: &Clip, arm: &ArmJoints, settings: &SegmentSettings) -> Result<Vec<f64>> {
    settings.validate()?;
    let path = hand_path(clip, arm, settings.relative_to_shoulder)?;
    Ok(smoothed_speed(&path, clip.frame_time(), settings.smoothing))
}

/// The segments of a speed series (see the [module docs](self)), in time order.
fn segments_of(speed: &[f64], frame_time: f64, settings: &SegmentSettings) -> Vec<Segment> {
    let n = speed.len();
    // Candidates fastest first (earlier first among equals): each is the fastest free frame
    // when its turn comes, so one pass replaces a search per segment.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| speed[b].total_cmp(&speed[a]).then(a.cmp(&b)));
    let mut taken = vec![false; n];
    let mut out = Vec::new();
    for peak in order {
        let peak_speed = speed[peak];
        if peak_speed < settings.min_peak_speed {
            break;
        }
        if taken[peak] {
            continue;
        }
        // A faster neighbour is taken: this frame is the tail of that segment's motion,
        // slowing below its rest threshold, not a new peak.
        let faster = |j: Option<usize>| j.is_some_and(|j| j < n && speed[j] > peak_speed);
        if faster(peak.checked_sub(1)) || faster(Some(peak + 1)) {
            taken[peak] = true;
            continue;
        }
        let rest = (settings.rest_fraction * peak_speed).max(settings.rest_speed);
        let mut onset = peak;
        while onset > 0 && speed[onset] >= rest && !taken[onset - 1] {
            onset -= 1;
        }
        let mut end = peak;
        while end + 1 < n && speed[end] >= rest && !taken[end + 1] {
            end += 1;
        }
        taken[onset..=end].iter_mut().for_each(|t| *t = true);
        let segment = Segment {
            onset,
            peak,
            end,
            peak_speed,
        };
        if segment.duration(frame_time) >= settings.min_duration {
            out.push(segment);
        }
    }
    out.sort_by_key(|s| s.onset);
    out
}

/// Every reach of `arm` in `clip`, in time order and non-overlapping (see the
/// [module docs](self) for the rule). Empty when the hand never moves faster than
/// [`SegmentSettings::min_peak_speed`] for [`SegmentSettings::min_duration`].
pub fn find_segments(
    clip: &Clip,
    arm: &ArmJoints,
    settings: &SegmentSettings,
) -> Result<Vec<Segment>> {
    let speed = hand_speed(clip, arm, settings)?;
    Ok(segments_of(&speed, clip.frame_time(), settings))
}

/// The clip's main reach: of [`find_segments`]' segments, the one whose hand moves farthest
/// from onset to end (measured on the same path as the speed: relative to the shoulder by
/// default). [`TrainError::Reach`], naming `clip_name`, when there is none.
pub fn main_segment(
    clip: &Clip,
    arm: &ArmJoints,
    settings: &SegmentSettings,
    clip_name: &str,
) -> Result<Segment> {
    settings.validate()?;
    let path = hand_path(clip, arm, settings.relative_to_shoulder)?;
    let speed = smoothed_speed(&path, clip.frame_time(), settings.smoothing);
    let displacement = |s: &Segment| (path[s.end] - path[s.onset]).norm();
    segments_of(&speed, clip.frame_time(), settings)
        .into_iter()
        .map(|s| (displacement(&s), s))
        .fold(None, |best: Option<(f64, Segment)>, (d, s)| match best {
            Some((b, _)) if b >= d => best,
            _ => Some((d, s)),
        })
        .map(|(_, s)| s)
        .ok_or_else(|| {
            let fastest = speed.iter().copied().fold(0.0, f64::max);
            TrainError::Reach {
                clip: clip_name.to_string(),
                why: format!(
                    "no hand motion faster than {} m/s lasting {} s (the {} hand's fastest is \
                     {fastest:.3} m/s{})",
                    settings.min_peak_speed,
                    settings.min_duration,
                    arm.side
                        .map_or_else(|| "arm's".to_string(), |s| s.to_string()),
                    if settings.relative_to_shoulder {
                        " relative to the shoulder"
                    } else {
                        ""
                    },
                ),
            }
        })
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn settings() -> SegmentSettings {
        SegmentSettings::default()
    }

    #[test]
    fn degenerate_series_give_no_segment() {
        for speed in [vec![], vec![5.0], vec![0.0; 10], vec![1.0; 3]] {
            // A constant fast series is one segment only when it lasts min_duration.
            let s = segments_of(&speed, 0.01, &settings());
            assert!(s.len() <= 1, "{speed:?}: {s:?}");
            if let Some(seg) = s.first() {
                assert!(seg.duration(0.01) >= settings().min_duration);
            }
        }
        let long = segments_of(&[1.0; 100], 0.01, &settings());
        assert_eq!(
            long,
            [Segment {
                onset: 0,
                peak: 0,
                end: 99,
                peak_speed: 1.0
            }]
        );
    }

    #[test]
    fn neighbouring_segments_do_not_share_a_frame() {
        // Two humps separated by a single rest frame, which only the bigger one (taken
        // first) may hold; the smaller one's tail stays above its own rest threshold.
        let hump =
            |peak: f64| (1..29).map(move |i| peak * (std::f64::consts::PI * i as f64 / 29.0).sin());
        let speed: Vec<f64> = hump(1.0).chain([0.0]).chain(hump(2.0)).collect();
        let s = segments_of(&speed, 0.01, &settings());
        assert_eq!(s.len(), 2, "{s:?}");
        assert_eq!((s[0].end, s[1].onset), (27, 28), "{s:?}");
        assert_relative_eq!(s[1].peak_speed, speed[s[1].peak]);
    }

    #[test]
    fn a_slow_drift_after_a_fast_reach_is_not_a_reach() {
        // A hump peaking at 3 m/s (rest below 0.3 m/s), then 0.3 s of drift slowing from
        // 0.29 to 0.2 m/s: above min_peak_speed but only ever slowing, so not a new peak.
        let hump = (0..=30).map(|i| 3.0 * (std::f64::consts::PI * i as f64 / 30.0).sin());
        let drift = (0..30).map(|i| 0.29 - 0.003 * i as f64);
        let speed: Vec<f64> = hump.take(29).chain(drift).chain([0.0; 10]).collect();
        let s = segments_of(&speed, 0.01, &settings());
        assert_eq!(s.len(), 1, "{s:?}");
        assert_eq!((s[0].peak, s[0].end), (15, 29), "{s:?}");
    }

    #[test]
    fn moving_average_keeps_constants_and_cuts_the_ends() {
        assert_eq!(moving_average(&[2.0; 7], 5), vec![2.0; 7]);
        let m = moving_average(&[0.0, 3.0, 0.0, 0.0], 3);
        assert_eq!(m, vec![1.5, 1.0, 1.0, 0.0]);
    }

    #[test]
    fn bad_settings_name_their_field() {
        let bad = [
            SegmentSettings {
                smoothing: -1.0,
                ..settings()
            },
            SegmentSettings {
                rest_fraction: 1.0,
                ..settings()
            },
            SegmentSettings {
                rest_speed: f64::NAN,
                ..settings()
            },
            SegmentSettings {
                min_peak_speed: 0.01,
                ..settings()
            },
            SegmentSettings {
                min_duration: f64::INFINITY,
                ..settings()
            },
        ];
        let fields = [
            "smoothing",
            "rest_fraction",
            "rest_speed",
            "min_peak_speed",
            "min_duration",
        ];
        for (s, f) in bad.iter().zip(fields) {
            match s.validate() {
                Err(TrainError::Setting { field, .. }) => assert_eq!(field, format!("segment.{f}")),
                other => panic!("{f}: {other:?}"),
            }
        }
        settings().validate().expect("defaults are valid");
    }
}
