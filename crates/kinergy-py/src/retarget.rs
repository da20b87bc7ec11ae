//! `kinergy.retarget`: a motion moved onto another skeleton, the library's [`Retargeter`]
//! from Python's arguments, the roles chosen as `kinergy retarget` chooses them
//! ([`BodyJoints`]: found, a built-in map or a JSON map).

use kinergy_motion::{BodyJoints, Retargeter, TargetArms};
use pyo3::prelude::*;

use crate::args::to_python;
use crate::clip::Clip;
use crate::errors;

/// Moves `clip`'s motion onto the skeleton of `template` (its motion is not used), as
/// `kinergy retarget` does: joints matched by role, each role's world orientation carried
/// over, the root's path scaled by the ratio of standing pelvis heights, the hands on their
/// paths about the shoulders scaled by arm length, planted feet held (two-bone IK, knees and
/// elbows within their bend limits). Returns the motion on the template's skeleton (the
/// clip's frames and frame time) and the report, `kinergy retarget --json`'s fields of the
/// retargeting, as a dict: `roles` ([role, clip's joint, template's joint]), `unmapped`,
/// `leg_scale`, `arm_scale` (right, left), `plants` (per foot, right then left: {first,
/// last, at}), `foot_slide_m`, `foot_error_m`, `hand_error_m`, `bend_limited_frames`,
/// `pelvis_drop_m`.
///
/// map, to_map: the roles of the clip's and of the template's skeleton — "auto" (found by
/// joint names), a built-in map ("cmu", "bandai", "mixamo", "cc") or the path of a JSON map
/// of roles to joint names (ending in .json). Raises InputError for an unknown map name, a
/// skeleton lacking a joint its map names, or a body whose roles are not found.
///
/// arms: "template" (the template's skeleton as it is) or "source" (its upper arms and
/// forearms scaled to the clip performer's, times the bodies' size ratio: the performer's arm
/// proportions, on which a person's synergy replays as fitted), as `kinergy retarget --arms`.
/// Raises InputError for another value.
#[pyfunction]
#[pyo3(signature = (clip, template, *, map = "auto", to_map = "auto", arms = "template"))]
pub fn retarget<'py>(
    py: Python<'py>,
    clip: &Bound<'py, Clip>,
    template: &Bound<'py, Clip>,
    map: &str,
    to_map: &str,
    arms: &str,
) -> PyResult<(Clip, Bound<'py, PyAny>)> {
    let (clip, template) = (clip.get(), template.get());
    let arms: TargetArms = arms.parse().map_err(|e| errors::input(format!("{e}")))?;
    let from = body(clip, map, "map", "clip")?;
    let to = body(template, to_map, "to_map", "template")?;
    let target = template.inner.skeleton().clone();
    let done = py
        .detach(|| {
            let target = arms.skeleton(&clip.inner, &from, target, &to)?;
            Retargeter::new(&clip.inner, from, target, to)?.run(&clip.inner)
        })
        .map_err(|e| errors::input(format!("retarget: {e}")))?;
    let report = to_python(py, &done.report)?;
    Ok((Clip::made(done.clip), report))
}

/// The roles `choice` (the keyword argument `name`) names on the skeleton of `clip` (`what`:
/// "clip" or "template", for messages): [`BodyJoints::choose`], as the CLI's `--map`.
fn body(clip: &Clip, choice: &str, name: &str, what: &str) -> PyResult<BodyJoints> {
    let which = clip
        .path
        .as_ref()
        .map_or_else(|| what.to_string(), |p| format!("{what} {}", p.display()));
    BodyJoints::choose(clip.inner.skeleton(), choice)
        .map_err(|e| errors::input(format!("{which}: {e} ({name}={choice:?})")))
}
