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
//! number but `seconds` is the same on any thread count.

use std::path::PathBuf;
use std::time::Instant;

use kinergy_solver::{Model, OptimizerKind, ParamSpace};
use kinergy_train::baseline::{BaselineMethod, BaselineSettings};
use kinergy_train::fit::{FitSettings, fit_nested};
use kinergy_train::{CapturedReach, CostFunction, Objective};
use rayon::prelude::*;
use serde::Serialize;

use crate::common::{
    Bar, CaptureArgs, Failure, SearchArgs, collect_clips, emit, print_json, train_failure,
};

/// The folder `compare` uses when no clips are given.
pub const DEFAULT_DATA: &str = "data-synthetic";

/// Arguments of `kinergy compare`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// Captures: BVH files or folders of them (default: `data-synthetic/`).
    #[arg(value_name = "CLIPS")]
    pub clips: Vec<PathBuf>,
    /// Models for Fig. 3.
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
    /// Output folder for results.csv, summary.md and the charts fig3/fig4 (.svg and .png).
    #[arg(short, long, default_value = "compare-out", value_name = "DIR")]
    pub output: PathBuf,
    /// Print the summary as JSON too.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub search: SearchArgs,
    #[command(flatten)]
    pub reach: CaptureArgs,
}

/// One fit's row of results.csv.
#[derive(Debug, Clone, Serialize)]
pub struct Row {
    /// The clip.
    pub clip: String,
    /// The model.
    pub model: &'static str,
    /// The optimizer.
    pub optimizer: &'static str,
    /// How it was fitted.
    pub method: &'static str,
    /// Mean motion distance, meters.
    pub distance_m: f64,
    /// Frames of the reach.
    pub frames: usize,
    /// Evaluations spent.
    pub evaluations: usize,
    /// Wall time of the fit, seconds.
    pub seconds: f64,
}

/// The paper's reductions of the mean distance (Aubry et al. 2009, §4).
const PAPER_MODEL_REDUCTIONS: [(&str, &str, f64); 3] =
    [("sa", "sb", 55.0), ("sb", "sc", 13.0), ("sc", "sd", 10.0)];
const PAPER_OPTIMIZER_REDUCTIONS: [(&str, f64); 3] = [("jt", 34.0), ("njt", 47.0), ("svd", 66.0)];

