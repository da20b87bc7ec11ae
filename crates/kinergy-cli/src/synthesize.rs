//! `kinergy synthesize`: one reach by the synergy controller, from a capture's first frame
//! to its final hand position (or a given target), written as BVH on the capture's skeleton.
//! `--frames` picks the part of the capture the reach covers: by default the frames the
//! parameters were fitted on (so `fit` then `synthesize` replays what the fit scored), all of
//! it, the main reach segment, or given frames. `--params` takes a parameters file or a field
//! file: from a field, the vector is the one it predicts for the target in the arm's base frame
//! on the segment's first frame. Exit code 1 when the target is not reached; the motion is
//! written all the same.

use std::path::{Path, PathBuf};

use kinergy_motion::segment::Selection;
use kinergy_motion::{ExportOptions, LengthUnit, Side};
use kinergy_solver::{BaseMode, Model, OptimizerKind};
use kinergy_train::TrainError;
use kinergy_train::source::FrameChoice;
use kinergy_train::synthesize::{Drive, Step, SynthesisReport, SynthesizeError, SynthesizeRequest};

use crate::common::{ControllerKind, Failure, ReadArgs, emit, parse_point, print_json};

/// Arguments of `kinergy synthesize`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The capture: the reach starts from its first frame, its torso motion is replayed.
    #[arg(value_name = "CLIP.bvh", required_unless_present = "from")]
    clip: Option<PathBuf>,
    /// The capture, given as an option (the older spelling of CLIP; not both).
    #[arg(long, value_name = "CLIP.bvh", conflicts_with = "clip")]
    from: Option<PathBuf>,
    /// Where to write the synthesized motion (BVH, written atomically).
    #[arg(short, long, value_name = "OUT.bvh")]
    output: PathBuf,
    /// A parameters file (from `kinergy fit`: model, optimizer and values), or a field file
    /// (`kinergy fit --field`): the vector it predicts for the target, taken in the arm's
    /// base frame on the segment's first frame.
    #[arg(long, value_name = "P.json", conflicts_with_all = ["model", "optimizer"])]
    params: Option<PathBuf>,
    /// Synergy model without a parameters file: neutral values (gains 1, sigmoids on).
    #[arg(long, default_value = "sa", value_name = "sa|sb|sc|sd|se")]
    model: Model,
    /// IK optimizer without a parameters file, with its default settings.
    #[arg(long, default_value = "svd", value_name = "jt|njt|svd|dls")]
    optimizer: OptimizerKind,
    /// Target hand position in world meters `x,y,z` (default: the capture's final hand
    /// position).
    #[arg(long, value_name = "x,y,z", allow_hyphen_values = true)]
    target: Option<String>,
    /// Keep the shoulder where it is on the first frame instead of replaying the capture's
    /// torso motion.
    #[arg(long)]
    fixed_base: bool,
    /// The synergy controller: `smooth` (bounded accelerations, progress floor, the finish to
    /// the plain optimizer after the reach's frames, the capture's start velocity) or `paper`
    /// (Aubry et al.'s controller alone, from rest). Default: the one the parameters were
    /// fitted under (their file records it, `fit --controller`), else smooth; another one
    /// than they were fitted under gets a warning.
    #[arg(long, value_parser = crate::common::named::<ControllerKind>(ControllerKind::ALL.map(ControllerKind::name)))]
    controller: Option<ControllerKind>,
    /// Stop as soon as the target is reached (default: keep tracking it at least until the
    /// capture's last frame, and on until it is reached, up to --max-seconds).
    #[arg(long)]
    stop_at_reach: bool,
    /// Which frames of the capture the reach covers: `fit` (the frames the --params file
    /// was fitted on for this capture, so the motion is the one the fit scored; all frames
    /// without such a record), `all`, `auto` (the main reach segment of the hand speed, as
    /// `kinergy fit` picks it by default) or `A..B` (0-based, end excluded).
    #[arg(long, default_value = "fit", value_name = "fit|all|auto|A..B")]
    frames: String,
    /// Instead of `--frames`, a labelled segment of the capture: `main` (its main reach, as
    /// `--frames auto`) or `N` (segment N as `kinergy segment` lists them, from 0).
    #[arg(long, value_name = "main|N", conflicts_with = "frames")]
    select: Option<Selection>,
    /// ε: the target counts as reached within this many meters (0.00001 to 1).
    #[arg(long, default_value_t = 0.005, value_name = "M")]
    tolerance: f64,
    /// Longest motion synthesized, seconds (0.01 to 60).
    #[arg(long, default_value_t = 10.0, value_name = "S")]
    max_seconds: f64,
    /// Length unit of the written file: m, cm, mm, in or cmu.
    #[arg(long, default_value = "cm", value_name = "UNIT")]
    unit: LengthUnit,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
    #[command(flatten)]
    read: ReadArgs,
    /// Which arm. Default: the one the --params file was fitted on (its `fit.reaches[].arm`),
    /// else right. A capture arm that differs from the fitted one (the other side, or bones
    /// more than 10 % longer or shorter) gets a warning.
    #[arg(long, value_name = "SIDE")]
    arm: Option<Side>,
    /// The arm's joints by name, overriding the search: clavicle,shoulder,elbow,wrist (or
    /// shoulder,elbow,wrist).
    #[arg(long, value_delimiter = ',', value_name = "JOINTS")]
    chain: Option<Vec<String>>,
}

