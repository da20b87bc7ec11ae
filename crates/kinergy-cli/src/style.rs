//! `kinergy style`: whether `reach --params` reaches in the person's style (issue 16 §2). For
//! each of the person's captures, the full-body character (the capture's proportions) reaches
//! the capture's own target — the hand's last position of its main reach, carried over in the
//! arm's fitted base frame — once with the person's parameters and once with the default
//! profile; each motion's hand-speed profile (relative to the shoulder, from the reach's onset
//! to its end, time-normalized) is compared with the captured one: Pearson correlation, and
//! the fraction of the movement at which the speed peaks. Where the synergy handed the hand
//! over, its own part (onset to hand-over) is scored too.

use std::path::{Path, PathBuf};

use kinergy_motion::nalgebra::Point3;
use kinergy_reach::character::{Character, Limb, Proportions};
use kinergy_reach::controller::{
    ArmDrive, ReachSettings, fitted_base_at_rest, reach_full_body_driven,
};
use kinergy_solver::{BaseMode, CaptureArm};
use kinergy_train::PersonParams;
use kinergy_train::segment::{SegmentSettings, hand_speed, main_segment};
use serde::Serialize;

use crate::common::{ArmArgs, Failure, ReadArgs, emit, print_json};

/// Samples of a time-normalized profile (0, 1/100, …, 1 of the movement).
const SAMPLES: usize = 101;

/// Arguments of `kinergy style`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The person's captures (files or folders of .bvh).
    #[arg(required = true, value_name = "CLIPS")]
    pub clips: Vec<PathBuf>,
    /// The person's parameters (`kinergy fit --per person -o person.json`) or field
    /// (`--field`).
    #[arg(long, value_name = "person.json")]
    pub params: PathBuf,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// Also write style.csv (one row per capture) and summary.md into this folder.
    #[arg(short, long, value_name = "DIR")]
    pub output: Option<PathBuf>,
    #[command(flatten)]
    pub arm: ArmArgs,
    #[command(flatten)]
    pub read: ReadArgs,
}

/// One capture's comparison.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
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

/// A [`Row`] as one flat line of style.csv.
#[derive(Serialize)]
struct CsvRow<'a> {
    clip: &'a str,
    onset: usize,
    end: usize,
    target_x_m: f64,
    target_y_m: f64,
    target_z_m: f64,
    captured_peak: f64,
    params_correlation: f64,
    params_peak: f64,
    params_error_m: f64,
    params_hand_over: bool,
    synergy_correlation: f64,
    synergy_peak: f64,
    profile_correlation: f64,
    profile_peak: f64,
}

impl<'a> From<&'a Row> for CsvRow<'a> {
    fn from(r: &'a Row) -> CsvRow<'a> {
        CsvRow {
            clip: &r.clip,
            onset: r.frames[0],
            end: r.frames[1],
            target_x_m: r.target_in_base_m[0],
            target_y_m: r.target_in_base_m[1],
            target_z_m: r.target_in_base_m[2],
            captured_peak: r.captured_peak,
            params_correlation: r.params_correlation,
            params_peak: r.params_peak,
            params_error_m: r.params_error_m,
            params_hand_over: r.params_hand_over,
            synergy_correlation: r.synergy_correlation,
            synergy_peak: r.synergy_peak,
            profile_correlation: r.profile_correlation,
            profile_peak: r.profile_peak,
        }
    }
}

/// The means over the person's captures.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
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

#[derive(Serialize)]
struct Report<'a> {
    params: String,
    summary: &'a Summary,
    rows: &'a [Row],
}

