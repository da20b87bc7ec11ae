//! The arguments of `kinergy fit`.

use std::path::PathBuf;
use std::str::FromStr;

use kinergy_solver::{FitGrouping, Model, OptimizerKind};
use kinergy_train::who::PersonRule;

use crate::common::{CaptureArgs, SearchArgs};

/// Arguments of `kinergy fit`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Captures: BVH files or folders of them. With `--segments` they may be left out (the
    /// segments file names the clips); given, they keep only the rows of those clips.
    #[arg(value_name = "CLIPS", required_unless_present = "segments")]
    pub clips: Vec<PathBuf>,
    /// The synergy model to fit: the paper's S_A … S_D, or `se`, S_E (beyond the paper: S_D
    /// with per-DoF gain growth and the person's acceleration and onset;
    /// `docs/guide/fitting.md` "S_E, beyond the paper").
    #[arg(long, value_name = "sa|sb|sc|sd|se")]
    pub model: Model,
    /// The IK optimizer the motions are synthesized with.
    #[arg(long, default_value = "svd", value_name = "jt|njt|svd|dls")]
    pub optimizer: OptimizerKind,
    /// One vector per clip, or one for all clips.
    #[arg(long, value_enum, default_value = "person")]
    pub per: Per,
    /// Fit only the model asked for, from its neutral vector, instead of the poorer models
    /// first (S_A → S_B → S_C → S_D → S_E), each starting from the previous solution.
    #[arg(long)]
    pub no_nested: bool,
    /// Fit each reach on its own (nested, as `--per clip` does), then the person's parameter
    /// field over the reaches' targets (in the arm's base frame on each reach's first frame;
    /// kernel bandwidth chosen by leave-one-out), and write it as a field file to `-o FILE`:
    /// `synthesize --params` takes it where it takes a parameters file and predicts the
    /// person's vector for the target at hand. One arm per field.
    #[arg(long, conflicts_with_all = ["out_dir", "checkpoint"])]
    pub field: bool,
    /// Where to write the parameters (JSON, atomically). Ending in `/` (`-o fits/`) it names
    /// a folder, as `--out-dir` does; several results (`--per clip` over several reaches)
    /// need a folder.
    #[arg(
        short,
        long,
        value_name = "params.json",
        required_unless_present = "out_dir"
    )]
    pub output: Option<PathBuf>,
    /// A folder that receives one file per fit, named by the clip's path from the clips'
    /// common folder (`p01/r01.json`; `p01/r01_<onset>-<end>.json` for several reaches of
    /// one clip). It is created if missing; its parent must exist. With `--per clip` it
    /// holds a library: `library.csv` (one row per reach), `skipped.csv` (takes with nothing
    /// to fit, and why) and `shards/` (each shard's record, for `kinergy collect`).
    #[arg(long, value_name = "DIR", conflicts_with = "output")]
    pub out_dir: Option<PathBuf>,
    /// Checkpoint file, written atomically every `--checkpoint-every` iterations and on
    /// Ctrl-C.
    #[arg(long, value_name = "F")]
    pub checkpoint: Option<PathBuf>,
    /// Iterations between checkpoints, 1 to 1000000.
    #[arg(long, default_value_t = 20, value_name = "N")]
    pub checkpoint_every: usize,
    /// Continue the fit saved in `--checkpoint` (same clips and settings); the result is bit
    /// for bit the uninterrupted fit's. For a library (`--per clip` into a folder): skip the
    /// reaches whose result file is already complete, fit the rest.
    #[arg(long)]
    pub resume: bool,
    /// For a library (`--per clip --out-dir DIR`): fit shard I of N (1 ≤ I ≤ N) — a
    /// deterministic share of the takes, balanced by their frame counts — writing into DIR
    /// beside the other shards; then `kinergy collect DIR`. Default: the Slurm array task
    /// (`SLURM_ARRAY_TASK_ID` from `SLURM_ARRAY_TASK_MIN`, of `SLURM_ARRAY_TASK_COUNT`) when
    /// those are set, else the whole library.
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// For a library (`--per clip --out-dir DIR`): who moves in each take, library.csv's
    /// `person` (and `motion`) — `auto` (default: the `person` column of `--segments`; else
    /// the performer a Bandai `dataset-N_MOTION_STYLE_NNN` or CMU `SS_TT` file name gives;
    /// else the folder), `folder` (the take's folder from the library's root; the root's own
    /// takes: the root's name), `file` (the file name: Bandai's STYLE, CMU's subject,
    /// `STYLE_NNN` → STYLE, else the name; alias `prefix`), `segments`, `regex:PATTERN` (its
    /// group `person`, or its first group, in the take's path from the root; an optional
    /// group `motion`) or `map:FILE.csv` (rows `take,person`, optionally `motion`). Recorded
    /// among the library's settings; a motion is Bandai's MOTION unless the rule says one.
    #[arg(long, value_name = "RULE", value_parser = PersonRule::from_str)]
    pub person: Option<PersonRule>,
    /// For a library (`--per clip --out-dir DIR`) of a person's repeats: the first reach of
    /// each person, motion (by `--person`) and arm is fitted as usual, every model nested;
    /// the group's other reaches anneal the model asked for alone, from its vector (about a
    /// third of the evaluations on the shared people's raises, at a like distance; worse
    /// fits where a person's reaches differ). Each result records its start
    /// (`fit.started_from`); recorded among the library's settings.
    #[arg(long)]
    pub warm_start: bool,
    /// Write the score of every iteration to this CSV file.
    #[arg(long, value_name = "F.csv")]
    pub log: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    /// After the annealing, refine the fitted model's vector locally — rounds of Nelder–Mead
    /// and of Levenberg–Marquardt on the motion's joint-position residuals — with at most N
    /// evaluations (1 to 10000000): the annealing finds a basin, the refinement its floor.
    /// Deterministic; never worse than the annealing's vector. The file's `fit.method` then
    /// reads `simulated_annealing+nelder_mead+levenberg_marquardt` and its evaluations include
    /// the refinement's.
    #[arg(long, value_name = "N")]
    pub refine: Option<usize>,
    /// Testing hook: behave as if Ctrl-C came after this many iterations in all.
    #[arg(long, hide = true, value_name = "N")]
    pub interrupt_after: Option<usize>,
    #[command(flatten)]
    pub search: SearchArgs,
    #[command(flatten)]
    pub reach: CaptureArgs,
}

/// One vector per clip or one for all clips.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Per {
    /// One parameter vector per clip (the paper's experiment).
    Clip,
    /// One parameter vector for all the clips (one person's).
    Person,
}

impl Per {
    /// The grouping the parameters file records.
    pub fn grouping(self) -> FitGrouping {
        match self {
            Per::Clip => FitGrouping::Clip,
            Per::Person => FitGrouping::Person,
        }
    }
}
