//! `kinergy animate`: clips as superposed stick figures, synchronized by time (the paper's
//! Fig. 6: captured vs S_A vs S_C) — an animated GIF and a film strip of snapshots — with,
//! optionally, the scene a `plan` output moves in and the objects it carries (Kallmann's
//! Fig. 5).
//!
//! What is drawn of a skeleton is decided by [`draw::bones`]: body bones full width, finger
//! bones thin, face joints, a reference root and zero-length bones not at all. The view is
//! fitted to the drawn joints over all frames (and to carried objects), with a margin; the
//! scene is drawn clipped to it.

use std::error::Error;
use std::path::{Path, PathBuf};

use kinergy_motion::Clip;
use nalgebra::{Isometry3, Point3, Quaternion, Translation3, UnitQuaternion};
use plotters::coord::Shift;
use plotters::prelude::*;
use serde::{Deserialize, Serialize};

use crate::common::limits;
use crate::common::{Failure, ReadArgs, check_range, collect_clips, emit, parse_size, print_json};
use crate::draw::bones::{BoneKind, Role, StickFigure};
use crate::draw::shapes::{Flat, Solid, clip_line, clip_polygon};
use crate::draw::{self, DrawResult, FONT, Figure, Format};

/// The most clips one picture holds: one palette colour each.
const MAX_CLIPS: usize = 8;
/// The widest film strip, pixels (its bitmap is held in memory).
const MAX_STRIP_WIDTH: u64 = 32_768;
/// The margin around the figures' common bounding box, as a part of its larger side.
const MARGIN: f64 = 0.06;
/// The length of a legend entry's colour line, pixels.
const SWATCH: i32 = 18;

/// Where the camera looks from. The character faces +Z, Y up, its left at +X.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum View {
    /// From in front, the camera on +Z looking back: screen right = world +X (the character's
    /// left), so its right arm is on the screen's left, as when you face someone; screen up = +Y.
    Front,
    /// From the character's right, the camera on −X: screen right = +Z (the character faces
    /// right), screen up = +Y.
    Side,
    /// From above: screen right = +X as in the front view, screen down = +Z (the character
    /// faces the bottom of the picture).
    Top,
}

impl View {
    /// Screen coordinates (right, up) of a world point, meters.
    fn project(self, p: &Point3<f64>) -> (f64, f64) {
        match self {
            View::Front => (p.x, p.y),
            View::Side => (p.z, p.y),
            View::Top => (p.x, -p.z),
        }
    }

    fn name(self) -> &'static str {
        match self {
            View::Front => "front",
            View::Side => "side",
            View::Top => "top",
        }
    }
}

/// Arguments of `kinergy animate`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// BVH clips, or folders searched for them (sorted): 1 to 8 clips, drawn in this order, one
    /// colour each, labelled by file name.
    #[arg(value_name = "CLIPS", required = true)]
    pub clips: Vec<PathBuf>,
    /// Where to write the animation: an animated GIF (written atomically).
    #[arg(short, long, value_name = "OUT.gif")]
    pub output: PathBuf,
    /// Where the camera looks from (the character faces +Z, Y up, its left at +X).
    #[arg(long, value_enum, default_value = "front")]
    pub view: View,
    /// GIF frames per second, 1 to 100. Frame k shows every clip at t = k / fps (its nearest
    /// frame; a shorter clip holds its last pose), up to the end of the longest clip. GIF
    /// delays are whole hundredths of a second, and browsers slow down delays under 20 ms.
    #[arg(long, default_value_t = 25, value_name = "N")]
    pub fps: u32,
    /// The film strip: snapshots side by side in one row under one legend, PNG or SVG by the
    /// extension; default: the GIF's path with .png. Always written. Its text and lines are
    /// larger than the GIF's (made to be read when the strip is shown page-wide).
    #[arg(long, value_name = "FILE.png")]
    pub strip: Option<PathBuf>,
    /// Snapshots in the film strip, 1 to 24, evenly spaced in time from 0 to the end of the
    /// longest clip.
    #[arg(long, default_value_t = 6, value_name = "N")]
    pub strip_frames: usize,
    /// The GIF's size in pixels (each side 64 to 3840, and at most 400 million pixels in all
    /// its frames); the strip is N times as wide (at most 32768 pixels wide and 100 million
    /// pixels), as high.
    #[arg(long, default_value = "640x480", value_name = "WxH")]
    pub size: String,
    /// A scene (the JSON file `kinergy plan --scene` reads) drawn behind the figures: boxes,
    /// spheres and capsules as filled outlines, meshes as filled triangles with their edges.
    #[arg(long, value_name = "S.json")]
    pub scene: Option<PathBuf>,
    /// The JSON report of the `kinergy plan ... --json` that made the clip: the objects it
    /// moves are drawn where they are on every frame (with the first clip's timing).
    #[arg(long, value_name = "REPORT.json", requires = "scene")]
    pub report: Option<PathBuf>,
    /// Print the report as JSON.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub read: ReadArgs,
}

