//! `kinergy convert`: read a BVH file and write it back, atomically, optionally in another
//! unit and cut to some of its frames.

use std::path::PathBuf;

use kinergy_motion::{ExportOptions, LengthUnit};

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
    #[command(flatten)]
    read: ReadArgs,
}

/// Runs `kinergy convert`.
pub fn run(args: &Args) -> Result<(), Failure> {
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
            ..Default::default()
        },
    )
    .map_err(|e| Failure::Task(format!("{}: {e}", args.output.display())))
}
