//! The toolkit's verbs from Python — `segment`, `fit`, `synthesize`, `reach` — each doing
//! what the `kinergy` command of the same name does, with the same defaults.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::AtomicBool;

use kinergy_motion::segment::{SegmentSettings, Selection, find_segments, main_index};
use kinergy_motion::{ImportOptions, Side};
use kinergy_solver::{BaseMode, FitGrouping, FitObjective, Model, OptimizerKind};
use kinergy_train::anneal::AnnealSettings;
use kinergy_train::field::{FieldFile, FieldSettings};
use kinergy_train::fit::{FitJob, FitSettings, NestedFit};
use kinergy_train::segments_file::SegmentsFile;
use kinergy_train::source::{
    ArmChoice, ArmRequest, Capture, Controller, Found, ReachFrames, ReachQuery, Take, capture_files,
};
use kinergy_train::{CapturedReach, PersonParams, limits};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::clip::{Clip, import_options, parse};
use crate::errors;
use crate::params::Params;
use crate::progress::Watch;

/// A clip argument: a `Clip`, or a path read with `options`. Returns the clip and the path
/// it is named by (a made clip: `<clip>`).
pub fn clip_arg(
    py: Python<'_>,
    arg: &Bound<'_, PyAny>,
    options: &ImportOptions,
) -> PyResult<(kinergy_motion::Clip, PathBuf)> {
    if let Ok(clip) = arg.cast::<Clip>() {
        let clip = clip.get();
        let path = clip.path.clone().unwrap_or_else(|| PathBuf::from("<clip>"));
        return Ok((clip.inner.clone(), path));
    }
    let path: PathBuf = arg.extract().map_err(|_| {
        errors::input(format!(
            "expected a kinergy.Clip or a path to a BVH file, got {}",
            arg.get_type()
                .name()
                .map_or_else(|_| "?".to_string(), |n| n.to_string())
        ))
    })?;
    let read = py.detach(|| kinergy_motion::read_clip(&path, options));
    let (clip, _) = read.map_err(errors::raise)?;
    Ok((clip, path))
}

/// The arm named `arm` ("right", "left") or by `chain` in `clip` read from `path`.
fn arm_joints(
    clip: &kinergy_motion::Clip,
    path: &Path,
    side: Side,
    chain: Option<Vec<String>>,
) -> PyResult<kinergy_motion::ArmJoints> {
    ArmChoice {
        side,
        joints: chain,
    }
    .find(clip, path)
    .map_err(errors::raise)
}