#[derive(Serialize)]
struct ClipRow {
    path: String,
    label: String,
    frames: usize,
    duration_s: f64,
    /// Body bones drawn on the first frame.
    body_bones: usize,
    /// Finger bones (drawn thin) on the first frame.
    finger_bones: usize,
    /// Joints not drawn: a reference root and face joints.
    not_drawn: Vec<String>,
}

#[derive(Serialize)]
struct Report {
    output: String,
    strip: String,
    clips: Vec<ClipRow>,
    frames: usize,
    fps: u32,
    duration_s: f64,
    view: View,
    size: [u32; 2],
    strip_size: [u32; 2],
    strip_times_s: Vec<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    scene: Option<String>,
    /// Objects drawn moving, from `--report`.
    moving_objects: Vec<String>,
}

/// One clip's stick figure over time.
struct Track {
    label: String,
    frame_time: f64,
    joints: usize,
    /// World positions (meters), frame after frame, `joints` per frame.
    world: Vec<Point3<f64>>,
    /// What is drawn of the skeleton.
    figure: StickFigure,
}

impl Track {
    fn new(clip: &Clip, path: &Path, label: String) -> Result<Track, Failure> {
        let joints = clip.skeleton().joint_count();
        if clip.frame_count() == 0 || joints == 0 {
            return Err(Failure::input(path, "the clip has no frames to draw"));
        }
        let (figure, world) = StickFigure::of(clip).map_err(|e| Failure::input(path, e))?;
        Ok(Track {
            label,
            frame_time: clip.frame_time(),
            joints,
            world,
            figure,
        })
    }

    /// The pose at time `t`, seconds: the nearest frame, the last one after the end.
    fn at(&self, t: f64) -> &[Point3<f64>] {
        let i = nearest_frame(t, self.frame_time, self.world.len() / self.joints);
        &self.world[i * self.joints..(i + 1) * self.joints]
    }

    /// The drawn joints' positions over all frames (what the view is fitted to).
    fn drawn_points(&self) -> impl Iterator<Item = &Point3<f64>> + '_ {
        let roles = self.figure.roles();
        self.world
            .iter()
            .enumerate()
            .filter(move |(i, _)| matches!(roles[i % self.joints], Role::Body | Role::Finger))
            .map(|(_, p)| p)
    }
}

/// Where a scene object is: fixed, or on every frame of a plan.
enum Placement {
    Fixed(Isometry3<f64>),
    Moving {
        frame_time: f64,
        poses: Vec<Isometry3<f64>>,
    },
}

/// One scene object ready to draw.
struct Prop {
    name: String,
    solid: Solid,
    placement: Placement,
}

impl Prop {
    fn pose(&self, t: f64) -> &Isometry3<f64> {
        match &self.placement {
            Placement::Fixed(p) => p,
            Placement::Moving { frame_time, poses } => {
                &poses[nearest_frame(t, *frame_time, poses.len())]
            }
        }
    }

    fn moving(&self) -> bool {
        matches!(self.placement, Placement::Moving { .. })
    }

    /// A moving object's outline points over all its frames (the view is fitted to them).
    fn moving_points(&self, view: View) -> Vec<(f64, f64)> {
        match &self.placement {
            Placement::Fixed(_) => Vec::new(),
            Placement::Moving { poses, .. } => poses
                .iter()
                .flat_map(|pose| {
                    let outline = self.solid.outline(pose, |p| view.project(p));
                    outline.fills.into_iter().flatten()
                })
                .collect(),
        }
    }
}

