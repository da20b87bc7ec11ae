//! `kinergy.fit`: synergy parameters fitted to captured reaches — per person, per clip, a
//! person's field, or a library into a folder ([`crate::library`]) — with the library's
//! [`FitJob`] and [`SearchOptions`], as `kinergy fit` fits them.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use kinergy_solver::{FitGrouping, Model, OptimizerKind};
use kinergy_train::field::{FieldFile, check_one_arm, field_groups};
use kinergy_train::fit::{FitJob, NestedFit, SearchOptions};
use kinergy_train::source::ControllerKind;
use kinergy_train::{CapturedReach, PersonParams, limits};
use pyo3::prelude::*;
use pyo3::types::PyList;

use crate::args::{
    Arg, ClipsArg, ReachSource, Reading, SelectArg, ShardArg, on_pool, parse, thread_pool,
};
use crate::errors;
use crate::params::Params;
use crate::progress::{Watch, watched};

/// Fits synergy parameters to captured reaches by simulated annealing, as `kinergy fit`
/// does: for the same inputs and seed, `Params.save` writes the CLI's bytes.
///
/// clips: a path (file or folder), a Clip, or a list of them; or None with `segments` (a
/// segments file, as `kinergy segment --manifest` writes). model: "sa", "sb", "sc", "sd" or
/// "se"; nested (default) fits the poorer models first, each from the previous solution.
/// optimizer: "jt", "njt", "svd" or "dls". per: "person" (one vector for all the reaches:
/// returns one Params) or "clip" (one per reach: returns a list). field: the person's
/// parameter field over their reaches' targets instead of one vector (`fit --field`: each
/// reach fitted on its own, anchored to the person's vector; one arm). arm: "right", "left" or
/// "auto". select: "main" (default), "all" or a segment number; frames: (start, end) instead.
/// seed, budget, population, temperature, stable_change, stable_window: the annealer's
/// settings (CLI defaults). objective: "positions" (the paper's distance) or
/// "positions+speed" (plus `speed_weight` seconds × the hand's RMS speed error, default
/// 0.05). refine: evaluations of a local refinement after the annealing.
/// threads: worker threads (default: all cores; the result does not depend on it).
/// progress: called after every annealing iteration with a dict (model, stage, stages,
/// iteration, evaluations, max_evaluations, best_m, mean_m, temperature); an exception it
/// raises stops the fit and is raised here. out_dir, shard, resume, person: a library
/// (`per="clip"`), as `kinergy fit --out-dir` fits it ([`crate::library`]); person is its
/// person rule, as `--person` spells it ("auto" by default, "folder", "file", "segments",
/// "regex:PATTERN", "map:FILE.csv"); warm_start fits each person's, motion's and arm's
/// reaches from the first one's fit (`fit --warm-start`). The GIL is released while fitting; Ctrl-C raises
/// KeyboardInterrupt.
#[pyfunction]
#[pyo3(signature = (clips = None, *, model = "sc", optimizer = "svd", per = "person", nested = true, field = false, arm = "right", chain = None, select = None, frames = None, segments = None, fixed_base = false, controller = "smooth", seed = 1, budget = None, population = None, temperature = None, stable_change = None, stable_window = None, objective = "positions", speed_weight = None, refine = None, threads = None, progress = None, out_dir = None, shard = None, resume = false, person = None, warm_start = false, unit = "auto", up = "auto", positions = "auto"))]
#[allow(clippy::too_many_arguments)]
pub fn fit<'py>(
    py: Python<'py>,
    clips: Option<Arg<ClipsArg>>,
    model: &str,
    optimizer: &str,
    per: &str,
    nested: bool,
    field: bool,
    arm: &str,
    chain: Option<Vec<String>>,
    select: Option<Arg<SelectArg>>,
    frames: Option<(usize, usize)>,
    segments: Option<PathBuf>,
    fixed_base: bool,
    controller: &str,
    seed: u64,
    budget: Option<usize>,
    population: Option<usize>,
    temperature: Option<f64>,
    stable_change: Option<f64>,
    stable_window: Option<usize>,
    objective: &str,
    speed_weight: Option<f64>,
    refine: Option<usize>,
    threads: Option<usize>,
    progress: Option<Py<PyAny>>,
    out_dir: Option<PathBuf>,
    shard: Option<Arg<ShardArg>>,
    resume: bool,
    person: Option<&str>,
    warm_start: bool,
    unit: &str,
    up: &str,
    positions: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let grouping = per.parse::<FitGrouping>().map_err(errors::raise)?;
    let controller = controller
        .parse::<ControllerKind>()
        .map_err(errors::raise)?;
    let search = SearchOptions {
        seed,
        budget,
        population,
        temperature,
        stable_change,
        stable_window,
        objective: Some(objective.to_string()),
        speed_weight,
        library: out_dir.is_some(),
    };
    if let Some(n) = refine {
        errors::check_range("refine", n, limits::BUDGET)?;
    }
    let job = FitJob {
        models: FitJob::models_up_to(parse::<Model>("model", model)?, nested),
        optimizer: parse::<OptimizerKind>("optimizer", optimizer)?.default_optimizer(),
        settings: search.settings().map_err(errors::raise)?,
        refine,
    };
    let mut source = ReachSource {
        clips,
        segments,
        arm,
        chain,
        select,
        frames,
        fixed_base,
        reading: Reading {
            unit,
            up,
            positions,
        },
    };
    if let Some(dir) = out_dir {
        if grouping != FitGrouping::Clip || field {
            return Err(errors::input(
                "out_dir= fits a library, one result per reach: per=\"clip\" without field",
            ));
        }
        let library = crate::library::LibraryFit {
            shard: ShardArg::shard(shard)?,
            query: source.query(controller)?,
            clips: source.paths()?,
            segments: source.segments,
            job,
            dir,
            resume,
            person: crate::library::person_rule(person)?,
            warm_start,
            pool: thread_pool(threads)?,
        };
        return crate::library::fit_library(py, library).map(Bound::into_any);
    }
    if shard.is_some() || resume || person.is_some() || warm_start {
        return Err(errors::input(
            "shard=, resume=, person= and warm_start= belong to a library: fit(..., per=\"clip\", out_dir=DIR)",
        ));
    }
    if field && grouping == FitGrouping::Clip {
        return Err(errors::input(
            "field=True fits one field per person (each reach on its own inside it): drop per=\"clip\"",
        ));
    }
    let reaches = source.load(py, controller)?;
    let interrupt = AtomicBool::new(false);
    let names: Vec<&'static str> = job.models.iter().map(|m| m.name()).collect();
    let mut runner = Runner {
        job,
        pool: thread_pool(threads)?,
        interrupt: &interrupt,
        watch: Watch::new(progress.as_ref(), &interrupt, names),
    };
    if field {
        let file = runner.field(py, reaches)?;
        return Ok(Bound::new(py, Params::of(PersonParams::Field(file)))?.into_any());
    }
    runner.vectors(py, reaches, grouping)
}

