//! `kinergy fit`: fit synergy parameters to captured reaches by simulated annealing, per
//! clip or per person, and write the parameters file; with `--field`, each reach on its own
//! and the person's parameter field over their targets, written as a field file ([`field`]).

mod args;
mod field;
mod library;

pub use args::{Args, Per};

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use kinergy_solver::{FittedReach, Model};
use kinergy_train::CapturedReach;
use kinergy_train::TrainError;
use kinergy_train::anneal::{Checkpoint, Control, CsvLog, Observer, Progress};
use kinergy_train::fit::{Fit, FitJob, FitSettings, Interrupted, NestedFit};
use kinergy_train::library::{LIBRARY, SKIPPED, Takes, take_names};
use serde::Serialize;

use crate::common::{Bar, Failure, check_range, emit, limits, print_json};

/// Set by Ctrl-C: the running fit stops after its current iteration and checkpoints.
pub static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// Raises [`INTERRUPTED`] after a number of iterations (the `--interrupt-after` hook).
struct InterruptAfter {
    left: Option<usize>,
}

impl Observer for InterruptAfter {
    fn on_iteration(&mut self, _: &Progress) {
        if let Some(n) = self.left.as_mut() {
            *n = n.saturating_sub(1);
            if *n == 0 {
                INTERRUPTED.store(true, Ordering::SeqCst);
            }
        }
    }
}

#[derive(Serialize)]
struct ModelRow {
    model: &'static str,
    score_m: f64,
    start_score_m: f64,
    evaluations: usize,
    iterations: usize,
    status: &'static str,
}

#[derive(Serialize)]
struct FitReport {
    output: String,
    per: &'static str,
    optimizer: &'static str,
    reaches: Vec<FittedReach>,
    models: Vec<ModelRow>,
    nested_violations: Vec<String>,
}

/// Runs `kinergy fit`.
pub fn run(args: &Args) -> Result<(), Failure> {
    check_flags(args)?;
    let clips = args.reach.clips(&args.clips)?;
    let settings = args.search.settings()?;
    settings.anneal.validate().map_err(Failure::from)?;
    let models = FitJob::models_up_to(args.model, !args.no_nested);
    if args.field && args.per == Per::Clip {
        return Err(Failure::Input(
            "--field fits one field per person (each reach on its own inside it): drop \
             --per clip"
                .into(),
        ));
    }
    if let (dest, true) = destination(args, false)?
        && args.per == Per::Clip
    {
        // A library stops coarser by default (`AnnealSettings::for_library`).
        let settings = args.search.library_settings()?;
        settings.anneal.validate().map_err(Failure::from)?;
        return library_run(args, &clips, &models, &settings, dest);
    }
    check_not_library(args)?;
    let reaches = args.reach.load_all(&clips)?;
    if args.field {
        field::check_one_arm(&reaches)?;
    }
    let groups: Vec<Vec<CapturedReach>> = match (args.per, args.field) {
        (Per::Person, false) => vec![reaches],
        (_, true) => kinergy_train::field::field_groups(&reaches),
        _ => reaches.into_iter().map(|r| vec![r]).collect(),
    };
    let several = groups.len() > 1 && !args.field;
    let (dest, folder) = destination(args, several)?;
    if args.field && folder {
        return Err(Failure::Input(format!(
            "-o {}: --field writes one field file: name it (-o field.json)",
            dest.display()
        )));
    }
    // A folder here holds one person's fit, named by its first clip.
    let names = match groups.first().and_then(|g| g.first()) {
        Some(first) if folder => {
            // Named by the clip's file name alone, from its own folder.
            let clip = Path::new(first.name());
            let folder = std::fs::canonicalize(clip)
                .ok()
                .and_then(|p| p.parent().map(Path::to_path_buf))
                .unwrap_or_default();
            take_names(&folder, clip, std::slice::from_ref(first))
        }
        _ => Vec::new(),
    };
    if several && args.checkpoint.is_some() {
        return Err(Failure::Input(
            "--checkpoint works on one fit at a time: use --per person or one clip".into(),
        ));
    }
    check_fit_outputs(args, &clips, dest, folder, &names)?;
    if folder {
        crate::common::make_folder(dest)?;
    }
    ctrlc::set_handler(|| INTERRUPTED.store(true, Ordering::SeqCst))
        .map_err(|e| Failure::Task(format!("cannot watch for Ctrl-C: {e}")))?;
    let mut log = match &args.log {
        Some(p) => Some(CsvLog::create(p, args.resume).map_err(Failure::from)?),
        None => None,
    };
    let fit = |group: &[CapturedReach], log: Option<&mut CsvLog>| {
        run_group(args, group, &models, &settings, log, true)
    };
    if args.field {
        let mut fits = Vec::with_capacity(groups.len());
        for group in &groups {
            fits.push(fit(group, log.as_mut())?);
        }
        // The person's single vector, the field's anchor: all the reaches at once.
        let reaches: Vec<CapturedReach> = groups.into_iter().flatten().collect();
        let person = fit(&reaches, log.as_mut())?;
        if let Some(log) = log {
            log.finish().map_err(Failure::from)?;
        }
        return field::finish(args.json, dest, &reaches, &fits, &person, &settings);
    }
    let mut reports = Vec::new();
    for (g, group) in groups.iter().enumerate() {
        let fits = fit(group, log.as_mut())
            .map_err(|e| written_before(e, &reports, groups.len(), dest))?;
        let output = if folder {
            let path = dest.join(&names[g]);
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent).map_err(|e| Failure::input(parent, e))?;
            }
            path
        } else {
            dest.to_path_buf()
        };
        let file = fits
            .params_file(group, args.per.grouping())
            .map_err(Failure::from)?;
        file.write(&output).map_err(Failure::from)?;
        let done = report(&output, args, group, &fits.fits, &fits.violations());
        // Said as soon as it is written: what a killed or interrupted run reported is on disk.
        if !args.json {
            emit(&report_text(&done))?;
        }
        reports.push(done);
    }
    if let Some(log) = log {
        log.finish().map_err(Failure::from)?;
    }
    match (args.json, reports.len()) {
        (false, _) => Ok(()),
        (true, 1) => print_json(&reports[0]),
        (true, _) => print_json(&reports),
    }
}

