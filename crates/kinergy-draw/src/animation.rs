//! Clips as superposed stick figures, synchronized by time (the paper's Fig. 6: captured vs
//! S_A vs S_C) — an animated GIF and a film strip of snapshots — with, optionally, the scene a
//! plan moves in and the objects it carries (Kallmann's Fig. 5).
//!
//! What is drawn of a skeleton is decided by [`bones`](crate::bones): body bones full width,
//! finger bones thin, face joints, a reference root and zero-length bones not at all. The view
//! is fitted to the drawn joints over all frames (and to carried objects), with a margin; the
//! scene is drawn clipped to it.
//!
//! - [`Track`]: one clip's figure over time; [`read_props`]: a scene's objects, fixed or moved
//!   by a plan's report; [`Scene`]: both, seen from a [`View`];
//! - [`stage_gif`] and [`stage_strip`]: the two pictures, staged for an atomic
//!   [`commit`](crate::commit); [`gif_frame_count`] and [`strip_times`]: their instants.

mod objects;
mod picture;
mod timing;
mod view;

use std::path::{Path, PathBuf};

use kinergy_io::AtomicFile;

use crate::DrawError;
pub use objects::{Drawn, Prop, Props, Track, read_props};
pub use picture::{Scene, Strip, Style, draw_scene};
pub use timing::{gif_frame_count, nearest_frame, strip_times};
pub(crate) use view::{Bounds, Mapping};
pub use view::{UnknownView, View};

/// Labels for the clips at `paths`: their file stems, with as many parent folders as it takes
/// to tell them apart (`p01/r01`, `p02/r01`).
pub fn labels(paths: &[PathBuf]) -> Vec<String> {
    let parts: Vec<Vec<String>> = paths
        .iter()
        .map(|p| {
            let stem = p.file_stem().unwrap_or(p.as_os_str());
            let mut parts = vec![stem.to_string_lossy().into_owned()];
            if let Some(parent) = p.parent() {
                parts.extend(
                    parent
                        .components()
                        .rev()
                        .map(|c| c.as_os_str().to_string_lossy().into_owned()),
                );
            }
            parts
        })
        .collect();
    let deepest = parts.iter().map(Vec::len).max().unwrap_or(1);
    let mut out = Vec::new();
    for depth in 1..=deepest {
        out = parts
            .iter()
            .map(|p| {
                let mut head: Vec<&str> = p.iter().take(depth).map(String::as_str).collect();
                head.reverse();
                head.join("/")
            })
            .collect();
        let mut sorted = out.clone();
        sorted.sort();
        sorted.dedup();
        if sorted.len() == out.len() {
            break;
        }
    }
    out
}

/// Draws the animated GIF of `scene` for `path` ([`gif_frame_count`] `frames` of `size`
/// pixels; frame k shows every clip at t = k / `fps`) into a temporary file beside it, not yet
/// in place ([`stage_gif`](crate::stage_gif)); `tick()` is called as each frame is begun (a
/// progress bar).
pub fn stage_gif(
    scene: &Scene,
    path: &Path,
    size: (u32, u32),
    frames: usize,
    fps: u32,
    tick: impl Fn(),
) -> Result<AtomicFile, DrawError> {
    // The GIF is seen at its size: text 1/24 of its height, lines 1/200.
    let style = Style::for_height(size.1, 24, 200);
    let fps = f64::from(fps);
    let delay_ms = (1000.0 / fps).round() as u32;
    crate::stage_gif(path, size, frames, delay_ms, |k, root| {
        tick();
        draw_scene(root, scene, style, &[k as f64 / fps])
    })
}

/// Draws the film strip of `scene` for `path` (SVG or PNG by its extension; snapshots at
/// `times`, side by side in `size` pixels) into a temporary file beside it, not yet in place
/// ([`stage`](crate::stage)).
pub fn stage_strip(
    scene: &Scene,
    path: &Path,
    size: (u32, u32),
    times: &[f64],
) -> Result<AtomicFile, DrawError> {
    // The strip is usually shown shrunk to a page's width: larger text and lines.
    let strip = Strip {
        scene,
        style: Style::for_height(size.1, 13, 120),
        times,
    };
    crate::stage(&strip, path, size)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_add_folders_only_to_tell_clips_apart() {
        let p = |s: &str| PathBuf::from(s);
        assert_eq!(
            labels(&[p("a/p01/r01.bvh"), p("a/p01/r02.bvh")]),
            ["r01", "r02"]
        );
        assert_eq!(
            labels(&[p("a/p01/r01.bvh"), p("a/p02/r01.bvh")]),
            ["p01/r01", "p02/r01"]
        );
    }
}
