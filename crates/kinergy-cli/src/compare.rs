//! `kinergy compare`: the paper's two experiments on a set of captures, plus what simulated
//! annealing buys over argmin's optimizers.
//!
//! - **Fig. 3** — every model of `--models`, fitted per clip with `--optimizer` (default
//!   SVD), nested: each richer model starts from the poorer one's solution.
//! - **Fig. 4** — every optimizer of `--optimizers` with S_A and with S_C, per clip (S_C
//!   starting from S_A's solution; for the Fig. 3 optimizer the Fig. 3 fits are reused).
//! - **Methods** — S_C per clip from its neutral vector under the same evaluation budget with
//!   simulated annealing, argmin's Nelder–Mead and argmin's particle swarm.
//! - **Parameter field** — per person (the clips of one folder), each clip's S_C parameters
//!   predicted from the other clips' fits by the field over targets, scored on the clip
//!   (leave one target out), beside the clip's own fit.
//!
//! Writes `DIR/results.csv` (one row per fit: `clip,model,optimizer,method,distance_m,frames,
//! evaluations,seconds`), `DIR/summary.md` (mean/min/max per model, per optimizer and per
//! method, the relative reductions beside the paper's) and the charts `DIR/fig3.svg|png` and
//! `DIR/fig4.svg|png` (mean with min–max bars). Clips are fitted in parallel; every
//! number but `seconds` is the same on any thread count. The experiment itself is
//! [`kinergy_train::experiment`]; this command reads the options and renders its results.
//!
//! With `--per person --holdout K` it runs the held-out experiment instead ([`holdout`]):
//! per person (`--person RULE`, [`kinergy_train::who`]), `--models` fitted on all but the last K takes in
//! name order, scored on those K against neutral parameters and every other person's vector,
//! and the person's parameter field of the training takes (each fitted on its own) against
//! their single vector; `DIR/holdout.csv` (`person,clip,arm,onset,end,fitted_on,model,optimizer,distance_m,
//! frames,params`, `fitted_on` empty for the neutral parameters, `params` one of `neutral`,
//! `vector`, `field`) and `DIR/summary.md`.

mod args;
mod holdout;
mod library;

pub use args::{Args, Per};

use std::path::PathBuf;
use std::time::Instant;

use kinergy_train::experiment::{
    self, ExperimentSettings, PAPER_MODEL_REDUCTIONS, PAPER_OPTIMIZER_REDUCTIONS, Results, Stats,
    Summary,
};
use serde::Serialize;

use crate::common::{Bar, CaptureClips, Failure, check_optional, emit, limits, print_json};

/// The folder `compare` uses when no clips are given.
pub const DEFAULT_DATA: &str = "data-synthetic";

/// Runs `kinergy compare`.
pub fn run(args: &Args) -> Result<(), Failure> {
    if let Some(dir) = &args.library {
        return library::run(args, dir);
    }
    args.search.check()?;
    args.reach.read.check()?;
    args.reach.check_arm()?;
    check_optional("--holdout", args.holdout, limits::HOLDOUT)?;
    args.search.apply_threads()?;
    let holdout = match (args.per, args.holdout) {
        (Per::Clip, None) => None,
        (Per::Person, Some(0)) => {
            return Err(Failure::Input(
                "--holdout 0: hold out at least 1 take per person".into(),
            ));
        }
        (Per::Person, Some(k)) => Some(k),
        (Per::Person, None) => {
            return Err(Failure::Input(
                "--per person needs --holdout K (the takes held out per person)".into(),
            ));
        }
        (Per::Clip, Some(_)) => {
            return Err(Failure::Input(
                "--holdout needs --per person (per clip, the field is left one target out)".into(),
            ));
        }
    };
    if args.models.is_empty() {
        return Err(Failure::Input("--models needs at least one model".into()));
    }
    let paths = if args.clips.is_empty() && args.reach.segments.is_none() {
        let default = PathBuf::from(DEFAULT_DATA);
        if !default.is_dir() {
            return Err(Failure::Input(format!(
                "no clips given and no {DEFAULT_DATA}/ folder here: name captures or folders, or run from the repository root"
            )));
        }
        vec![default]
    } else {
        args.clips.clone()
    };
    let clips = args.reach.clips(&paths)?;
    {
        use crate::common::{Output, check_outputs};
        let mut inputs: Vec<&std::path::Path> = paths.iter().map(PathBuf::as_path).collect();
        inputs.extend(clips.inputs());
        inputs.extend(args.reach.segments.as_deref());
        let files = output_files(&args.output, holdout.is_some());
        check_outputs(&inputs, &[Output::Folder("-o", &args.output, &files)])?;
    }
    if let Some(k) = holdout {
        let reaches = args.reach.load_all_with_persons(&clips)?;
        return holdout::run(args, reaches, k);
    }
    if args.person.is_some() {
        return Err(Failure::Input(
            "--person needs --per person --holdout K".into(),
        ));
    }
    run_experiment(args, &clips)
}

