//! `kinergy collect`: a library fitted into a folder, checked and tabled.

use std::path::PathBuf;

use crate::common::{Failure, emit};

/// Arguments of `kinergy collect`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The folder `fit --per clip --out-dir DIR` (or its shards) fitted into.
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
}

/// Runs `kinergy collect`.
pub fn run(args: &Args) -> Result<(), Failure> {
    let collected = kinergy_train::library::collect(&args.dir)?;
    emit(&collected.text)
}