/// The labelled segments of a clip's hand speed: a list of dicts with `index`, `onset`,
/// `peak`, `end` (frames, end excluded), `label` ("reach", "return" or "other"), `arm`,
/// `peak_speed_m_s`, `displacement_m`, `duration_s`, `in_world` and `main` (the clip's main
/// reach), as `kinergy segment --json` lists them.
///
/// clip: a Clip or a path. arm: "right", "left" or "auto" (the arms that reach; their
/// reaches). select: None (every segment), "main", "all" (every reach) or a segment number.
/// world: measure the hand's speed in the world instead of relative to the shoulder.
#[pyfunction]
#[pyo3(signature = (clip, *, arm = "right", chain = None, select = None, world = false, min_peak_speed = None, unit = "auto", up = "auto", positions = "auto"))]
#[allow(clippy::too_many_arguments)]
pub fn segment<'py>(
    py: Python<'py>,
    clip: &Bound<'py, PyAny>,
    arm: &str,
    chain: Option<Vec<String>>,
    select: Option<&Bound<'py, PyAny>>,
    world: bool,
    min_peak_speed: Option<f64>,
    unit: &str,
    up: &str,
    positions: &str,
) -> PyResult<Bound<'py, PyList>> {
    let options = import_options(unit, up, positions, limits::DEFAULT_INPUT_MB)?;
    let (clip, path) = clip_arg(py, clip, &options)?;
    let selection = selection_arg(select)?;
    let defaults = SegmentSettings::default();
    let settings = SegmentSettings {
        relative_to_shoulder: !world,
        min_peak_speed: min_peak_speed.unwrap_or(defaults.min_peak_speed),
        ..defaults
    };
    settings
        .validate()
        .map_err(|e| errors::input(format!("min_peak_speed: {e}")))?;
    let arms: Vec<(
        kinergy_motion::ArmJoints,
        Option<Vec<kinergy_motion::segment::Segment>>,
    )> = if arm == "auto" {
        let capture = Capture::from_clip(&path, clip.clone());
        capture
            .reaching_segments(selection.unwrap_or_default(), &settings)
            .map_err(errors::raise)?
            .into_iter()
            .map(|(joints, kept)| (joints, Some(kept)))
            .collect()
    } else {
        let side = parse::<Side>("arm", arm)?;
        vec![(arm_joints(&clip, &path, side, chain)?, None)]
    };
    let out = PyList::empty(py);
    let dt = clip.frame_time();
    let name = path.display().to_string();
    for (joints, kept) in arms {
        let found = find_segments(&clip, &joints, &settings).map_err(errors::raise)?;
        let main = main_index(&found);
        let chosen = match (&kept, selection) {
            (Some(kept), _) => kept.clone(),
            (None, None) => found.clone(),
            (None, Some(selection)) => kinergy_motion::segment::select(&found, selection, &name)
                .map_err(|e| errors::input(e.to_string()))?,
        };
        let side = joints
            .side
            .map_or_else(|| "named".to_string(), |s| s.to_string());
        for (i, s) in found.iter().enumerate().filter(|(_, s)| chosen.contains(s)) {
            let row = PyDict::new(py);
            row.set_item("index", i)?;
            row.set_item("onset", s.onset)?;
            row.set_item("peak", s.peak)?;
            row.set_item("end", s.end)?;
            row.set_item("label", s.label.as_str())?;
            row.set_item("arm", &side)?;
            row.set_item("peak_speed_m_s", s.peak_speed)?;
            row.set_item("displacement_m", s.displacement)?;
            row.set_item("onset_s", s.onset as f64 * dt)?;
            row.set_item("duration_s", s.duration(dt))?;
            row.set_item("truncated", s.truncated())?;
            row.set_item("in_world", s.from_world)?;
            row.set_item("main", main == Some(i))?;
            out.append(row)?;
        }
    }
    Ok(out)
}

