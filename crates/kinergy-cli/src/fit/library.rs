//! `fit --per clip` into a folder: a library of captures, one result per reach. The shards,
//! records, result names, resume and collect are the library's
//! ([`kinergy_train::library`]); this is the command line's run of a shard: which shard
//! (`--shard I/N`, or the Slurm array's task), the progress bar, the reports and the text.

use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::Ordering;

use kinergy_solver::Model;
use kinergy_train::TrainError;
use kinergy_train::anneal::Observer;
use kinergy_train::fit::FitJob;
use kinergy_train::library::{Shard, ShardEvent, ShardOutcome, ShardRun, Takes, collect};
use kinergy_train::who::PersonRule;

use super::{Args, FitReport, INTERRUPTED, InterruptAfter, report, report_text};
use crate::common::{Bar, CaptureClips, Failure, emit, report_skipped};

/// Runs `fit --per clip` into the folder `dest`: this run's shard of the library of
/// `clips`, then, with one shard, [`collect`].
pub fn run(
    args: &Args,
    clips: &CaptureClips,
    takes: Takes<'_>,
    models: &[Model],
    settings: &kinergy_train::fit::FitSettings,
    dest: &Path,
) -> Result<(), Failure> {
    let shard = match &args.shard {
        Some(text) => kinergy_train::library::Shard::parse(text)
            .map_err(|e| Failure::Input(format!("--shard {e}")))?,
        None => kinergy_train::library::Shard::from_slurm_env()
            .map_err(Failure::Input)?
            .unwrap_or(kinergy_train::library::Shard::ALL),
    };
    let job = FitJob {
        models: models.to_vec(),
        optimizer: args.optimizer.default_optimizer(),
        settings: *settings,
        refine: args.refine,
    };
    let query = args.reach.query()?;
    let mut inputs: Vec<PathBuf> = clips.inputs().into_iter().map(Path::to_path_buf).collect();
    inputs.extend(args.reach.segments.clone());
    let interrupt_after = args.interrupt_after;
    let observer = move || -> Box<dyn Observer> {
        Box::new(InterruptAfter {
            left: interrupt_after,
        })
    };
    let run = ShardRun {
        dir: dest,
        takes: &takes,
        query: &query,
        job: &job,
        person: args.person.as_ref().unwrap_or(&PersonRule::Auto),
        shard,
        warm_start: args.warm_start,
        resume: args.resume,
        inputs: &inputs,
        interrupt: &INTERRUPTED,
        observer: &observer,
    };
    let plan = run.plan()?;
    let bar = Bar::counting(plan.dealt() as u64, "takes");
    let reports = Mutex::new(Vec::new());
    let said = Mutex::new(Ok(()));
    let on_event = |event: ShardEvent<'_>| match event {
        ShardEvent::TakeDone => bar.inc(),
        ShardEvent::Fitted {
            output,
            reach,
            fits,
        } => {
            let group = std::slice::from_ref(reach);
            let done = report(output, args, group, &fits.fits, &fits.violations());
            if args.json {
                if let Ok(mut reports) = reports.lock() {
                    reports.push(done);
                }
            } else if let Ok(mut said) = said.lock()
                && said.is_ok()
            {
                *said = emit(&report_text(&done));
            }
        }
    };
    let outcome = run.run(&plan, &on_event)?;
    bar.finish();
    said.into_inner()
        .map_err(|_| Failure::Task("a worker of the library run failed".into()))??;
    let reports = reports
        .into_inner()
        .map_err(|_| Failure::Task("a worker of the library run failed".into()))?;
    finish(args, dest, shard, outcome, reports)
}

/// What a finished shard says: the skipped takes, an interruption or a failed take, then the
/// reports (`--json`), or the collected library (one shard), or the shard's summary.
fn finish(
    args: &Args,
    dest: &Path,
    shard: Shard,
    outcome: ShardOutcome,
    mut reports: Vec<FitReport>,
) -> Result<(), Failure> {
    report_skipped(&outcome.skipped);
    let fitted = outcome.fitted;
    if outcome.interrupted || INTERRUPTED.load(Ordering::SeqCst) {
        return Err(Failure::Task(format!(
            "interrupted: {fitted} reaches fitted and written to {}; the rest were not: run \
             again with --resume to fit only those",
            dest.display()
        )));
    }
    if let Some((take, e)) = outcome.failed {
        let note = format!(
            "{fitted} reaches were fitted and written to {} before it; run again with \
             --resume to fit only the rest",
            dest.display()
        );
        return Err(match take_failure(args, &take, e) {
            Failure::Input(why) => Failure::Input(format!("{why}; {note}")),
            Failure::Task(why) => Failure::Task(format!("{}: {why}; {note}", take.display())),
        });
    }
    if args.json {
        reports.sort_by(|a, b| a.output.cmp(&b.output));
        if shard.count == 1 {
            collect(dest)?;
        }
        if reports.is_empty() && fitted == 0 {
            return Err(crate::common::nothing_to_fit(&outcome.skipped));
        }
        return crate::common::print_json(&reports);
    }
    if shard.count == 1 {
        let summary = collect(dest)?;
        emit(&summary.text)?;
        if summary.table.rows.is_empty() {
            return Err(crate::common::nothing_to_fit(&outcome.skipped));
        }
    } else {
        emit(&format!(
            "shard {}/{}: {} takes, {fitted} reaches fitted, {} skipped; record {} (then \
             `kinergy collect {}`)\n",
            shard.index,
            shard.count,
            outcome.dealt,
            outcome.skipped.len(),
            outcome.record.display(),
            dest.display()
        ))?;
        if fitted == 0 && outcome.dealt > 0 {
            return Err(crate::common::nothing_to_fit(&outcome.skipped));
        }
    }
    Ok(())
}

/// A take's failure as the command line says it: what was wrong with the take (its
/// capture, arm, segments row or frames: bad input) named with the flags that choose them; a
/// fit that failed as a failed task.
fn take_failure(args: &Args, take: &Path, e: TrainError) -> Failure {
    use kinergy_io::{Classify, ErrorKind};
    match e {
        TrainError::Setting(kinergy_io::InvalidSetting { field, why }) => {
            Failure::Input(format!("--{field}: {why}"))
        }
        e if e.kind().is_input() || e.kind() == ErrorKind::NothingToFit => {
            args.reach.render(take, e)
        }
        e => e.into(),
    }
}
