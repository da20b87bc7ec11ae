//! The full-body verbs beyond one reach: `style` (does a person's drive reach in their
//! style?) and `plan` (collision-free reaching and manipulation in a scene).

use std::path::PathBuf;
use std::time::Duration;

use kinergy_motion::Side;
use kinergy_motion::nalgebra::Point3;
use kinergy_plan::request::{BUDGET_MS, DISTANCE_M, Goal, TaskKind, TaskRequest};
use kinergy_plan::scene::Scene;
use kinergy_plan::space::HandTarget;
use kinergy_reach::style::{StyleCapture, StyleRun, StyleSummary};
use kinergy_train::fidelity::PersonFidelity;
use kinergy_train::limits;
use kinergy_train::source::capture_files;
use kinergy_train::style::StyleTake;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::clip::{Clip, import_options, parse};
use crate::errors;
use crate::params::params_arg;

/// `json.loads(serde_json of value)`.
fn to_python<'py, T: serde::Serialize>(py: Python<'py>, value: &T) -> PyResult<Bound<'py, PyAny>> {
    let text = kinergy_io::to_pretty_json(value)
        .map_err(|e| errors::KinergyError::new_err(e.to_string()))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// Whether a person's parameters make the full-body character reach in their style, as
/// `kinergy style` measures it: for each capture (paths or folders), the character reaches
/// the capture's target with the person's drive and with the default profile, and each hand
/// speed profile is compared with the captured one.
///
/// Returns a dict: `fidelity` (the real-time figures of `kinergy style --json`: per capture
/// and per person the error e of the arm on the captured torso, the full body and the
/// default profile against the person's own repeats and minimum jerk, duration and peak
/// ratios, SPARC, real-time jumps), `summary` (the time-normalized means over the
/// captures), `rows` (one dict per capture: correlations, peak times, arm paths, as
/// `style.csv`), and with `motions=True` also
/// `motions`, one dict per capture with the two full-body Clips (`params`, `profile`).
/// Ctrl-C stops it between captures (KeyboardInterrupt).
#[pyfunction]
#[pyo3(signature = (clips, params, *, arm = "right", chain = None, motions = false, unit = "auto", up = "auto", positions = "auto"))]
#[allow(clippy::too_many_arguments)]
pub fn style<'py>(
    py: Python<'py>,
    clips: Vec<PathBuf>,
    params: &Bound<'py, PyAny>,
    arm: &str,
    chain: Option<Vec<String>>,
    motions: bool,
    unit: &str,
    up: &str,
    positions: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let options = import_options(unit, up, positions, limits::DEFAULT_INPUT_MB)?;
    let side = parse::<Side>("arm", arm)?;
    let person = params_arg(params)?;
    let paths = capture_files(&clips).map_err(errors::raise)?;
    // One capture at a time with the GIL released, Ctrl-C checked between them.
    let mut runs = Vec::with_capacity(paths.len());
    for path in &paths {
        let run = py.detach(|| -> PyResult<_> {
            let (clip, _) = kinergy_motion::read_clip(path, &options).map_err(errors::raise)?;
            let joints = kinergy_train::source::ArmChoice {
                side,
                joints: chain.clone(),
            }
            .find(&clip, path)
            .map_err(errors::raise)?;
            let name = path.display().to_string();
            // The same take as `kinergy style` runs: the body's arm starts as the fit's
            // replay, and every motion is kept in real time.
            let take =
                StyleTake::run(&clip, &joints, &name, &person, side).map_err(|e| match e {
                    e @ kinergy_train::TrainError::Reach { .. } => {
                        errors::input(format!("{name}: {e}"))
                    }
                    e => errors::raise(e),
                })?;
            Ok(take)
        })?;
        runs.push(run);
        py.check_signals()?;
    }
    let motions_of: Vec<_> = runs.iter().map(|t| t.motions.clone()).collect();
    let fidelity = PersonFidelity::of(&motions_of);
    let runs: Vec<(StyleCapture, StyleRun)> =
        runs.into_iter().map(|t| (t.capture, t.run)).collect();
    let rows: Vec<_> = runs.iter().map(|(_, run)| run.row.clone()).collect();
    let out = PyDict::new(py);
    out.set_item("fidelity", to_python(py, &fidelity)?)?;
    out.set_item("summary", to_python(py, &StyleSummary::of(&rows))?)?;
    out.set_item("rows", to_python(py, &rows)?)?;
    if motions {
        let list = PyList::empty(py);
        for (capture, run) in &runs {
            let item = PyDict::new(py);
            item.set_item("clip", &run.row.clip)?;
            for (key, motion) in [
                ("params", &run.params_motion),
                ("profile", &run.profile_motion),
            ] {
                let clip = capture
                    .character()
                    .to_clip(&motion.poses, motion.frame_time)
                    .map_err(errors::raise)?;
                let clip = Clip::made(clip).with_report(&motion.report);
                item.set_item(key, Bound::new(py, clip)?)?;
            }
            list.append(item)?;
        }
        out.set_item("motions", list)?;
    }
    Ok(out)
}