/// What `animate` reads of a `kinergy plan --json` report.
#[derive(Deserialize)]
struct PlanReport {
    frame_time_s: Option<f64>,
    #[serde(default)]
    objects: Vec<PlanObject>,
}

#[derive(Deserialize)]
struct PlanObject {
    name: String,
    poses: Option<Vec<PlanPose>>,
}

#[derive(Deserialize)]
struct PlanPose {
    position_m: [f64; 3],
    rotation_xyzw: [f64; 4],
}

/// The most poses an object's track may hold (a plan of an hour at 1000 Hz is fewer).
const MAX_OBJECT_POSES: usize = 4_000_000;

/// Reads the scene `path` and, with `report`, the poses of the objects a plan moved.
fn read_props(path: &Path, report: Option<&Path>, max_input_mb: u64) -> Result<Vec<Prop>, Failure> {
    let plan_scene = kinergy_plan::scene::Scene::read(path).map_err(|e| Failure::input(path, e))?;
    let mut props: Vec<Prop> = plan_scene
        .objects
        .iter()
        .map(|o| Prop {
            name: o.name.clone(),
            solid: Solid::new(&o.shape),
            placement: Placement::Fixed(o.pose),
        })
        .collect();
    let Some(report_path) = report else {
        return Ok(props);
    };
    let bad = |why: String| Failure::input(report_path, why);
    let text =
        kinergy_io::read_to_string_limited(report_path, max_input_mb.saturating_mul(1 << 20))
            .map_err(|e| Failure::input(report_path, e))?;
    let plan: PlanReport = serde_json::from_str(&text).map_err(|e| {
        bad(format!(
            "not a `kinergy plan --json` report: {}",
            kinergy_io::clip_text(&e.to_string(), 120)
        ))
    })?;
    let frame_time = plan.frame_time_s.ok_or_else(|| {
        bad("the report has no frame_time_s: it was written by an older kinergy; run `kinergy plan ... --json` again".into())
    })?;
    if !(frame_time.is_finite() && frame_time > 0.0) {
        return Err(bad(format!(
            "frame_time_s {frame_time}: expected a number > 0"
        )));
    }
    for object in plan.objects {
        let shown = kinergy_io::clip_text(&object.name, 120);
        let Some(prop) = props.iter_mut().find(|p| p.name == object.name) else {
            return Err(bad(format!(
                "object `{shown}` is not in the scene {}",
                path.display()
            )));
        };
        let poses = object.poses.ok_or_else(|| {
            bad(format!("object `{shown}` has no per-frame poses: the report was written by an older kinergy; run `kinergy plan ... --json` again"))
        })?;
        if poses.is_empty() || poses.len() > MAX_OBJECT_POSES {
            return Err(bad(format!(
                "object `{shown}`: {} poses, expected 1 to {MAX_OBJECT_POSES}",
                poses.len()
            )));
        }
        let poses = poses
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let [x, y, z] = p.position_m;
                let [qx, qy, qz, qw] = p.rotation_xyzw;
                let q = Quaternion::new(qw, qx, qy, qz);
                let finite = p
                    .position_m
                    .iter()
                    .chain(&p.rotation_xyzw)
                    .all(|v| v.is_finite());
                if !finite || q.norm() < 1e-9 {
                    return Err(bad(format!(
                        "object `{shown}` pose {k}: expected finite numbers and a non-zero rotation"
                    )));
                }
                Ok(Isometry3::from_parts(
                    Translation3::new(x, y, z),
                    UnitQuaternion::from_quaternion(q),
                ))
            })
            .collect::<Result<Vec<_>, Failure>>()?;
        prop.placement = Placement::Moving { frame_time, poses };
    }
    Ok(props)
}

/// The frame nearest to `t` seconds in a clip of `count` frames, clamped to the clip.
fn nearest_frame(t: f64, frame_time: f64, count: usize) -> usize {
    let i = (t / frame_time).round();
    if i > 0.0 {
        // `as` saturates: a time past the end clamps to the last frame.
        (i as usize).min(count.saturating_sub(1))
    } else {
        0
    }
}

