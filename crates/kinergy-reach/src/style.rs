//! Whether a person's style survives the transfer to the full body (`kinergy style`, issue 16
//! §2). For a capture of the person, the full-body character (the capture's proportions)
//! reaches the capture's own target — the hand's last position of its main reach, carried
//! over in the arm's fitted base frame — once driven by the person's parameters and once with
//! the default profile; each motion's hand-speed profile (relative to the shoulder, from the
//! reach's onset to its end, time-normalized) is compared with the captured one: Pearson
//! correlation, and the fraction of the movement at which the speed peaks. Where the synergy
//! handed the hand over, its own part (onset to hand-over) is scored too.

use kinergy_motion::nalgebra::Point3;
use kinergy_motion::segment::{SegmentSettings, hand_speed, main_segment};
use kinergy_motion::{ArmJoints, Clip, Side};
use kinergy_solver::{BaseMode, CaptureArm, PersonStyle};
use serde::Serialize;

use crate::character::{Character, Proportions};
use crate::controller::{ArmDrive, ReachSettings, reach_full_body_driven};
use crate::drive::PersonArm;
use crate::error::Result;

/// Samples of a time-normalized profile (0, 1/100, …, 1 of the movement).
pub const SAMPLES: usize = 101;

/// One capture's comparison ([`StyleCapture::compare`]).
#[derive(Debug, Clone, Serialize)]
pub struct StyleRow {
    /// The capture.
    pub clip: String,
    /// Its main reach's frames `[onset, end)`.
    pub frames: [usize; 2],
    /// Its target in the arm's fitted base frame, meters.
    pub target_in_base_m: [f64; 3],
    /// The fraction of the captured movement at which its hand speed peaks.
    pub captured_peak: f64,
    /// Pearson correlation of the `reach --params` profile with the captured one.
    pub params_correlation: f64,
    /// Its peak's fraction of the movement.
    pub params_peak: f64,
    /// The hand's distance from the target at the end, meters.
    pub params_error_m: f64,
    /// Whether the synergy handed the hand over.
    pub params_hand_over: bool,
    /// Correlation of the synergy's own part (onset to hand-over, or the whole reach).
    pub synergy_correlation: f64,
    /// Its peak's fraction of the movement.
    pub synergy_peak: f64,
    /// Pearson correlation of the default `reach` profile with the captured one.
    pub profile_correlation: f64,
    /// Its peak's fraction of the movement.
    pub profile_peak: f64,
}

/// The means over a person's captures ([`StyleSummary::of`]).
#[derive(Debug, Clone, Serialize)]
pub struct StyleSummary {
    /// Captures compared.
    pub captures: usize,
    /// Mean correlation with the captured profiles, `reach --params`.
    pub params_correlation: f64,
    /// Mean |peak fraction − captured|, `reach --params`.
    pub params_peak_error: f64,
    /// Mean correlation of the synergy's own part (to the hand-over).
    pub synergy_correlation: f64,
    /// Mean |peak fraction − captured| of the synergy's own part.
    pub synergy_peak_error: f64,
    /// Captures where the synergy handed the hand over.
    pub hand_overs: usize,
    /// Mean correlation, default `reach`.
    pub profile_correlation: f64,
    /// Mean |peak fraction − captured|, default `reach`.
    pub profile_peak_error: f64,
}

impl StyleSummary {
    /// The means over `rows` (NaN means for no rows).
    pub fn of(rows: &[StyleRow]) -> StyleSummary {
        let n = rows.len() as f64;
        let mean = |f: &dyn Fn(&StyleRow) -> f64| rows.iter().map(f).sum::<f64>() / n;
        StyleSummary {
            captures: rows.len(),
            params_correlation: mean(&|r| r.params_correlation),
            params_peak_error: mean(&|r| (r.params_peak - r.captured_peak).abs()),
            synergy_correlation: mean(&|r| r.synergy_correlation),
            synergy_peak_error: mean(&|r| (r.synergy_peak - r.captured_peak).abs()),
            hand_overs: rows.iter().filter(|r| r.params_hand_over).count(),
            profile_correlation: mean(&|r| r.profile_correlation),
            profile_peak_error: mean(&|r| (r.profile_peak - r.captured_peak).abs()),
        }
    }
}

/// What a comparison needs of one capture: its main reach's frames and hand-speed profile,
/// its target in the arm's base frame, and the character of its proportions.
#[derive(Debug, Clone)]
pub struct StyleCapture {
    name: String,
    frames: [usize; 2],
    speeds: Vec<f64>,
    local: Point3<f64>,
    character: Character,
}

