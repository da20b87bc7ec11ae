//! Pictures that show the motion, as the commands draw them: a plan's output drawn with thin
//! fingers, the scene `animate` draws behind the figures and the book it moves, `style`'s
//! charts and film strip (what the figures decide on captures: kinergy-draw's tests).

mod common;
use common::{fixture, json, kinergy, repo, stderr};

use std::path::{Path, PathBuf};

use approx::assert_relative_eq;
use kinergy_draw::bones::{BoneKind, MIN_BONE_M, Role, Segment, StickFigure};
use kinergy_motion::Clip;

fn read(path: &Path) -> Clip {
    kinergy_motion::read_clip(path, &Default::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .0
}

/// Every frame's drawn segments.
fn all_segments(clip: &Clip) -> (StickFigure, Vec<Vec<Segment>>) {
    let (figure, world) = StickFigure::of(clip).expect("fk");
    let n = clip.skeleton().joint_count();
    let frames = world.chunks(n).map(|w| figure.world_segments(w)).collect();
    (figure, frames)
}

fn name(clip: &Clip, j: usize) -> String {
    clip.skeleton().joint(j).name.to_ascii_lowercase()
}

fn says_finger(name: &str) -> bool {
    ["finger", "thumb", "index", "middle", "ring", "pinky"]
        .iter()
        .any(|p| name.contains(p))
}

/// No segment shorter than [`MIN_BONE_M`].
fn assert_no_zero_length(frames: &[Vec<Segment>], what: &str) {
    for (k, segments) in frames.iter().enumerate() {
        for s in segments {
            let length = nalgebra::distance(&s.from, &s.to);
            assert!(
                length >= MIN_BONE_M,
                "{what} frame {k}: {s:?} is {length} m long"
            );
        }
    }
}

/// Runs `kinergy plan` relocating the bookshelf's blue book; returns the BVH and the report.
fn relocate(dir: &Path) -> (PathBuf, PathBuf) {
    let bvh = dir.join("relocate.bvh");
    let report = dir.join("relocate.json");
    let scene = repo().join("examples/bookshelf/scene.json");
    let o = kinergy(&[
        "plan",
        "--scene",
        scene.to_str().expect("utf-8"),
        "--task",
        "relocate",
        "--object",
        "blue_book",
        "--to",
        "-0.22,1.49,0.50",
        "-o",
        bvh.to_str().expect("utf-8"),
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    std::fs::write(&report, &o.stdout).expect("write report");
    (bvh, report)
}

#[test]
fn plan_output_draws_fingers_thin_and_reports_the_books_poses() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (bvh, report) = relocate(dir.path());
    let clip = read(&bvh);
    let (figure, frames) = all_segments(&clip);
    assert_no_zero_length(&frames, "plan");
    assert!(!figure.roles().contains(&Role::Reference));
    let fingers = frames[0]
        .iter()
        .filter(|s| s.kind == BoneKind::Finger)
        .count();
    let body = frames[0].len() - fingers;
    // Two hands of five three-joint fingers, each finger's bones from the hand: 15 a hand,
    // plus their End Sites.
    assert!(fingers >= 30, "{fingers} finger bones");
    assert!(body >= 15, "{body} body bones");
    for s in &frames[0] {
        let finger = says_finger(&name(&clip, s.child)) || says_finger(&name(&clip, s.parent));
        assert_eq!(
            s.kind == BoneKind::Finger,
            finger,
            "{}",
            name(&clip, s.child)
        );
    }
    let report: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&report).expect("report")).expect("json");
    let book = &report["objects"][0];
    assert_eq!(book["name"], "blue_book");
    let poses = book["poses"].as_array().expect("poses");
    assert_eq!(poses.len(), clip.frame_count());
    assert_relative_eq!(
        report["frame_time_s"].as_f64().expect("frame time"),
        clip.frame_time(),
        epsilon = 1e-9
    );
    assert_eq!(poses.last(), Some(&book["end"]));
}

/// The strip's pixels of exactly `colour` between 30 % and 80 % of its height (away from the
/// legend and the time stamps, whose anti-aliased text has greys): their count and mean x, y
/// per snapshot.
fn pixels_of(png: &Path, colour: [u8; 3], panels: u32) -> Vec<(usize, f64, f64)> {
    let img = image::open(png).expect("png").to_rgb8();
    let width = img.width() / panels;
    let mut out = vec![(0usize, 0.0, 0.0); panels as usize];
    let rows = img.height() * 3 / 10..img.height() * 8 / 10;
    for (x, y, p) in img.enumerate_pixels() {
        if p.0 == colour && rows.contains(&y) {
            let k = ((x / width) as usize).min(panels as usize - 1);
            out[k].0 += 1;
            out[k].1 += f64::from(x % width);
            out[k].2 += f64::from(y);
        }
    }
    out.into_iter()
        .map(|(n, x, y)| (n, x / n.max(1) as f64, y / n.max(1) as f64))
        .collect()
}