/// The experiments of Fig. 3, Fig. 4, the methods and the field on `clips`: results.csv,
/// summary.md and the charts into `-o`.
fn run_experiment(args: &Args, clips: &CaptureClips) -> Result<(), Failure> {
    let reaches = args.reach.load_all(clips)?;
    let settings = ExperimentSettings {
        models: args.models.clone(),
        optimizers: args.optimizers.clone(),
        optimizer: args.optimizer,
        baselines: !args.no_baselines,
        fit: args.search.settings()?,
    };
    settings.fit.anneal.validate().map_err(Failure::from)?;
    if args.models.is_empty() || args.optimizers.is_empty() {
        return Err(Failure::Input(
            "--models and --optimizers need at least one each".into(),
        ));
    }
    // Ctrl-C: the reaches in progress finish, the others are not started, nothing is written.
    ctrlc::set_handler(|| crate::fit::INTERRUPTED.store(true, std::sync::atomic::Ordering::SeqCst))
        .map_err(|e| Failure::Task(format!("cannot watch for Ctrl-C: {e}")))?;
    let clock = Instant::now();
    let bar = Bar::counting(reaches.len() as u64, "clips");
    let results =
        experiment::run_until(&reaches, &settings, &|| bar.inc(), &crate::fit::INTERRUPTED);
    bar.finish();
    let Some(results) = results.map_err(Failure::from)? else {
        return Err(Failure::Task(format!(
            "interrupted: the reaches in progress finished, the others were not fitted; nothing \
             was written to {}",
            args.output.display()
        )));
    };
    // Made once there is something to write: a failed run leaves no empty folder.
    crate::common::make_folder(&args.output)?;
    let seconds = clock.elapsed().as_secs_f64();

    let csv_path = args.output.join("results.csv");
    crate::common::write_csv(&csv_path, &results.rows)?;

    let summary = Summary::of(&results, &settings);
    let report = SummaryReport::new(&summary, &results, &settings, reaches.len(), seconds);
    let markdown = markdown(&report, &summary, &settings);
    let md_path = args.output.join("summary.md");
    kinergy_io::write_atomic(&md_path, markdown.as_bytes())
        .map_err(|e| Failure::task(&md_path, e))?;
    // Fig. 3 (per model) and Fig. 4 (per optimizer, S_A and S_C) next to summary.md.
    let charts = kinergy_draw::experiment::save_figures(
        &results,
        &args.models,
        &args.optimizers,
        args.optimizer,
        &args.output,
    )?;
    // The first reach, captured and as each model moves it, in the browser.
    let mut charts = charts;
    if let Some(reach) = reaches.first()
        && !results.first_reach_fits.is_empty()
    {
        let path = std::path::Path::new(reach.name());
        let (clip, _) = args.reach.read.read(path)?;
        let motions = experiment::fig3_clips(reach, &clip, &results.first_reach_fits, &settings)
            .map_err(Failure::from)?;
        let captured = clip
            .slice(reach.frames())
            .map_err(|e| Failure::task(path, e))?;
        charts.push(kinergy_draw::experiment::save_view(
            &args.output,
            reach.name(),
            &captured,
            &motions,
            reach.fitted_arm().side,
            reach.target(),
        )?);
    }
    if args.json {
        return print_json(&report);
    }
    emit(&format!(
        "{}\nwritten: {}, {} and {}\n",
        markdown,
        csv_path.display(),
        md_path.display(),
        charts
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    ))
}