/// Checks the flags' ranges (before any work), then sizes the thread pool.
fn check_flags(args: &Args) -> Result<(), Failure> {
    args.search.check()?;
    args.reach.read.check()?;
    args.reach.check_arm()?;
    check_range(
        "--checkpoint-every",
        args.checkpoint_every,
        limits::CHECKPOINT_EVERY,
    )?;
    if let Some(n) = args.refine {
        check_range("--refine", n, limits::BUDGET)?;
    }
    args.search.apply_threads()
}

/// Refuses a library's flags on a fit that is not one.
fn check_not_library(args: &Args) -> Result<(), Failure> {
    if args.shard.is_some() {
        return Err(Failure::Input(
            "--shard shares a library: fit --per clip --out-dir DIR".into(),
        ));
    }
    if args.person.is_some() {
        return Err(Failure::Input(
            "--person names a library's persons: fit --per clip --out-dir DIR".into(),
        ));
    }
    if args.warm_start {
        return Err(Failure::Input(
            "--warm-start fits a library's repeats from their first: fit --per clip --out-dir \
             DIR"
            .into(),
        ));
    }
    if args.resume && args.checkpoint.is_none() {
        return Err(Failure::Input(
            "--resume continues a --checkpoint, or a library (fit --per clip --out-dir DIR)".into(),
        ));
    }
    Ok(())
}

/// Refuses outputs over the inputs (the captures, the segments file) or over each other:
/// the results (a file, or the named files in a folder), the checkpoint and the log.
fn check_fit_outputs(
    args: &Args,
    clips: &crate::common::CaptureClips,
    dest: &Path,
    folder: bool,
    names: &[PathBuf],
) -> Result<(), Failure> {
    use crate::common::{Output, check_outputs};
    let mut inputs: Vec<&Path> = args.clips.iter().map(PathBuf::as_path).collect();
    inputs.extend(clips.inputs());
    inputs.extend(args.reach.segments.as_deref());
    let option = if args.out_dir.is_some() {
        "--out-dir"
    } else {
        "-o"
    };
    let files: Vec<PathBuf> = names.iter().map(|name| dest.join(name)).collect();
    let mut outputs = vec![if folder {
        Output::Folder(option, dest, &files)
    } else {
        Output::File(option, dest)
    }];
    // Resumed, the checkpoint is read, then rewritten: it is an output like any other.
    outputs.extend(
        args.checkpoint
            .as_deref()
            .map(|p| Output::File("--checkpoint", p)),
    );
    outputs.extend(args.log.as_deref().map(|p| Output::File("--log", p)));
    check_outputs(&inputs, &outputs)
}

