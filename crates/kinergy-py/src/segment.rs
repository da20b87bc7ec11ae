//! `kinergy.segment`: a capture's labelled segments, the library's
//! [`SegmentListing`] from Python's arguments.

use kinergy_motion::Side;
use kinergy_motion::segment::{SegmentSettings, Selection};
use kinergy_train::listing::SegmentListing;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::args::{Arg, ClipArg, Reading, SelectArg, arm_joints, parse, to_python};
use crate::errors;

/// The labelled segments of a clip's hand speed: a list of dicts, each a segment of
/// `kinergy segment --json` (`index`, `frames`, `onset`, `peak`, `end` — frames, end
/// excluded — `label` "reach", "return" or "other", `peak_speed_m_s`, `displacement_m`,
/// `onset_s`, `duration_s`, `truncated`, `in_world`, `main`) with its `arm`.
///
/// clip: a Clip or a path. arm: "right", "left" or "auto" (the arms that reach; their
/// reaches). select: None (every segment), "main", "all" (every reach) or a segment number.
/// world: measure the hand's speed in the world instead of relative to the shoulder.
#[pyfunction]
#[pyo3(signature = (clip, *, arm = "right", chain = None, select = None, world = false, min_peak_speed = None, unit = "auto", up = "auto", positions = "auto"))]
#[allow(clippy::too_many_arguments)]
pub fn segment<'py>(
    py: Python<'py>,
    clip: Arg<ClipArg>,
    arm: &str,
    chain: Option<Vec<String>>,
    select: Option<Arg<SelectArg>>,
    world: bool,
    min_peak_speed: Option<f64>,
    unit: &str,
    up: &str,
    positions: &str,
) -> PyResult<Bound<'py, PyList>> {
    let options = Reading {
        unit,
        up,
        positions,
    }
    .options()?;
    let (clip, path) = clip.0.load(py, &options)?;
    let defaults = SegmentSettings::default();
    let listing = SegmentListing {
        selection: select.map(|s| s.0.selection()).transpose()?,
        settings: SegmentSettings {
            relative_to_shoulder: !world,
            ..min_peak_speed.map_or(defaults, |v| defaults.with_min_peak_speed(v))
        },
    };
    listing.validate().map_err(errors::raise)?;
    let arms = if arm == "auto" {
        if let Some(Selection::Nth(n)) = listing.selection {
            return Err(errors::input(format!(
                "select={n}: one numbered segment names no arm: with arm=\"auto\" select \"main\" or \"all\""
            )));
        }
        match listing.reaching_arms(&path, &clip).map_err(errors::raise)? {
            Ok(arms) => arms,
            Err(skipped) => {
                return Err(errors::raise(kinergy_train::source::nothing_found(&[
                    skipped,
                ])));
            }
        }
    } else {
        let side = parse::<Side>("arm", arm)?;
        let joints = arm_joints(&clip, &path, side, chain)?;
        vec![
            listing
                .arm(&path, &clip, &joints, side)
                .map_err(errors::raise)?,
        ]
    };
    let out = PyList::empty(py);
    for listed in &arms {
        let side = listed.side.to_string();
        for segment in &listed.segments {
            let row = to_python(py, segment)?.cast_into::<PyDict>()?;
            row.set_item("arm", &side)?;
            out.append(row)?;
        }
    }
    Ok(out)
}
