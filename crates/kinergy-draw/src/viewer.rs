//! One self-contained HTML page that shows clips in a browser, offline: the clips overlaid in
//! 3-D (orbit, zoom, play, pause, step, speed, a scrubber), each in its colour with its name,
//! the target and a scene's objects, and the hand-speed chart synced to the scrubber (a cursor
//! moves with the time; a click on the chart seeks there). Optional figures (a `style` run's
//! fidelity pictures) go under the chart.
//!
//! The page is built on three.js r160.1, vendored with its licence in `assets/three/` and
//! inlined, with the data as JSON: world positions in meters, Y up, as Kinergy's forward
//! kinematics gives them, so what the page draws is what the library computed. Every clip plays
//! at its own frame rate on one shared clock: at time `t` a clip shows its frame nearest `t`
//! (its last after its end).
//!
//! For people and for tests the page reports on `<body>`'s data attributes what it loaded
//! (`data-clips`, `data-joints`, `data-frames`, `data-labels`) and what it shows
//! (`data-time`, `data-shown`: each clip's frame; `data-screen`: each joint's position on the
//! screen read back from the drawn geometry; `data-camera`: the view-projection matrix;
//! `data-viewport`), its frame times while playing (`data-frame-ms`, `data-frame-ms-p95`), and a
//! summary line on the console. `#t=SECONDS` or `#frame=N` (of the first clip) in the address
//! seeks there and pauses.
//!
//! ```
//! use kinergy_draw::viewer::{ViewerClip, ViewerPage, page_html};
//! use kinergy_motion::nalgebra::Point3;
//!
//! // Two joints, two frames at 10 Hz: a bone that rises.
//! let positions = vec![
//!     Point3::new(0.0, 1.0, 0.0), Point3::new(0.0, 1.5, 0.0),
//!     Point3::new(0.0, 1.0, 0.0), Point3::new(0.0, 1.6, 0.0),
//! ];
//! let clip = ViewerClip::new(
//!     "demo".into(), 0.1, vec!["Hips".into(), "Head".into()], vec![(0, 1)], &positions,
//!     vec![0.0, 1.0],
//! )?;
//! let page = ViewerPage { title: "demo".into(), clips: vec![clip], ..ViewerPage::default() };
//! let html = page_html(&page)?;
//! assert!(html.contains("three.js") && html.contains("\"frames\":2"));
//! # Ok::<(), kinergy_draw::DrawError>(())
//! ```

use std::fmt::Write as _;
use std::path::Path;

use kinergy_motion::limbs::ArmJoints;
use kinergy_motion::segment::{SegmentSettings, hand_speed};
use kinergy_motion::{Clip, Side};
use kinergy_plan::scene::Shape;
use nalgebra::{Isometry3, Point3};
use serde::Serialize;

use plotters::style::RGBColor;

use crate::DrawError;
use crate::PALETTE;
use crate::bones::StickFigure;

/// three.js r160.1, classic build (MIT; `assets/three/README.md`).
const THREE_JS: &str = include_str!("../assets/three/three.min.js");
/// three.js r160.1's orbit controls, made a classic script (`assets/three/README.md`).
const ORBIT_JS: &str = include_str!("../assets/three/OrbitControls.global.js");
/// The page's own script.
const VIEWER_JS: &str = include_str!("../assets/viewer.js");
/// The page, with `{{…}}` slots.
const TEMPLATE: &str = include_str!("../assets/viewer.html");

/// The most clips one page overlays (one palette colour each, cycled).
pub const MAX_CLIPS: usize = 24;

/// One clip as the page draws it.
#[derive(Debug, Clone, Serialize)]
pub struct ViewerClip {
    label: String,
    color: String,
    frame_time: f64,
    joints: Vec<String>,
    bones: Vec<(usize, usize)>,
    frames: usize,
    /// Frame after frame, joint after joint, x y z in meters (to 0.1 mm).
    positions: Vec<f32>,
    /// The hand's speed per frame, m/s (to 0.1 mm/s).
    speed: Vec<f32>,
}