/// A failure `e` of the fit after `written` of `total` results were written into `dest`:
/// with several, the message says which results are safe and which must be fitted again.
fn written_before(e: Failure, written: &[FitReport], total: usize, dest: &Path) -> Failure {
    if total < 2 {
        return e;
    }
    let done = match written.last() {
        Some(last) => format!(
            "{} of {total} results were written to {} before it (the last {}); the others \
             were not: fit them again",
            written.len(),
            dest.display(),
            last.output
        ),
        None => format!("none of the {total} results was written"),
    };
    match e {
        Failure::Task(why) => Failure::Task(format!("{why}; {done}")),
        Failure::Input(why) => Failure::Input(format!("{why}; {done}")),
    }
}

/// One result as the text output shows it.
fn report_text(r: &FitReport) -> String {
    let mut text = String::new();
    text.push_str(&format!("{} ({} fit, {}):\n", r.output, r.per, r.optimizer));
    for m in &r.models {
        text.push_str(&format!(
            "  {}  {:8.3} mm  (from {:.3} mm, {} evaluations, {})\n",
            m.model,
            m.score_m * 1e3,
            m.start_score_m * 1e3,
            m.evaluations,
            m.status
        ));
    }
    for reach in &r.reaches {
        text.push_str(&format!(
            "  {}  frames {}..{}{}  {:.3} mm\n",
            reach.clip,
            reach.frames[0],
            reach.frames[1],
            reach
                .arm
                .as_ref()
                .and_then(|a| a.side)
                .map_or_else(String::new, |s| format!("  {s} arm")),
            reach.distance_m * 1e3
        ));
    }
    for v in &r.nested_violations {
        text.push_str(&format!("  note: {v}\n"));
    }
    text
}

/// One nested fit of `group` with the progress bar, the CSV log, checkpoints and Ctrl-C
/// ([`FitJob::run`]); an interrupted fit is a failed task that says where it was saved.
fn run_group(
    args: &Args,
    group: &[CapturedReach],
    models: &[Model],
    settings: &FitSettings,
    log: Option<&mut CsvLog>,
    show_bar: bool,
) -> Result<NestedFit, Failure> {
    let job = FitJob {
        models: models.to_vec(),
        optimizer: args.optimizer.default_optimizer(),
        settings: *settings,
        refine: args.refine,
    };
    let mut bar = if show_bar {
        Bar::new((settings.anneal.max_evaluations * models.len()) as u64)
    } else {
        Bar::hidden()
    };
    let control = Control {
        checkpoint: args.checkpoint.as_ref().map(|p| p as &dyn Checkpoint),
        checkpoint_every: args.checkpoint_every,
        interrupt: Some(&INTERRUPTED),
    };
    let mut hook = InterruptAfter {
        left: args.interrupt_after,
    };
    // A library's --resume skips finished reaches; a fit's continues its checkpoint.
    let resume = args.resume && args.checkpoint.is_some();
    let outcome = match log {
        Some(log) => job.run(group, &mut ((&mut bar, &mut hook), log), &control, resume),
        None => job.run(group, &mut (&mut bar, &mut hook), &control, resume),
    };
    bar.finish();
    match outcome {
        Ok(fits) if fits.fits.is_empty() => Err(Failure::Task("nothing was fitted".into())),
        Ok(fits) => Ok(fits),
        Err(TrainError::Interrupted {
            during: Interrupted::Annealing,
        }) => Err(Failure::Task(match &args.checkpoint {
            Some(p) => format!(
                "interrupted; the fit so far is in {}: continue it with --resume",
                p.display()
            ),
            None => "interrupted (no --checkpoint: nothing saved)".into(),
        })),
        // The refinement has no checkpoint: its vector is not the refined one, and nothing
        // of this fit is written.
        Err(TrainError::Interrupted {
            during: Interrupted::Refinement,
        }) => Err(Failure::Task(
            "interrupted during --refine: this fit is not written (the refinement has no \
             checkpoint; run it again)"
                .into(),
        )),
        Err(e) => Err(e.into()),
    }
}

