//! `kinergy.view`: the page of `kinergy view`.

use std::path::{Path, PathBuf};

use kinergy_draw::viewer::{self, Hand, ViewerClip, ViewerPage};
use kinergy_motion::nalgebra::Point3;
use pyo3::prelude::*;

use crate::args::{Arg, ClipsArg, Reading};
use crate::errors;

/// Writes `kinergy view`'s page of `clips` (Clips or BVH paths, 1 to 24) to `output` (a
/// `.html` file, written atomically; everything inlined, it opens offline): the clips overlaid
/// in 3-D on one clock, each at its own frame rate, the hand-speed chart synced to the
/// scrubber. `target` (x, y, z, meters) is drawn as a ball and `scene` (a `plan` scene file)
/// with the clips. `hand`: "right", "left", "auto" (per clip, the hand that travels farther) or
/// "none". `labels` name the clips in the legend (default: the file names, or `clip1`, …).
/// Returns the page's size in bytes. Raises `InputError` for a bad clip or argument, naming
/// it, before anything is written.
#[pyfunction]
#[pyo3(signature = (clips, output, *, target = None, scene = None, hand = "auto", title = None, labels = None, unit = "auto", up = "auto", positions = "auto"))]
#[allow(clippy::too_many_arguments)]
pub fn view(
    py: Python<'_>,
    clips: Arg<ClipsArg>,
    output: PathBuf,
    target: Option<[f64; 3]>,
    scene: Option<PathBuf>,
    hand: &str,
    title: Option<String>,
    labels: Option<Vec<String>>,
    unit: &str,
    up: &str,
    positions: &str,
) -> PyResult<usize> {
    let is_html = output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("html") || e.eq_ignore_ascii_case("htm"));
    if !is_html {
        return Err(errors::input(format!(
            "output {}: the page is HTML: the file name must end in .html",
            output.display()
        )));
    }
    let hand: Hand = hand
        .parse()
        .map_err(|why: String| errors::input(format!("hand: {why}")))?;
    let target = match target {
        Some(t) if t.iter().all(|v| v.is_finite()) => Some(Point3::from(t)),
        Some(_) => return Err(errors::input("target: three finite numbers (meters)")),
        None => None,
    };
    let options = Reading {
        unit,
        up,
        positions,
    }
    .options()?;
    let clips = clips.0.into_vec();
    if clips.is_empty() || clips.len() > viewer::MAX_CLIPS {
        return Err(errors::input(format!(
            "clips: {} given, a page shows 1 to {}",
            clips.len(),
            viewer::MAX_CLIPS
        )));
    }
    if let Some(l) = &labels
        && l.len() != clips.len()
    {
        return Err(errors::input(format!(
            "labels: {} for {} clips",
            l.len(),
            clips.len()
        )));
    }
    let objects = match &scene {
        Some(path) => viewer::read_scene(path).map_err(errors::raise)?.0,
        None => Vec::new(),
    };
    let mut shown = Vec::with_capacity(clips.len());
    for (k, clip) in clips.into_iter().enumerate() {
        let (clip, path) = clip.load(py, &options)?;
        let label = match &labels {
            Some(l) => l[k].clone(),
            None => label_of(&path, k),
        };
        shown.push(ViewerClip::of_clip(&clip, &path, label, hand).map_err(errors::raise)?);
    }
    let page = ViewerPage {
        title: title.unwrap_or_else(|| {
            shown
                .iter()
                .map(|c| c.label().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        }),
        clips: shown,
        target,
        objects,
        figures: Vec::new(),
    };
    let html = viewer::page_html(&page).map_err(errors::raise)?;
    py.detach(|| kinergy_io::write_atomic(&output, html.as_bytes()))
        .map_err(|e| errors::KinergyError::new_err(format!("{}: {e}", output.display())))?;
    Ok(html.len())
}

/// A clip's legend entry: its file's stem, or `clip1`, … for a clip made in memory.
fn label_of(path: &Path, k: usize) -> String {
    match path.file_stem() {
        Some(s) if path != Path::new("<clip>") => s.to_string_lossy().into_owned(),
        _ => format!("clip{}", k + 1),
    }
}