#[test]
fn animate_draws_the_scene_and_the_book_moving_with_the_hand() {
    let dir = tempfile::tempdir().expect("tempdir");
    let (bvh, report) = relocate(dir.path());
    let scene = repo().join("examples/bookshelf/scene.json");
    let s = |p: &Path| p.to_str().expect("utf-8").to_string();
    let run = |extra: &[String], name: &str| -> PathBuf {
        let strip = dir.path().join(format!("{name}.png"));
        let mut args = vec![
            "animate".to_string(),
            s(&bvh),
            "--view".into(),
            "side".into(),
            "--fps".into(),
            "1".into(),
            "--size".into(),
            "200x200".into(),
            "--strip-frames".into(),
            "2".into(),
            "-o".into(),
            s(&dir.path().join(format!("{name}.gif"))),
            "--strip".into(),
            s(&strip),
            "--json".into(),
        ];
        args.extend_from_slice(extra);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let o = kinergy(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        strip
    };
    let bare = run(&[], "bare");
    let with_scene = run(&["--scene".into(), s(&scene)], "scene");
    let moving = run(
        &["--scene".into(), s(&scene), "--report".into(), s(&report)],
        "moving",
    );
    let shelf_grey = [228, 228, 228];
    let book = [240, 200, 120];
    assert!(pixels_of(&bare, shelf_grey, 2).iter().all(|p| p.0 == 0));
    let grey = pixels_of(&with_scene, shelf_grey, 2);
    assert!(
        grey.iter().all(|p| p.0 > 200),
        "the shelf is not drawn: {grey:?}"
    );
    // In the side view the shelf stands in front of the character: right of its middle.
    assert!(grey.iter().all(|p| p.1 > 100.0), "{grey:?}");
    assert!(pixels_of(&with_scene, book, 2).iter().all(|p| p.0 == 0));
    // With the report the book is drawn, first on the middle shelf, last on the top one.
    let books = pixels_of(&moving, book, 2);
    assert!(
        books.iter().all(|p| p.0 > 10),
        "the book is not drawn: {books:?}"
    );
    assert!(
        books[1].2 < books[0].2 - 5.0,
        "the book did not go up: {books:?}"
    );
}

#[test]
fn animate_report_needs_a_scene_and_objects_in_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    let clip = fixture("006_14.bvh");
    let report = dir.path().join("r.json");
    std::fs::write(
        &report,
        r#"{"frame_time_s": 0.1, "objects": [{"name": "teapot", "poses": [{"position_m": [0,0,0], "rotation_xyzw": [0,0,0,1]}]}]}"#,
    )
    .expect("write");
    let gif = dir.path().join("a.gif");
    let (c, r, g) = (
        clip.to_str().expect("utf-8"),
        report.to_str().expect("utf-8"),
        gif.to_str().expect("utf-8"),
    );
    common::assert_bad_input(&["animate", c, "--report", r, "-o", g], "--scene", &gif);
    let scene = repo().join("examples/bookshelf/scene.json");
    let sc = scene.to_str().expect("utf-8");
    common::assert_bad_input(
        &["animate", c, "--scene", sc, "--report", r, "-o", g],
        "teapot",
        &gif,
    );
    let o = kinergy(&["animate", c, "--scene", sc, "-o", g, "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert_eq!(json(&o)["moving_objects"], serde_json::json!([]));
}

/// Whether `xml` is well formed as far as its tags go: every element closed in order, one
/// root, nothing but whitespace outside it (plotters writes no comments, CDATA or doctype).
fn well_formed(xml: &str) -> Result<(), String> {
    let mut open: Vec<String> = Vec::new();
    let mut roots = 0;
    let mut rest = xml.trim();
    while let Some(at) = rest.find('<') {
        if open.is_empty() && !rest[..at].trim().is_empty() {
            return Err(format!("text outside the root: {}", &rest[..at]));
        }
        let end = rest[at..].find('>').ok_or("a tag is not closed")? + at;
        let tag = &rest[at + 1..end];
        if let Some(name) = tag.strip_prefix('/') {
            match open.pop() {
                Some(o) if o == name.trim() => {}
                other => return Err(format!("</{name}> closes {other:?}")),
            }
        } else if !tag.starts_with('?') {
            let name = tag.split_whitespace().next().ok_or("an empty tag")?;
            if open.is_empty() {
                roots += 1;
            }
            if !tag.ends_with('/') {
                open.push(name.to_string());
            }
        }
        rest = &rest[end + 1..];
    }
    match (open.is_empty(), roots, rest.trim().is_empty()) {
        (true, 1, true) => Ok(()),
        _ => Err(format!(
            "{} unclosed, {roots} roots, tail {rest:?}",
            open.len()
        )),
    }
}

/// How many `<polyline>`s are stroked in `colour`, and of those how many `width` wide.
fn polylines(svg: &str, colour: &str) -> Vec<String> {
    svg.split("<polyline")
        .skip(1)
        .filter_map(|p| {
            let tag = &p[..p.find('>')?];
            tag.contains(&format!(r#"stroke="{colour}""#))
                .then(|| tag.split("stroke-width=\"").nth(1)?.split('"').next())
                .flatten()
                .map(str::to_string)
        })
        .collect()
}

/// `style -o DIR` draws the hand-speed chart (one line per capture and kind —
/// captured black, `reach --params` blue, default vermillion — plus a legend entry each, the
/// means in the legend) and the film strip (five panels, the captured figure and the
/// character's in two colours), as well-formed SVG and PNG.
#[test]
fn style_draws_the_speed_chart_and_the_film_strip_overlaid_on_the_capture() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("style");
    let params = repo().join("tests/data/params/synthetic-p01-r09-sc.json");
    let clips = [common::synthetic("r09.bvh"), common::synthetic("r01.bvh")];
    let s = |p: &Path| p.to_str().expect("utf-8").to_string();
    let mut args = vec!["style".to_string()];
    args.extend(clips.iter().map(|p| s(p)));
    args.extend(
        [
            "--arm",
            "right",
            "--params",
            &s(&params),
            "-o",
            &s(&out),
            "--json",
        ]
        .map(String::from),
    );
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let o = kinergy(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let summary = json(&o)["summary"].clone();

    for name in ["speed.png", "strip.png"] {
        let bytes = std::fs::read(out.join(name)).expect("png");
        assert!(
            bytes.starts_with(b"\x89PNG\r\n\x1a\n"),
            "{name} is not a PNG"
        );
    }
    // The page: the first capture and its two reaches, with the charts under them.
    let page = std::fs::read_to_string(out.join("view.html")).expect("view.html");
    for label in [
        "r09 (captured)",
        "r09 (the person's parameters)",
        "r09 (the default profile)",
        "In real time, beside the person&#39;s own repeats",
        "data:image/svg+xml,",
    ] {
        assert!(page.contains(label), "{label:?} missing from view.html");
    }
    let speed = std::fs::read_to_string(out.join("speed.svg")).expect("speed.svg");
    well_formed(&speed).unwrap_or_else(|e| panic!("speed.svg: {e}"));
    let mean_r = format!(
        "reach --params: r {:.2}",
        summary["params_correlation"].as_f64().expect("r")
    );
    for label in [
        "captured (2 takes)",
        &mean_r,
        "default profile: r ",
        "arm path",
        "fraction of the reach",
    ] {
        assert!(speed.contains(label), "{label:?} missing from speed.svg");
    }
    // The series' width is the blue lines' (no axis is blue): 2 captures + a legend swatch.
    let blue = polylines(&speed, "#0072B2");
    assert_eq!(blue.len(), 3, "blue lines {blue:?}");
    let width = &blue[0];
    for colour in ["#000000", "#D55E00"] {
        let lines = polylines(&speed, colour)
            .iter()
            .filter(|w| *w == width)
            .count();
        assert_eq!(lines, 3, "{colour}: {lines} lines {width} wide");
    }

    let strip = std::fs::read_to_string(out.join("strip.svg")).expect("strip.svg");
    well_formed(&strip).unwrap_or_else(|e| panic!("strip.svg: {e}"));
    for label in [
        "captured",
        "reach --params (full body)",
        "0 % of the reach",
        "50 % of the reach",
        "100 % of the reach",
        "r09",
    ] {
        assert!(strip.contains(label), "{label:?} missing from strip.svg");
    }
    // The captured figure's dots (its body joints) in every one of the five panels.
    let (figure, _) = StickFigure::of(&read(&clips[0])).expect("fk");
    let dots = |colour: &str| {
        strip
            .split("<circle")
            .skip(1)
            .filter(|c| c[..c.find('>').unwrap_or(0)].contains(&format!(r#"fill="{colour}""#)))
            .count()
    };
    assert_eq!(dots("#000000"), 5 * figure.dots().len());
    let character = dots("#0072B2");
    assert!(
        character >= 5 * 10 && character % 5 == 0,
        "{character} character dots"
    );
}

#[test]
fn the_well_formedness_check_catches_what_it_should() {
    assert!(well_formed(r#"<svg a="1"><g><line/></g><text>x</text></svg>"#).is_ok());
    assert!(well_formed("<svg><g></svg>").is_err());
    assert!(well_formed("<svg></svg><svg></svg>").is_err());
    assert!(well_formed("<svg><g>").is_err());
}
