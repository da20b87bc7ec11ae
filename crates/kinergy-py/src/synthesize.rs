//! `kinergy.synthesize`: a synergy reach on a capture's skeleton, the library's
//! [`SynthesizeRequest`] from Python's arguments.

use kinergy_motion::Side;
use kinergy_motion::segment::Selection;
use kinergy_solver::{BaseMode, Model, OptimizerKind};
use kinergy_train::source::{ControllerKind, FrameChoice};
use kinergy_train::synthesize::{Drive, SynthesizeRequest};
use pyo3::prelude::*;

use crate::args::{Arg, ClipArg, FramesArg, ParamsArg, Reading, SelectArg, parse};
use crate::clip::Clip;
use crate::errors;

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
/// one is warned of). controller: "smooth" or "paper" (default: the one the params were
/// fitted under, else smooth; another one is warned of). check: raise UnreachableError (its `clip` holds the motion) when the
/// target is not reached.
#[pyfunction]
#[pyo3(signature = (clip, params = None, *, frames = None, select = None, target = None, model = "sa", optimizer = "svd", arm = None, chain = None, fixed_base = false, controller = None, stop_at_reach = false, tolerance = 0.005, max_seconds = 10.0, check = true, unit = "auto", up = "auto", positions = "auto"))]
#[allow(clippy::too_many_arguments)]
pub fn synthesize<'py>(
    py: Python<'py>,
    clip: Arg<ClipArg>,
    params: Option<Arg<ParamsArg>>,
    frames: Option<Arg<FramesArg>>,
    select: Option<Arg<SelectArg>>,
    target: Option<[f64; 3]>,
    model: &str,
    optimizer: &str,
    arm: Option<&str>,
    chain: Option<Vec<String>>,
    fixed_base: bool,
    controller: Option<&str>,
    stop_at_reach: bool,
    tolerance: f64,
    max_seconds: f64,
    check: bool,
    unit: &str,
    up: &str,
    positions: &str,
) -> PyResult<Clip> {
    let options = Reading {
        unit,
        up,
        positions,
    }
    .options()?;
    let frames = frames.map_or(Ok(FrameChoice::Fitted), |f| f.0.choice())?;
    let frames = match select.map(|s| s.0.selection()).transpose()? {
        None => frames,
        Some(_) if !matches!(frames, FrameChoice::Fitted) => {
            return Err(errors::input("select= or frames=: not both"));
        }
        Some(Selection::Nth(n)) => FrameChoice::Nth(n),
        Some(Selection::Main) => FrameChoice::Main,
        Some(Selection::All) => {
            return Err(errors::input(
                "select=\"all\": synthesize makes one reach; pick \"main\" or a segment number",
            ));
        }
    };
    let drive = match params.map(|p| p.0.load()).transpose()? {
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
        controller: controller
            .map(str::parse::<ControllerKind>)
            .transpose()
            .map_err(errors::raise)?,
        target: target.map(|[x, y, z]| kinergy_motion::nalgebra::Point3::new(x, y, z)),
        drive,
        tolerance,
        max_seconds,
        stop_at_reach,
    };
    request.validate().map_err(errors::raise)?;
    let (whole, from) = clip.0.load(py, &options)?;
    let done = py
        .detach(|| request.run(&whole, &from))
        .map_err(errors::raise)?;
    if let Some(warning) = &done.warning {
        let warnings = py.import("warnings")?;
        warnings.call_method1("warn", (warning.as_str(),))?;
    }
    let out = Clip::made(done.clip).with_report(&done.report);
    match done.report.ending() {
        Err(e) if check => Err(crate::clip::unreachable(py, e.to_string(), out)),
        _ => Ok(out),
    }
}
