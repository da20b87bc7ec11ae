//! The `kinergy` command line. Exit codes: 0 done, 1 the task failed, 2 bad input.

use std::process::ExitCode;

use clap::{CommandFactory, Parser, Subcommand};

mod animate;
mod collect;
mod common;
mod compare;
mod convert;
mod fit;
mod from_positions;
mod inspect;
mod plan;
mod plot;
mod reach;
mod retarget;
mod segment;
mod style;
mod synth;
mod synthesize;
mod view;

/// Learn and synthesize human reaching motion from BVH captures.
#[derive(Debug, Parser)]
#[command(
    name = "kinergy",
    version,
    about = "Learn how a person reaches from BVH captures and synthesize reaches in that style.",
    after_help = "A walk-through:\n  kinergy inspect capture.bvh\n  kinergy fit capture.bvh --model sc --per clip -o sc.json\n  kinergy synthesize capture.bvh --params sc.json --frames auto -o sc.bvh\n  kinergy plot speed capture.bvh sc.bvh -o speed.svg\n  kinergy animate capture.bvh sc.bvh -o overlay.gif --view side\n\nExit codes: 0 done, 1 the task failed (e.g. unreachable), 2 bad input."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
    /// Print no report on standard output (errors still go to standard error, and `-o -`
    /// still writes its data there).
    #[arg(short, long, global = true)]
    quiet: bool,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Show a capture's skeleton, units, frame rate, root reading and arm chains.
    #[command(after_help = "Example:\n  kinergy inspect tests/data/cmu_12_01_walk.bvh --json")]
    Inspect(inspect::Args),
    /// Read a BVH file and write it back (optionally in another unit), atomically.
    #[command(
        after_help = "Examples:\n  kinergy convert in.bvh -o out.bvh --unit m\n  kinergy convert capture.bvh --frames 5..88 -o reach.bvh\n  kinergy convert capture.bvh --unit m -o - | less"
    )]
    Convert(convert::Args),
    /// Find the segments of captures' hand speed and label them reach, return or other
    /// (frames onset..end, peak); optionally write them as an editable segments file.
    #[command(
        after_help = "Examples:\n  kinergy segment tests/data/006_14.bvh\n  kinergy segment reach.bvh --arm left --json\n  kinergy segment takes/ --arm left --select all --manifest segments.csv"
    )]
    Segment(segment::Args),
    /// Make the synthetic motion-capture set: persons × reaches, with manifest.csv.
    #[command(
        after_help = "Examples:\n  kinergy synth\n  kinergy synth -o my-set --persons 2 --reaches 5 --seed 7\n  kinergy synth -o lib --persons 40 --reaches 40 --frame-rate 30 --both-hands 0.3"
    )]
    Synth(synth::Args),
    /// Fit synergy parameters to captured reaches by simulated annealing, per clip or per
    /// person, and write the parameters file.
    #[command(
        after_help = "Examples:\n  kinergy fit me/ --model sc --optimizer svd -o me.json\n  kinergy fit reach.bvh --model sc --per clip --frames 12..140 --checkpoint fit.ckpt -o p.json\n  kinergy fit me/ --model sc --checkpoint fit.ckpt --resume -o me.json"
    )]
    Fit(fit::Args),
    /// Collect a library fitted into a folder (`fit --per clip --out-dir DIR`, in shards or
    /// not): check every take was fitted or skipped and every result is whole, and write
    /// DIR/library.csv and DIR/skipped.csv. Idempotent; exit 1 naming what is missing.
    #[command(after_help = "Examples:
  kinergy collect fits/
  kinergy collect fits/ --person file          # active_001.bvh → active, without refitting
  kinergy collect fits/ --person 'regex:^(?P<person>[^/]+)/'
  sbatch --dependency=afterany:$ARRAY_JOB --wrap 'kinergy collect fits/'")]
    Collect(collect::Args),
    /// Run the paper's experiments on captures (default: data-synthetic/): S_A–S_D per clip
    /// (Fig. 3), optimizers with S_A and S_C (Fig. 4), and annealing vs argmin's optimizers;
    /// writes results.csv, summary.md and the Fig. 3 / Fig. 4 charts.
    #[command(
        after_help = "Examples:\n  kinergy compare\n  kinergy compare me/ --models sa,sc --optimizers jt,svd -o out/ --budget 2000\n  kinergy compare takes/ --per person --holdout 1 --person file -o report/\n  kinergy compare --library fits/ -o report/"
    )]
    Compare(compare::Args),
    /// Synthesize one reach with the synergy controller from a capture's first frame to its
    /// final hand position (or --target), written on the capture's skeleton.
    #[command(
        after_help = "Examples:\n  kinergy synthesize reach.bvh --params sc.json --frames auto -o sc.bvh\n  kinergy synthesize reach.bvh --model sc --optimizer svd -o out.bvh\n  kinergy synthesize reach.bvh --params me.json --target 0.3,1.2,0.4 -o out.bvh --json"
    )]
    Synthesize(synthesize::Args),
    /// Synthesize one full-body reach (steps, spine, head, arm) toward a target, as BVH.
    #[command(
        after_help = "Examples:\n  kinergy reach --target 0.3,1.1,0.4 -o reach.bvh\n  kinergy reach --target 0.2,0.15,0.8 --flexibility 3 --seed 2 -o squat.bvh --json"
    )]
    Reach(reach::Args),
    /// Whether `reach --params` reaches in the person's style: the full-body character reaches
    /// each of their captures' targets with and without their parameters, and each motion's
    /// hand-speed profile is compared with the captured one (correlation, peak time).
    #[command(
        after_help = "Examples:\n  kinergy style takes/normal_00*.bvh --arm left --params normal.json\n  kinergy style takes/ --arm left --params field.json -o style/ --json"
    )]
    Style(style::Args),
    /// Plan collision-free reaching and manipulation in a scene (Kallmann 2005): IK with
    /// collision avoidance, RRT-Connect, smoothing; BVH with fingers.
    #[command(
        after_help = "Examples:\n  kinergy plan --scene examples/bookshelf/scene.json --task relocate --object blue_book --to -0.22,1.49,0.50 -o relocate.bvh\n  kinergy plan --scene examples/bookshelf/scene.json --target -0.25,1.1,0.3 --seed 3 -o reach.bvh --json\n  kinergy plan --scene examples/levels/board.json --target -0.2,1.15,0.35 --level planner -o board.bvh --tree-svg trees.svg"
    )]
    Plan(plan::Args),
    /// Draw charts: hand speed over time of captured and synthesized clips (Fig. 5).
    #[command(
        after_help = "Examples:\n  kinergy plot speed capture.bvh sa.bvh sc.bvh -o speed.svg\n  kinergy plot speed data-synthetic/p01 -o speed.png --csv speed.csv"
    )]
    Plot(plot::Args),
    /// Animate clips as superposed stick figures synchronized by time (the paper's Fig. 6:
    /// captured vs S_A vs S_C): an animated GIF and a film strip of snapshots.
    #[command(
        after_help = "Examples:\n  kinergy animate capture.bvh sa.bvh sc.bvh -o overlay.gif --view side\n  kinergy animate data-synthetic/p01/r01.bvh data-synthetic/p01/r02.bvh -o pair.gif --fps 12 --strip pair.svg --strip-frames 8 --json"
    )]
    Animate(animate::Args),
    /// Turn joint positions per frame (CSV or .npy; SMPL, Human3.6M, COCO, a JSON map or a
    /// BVH's skeleton) into BVH: bones of the median length, rotations from the children's
    /// directions.
    #[command(
        name = "from-positions",
        after_help = "Examples:\n  kinergy from-positions joints.csv --skeleton smpl24 -o out.bvh\n  kinergy from-positions keypoints.csv --skeleton h36m17 --unit mm --up z --frame-rate 50 -o out.bvh --json\n  kinergy from-positions lifted.npy --skeleton coco17 --frame-rate 30 -o out.bvh"
    )]
    FromPositions(from_positions::Args),
    /// Move a motion onto another skeleton: joints matched by role, the root's path scaled by
    /// leg length, hands and feet kept on their scaled paths by IK, planted feet held; with
    /// --params, the reach driven by a person's synergy on the new body.
    #[command(after_help = "Examples:
  kinergy retarget take.bvh --to cmu_rig.bvh -o take_on_cmu.bvh
  kinergy retarget take.bvh --to rig.bvh --to-map rig_roles.json -o out.bvh --json
  kinergy retarget take.bvh --to rig.bvh --params person.json -o driven.bvh")]
    Retarget(retarget::Args),
    /// Show clips in a browser: one self-contained HTML page (three.js, offline), the clips
    /// overlaid in 3-D with play, step, speed and a scrubber, and the hand-speed chart synced
    /// to it.
    #[command(
        after_help = "Examples:\n  kinergy view capture.bvh sa.bvh sc.bvh -o view.html\n  kinergy view data-synthetic/p01/r09.bvh --target 0.2,1.0,0.5 -o r09.html\n  kinergy view plan.bvh --scene examples/bookshelf/scene.json -o plan.html"
    )]
    View(view::Args),
    /// Print the shell completion script for bash, zsh, fish, elvish or PowerShell.
    #[command(
        after_help = "Examples:\n  kinergy completions bash > ~/.local/share/bash-completion/completions/kinergy\n  kinergy completions zsh > ~/.zfunc/_kinergy\n  kinergy completions fish > ~/.config/fish/completions/kinergy.fish"
    )]
    Completions {
        /// The shell.
        #[arg(value_enum)]
        shell: clap_complete::Shell,
    },
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    common::set_quiet(cli.quiet);
    let result = match cli.command {
        Command::Inspect(args) => inspect::run(&args),
        Command::Convert(args) => convert::run(&args),
        Command::Synthesize(args) => synthesize::run(&args),
        Command::Segment(args) => segment::run(&args),
        Command::Fit(args) => fit::run(&args),
        Command::Collect(args) => collect::run(&args),
        Command::Compare(args) => compare::run(&args),
        Command::Reach(args) => reach::run(&args),
        Command::Style(args) => style::run(&args),
        Command::Synth(args) => synth::run(&args),
        Command::Plan(args) => plan::run(&args),
        Command::Plot(args) => plot::run(&args),
        Command::Animate(args) => animate::run(&args),
        Command::View(args) => view::run(&args),
        Command::FromPositions(args) => from_positions::run(&args),
        Command::Retarget(args) => retarget::run(&args),
        Command::Completions { shell } => {
            let mut script = Vec::new();
            clap_complete::generate(shell, &mut Cli::command(), "kinergy", &mut script);
            common::emit_data(&script)
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(failure) => {
            #[allow(clippy::print_stderr)]
            {
                eprintln!("error: {failure}");
            }
            ExitCode::from(failure.exit_code())
        }
    }
}