/// GIF frames for `duration` seconds at `fps`: floor(duration · fps) + 1, the last instant
/// included even when rounding puts it a hair short.
fn gif_frame_count(duration: f64, fps: u32) -> usize {
    let ticks = duration * f64::from(fps) + 1e-9;
    if ticks.is_finite() && ticks > 0.0 {
        ticks.floor() as usize + 1
    } else {
        1
    }
}

/// `n` instants evenly spaced from 0 to `duration`, both included (0 alone when `n` is 1).
fn strip_times(duration: f64, n: usize) -> Vec<f64> {
    if n <= 1 {
        return vec![0.0];
    }
    (0..n)
        .map(|j| duration * j as f64 / (n - 1) as f64)
        .collect()
}

/// A screen-space box in meters: (left, right, bottom, top).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Bounds {
    u0: f64,
    u1: f64,
    v0: f64,
    v1: f64,
}

impl Bounds {
    /// The box around every finite point, grown by [`MARGIN`] of its larger side all round.
    fn around(points: impl Iterator<Item = (f64, f64)>) -> Bounds {
        let (mut u0, mut u1, mut v0, mut v1) = (
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
        );
        for (u, v) in points.filter(|(u, v)| u.is_finite() && v.is_finite()) {
            u0 = u0.min(u);
            u1 = u1.max(u);
            v0 = v0.min(v);
            v1 = v1.max(v);
        }
        if !u0.is_finite() {
            return Bounds {
                u0: -1.0,
                u1: 1.0,
                v0: -1.0,
                v1: 1.0,
            };
        }
        let pad = MARGIN * (u1 - u0).max(v1 - v0).max(0.05);
        Bounds {
            u0: u0 - pad,
            u1: u1 + pad,
            v0: v0 - pad,
            v1: v1 + pad,
        }
    }
}

/// Meters → pixels with one scale for both axes, the box centred in a pixel rectangle.
struct Mapping {
    scale: f64,
    centre: (f64, f64),
    pixel_centre: (f64, f64),
}

impl Mapping {
    /// Fits `b` into the rectangle `(x0, y0)–(x1, y1)`, pixels, keeping the aspect ratio.
    fn fit(b: &Bounds, (x0, y0, x1, y1): (i32, i32, i32, i32)) -> Mapping {
        let (w, h) = (f64::from(x1 - x0).max(1.0), f64::from(y1 - y0).max(1.0));
        Mapping {
            scale: (w / (b.u1 - b.u0)).min(h / (b.v1 - b.v0)),
            centre: ((b.u0 + b.u1) / 2.0, (b.v0 + b.v1) / 2.0),
            pixel_centre: (f64::from(x0 + x1) / 2.0, f64::from(y0 + y1) / 2.0),
        }
    }

    /// The pixel of a screen point (y grows downward), or `None` if it is not finite.
    fn pixel(&self, (u, v): (f64, f64)) -> Option<(i32, i32)> {
        let (x, y) = self.pixel_f((u, v));
        (x.is_finite() && y.is_finite()).then(|| (x.round() as i32, y.round() as i32))
    }

    /// The pixel of a screen point, unrounded (y grows downward).
    fn pixel_f(&self, (u, v): (f64, f64)) -> (f64, f64) {
        (
            self.pixel_centre.0 + (u - self.centre.0) * self.scale,
            self.pixel_centre.1 - (v - self.centre.1) * self.scale,
        )
    }
}

/// Everything a picture needs: the clips' tracks, the scene's objects, their common box.
struct Scene {
    tracks: Vec<Track>,
    props: Vec<Prop>,
    bounds: Bounds,
    view: View,
}

/// Text and line sizes of one picture, pixels.
#[derive(Debug, Clone, Copy)]
struct Style {
    font_px: i32,
    line_px: u32,
}

impl Style {
    /// Sizes for panels `height` pixels high: text 1/`per_text` of it, lines 1/`per_line`.
    fn for_height(height: u32, per_text: u32, per_line: u32) -> Style {
        Style {
            font_px: i32::try_from(height / per_text)
                .unwrap_or(i32::MAX)
                .clamp(10, 64),
            line_px: (height / per_line).clamp(1, 8),
        }
    }
}