/// `fit --per clip` into a folder: checks the outputs, then runs the library
/// ([`library::run`]).
fn library_run(
    args: &Args,
    clips: &crate::common::CaptureClips,
    models: &[Model],
    settings: &FitSettings,
    dest: &Path,
) -> Result<(), Failure> {
    use crate::common::{Output, check_outputs};
    if args.checkpoint.is_some() || args.log.is_some() {
        return Err(Failure::Input(
            "--checkpoint and --log follow one fit: a library (--per clip into a folder) \
             resumes with --resume alone"
                .into(),
        ));
    }
    let mut inputs: Vec<&Path> = args.clips.iter().map(PathBuf::as_path).collect();
    inputs.extend(clips.inputs());
    inputs.extend(args.reach.segments.as_deref());
    // Every take's first result name (a take with several reaches adds their frames) and the
    // library's tables; the rest are checked as they are written.
    let takes = Takes::of(&clips.paths, clips.segments()).walked_from(&args.clips);
    let mut files: Vec<PathBuf> = takes.first_names().iter().map(|n| dest.join(n)).collect();
    files.extend([LIBRARY, SKIPPED].map(|f| dest.join(f)));
    let option = if args.out_dir.is_some() {
        "--out-dir"
    } else {
        "-o"
    };
    check_outputs(&inputs, &[Output::Folder(option, dest, &files)])?;
    if dest.is_dir() {
        crate::common::clean_folder(dest);
    }
    ctrlc::set_handler(|| INTERRUPTED.store(true, Ordering::SeqCst))
        .map_err(|e| Failure::Task(format!("cannot watch for Ctrl-C: {e}")))?;
    library::run(args, clips, takes, models, settings, dest)
}

/// Where the results go and whether it is a folder: `--out-dir`, or `-o` ending in a path
/// separator, is a folder; a plain `-o` is one file, refused when there are several results.
fn destination(args: &Args, several: bool) -> Result<(&Path, bool), Failure> {
    if let Some(dir) = &args.out_dir {
        return Ok((dir, true));
    }
    let Some(output) = &args.output else {
        return Err(Failure::Input(
            "name an output: -o FILE or --out-dir DIR".into(),
        ));
    };
    let folder = output
        .as_os_str()
        .to_string_lossy()
        .ends_with(std::path::is_separator);
    if several && !folder {
        let dir = output.with_extension("");
        return Err(Failure::Input(format!(
            "-o {}: --per clip gives several fits here and -o names one file: name a folder \
             with a trailing slash (-o {}/) or --out-dir {}, or fit them together with \
             --per person",
            output.display(),
            dir.display(),
            dir.display()
        )));
    }
    Ok((output, folder))
}

fn report(
    output: &Path,
    args: &Args,
    reaches: &[CapturedReach],
    fits: &[Fit],
    violations: &[(Model, Model)],
) -> FitReport {
    let last = &fits[fits.len() - 1];
    FitReport {
        output: output.display().to_string(),
        per: args.per.grouping().name(),
        optimizer: args.optimizer.name(),
        reaches: last.record(reaches).reaches,
        models: fits
            .iter()
            .map(|f| ModelRow {
                model: f.model().name(),
                score_m: f.score,
                start_score_m: f.start_score,
                evaluations: f.evaluations,
                iterations: f.iterations,
                status: f.status.name(),
            })
            .collect(),
        nested_violations: violations
            .iter()
            .map(|(a, b)| {
                format!(
                    "{} ended worse than {} (the carry-over into a sigmoid is exact only where the offsets' lower bound reaches −37, as the default −40 does)",
                    b.name(),
                    a.name()
                )
            })
            .collect(),
    }
}
