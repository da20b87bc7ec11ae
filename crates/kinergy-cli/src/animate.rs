//! `kinergy animate`: clips as superposed stick figures, synchronized by time (the paper's
//! Fig. 6: captured vs S_A vs S_C) — an animated GIF and a film strip of snapshots — with,
//! optionally, the scene a `plan` output moves in and the objects it carries (Kallmann's
//! Fig. 5). The command checks its options and outputs, reads the clips and the scene, and
//! reports; the pictures are [`kinergy_draw::animation`]'s.

use std::path::{Path, PathBuf};

use clap::builder::PossibleValue;
use kinergy_draw::animation::{self, Scene, Track, View, gif_frame_count, read_props, strip_times};
use serde::Serialize;

use crate::common::limits;
use crate::common::{Failure, ReadArgs, check_range, collect_clips, emit, parse_size, print_json};

/// The most clips one picture holds: one palette colour each.
const MAX_CLIPS: usize = 8;
/// The widest film strip, pixels (its bitmap is held in memory).
const MAX_STRIP_WIDTH: u64 = 32_768;

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
    #[arg(long, default_value = "front", value_parser = crate::common::named::<View>(View::ALL.map(|v| PossibleValue::new(v.name()).help(v.description()))))]
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

/// The two pictures' files and sizes, pixels.
struct Pictures {
    strip: PathBuf,
    size: (u32, u32),
    strip_size: (u32, u32),
}

/// Checks the pictures' options before any work: the GIF's and the strip's names, the rate,
/// the snapshots and the sizes.
fn check_pictures(args: &Args) -> Result<Pictures, Failure> {
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
    crate::common::picture_format(&strip, "--strip")?;
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
    Ok(Pictures {
        strip,
        size,
        strip_size,
    })
}

/// Reads the clips at `paths` as tracks; with their report rows and the longest duration.
fn read_tracks(args: &Args, paths: &[PathBuf]) -> Result<(Vec<Track>, Vec<ClipRow>, f64), Failure> {
    let mut tracks = Vec::with_capacity(paths.len());
    let mut rows = Vec::with_capacity(paths.len());
    let mut duration = 0.0_f64;
    for (path, label) in paths.iter().zip(animation::labels(paths)) {
        let (clip, _) = args.read.read(path)?;
        duration = duration.max(clip.duration());
        let track = Track::new(&clip, path, label.clone())?;
        let drawn = track.drawn(clip.skeleton());
        rows.push(ClipRow {
            path: path.display().to_string(),
            label,
            frames: clip.frame_count(),
            duration_s: clip.duration(),
            body_bones: drawn.body_bones,
            finger_bones: drawn.finger_bones,
            not_drawn: drawn.not_drawn,
        });
        tracks.push(track);
    }
    Ok((tracks, rows, duration))
}

/// Draws the GIF (`frames` of them) and the strip (at `times`) of `scene`, both finished under
/// temporary names first, so that a failure leaves neither behind.
fn draw(
    args: &Args,
    scene: &Scene,
    pictures: &Pictures,
    frames: usize,
    times: &[f64],
) -> Result<(), Failure> {
    // A bar on the terminal only (indicatif hides it when stderr is not one).
    let bar = crate::common::Bar::counting(frames as u64, "frames");
    let staged = animation::stage_gif(scene, &args.output, pictures.size, frames, args.fps, || {
        bar.inc()
    });
    bar.finish();
    let gif = staged?;
    let strip = animation::stage_strip(scene, &pictures.strip, pictures.strip_size, times)?;
    kinergy_draw::commit(strip)?;
    kinergy_draw::commit(gif)?;
    Ok(())
}

/// Runs `kinergy animate`.
pub fn run(args: &Args) -> Result<(), Failure> {
    let pictures = check_pictures(args)?;
    let paths = collect_clips(&args.clips)?;
    if paths.len() > MAX_CLIPS {
        return Err(Failure::Input(format!(
            "{} clips given: at most {MAX_CLIPS} can be drawn together",
            paths.len()
        )));
    }
    // Read before the output check (reading writes nothing): its meshes are inputs too. A
    // scene that cannot be read is reported after the outputs are checked.
    let scene = args
        .scene
        .as_deref()
        .map(|path| read_props(path, args.report.as_deref(), args.read.max_input_mb));
    {
        use crate::common::{Output, check_outputs};
        let mut inputs: Vec<&Path> = args.clips.iter().map(PathBuf::as_path).collect();
        inputs.extend(paths.iter().map(PathBuf::as_path));
        inputs.extend(args.scene.as_deref());
        let meshes = scene.iter().flatten().flat_map(|s| &s.meshes);
        inputs.extend(meshes.map(PathBuf::as_path));
        inputs.extend(args.report.as_deref());
        check_outputs(
            &inputs,
            &[
                Output::File("-o", &args.output),
                Output::File("--strip", &pictures.strip),
            ],
        )?;
    }
    let (tracks, rows, duration) = read_tracks(args, &paths)?;
    let props = scene.transpose()?.map(|s| s.props).unwrap_or_default();
    let scene = Scene::new(tracks, props, args.view);

    let (size, frames) = (pictures.size, gif_frame_count(duration, args.fps));
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
    let times = strip_times(duration, args.strip_frames);
    draw(args, &scene, &pictures, frames, &times)?;

    let report = Report {
        output: args.output.display().to_string(),
        strip: pictures.strip.display().to_string(),
        clips: rows,
        frames,
        fps: args.fps,
        duration_s: duration,
        view: args.view,
        size: [size.0, size.1],
        strip_size: [pictures.strip_size.0, pictures.strip_size.1],
        strip_times_s: times,
        scene: args.scene.as_ref().map(|p| p.display().to_string()),
        moving_objects: scene.moving_objects(),
    };
    if args.json {
        return print_json(&report);
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_are_parsed_and_bounded() {
        assert_eq!(parse_size("640x480").ok(), Some((640, 480)));
        assert_eq!(parse_size("160X120").ok(), Some((160, 120)));
        for bad in ["640", "0x480", "640x-1", "9999x480", "axb"] {
            assert!(parse_size(bad).is_err(), "{bad}");
        }
    }
}
