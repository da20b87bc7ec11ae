//! `kinergy.plan`: collision-free reaching and manipulation in a scene, the library's
//! [`TaskRequest`] from Python's arguments.

use std::path::PathBuf;
use std::time::Duration;

use kinergy_motion::Side;
use kinergy_motion::nalgebra::Point3;
use kinergy_plan::level::Level;
use kinergy_plan::request::{BUDGET_MS, DISTANCE_M, Goal, TaskKind, TaskRequest};
use kinergy_plan::scene::Scene;
use kinergy_plan::space::HandTarget;
use pyo3::prelude::*;

use crate::args::{Arg, ParamsArg, parse};
use crate::clip::Clip;
use crate::errors;

/// Collision-free reaching and manipulation in a scene (Kallmann 2005), as `kinergy plan`
/// makes it: IK with collision avoidance, RRT-Connect and smoothing. Returns the motion as
/// a Clip of the character (with fingers).
///
/// scene: a scene file (JSON, see examples/bookshelf/). Either `target` — the grip point
/// [x, y, z] in world meters, optionally with the hand's rotation [x, y, z, qx, qy, qz, qw]
/// — or `task`: "grasp", "relocate" (with `to`), "pull" or "push" (by `distance` meters) on
/// the scene's `object`. params: a person's Params (or file): their synergy drives the arm
/// and their hand-speed bell times the path. arm: the acting arm. level: how a reach
/// (`target`) is computed after Kallmann's three levels — "ik" (the hand on a straight line,
/// IK on every frame, only the goal posture checked for collisions), "straight" (IK with
/// collision avoidance on every frame), "planner" (RRT-Connect), or "auto" (each in turn until
/// one's motion is collision-free); a task takes "auto" or "planner". seed: the planner's
/// random stream. budget_ms: the planner's time budget (default: its iteration budget only).
/// Where the arm alone cannot reach the target, the spine bends and twists and the legs squat,
/// the feet planted. The clip's report says which level solved a reach and how each tried
/// went, and which body DoFs moved (`body_dofs`, `body`).
/// Raises UnreachableError when no collision-free motion is found.
#[pyfunction]
#[pyo3(signature = (scene, *, target = None, task = None, object = None, to = None, distance = 0.2, arm = "right", level = "auto", seed = 0, params = None, budget_ms = None))]
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
    level: &str,
    seed: u64,
    params: Option<Arg<ParamsArg>>,
    budget_ms: Option<u64>,
) -> PyResult<Clip> {
    errors::check_range("distance", distance, DISTANCE_M)?;
    if let Some(ms) = budget_ms {
        errors::check_range("budget_ms", ms, BUDGET_MS)?;
    }
    let side = parse::<Side>("arm", arm)?;
    let level = parse::<Level>("level", level)?;
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
    let person = params.map(|p| p.0.load()).transpose()?;
    let request = TaskRequest {
        scene: scene_file,
        scene_name: scene.display().to_string(),
        goal,
        side,
        level,
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
