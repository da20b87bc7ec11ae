//! Whether a person's style survives the transfer to the full body (`kinergy style`).
//!
//! For a capture of the person, the full-body character (the capture's proportions) reaches the
//! capture's own target — the hand's last position of its main reach, carried over in the arm's
//! fitted base frame — once driven by the person's parameters and once with the default
//! profile; each motion's hand-speed profile (relative to the shoulder, from the reach's onset
//! to its end, time-normalized) is compared with the captured one: Pearson correlation, and the
//! fraction of the movement at which the speed peaks (its error: the distance of that fraction
//! from the captured one). Where the synergy handed the hand over, its own part (onset to
//! hand-over) is scored too. Beyond the hand's speed, each motion's arm path — the elbow, wrist
//! and hand from the shoulder over the reach, in arm lengths — is compared with the captured
//! one ([`arm_path`] defines the measure).

use kinergy_io::InvalidSetting;
use kinergy_motion::nalgebra::{IsometryMatrix3, Point3};
use kinergy_motion::segment::{SegmentSettings, hand_speed, main_segment};
use kinergy_motion::{ArmJoints, Clip, Side};
use kinergy_solver::{BaseMode, CaptureArm, PersonStyle};
use serde::Serialize;

use crate::character::{Character, Proportions};
use crate::controller::{
    ArmDrive, ReachMotion, ReachSettings, SynergyStart, reach_full_body_driven,
};
use crate::drive::PersonArm;
use crate::error::Result;

pub mod arm_path;

pub use arm_path::ArmPath;

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
    /// |its peak's fraction − the captured one's|.
    pub params_peak_error: f64,
    /// Its arm path's distance from the captured one, in arm lengths ([`arm_path`]).
    pub params_arm_path: f64,
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
    /// |its peak's fraction − the captured one's|.
    pub profile_peak_error: f64,
    /// Its arm path's distance from the captured one, in arm lengths.
    pub profile_arm_path: f64,
}

/// The means over a person's captures, and how often the person's parameters beat the
/// default profile ([`StyleSummary::of`]).
#[derive(Debug, Clone, Serialize)]
pub struct StyleSummary {
    /// Captures compared.
    pub captures: usize,
    /// Mean correlation with the captured profiles, `reach --params`.
    pub params_correlation: f64,
    /// Mean |peak fraction − captured|, `reach --params`.
    pub params_peak_error: f64,
    /// Mean arm-path distance from the captures, arm lengths, `reach --params`.
    pub params_arm_path: f64,
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
    /// Mean arm-path distance from the captures, arm lengths, default `reach`.
    pub profile_arm_path: f64,
    /// Captures where the person's parameters correlate better than the default profile.
    pub params_better_correlation: usize,
    /// Captures where the person's parameters peak nearer the captured peak than the default.
    pub params_better_peak: usize,
    /// Captures where the person's arm path is nearer the captured one than the default's.
    pub params_better_arm_path: usize,
}

impl StyleSummary {
    /// The means and counts over `rows` (NaN means for no rows).
    pub fn of(rows: &[StyleRow]) -> StyleSummary {
        let n = rows.len() as f64;
        let mean = |f: &dyn Fn(&StyleRow) -> f64| rows.iter().map(f).sum::<f64>() / n;
        let count = |f: &dyn Fn(&StyleRow) -> bool| rows.iter().filter(|r| f(r)).count();
        StyleSummary {
            captures: rows.len(),
            params_correlation: mean(&|r| r.params_correlation),
            params_peak_error: mean(&|r| r.params_peak_error),
            params_arm_path: mean(&|r| r.params_arm_path),
            synergy_correlation: mean(&|r| r.synergy_correlation),
            synergy_peak_error: mean(&|r| (r.synergy_peak - r.captured_peak).abs()),
            hand_overs: count(&|r| r.params_hand_over),
            profile_correlation: mean(&|r| r.profile_correlation),
            profile_peak_error: mean(&|r| r.profile_peak_error),
            profile_arm_path: mean(&|r| r.profile_arm_path),
            params_better_correlation: count(&|r| r.params_correlation > r.profile_correlation),
            params_better_peak: count(&|r| r.params_peak_error < r.profile_peak_error),
            params_better_arm_path: count(&|r| r.params_arm_path < r.profile_arm_path),
        }
    }
}