impl ViewerClip {
    /// A clip from its parts: `label`, seconds per frame, joint names, bones as (parent,
    /// child) joint indices, world positions (`frames × joints`, meters, Y up) and the hand's
    /// speed per frame (m/s; empty for none). Refuses a clip with no frames, positions that
    /// are not `frames × joints` or not finite, a bone naming no joint, or a speed series of
    /// another length — each message names the clip.
    pub fn new(
        label: String,
        frame_time: f64,
        joints: Vec<String>,
        bones: Vec<(usize, usize)>,
        positions: &[Point3<f64>],
        speed: Vec<f64>,
    ) -> Result<ViewerClip, DrawError> {
        let bad = |why: String| DrawError::View {
            clip: label.clone(),
            why,
        };
        if joints.is_empty() || positions.is_empty() {
            return Err(bad("the clip has no frames to show".into()));
        }
        if !(frame_time.is_finite() && frame_time > 0.0) {
            return Err(bad(format!("frame time {frame_time} s is not positive")));
        }
        if !positions.len().is_multiple_of(joints.len()) {
            return Err(bad(format!(
                "{} positions are not a whole number of frames of {} joints",
                positions.len(),
                joints.len()
            )));
        }
        let frames = positions.len() / joints.len();
        if let Some(k) = positions
            .iter()
            .position(|p| !p.iter().all(|v| v.is_finite()))
        {
            return Err(bad(format!(
                "joint `{}` has no finite position on frame {}",
                joints[k % joints.len()],
                k / joints.len()
            )));
        }
        if let Some(&(p, c)) = bones
            .iter()
            .find(|&&(p, c)| p >= joints.len() || c >= joints.len())
        {
            return Err(bad(format!(
                "bone ({p}, {c}) names a joint beyond the {}",
                joints.len()
            )));
        }
        if !speed.is_empty() && speed.len() != frames {
            return Err(bad(format!(
                "{} hand speeds for {frames} frames",
                speed.len()
            )));
        }
        if let Some(k) = speed.iter().position(|v| !v.is_finite()) {
            return Err(bad(format!("the hand speed is not finite on frame {k}")));
        }
        let round = |v: f64, unit: f64| ((v / unit).round() * unit) as f32;
        Ok(ViewerClip {
            color: String::new(),
            frame_time,
            bones,
            frames,
            positions: positions
                .iter()
                .flat_map(|p| [p.x, p.y, p.z])
                .map(|v| round(v, 1e-4))
                .collect(),
            speed: speed.iter().map(|&v| round(v, 1e-4)).collect(),
            joints,
            label,
        })
    }

    /// `clip` (read from `path`) as its stick figure draws it ([`StickFigure`]: no bones to a
    /// reference root or the face), labelled `label`, with the world speed of the hand `hand`
    /// chooses on the chart.
    pub fn of_clip(
        clip: &Clip,
        path: &Path,
        label: String,
        hand: Hand,
    ) -> Result<ViewerClip, DrawError> {
        let (figure, world) = StickFigure::of_file(clip, path)?;
        let joints: Vec<String> = clip
            .skeleton()
            .joints()
            .iter()
            .map(|j| j.name.clone())
            .collect();
        let bones = figure
            .bones(&world[..joints.len()])
            .map(|(p, c, _)| (p, c))
            .collect();
        let speed = hand.speed(clip, path)?;
        ViewerClip::new(label, clip.frame_time(), joints, bones, &world, speed).map_err(|e| match e
        {
            DrawError::View { why, .. } => DrawError::View {
                clip: path.display().to_string(),
                why,
            },
            other => other,
        })
    }

    /// Its name in the legend.
    pub fn label(&self) -> &str {
        &self.label
    }

    /// Its frame count.
    pub fn frames(&self) -> usize {
        self.frames
    }
}

