//! `kinergy.hand_speed`: the hand's speed of `kinergy plot speed --csv`.

use kinergy_motion::Side;
use kinergy_motion::segment::SegmentSettings;
use kinergy_train::limits;
use numpy::IntoPyArray;
use pyo3::prelude::*;

use crate::args::{Arg, ClipArg, Reading, arm_joints, parse};
use crate::errors;

/// The hand's speed, m/s, one value per frame (float64 array), as `kinergy plot speed
/// --csv` computes it: central differences of the arm's hand point, in the world (default) or
/// relative to the shoulder (`relative=True`, the arm's own motion), optionally smoothed by a
/// moving average of `smoothing` seconds (0 to 10; 0: raw).
#[pyfunction]
#[pyo3(signature = (clip, *, arm = "right", chain = None, relative = false, smoothing = 0.0, unit = "auto", up = "auto", positions = "auto"))]
#[allow(clippy::too_many_arguments)]
pub fn hand_speed<'py>(
    py: Python<'py>,
    clip: Arg<ClipArg>,
    arm: &str,
    chain: Option<Vec<String>>,
    relative: bool,
    smoothing: f64,
    unit: &str,
    up: &str,
    positions: &str,
) -> PyResult<Bound<'py, numpy::PyArray1<f64>>> {
    errors::check_range("smoothing", smoothing, limits::PLOT_SMOOTHING)?;
    let options = Reading {
        unit,
        up,
        positions,
    }
    .options()?;
    let (clip, path) = clip.0.load(py, &options)?;
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
