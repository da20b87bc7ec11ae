//! `kinergy segment`: the labelled segments of captures — reach, return, other — from the
//! hand's speed and direction, listed, and optionally written as a segments file.
//!
//! Frames are `onset..end`, numbered from 0, end excluded (see `kinergy_motion::segment`):
//! what this prints pastes into `--frames A..B`.

use std::path::{Path, PathBuf};

use kinergy_motion::segment::{SegmentSettings, Selection};
use kinergy_train::listing::{ArmListing, FRAMES, SegmentListing};
use kinergy_train::segments_file::SegmentsFile;

use crate::common::{
    ArmArgs, ArmSide, Failure, ReadArgs, Skipped, check_range, emit, limits, print_json,
};

/// Arguments of `kinergy segment`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Captures: BVH files, or folders searched for them.
    #[arg(value_name = "CLIPS", required = true)]
    pub clips: Vec<PathBuf>,
    /// Which segments to list (and write): `main` (the main reach), `all` (every reach), or
    /// one segment's number N as listed, counted from 0. Default: every segment, whatever its
    /// label.
    #[arg(long, value_name = "main|all|N")]
    pub select: Option<Selection>,
    /// Also write the listed segments to this segments file, atomically (CSV:
    /// clip,onset,end,arm,label,person; clips relative to its folder, the person is the
    /// clip's folder name). Edit it by hand as you like. `-` writes it to standard output
    /// (clips relative to the current folder) instead of the listing.
    #[arg(long, value_name = "segments.csv")]
    pub manifest: Option<PathBuf>,
    /// Measure the hand's speed in the world instead of relative to the shoulder (then torso
    /// motion and walking count as hand motion).
    #[arg(long)]
    pub world: bool,
    /// Slowest peak hand speed that counts as motion, m/s, 0.001 to 50.
    #[arg(long, default_value_t = SegmentSettings::default().min_peak_speed, value_name = "M/S")]
    pub min_peak_speed: f64,
    /// Print JSON: one object for one clip, an array of them for several.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub read: ReadArgs,
    #[command(flatten)]
    pub arm: ArmArgs,
}

/// Segments one clip: for the arm named, the selected segments; with `--arm auto`, the
/// reaches of each arm that reaches (as `fit --arm auto` finds them), or the reason it has
/// none (`Ok(Err(skipped))`).
fn segment_clip(
    args: &Args,
    path: &Path,
    listing: &SegmentListing,
) -> Result<Result<Vec<ArmListing>, Skipped>, Failure> {
    let (clip, _) = args.read.read(path)?;
    // Errors name the capture.
    let failure = |e: kinergy_train::TrainError| match e {
        kinergy_train::TrainError::Setting(kinergy_io::InvalidSetting { field, why }) => {
            Failure::Input(format!("--{field}: {why}"))
        }
        e => Failure::input(path, e),
    };
    match args.arm.arm {
        ArmSide::Auto => listing.reaching_arms(path, &clip).map_err(failure),
        ArmSide::Side(side) => {
            let arm = args.arm.find(&clip, path)?;
            let listed = listing.arm(path, &clip, &arm, side).map_err(failure)?;
            Ok(Ok(vec![listed]))
        }
    }
}

fn text(report: &ArmListing, settings: &SegmentSettings, selected: bool) -> String {
    let mut out = format!(
        "{}: {} frames at {:.1} Hz, {} arm {}, hand speed {}\n",
        report.clip,
        report.frames,
        1.0 / report.frame_time_s,
        report.side,
        report.arm.join(" → "),
        report.speed
    );
    if report.segments.is_empty() {
        out.push_str(&if selected {
            "  no segment selected\n".to_string()
        } else {
            format!(
                "  no segment: the hand never moves faster than {} m/s for {} s\n",
                settings.min_peak_speed, settings.min_duration
            )
        });
        return out;
    }
    out.push_str("     #  frames     label   peak  duration  peak speed  moves\n");
    for r in &report.segments {
        let cut = match (r.truncated_start, r.truncated_end) {
            (true, true) => "  cut at both ends",
            (true, false) => "  cut at start",
            (false, true) => "  cut at end",
            (false, false) => "",
        };
        out.push_str(&format!(
            "  {:>4}  {:<9}  {:<6} {:>5}  {:>6.2} s  {:>6.2} m/s  {:.2} m{}{cut}{}\n",
            r.index,
            r.frames,
            r.label,
            r.peak,
            r.duration_s,
            r.peak_speed_m_s,
            r.displacement_m,
            if r.in_world { " (in the world)" } else { "" },
            if r.main { "  ← main reach" } else { "" }
        ));
    }
    out
}

