//! `kinergy segment`: the reach segments of a capture from its hand-speed series.

use std::path::PathBuf;

use kinergy_train::segment::{SegmentSettings, find_segments, main_segment};
use serde::Serialize;

use crate::common::{ArmArgs, Failure, ReadArgs, emit, print_json};

/// Arguments of `kinergy segment`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The capture.
    #[arg(value_name = "CLIP.bvh")]
    pub clip: PathBuf,
    /// Measure the hand's speed in the world instead of relative to the shoulder (then torso
    /// motion and walking count as hand motion).
    #[arg(long)]
    pub world: bool,
    /// Slowest peak hand speed that counts as a reach, m/s.
    #[arg(long, default_value_t = SegmentSettings::default().min_peak_speed, value_name = "M/S")]
    pub min_peak_speed: f64,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub read: ReadArgs,
    #[command(flatten)]
    pub arm: ArmArgs,
}

#[derive(Serialize)]
struct Row {
    onset: usize,
    peak: usize,
    end: usize,
    onset_s: f64,
    peak_s: f64,
    end_s: f64,
    duration_s: f64,
    peak_speed_m_s: f64,
    main: bool,
}

#[derive(Serialize)]
struct Report {
    clip: String,
    arm: Vec<String>,
    frames: usize,
    frame_time_s: f64,
    speed: &'static str,
    segments: Vec<Row>,
}

/// Runs `kinergy segment`.
pub fn run(args: &Args) -> Result<(), Failure> {
    let (clip, _) = args.read.read(&args.clip)?;
    let arm = args.arm.find(&clip, &args.clip)?;
    let settings = SegmentSettings {
        relative_to_shoulder: !args.world,
        min_peak_speed: args.min_peak_speed,
        ..SegmentSettings::default()
    };
    let name = args.clip.display().to_string();
    let segments =
        find_segments(&clip, &arm, &settings).map_err(|e| Failure::input(&args.clip, e))?;
    let main = main_segment(&clip, &arm, &settings, &name).ok();
    let dt = clip.frame_time();
    let report = Report {
        clip: name.clone(),
        arm: arm
            .names(clip.skeleton())
            .into_iter()
            .map(String::from)
            .collect(),
        frames: clip.frame_count(),
        frame_time_s: dt,
        speed: if args.world {
            "world"
        } else {
            "relative to the shoulder"
        },
        segments: segments
            .iter()
            .map(|s| Row {
                onset: s.onset,
                peak: s.peak,
                end: s.end,
                onset_s: s.onset as f64 * dt,
                peak_s: s.peak as f64 * dt,
                end_s: s.end as f64 * dt,
                duration_s: s.duration(dt),
                peak_speed_m_s: s.peak_speed,
                main: main.as_ref() == Some(s),
            })
            .collect(),
    };
    if args.json {
        return print_json(&report);
    }
    let mut text = format!(
        "{}: {} frames at {:.1} Hz, arm {}, hand speed {}\n",
        report.clip,
        report.frames,
        1.0 / dt,
        report.arm.join(" → "),
        report.speed
    );
    if report.segments.is_empty() {
        text.push_str(&format!(
            "no reach: the hand never moves faster than {} m/s for long enough\n",
            settings.min_peak_speed
        ));
    } else {
        text.push_str("  onset    peak     end   (frames)   duration  peak speed\n");
        for r in &report.segments {
            text.push_str(&format!(
                "  {:>5}   {:>5}   {:>5}              {:>6.2} s  {:>6.2} m/s{}\n",
                r.onset,
                r.peak,
                r.end,
                r.duration_s,
                r.peak_speed_m_s,
                if r.main { "   ← main reach" } else { "" }
            ));
        }
    }
    emit(&text)
}
