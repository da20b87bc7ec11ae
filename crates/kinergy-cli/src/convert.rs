//! `kinergy convert`: read a BVH file and write it back, atomically, optionally in another
//! unit and cut to some of its frames.

use std::path::PathBuf;

use kinergy_motion::{ExportOptions, ExportUp, LengthUnit};

use serde::Serialize;

use crate::common::{Failure, ReadArgs, is_stdout, print_json};

/// What `kinergy convert --json` prints.
#[derive(Serialize)]
struct Report {
    input: String,
    output: String,
    frames: usize,
    frame_time_s: f64,
    joints: usize,
    unit: String,
}

/// Arguments of `kinergy convert`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The BVH file to read.
    input: PathBuf,
    /// Where to write (written to a temporary file, then renamed into place); `-` writes
    /// the BVH to standard output.
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
    /// Print a report of what was written as JSON (not with `-o -`).
    #[arg(long)]
    json: bool,
    /// Length unit of the written file: m, cm, mm, in or cmu.
    #[arg(long, default_value = "cm", value_name = "UNIT")]
    unit: LengthUnit,
    /// Keep only frames `A..B` (0-based, end excluded), e.g. a reach segment found by
    /// `kinergy segment`.
    #[arg(long, value_name = "A..B")]
    frames: Option<String>,
    /// Up axis of the written file: `as-read` keeps the file's own axis (its joint values
    /// are written as read), `y` bakes the turn into the root so the file is Y-up (what
    /// Blender and three.js expect from BVH).
    #[arg(long = "up-out", default_value = "as-read", value_name = "AXIS")]
    up_out: UpOut,
    #[command(flatten)]
    read: ReadArgs,
}

/// The written file's up axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
enum UpOut {
    /// The axis the file was read with.
    AsRead,
    /// Y up.
    Y,
}

/// Runs `kinergy convert`.
pub fn run(args: &Args) -> Result<(), Failure> {
    let to_stdout = is_stdout(&args.output);
    if to_stdout && args.json {
        return Err(Failure::Input(
            "--json and -o - both write to standard output: write the BVH to a file".into(),
        ));
    }
    crate::common::check_outputs(
        &[&args.input],
        &[crate::common::Output::File("-o", &args.output)],
    )?;
    let (clip, _) = args.read.read(&args.input)?;
    let clip = match &args.frames {
        None => clip,
        Some(text) => {
            let range = crate::common::parse_frames(text)?;
            if range.end > clip.frame_count() {
                return Err(Failure::Input(format!(
                    "--frames {text}: {} has {} frames",
                    args.input.display(),
                    clip.frame_count()
                )));
            }
            clip.slice(range)
                .map_err(|e| Failure::input(&args.input, e))?
        }
    };
    let options = ExportOptions {
        unit: args.unit,
        up: match args.up_out {
            UpOut::AsRead => ExportUp::AsRead,
            UpOut::Y => ExportUp::Y,
        },
    };
    crate::common::write_clip(&args.output, &clip, &options)?;
    if args.json {
        print_json(&Report {
            input: args.input.display().to_string(),
            output: args.output.display().to_string(),
            frames: clip.frame_count(),
            frame_time_s: clip.frame_time(),
            joints: clip.skeleton().joints().len(),
            unit: args.unit.name().to_string(),
        })
    } else {
        Ok(())
    }
}