/// What every nested fit of one `fit` call shares: the job (models, optimizer, settings,
/// refinement), threads and the watch of Ctrl-C and the progress callback.
struct Runner<'a> {
    job: FitJob,
    pool: Option<rayon::ThreadPool>,
    interrupt: &'a AtomicBool,
    watch: Watch<'a>,
}

impl Runner<'_> {
    /// The nested fit of `group` (then its refinement), on a worker with the GIL released
    /// while this thread watches for Ctrl-C ([`watched`]: the main thread is where Python's
    /// signal handlers run, whatever pool the fit runs on).
    fn nested(&mut self, py: Python<'_>, group: &[CapturedReach]) -> PyResult<NestedFit> {
        self.watch.next_group();
        let (job, watch, pool, interrupt) =
            (&self.job, &mut self.watch, &self.pool, self.interrupt);
        let outcome = watched(
            py,
            interrupt,
            move || {
                on_pool(pool, move || {
                    job.run_stoppable(group, watch, Some(interrupt))
                })
            },
            |_| Ok(()),
        );
        let callback = self.watch.finish();
        let outcome = outcome?;
        callback?;
        outcome.map_err(errors::raise)
    }

    /// One Params for all the reaches (per person), or a list of one per reach (per clip).
    fn vectors<'py>(
        &mut self,
        py: Python<'py>,
        reaches: Vec<CapturedReach>,
        grouping: FitGrouping,
    ) -> PyResult<Bound<'py, PyAny>> {
        let groups: Vec<Vec<CapturedReach>> = match grouping {
            FitGrouping::Person => vec![reaches],
            FitGrouping::Clip => reaches.into_iter().map(|r| vec![r]).collect(),
        };
        let mut files = Vec::with_capacity(groups.len());
        for group in &groups {
            let fits = self.nested(py, group)?;
            let file = fits.params_file(group, grouping).map_err(errors::raise)?;
            files.push(Params::of(PersonParams::Vector(file)));
        }
        match grouping {
            FitGrouping::Person => Ok(Bound::new(py, files.remove(0))?.into_any()),
            FitGrouping::Clip => Ok(PyList::new(py, files)?.into_any()),
        }
    }

    /// `fit(field=True)`: each reach fitted on its own (nested), the person's single vector
    /// (all the reaches at once), and the field over the reaches' targets anchored to it, as
    /// `kinergy fit --field` makes it.
    fn field(&mut self, py: Python<'_>, reaches: Vec<CapturedReach>) -> PyResult<FieldFile> {
        check_one_arm(&reaches).map_err(|e| errors::input(format!("field=True: {e}")))?;
        let mut per_reach = Vec::with_capacity(reaches.len());
        for group in field_groups(&reaches) {
            per_reach.push(self.nested(py, &group)?);
        }
        let person = self.nested(py, &reaches)?;
        let tolerance = self.job.settings.tolerance;
        let pool = &self.pool;
        py.detach(|| {
            on_pool(pool, || {
                FieldFile::from_nested(&reaches, &per_reach, &person, tolerance)
            })
        })
        .map_err(errors::raise)
    }
}