/// A capture's comparison with what it was scored on: the [`StyleRow`], the three
/// time-normalized hand-speed profiles ([`SAMPLES`] each, m/s) and the two full-body reaches
/// (for pictures).
#[derive(Debug, Clone)]
pub struct StyleRun {
    /// The scores.
    pub row: StyleRow,
    /// The captured hand speed over its main reach, time-normalized.
    pub captured_speed: Vec<f64>,
    /// The `reach --params` hand speed from the arm's onset, [ended](ended_like) as the
    /// captured segment ends, time-normalized.
    pub params_speed: Vec<f64>,
    /// The default `reach`'s, ended and time-normalized alike.
    pub profile_speed: Vec<f64>,
    /// The character's reach driven by the person's parameters.
    pub params_motion: ReachMotion,
    /// The character's reach with the default profile.
    pub profile_motion: ReachMotion,
}

/// What a comparison needs of one capture: its main reach's frames, hand-speed profile and
/// arm path, its target in the arm's base frame, and the character of its proportions.
#[derive(Debug, Clone)]
pub struct StyleCapture {
    name: String,
    frames: [usize; 2],
    speeds: Vec<f64>,
    path: ArmPath,
    local: Point3<f64>,
    frame: IsometryMatrix3<f64>,
    character: Character,
    /// The hand point (the hand, or the wrist without one) from the shoulder, per frame of the
    /// main reach, world meters.
    relative: Vec<Point3<f64>>,
    frame_time: f64,
}

impl StyleCapture {
    /// The capture `clip` (named `name` in errors and rows), reaching with the arm `joints`:
    /// its main reach, the hand speed over it (relative to the shoulder), its arm path, its
    /// target — the hand's last position of the reach in the arm's base frame on its first
    /// frame (where the person stood and which way they faced do not matter) — and a
    /// character of its proportions. Errors are the capture's: no main reach, an arm without
    /// length, a skeleton the character cannot take.
    pub fn new(clip: &Clip, joints: &ArmJoints, name: &str) -> Result<StyleCapture> {
        let settings = SegmentSettings::default();
        let segment = main_segment(clip, joints, &settings, name)?;
        let speed = hand_speed(clip, joints, &settings)?;
        let capture = CaptureArm::new(clip, joints)?;
        let base = *capture.base(BaseMode::Replay).at(segment.onset);
        let skeleton = clip.skeleton();
        let mut arm = Vec::with_capacity(segment.end - segment.onset);
        for i in segment.onset..segment.end {
            let w = skeleton.world_positions(clip.frame(i).unwrap_or_default())?;
            let at = |j: usize| w.get(j).copied();
            arm.push([
                at(joints.shoulder),
                at(joints.elbow),
                at(joints.wrist),
                joints.hand.and_then(at),
            ]);
        }
        // The reach frame at the onset from both shoulders; the fitted base where the other
        // arm cannot be found.
        let frame = joints
            .side
            .and_then(|side| ArmJoints::find(skeleton, side.opposite()).ok())
            .and_then(|other| {
                let w = skeleton
                    .world_positions(clip.frame(segment.onset).unwrap_or_default())
                    .ok()?;
                reach_frame(w[joints.shoulder], w[other.shoulder])
            })
            .unwrap_or(base);
        let path = ArmPath::new(&arm, &frame.rotation).ok_or_else(|| {
            crate::ReachError::Setting(InvalidSetting::new(
                name.to_string(),
                "the arm has no length on the reach's first frame",
            ))
        })?;
        let last = arm
            .last()
            .and_then(|a| a[3].or(a[2]))
            .unwrap_or_else(Point3::origin);
        let relative = arm
            .iter()
            .filter_map(|a| Some(Point3::from(a[3].or(a[2])? - a[0]?)))
            .collect();
        Ok(StyleCapture {
            relative,
            frame_time: clip.frame_time(),
            name: name.to_string(),
            frames: [segment.onset, segment.end],
            speeds: speed[segment.onset..segment.end].to_vec(),
            path,
            local: base.inverse() * last,
            frame,
            character: Character::new(&Proportions::from_clip(clip)?)?,
        })
    }

    /// The character of the capture's proportions (the one that reaches).
    pub fn character(&self) -> &Character {
        &self.character
    }

    /// The hand point (the capture's hand, or its wrist without one) relative to the shoulder
    /// on each frame of the main reach, world meters: what real-time fidelity compares.
    pub fn relative_hand(&self) -> &[Point3<f64>] {
        &self.relative
    }

