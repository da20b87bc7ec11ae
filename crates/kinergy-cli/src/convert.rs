//! `kinergy convert`: read a BVH file and write it back, atomically.

use std::path::PathBuf;

use kinergy_motion::{ExportOptions, LengthUnit};

use crate::common::{Failure, ReadArgs};

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
    #[command(flatten)]
    read: ReadArgs,
}

pub fn run(args: &Args) -> Result<(), Failure> {
    let (clip, _) = args.read.read(&args.input)?;
    kinergy_motion::write_clip(&args.output, &clip, &ExportOptions { unit: args.unit })
        .map_err(|e| Failure::Task(format!("{}: {e}", args.output.display())))
}