fn text_style(px: i32, colour: RGBColor) -> TextStyle<'static> {
    (FONT, f64::from(px)).into_font().color(&colour)
}

/// The legend's layout: entries in rows across the picture's width.
struct Legend {
    /// Each entry's top-left corner, pixels.
    spots: Vec<(i32, i32)>,
    /// The band's height, pixels.
    height: u32,
}

/// Lays the legend out in rows across `root`'s width.
fn layout_legend<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    scene: &Scene,
    style: Style,
) -> Result<Legend, Box<dyn Error>>
where
    DB::ErrorType: 'static,
{
    let width = i32::try_from(root.dim_in_pixel().0)?;
    let fs = style.font_px;
    let row = fs + fs / 2;
    let text = text_style(fs, BLACK);
    let swatch = SWATCH * fs / 16;
    let (mut x, mut y) = (8, 4);
    let mut spots = Vec::with_capacity(scene.tracks.len());
    for track in &scene.tracks {
        let (tw, _) = root.estimate_text_size(&track.label, &text)?;
        let entry = swatch + 5 + i32::try_from(tw)?;
        if x > 8 && x + entry > width - 8 {
            x = 8;
            y += row;
        }
        spots.push((x, y));
        x += entry + fs + 4;
    }
    Ok(Legend {
        spots,
        height: u32::try_from(y + row + 2)?,
    })
}

/// Draws the legend band and, below it, one panel per instant in `times`, side by side.
fn draw_scene<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    scene: &Scene,
    style: Style,
    times: &[f64],
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let legend = layout_legend(root, scene, style)?;
    let (top, rest) = root.split_vertically(legend.height);
    let fs = style.font_px;
    let swatch = SWATCH * fs / 16;
    for (i, (track, &(x, y))) in scene.tracks.iter().zip(&legend.spots).enumerate() {
        let c = draw::colour(i);
        let mid = y + fs / 2 + 1;
        top.draw(&PathElement::new(
            vec![(x, mid), (x + swatch, mid)],
            c.stroke_width((style.line_px + 2).max(3)),
        ))?;
        top.draw(&Text::new(
            track.label.as_str(),
            (x + swatch + 5, y),
            text_style(fs, c),
        ))?;
    }
    let (_, height) = rest.dim_in_pixel();
    let height = i32::try_from(height)?;
    for (j, (panel, &t)) in rest
        .split_evenly((1, times.len()))
        .iter()
        .zip(times)
        .enumerate()
    {
        if j > 0 {
            panel.draw(&PathElement::new(
                vec![(0, 0), (0, height)],
                RGBColor(200, 200, 200).stroke_width(1),
            ))?;
        }
        draw_panel(panel, scene, style, t)?;
    }
    Ok(())
}

/// Light fills and darker edges of the scene's fixed and moving objects.
const FIXED_FILL: RGBColor = RGBColor(228, 228, 228);
const FIXED_EDGE: RGBColor = RGBColor(150, 150, 150);
const MOVING_FILL: RGBColor = RGBColor(240, 200, 120);
const MOVING_EDGE: RGBColor = RGBColor(150, 95, 0);

/// Draws the scene's objects at time `t`: fixed ones first, moving ones over them, each
/// clipped to the panel's figure area `(x0, y0, x1, y1)`, pixels.
fn draw_props<DB: DrawingBackend>(
    panel: &DrawingArea<DB, Shift>,
    scene: &Scene,
    map: &Mapping,
    area: (f64, f64, f64, f64),
    t: f64,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let px = |p: Flat| map.pixel_f(p);
    let round = |p: Flat| (p.0.round() as i32, p.1.round() as i32);
    for moving in [false, true] {
        let (fill, edge) = if moving {
            (MOVING_FILL, MOVING_EDGE)
        } else {
            (FIXED_FILL, FIXED_EDGE)
        };
        for prop in scene.props.iter().filter(|p| p.moving() == moving) {
            let outline = prop.solid.outline(prop.pose(t), |p| scene.view.project(p));
            for polygon in &outline.fills {
                let pixels: Vec<Flat> = polygon.iter().map(|&p| px(p)).collect();
                let clipped = clip_polygon(&pixels, area);
                if clipped.len() >= 3 {
                    let points: Vec<(i32, i32)> = clipped.into_iter().map(round).collect();
                    panel.draw(&Polygon::new(points, fill.filled()))?;
                }
            }
            for line in &outline.lines {
                if let Some([a, b]) = clip_line([px(line[0]), px(line[1])], area) {
                    panel.draw(&PathElement::new(
                        vec![round(a), round(b)],
                        edge.stroke_width(1),
                    ))?;
                }
            }
        }
    }
    Ok(())
}