/// Every file `compare -o DIR` may write: with `--holdout`, holdout.csv and summary.md;
/// without, results.csv, summary.md and the charts.
fn output_files(dir: &std::path::Path, holdout: bool) -> Vec<PathBuf> {
    let names: &[&str] = if holdout {
        &["holdout.csv", "summary.md"]
    } else {
        &[
            "results.csv",
            "summary.md",
            "fig3.svg",
            "fig3.png",
            "fig4.svg",
            "fig4.png",
            kinergy_draw::experiment::VIEW,
        ]
    };
    names.iter().map(|name| dir.join(name)).collect()
}

/// The summary as `--json` prints it.
#[derive(Debug, Serialize)]
struct SummaryReport {
    clips: usize,
    seconds: f64,
    budget: usize,
    seed: u64,
    models: Vec<(String, Stats)>,
    optimizers: Vec<(String, Option<Stats>, Option<Stats>)>,
    methods: Vec<(String, Stats)>,
    /// (field, direct).
    field_loo: Option<(Stats, Stats)>,
    nested_violations: Vec<String>,
}

impl SummaryReport {
    fn new(
        summary: &Summary,
        results: &Results,
        settings: &ExperimentSettings,
        clips: usize,
        seconds: f64,
    ) -> SummaryReport {
        SummaryReport {
            clips,
            seconds,
            budget: settings.fit.anneal.max_evaluations,
            seed: settings.fit.anneal.seed,
            models: summary
                .models
                .iter()
                .map(|(m, s)| (m.name().to_string(), *s))
                .collect(),
            optimizers: summary
                .optimizers
                .iter()
                .map(|(o, a, c)| (o.name().to_string(), *a, *c))
                .collect(),
            methods: summary
                .methods
                .iter()
                .map(|(m, s)| (m.name().to_string(), *s))
                .collect(),
            field_loo: summary.field.map(|f| (f.field, f.direct)),
            nested_violations: results
                .violations
                .iter()
                .map(|v| {
                    format!(
                        "{}: {} {:.3} mm > {} {:.3} mm",
                        v.clip,
                        v.richer.0.name(),
                        v.richer.1 * 1e3,
                        v.poorer.0.name(),
                        v.poorer.1 * 1e3
                    )
                })
                .collect(),
        }
    }
}

/// How the fits searched, for a summary's first lines: budget, population, temperature,
/// stopping rule and seed.
pub(crate) fn search_line(fit: &kinergy_train::fit::FitSettings) -> String {
    let anneal = &fit.anneal;
    let objective = match fit.objective {
        kinergy_solver::FitObjective::Positions => String::new(),
        o => format!(
            ", minimizing the joint-position distance + {} s × the hand's RMS speed error (the fitted scores include it)",
            o.speed_weight()
        ),
    };
    format!(
        "simulated annealing, {} evaluations per fit, population {}, temperature {}, stopping when the mean score changes by at most {} % over {} iterations, seed {}{objective}",
        anneal.max_evaluations,
        anneal.population,
        anneal.temperature,
        anneal.stable_tolerance * 100.0,
        anneal.stable_window,
        anneal.seed
    )
}