    /// The capture's target: the hand point's last position of its main reach in the arm's
    /// fitted base frame on the reach's first frame, meters (where
    /// [`PersonArm::world_target`] puts it for the character).
    pub fn target_in_base(&self) -> Point3<f64> {
        self.local
    }

    /// The capture's seconds per frame.
    pub fn frame_time(&self) -> f64 {
        self.frame_time
    }

    /// Whether the capture tracks a hand point beyond the wrist.
    pub fn has_hand(&self) -> bool {
        self.path.has_hand()
    }

    /// The main reach's frames `[onset, end)`.
    pub fn frames(&self) -> [usize; 2] {
        self.frames
    }

    /// The captured arm path.
    pub fn arm_path(&self) -> &ArmPath {
        &self.path
    }

    /// The capture's [`reach_frame`] at the reach's onset (world meters; the arm's fitted
    /// base frame where the skeleton has no other arm).
    pub fn frame(&self) -> &IsometryMatrix3<f64> {
        &self.frame
    }

    /// The rigid motion that puts the capture's world on the character's (arm `side`): the
    /// capture's reach frame at the onset onto the character's at rest, as the arm path
    /// compares them, so the capture's poses can be drawn over the character's.
    pub fn to_character(&self, side: Side) -> Result<IsometryMatrix3<f64>> {
        Ok(character_frame(&self.character, side)? * self.frame.inverse())
    }

    /// The arm path of the character's reach `motion` (from the arm's onset to its end), read
    /// like the capture's: with a hand only if the capture has one.
    pub fn motion_arm_path(&self, side: Side, motion: &ReachMotion) -> Result<ArmPath> {
        let character = &self.character;
        let [s, e, w, h] = motion.report.arm.joints();
        let base = character_frame(character, side)?;
        let hand = self.path.has_hand();
        let start = motion.report.arm_onset_frame.min(motion.poses.len());
        let arm: Vec<_> = motion.poses[start..]
            .iter()
            .map(|p| {
                let x = character.world_positions(p);
                [Some(x[s]), Some(x[e]), Some(x[w]), hand.then_some(x[h])]
            })
            .collect();
        ArmPath::new(&arm, &base.rotation).ok_or_else(|| {
            crate::ReachError::Setting(InvalidSetting::new(
                "character",
                "its reach has no frames or its arm no length",
            ))
        })
    }

    /// The character reaches the capture's target with the arm on `side`, once driven by
    /// `person`'s parameters and once with the default profile; both hand-speed profiles and
    /// arm paths against the captured ones.
    ///
    /// Errors: [`crate::ReachError::Params`] when the person's parameters do not fit, and
    /// the full-body reach's.
    pub fn compare(&self, side: Side, person: &dyn PersonStyle) -> Result<StyleRun> {
        self.compare_from(side, person, None)
    }

    /// [`StyleCapture::compare`] with the person's synergy arm started at `start` (the
    /// capture's own start posture and velocity, as a fit's replay starts: see
    /// [`ReachSettings::synergy_start`]) instead of from the character's hanging arm at rest,
    /// and the character at the capture's frame rate (the frames a fit compares).
    pub fn compare_from(
        &self,
        side: Side,
        person: &dyn PersonStyle,
        start: Option<SynergyStart>,
    ) -> Result<StyleRun> {
        let character = &self.character;
        let target = PersonArm::world_target(character, &self.local, side)?;
        let synergy = PersonArm::in_base(character, person, &self.local, side)?.drive;
        let settings = ReachSettings {
            arm: Some(side),
            ..ReachSettings::default()
        };
        let run = |drive: &ArmDrive, start: Option<SynergyStart>| {
            let settings = ReachSettings {
                synergy_start: start,
                frame_rate: if start.is_some() {
                    1.0 / self.frame_time
                } else {
                    settings.frame_rate
                },
                ..settings
            };
            reach_full_body_driven(character, target, &settings, drive)
        };
        let with = run(&synergy, start)?;
        let without = run(&ArmDrive::Profile, None)?;
        let captured = normalized(&self.speeds);
        let share = end_share(&self.speeds);
        let ours = normalized(ended_like(&with.arm_speeds(character, false), share));
        let own = normalized(ended_like(&with.arm_speeds(character, true), share));
        let theirs = normalized(ended_like(&without.arm_speeds(character, false), share));
        let tip = with.report.arm.joints()[3];
        let hand_at_end =
            character.world_positions(with.poses.last().unwrap_or(&character.rest_pose()))[tip];
        let captured_peak = peak(&captured);
        let row = StyleRow {
            clip: self.name.clone(),
            frames: self.frames,
            target_in_base_m: [self.local.x, self.local.y, self.local.z],
            captured_peak,
            params_correlation: pearson(&ours, &captured),
            params_peak: peak(&ours),
            params_peak_error: (peak(&ours) - captured_peak).abs(),
            params_arm_path: self.motion_arm_path(side, &with)?.distance(&self.path),
            params_error_m: (hand_at_end - target).norm(),
            params_hand_over: with.report.hand_over.is_some(),
            synergy_correlation: pearson(&own, &captured),
            synergy_peak: peak(&own),
            profile_correlation: pearson(&theirs, &captured),
            profile_peak: peak(&theirs),
            profile_peak_error: (peak(&theirs) - captured_peak).abs(),
            profile_arm_path: self.motion_arm_path(side, &without)?.distance(&self.path),
        };
        Ok(StyleRun {
            row,
            captured_speed: captured,
            params_speed: ours,
            profile_speed: theirs,
            params_motion: with,
            profile_motion: without,
        })
    }
}

