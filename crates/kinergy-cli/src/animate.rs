//! `kinergy animate`: clips as superposed stick figures, synchronized by time (the paper's
//! Fig. 6: captured vs S_A vs S_C) — an animated GIF and a film strip of snapshots.

use std::error::Error;
use std::path::{Path, PathBuf};

use kinergy_motion::Clip;
use nalgebra::Point3;
use plotters::coord::Shift;
use plotters::prelude::*;
use serde::Serialize;

use crate::common::limits;
use crate::common::{Failure, ReadArgs, check_range, collect_clips, emit, parse_size, print_json};
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
    /// extension; default: the GIF's path with .png. Always written.
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
}

/// One clip's stick figure over time, projected on the screen.
struct Track {
    label: String,
    frame_time: f64,
    joints: usize,
    /// Screen positions (meters), frame after frame, `joints` per frame.
    points: Vec<(f64, f64)>,
    /// (parent, child) joint pairs: every bone, End Sites included.
    bones: Vec<(usize, usize)>,
    /// The joints drawn as dots (not End Sites).
    dots: Vec<usize>,
}

impl Track {
    fn new(clip: &Clip, path: &Path, label: String, view: View) -> Result<Track, Failure> {
        let skeleton = clip.skeleton();
        let joints = skeleton.joint_count();
        let mut points = Vec::with_capacity(joints * clip.frame_count());
        for pose in clip.frames() {
            let world = skeleton
                .world_positions(pose)
                .map_err(|e| Failure::input(path, e))?;
            points.extend(world.iter().map(|p| view.project(p)));
        }
        if clip.frame_count() == 0 || joints == 0 {
            return Err(Failure::input(path, "the clip has no frames to draw"));
        }
        let bones = skeleton
            .joints()
            .iter()
            .enumerate()
            .filter_map(|(j, joint)| joint.parent.map(|p| (p, j)))
            .collect();
        let dots = skeleton
            .joints()
            .iter()
            .enumerate()
            .filter(|(_, joint)| !joint.end_site)
            .map(|(j, _)| j)
            .collect();
        Ok(Track {
            label,
            frame_time: clip.frame_time(),
            joints,
            points,
            bones,
            dots,
        })
    }

    /// The pose at time `t`, seconds: the nearest frame, the last one after the end.
    fn at(&self, t: f64) -> &[(f64, f64)] {
        let i = nearest_frame(t, self.frame_time, self.points.len() / self.joints);
        &self.points[i * self.joints..(i + 1) * self.joints]
    }
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
        let x = self.pixel_centre.0 + (u - self.centre.0) * self.scale;
        let y = self.pixel_centre.1 - (v - self.centre.1) * self.scale;
        (x.is_finite() && y.is_finite()).then(|| (x.round() as i32, y.round() as i32))
    }
}

/// Everything a picture needs: the clips' tracks, their common box, the text size.
struct Scene {
    tracks: Vec<Track>,
    bounds: Bounds,
    view: View,
    font_px: i32,
    line_px: u32,
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
) -> Result<Legend, Box<dyn Error>>
where
    DB::ErrorType: 'static,
{
    let width = i32::try_from(root.dim_in_pixel().0)?;
    let fs = scene.font_px;
    let row = fs + fs / 2;
    let style = text_style(fs, BLACK);
    let (mut x, mut y) = (8, 4);
    let mut spots = Vec::with_capacity(scene.tracks.len());
    for track in &scene.tracks {
        let (tw, _) = root.estimate_text_size(&track.label, &style)?;
        let entry = SWATCH + 5 + i32::try_from(tw)?;
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
    times: &[f64],
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE)?;
    let legend = layout_legend(root, scene)?;
    let (top, rest) = root.split_vertically(legend.height);
    let fs = scene.font_px;
    for (i, (track, &(x, y))) in scene.tracks.iter().zip(&legend.spots).enumerate() {
        let c = draw::colour(i);
        let mid = y + fs / 2 + 1;
        top.draw(&PathElement::new(
            vec![(x, mid), (x + SWATCH, mid)],
            c.stroke_width(3),
        ))?;
        top.draw(&Text::new(
            track.label.as_str(),
            (x + SWATCH + 5, y),
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
        draw_panel(panel, scene, t)?;
    }
    Ok(())
}

/// Draws every clip's stick figure at time `t` with the time in the bottom-left corner.
fn draw_panel<DB: DrawingBackend>(
    panel: &DrawingArea<DB, Shift>,
    scene: &Scene,
    t: f64,
) -> DrawResult
where
    DB::ErrorType: 'static,
{
    let (w, h) = panel.dim_in_pixel();
    let (w, h) = (i32::try_from(w)?, i32::try_from(h)?);
    let fs = scene.font_px;
    let label_band = fs + 8;
    let map = Mapping::fit(&scene.bounds, (4, 2, w - 4, h - label_band));
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
    let line = scene.line_px;
    let dot = line as i32 + 1;
    for (i, track) in scene.tracks.iter().enumerate() {
        let c = draw::colour(i);
        let pixels: Vec<Option<(i32, i32)>> = track.at(t).iter().map(|&p| map.pixel(p)).collect();
        for &(p, j) in &track.bones {
            if let (Some(a), Some(b)) = (pixels[p], pixels[j]) {
                panel.draw(&PathElement::new(vec![a, b], c.stroke_width(line)))?;
            }
        }
        for &j in &track.dots {
            if let Some(p) = pixels[j] {
                panel.draw(&Circle::new(p, dot, c.filled()))?;
            }
        }
    }
    panel.draw(&Text::new(
        format!("t = {t:.2} s"),
        (6, h - label_band + 3),
        text_style(fs, BLACK),
    ))?;
    Ok(())
}

/// The film strip: snapshots side by side under one legend.
struct Strip<'a> {
    scene: &'a Scene,
    times: &'a [f64],
}

impl Figure for Strip<'_> {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> DrawResult
    where
        DB::ErrorType: 'static,
    {
        draw_scene(root, self.scene, self.times)
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
        rows.push(ClipRow {
            path: path.display().to_string(),
            label: label.clone(),
            frames: clip.frame_count(),
            duration_s: clip.duration(),
        });
        tracks.push(Track::new(&clip, path, label, args.view)?);
    }
    let bounds = Bounds::around(tracks.iter().flat_map(|t| t.points.iter().copied()));
    let scene = Scene {
        tracks,
        bounds,
        view: args.view,
        font_px: (i32::try_from(size.1).unwrap_or(i32::MAX) / 30).clamp(10, 32),
        line_px: (size.1 / 240).max(1),
    };

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
        draw_scene(root, &scene, &[k as f64 / fps])
    });
    bar.finish();
    let gif = staged?;
    let strip_file = draw::stage(
        &Strip {
            scene: &scene,
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