/// Which hand's speed a clip's chart line shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Hand {
    /// This side's hand (an error where the skeleton has no such arm).
    Side(Side),
    /// The hand that travels farther over the clip (either, where only one arm is found;
    /// no line where neither is).
    Auto,
    /// No chart line.
    None,
}

impl std::str::FromStr for Hand {
    type Err = String;

    /// `right`, `left`, `auto` or `none`.
    fn from_str(text: &str) -> Result<Hand, String> {
        match text {
            "right" => Ok(Hand::Side(Side::Right)),
            "left" => Ok(Hand::Side(Side::Left)),
            "auto" => Ok(Hand::Auto),
            "none" => Ok(Hand::None),
            other => Err(format!("`{other}`: one of right, left, auto, none")),
        }
    }
}

impl Hand {
    /// The world speed per frame of the chosen hand of `clip` (read from `path`), m/s; empty
    /// for none.
    fn speed(self, clip: &Clip, path: &Path) -> Result<Vec<f64>, DrawError> {
        let settings = SegmentSettings::default();
        let of = |side: Side| -> Result<Vec<f64>, kinergy_motion::MotionError> {
            let arm = ArmJoints::find(clip.skeleton(), side)?;
            hand_speed(clip, &arm, &settings)
        };
        let figure = |source| DrawError::Figure {
            path: path.to_path_buf(),
            source,
        };
        match self {
            Hand::None => Ok(Vec::new()),
            Hand::Side(side) => of(side).map_err(figure),
            Hand::Auto => {
                let travel = |v: &Vec<f64>| v.iter().sum::<f64>();
                let found: Vec<Vec<f64>> = [Side::Right, Side::Left]
                    .into_iter()
                    .filter_map(|side| of(side).ok())
                    .collect();
                Ok(found
                    .into_iter()
                    .max_by(|a, b| travel(a).total_cmp(&travel(b)))
                    .unwrap_or_default())
            }
        }
    }
}

/// A scene object as the page draws it: a primitive or a triangle mesh at a pose.
#[derive(Debug, Clone, Serialize)]
pub struct ViewerObject {
    name: String,
    kind: &'static str,
    #[serde(skip_serializing_if = "Option::is_none")]
    half: Option<[f64; 3]>,
    #[serde(skip_serializing_if = "Option::is_none")]
    radius: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    half_height: Option<f64>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    vertices: Vec<f32>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    triangles: Vec<u32>,
    translation: [f64; 3],
    /// Row-major.
    rotation: [f64; 9],
}

impl ViewerObject {
    /// The object `name` of shape `shape` at `pose` (world).
    pub fn new(name: String, shape: &Shape, pose: &Isometry3<f64>) -> ViewerObject {
        let r = pose.rotation.to_rotation_matrix();
        let m = r.matrix();
        let mut o = ViewerObject {
            name,
            kind: "mesh",
            half: None,
            radius: None,
            half_height: None,
            vertices: Vec::new(),
            triangles: Vec::new(),
            translation: pose.translation.vector.into(),
            rotation: std::array::from_fn(|i| m[(i / 3, i % 3)]),
        };
        match shape {
            Shape::Box { half_extents } => {
                o.kind = "box";
                o.half = Some((*half_extents).into());
            }
            Shape::Sphere { radius } => {
                o.kind = "sphere";
                o.radius = Some(*radius);
            }
            Shape::Capsule {
                half_height,
                radius,
            } => {
                o.kind = "capsule";
                o.radius = Some(*radius);
                o.half_height = Some(*half_height);
            }
            Shape::Mesh { mesh, .. } => {
                o.vertices = mesh
                    .vertices
                    .iter()
                    .flat_map(|p| [p.x as f32, p.y as f32, p.z as f32])
                    .collect();
                o.triangles = mesh.triangles.iter().flatten().copied().collect();
            }
        }
        o
    }
}