impl StyleCapture {
    /// The capture `clip` (named `name` in errors and rows), reaching with the arm `joints`:
    /// its main reach, the hand speed over it (relative to the shoulder), its target — the
    /// hand's last position of the reach in the arm's base frame on its first frame (where
    /// the person stood and which way they faced do not matter) — and a character of its
    /// proportions. Errors are the capture's: no main reach, a skeleton the character
    /// cannot take.
    pub fn new(clip: &Clip, joints: &ArmJoints, name: &str) -> Result<StyleCapture> {
        let settings = SegmentSettings::default();
        let segment = main_segment(clip, joints, &settings, name)?;
        let speed = hand_speed(clip, joints, &settings)?;
        let capture = CaptureArm::new(clip, joints)?;
        let base = *capture.base(BaseMode::Replay).at(segment.onset);
        let last = clip
            .skeleton()
            .world_positions(clip.frame(segment.end - 1).unwrap_or_default())?;
        let hand = joints.hand.unwrap_or(joints.wrist);
        Ok(StyleCapture {
            name: name.to_string(),
            frames: [segment.onset, segment.end],
            speeds: speed[segment.onset..segment.end].to_vec(),
            local: base.inverse() * last[hand],
            character: Character::new(&Proportions::from_clip(clip)?)?,
        })
    }

    /// The character reaches the capture's target with the arm on `side`, once driven by
    /// `person`'s parameters and once with the default profile; both hand-speed profiles
    /// against the captured one.
    ///
    /// Errors: [`crate::ReachError::Params`] when the person's parameters do not fit, and
    /// the full-body reach's.
    pub fn compare(&self, side: Side, person: &dyn PersonStyle) -> Result<StyleRow> {
        let character = &self.character;
        let target = PersonArm::world_target(character, &self.local, side)?;
        let synergy = PersonArm::in_base(character, person, &self.local, side)?.drive;
        let settings = ReachSettings {
            arm: Some(side),
            ..ReachSettings::default()
        };
        let run = |drive: &ArmDrive| reach_full_body_driven(character, target, &settings, drive);
        let with = run(&synergy)?;
        let without = run(&ArmDrive::Profile)?;
        let captured = normalized(&self.speeds);
        let ours = normalized(&with.arm_speeds(character, false));
        let own = normalized(&with.arm_speeds(character, true));
        let theirs = normalized(&without.arm_speeds(character, false));
        let wrist = with.report.arm.joints()[3];
        let hand_at_end =
            character.world_positions(with.poses.last().unwrap_or(&character.rest_pose()))[wrist];
        Ok(StyleRow {
            clip: self.name.clone(),
            frames: self.frames,
            target_in_base_m: [self.local.x, self.local.y, self.local.z],
            captured_peak: peak(&captured),
            params_correlation: pearson(&ours, &captured),
            params_peak: peak(&ours),
            params_error_m: (hand_at_end - target).norm(),
            params_hand_over: with.report.hand_over.is_some(),
            synergy_correlation: pearson(&own, &captured),
            synergy_peak: peak(&own),
            profile_correlation: pearson(&theirs, &captured),
            profile_peak: peak(&theirs),
        })
    }
}

/// `values` resampled at [`SAMPLES`] evenly spaced fractions of their span (linear
/// interpolation).
pub fn normalized(values: &[f64]) -> Vec<f64> {
    if values.len() < 2 {
        return vec![values.first().copied().unwrap_or(0.0); SAMPLES];
    }
    let last = (values.len() - 1) as f64;
    (0..SAMPLES)
        .map(|k| {
            let x = k as f64 / (SAMPLES - 1) as f64 * last;
            let i = (x.floor() as usize).min(values.len() - 2);
            let u = x - i as f64;
            values[i] * (1.0 - u) + values[i + 1] * u
        })
        .collect()
}

/// The fraction of the movement at which a normalized profile peaks (the first maximum).
pub fn peak(profile: &[f64]) -> f64 {
    let at = profile
        .iter()
        .enumerate()
        .fold(
            (0, f64::NEG_INFINITY),
            |a, (i, &v)| if v > a.1 { (i, v) } else { a },
        )
        .0;
    at as f64 / (profile.len().max(2) - 1) as f64
}

/// Pearson's correlation of two series over their common length (0 when either is
/// constant).
pub fn pearson(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len()) as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    if saa <= 0.0 || sbb <= 0.0 {
        0.0
    } else {
        sab / (saa * sbb).sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pearson_of_a_profile_with_itself_scaled_is_one_and_with_its_mirror_minus_one() {
        let a: Vec<f64> = (0..50).map(|i| (i as f64 * 0.1).sin()).collect();
        let scaled: Vec<f64> = a.iter().map(|v| 3.0 * v + 1.0).collect();
        let mirrored: Vec<f64> = a.iter().map(|v| -v).collect();
        approx::assert_relative_eq!(pearson(&a, &scaled), 1.0, epsilon = 1e-12);
        approx::assert_relative_eq!(pearson(&a, &mirrored), -1.0, epsilon = 1e-12);
        assert_eq!(pearson(&a, &[2.0; 50]), 0.0);
    }

    #[test]
    fn normalizing_keeps_the_ends_and_the_peak_fraction() {
        let v: Vec<f64> = (0..=20).map(|i| -((i as f64 - 5.0).powi(2))).collect();
        let n = normalized(&v);
        assert_eq!(n.len(), SAMPLES);
        assert_eq!(n[0], v[0]);
        assert_eq!(n[SAMPLES - 1], v[20]);
        approx::assert_relative_eq!(peak(&n), 0.25, epsilon = 1e-12);
    }
}