/// The reach frame of an arm whose shoulder is at `shoulder` and the other arm's at `other`
/// (world meters, Y up): at the shoulder, y up, z horizontal from the other shoulder to this
/// one (out of the body sideways), x = y × z. Made from the body's own joints, it means the
/// same on any skeleton, whatever its rest pose. `None` when the shoulders are one above the
/// other.
pub fn reach_frame(shoulder: Point3<f64>, other: Point3<f64>) -> Option<IsometryMatrix3<f64>> {
    use kinergy_motion::nalgebra::{Matrix3, Rotation3, Translation3, Vector3};
    let mut z = shoulder - other;
    z.y = 0.0;
    if z.norm() < 1e-6 {
        return None;
    }
    let z = z.normalize();
    let y = Vector3::y();
    let x = y.cross(&z);
    Some(IsometryMatrix3::from_parts(
        Translation3::from(shoulder.coords),
        Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[x, y, z])),
    ))
}

/// The character's [`reach_frame`] of the arm on `side` at rest.
fn character_frame(character: &Character, side: Side) -> Result<IsometryMatrix3<f64>> {
    use crate::character::Limb;
    let rest = character.world_positions(&character.rest_pose());
    let at = |side: Side| rest[Limb::arm(side).joints()[0]];
    reach_frame(at(side), at(side.opposite())).ok_or_else(|| {
        crate::ReachError::Setting(InvalidSetting::new(
            "character",
            "its shoulders are one above the other",
        ))
    })
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

/// The share of its peak speed at which a captured segment ends (its last speed over its
/// largest; 0 for an empty or still one).
pub fn end_share(speeds: &[f64]) -> f64 {
    let top = speeds.iter().copied().fold(0.0f64, f64::max);
    match speeds.last() {
        Some(&last) if top > 0.0 => (last / top).clamp(0.0, 1.0),
        _ => 0.0,
    }
}

/// A synthesized reach's speeds `values` ended as the captured segment ends: at the first
/// frame past its peak where the speed has fallen to `share` of the peak (the whole of it when
/// it never does). The capture's segment ends where its speed falls to a share of its peak
/// (the segmenter's rule), while a synthesized reach runs on until the hand is at rest on the
/// target: compared whole, its bell would be squeezed into the first part of the normalized
/// time and its peak come early.
pub fn ended_like(values: &[f64], share: f64) -> &[f64] {
    let Some((top, peak)) = values
        .iter()
        .copied()
        .enumerate()
        .max_by(|a, b| a.1.total_cmp(&b.1))
    else {
        return values;
    };
    match (top + 1..values.len()).find(|&k| values[k] <= share * peak) {
        Some(k) => &values[..=k],
        None => values,
    }
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

    /// A capture made by the character itself (a default reach, exported), its arm.
    fn made_capture(shift: [f64; 3]) -> (Clip, ArmJoints) {
        use kinergy_motion::{Axis, Dof};
        let character = Character::from_height(1.75).expect("character");
        let target = Point3::new(0.35, 1.35, 0.45);
        let motion = reach_full_body_driven(
            &character,
            target,
            &ReachSettings::default(),
            &ArmDrive::Profile,
        )
        .expect("reach");
        let clip = character
            .to_clip(&motion.poses, motion.frame_time)
            .expect("clip");
        let skeleton = clip.skeleton().clone();
        let n = skeleton.dof_count();
        let mut values = clip.values().to_vec();
        for (k, dof) in skeleton.joint(0).dofs.iter().enumerate() {
            if let Dof::Translation(axis) = dof {
                let d = match axis {
                    Axis::X => shift[0],
                    Axis::Y => shift[1],
                    Axis::Z => shift[2],
                };
                for frame in values.chunks_mut(n) {
                    frame[skeleton.first_dof(0) + k] += d;
                }
            }
        }
        let clip = Clip::new(skeleton, clip.frame_time(), values).expect("shifted clip");
        let joints = ArmJoints::find(clip.skeleton(), Side::Left).expect("left arm");
        (clip, joints)
    }

    #[test]
    fn a_captures_arm_path_is_zero_from_itself_and_from_the_capture_moved_elsewhere() {
        let (clip, joints) = made_capture([0.0; 3]);
        let here = StyleCapture::new(&clip, &joints, "here").expect("capture");
        assert_eq!(here.arm_path().distance(here.arm_path()), 0.0);
        let (moved, joints) = made_capture([1.5, 0.2, -3.0]);
        let there = StyleCapture::new(&moved, &joints, "there").expect("capture");
        assert_eq!(here.frames(), there.frames());
        approx::assert_relative_eq!(
            here.arm_path().distance(there.arm_path()),
            0.0,
            epsilon = 1e-9
        );
    }

    #[test]
    fn the_summary_counts_where_the_persons_parameters_beat_the_default() {
        let row = |pc: f64, rc: f64, pa: f64, ra: f64| StyleRow {
            clip: String::new(),
            frames: [0, 1],
            target_in_base_m: [0.0; 3],
            captured_peak: 0.5,
            params_correlation: pc,
            params_peak: 0.4,
            params_peak_error: 0.1,
            params_arm_path: pa,
            params_error_m: 0.0,
            params_hand_over: pc > 0.5,
            synergy_correlation: pc,
            synergy_peak: 0.4,
            profile_correlation: rc,
            profile_peak: 0.8,
            profile_peak_error: 0.3,
            profile_arm_path: ra,
        };
        let rows = [
            row(0.9, 0.5, 0.1, 0.2),
            row(0.3, 0.6, 0.3, 0.2),
            row(0.7, 0.2, 0.4, 0.1),
        ];
        let s = StyleSummary::of(&rows);
        assert_eq!(s.captures, 3);
        assert_eq!(s.params_better_correlation, 2);
        assert_eq!(s.params_better_arm_path, 1);
        assert_eq!(s.params_better_peak, 3);
        assert_eq!(s.hand_overs, 2);
        approx::assert_relative_eq!(s.params_arm_path, 0.8 / 3.0, epsilon = 1e-12);
        approx::assert_relative_eq!(s.profile_peak_error, 0.3, epsilon = 1e-12);
    }

    #[test]
    fn a_synthesized_reach_ends_where_its_speed_falls_to_the_captures_end_share() {
        let captured = [0.0, 0.5, 1.0, 0.5, 0.2];
        assert!((end_share(&captured) - 0.2).abs() < 1e-12);
        let ours = [0.0, 1.0, 2.0, 1.0, 0.5, 0.4, 0.1, 0.0];
        // Past the peak (2.0) the first speed at or below 0.2 × 2.0 = 0.4 is frame 5.
        assert_eq!(ended_like(&ours, 0.2), &ours[..6]);
        // A rise before the peak at the share does not end it; never falling keeps it whole.
        assert_eq!(
            ended_like(&[0.1, 0.3, 1.0, 0.9], 0.2),
            &[0.1, 0.3, 1.0, 0.9]
        );
        assert_eq!(end_share(&[]), 0.0);
        assert!(ended_like(&[], 0.5).is_empty());
    }

    #[test]
    fn peak_is_the_first_maximum_and_its_error_the_distance_of_fractions() {
        let mut v = vec![0.0; SAMPLES];
        v[30] = 2.0;
        v[70] = 2.0;
        approx::assert_relative_eq!(peak(&v), 0.3, epsilon = 1e-12);
        approx::assert_relative_eq!(peak(&[1.0, 3.0, 2.0]), 0.5, epsilon = 1e-12);
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