/// Draws the scene and every clip's stick figure at time `t` with the time in the
/// bottom-left corner.
fn draw_panel<DB: DrawingBackend>(
    panel: &DrawingArea<DB, Shift>,
    scene: &Scene,
    style: Style,
    t: f64,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let (w, h) = panel.dim_in_pixel();
    let (w, h) = (i32::try_from(w)?, i32::try_from(h)?);
    let fs = style.font_px;
    let label_band = fs + fs / 2;
    let figure_area = (4, 2, w - 4, h - label_band);
    let map = Mapping::fit(&scene.bounds, figure_area);
    let b = &scene.bounds;
    // The floor, where the box holds it.
    if scene.view != View::Top && b.v0 < 0.0 && 0.0 < b.v1 {
        let left = map.pixel((b.u0, 0.0));
        let right = map.pixel((b.u1, 0.0));
        if let (Some(l), Some(r)) = (left, right) {
            panel.draw(&PathElement::new(
                vec![l, r],
                RGBColor(190, 190, 190).stroke_width(1),
            ))?;
        }
    }
    if !scene.props.is_empty() {
        let area = (0.0, 0.0, f64::from(w - 1), f64::from(h - label_band));
        draw_props(panel, scene, &map, area, t)?;
    }
    let line = style.line_px;
    let dot = line as i32 + 1;
    for (i, track) in scene.tracks.iter().enumerate() {
        let c = draw::colour(i);
        let world = track.at(t);
        let pixels: Vec<Option<(i32, i32)>> = world
            .iter()
            .map(|p| map.pixel(scene.view.project(p)))
            .collect();
        for segment in track.figure.world_segments(world) {
            if let (Some(a), Some(b)) = (pixels[segment.parent], pixels[segment.child]) {
                let width = match segment.kind {
                    BoneKind::Body => line,
                    BoneKind::Finger => 1,
                };
                panel.draw(&PathElement::new(vec![a, b], c.stroke_width(width)))?;
            }
        }
        for &j in track.figure.dots() {
            if let Some(p) = pixels[j] {
                panel.draw(&Circle::new(p, dot, c.filled()))?;
            }
        }
    }
    panel.draw(&Text::new(
        format!("t = {t:.2} s"),
        (6, h - label_band + fs / 4),
        text_style(fs, BLACK),
    ))?;
    Ok(())
}

/// The film strip: snapshots side by side under one legend.
struct Strip<'a> {
    scene: &'a Scene,
    style: Style,
    times: &'a [f64],
}

impl Figure for Strip<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        draw_scene(root, self.scene, self.style, self.times)
    }
}