/// Runs `kinergy style`.
pub fn run(args: &Args) -> Result<(), Failure> {
    args.read.check()?;
    let clips = crate::common::collect_clips(&args.clips)?;
    if let Some(dir) = &args.output {
        let mut inputs: Vec<&Path> = clips.iter().map(PathBuf::as_path).collect();
        inputs.push(&args.params);
        crate::common::check_outputs(&inputs, &[crate::common::Output::Folder("-o", dir)])?;
    }
    let person = PersonParams::read(&args.params).map_err(|e| Failure::Input(e.to_string()))?;
    let mut rows = Vec::with_capacity(clips.len());
    for path in &clips {
        rows.push(compare_one(args, &person, path)?);
    }
    let n = rows.len() as f64;
    let mean = |f: &dyn Fn(&Row) -> f64| rows.iter().map(f).sum::<f64>() / n;
    let summary = Summary {
        captures: rows.len(),
        params_correlation: mean(&|r| r.params_correlation),
        params_peak_error: mean(&|r| (r.params_peak - r.captured_peak).abs()),
        synergy_correlation: mean(&|r| r.synergy_correlation),
        synergy_peak_error: mean(&|r| (r.synergy_peak - r.captured_peak).abs()),
        hand_overs: rows.iter().filter(|r| r.params_hand_over).count(),
        profile_correlation: mean(&|r| r.profile_correlation),
        profile_peak_error: mean(&|r| (r.profile_peak - r.captured_peak).abs()),
    };
    if let Some(dir) = &args.output {
        let flat: Vec<CsvRow<'_>> = rows.iter().map(CsvRow::from).collect();
        crate::common::write_csv(&dir.join("style.csv"), &flat)?;
        kinergy_io::write_atomic(
            &dir.join("summary.md"),
            markdown(&args.params, &summary, &rows).as_bytes(),
        )
        .map_err(|e| Failure::task(&dir.join("summary.md"), e))?;
    }
    if args.json {
        return print_json(&Report {
            params: args.params.display().to_string(),
            summary: &summary,
            rows: &rows,
        });
    }
    emit(&markdown(&args.params, &summary, &rows))
}

/// One capture: its main reach's profile against the two reaches toward its target.
fn compare_one(args: &Args, person: &PersonParams, path: &Path) -> Result<Row, Failure> {
    let (clip, _) = args.read.read(path)?;
    let joints = args.arm.find(&clip, path)?;
    let name = path.display().to_string();
    let settings = SegmentSettings::default();
    let segment =
        main_segment(&clip, &joints, &settings, &name).map_err(|e| Failure::input(path, e))?;
    let speed = hand_speed(&clip, &joints, &settings).map_err(|e| Failure::input(path, e))?;
    let captured = &speed[segment.onset..segment.end];
    // The target: the hand's last position of the reach, in the arm's base frame on its
    // first frame (where the person stood and which way they faced do not matter).
    let capture = CaptureArm::new(&clip, &joints).map_err(|e| Failure::input(path, e))?;
    let base = *capture.base(BaseMode::Replay).at(segment.onset);
    let last = clip
        .skeleton()
        .world_positions(clip.frame(segment.end - 1).unwrap_or_default())
        .map_err(|e| Failure::input(path, e))?;
    let hand = joints.hand.unwrap_or(joints.wrist);
    let local = base.inverse() * last[hand];
    let proportions = Proportions::from_clip(&clip).map_err(|e| Failure::input(path, e))?;
    let character = Character::new(&proportions).map_err(|e| Failure::input(path, e))?;
    let side = args.arm.arm;
    let fitted = fitted_base_at_rest(&character, side).map_err(|e| Failure::Task(e.to_string()))?;
    let target = fitted * local;
    let file = person
        .params_for(&local)
        .map_err(|e| Failure::input(&args.params, e))?;
    let synergy = crate::common::synergy_drive(&file, &args.params, &character)?;
    let reach_settings = ReachSettings {
        arm: Some(side),
        ..ReachSettings::default()
    };
    let run = |drive: &ArmDrive| {
        reach_full_body_driven(&character, target, &reach_settings, drive)
            .map_err(|e| Failure::Task(format!("{name}: {e}")))
    };
    let with = run(&synergy)?;
    let without = run(&ArmDrive::Profile)?;
    let limb = Limb::arm(side);
    let captured = normalized(captured);
    let ours = normalized(&with.arm_speeds(&character, false));
    let own = normalized(&with.arm_speeds(&character, true));
    let theirs = normalized(&without.arm_speeds(&character, false));
    let hand_at_end = character
        .world_positions(with.poses.last().unwrap_or(&character.rest_pose()))[limb.joints()[3]];
    Ok(Row {
        clip: name,
        frames: [segment.onset, segment.end],
        target_in_base_m: [local.x, local.y, local.z],
        captured_peak: peak(&captured),
        params_correlation: pearson(&ours, &captured),
        params_peak: peak(&ours),
        params_error_m: (hand_at_end - Point3::from(target.coords)).norm(),
        params_hand_over: with.report.hand_over.is_some(),
        synergy_correlation: pearson(&own, &captured),
        synergy_peak: peak(&own),
        profile_correlation: pearson(&theirs, &captured),
        profile_peak: peak(&theirs),
    })
}