/// `select=`: None, "main", "all" or a segment number.
pub fn selection_arg(select: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Selection>> {
    let Some(select) = select else {
        return Ok(None);
    };
    if let Ok(n) = select.extract::<usize>() {
        return Ok(Some(Selection::Nth(n)));
    }
    let text: String = select
        .extract()
        .map_err(|_| errors::input("select: expected \"main\", \"all\" or a segment number"))?;
    parse::<Selection>("select", &text).map(Some)
}

/// The search settings of `fit`'s keyword arguments, checked as the CLI checks its flags.
#[allow(clippy::too_many_arguments)]
pub fn fit_settings(
    library: bool,
    seed: u64,
    budget: Option<usize>,
    population: Option<usize>,
    temperature: Option<f64>,
    stable_change: Option<f64>,
    stable_window: Option<usize>,
    objective: &str,
    speed_weight: Option<f64>,
) -> PyResult<FitSettings> {
    let weight = speed_weight.unwrap_or(FitObjective::DEFAULT_SPEED_WEIGHT);
    errors::check_range("speed_weight", weight, limits::SPEED_WEIGHT)?;
    let objective = match objective {
        "positions" => FitObjective::Positions,
        "positions+speed" => FitObjective::PositionsSpeed {
            speed_weight_s: weight,
        },
        _ => {
            return Err(errors::input(format!(
                "objective={objective:?}: expected \"positions\" or \"positions+speed\""
            )));
        }
    };
    let defaults = if library {
        AnnealSettings::default().for_library()
    } else {
        AnnealSettings::default()
    };
    let anneal = AnnealSettings {
        seed,
        max_evaluations: budget.unwrap_or(defaults.max_evaluations),
        population: population.unwrap_or(defaults.population),
        temperature: temperature.unwrap_or(defaults.temperature),
        stable_tolerance: stable_change.unwrap_or(defaults.stable_tolerance),
        stable_window: stable_window.unwrap_or(defaults.stable_window),
        ..defaults
    };
    if anneal.max_evaluations < anneal.population {
        return Err(errors::input(format!(
            "budget={}: at least population ({}), the evaluations of the first generation",
            anneal.max_evaluations, anneal.population
        )));
    }
    anneal.validate().map_err(errors::raise)?;
    Ok(FitSettings {
        anneal,
        objective,
        ..FitSettings::default()
    })
}

/// Where `fit` and `compare` take their reaches from: their keyword arguments of the
/// captures, the segments file, the arm, the frames and the reading.
pub struct ReachSource<'a, 'py> {
    /// One path or Clip, or a list of them (none only with `segments`).
    pub clips: Option<&'a Bound<'py, PyAny>>,
    /// A segments file.
    pub segments: Option<PathBuf>,
    /// "right", "left" or "auto".
    pub arm: &'a str,
    /// The arm's joints by name.
    pub chain: Option<Vec<String>>,
    /// "main", "all" or a segment number.
    pub select: Option<&'a Bound<'py, PyAny>>,
    /// One window (start, end) for every clip.
    pub frames: Option<(usize, usize)>,
    /// Keep the shoulder where it is on the reach's first frame.
    pub fixed_base: bool,
    /// unit, up, positions of the reading.
    pub reading: (&'a str, &'a str, &'a str),
}

impl ReachSource<'_, '_> {
    /// The library's request for these arguments (checked as the CLI checks its flags).
    pub fn query(&self, controller: Controller) -> PyResult<ReachQuery> {
        let (unit, up, positions) = self.reading;
        let frames = match self.frames {
            Some((a, b)) if a < b => ReachFrames::Window(a..b),
            Some((a, b)) => {
                return Err(errors::input(format!(
                    "frames=({a}, {b}): expected (start, end) with start < end"
                )));
            }
            None => ReachFrames::Segments(selection_arg(self.select)?.unwrap_or_default()),
        };
        let arm = match self.arm {
            "auto" => ArmRequest::Auto,
            arm => ArmRequest::Arm(ArmChoice {
                side: parse::<Side>("arm", arm)?,
                joints: self.chain.clone(),
            }),
        };
        let query = ReachQuery {
            frames,
            arm,
            base: if self.fixed_base {
                BaseMode::Fixed
            } else {
                BaseMode::Replay
            },
            controller,
            read: import_options(unit, up, positions, limits::DEFAULT_INPUT_MB)?,
        };
        if self.segments.is_none() {
            query.validate().map_err(errors::raise)?;
        }
        Ok(query)
    }

    /// The reaches, read and cut as the CLI reads and cuts them, under `controller`:
    /// [`ReachQuery::find`] of the captures given (paths, folders or Clips), or
    /// [`ReachQuery::find_rows`] of a segments file's rows; `NothingToFitError` when every
    /// take was skipped.
    pub fn load(self, py: Python<'_>, controller: Controller) -> PyResult<Vec<CapturedReach>> {
        let query = self.query(controller)?;
        let clips = clip_list(self.clips, self.segments.is_some())?;
        let mut takes = Vec::new();
        let mut given = Vec::new();
        for c in &clips {
            if let Ok(clip) = c.cast::<Clip>() {
                let clip = clip.get();
                takes.push(Take::Read(Capture::from_clip(
                    clip.path.as_deref().unwrap_or(Path::new("<clip>")),
                    clip.inner.clone(),
                )));
            } else {
                let path: PathBuf = c.extract().map_err(|_| {
                    errors::input(
                        "clips: expected paths (files or folders) or kinergy.Clip objects",
                    )
                })?;
                given.push(path.clone());
                // Folders expanded as the CLI expands them, in place.
                takes.extend(
                    capture_files(&[path])
                        .map_err(errors::raise)?
                        .into_iter()
                        .map(Take::File),
                );
            }
        }
        let found = match self.segments {
            Some(file) => {
                let file = SegmentsFile::read(&file).map_err(|e| errors::input(e.to_string()))?;
                let wanted = if given.is_empty() {
                    kinergy_train::source::segment_clips(&file)
                } else {
                    capture_files(&given).map_err(errors::raise)?
                };
                py.detach(|| query.find_rows(&file, &wanted))
            }
            None => py.detach(|| query.find(takes)),
        };
        Ok(found
            .and_then(Found::require_some)
            .map_err(errors::raise)?
            .into_reaches())
    }
}

/// `clips=` as paths (files or folders): a library's results are named by their captures'
/// paths, so not Clips.
fn clip_paths(clips: Option<&Bound<'_, PyAny>>) -> PyResult<Vec<PathBuf>> {
    let Some(clips) = clips else {
        return Ok(Vec::new());
    };
    clip_list(Some(clips), true)?
        .iter()
        .map(|c| {
            c.extract::<PathBuf>().map_err(|_| {
                errors::input("clips: a library takes paths (files or folders), not Clips")
            })
        })
        .collect()
}

/// `clips=`: one path or Clip, or a list or tuple of them; none only with a segments file.
pub fn clip_list<'py>(
    clips: Option<&Bound<'py, PyAny>>,
    segments: bool,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let clips: Vec<Bound<'py, PyAny>> = match clips {
        None => Vec::new(),
        Some(c) if c.is_instance_of::<PyList>() || c.is_instance_of::<pyo3::types::PyTuple>() => {
            c.try_iter()?.collect::<PyResult<_>>()?
        }
        Some(c) => vec![c.clone()],
    };
    if clips.is_empty() && !segments {
        return Err(errors::input(
            "name the captures (paths, folders or Clips), or a segments file with segments=",
        ));
    }
    Ok(clips)
}

