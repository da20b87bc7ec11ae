//! The arguments of `kinergy compare`.

use std::path::PathBuf;
use std::str::FromStr;

use kinergy_solver::{Model, OptimizerKind};
use kinergy_train::who::PersonRule;

use crate::common::{CaptureArgs, SearchArgs};

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
    /// With `--per person`: who a take belongs to, by the library's person rule — `auto`
    /// (default: the `person` column of `--segments`; else the performer a Bandai
    /// `dataset-N_MOTION_STYLE_NNN` or CMU `SS_TT` file name gives; else the folder), `folder`
    /// (the take's folder from the takes' common folder), `file` (the file name: Bandai's
    /// STYLE, CMU's subject, `STYLE_NNN` → STYLE, else the name; `prefix` is its old
    /// spelling), `segments`, `regex:PATTERN` (its group `person`, or its first group, in the
    /// take's path from the common folder) or `map:FILE.csv` (rows `take,person`).
    #[arg(long, value_name = "RULE", value_parser = PersonRule::from_str)]
    pub person: Option<PersonRule>,
    /// A fitted library (`fit --per clip --out-dir DIR`, or `collect DIR`): summarise its
    /// `library.csv` per person, per motion (where the takes' motions are known) and per
    /// model and draw Fig. 3 from it, without refitting (writes summary.md and fig3.svg/png
    /// to -o). Its persons are named when it is tabled: `collect DIR --person RULE`.
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
