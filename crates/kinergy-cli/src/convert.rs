//! `kinergy convert`: read a BVH file and write it back, atomically, optionally in another
//! unit and cut to some of its frames.

use std::path::PathBuf;

use kinergy_motion::{ExportOptions, ExportUp, LengthUnit};

use crate::common::{Failure, ReadArgs};

/// Arguments of `kinergy convert`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The BVH file to read.
    input: PathBuf,
    /// Where to write (written to a temporary file, then renamed into place).
    #[arg(short, long, value_name = "FILE")]
    output: PathBuf,
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
    kinergy_motion::write_clip(
        &args.output,
        &clip,
        &ExportOptions {
            unit: args.unit,
            up: match args.up_out {
                UpOut::AsRead => ExportUp::AsRead,
                UpOut::Y => ExportUp::Y,
            },
        },
    )
    .map_err(|e| Failure::Task(format!("{}: {e}", args.output.display())))
}