/// Fits synergy parameters to captured reaches by simulated annealing, as `kinergy fit`
/// does: for the same inputs and seed, `Params.save` writes the CLI's bytes.
///
/// clips: a path (file or folder), a Clip, or a list of them; or None with `segments` (a
/// segments file, as `kinergy segment --manifest` writes). model: "sa", "sb", "sc" or "sd";
/// nested (default) fits the poorer models first, each from the previous solution.
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
/// raises stops the fit and is raised here. The GIL is released while fitting; Ctrl-C raises
/// KeyboardInterrupt.
#[pyfunction]
#[pyo3(signature = (clips = None, *, model = "sc", optimizer = "svd", per = "person", nested = true, field = false, arm = "right", chain = None, select = None, frames = None, segments = None, fixed_base = false, controller = "smooth", seed = 1, budget = None, population = None, temperature = None, stable_change = None, stable_window = None, objective = "positions", speed_weight = None, refine = None, threads = None, progress = None, out_dir = None, shard = None, resume = false, unit = "auto", up = "auto", positions = "auto"))]
#[allow(clippy::too_many_arguments)]
pub fn fit<'py>(
    py: Python<'py>,
    clips: Option<&Bound<'py, PyAny>>,
    model: &str,
    optimizer: &str,
    per: &str,
    nested: bool,
    field: bool,
    arm: &str,
    chain: Option<Vec<String>>,
    select: Option<&Bound<'py, PyAny>>,
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
    shard: Option<&Bound<'py, PyAny>>,
    resume: bool,
    unit: &str,
    up: &str,
    positions: &str,
) -> PyResult<Bound<'py, PyAny>> {
    let model = parse::<Model>("model", model)?;
    let optimizer = parse::<OptimizerKind>("optimizer", optimizer)?.default_optimizer();
    let grouping = match per {
        "person" => FitGrouping::Person,
        "clip" => FitGrouping::Clip,
        _ => {
            return Err(errors::input(format!(
                "per={per:?}: expected \"person\" or \"clip\""
            )));
        }
    };
    let controller = controller.parse::<Controller>().map_err(errors::raise)?;
    let settings = fit_settings(
        out_dir.is_some(),
        seed,
        budget,
        population,
        temperature,
        stable_change,
        stable_window,
        objective,
        speed_weight,
    )?;
    if let Some(n) = refine {
        errors::check_range("refine", n, limits::BUDGET)?;
    }
    let source = ReachSource {
        clips,
        segments,
        arm,
        chain,
        select,
        frames,
        fixed_base,
        reading: (unit, up, positions),
    };
    let job = FitJob {
        models: FitJob::models_up_to(model, nested),
        optimizer,
        settings,
        refine,
    };
    if let Some(dir) = out_dir {
        if grouping != FitGrouping::Clip || field {
            return Err(errors::input(
                "out_dir= fits a library, one result per reach: per=\"clip\" without field",
            ));
        }
        let library = crate::library::LibraryFit {
            shard: crate::library::shard_arg(shard)?,
            query: source.query(controller)?,
            source: crate::library::LibrarySource {
                clips: clip_paths(source.clips)?,
                segments: source.segments,
            },
            job,
            dir,
            resume,
            pool: thread_pool(threads)?,
        };
        return crate::library::fit_library(py, library).map(Bound::into_any);
    }
    if shard.is_some() || resume {
        return Err(errors::input(
            "shard= and resume= belong to a library: fit(..., per=\"clip\", out_dir=DIR)",
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
        return fit_field(py, &mut runner, reaches, grouping);
    }
    let groups: Vec<Vec<CapturedReach>> = match grouping {
        FitGrouping::Person => vec![reaches],
        FitGrouping::Clip => reaches.into_iter().map(|r| vec![r]).collect(),
    };
    let mut files = Vec::with_capacity(groups.len());
    for group in &groups {
        let fits = runner.nested(py, group)?;
        let file = fits.params_file(group, grouping).map_err(errors::raise)?;
        files.push(Params {
            inner: PersonParams::Vector(file),
        });
    }
    match grouping {
        FitGrouping::Person => Ok(Bound::new(py, files.remove(0))?.into_any()),
        FitGrouping::Clip => Ok(PyList::new(py, files)?.into_any()),
    }
}

/// `fit(field=True)`: each reach fitted on its own (nested), the person's single vector (all
/// the reaches at once), and the field over the reaches' targets anchored to it, as
/// `kinergy fit --field` makes it.
fn fit_field<'py>(
    py: Python<'py>,
    runner: &mut Runner<'_>,
    reaches: Vec<CapturedReach>,
    grouping: FitGrouping,
) -> PyResult<Bound<'py, PyAny>> {
    if grouping == FitGrouping::Clip {
        return Err(errors::input(
            "field=True fits one field per person (each reach on its own inside it): drop per=\"clip\"",
        ));
    }
    if let Some(first) = reaches.first()
        && let Some(other) = reaches
            .iter()
            .find(|r| r.fitted_arm().side != first.fitted_arm().side)
    {
        return Err(errors::input(format!(
            "field=True: {} and {} are reaches of different arms; a field holds one arm's \
             reaches: fit each arm on its own",
            first.name(),
            other.name()
        )));
    }
    let mut last = Vec::with_capacity(reaches.len());
    // Each reach fitted under the person's tempo law, as the field runs.
    for reach in &kinergy_train::under_person_tempo(&reaches) {
        let fits = runner.nested(py, std::slice::from_ref(reach))?;
        last.extend(fits.fits.last().cloned());
    }
    let person = runner.nested(py, &reaches)?;
    let anchor = person
        .fits
        .last()
        .ok_or_else(|| errors::KinergyError::new_err("no model was fitted"))?;
    let tolerance = runner.job.settings.tolerance;
    let build = || {
        FieldFile::from_fits(&reaches, &last, &FieldSettings::default())
            .and_then(|f| f.anchored(anchor.values.clone(), &reaches, tolerance))
    };
    let pool = &runner.pool;
    let file = py
        .detach(|| match pool {
            Some(pool) => pool.install(build),
            None => build(),
        })
        .map_err(errors::raise)?;
    Ok(Bound::new(
        py,
        Params {
            inner: PersonParams::Field(file),
        },
    )?
    .into_any())
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
    /// The nested fit of `group` (then its refinement), with the GIL released
    /// ([`FitJob::run_stoppable`]).
    fn nested(&mut self, py: Python<'_>, group: &[CapturedReach]) -> PyResult<NestedFit> {
        self.watch.next_group();
        let (job, watch, pool, interrupt) =
            (&self.job, &mut self.watch, &self.pool, self.interrupt);
        let outcome = py.detach(move || {
            let mut go = move || job.run_stoppable(group, watch, Some(interrupt));
            match pool {
                Some(pool) => pool.install(go),
                None => go(),
            }
        });
        self.watch.finish()?;
        outcome.map_err(errors::raise)
    }
}

