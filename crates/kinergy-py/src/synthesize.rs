//! `kinergy.synthesize`: a synergy reach on a capture's skeleton, the library's
//! [`SynthesizeRequest`] from Python's arguments.

use kinergy_motion::Side;
use kinergy_motion::segment::Selection;
use kinergy_solver::{BaseMode, Model, OptimizerKind};
use kinergy_train::limits;
use kinergy_train::source::{Controller, FrameChoice};
use kinergy_train::synthesize::{Drive, SynthesizeRequest};
use pyo3::prelude::*;

use crate::clip::{Clip, import_options, parse};
use crate::errors;
use crate::params::params_arg;
use crate::verbs::{clip_arg, selection_arg};

/// A synergy reach on a capture's skeleton, as `kinergy synthesize` makes it: from the
/// capture's frame where the reach starts toward its final hand position (or `target`,
/// world meters), with the capture's torso replayed. Returns the motion as a Clip (the
/// capture's skeleton; `Clip.report` says how it ended).
///
/// clip: a Clip or a path. params: Params (or a path to a parameters or field file);
/// None drives the neutral `model` with `optimizer`. frames: "fit" (the frames the params
/// were fitted on for this capture; the default), "auto" (the main reach), "all", or
/// (start, end); or select: "main" or a segment number (as `kinergy segment` lists them).
/// arm: "right" or "left" (default: the fitted arm, else right; an arm other than the fitted
/// one is warned of). check: raise UnreachableError (its `clip` holds the motion) when the
/// target is not reached.
#[pyfunction]
#[pyo3(signature = (clip, params = None, *, frames = None, select = None, target = None, model = "sa", optimizer = "svd", arm = None, chain = None, fixed_base = false, controller = "smooth", stop_at_reach = false, tolerance = 0.005, max_seconds = 10.0, check = true, unit = "auto", up = "auto", positions = "auto"))]
#[allow(clippy::too_many_arguments)]
pub fn synthesize<'py>(
    py: Python<'py>,
    clip: &Bound<'py, PyAny>,
    params: Option<&Bound<'py, PyAny>>,
    frames: Option<&Bound<'py, PyAny>>,
    select: Option<&Bound<'py, PyAny>>,
    target: Option<[f64; 3]>,
    model: &str,
    optimizer: &str,
    arm: Option<&str>,
    chain: Option<Vec<String>>,
    fixed_base: bool,
    controller: &str,
    stop_at_reach: bool,
    tolerance: f64,
    max_seconds: f64,
    check: bool,
    unit: &str,
    up: &str,
    positions: &str,
) -> PyResult<Clip> {
    let options = import_options(unit, up, positions, limits::DEFAULT_INPUT_MB)?;
    let frames = match frames {
        None => FrameChoice::Fitted,
        Some(f) => match f.extract::<(usize, usize)>() {
            Ok((a, b)) if a < b => FrameChoice::Window(a..b),
            Ok((a, b)) => {
                return Err(errors::input(format!(
                    "frames=({a}, {b}): expected (start, end) with start < end"
                )));
            }
            Err(_) => match f.extract::<String>()?.as_str() {
                "fit" => FrameChoice::Fitted,
                "auto" => FrameChoice::Main,
                "all" => FrameChoice::All,
                other => {
                    return Err(errors::input(format!(
                        "frames={other:?}: expected \"fit\", \"auto\", \"all\" or (start, end)"
                    )));
                }
            },
        },
    };
    let frames = match select {
        None => frames,
        Some(_) if !matches!(frames, FrameChoice::Fitted) => {
            return Err(errors::input("select= or frames=: not both"));
        }
        Some(s) => match selection_arg(Some(s))? {
            Some(Selection::Nth(n)) => FrameChoice::Nth(n),
            Some(Selection::Main) | None => FrameChoice::Main,
            Some(Selection::All) => {
                return Err(errors::input(
                    "select=\"all\": synthesize makes one reach; pick \"main\" or a segment number",
                ));
            }
        },
    };
    let drive = match params.map(params_arg).transpose()? {
        Some(params) => Drive::Person {
            params: Box::new(params),
            path: None,
        },
        None => Drive::Neutral {
            model: parse::<Model>("model", model)?,
            optimizer: parse::<OptimizerKind>("optimizer", optimizer)?.default_optimizer(),
        },
    };
    let request = SynthesizeRequest {
        frames,
        arm: arm.map(|a| parse::<Side>("arm", a)).transpose()?,
        chain,
        base: if fixed_base {
            BaseMode::Fixed
        } else {
            BaseMode::Replay
        },
        controller: controller.parse::<Controller>().map_err(errors::raise)?,
        target: target.map(|[x, y, z]| kinergy_motion::nalgebra::Point3::new(x, y, z)),
        drive,
        tolerance,
        max_seconds,
        stop_at_reach,
    };
    request.validate().map_err(errors::raise)?;
    let (whole, from) = clip_arg(py, clip, &options)?;
    let done = py
        .detach(|| request.run(&whole, &from))
        .map_err(errors::raise)?;
    if let Some(warning) = &done.warning {
        let warnings = py.import("warnings")?;
        warnings.call_method1("warn", (warning.as_str(),))?;
    }
    let out = Clip::made(done.clip).with_report(&done.report);
    match done.report.ending() {
        Err(e) if check => Err(errors::unreachable(py, e.to_string(), out)),
        _ => Ok(out),
    }
}