/// The objects of the scene `path` (the JSON file `kinergy plan --scene` reads) as the page
/// draws them, and the mesh files it was read from (inputs too).
pub fn read_scene(path: &Path) -> Result<(Vec<ViewerObject>, Vec<std::path::PathBuf>), DrawError> {
    let scene = kinergy_plan::scene::Scene::read(path).map_err(|source| DrawError::Scene {
        path: path.to_path_buf(),
        source,
    })?;
    let meshes = scene.mesh_files().map(Path::to_path_buf).collect();
    let objects = scene
        .objects
        .iter()
        .map(|o| ViewerObject::new(o.name.clone(), &o.shape, &o.pose))
        .collect();
    Ok((objects, meshes))
}

/// What one page shows.
#[derive(Debug, Clone, Default)]
pub struct ViewerPage {
    /// The page's title.
    pub title: String,
    /// The clips, overlaid in this order (1 to [`MAX_CLIPS`]).
    pub clips: Vec<ViewerClip>,
    /// A reach's target, world meters.
    pub target: Option<Point3<f64>>,
    /// A scene's objects.
    pub objects: Vec<ViewerObject>,
    /// Pictures shown under the chart, each a (caption, SVG text) pair (a style run's
    /// fidelity figures).
    pub figures: Vec<(String, String)>,
}

/// The page's data, as the script reads it.
#[derive(Serialize)]
struct Data<'a> {
    title: &'a str,
    clips: Vec<ViewerClip>,
    target: Option<[f64; 3]>,
    objects: &'a [ViewerObject],
}

/// The HTML of `page`: one file, everything inlined. Refuses a page with no clips or more than
/// [`MAX_CLIPS`], or a target that is not finite.
pub fn page_html(page: &ViewerPage) -> Result<String, DrawError> {
    let bad = |why: String| DrawError::View {
        clip: page.title.clone(),
        why,
    };
    if page.clips.is_empty() || page.clips.len() > MAX_CLIPS {
        return Err(bad(format!(
            "{} clips: a page shows 1 to {MAX_CLIPS}",
            page.clips.len()
        )));
    }
    if let Some(t) = page.target
        && !t.iter().all(|v| v.is_finite())
    {
        return Err(bad("the target is not finite".into()));
    }
    let clips: Vec<ViewerClip> = page
        .clips
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let RGBColor(r, g, b) = PALETTE[i % PALETTE.len()];
            ViewerClip {
                color: format!("#{r:02x}{g:02x}{b:02x}"),
                ..c.clone()
            }
        })
        .collect();
    let mut legend = String::new();
    for c in &clips {
        let _ = write!(
            legend,
            "<span class=\"clip\"><span class=\"swatch\" style=\"background:{}\"></span>{} \
             <small>({} frames, {:.0} Hz)</small></span>",
            c.color,
            escape(&c.label),
            c.frames,
            1.0 / c.frame_time
        );
    }
    let mut extra = String::new();
    if !page.figures.is_empty() {
        extra.push_str("<div id=\"extra\">");
        for (caption, svg) in &page.figures {
            // As an image, so that it scales to the page's width.
            let _ = write!(
                extra,
                "<figure><figcaption>{}</figcaption><img alt=\"{}\" src=\"data:image/svg+xml,{}\"></figure>",
                escape(caption),
                escape(caption),
                percent_encoded(svg_body(svg))
            );
        }
        extra.push_str("</div>");
    }
    let data = Data {
        title: &page.title,
        clips,
        target: page.target.map(|t| t.coords.into()),
        objects: &page.objects,
    };
    let json = serde_json::to_string(&data).map_err(|e| bad(e.to_string()))?;
    // Inside <script>, "</" could end it: JSON allows "<\/".
    let json = json.replace("</", "<\\/");
    let title = escape(&page.title);
    let mut html = String::with_capacity(THREE_JS.len() + json.len() + 64 * 1024);
    // Fill the slots in one pass, so no slot's text is read for another slot.
    let mut rest = TEMPLATE;
    while let Some(start) = rest.find("{{") {
        html.push_str(&rest[..start]);
        let after = &rest[start + 2..];
        let Some(end) = after.find("}}") else {
            html.push_str(&rest[start..]);
            rest = "";
            break;
        };
        match &after[..end] {
            "VERSION" => html.push_str(env!("CARGO_PKG_VERSION")),
            "TITLE" => html.push_str(&title),
            "LEGEND" => html.push_str(&legend),
            "EXTRA" => html.push_str(&extra),
            "DATA" => html.push_str(&json),
            "THREE" => html.push_str(THREE_JS),
            "ORBIT" => html.push_str(ORBIT_JS),
            "VIEWER" => html.push_str(VIEWER_JS),
            other => {
                html.push_str("{{");
                html.push_str(other);
                html.push_str("}}");
            }
        }
        rest = &after[end + 2..];
    }
    html.push_str(rest);
    Ok(html)
}