/// Runs `kinergy synthesize`: the request ([`SynthesizeRequest`]) from the flags, run, the
/// motion written and the report said.
pub fn run(args: &Args) -> Result<(), Failure> {
    args.read.check()?;
    let Some(from) = args.clip.as_deref().or(args.from.as_deref()) else {
        return Err(Failure::Input(
            "name the capture: kinergy synthesize CLIP.bvh …".into(),
        ));
    };
    let mut request = SynthesizeRequest {
        frames: frame_choice(args)?,
        arm: args.arm,
        chain: args.chain.clone(),
        base: if args.fixed_base {
            BaseMode::Fixed
        } else {
            BaseMode::Replay
        },
        controller: args.controller,
        target: None,
        drive: Drive::Neutral {
            model: args.model,
            optimizer: args.optimizer.default_optimizer(),
        },
        tolerance: args.tolerance,
        max_seconds: args.max_seconds,
        stop_at_reach: args.stop_at_reach,
    };
    request
        .validate()
        .map_err(|e| Failure::Input(format!("--{} {}", e.field.replace('_', "-"), e.why)))?;
    let mut inputs = vec![from];
    inputs.extend(args.params.as_deref());
    crate::common::check_outputs(&inputs, &[crate::common::Output::File("-o", &args.output)])?;
    if let Some(path) = &args.params {
        request.drive = Drive::Person {
            params: Box::new(crate::common::read_person(path)?),
            path: Some(path.clone()),
        };
    }
    let (whole, _) = args.read.read(from)?;
    if let Some(t) = &args.target {
        request.target = Some(parse_point(t, "--target")?);
    }
    let done = request
        .run(&whole, from)
        .map_err(|e| failure(args, &request, from, e))?;
    if let Some(warning) = &done.warning {
        eprintln!("warning: {warning}");
    }
    crate::common::write_clip(
        &args.output,
        &done.clip,
        &ExportOptions {
            unit: args.unit,
            ..Default::default()
        },
    )?;
    let report = SynthesisReport {
        output: Some(args.output.display().to_string()),
        ..done.report
    };
    if args.json {
        print_json(&report)?;
    } else {
        emit(&text(&report))?;
    }
    report.ending().map_err(|e| match e {
        TrainError::NotReached {
            final_error_m,
            shoulder_to_target_m,
            arm_length_m,
            ..
        } if shoulder_to_target_m > arm_length_m => Failure::Task(format!(
            "the target is beyond reach by {}: it is {} from the shoulder on the last frame and \
             the arm is {} long; the motion written to {} ends with the hand {} from it",
            crate::common::length(shoulder_to_target_m - arm_length_m),
            crate::common::length(shoulder_to_target_m),
            crate::common::length(arm_length_m),
            crate::common::shown(&args.output),
            crate::common::length(final_error_m)
        )),
        TrainError::NotReached {
            stop,
            final_error_m,
            ..
        } => Failure::Task(format!(
            "the target was not reached ({stop}): the motion written to {} ends {:.1} mm from it",
            crate::common::shown(&args.output),
            final_error_m * 1000.0
        )),
        e => e.into(),
    })
}