/// Collision-free reaching and manipulation in a scene (Kallmann 2005), as `kinergy plan`
/// makes it: IK with collision avoidance, RRT-Connect and smoothing. Returns the motion as
/// a Clip of the character (with fingers).
///
/// scene: a scene file (JSON, see examples/bookshelf/). Either `target` — the grip point
/// [x, y, z] in world meters, optionally with the hand's rotation [x, y, z, qx, qy, qz, qw]
/// — or `task`: "grasp", "relocate" (with `to`), "pull" or "push" (by `distance` meters) on
/// the scene's `object`. params: a person's Params (or file): their synergy drives the arm
/// and their hand-speed bell times the path. arm: the acting arm. seed: the planner's random
/// stream. budget_ms: the planner's time budget (default: its iteration budget only).
/// Raises UnreachableError when no collision-free motion is found.
#[pyfunction]
#[pyo3(signature = (scene, *, target = None, task = None, object = None, to = None, distance = 0.2, arm = "right", seed = 0, params = None, budget_ms = None))]
#[allow(clippy::too_many_arguments)]
pub fn plan<'py>(
    py: Python<'py>,
    scene: PathBuf,
    target: Option<Vec<f64>>,
    task: Option<&str>,
    object: Option<String>,
    to: Option<[f64; 3]>,
    distance: f64,
    arm: &str,
    seed: u64,
    params: Option<&Bound<'py, PyAny>>,
    budget_ms: Option<u64>,
) -> PyResult<Clip> {
    errors::check_range("distance", distance, DISTANCE_M)?;
    if let Some(ms) = budget_ms {
        errors::check_range("budget_ms", ms, BUDGET_MS)?;
    }
    let side = parse::<Side>("arm", arm)?;
    let scene_file = Scene::read(&scene).map_err(errors::raise)?;
    let goal = match (target, task) {
        (Some(t), _) => Goal::Reach(hand_target(&t)?),
        (None, Some(kind)) => {
            let kind = kind.parse::<TaskKind>().map_err(errors::raise)?;
            let object = object.ok_or_else(|| errors::input("task needs object=NAME"))?;
            let to = to.map(|[x, y, z]| Point3::new(x, y, z));
            if let Some(to) = &to {
                kinergy_reach::drive::check_target(to).map_err(errors::raise)?;
            }
            Goal::task(kind, object, to, distance).map_err(errors::raise)?
        }
        (None, None) => return Err(errors::input("give target=[x, y, z] or task=")),
    };
    let person = params.map(params_arg).transpose()?;
    let request = TaskRequest {
        scene: scene_file,
        scene_name: scene.display().to_string(),
        goal,
        side,
        seed,
        budget: budget_ms.map(Duration::from_millis),
        person: person
            .as_ref()
            .map(|p| p as &dyn kinergy_solver::PersonStyle),
    };
    request.validate().map_err(errors::raise)?;
    let planned = py.detach(|| request.run()).map_err(errors::raise)?;
    Ok(Clip::made(planned.clip).with_report(&planned.report))
}

/// `target=`: [x, y, z] or [x, y, z, qx, qy, qz, qw], finite, within reach of any body.
fn hand_target(values: &[f64]) -> PyResult<HandTarget> {
    let target = HandTarget::from_values(values)
        .map_err(|why| errors::input(format!("target {values:?}: {why}")))?;
    let reach = target.position.coords.norm();
    if reach > kinergy_train::MAX_TARGET_DISTANCE {
        return Err(errors::input(format!(
            "target: {reach} m from the character, beyond what any body reaches (at most {} m)",
            kinergy_train::MAX_TARGET_DISTANCE
        )));
    }
    Ok(target)
}
