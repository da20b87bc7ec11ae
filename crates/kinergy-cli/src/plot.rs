//! `kinergy plot`: charts of captured and synthesized motions.
//!
//! `kinergy plot speed CLIPS... -o speed.svg|png` draws each clip's hand speed over time on
//! one chart (the paper's Fig. 5: a capture beside its S_A and S_C syntheses), with a legend
//! and axes in seconds and meters per second; `--csv` also writes the series.

use std::path::PathBuf;

use kinergy_draw::{LineChart, Series, save};
use kinergy_motion::segment::{SegmentSettings, hand_speed};
use serde::Serialize;

use crate::common::{
    ArmArgs, Failure, ReadArgs, check_range, collect_clips, emit, limits, parse_size, print_json,
};

/// Arguments of `kinergy plot`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// What to plot.
    #[command(subcommand)]
    pub chart: Chart,
}

/// The charts `kinergy plot` draws.
#[derive(Debug, clap::Subcommand)]
pub enum Chart {
    /// Hand speed over time of several clips on one chart (the paper's Fig. 5).
    #[command(
        after_help = "Examples:\n  kinergy plot speed capture.bvh sa.bvh sc.bvh -o speed.svg\n  kinergy plot speed data-synthetic/p01 --arm left --relative -o speed.png --csv speed.csv"
    )]
    Speed(SpeedArgs),
}

/// Arguments of `kinergy plot speed`.
#[derive(Debug, clap::Args)]
pub struct SpeedArgs {
    /// BVH clips or folders of them (one line each, at most 12).
    #[arg(value_name = "CLIPS", required = true)]
    pub clips: Vec<PathBuf>,
    /// Where to draw the chart: `.svg` or `.png` (written atomically).
    #[arg(short, long, value_name = "speed.svg|png")]
    pub output: PathBuf,
    /// Also write the series as CSV (`clip,time_s,speed_m_s`, one row per frame).
    #[arg(long, value_name = "FILE.csv")]
    pub csv: Option<PathBuf>,
    /// The hand's speed relative to the shoulder (the arm's own motion) instead of in world.
    #[arg(long)]
    pub relative: bool,
    /// Moving-average window, seconds, 0 to 10 (0: the raw central differences).
    #[arg(long, default_value_t = 0.0, value_name = "S")]
    pub smoothing: f64,
    /// The chart's title.
    #[arg(long, default_value = "Hand speed", value_name = "TEXT")]
    pub title: String,
    /// Picture size in pixels, `WIDTHxHEIGHT`, each side 64 to 3840.
    #[arg(long, default_value = "900x500", value_name = "WxH")]
    pub size: String,
    /// Print a summary as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub arm: ArmArgs,
    #[command(flatten)]
    pub read: ReadArgs,
}

#[derive(Serialize)]
struct ClipSummary {
    path: String,
    name: String,
    frames: usize,
    duration_s: f64,
    peak_speed_m_s: f64,
    peak_time_s: f64,
}

#[derive(Serialize)]
struct Report {
    output: String,
    csv: Option<String>,
    clips: Vec<ClipSummary>,
}

/// Runs `kinergy plot`.
pub fn run(args: &Args) -> Result<(), Failure> {
    match &args.chart {
        Chart::Speed(a) => speed(a),
    }
}

fn speed(args: &SpeedArgs) -> Result<(), Failure> {
    crate::common::picture_format(&args.output, "-o")?;
    args.read.check()?;
    let size = parse_size(&args.size)?;
    check_range("--smoothing", args.smoothing, limits::PLOT_SMOOTHING)?;
    let paths = collect_clips(&args.clips)?;
    if paths.len() > 12 {
        return Err(Failure::Input(format!(
            "{} clips: a chart shows at most 12 lines",
            paths.len()
        )));
    }
    {
        use crate::common::{Output, check_outputs};
        let mut inputs: Vec<&std::path::Path> = args.clips.iter().map(|p| p.as_path()).collect();
        inputs.extend(paths.iter().map(|p| p.as_path()));
        let mut outputs = vec![Output::File("-o", &args.output)];
        outputs.extend(args.csv.as_deref().map(|p| Output::File("--csv", p)));
        check_outputs(&inputs, &outputs)?;
    }
    let settings = SegmentSettings {
        smoothing: args.smoothing,
        relative_to_shoulder: args.relative,
        ..SegmentSettings::default()
    };
    let mut series = Vec::new();
    let mut summaries = Vec::new();
    let mut csv = String::from("clip,time_s,speed_m_s\n");
    for path in &paths {
        let (clip, _) = args.read.read(path)?;
        let arm = args.arm.find(&clip, path)?;
        let speed = hand_speed(&clip, &arm, &settings).map_err(|e| Failure::input(path, e))?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| path.display().to_string());
        let dt = clip.frame_time();
        let points: Vec<(f64, f64)> = speed
            .iter()
            .enumerate()
            .map(|(i, &v)| (i as f64 * dt, v))
            .collect();
        for (t, v) in &points {
            csv += &format!("{name},{t},{v}\n");
        }
        let (peak_time_s, peak_speed_m_s) = points
            .iter()
            .copied()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0.0, 0.0));
        summaries.push(ClipSummary {
            path: path.display().to_string(),
            name: name.clone(),
            frames: clip.frame_count(),
            duration_s: clip.frame_count().saturating_sub(1) as f64 * dt,
            peak_speed_m_s,
            peak_time_s,
        });
        series.push(Series::new(name, points));
    }
    let chart = LineChart {
        title: args.title.clone(),
        x_label: "time (s)".into(),
        y_label: if args.relative {
            "hand speed relative to the shoulder (m/s)".into()
        } else {
            "hand speed (m/s)".into()
        },
        series,
    };
    save(&chart, &args.output, size)?;
    if let Some(csv_path) = &args.csv
        && let Err(e) = kinergy_io::write_atomic(csv_path, csv.as_bytes())
    {
        let _ = std::fs::remove_file(&args.output);
        return Err(Failure::task(csv_path, e));
    }
    let report = Report {
        output: args.output.display().to_string(),
        csv: args.csv.as_ref().map(|p| p.display().to_string()),
        clips: summaries,
    };
    if args.json {
        return print_json(&report);
    }
    let mut text = format!(
        "{}: hand speed of {} clips\n",
        report.output,
        report.clips.len()
    );
    for c in &report.clips {
        text += &format!(
            "  {:<24} {:>5} frames, {:.2} s, peak {:.2} m/s at {:.2} s\n",
            c.name, c.frames, c.duration_s, c.peak_speed_m_s, c.peak_time_s
        );
    }
    emit(&text)
}