/// summary.md: the tables of Fig. 3, Fig. 4, the methods and the field, the nested-model
/// notes and the paper's figures.
fn markdown(report: &SummaryReport, summary: &Summary, settings: &ExperimentSettings) -> String {
    let mm = |v: f64| format!("{:.2}", v * 1e3);
    let clips = report.clips;
    let fig3_opt = settings.optimizer.name();
    let mut md = String::new();
    md.push_str("# Synergy models compared\n\n");
    md.push_str(&format!(
        "{clips} clip{}; {}; {:.1} s wall.\nDistances are the mean joint-position motion distance (shoulder, elbow, wrist, hand), in millimeters.\n\n",
        if clips == 1 { "" } else { "s" },
        search_line(&settings.fit),
        report.seconds
    ));
    md.push_str(&format!(
        "## Fig. 3 — models, per clip, {fig3_opt}\n\n| model | mean | min | max | reduction of the mean | paper |\n|---|---|---|---|---|---|\n"
    ));
    let models = &summary.models;
    for (i, (model, s)) in models.iter().enumerate() {
        let reduction = if i > 0 {
            format!("{:.0} %", 100.0 * (1.0 - s.mean / models[i - 1].1.mean))
        } else {
            "—".into()
        };
        let paper = PAPER_MODEL_REDUCTIONS
            .iter()
            .find(|(a, b, _)| i > 0 && *a == models[i - 1].0 && b == model)
            .map_or("—".to_string(), |(_, _, r)| format!("{r:.0} %"));
        md.push_str(&format!(
            "| {} | {} | {} | {} | {reduction} | {paper} |\n",
            model.name().to_uppercase().replace('S', "S_"),
            mm(s.mean),
            mm(s.min),
            mm(s.max)
        ));
    }
    md.push_str("\n## Fig. 4 — optimizers with S_A and S_C, per clip\n\n| optimizer | S_A mean (min–max) | S_C mean (min–max) | reduction | paper |\n|---|---|---|---|---|\n");
    for (optimizer, a, c) in &summary.optimizers {
        let cell = |s: &Option<Stats>| {
            s.map_or("—".into(), |s| {
                format!("{} ({}–{})", mm(s.mean), mm(s.min), mm(s.max))
            })
        };
        let reduction = match (a, c) {
            (Some(a), Some(c)) => format!("{:.0} %", 100.0 * (1.0 - c.mean / a.mean)),
            _ => "—".into(),
        };
        let paper = PAPER_OPTIMIZER_REDUCTIONS
            .iter()
            .find(|(o, _)| o == optimizer)
            .map_or("—".into(), |(_, r)| format!("{r:.0} %"));
        md.push_str(&format!(
            "| {} | {} | {} | {reduction} | {paper} |\n",
            optimizer.name().to_uppercase(),
            cell(a),
            cell(c)
        ));
    }
    if !summary.methods.is_empty() {
        md.push_str(&format!(
            "\n## What annealing buys — S_C from its neutral vector, {fig3_opt}, same budget\n\n| method | mean | min | max |\n|---|---|---|---|\n"
        ));
        for (method, s) in &summary.methods {
            md.push_str(&format!(
                "| {} | {} | {} | {} |\n",
                method.name(),
                mm(s.mean),
                mm(s.min),
                mm(s.max)
            ));
        }
    }
    if let Some(field) = &summary.field {
        let (f, d) = (field.field, field.direct);
        md.push_str(&format!(
            "\n## Parameter field — leave one target out (S_C, {fig3_opt})\n\nEach clip's parameters predicted from the same person's other clips' fits (clips in one folder are one person), against fitting the clip itself.\n\n| parameters | mean | min | max |\n|---|---|---|---|\n| direct per-clip fit | {} | {} | {} |\n| field from the other targets | {} | {} | {} |\n",
            mm(d.mean),
            mm(d.min),
            mm(d.max),
            mm(f.mean),
            mm(f.min),
            mm(f.max)
        ));
    }
    md.push_str("\n## Nested models\n\n");
    if report.nested_violations.is_empty() {
        md.push_str("No richer model ended worse than the poorer one it started from.\n");
    } else {
        md.push_str("A richer model ended worse than the poorer one (the carry-over into a sigmoid is exact only where the offsets' lower bound reaches −37, as the default −40 does; with the paper's o ≥ 0 it is not):\n\n");
        for v in &report.nested_violations {
            md.push_str(&format!("- {v}\n"));
        }
    }
    md.push_str("\nThe paper (14 seated reaches of one subject; its distance unit is not stated): S_A → S_B −55 %, S_B → S_C −13 %, S_C → S_D −10 %; with S_C instead of S_A: JT −34 %, NJT −47 %, SVD −66 %.\n");
    md
}
