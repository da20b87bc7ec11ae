//! The arguments of `kinergy compare`.

use std::path::{Path, PathBuf};

use kinergy_solver::{Model, OptimizerKind};
use kinergy_train::{CapturedReach, experiment};

use crate::common::{CaptureArgs, Failure, SearchArgs};

/// Arguments of `kinergy compare`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Captures: BVH files or folders of them (default: `data-synthetic/`).
    #[arg(value_name = "CLIPS")]
    pub clips: Vec<PathBuf>,
    /// Models for Fig. 3 (the paper's four by default; add `se` for S_E, beyond the paper).
    #[arg(long, value_delimiter = ',', default_value = "sa,sb,sc,sd")]
    pub models: Vec<Model>,
    /// Optimizers for Fig. 4.
    #[arg(long, value_delimiter = ',', default_value = "jt,njt,svd")]
    pub optimizers: Vec<OptimizerKind>,
    /// The optimizer of Fig. 3 and of the method comparison.
    #[arg(long, default_value = "svd")]
    pub optimizer: OptimizerKind,
    /// Skip the comparison with argmin's Nelder–Mead and particle swarm.
    #[arg(long)]
    pub no_baselines: bool,
    /// Output folder for results.csv, summary.md, the charts fig3/fig4 (.svg and .png) and
    /// view.html (the first reach, captured and as each model moves it).
    #[arg(short, long, default_value = "compare-out", value_name = "DIR")]
    pub output: PathBuf,
    /// What one vector is fitted to: each clip (the paper's experiment), or each person's
    /// training takes (needs `--holdout`).
    #[arg(long, default_value = "clip", value_name = "clip|person")]
    pub per: Per,
    /// With `--per person`: hold out the last K takes of each person (1 to 1000, in name order), fit on
    /// the rest and report the held-out takes' distances.
    #[arg(long, value_name = "K")]
    pub holdout: Option<usize>,
    /// With `--holdout`: how fast each held-out take is synthesized — under the fitted
    /// person's tempo law for its distance (a prediction, as `synthesize --params` and the
    /// full body deliver the person), or under the held-out capture's own speed (the protocol
    /// before the law was recorded, which tells the synthesis how fast the take moved).
    #[arg(
        long,
        default_value = "person",
        value_name = "person|capture",
        requires = "holdout"
    )]
    pub held_out_tempo: HeldOutTempoArg,
    /// With `--per person`: who a take belongs to — its folder, its file name up to the
    /// last `_` (`active_003.bvh` → `active`), or the `person` column of `--segments`.
    /// Default: `segments` when a segments file is given, else `folder`.
    #[arg(long, value_name = "folder|prefix|segments")]
    pub person: Option<PersonBy>,
    /// A fitted library (`fit --per clip --out-dir DIR`, or `collect DIR`): summarise its
    /// `library.csv` per person and per model and draw Fig. 3 from it, without refitting
    /// (writes summary.md and fig3.svg/png to -o).
    #[arg(long, value_name = "DIR", conflicts_with_all = ["clips", "segments", "holdout"])]
    pub library: Option<PathBuf>,
    /// Print the summary as JSON too.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub search: SearchArgs,
    #[command(flatten)]
    pub reach: CaptureArgs,
}

pub use kinergy_draw::experiment::model_label;

/// What one vector is fitted to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Per {
    /// Each clip.
    Clip,
    /// Each person's training takes.
    Person,
}

/// How fast a held-out take is synthesized ([`kinergy_train::experiment::HeldOutTempo`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum HeldOutTempoArg {
    /// The fitted person's tempo law for the take's distance.
    Person,
    /// The held-out capture's own speed.
    Capture,
}

impl From<HeldOutTempoArg> for kinergy_train::experiment::HeldOutTempo {
    fn from(a: HeldOutTempoArg) -> Self {
        match a {
            HeldOutTempoArg::Person => Self::Person,
            HeldOutTempoArg::Capture => Self::Capture,
        }
    }
}

/// Who a take belongs to.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum PersonBy {
    /// The clip's folder (`data-synthetic/p01/r03.bvh` → `data-synthetic/p01`).
    Folder,
    /// The clip's file name up to its last `_` (`active_003.bvh` → `active`).
    Prefix,
    /// The `person` column of the segments file (`--segments`).
    Segments,
}

impl PersonBy {
    /// The person of `reach` (named by its clip's path); `listed` is the person its
    /// segments-file row names, if any.
    pub fn person(self, reach: &CapturedReach, listed: Option<&str>) -> Result<String, Failure> {
        let path = Path::new(reach.name());
        Ok(match self {
            PersonBy::Segments => listed
                .ok_or_else(|| Failure::Input("--person segments needs --segments FILE".into()))?
                .to_string(),
            PersonBy::Folder => {
                let folder = experiment::person_of(reach);
                if folder.as_os_str().is_empty() {
                    ".".into()
                } else {
                    folder.display().to_string()
                }
            }
            PersonBy::Prefix => {
                let stem = path
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_default();
                match stem.rsplit_once('_') {
                    Some((prefix, _)) if !prefix.is_empty() => prefix.to_string(),
                    _ => stem,
                }
            }
        })
    }
}