/// Runs `kinergy compare`.
pub fn run(args: &Args) -> Result<(), Failure> {
    args.search.apply_threads()?;
    let paths = if args.clips.is_empty() {
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
    let clips = collect_clips(&paths)?;
    let reaches = args.reach.load_all(&clips)?;
    let settings = args.search.settings();
    settings
        .anneal
        .validate()
        .map_err(|e| Failure::Input(e.to_string()))?;
    if args.models.is_empty() || args.optimizers.is_empty() {
        return Err(Failure::Input(
            "--models and --optimizers need at least one each".into(),
        ));
    }
    std::fs::create_dir_all(&args.output).map_err(|e| Failure::input(&args.output, e))?;
    let clock = Instant::now();
    let bar = Bar::counting(reaches.len() as u64, "clips");

    // One job per clip; each returns its rows in a fixed order.
    let per_clip: Result<Vec<ClipRows>, kinergy_train::TrainError> = reaches
        .par_iter()
        .map(|reach| {
            let rows = clip_rows(reach, args, &settings);
            bar.inc();
            rows
        })
        .collect();
    bar.finish();
    let (per_clip, sc): (Vec<Vec<Row>>, Vec<Option<Vec<f64>>>) =
        per_clip.map_err(train_failure)?.into_iter().unzip();
    let mut rows: Vec<Row> = per_clip.into_iter().flatten().collect();
    rows.extend(field_rows(&reaches, &sc, args, &settings).map_err(train_failure)?);
    let seconds = clock.elapsed().as_secs_f64();

    let csv_path = args.output.join("results.csv");
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in &rows {
        w.serialize(r)
            .map_err(|e| Failure::Task(format!("results.csv: {e}")))?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| Failure::Task(format!("results.csv: {e}")))?;
    kinergy_bvh::write_atomic(&csv_path, &bytes)
        .map_err(|e| Failure::Task(format!("{}: {e}", csv_path.display())))?;

    let summary = summarize(&rows, args, &settings, reaches.len(), seconds);
    let md_path = args.output.join("summary.md");
    kinergy_bvh::write_atomic(&md_path, summary.markdown.as_bytes())
        .map_err(|e| Failure::Task(format!("{}: {e}", md_path.display())))?;
    let charts = draw_charts(&rows, args)?;
    if args.json {
        return print_json(&summary);
    }
    emit(&format!(
        "{}\nwritten: {}, {} and {}\n",
        summary.markdown,
        csv_path.display(),
        md_path.display(),
        charts
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    ))
}

/// Fig. 3 (per model) and Fig. 4 (per optimizer, S_A and S_C) as bar charts of the mean
/// motion distance with min–max whiskers, in millimetres: `fig3.svg`/`.png` and
/// `fig4.svg`/`.png` next to summary.md. Returns the files written.
fn draw_charts(rows: &[Row], args: &Args) -> Result<Vec<PathBuf>, Failure> {
    use crate::draw::{BarChart, save};
    let bar = |series: usize, model: &str, optimizer: &str| {
        stats(
            rows.iter()
                .filter(|r| r.model == model && r.optimizer == optimizer && r.method == "sa")
                .map(|r| r.distance_m * 1e3),
        )
        .map(|s| crate::draw::Bar {
            series,
            mean: s.mean,
            min: s.min,
            max: s.max,
        })
    };
    let mut models = args.models.clone();
    models.sort();
    models.dedup();
    let fig3 = BarChart {
        title: format!(
            "Fig. 3: synergy models ({}, {} clips)",
            args.optimizer.name().to_uppercase(),
            rows.iter()
                .map(|r| r.clip.as_str())
                .collect::<std::collections::BTreeSet<_>>()
                .len()
        ),
        y_label: "motion distance to the capture (mm)".into(),
        series: vec!["mean, min–max".into()],
        groups: models
            .iter()
            .filter_map(|m| {
                let b = bar(0, m.name(), args.optimizer.name())?;
                Some((m.name().to_uppercase().replacen('S', "S_", 1), vec![b]))
            })
            .collect(),
    };
    let fig4 = BarChart {
        title: "Fig. 4: optimizers with S_A and S_C".into(),
        y_label: "motion distance to the capture (mm)".into(),
        series: vec!["S_A".into(), "S_C".into()],
        groups: args
            .optimizers
            .iter()
            .map(|o| {
                let bars = [bar(0, "sa", o.name()), bar(1, "sc", o.name())]
                    .into_iter()
                    .flatten()
                    .collect();
                (o.name().to_uppercase(), bars)
            })
            .collect(),
    };
    let mut written = Vec::new();
    for (name, chart) in [("fig3", &fig3), ("fig4", &fig4)] {
        if chart.groups.iter().all(|g| g.1.is_empty()) {
            continue;
        }
        for ext in ["svg", "png"] {
            let path = args.output.join(format!("{name}.{ext}"));
            save(chart, &path, (800, 500))?;
            written.push(path);
        }
    }
    Ok(written)
}

/// A clip's rows and its Fig. 3 S_C values (for the parameter field).
type ClipRows = (Vec<Row>, Option<Vec<f64>>);

/// The rows of one clip: Fig. 3, Fig. 4, methods.
fn clip_rows(
    reach: &CapturedReach,
    args: &Args,
    settings: &FitSettings,
) -> Result<ClipRows, kinergy_train::TrainError> {
    let reaches = std::slice::from_ref(reach);
    let mut rows = Vec::new();
    let row = |model: Model,
               optimizer: OptimizerKind,
               method: &'static str,
               distance,
               evaluations,
               seconds| Row {
        clip: reach.name().to_string(),
        model: model.name(),
        optimizer: optimizer.name(),
        method,
        distance_m: distance,
        frames: reach.frame_count(),
        evaluations,
        seconds,
    };
    // Fig. 3.
    let clock = Instant::now();
    let fig3 = fit_nested(
        reaches,
        &args.models,
        args.optimizer.default_optimizer(),
        settings,
    )?;
    let per_fit = clock.elapsed().as_secs_f64() / fig3.fits.len() as f64;
    for f in &fig3.fits {
        rows.push(row(
            f.model(),
            args.optimizer,
            "sa",
            f.score,
            f.evaluations,
            per_fit,
        ));
    }
    let sc_values = fig3.get(Model::Sc).map(|f| f.values.clone());
    // Fig. 4.
    for &optimizer in &args.optimizers {
        if optimizer == args.optimizer
            && fig3.get(Model::Sa).is_some()
            && fig3.get(Model::Sc).is_some()
        {
            continue; // the Fig. 3 rows serve
        }
        let clock = Instant::now();
        let fits = fit_nested(
            reaches,
            &[Model::Sa, Model::Sc],
            optimizer.default_optimizer(),
            settings,
        )?;
        let per_fit = clock.elapsed().as_secs_f64() / fits.fits.len() as f64;
        for f in &fits.fits {
            rows.push(row(
                f.model(),
                optimizer,
                "sa",
                f.score,
                f.evaluations,
                per_fit,
            ));
        }
    }
    // Methods, S_C from neutral, same budget.
    if !args.no_baselines {
        let space = ParamSpace::new(Model::Sc, &reach.dof_names(), settings.bounds)?;
        let objective = Objective::new(
            reaches.to_vec(),
            space.clone(),
            args.optimizer.default_optimizer(),
        )?
        .with_tolerance(settings.tolerance)?;
        let start = space.neutral();
        let clock = Instant::now();
        let annealer =
            kinergy_train::anneal::Annealer::new(kinergy_train::anneal::AnnealSettings {
                seed: kinergy_train::fit::model_seed(settings.anneal.seed, Model::Sc),
                ..settings.anneal
            })?;
        let state = annealer.minimize(&objective, &start)?;
        rows.push(row(
            Model::Sc,
            args.optimizer,
            "sa_from_neutral",
            state.best_cost,
            state.evaluations,
            clock.elapsed().as_secs_f64(),
        ));
        for method in BaselineMethod::ALL {
            let clock = Instant::now();
            let result = kinergy_train::baseline::minimize(
                method,
                &objective as &dyn CostFunction,
                &start,
                &BaselineSettings {
                    max_evaluations: settings.anneal.max_evaluations,
                    seed: settings.anneal.seed,
                    ..BaselineSettings::default()
                },
            )?;
            rows.push(row(
                Model::Sc,
                args.optimizer,
                method.name(),
                result.best_cost,
                result.evaluations,
                clock.elapsed().as_secs_f64(),
            ));
        }
    }
    Ok((rows, sc_values))
}

/// Leave-one-target-out with the parameter field, per person (clips in the same folder are
/// one person's): for each clip, S_C parameters from the field of the person's other
/// per-clip S_C fits, scored on the clip; one row per clip with method `field_loo`.
fn field_rows(
    reaches: &[CapturedReach],
    sc: &[Option<Vec<f64>>],
    args: &Args,
    settings: &FitSettings,
) -> Result<Vec<Row>, kinergy_train::TrainError> {
    use kinergy_train::field::{FieldSettings, leave_one_out};
    let person = |r: &CapturedReach| {
        std::path::Path::new(r.name())
            .parent()
            .map(|p| p.to_path_buf())
            .unwrap_or_default()
    };
    let mut persons: Vec<PathBuf> = reaches.iter().map(person).collect();
    persons.sort();
    persons.dedup();
    let mut rows = Vec::new();
    for p in persons {
        let members: Vec<usize> = (0..reaches.len())
            .filter(|&i| person(&reaches[i]) == p && sc[i].is_some())
            .collect();
        if members.len() < 2 {
            continue;
        }
        let space = ParamSpace::new(Model::Sc, &reaches[members[0]].dof_names(), settings.bounds)?;
        let samples: Vec<_> = members
            .iter()
            .map(|&i| (reaches[i].target(), sc[i].clone().unwrap_or_default()))
            .collect();
        let clock = Instant::now();
        let loo = leave_one_out(&space, &samples, &FieldSettings::default(), |k, params| {
            let reach = &reaches[members[k]];
            Objective::new(
                vec![reach.clone()],
                space.clone(),
                args.optimizer.default_optimizer(),
            )?
            .with_tolerance(settings.tolerance)?
            .score(params)
        })?;
        let per = clock.elapsed().as_secs_f64() / loo.len() as f64;
        for row in loo {
            let reach = &reaches[members[row.index]];
            rows.push(Row {
                clip: reach.name().to_string(),
                model: Model::Sc.name(),
                optimizer: args.optimizer.name(),
                method: "field_loo",
                distance_m: row.field_distance,
                frames: reach.frame_count(),
                evaluations: 1,
                seconds: per,
            });
        }
    }
    Ok(rows)
}

/// Mean, min and max of a set of distances, meters.
#[derive(Debug, Clone, Copy, Serialize)]
struct Stats {
    mean: f64,
    min: f64,
    max: f64,
    count: usize,
}

fn stats(values: impl Iterator<Item = f64>) -> Option<Stats> {
    let v: Vec<f64> = values.collect();
    if v.is_empty() {
        return None;
    }
    Some(Stats {
        mean: v.iter().sum::<f64>() / v.len() as f64,
        min: v.iter().copied().fold(f64::INFINITY, f64::min),
        max: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        count: v.len(),
    })
}

#[derive(Debug, Serialize)]
struct Summary {
    clips: usize,
    seconds: f64,
    budget: usize,
    seed: u64,
    models: Vec<(String, Stats)>,
    optimizers: Vec<(String, Option<Stats>, Option<Stats>)>,
    methods: Vec<(String, Stats)>,
    field_loo: Option<(Stats, Stats)>,
    nested_violations: Vec<String>,
    #[serde(skip)]
    markdown: String,
}

fn summarize(
    rows: &[Row],
    args: &Args,
    settings: &FitSettings,
    clips: usize,
    seconds: f64,
) -> Summary {
    let select = |model: &str, optimizer: &str, method: &str| {
        stats(
            rows.iter()
                .filter(|r| r.model == model && r.optimizer == optimizer && r.method == method)
                .map(|r| r.distance_m),
        )
    };
    let mut sorted_models = args.models.clone();
    sorted_models.sort();
    sorted_models.dedup();
    let fig3_opt = args.optimizer.name();
    let models: Vec<(String, Stats)> = sorted_models
        .iter()
        .filter_map(|m| select(m.name(), fig3_opt, "sa").map(|s| (m.name().to_string(), s)))
        .collect();
    let optimizers: Vec<(String, Option<Stats>, Option<Stats>)> = args
        .optimizers
        .iter()
        .map(|o| {
            (
                o.name().to_string(),
                select("sa", o.name(), "sa"),
                select("sc", o.name(), "sa"),
            )
        })
        .collect();
    let methods: Vec<(String, Stats)> = ["sa_from_neutral", "nelder_mead", "particle_swarm"]
        .iter()
        .filter_map(|m| select("sc", fig3_opt, m).map(|s| (m.to_string(), s)))
        .collect();
    // Per clip: a richer model with a higher distance than the poorer one (Fig. 3 rows).
    let mut nested_violations = Vec::new();
    // Each clip once, in the order of the rows (field rows come back to every clip later).
    let mut by_clip: Vec<&str> = Vec::new();
    for r in rows {
        if !by_clip.contains(&r.clip.as_str()) {
            by_clip.push(&r.clip);
        }
    }
    for clip in by_clip {
        let chain: Vec<&Row> = rows
            .iter()
            .filter(|r| r.clip == clip && r.optimizer == fig3_opt && r.method == "sa")
            .filter(|r| sorted_models.iter().any(|m| m.name() == r.model))
            .collect();
        for w in chain.windows(2) {
            if w[1].distance_m > w[0].distance_m {
                nested_violations.push(format!(
                    "{clip}: {} {:.3} mm > {} {:.3} mm",
                    w[1].model,
                    w[1].distance_m * 1e3,
                    w[0].model,
                    w[0].distance_m * 1e3
                ));
            }
        }
    }

    let mm = |v: f64| format!("{:.2}", v * 1e3);
    let mut md = String::new();
    md.push_str("# Synergy models compared\n\n");
    md.push_str(&format!(
        "{clips} clip{}; simulated annealing, {} evaluations per fit, population {}, seed {}; {:.1} s wall.\nDistances are the mean joint-position motion distance (shoulder, elbow, wrist, hand), in millimeters.\n\n",
        if clips == 1 { "" } else { "s" },
        settings.anneal.max_evaluations, settings.anneal.population, settings.anneal.seed, seconds
    ));
    md.push_str(&format!(
        "## Fig. 3 — models, per clip, {fig3_opt}\n\n| model | mean | min | max | reduction of the mean | paper |\n|---|---|---|---|---|---|\n"
    ));
    for (i, (name, s)) in models.iter().enumerate() {
        let reduction = if i > 0 {
            format!("{:.0} %", 100.0 * (1.0 - s.mean / models[i - 1].1.mean))
        } else {
            "—".into()
        };
        let paper = PAPER_MODEL_REDUCTIONS
            .iter()
            .find(|(a, b, _)| i > 0 && *a == models[i - 1].0 && *b == name)
            .map_or("—".to_string(), |(_, _, r)| format!("{r:.0} %"));
        md.push_str(&format!(
            "| {} | {} | {} | {} | {reduction} | {paper} |\n",
            name.to_uppercase().replace('S', "S_"),
            mm(s.mean),
            mm(s.min),
            mm(s.max)
        ));
    }
    md.push_str("\n## Fig. 4 — optimizers with S_A and S_C, per clip\n\n| optimizer | S_A mean (min–max) | S_C mean (min–max) | reduction | paper |\n|---|---|---|---|---|\n");
    for (name, a, c) in &optimizers {
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
            .find(|(o, _)| o == name)
            .map_or("—".into(), |(_, r)| format!("{r:.0} %"));
        md.push_str(&format!(
            "| {} | {} | {} | {reduction} | {paper} |\n",
            name.to_uppercase(),
            cell(a),
            cell(c)
        ));
    }
    if !methods.is_empty() {
        md.push_str(&format!(
            "\n## What annealing buys — S_C from its neutral vector, {fig3_opt}, same budget\n\n| method | mean | min | max |\n|---|---|---|---|\n"
        ));
        for (name, s) in &methods {
            md.push_str(&format!(
                "| {name} | {} | {} | {} |\n",
                mm(s.mean),
                mm(s.min),
                mm(s.max)
            ));
        }
    }
    let field_direct: Vec<(f64, f64)> = rows
        .iter()
        .filter(|r| r.method == "field_loo")
        .filter_map(|f| {
            rows.iter()
                .find(|r| {
                    r.clip == f.clip
                        && r.model == "sc"
                        && r.optimizer == fig3_opt
                        && r.method == "sa"
                })
                .map(|d| (d.distance_m, f.distance_m))
        })
        .collect();
    let field =
        stats(field_direct.iter().map(|p| p.1)).zip(stats(field_direct.iter().map(|p| p.0)));
    if let Some((f, d)) = field {
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
    if nested_violations.is_empty() {
        md.push_str("No richer model ended worse than the poorer one it started from.\n");
    } else {
        md.push_str("A richer model ended worse than the poorer one (the S_B → S_C carry-over is not exact with the paper's o ≥ 0):\n\n");
        for v in &nested_violations {
            md.push_str(&format!("- {v}\n"));
        }
    }
    md.push_str("\nThe paper (14 seated reaches of one subject; its distance unit is not stated): S_A → S_B −55 %, S_B → S_C −13 %, S_C → S_D −10 %; with S_C instead of S_A: JT −34 %, NJT −47 %, SVD −66 %.\n");
    Summary {
        clips,
        seconds,
        budget: settings.anneal.max_evaluations,
        seed: settings.anneal.seed,
        models,
        optimizers,
        methods,
        field_loo: field,
        nested_violations,
        markdown: md,
    }
}
