//! `kinergy collect`: a library fitted into a folder, checked and tabled.

use std::path::PathBuf;
use std::str::FromStr;

use kinergy_train::who::PersonRule;

use crate::common::{Failure, emit};

/// Arguments of `kinergy collect`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The folder `fit --per clip --out-dir DIR` (or its shards) fitted into.
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
    /// Name each reach's person (and motion) in library.csv by this rule instead of the one
    /// the library was fitted with (`fit --person`), without fitting anything or changing
    /// the shards' records: `auto`, `folder`, `file` (alias `prefix`), `segments`,
    /// `regex:PATTERN` or `map:FILE.csv`, as `fit --person` reads them. The table's
    /// `settings` fingerprint is then that of a fit with this rule.
    #[arg(long, value_name = "RULE", value_parser = PersonRule::from_str)]
    pub person: Option<PersonRule>,
}

/// Runs `kinergy collect`.
pub fn run(args: &Args) -> Result<(), Failure> {
    let collected = kinergy_train::library::collect_with(&args.dir, args.person.as_ref())?;
    emit(&collected.text)
}