/// Labels for the clips: their file stems, with as many parent folders as it takes to tell
/// them apart (`p01/r01`, `p02/r01`).
fn labels(paths: &[PathBuf]) -> Vec<String> {
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

/// Runs `kinergy animate`.
pub fn run(args: &Args) -> Result<(), Failure> {
    let is_gif = args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("gif"));
    if !is_gif {
        return Err(Failure::Input(format!(
            "-o {}: the animation is written as GIF: the file name must end in .gif",
            args.output.display()
        )));
    }
    let strip = args
        .strip
        .clone()
        .unwrap_or_else(|| args.output.with_extension("png"));
    Format::of(&strip, "--strip")?;
    args.read.check()?;
    check_range("--fps", args.fps, limits::ANIMATE_FPS)?;
    check_range(
        "--strip-frames",
        args.strip_frames,
        limits::ANIMATE_STRIP_FRAMES,
    )?;
    let size = parse_size(&args.size)?;
    let strip_width = u64::from(size.0) * args.strip_frames as u64;
    if strip_width > MAX_STRIP_WIDTH {
        return Err(Failure::Input(format!(
            "--strip-frames {} × --size width {} = {strip_width} pixels: the strip may be at \
             most {MAX_STRIP_WIDTH} pixels wide",
            args.strip_frames, size.0
        )));
    }
    let strip_pixels = strip_width * u64::from(size.1);
    if strip_pixels > limits::MAX_STRIP_PIXELS {
        return Err(Failure::Input(format!(
            "--strip-frames {} × --size {}: the strip would have {strip_pixels} pixels, at \
             most {} are drawn; lower --size or --strip-frames",
            args.strip_frames,
            args.size,
            limits::MAX_STRIP_PIXELS
        )));
    }
    let strip_size = (u32::try_from(strip_width).unwrap_or(u32::MAX), size.1);

    let paths = collect_clips(&args.clips)?;
    if paths.len() > MAX_CLIPS {
        return Err(Failure::Input(format!(
            "{} clips given: at most {MAX_CLIPS} can be drawn together",
            paths.len()
        )));
    }
    {
        use crate::common::{Output, check_outputs};
        let mut inputs: Vec<&Path> = args.clips.iter().map(PathBuf::as_path).collect();
        inputs.extend(paths.iter().map(PathBuf::as_path));
        inputs.extend(args.scene.as_deref());
        inputs.extend(args.report.as_deref());
        check_outputs(
            &inputs,
            &[
                Output::File("-o", &args.output),
                Output::File("--strip", &strip),
            ],
        )?;
    }
    let names = labels(&paths);
    let mut tracks = Vec::with_capacity(paths.len());
    let mut rows = Vec::with_capacity(paths.len());
    let mut duration = 0.0_f64;
    for (path, label) in paths.iter().zip(names) {
        let (clip, _) = args.read.read(path)?;
        duration = duration.max(clip.duration());
        let track = Track::new(&clip, path, label.clone())?;
        let first = &track.world[..track.joints];
        let (mut body_bones, mut finger_bones) = (0, 0);
        for (_, _, kind) in track.figure.bones(first) {
            match kind {
                BoneKind::Body => body_bones += 1,
                BoneKind::Finger => finger_bones += 1,
            }
        }
        let skeleton = clip.skeleton();
        rows.push(ClipRow {
            path: path.display().to_string(),
            label,
            frames: clip.frame_count(),
            duration_s: clip.duration(),
            body_bones,
            finger_bones,
            not_drawn: track
                .figure
                .roles()
                .iter()
                .enumerate()
                .filter(|(_, r)| matches!(r, Role::Face | Role::Reference))
                .map(|(j, _)| skeleton.joint(j).name.clone())
                .collect(),
        });
        tracks.push(track);
    }
    let props = match &args.scene {
        Some(path) => read_props(path, args.report.as_deref(), args.read.max_input_mb)?,
        None => Vec::new(),
    };
    let moving_objects: Vec<String> = props
        .iter()
        .filter(|p| p.moving())
        .map(|p| p.name.clone())
        .collect();
    let view = args.view;
    let bounds = Bounds::around(
        tracks
            .iter()
            .flat_map(|t| t.drawn_points().map(|p| view.project(p)))
            .chain(props.iter().flat_map(|p| p.moving_points(view))),
    );
    let scene = Scene {
        tracks,
        props,
        bounds,
        view,
    };
    // The GIF is seen at its size; the strip is usually shown shrunk to a page's width.
    let gif_style = Style::for_height(size.1, 24, 200);
    let strip_style = Style::for_height(size.1, 13, 120);

    let frames = gif_frame_count(duration, args.fps);
    let gif_pixels = u64::from(size.0)
        .saturating_mul(u64::from(size.1))
        .saturating_mul(frames as u64);
    if gif_pixels > limits::MAX_GIF_PIXELS {
        return Err(Failure::Input(format!(
            "--size {} × {frames} frames (--fps {} over {duration:.2} s): {gif_pixels} pixels \
             to draw, at most {} are; lower --size or --fps",
            args.size,
            args.fps,
            limits::MAX_GIF_PIXELS
        )));
    }
    let fps = f64::from(args.fps);
    let delay_ms = (1000.0 / fps).round() as u32;
    let times = strip_times(duration, args.strip_frames);

    // Both pictures are finished under temporary names first, so that a failure leaves
    // neither behind.
    // A bar on the terminal only (indicatif hides it when stderr is not one).
    let bar = crate::common::Bar::counting(frames as u64, "frames");
    let staged = draw::stage_gif(&args.output, size, frames, delay_ms, |k, root| {
        bar.inc();
        draw_scene(root, &scene, gif_style, &[k as f64 / fps])
    });
    bar.finish();
    let gif = staged?;
    let strip_file = draw::stage(
        &Strip {
            scene: &scene,
            style: strip_style,
            times: &times,
        },
        &strip,
        strip_size,
    )?;
    draw::commit(strip_file)?;
    draw::commit(gif)?;

    let report = Report {
        output: args.output.display().to_string(),
        strip: strip.display().to_string(),
        clips: rows,
        frames,
        fps: args.fps,
        duration_s: duration,
        view: args.view,
        size: [size.0, size.1],
        strip_size: [strip_size.0, strip_size.1],
        strip_times_s: times,
        scene: args.scene.as_ref().map(|p| p.display().to_string()),
        moving_objects,
    };
    if args.json {
        print_json(&report)
    } else {
        let plural = |n: usize| if n == 1 { "" } else { "s" };
        let clips = report.clips.len();
        emit(&format!(
            "{}: {clips} clip{}, {frames} frame{} at {} fps ({duration:.2} s), {} view; strip {} \
             ({} snapshot{})\n",
            report.output,
            plural(clips),
            plural(frames),
            args.fps,
            args.view.name(),
            report.strip,
            args.strip_frames,
            plural(args.strip_frames),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn views_put_the_characters_left_and_front_where_the_help_says() {
        let left = Point3::new(1.0, 0.0, 0.0);
        let front = Point3::new(0.0, 0.0, 1.0);
        let up = Point3::new(0.0, 1.0, 0.0);
        assert_eq!(View::Front.project(&left), (1.0, 0.0));
        assert_eq!(View::Front.project(&up), (0.0, 1.0));
        assert_eq!(View::Side.project(&front), (1.0, 0.0));
        assert_eq!(View::Side.project(&up), (0.0, 1.0));
        assert_eq!(View::Top.project(&left), (1.0, 0.0));
        assert_eq!(View::Top.project(&front), (0.0, -1.0));
    }

    #[test]
    fn frame_count_includes_the_last_instant_despite_rounding() {
        // 108 frames at 60 Hz: 1.7999999999999998 s.
        assert_eq!(gif_frame_count(108.0 * (1.0 / 60.0), 10), 19);
        assert_eq!(gif_frame_count(1.27, 25), 32);
        assert_eq!(gif_frame_count(0.0, 25), 1);
    }

    #[test]
    fn poses_are_the_nearest_frame_held_after_the_end() {
        assert_eq!(nearest_frame(0.0, 0.1, 5), 0);
        assert_eq!(nearest_frame(0.26, 0.1, 5), 3);
        assert_eq!(nearest_frame(9.0, 0.1, 5), 4);
        assert_eq!(nearest_frame(f64::INFINITY, 0.1, 5), 4);
    }

    #[test]
    fn strip_times_span_the_whole_motion() {
        assert_eq!(strip_times(2.0, 5), vec![0.0, 0.5, 1.0, 1.5, 2.0]);
        assert_eq!(strip_times(2.0, 1), vec![0.0]);
    }

    #[test]
    fn mapping_keeps_the_aspect_ratio() {
        let b = Bounds {
            u0: 0.0,
            u1: 1.0,
            v0: 0.0,
            v1: 2.0,
        };
        let m = Mapping::fit(&b, (0, 0, 400, 200));
        assert_eq!(m.pixel((0.5, 1.0)), Some((200, 100)));
        assert_eq!(m.pixel((1.0, 2.0)), Some((250, 0)));
        assert_eq!(m.pixel((0.0, 0.0)), Some((150, 200)));
        assert_eq!(m.pixel((f64::NAN, 0.0)), None);
    }

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

    #[test]
    fn sizes_are_parsed_and_bounded() {
        assert_eq!(parse_size("640x480").ok(), Some((640, 480)));
        assert_eq!(parse_size("160X120").ok(), Some((160, 120)));
        for bad in ["640", "0x480", "640x-1", "9999x480", "axb"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }
}
