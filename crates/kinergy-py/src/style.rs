//! `kinergy.style`: does a person's drive make the full-body character reach in their
//! style? The library's [`StyleTake`] and [`PersonFidelity`], as `kinergy style` runs them.

use std::path::PathBuf;

use kinergy_motion::Side;
use kinergy_reach::style::{StyleCapture, StyleRun, StyleSummary};
use kinergy_train::fidelity::PersonFidelity;
use kinergy_train::style::StyleTake;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::args::{Arg, ParamsArg, Reading, arm_joints, parse, to_python};
use crate::clip::Clip;
use crate::errors;

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
    params: Arg<ParamsArg>,
    arm: &str,
    chain: Option<Vec<String>>,
    motions: bool,
    unit: &str,
    up: &str,
    positions: &str,
) -> PyResult<Bound<'py, PyDict>> {
    let options = Reading {
        unit,
        up,
        positions,
    }
    .options()?;
    let side = parse::<Side>("arm", arm)?;
    let person = params.0.load()?;
    let paths = crate::args::capture_files(py, &clips)?;
    // One capture at a time with the GIL released, Ctrl-C checked between them.
    let mut runs = Vec::with_capacity(paths.len());
    for path in &paths {
        let run = py.detach(|| -> PyResult<_> {
            let (clip, _) = kinergy_motion::read_clip(path, &options).map_err(errors::raise)?;
            let joints = arm_joints(&clip, path, side, chain.clone())?;
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
