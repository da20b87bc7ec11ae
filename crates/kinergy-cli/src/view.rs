//! `kinergy view`: clips in a browser — one self-contained HTML page that opens offline, the
//! clips overlaid in 3-D with the hand-speed chart synced to the scrubber, a target and a
//! scene's objects where given. The command checks its options and outputs, reads the clips and
//! the scene, and reports; the page is [`kinergy_draw::viewer`]'s.

use std::path::{Path, PathBuf};

use kinergy_draw::animation;
use kinergy_draw::viewer::{self, Hand, ViewerClip, ViewerPage};
use serde::Serialize;

use crate::common::{Failure, ReadArgs, collect_clips, emit, parse_point, print_json};

/// Arguments of `kinergy view`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// BVH clips, or folders searched for them (sorted): 1 to 24 clips, overlaid in this
    /// order, one colour each, labelled by file name. Each plays at its own frame rate; all
    /// share one clock.
    #[arg(value_name = "CLIPS", required = true)]
    pub clips: Vec<PathBuf>,
    /// Where to write the page (HTML, written atomically; everything inlined: it opens offline).
    #[arg(short, long, value_name = "OUT.html")]
    pub output: PathBuf,
    /// The page's title (default: the clips' names).
    #[arg(long, value_name = "TEXT")]
    pub title: Option<String>,
    /// A target drawn as a ball, world meters `x,y,z` (Y up, the character facing +Z).
    #[arg(long, value_name = "x,y,z", allow_hyphen_values = true)]
    pub target: Option<String>,
    /// A scene (the JSON file `kinergy plan --scene` reads) drawn with the clips.
    #[arg(long, value_name = "S.json")]
    pub scene: Option<PathBuf>,
    /// Whose speed the chart shows: right, left, auto (the hand that travels farther in each
    /// clip) or none.
    #[arg(long, default_value = "auto", value_name = "right|left|auto|none")]
    pub hand: Hand,
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
    frame_rate_hz: f64,
    duration_s: f64,
    joints: usize,
}

#[derive(Serialize)]
struct Report {
    output: String,
    bytes: usize,
    clips: Vec<ClipRow>,
    #[serde(skip_serializing_if = "Option::is_none")]
    scene: Option<String>,
    objects: usize,
}

/// Runs `kinergy view`.
pub fn run(args: &Args) -> Result<(), Failure> {
    let is_html = args
        .output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("html") || e.eq_ignore_ascii_case("htm"));
    if !is_html {
        return Err(Failure::Input(format!(
            "-o {}: the page is HTML: the file name must end in .html",
            args.output.display()
        )));
    }
    args.read.check()?;
    let target = args
        .target
        .as_deref()
        .map(|t| parse_point(t, "--target"))
        .transpose()?;
    let paths = collect_clips(&args.clips)?;
    if paths.len() > viewer::MAX_CLIPS {
        return Err(Failure::Input(format!(
            "{} clips given: a page shows at most {}",
            paths.len(),
            viewer::MAX_CLIPS
        )));
    }
    // Read before the output check (reading writes nothing): its meshes are inputs too.
    let scene = args.scene.as_deref().map(viewer::read_scene);
    {
        use crate::common::{Output, check_outputs};
        let mut inputs: Vec<&Path> = args.clips.iter().map(PathBuf::as_path).collect();
        inputs.extend(paths.iter().map(PathBuf::as_path));
        inputs.extend(args.scene.as_deref());
        let meshes = scene.iter().flatten().flat_map(|s| &s.1);
        inputs.extend(meshes.map(PathBuf::as_path));
        check_outputs(&inputs, &[Output::File("-o", &args.output)])?;
    }
    let objects = scene.transpose()?.map(|s| s.0).unwrap_or_default();
    // Every clip is read and checked before anything is written.
    let mut clips = Vec::with_capacity(paths.len());
    let mut rows = Vec::with_capacity(paths.len());
    let labels = animation::labels(&paths);
    for (path, label) in paths.iter().zip(&labels) {
        let (clip, _) = args.read.read(path)?;
        let shown = ViewerClip::of_clip(&clip, path, label.clone(), args.hand)?;
        rows.push(ClipRow {
            path: path.display().to_string(),
            label: label.clone(),
            frames: clip.frame_count(),
            frame_rate_hz: 1.0 / clip.frame_time(),
            duration_s: clip.duration(),
            joints: clip.skeleton().joint_count(),
        });
        clips.push(shown);
    }
    let page = ViewerPage {
        title: args.title.clone().unwrap_or_else(|| labels.join(", ")),
        clips,
        target,
        objects,
        figures: Vec::new(),
    };
    let html = viewer::page_html(&page)?;
    kinergy_io::write_atomic(&args.output, html.as_bytes())
        .map_err(|e| Failure::task(&args.output, e))?;
    let report = Report {
        output: args.output.display().to_string(),
        bytes: html.len(),
        clips: rows,
        scene: args.scene.as_ref().map(|p| p.display().to_string()),
        objects: page.objects.len(),
    };
    if args.json {
        return print_json(&report);
    }
    let mut text = format!(
        "{}: {} clip{} ({:.1} MB), open it in a browser\n",
        report.output,
        report.clips.len(),
        if report.clips.len() == 1 { "" } else { "s" },
        report.bytes as f64 / 1e6
    );
    for c in &report.clips {
        text += &format!(
            "  {:<24} {:>6} frames at {:.0} Hz, {:.2} s, {} joints\n",
            c.label, c.frames, c.frame_rate_hz, c.duration_s, c.joints
        );
    }
    emit(&text)
}