/// Runs `kinergy segment`.
pub fn run(args: &Args) -> Result<(), Failure> {
    args.read.check()?;
    if let (ArmSide::Auto, Some(Selection::Nth(n))) = (args.arm.arm, args.select) {
        return Err(Failure::Input(format!(
            "--select {n}: one numbered segment names no arm: with --arm auto select main or all"
        )));
    }
    check_range(
        "--min-peak-speed",
        args.min_peak_speed,
        limits::MIN_PEAK_SPEED,
    )?;
    let clips = crate::common::collect_clips(&args.clips)?;
    let manifest_to_stdout = args
        .manifest
        .as_deref()
        .is_some_and(crate::common::is_stdout);
    if manifest_to_stdout && args.json {
        return Err(Failure::Input(
            "--manifest - and --json both want standard output: write the segments file to a \
             path, or drop --json"
                .into(),
        ));
    }
    if let Some(path) = args.manifest.as_deref().filter(|_| !manifest_to_stdout) {
        let mut inputs: Vec<&Path> = args.clips.iter().map(PathBuf::as_path).collect();
        inputs.extend(clips.iter().map(PathBuf::as_path));
        crate::common::check_outputs(&inputs, &[crate::common::Output::File("--manifest", path)])?;
    }
    let settings = SegmentSettings {
        relative_to_shoulder: !args.world,
        ..SegmentSettings::default().with_min_peak_speed(args.min_peak_speed)
    };
    settings
        .validate()
        .map_err(|e| Failure::Input(format!("--min-peak-speed {}: {e}", args.min_peak_speed)))?;
    let listing = SegmentListing {
        selection: args.select,
        settings,
    };
    let mut reports = Vec::with_capacity(clips.len());
    let mut rows = Vec::new();
    let mut skipped = Vec::new();
    for path in &clips {
        match segment_clip(args, path, &listing)? {
            Ok(arms) => {
                for report in arms {
                    rows.extend(report.rows.iter().cloned());
                    reports.push(report);
                }
            }
            Err(skip) => skipped.push(skip),
        }
    }
    crate::common::report_skipped(&skipped);
    if reports.is_empty() {
        return Err(crate::common::nothing_to_fit(&skipped));
    }
    if manifest_to_stdout {
        // Clips relative to the current folder, as a file written here would list them.
        let here = std::env::current_dir()
            .map_err(|e| Failure::Task(format!("the current folder: {e}")))?
            .join("segments.csv");
        crate::common::set_quiet(true);
        return crate::common::emit_data(SegmentsFile::new(here, rows).to_csv().as_bytes());
    }
    let written = match &args.manifest {
        Some(path) => {
            let manifest = SegmentsFile::new(path, rows);
            manifest
                .write()
                .map_err(|e| Failure::Task(format!("could not write the segments file: {e}")))?;
            Some((path, manifest.rows().len()))
        }
        None => None,
    };
    if args.json {
        return if reports.len() == 1 {
            print_json(&reports[0])
        } else {
            print_json(&reports)
        };
    }
    let mut out: Vec<String> = reports
        .iter()
        .map(|r| text(r, &settings, args.select.is_some()))
        .collect();
    out.push(format!("({FRAMES})\n"));
    if let Some((path, n)) = written {
        out.push(format!(
            "{n} segment{} written to {}\n",
            if n == 1 { "" } else { "s" },
            path.display()
        ));
    }
    emit(&out.join(""))
}