/// `text` safe in HTML text and attributes.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for ch in text.chars() {
        match ch {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

/// `text` percent-encoded for a `data:` address (RFC 3986's unreserved characters kept).
fn percent_encoded(text: &str) -> String {
    let mut out = String::with_capacity(text.len() * 3 / 2);
    for b in text.bytes() {
        if b.is_ascii_alphanumeric() || b"-_.~".contains(&b) {
            out.push(b as char);
        } else {
            let _ = write!(out, "%{b:02X}");
        }
    }
    out
}

/// An SVG document's `<svg …>…</svg>` element, without its XML prolog.
fn svg_body(svg: &str) -> &str {
    svg.find("<svg").map_or(svg, |i| &svg[i..])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clip(label: &str, frames: usize) -> ViewerClip {
        let positions: Vec<Point3<f64>> = (0..frames)
            .flat_map(|k| {
                [
                    Point3::new(0.0, 1.0, 0.0),
                    Point3::new(0.0, 1.5 + 0.01 * k as f64, 0.0),
                ]
            })
            .collect();
        ViewerClip::new(
            label.into(),
            1.0 / 30.0,
            vec!["Hips".into(), "Head".into()],
            vec![(0, 1)],
            &positions,
            vec![0.3; frames],
        )
        .expect("clip")
    }

    #[test]
    fn the_page_inlines_everything_and_escapes_what_it_is_given() {
        let page = ViewerPage {
            title: "a <b> & \"c\"".into(),
            clips: vec![clip("x</script><script>alert(1)", 3), clip("y", 5)],
            target: Some(Point3::new(0.1, 1.0, 0.4)),
            ..ViewerPage::default()
        };
        let html = page_html(&page).expect("page");
        assert!(html.contains(THREE_JS) && html.contains(ORBIT_JS) && html.contains(VIEWER_JS));
        assert!(!html.contains("{{"), "every slot filled");
        assert!(html.contains("a &lt;b&gt; &amp; &quot;c&quot;"));
        // The label cannot end the data's <script>: only the page's own scripts close.
        assert_eq!(html.matches("</script>").count(), 4);
        assert!(html.contains("x<\\/script><script>alert(1)"));
        assert!(!html.contains("src=\"http"), "nothing fetched");
    }

    #[test]
    fn bad_clips_are_refused_naming_them() {
        let nan = [Point3::new(0.0, f64::NAN, 0.0)];
        let e = ViewerClip::new("bad".into(), 0.1, vec!["Hips".into()], vec![], &nan, vec![])
            .expect_err("NaN");
        assert!(e.to_string().contains("bad") && e.to_string().contains("Hips"));
        let one = [Point3::origin()];
        let e = ViewerClip::new(
            "b2".into(),
            0.1,
            vec!["Hips".into()],
            vec![(0, 3)],
            &one,
            vec![],
        )
        .expect_err("bone");
        assert!(e.to_string().contains("b2"));
        let e = ViewerClip::new("b3".into(), 0.0, vec!["Hips".into()], vec![], &one, vec![])
            .expect_err("rate");
        assert!(e.to_string().contains("b3"));
        let e = page_html(&ViewerPage::default()).expect_err("no clips");
        assert!(e.to_string().contains("0 clips"));
    }
}