/// `--frames` or `--select`, as the reach's frames.
fn frame_choice(args: &Args) -> Result<FrameChoice, Failure> {
    Ok(match (args.select, args.frames.as_str()) {
        (Some(Selection::All), _) => {
            return Err(Failure::Input(
                "--select all: synthesize makes one reach; pick main or a segment number".into(),
            ));
        }
        (Some(Selection::Main), _) | (None, "auto") => FrameChoice::Main,
        (Some(Selection::Nth(n)), _) => FrameChoice::Nth(n),
        (None, "fit") => FrameChoice::Fitted,
        (None, "all") => FrameChoice::All,
        (None, text) => FrameChoice::Window(crate::common::parse_frames(text)?),
    })
}

/// A synthesis that failed, said with the flags and files behind it.
fn failure(args: &Args, request: &SynthesizeRequest, from: &Path, e: SynthesizeError) -> Failure {
    match (e.step, e.source) {
        (
            Step::Reach,
            TrainError::Arm {
                path,
                source,
                other_side,
            },
        ) => crate::common::args::arm_failure_with(source, &path, other_side),
        (
            Step::Frames,
            TrainError::Frames {
                frames, available, ..
            },
        ) => {
            // Name where the window came from: the option, or the parameters file's record.
            let source = match (&args.params, &request.frames) {
                (Some(path), FrameChoice::Fitted) => {
                    format!("{}: `fit.reaches` frames", path.display())
                }
                _ => "--frames".to_string(),
            };
            Failure::Input(format!(
                "{source} {}..{}: {} has {available} frames and a reach needs at least 2",
                frames.start,
                frames.end,
                from.display(),
            ))
        }
        (Step::Target, e) => Failure::Input(format!(
            "--target `{}`: {e}",
            kinergy_io::clip_text(args.target.as_deref().unwrap_or(""), 60)
        )),
        (Step::Frames | Step::Reach | Step::Clip, e) => Failure::input(from, e),
        (Step::Params, e) => Failure::Input(e.to_string()),
        (Step::Synthesis, e) => e.into(),
    }
}

fn text(r: &SynthesisReport) -> String {
    let mut s = format!(
        "{} → {}\narm: {}\nmodel {}, optimizer {}, base {}\ntarget ({:.4}, {:.4}, {:.4}) m from {}\n\
         stop: {} after {} frames ({:.3} s), final error {:.2} mm\n\
         the target is {:.3} m from the shoulder on the last frame; the arm is {:.3} m long\n",
        r.input,
        r.output.as_deref().unwrap_or("-"),
        r.arm.join(" → "),
        r.model,
        r.optimizer,
        r.base,
        r.target_m[0],
        r.target_m[1],
        r.target_m[2],
        r.target_from,
        r.stop,
        r.frames,
        r.duration_s,
        r.final_error_m * 1000.0,
        r.shoulder_to_target_m,
        r.arm_length_m,
    );
    if let Some(f) = &r.field {
        s.push_str(&format!(
            "parameters predicted by the field of {} reaches ({}) at ({:.4}, {:.4}, {:.4}) m \
             in the arm's base frame\n",
            f.samples,
            if f.bandwidth_m.is_infinite() {
                "flat: the person's single vector".to_string()
            } else {
                format!("bandwidth {:.3} m", f.bandwidth_m)
            },
            f.target_in_base_m[0],
            f.target_in_base_m[1],
            f.target_in_base_m[2]
        ));
    }
    if let Some(d) = r.distance_to_capture_m {
        s.push_str(&format!(
            "motion distance to the captured arm: {:.3} mm\n",
            d * 1000.0
        ));
    }
    if !r.at_limits_at_end.is_empty() {
        s.push_str(&format!(
            "at their limits on the last frame: {}\n",
            r.at_limits_at_end.join(", ")
        ));
    }
    if !r.widened_limits.is_empty() {
        s.push_str(&format!(
            "limits widened to include the captured start: {}\n",
            r.widened_limits.join(", ")
        ));
    }
    s
}