/// The process that loaded the module. A process forked from it (multiprocessing's default
/// start method on Linux, after a fit here) inherits rayon's global pool without its threads:
/// a parallel loop on it would wait forever. Such a process runs on pools of its own.
pub static LOADED_BY: OnceLock<u32> = OnceLock::new();

/// A rayon pool of `threads` workers, or None for the global pool (all cores) — in a forked
/// process ([`LOADED_BY`]) always a pool of its own.
pub fn thread_pool(threads: Option<usize>) -> PyResult<Option<rayon::ThreadPool>> {
    let forked = LOADED_BY
        .get()
        .is_some_and(|pid| *pid != std::process::id());
    let n = match threads {
        None if !forked => return Ok(None),
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
        Some(n) => {
            errors::check_range("threads", n, limits::THREADS)?;
            n
        }
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map(Some)
        .map_err(|e| errors::KinergyError::new_err(format!("threads={n}: {e}")))
}

/// The hand's speed, m/s, one value per frame (float64 array), as `kinergy plot speed
/// --csv` computes it: central differences of the arm's hand point, in the world (default) or
/// relative to the shoulder (`relative=True`, the arm's own motion), optionally smoothed by a
/// moving average of `smoothing` seconds (0 to 10; 0: raw).
#[pyfunction]
#[pyo3(signature = (clip, *, arm = "right", chain = None, relative = false, smoothing = 0.0, unit = "auto", up = "auto", positions = "auto"))]
#[allow(clippy::too_many_arguments)]
pub fn hand_speed<'py>(
    py: Python<'py>,
    clip: &Bound<'py, PyAny>,
    arm: &str,
    chain: Option<Vec<String>>,
    relative: bool,
    smoothing: f64,
    unit: &str,
    up: &str,
    positions: &str,
) -> PyResult<Bound<'py, numpy::PyArray1<f64>>> {
    use numpy::IntoPyArray;
    errors::check_range("smoothing", smoothing, limits::PLOT_SMOOTHING)?;
    let options = import_options(unit, up, positions, limits::DEFAULT_INPUT_MB)?;
    let (clip, path) = clip_arg(py, clip, &options)?;
    let joints = arm_joints(&clip, &path, parse::<Side>("arm", arm)?, chain)?;
    let settings = SegmentSettings {
        smoothing,
        relative_to_shoulder: relative,
        ..SegmentSettings::default()
    };
    let speed =
        kinergy_motion::segment::hand_speed(&clip, &joints, &settings).map_err(errors::raise)?;
    Ok(speed.into_pyarray(py))
}