/// `values` resampled at [`SAMPLES`] evenly spaced fractions of their span (linear
/// interpolation).
fn normalized(values: &[f64]) -> Vec<f64> {
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

/// The fraction of the movement at which a normalized profile peaks.
fn peak(profile: &[f64]) -> f64 {
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

/// Pearson's correlation of two equally long series (0 when either is constant).
fn pearson(a: &[f64], b: &[f64]) -> f64 {
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

/// The summary and the rows as markdown tables.
fn markdown(params: &Path, s: &Summary, rows: &[Row]) -> String {
    let mut out = format!(
        "# Style: {} against {} captures\n\nHand speed relative to the shoulder, from the \
         reach's onset to its end, time-normalized; r is Pearson's correlation with the \
         captured profile, peak the fraction of the movement at which the speed peaks.\n\n\
         | reach | mean r | mean peak error |\n|---|---|---|\n| with the person's parameters \
         | {:.3} | {:.3} |\n| its synergy's own part ({} of {} handed over) | {:.3} | {:.3} \
         |\n| default profile | {:.3} | {:.3} |\n\n",
        params.display(),
        s.captures,
        s.params_correlation,
        s.params_peak_error,
        s.hand_overs,
        s.captures,
        s.synergy_correlation,
        s.synergy_peak_error,
        s.profile_correlation,
        s.profile_peak_error
    );
    out.push_str(
        "| capture | frames | captured peak | r (params) | peak (params) | r (profile) | peak \
         (profile) | hand-over |\n|---|---|---|---|---|---|---|---|\n",
    );
    for r in rows {
        out.push_str(&format!(
            "| {} | {}..{} | {:.2} | {:.3} | {:.2} | {:.3} | {:.2} | {} |\n",
            r.clip,
            r.frames[0],
            r.frames[1],
            r.captured_peak,
            r.params_correlation,
            r.params_peak,
            r.profile_correlation,
            r.profile_peak,
            if r.params_hand_over { "yes" } else { "no" }
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pearson_of_a_profile_with_itself_scaled_is_one_and_with_its_mirror_minus_one() {
        let a: Vec<f64> = (0..50).map(|i| (i as f64 * 0.1).sin()).collect();
        let scaled: Vec<f64> = a.iter().map(|v| 3.0 * v + 1.0).collect();
        let mirrored: Vec<f64> = a.iter().map(|v| -v).collect();
        assert!((pearson(&a, &scaled) - 1.0).abs() < 1e-12);
        assert!((pearson(&a, &mirrored) + 1.0).abs() < 1e-12);
        assert_eq!(pearson(&a, &[2.0; 50]), 0.0);
    }

    #[test]
    fn normalizing_keeps_the_ends_and_the_peak_fraction() {
        let v: Vec<f64> = (0..=20).map(|i| -((i as f64 - 5.0).powi(2))).collect();
        let n = normalized(&v);
        assert_eq!(n.len(), SAMPLES);
        assert_eq!(n[0], v[0]);
        assert_eq!(n[SAMPLES - 1], v[20]);
        assert!((peak(&n) - 0.25).abs() < 1e-12);
    }
}
