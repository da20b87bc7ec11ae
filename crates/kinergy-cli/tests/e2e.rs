//! End-to-end tests of every `kinergy` subcommand on a small synthetic set (one person,
//! three reaches, made afresh by `kinergy synth` in each test): the files written and their
//! content, pictures checked for their format, size and number of series or frames; each kind
//! of bad input exiting 2 with a message naming the problem and leaving nothing behind; every
//! subcommand's help carrying an example; no colour or progress bar when not on a terminal.

mod common;
use common::{json, kinergy, repo, stderr, stdout, text};

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use kinergy_motion::{Clip, ImportOptions, LengthUnit, UnitChoice};

// ---------------------------------------------------------------------------------------------
// Helpers
// ---------------------------------------------------------------------------------------------

fn utf8(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// Runs `kinergy` with `args`, `set` added to and `unset` removed from the environment.
fn kinergy_env(args: &[&str], set: &[(&str, &str)], unset: &[&str]) -> Output {
    let mut c = Command::new(env!("CARGO_BIN_EXE_kinergy"));
    c.args(args);
    for name in unset {
        c.env_remove(name);
    }
    for (name, value) in set {
        c.env(name, value);
    }
    c.output().expect("run kinergy")
}

/// What a progress bar or colour would leave on a captured stream.
fn terminal_remnants(s: &str) -> Vec<&'static str> {
    let mut found = Vec::new();
    if s.contains("\x1b[") {
        found.push("an ANSI escape");
    }
    if s.contains('\r') {
        found.push("a carriage return");
    }
    if s.contains("=>") || s.contains("evaluations  best") {
        found.push("a progress bar");
    }
    found
}

/// Asserts exit code 0 and a stderr without progress-bar or colour remnants.
#[track_caller]
fn succeed(o: &Output, what: &str) {
    let err = stderr(o);
    assert_eq!(o.status.code(), Some(0), "{what}: {err}");
    let remnants = terminal_remnants(&err);
    assert!(
        remnants.is_empty(),
        "{what}: {remnants:?} on stderr: {err:?}"
    );
}

/// Reads a BVH file the way the library does (SI units, radians), guessing its unit.
fn read_clip(path: &Path) -> Clip {
    read_clip_in(path, UnitChoice::Auto)
}

fn read_clip_in(path: &Path, unit: UnitChoice) -> Clip {
    let options = ImportOptions {
        unit,
        ..Default::default()
    };
    kinergy_motion::read_clip(path, &options)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .0
}

/// The names of the entries of `dir`, sorted.
fn listing(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .expect("read dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// A fresh synthetic set, `--persons 1 --reaches 3 --seed 5`, in `DIR/set`.
struct Set {
    dir: tempfile::TempDir,
    root: PathBuf,
    /// The clips the manifest lists, in its order.
    clips: Vec<PathBuf>,
    /// Each clip's `frames` column.
    manifest_frames: Vec<usize>,
}

fn synth_set() -> Set {
    let dir = tempfile::tempdir().expect("tempdir");
    let root = dir.path().join("set");
    let o = kinergy(&[
        "synth",
        "-o",
        utf8(&root),
        "--persons",
        "1",
        "--reaches",
        "3",
        "--seed",
        "5",
    ]);
    succeed(&o, "synth");
    let manifest = std::fs::read_to_string(root.join("manifest.csv")).expect("manifest.csv");
    let mut lines = manifest.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .unwrap_or_else(|| panic!("manifest.csv has no `{name}` column: {header:?}"))
    };
    let (clip_col, frames_col) = (col("clip"), col("frames"));
    let (mut clips, mut manifest_frames) = (Vec::new(), Vec::new());
    for line in lines {
        let cells: Vec<&str> = line.split(',').collect();
        assert_eq!(cells.len(), header.len(), "ragged manifest row {line}");
        clips.push(root.join(cells[clip_col]));
        manifest_frames.push(cells[frames_col].parse().expect("frames"));
    }
    Set {
        dir,
        root,
        clips,
        manifest_frames,
    }
}

/// Every `.bvh` file under `dir`, sorted.
fn bvh_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("read_dir") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|e| e == "bvh") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// A PNG's width and height from its IHDR chunk, after checking the signature and that the
/// file ends with the IEND chunk (a complete file).
#[track_caller]
fn png_size(b: &[u8]) -> (u32, u32) {
    assert!(b.len() > 33 + 12, "too short for a PNG: {} bytes", b.len());
    assert_eq!(&b[..8], b"\x89PNG\r\n\x1a\n", "PNG signature");
    assert_eq!(&b[12..16], b"IHDR", "IHDR first");
    assert_eq!(
        &b[b.len() - 12..],
        b"\0\0\0\0IEND\xaeB`\x82",
        "the PNG does not end with IEND"
    );
    let be = |at: usize| u32::from_be_bytes([b[at], b[at + 1], b[at + 2], b[at + 3]]);
    (be(16), be(20))
}

/// A GIF's logical screen size and its number of images (frames), walking its blocks.
#[track_caller]
fn gif_frames(b: &[u8]) -> (u16, u16, usize) {
    assert_eq!(&b[..6], b"GIF89a", "GIF signature");
    let u16_le = |at: usize| u16::from_le_bytes([b[at], b[at + 1]]);
    let skip_sub_blocks = |mut at: usize| loop {
        let n = usize::from(b[at]);
        at += 1 + n;
        if n == 0 {
            return at;
        }
    };
    let packed = b[10];
    let mut at = 13;
    if packed & 0x80 != 0 {
        at += 3 << ((packed & 7) + 1);
    }
    let mut images = 0;
    loop {
        match b[at] {
            0x21 => at = skip_sub_blocks(at + 2),
            0x2C => {
                let local = b[at + 9];
                at += 10;
                if local & 0x80 != 0 {
                    at += 3 << ((local & 7) + 1);
                }
                at = skip_sub_blocks(at + 1);
                images += 1;
            }
            0x3B => {
                assert_eq!(at + 1, b.len(), "bytes after the GIF trailer");
                return (u16_le(6), u16_le(8), images);
            }
            other => panic!("unexpected GIF block {other:#04x} at byte {at}"),
        }
    }
}

/// The text of every `<text>` element of an SVG, trimmed, after checking it is one complete
/// `<svg>` element of `size` (when given).
#[track_caller]
fn svg_texts(svg: &str, size: Option<(u32, u32)>) -> Vec<String> {
    assert!(
        svg.starts_with("<svg"),
        "not an SVG: {}",
        &svg[..svg.len().min(80)]
    );
    assert!(svg.trim_end().ends_with("</svg>"), "the SVG is not closed");
    assert_eq!(
        svg.matches("<text").count(),
        svg.matches("</text>").count(),
        "unbalanced <text> elements"
    );
    if let Some((w, h)) = size {
        let want = format!(r#"<svg width="{w}" height="{h}""#);
        assert!(svg.starts_with(&want), "the SVG is not {w}×{h}");
    }
    let mut out = Vec::new();
    let mut rest = svg;
    while let Some(i) = rest.find("<text") {
        let element = &rest[i..];
        let open = element.find('>').expect("<text …>") + 1;
        let close = element.find("</text>").expect("</text>");
        out.push(element[open..close].trim().to_string());
        rest = &element[close + "</text>".len()..];
    }
    out
}

/// Reads a float out of a JSON value.
#[track_caller]
fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

// ---------------------------------------------------------------------------------------------
// 1. The walkthrough
// ---------------------------------------------------------------------------------------------

// `synth` writes one manifest row per clip it writes, and each clip is BVH the library reads
// with the frame count the manifest gives.
#[test]
fn synth_writes_one_readable_clip_per_manifest_row() {
    let set = synth_set();
    assert_eq!(set.clips.len(), 3, "1 person × 3 reaches");
    assert_eq!(
        bvh_files(&set.root),
        set.clips,
        "manifest rows vs clips on disk"
    );
    for (path, &frames) in set.clips.iter().zip(&set.manifest_frames) {
        let clip = read_clip(path);
        assert_eq!(clip.frame_count(), frames, "{}", path.display());
        assert!(
            (clip.frame_time() - 1.0 / 60.0).abs() < 1e-12,
            "the default 60 Hz"
        );
        assert!(
            clip.skeleton().require_joint("RightHand").is_ok(),
            "{}",
            path.display()
        );
    }
    // Nothing but the person folder and the manifest.
    assert_eq!(listing(&set.root), ["manifest.csv", "p01"]);
}

// segment → fit → synthesize (replaying what the fit scored) → plot speed (SVG + CSV, PNG) →
// animate, on one synthetic clip.
#[test]
fn walkthrough_segment_fit_synthesize_plot_animate() {
    let set = synth_set();
    let work = set.dir.path();
    let clip_path = &set.clips[0];
    let clip_s = utf8(clip_path);
    let clip = read_clip(clip_path);
    let stem = clip_path.file_stem().expect("stem").to_string_lossy();

    // segment --json: at least one segment, each onset < peak < end inside the clip.
    let o = kinergy(&["segment", clip_s, "--json"]);
    succeed(&o, "segment");
    let seg = json(&o);
    assert_eq!(seg["frames"].as_u64(), Some(clip.frame_count() as u64));
    let segments = seg["segments"].as_array().expect("segments");
    assert!(!segments.is_empty(), "no segment in {seg}");
    for s in segments {
        let (a, p, b) = (
            s["onset"].as_u64().expect("onset"),
            s["peak"].as_u64().expect("peak"),
            s["end"].as_u64().expect("end"),
        );
        assert!(a < p && p < b, "not onset < peak < end: {s}");
        assert!((b as usize) <= clip.frame_count(), "{s}"); // end excluded
    }
    assert_eq!(segments.iter().filter(|s| s["main"] == true).count(), 1);

    // fit: a parameters file of model sc with finite values; the report's score.
    let params = work.join("p.json");
    let o = kinergy(&[
        "fit",
        clip_s,
        "--model",
        "sc",
        "--optimizer",
        "svd",
        "--per",
        "clip",
        "--budget",
        "80",
        "-o",
        utf8(&params),
        "--json",
    ]);
    succeed(&o, "fit");
    let report = json(&o);
    let models = report["models"].as_array().expect("models");
    let last = models.last().expect("a model");
    assert_eq!(last["model"], "sc");
    let score = f(&last["score_m"]);
    assert!(score.is_finite() && score > 0.0, "{report}");
    assert_eq!(report["reaches"].as_array().map(Vec::len), Some(1));
    assert_eq!(f(&report["reaches"][0]["distance_m"]), score);
    for m in models {
        assert!(m["evaluations"].as_u64().expect("evaluations") <= 80, "{m}");
    }
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&params).expect("p.json")).expect("JSON");
    assert!(
        file["format_version"].as_u64().is_some_and(|v| v >= 1),
        "format_version: {file}"
    );
    assert_eq!(file["model"], "sc");
    assert_eq!(file["optimizer"]["kind"], "svd");
    let values = file["values"].as_object().expect("values");
    assert!(!values.is_empty());
    for (name, v) in values {
        assert!(f(v).is_finite(), "{name} = {v}");
    }
    assert_eq!(f(&file["fit"]["score_m"]), score);

    // synthesize --frames auto replays the fitted reach: the same distance as the fit scored.
    let synthesized = work.join("s.bvh");
    let o = kinergy(&[
        "synthesize",
        "--from",
        clip_s,
        "--params",
        utf8(&params),
        "--frames",
        "auto",
        "-o",
        utf8(&synthesized),
        "--json",
    ]);
    succeed(&o, "synthesize");
    let synth = json(&o);
    assert_eq!(synth["model"], "sc");
    assert_eq!(synth["capture_frames"], report["reaches"][0]["frames"]);
    let distance = f(&synth["distance_to_capture_m"]);
    assert!(
        (distance - score).abs() < 1e-9,
        "synthesize says {distance} m, fit scored {score} m"
    );
    let s_clip = read_clip(&synthesized);
    assert_eq!(
        s_clip.frame_count() as u64,
        synth["frames"].as_u64().expect("frames")
    );
    assert_eq!(s_clip.frame_time(), clip.frame_time());

    // plot speed → SVG + CSV: one line and one legend label per clip, one CSV row per frame.
    let svg = work.join("speed.svg");
    let csv = work.join("speed.csv");
    let o = kinergy(&[
        "plot",
        "speed",
        clip_s,
        utf8(&synthesized),
        "-o",
        utf8(&svg),
        "--csv",
        utf8(&csv),
    ]);
    succeed(&o, "plot speed svg");
    let texts = svg_texts(
        &std::fs::read_to_string(&svg).expect("svg"),
        Some((900, 500)),
    );
    let legend: Vec<&str> = texts
        .iter()
        .map(String::as_str)
        .filter(|t| t.parse::<f64>().is_err())
        .filter(|t| !["Hand speed", "time (s)", "hand speed (m/s)"].contains(t))
        .collect();
    assert_eq!(legend, [&*stem, "s"], "legend labels among {texts:?}");
    let table = std::fs::read_to_string(&csv).expect("csv");
    let mut lines = table.lines();
    assert_eq!(lines.next(), Some("clip,time_s,speed_m_s"));
    let rows: Vec<(String, f64, f64)> = lines
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            assert_eq!(c.len(), 3, "{l}");
            (
                c[0].to_string(),
                c[1].parse().expect("time"),
                c[2].parse().expect("speed"),
            )
        })
        .collect();
    for (name, c) in [(&*stem, &clip), ("s", &s_clip)] {
        let series: Vec<&(String, f64, f64)> = rows.iter().filter(|r| r.0 == name).collect();
        assert_eq!(series.len(), c.frame_count(), "{name}: one row per frame");
        for (k, r) in series.iter().enumerate() {
            assert!(
                (r.1 - k as f64 * c.frame_time()).abs() < 1e-12,
                "{name} row {k}: t = {}",
                r.1
            );
            assert!(r.2.is_finite() && r.2 >= 0.0, "{name} row {k}: {}", r.2);
        }
        assert!(series.windows(2).all(|w| w[1].1 > w[0].1), "{name}: times");
    }
    assert_eq!(rows.len(), clip.frame_count() + s_clip.frame_count());

    // plot speed → PNG of the size asked for.
    let png = work.join("speed.png");
    let o = kinergy(&[
        "plot",
        "speed",
        clip_s,
        utf8(&synthesized),
        "-o",
        utf8(&png),
        "--size",
        "640x360",
    ]);
    succeed(&o, "plot speed png");
    assert_eq!(png_size(&std::fs::read(&png).expect("png")), (640, 360));

    // animate → a GIF of floor(longest duration · fps) + 1 frames and the strip beside it.
    let gif = work.join("ov.gif");
    let o = kinergy(&[
        "animate",
        clip_s,
        utf8(&synthesized),
        "-o",
        utf8(&gif),
        "--fps",
        "10",
        "--size",
        "160x120",
        "--strip-frames",
        "3",
        "--json",
    ]);
    succeed(&o, "animate");
    let anim = json(&o);
    let longest = clip.duration().max(s_clip.duration());
    let expected = (longest * 10.0 + 1e-6).floor() as usize + 1;
    let (w, h, frames) = gif_frames(&std::fs::read(&gif).expect("gif"));
    assert_eq!((w, h), (160, 120));
    assert_eq!(frames, expected, "GIF frames for {longest} s at 10 fps");
    assert_eq!(anim["frames"].as_u64(), Some(expected as u64));
    let labels: Vec<&str> = anim["clips"]
        .as_array()
        .expect("clips")
        .iter()
        .map(|c| c["label"].as_str().expect("label"))
        .collect();
    assert_eq!(labels, [&*stem, "s"]);
    let strip = work.join("ov.png");
    assert_eq!(anim["strip"], utf8(&strip));
    assert_eq!(png_size(&std::fs::read(&strip).expect("strip")), (480, 120));

    // Every output is in place and nothing else (no temporary files).
    assert_eq!(
        listing(work),
        [
            "ov.gif",
            "ov.png",
            "p.json",
            "s.bvh",
            "set",
            "speed.csv",
            "speed.png",
            "speed.svg"
        ]
    );
}

// compare on the set: the Fig. 3 rows of every clip, and both figures as valid SVG and PNG.
#[test]
fn compare_writes_results_and_both_figures() {
    let set = synth_set();
    let out = set.dir.path().join("out");
    let o = kinergy(&[
        "compare",
        utf8(&set.root),
        "--budget",
        "40",
        "--no-baselines",
        "-o",
        utf8(&out),
    ]);
    succeed(&o, "compare");
    let said = stdout(&o);
    assert!(
        said.contains("fig3.svg") && said.contains("fig4.png"),
        "{said}"
    );
    assert_eq!(
        listing(&out),
        [
            "fig3.png",
            "fig3.svg",
            "fig4.png",
            "fig4.svg",
            "results.csv",
            "summary.md"
        ]
    );

    let csv = std::fs::read_to_string(out.join("results.csv")).expect("results.csv");
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("clip,model,optimizer,method,distance_m,frames,evaluations,seconds")
    );
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    for r in &rows {
        assert_eq!(r.len(), 8, "{r:?}");
        let d: f64 = r[4].parse().expect("distance");
        assert!(d.is_finite() && d > 0.0, "{r:?}");
        assert!(r[6].parse::<usize>().expect("evaluations") <= 40, "{r:?}");
        assert!(
            !["sa_from_neutral", "nelder_mead", "particle_swarm"].contains(&r[3]),
            "--no-baselines but {r:?}"
        );
    }
    for clip in &set.clips {
        let name = clip.strip_prefix(&set.root).expect("in the set");
        let mine: Vec<&Vec<&str>> = rows
            .iter()
            .filter(|r| Path::new(r[0]).ends_with(name))
            .collect();
        let fig3: Vec<&str> = mine
            .iter()
            .filter(|r| r[2] == "svd" && r[3] == "sa")
            .map(|r| r[1])
            .collect();
        assert_eq!(fig3, ["sa", "sb", "sc", "sd"], "{}", name.display());
        // Fig. 4's other optimizers (S_A and S_C each) and the parameter field's row.
        for optimizer in ["jt", "njt"] {
            let models: Vec<&str> = mine
                .iter()
                .filter(|r| r[2] == optimizer && r[3] == "sa")
                .map(|r| r[1])
                .collect();
            assert_eq!(models, ["sa", "sc"], "{} {optimizer}", name.display());
        }
        assert_eq!(mine.iter().filter(|r| r[3] == "field_loo").count(), 1);
        assert_eq!(mine.len(), 4 + 2 * 2 + 1, "{}: {mine:?}", name.display());
    }
    assert_eq!(rows.len(), set.clips.len() * 9);

    let fig3 = svg_texts(
        &std::fs::read_to_string(out.join("fig3.svg")).expect("fig3.svg"),
        None,
    );
    for label in ["S_A", "S_B", "S_C", "S_D"] {
        assert!(
            fig3.iter().any(|t| t == label),
            "fig3.svg lacks {label}: {fig3:?}"
        );
    }
    let fig4 = svg_texts(
        &std::fs::read_to_string(out.join("fig4.svg")).expect("fig4.svg"),
        None,
    );
    for label in ["JT", "NJT", "SVD", "S_A", "S_C"] {
        assert!(
            fig4.iter().any(|t| t == label),
            "fig4.svg lacks {label}: {fig4:?}"
        );
    }
    // The legend of Fig. 4 is exactly S_A and S_C: no S_B or S_D series.
    assert!(!fig4.iter().any(|t| t == "S_B" || t == "S_D"), "{fig4:?}");
    for name in ["fig3.png", "fig4.png"] {
        let (w, h) = png_size(&std::fs::read(out.join(name)).expect("png"));
        assert!(w >= 64 && h >= 64, "{name}: {w}×{h}");
    }
}

// reach and plan: the files read back with the frames the reports give.
#[test]
fn reach_and_plan_write_the_frames_they_report() {
    let dir = tempfile::tempdir().expect("tempdir");
    let reach = dir.path().join("r.bvh");
    let o = kinergy(&[
        "reach",
        "--target",
        "0.2,1.0,0.4",
        "-o",
        utf8(&reach),
        "--json",
    ]);
    succeed(&o, "reach");
    let report = json(&o);
    assert_eq!(report["stop"], "reached");
    let clip = read_clip(&reach);
    assert_eq!(
        clip.frame_count() as u64,
        report["frames"].as_u64().expect("frames")
    );
    assert_eq!(clip.frame_time(), 1.0 / 120.0);

    let plan = dir.path().join("p.bvh");
    let scene = repo().join("examples/bookshelf/scene.json");
    let o = kinergy(&[
        "plan",
        "--scene",
        utf8(&scene),
        "--target",
        "-0.25,1.1,0.3",
        "-o",
        utf8(&plan),
        "--json",
    ]);
    succeed(&o, "plan");
    let report = json(&o);
    let clip = read_clip(&plan);
    let frames = report["frames"].as_u64().expect("frames");
    assert_eq!(clip.frame_count() as u64, frames);
    assert!((clip.frame_time() - 1.0 / 60.0).abs() < 1e-12);
    let phases = report["phases"].as_array().expect("phases");
    assert_eq!(
        phases.last().and_then(|p| p["last_frame"].as_u64()),
        Some(frames - 1),
        "the phases cover the clip"
    );
    assert_eq!(listing(dir.path()), ["p.bvh", "r.bvh"]);
}

// inspect describes an output as the library reads it; convert to meters and back to
// centimeters keeps every joint's world position.
#[test]
fn inspect_and_convert_round_trip_an_output() {
    let dir = tempfile::tempdir().expect("tempdir");
    let reach = dir.path().join("r.bvh");
    // `--target=` because `reach` takes `--target -0.3,…` for a flag (see the test below).
    let o = kinergy(&["reach", "--target=-0.3,1.2,0.35", "-o", utf8(&reach)]);
    succeed(&o, "reach");
    let original = read_clip(&reach);

    let o = kinergy(&["inspect", utf8(&reach), "--json"]);
    succeed(&o, "inspect");
    let v = json(&o);
    let skeleton = original.skeleton();
    let joints = skeleton.joints().iter().filter(|j| !j.end_site).count();
    assert_eq!(
        v["frame_count"].as_u64(),
        Some(original.frame_count() as u64)
    );
    assert_eq!(v["joint_count"].as_u64(), Some(joints as u64));
    assert_eq!(
        v["end_site_count"].as_u64(),
        Some((skeleton.joint_count() - joints) as u64)
    );
    assert_eq!(v["unit"], "cm", "reach writes centimeters");
    assert_eq!(f(&v["frame_time"]), original.frame_time());
    let o = kinergy(&["inspect", utf8(&reach)]);
    succeed(&o, "inspect text");
    let said = stdout(&o);
    assert!(said.contains(utf8(&reach)), "{said}");
    assert!(
        said.contains(&format!("{} at", original.frame_count())),
        "{said}"
    );

    let meters = dir.path().join("r_m.bvh");
    let back = dir.path().join("r_cm.bvh");
    let o = kinergy(&["convert", utf8(&reach), "-o", utf8(&meters), "--unit", "m"]);
    succeed(&o, "convert to m");
    let o = kinergy(&[
        "convert",
        utf8(&meters),
        "-o",
        utf8(&back),
        "--from-unit",
        "m",
    ]);
    succeed(&o, "convert back to cm");
    let in_m = read_clip_in(&meters, UnitChoice::Fixed(LengthUnit::Meter));
    let in_cm = read_clip_in(&back, UnitChoice::Fixed(LengthUnit::Centimeter));
    let last = original.frame_count() - 1;
    for copy in [&in_m, &in_cm] {
        assert_eq!(copy.frame_count(), original.frame_count());
        assert_eq!(copy.frame_time(), original.frame_time());
        assert_eq!(copy.skeleton().joint_count(), skeleton.joint_count());
        for frame in [0, last / 3, last / 2, last] {
            let a = skeleton
                .world_positions(original.frame(frame).expect("frame"))
                .expect("fk");
            let b = copy
                .skeleton()
                .world_positions(copy.frame(frame).expect("frame"))
                .expect("fk");
            for (j, (p, q)) in a.iter().zip(&b).enumerate() {
                assert!(
                    (p - q).norm() < 1e-6,
                    "frame {frame}, {}: {p} vs {q}",
                    skeleton.joints()[j].name
                );
            }
        }
    }
    assert_eq!(listing(dir.path()), ["r.bvh", "r_cm.bvh", "r_m.bvh"]);
}

// A target on the character's right has a negative x: `--target -0.2,…` is a value, as
// `plan --target` already takes it, not an unknown flag `-0`.
#[test]
fn negative_target_coordinates_are_values_not_flags() {
    let set = synth_set();
    let out = set.dir.path().join("o.bvh");
    let scene = repo().join("examples/bookshelf/scene.json");
    for args in [
        vec!["reach", "--target", "-0.2,1.1,0.4", "-o", utf8(&out)],
        vec![
            "synthesize",
            "--from",
            utf8(&set.clips[0]),
            "--target",
            "-0.2,1.1,0.4",
            "-o",
            utf8(&out),
        ],
        vec![
            "plan",
            "--scene",
            utf8(&scene),
            "--target",
            "-0.25,1.1,0.3",
            "-o",
            utf8(&out),
        ],
    ] {
        let o = kinergy(&args);
        assert_ne!(o.status.code(), Some(2), "{args:?}: {}", stderr(&o));
        assert!(out.exists(), "{args:?} wrote nothing");
        std::fs::remove_file(&out).expect("remove");
    }
}

// ---------------------------------------------------------------------------------------------
// 2. Bad input
// ---------------------------------------------------------------------------------------------

/// One bad invocation: what must be said, and what must not be written.
struct Case {
    what: &'static str,
    args: Vec<String>,
    /// Each must appear in the message.
    needles: Vec<String>,
    /// Must not exist afterwards.
    output: PathBuf,
}

// Each kind of bad input, on every subcommand it applies to: exit code 2, a message naming
// the problem, no output file, nothing at all left in the output folder.
#[test]
fn bad_input_exits_2_names_the_problem_and_leaves_nothing() {
    let set = synth_set();
    let inputs = set.dir.path().join("in");
    let out = set.dir.path().join("out");
    std::fs::create_dir(&inputs).expect("mkdir");
    std::fs::create_dir(&out).expect("mkdir");
    let good = set.clips[0].to_str().expect("utf-8").to_string();
    let put = |name: &str, bytes: &[u8]| {
        let p = inputs.join(name);
        std::fs::write(&p, bytes).expect("write");
        p.to_str().expect("utf-8").to_string()
    };

    // A clip with a word in place of a number on its second frame, and one cut in half.
    let source = std::fs::read_to_string(&set.clips[0]).expect("clip");
    let mut lines: Vec<String> = source.lines().map(String::from).collect();
    let frame_time = lines
        .iter()
        .position(|l| l.starts_with("Frame Time"))
        .expect("Frame Time");
    let garbled_line = frame_time + 3; // 1-based: the second frame
    let mut cells: Vec<&str> = lines[garbled_line - 1].split_whitespace().collect();
    cells[2] = "zz";
    lines[garbled_line - 1] = cells.join(" ");
    let garbled = put("garbled.bvh", (lines.join("\n") + "\n").as_bytes());
    let truncated = put("truncated.bvh", &source.as_bytes()[..source.len() / 2]);
    let missing = inputs
        .join("missing.bvh")
        .to_str()
        .expect("utf-8")
        .to_string();
    let missing_json = inputs
        .join("missing.json")
        .to_str()
        .expect("utf-8")
        .to_string();
    let not_json = put("not_json.json", b"{ \"format_version\": 1,\n  \"model\": ");
    let v99 = put(
        "v99.json",
        br#"{"format_version": 99, "model": "sa", "optimizer": {"kind": "svd", "rate": 4.0, "threshold": 0.01}, "dof_names": ["shoulder_swing_x", "shoulder_swing_y", "shoulder_twist", "elbow_flexion", "elbow_twist", "wrist_swing_x", "wrist_swing_y"], "bounds": {"gain": {"lower": -5, "upper": 5}, "slope": {"lower": 1, "upper": 10}, "offset": {"lower": 0, "upper": 20}}, "values": {"g": 1.0}}"#,
    );
    let bad_scene = put("scene.json", b"{\"format_version\": 1, \"objects\": [");
    let scene = repo()
        .join("examples/bookshelf/scene.json")
        .to_str()
        .expect("utf-8")
        .to_string();
    let inputs_before = listing(&inputs);

    let o_bvh = out.join("o.bvh");
    let o_json = out.join("p.json");
    let o_svg = out.join("speed.svg");
    let o_gif = out.join("ov.gif");
    let o_dir = out.join("cmp");
    let o_set = out.join("set");
    let chain = "Nope,Nada,Zip";
    let file_name = |p: &str| {
        Path::new(p)
            .file_name()
            .expect("name")
            .to_string_lossy()
            .into_owned()
    };
    let line = format!("line {garbled_line}");

    let mut cases: Vec<Case> = Vec::new();
    let mut add = |what: &'static str, args: &[&str], needles: &[&str], output: &Path| {
        cases.push(Case {
            what,
            args: args.iter().map(|s| s.to_string()).collect(),
            needles: needles.iter().map(|s| s.to_string()).collect(),
            output: output.to_path_buf(),
        });
    };
    let (b, j, s, g, d) = (
        utf8(&o_bvh),
        utf8(&o_json),
        utf8(&o_svg),
        utf8(&o_gif),
        utf8(&o_dir),
    );
    let (gb, tr, mi) = (garbled.as_str(), truncated.as_str(), missing.as_str());
    let (gn, tn) = (file_name(gb), file_name(tr));
    let (gn, tn) = (gn.as_str(), tn.as_str());
    let cmp = ["--budget", "40", "--no-baselines", "-o", d];

    // Missing files: the message gives the path.
    add("inspect missing", &["inspect", mi], &[mi], &o_bvh);
    add("convert missing", &["convert", mi, "-o", b], &[mi], &o_bvh);
    add("segment missing", &["segment", mi], &[mi], &o_bvh);
    add(
        "fit missing",
        &["fit", mi, "--model", "sa", "-o", j],
        &[mi],
        &o_json,
    );
    add(
        "synthesize missing",
        &["synthesize", "--from", mi, "-o", b],
        &[mi],
        &o_bvh,
    );
    add(
        "compare missing",
        &[&["compare", mi][..], &cmp].concat(),
        &[mi],
        &o_dir,
    );
    add(
        "plot missing",
        &["plot", "speed", mi, "-o", s],
        &[mi],
        &o_svg,
    );
    add("animate missing", &["animate", mi, "-o", g], &[mi], &o_gif);
    add(
        "reach --person missing",
        &["reach", "--target", "0.2,1,0.4", "--person", mi, "-o", b],
        &[mi],
        &o_bvh,
    );
    add(
        "plan --scene missing",
        &[
            "plan",
            "--scene",
            &missing_json,
            "--target",
            "-0.25,1.1,0.3",
            "-o",
            b,
        ],
        &[&missing_json],
        &o_bvh,
    );
    add(
        "synthesize --params missing",
        &[
            "synthesize",
            "--from",
            &good,
            "--params",
            &missing_json,
            "-o",
            b,
        ],
        &[&missing_json],
        &o_bvh,
    );

    // Malformed BVH: the message names the file and the line.
    add("inspect garbled", &["inspect", gb], &[gn, &line], &o_bvh);
    add("inspect truncated", &["inspect", tr], &[tn, "line"], &o_bvh);
    add(
        "convert garbled",
        &["convert", gb, "-o", b],
        &[gn, &line],
        &o_bvh,
    );
    add(
        "convert truncated",
        &["convert", tr, "-o", b],
        &[tn, "line"],
        &o_bvh,
    );
    add("segment garbled", &["segment", gb], &[gn, &line], &o_bvh);
    add(
        "fit garbled",
        &["fit", gb, "--model", "sa", "-o", j],
        &[gn, &line],
        &o_json,
    );
    add(
        "fit truncated",
        &["fit", tr, "--model", "sa", "-o", j],
        &[tn, "line"],
        &o_json,
    );
    add(
        "synthesize garbled",
        &["synthesize", "--from", gb, "-o", b],
        &[gn, &line],
        &o_bvh,
    );
    add(
        "compare garbled",
        &[&["compare", &good, gb][..], &cmp].concat(),
        &[gn, &line],
        &o_dir,
    );
    add(
        "plot garbled second",
        &["plot", "speed", &good, gb, "-o", s],
        &[gn, &line],
        &o_svg,
    );
    add(
        "animate garbled second",
        &["animate", &good, gb, "-o", g],
        &[gn, &line],
        &o_gif,
    );
    add(
        "animate truncated",
        &["animate", tr, "-o", g],
        &[tn, "line"],
        &o_gif,
    );
    add(
        "reach --person garbled",
        &["reach", "--target", "0.2,1,0.4", "--person", gb, "-o", b],
        &[gn, &line],
        &o_bvh,
    );
    add(
        "plan --scene not JSON",
        &[
            "plan",
            "--scene",
            &bad_scene,
            "--target",
            "-0.25,1.1,0.3",
            "-o",
            b,
        ],
        &["scene.json"],
        &o_bvh,
    );

    // Unknown joints: the message names the first unknown one.
    add(
        "inspect --chain",
        &["inspect", &good, "--chain", chain],
        &["Nope"],
        &o_bvh,
    );
    add(
        "segment --chain",
        &["segment", &good, "--chain", chain],
        &["Nope"],
        &o_bvh,
    );
    add(
        "fit --chain",
        &["fit", &good, "--model", "sa", "--chain", chain, "-o", j],
        &["Nope"],
        &o_json,
    );
    add(
        "synthesize --chain",
        &["synthesize", "--from", &good, "--chain", chain, "-o", b],
        &["Nope"],
        &o_bvh,
    );
    add(
        "compare --chain",
        &[&["compare", &good, "--chain", chain][..], &cmp].concat(),
        &["Nope"],
        &o_dir,
    );
    add(
        "plot --chain",
        &["plot", "speed", &good, "--chain", chain, "-o", s],
        &["Nope"],
        &o_svg,
    );

    // Bad parameters files: the message names the file (and the field for a wrong version).
    add(
        "synthesize --params wrong version",
        &["synthesize", "--from", &good, "--params", &v99, "-o", b],
        &["v99.json", "format_version"],
        &o_bvh,
    );
    add(
        "synthesize --params not JSON",
        &[
            "synthesize",
            "--from",
            &good,
            "--params",
            &not_json,
            "-o",
            b,
        ],
        &["not_json.json"],
        &o_bvh,
    );

    // Targets with NaN.
    add(
        "synthesize --target NaN",
        &[
            "synthesize",
            "--from",
            &good,
            "--target",
            "nan,1,0",
            "-o",
            b,
        ],
        &["--target", "nan"],
        &o_bvh,
    );
    add(
        "reach --target NaN",
        &["reach", "--target", "0,nan,0", "-o", b],
        &["--target", "nan"],
        &o_bvh,
    );
    add(
        "plan --target NaN",
        &["plan", "--scene", &scene, "--target", "nan,1,0.3", "-o", b],
        &["--target", "nan"],
        &o_bvh,
    );

    // Wrong output extensions for pictures.
    let jpg = out.join("speed.jpg");
    let bare = out.join("speed");
    let mp4 = out.join("ov.mp4");
    add(
        "plot -o .jpg",
        &["plot", "speed", &good, "-o", utf8(&jpg)],
        &["speed.jpg", ".svg or .png"],
        &jpg,
    );
    add(
        "plot -o without extension",
        &["plot", "speed", &good, "-o", utf8(&bare)],
        &[".svg or .png"],
        &bare,
    );
    add(
        "animate -o .mp4",
        &["animate", &good, "-o", utf8(&mp4)],
        &["ov.mp4", ".gif"],
        &mp4,
    );
    add(
        "animate --strip .jpg",
        &["animate", &good, "-o", g, "--strip", utf8(&jpg)],
        &["--strip", "speed.jpg"],
        &o_gif,
    );

    // synth's own settings.
    add(
        "synth --persons 0",
        &["synth", "-o", utf8(&o_set), "--persons", "0"],
        &["persons"],
        &o_set,
    );

    let mut problems = Vec::new();
    for case in &cases {
        let args: Vec<&str> = case.args.iter().map(String::as_str).collect();
        let o = kinergy(&args);
        let err = stderr(&o);
        let what = case.what;
        if o.status.code() != Some(2) {
            problems.push(format!(
                "{what}: exit code {:?}, not 2: {err}",
                o.status.code()
            ));
        }
        for needle in &case.needles {
            if !err.contains(needle.as_str()) {
                problems.push(format!(
                    "{what}: the message does not name `{needle}`: {err}"
                ));
            }
        }
        if err.contains("panicked") {
            problems.push(format!("{what}: panicked: {err}"));
        }
        if !o.stdout.is_empty() {
            problems.push(format!("{what}: printed on stdout: {}", text(&o.stdout)));
        }
        if case.output.exists() {
            problems.push(format!("{what}: {} exists", case.output.display()));
        }
        let left = listing(&out);
        if !left.is_empty() {
            let temporary = left.iter().any(|n| n.contains(".tmp"));
            problems.push(format!(
                "{what}: left {left:?} in the output folder{}",
                if temporary { " (temporary files)" } else { "" }
            ));
            for name in left {
                let p = out.join(name);
                let _ = std::fs::remove_dir_all(&p).or_else(|_| std::fs::remove_file(&p));
            }
        }
        if listing(&inputs) != inputs_before {
            problems.push(format!(
                "{what}: the input folder changed: {:?}",
                listing(&inputs)
            ));
        }
    }
    assert!(
        problems.is_empty(),
        "{} of {} bad inputs misbehaved:\n{}",
        problems.len(),
        cases.len(),
        problems.join("\n")
    );
}

// ---------------------------------------------------------------------------------------------
// 3. Help and terminal behaviour
// ---------------------------------------------------------------------------------------------

/// The subcommands a `--help` output lists under `Commands:` (without `help`).
fn listed_commands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| !l.trim().is_empty())
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(String::from)
        .collect()
}

/// Every leaf subcommand, as its words (`["plot", "speed"]`), found from the help output.
fn every_subcommand() -> Vec<Vec<String>> {
    let mut leaves = Vec::new();
    let mut stack = vec![Vec::<String>::new()];
    while let Some(path) = stack.pop() {
        let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
        args.push("--help");
        let o = kinergy(&args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
        let children = listed_commands(&stdout(&o));
        if children.is_empty() {
            leaves.push(path);
        } else {
            for c in children {
                let mut p = path.clone();
                p.push(c);
                stack.push(p);
            }
        }
    }
    leaves.sort();
    leaves
}

// Every subcommand's help ends with an example of itself, in the short and the long help.
#[test]
fn every_subcommand_help_has_an_example() {
    let subcommands = every_subcommand();
    let names: BTreeSet<String> = subcommands.iter().map(|p| p.join(" ")).collect();
    for expected in [
        "inspect",
        "convert",
        "segment",
        "synth",
        "fit",
        "compare",
        "synthesize",
        "reach",
        "plan",
        "plot speed",
        "animate",
    ] {
        assert!(
            names.contains(expected),
            "`{expected}` not listed: {names:?}"
        );
    }
    let mut missing = Vec::new();
    let mut groups: Vec<Vec<String>> = subcommands
        .iter()
        .filter(|p| p.len() > 1)
        .map(|p| p[..p.len() - 1].to_vec())
        .collect();
    groups.dedup();
    for path in subcommands.iter().chain(&groups) {
        let command = format!("kinergy {}", path.join(" "));
        for flag in ["--help", "-h"] {
            let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
            args.push(flag);
            let o = kinergy(&args);
            let help = stdout(&o);
            let example = help
                .find("Example")
                .map(|at| &help[at..])
                .filter(|tail| tail.contains(&command));
            if o.status.code() != Some(0) || example.is_none() {
                missing.push(format!("{command} {flag}"));
            }
        }
    }
    assert!(missing.is_empty(), "no example of itself in: {missing:?}");
}

// With NO_COLOR set (even beside CLICOLOR_FORCE), neither help nor errors hold ANSI escapes.
#[test]
fn no_color_means_no_ansi_escapes_in_help_or_errors() {
    let dir = tempfile::tempdir().expect("tempdir");
    let missing = dir.path().join("missing.bvh");
    let mut invocations: Vec<Vec<String>> = vec![vec!["--help".into()], vec![]];
    for path in every_subcommand() {
        let mut help = path.clone();
        help.push("--help".into());
        invocations.push(help);
        let mut short = path.clone();
        short.push("-h".into());
        invocations.push(short);
        // A usage error (clap's own message) for each.
        let mut wrong = path.clone();
        wrong.push("--no-such-flag".into());
        invocations.push(wrong);
    }
    let m = utf8(&missing).to_string();
    for args in [
        vec!["inspect", &m],
        vec!["fit", &m, "--model", "sa", "-o", "x.json"],
        vec!["plot", "speed", &m, "-o", "x.svg"],
        vec!["animate", &m, "-o", "x.gif"],
        vec!["reach", "--target", "0,nan,0", "-o", "x.bvh"],
        vec!["synth", "--persons", "many"],
        vec!["frobnicate"],
    ] {
        invocations.push(args.into_iter().map(String::from).collect());
    }
    let mut coloured = Vec::new();
    for env in [
        &[("NO_COLOR", "1")][..],
        &[
            ("NO_COLOR", "1"),
            ("CLICOLOR_FORCE", "1"),
            ("TERM", "xterm-256color"),
        ][..],
    ] {
        for args in &invocations {
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let o = kinergy_env(&args, env, &["CLICOLOR_FORCE"]);
            for (stream, bytes) in [("stdout", &o.stdout), ("stderr", &o.stderr)] {
                if text(bytes).contains("\x1b[") {
                    coloured.push(format!("{env:?} kinergy {}: {stream}", args.join(" ")));
                }
            }
        }
    }
    assert!(coloured.is_empty(), "ANSI escapes in: {coloured:#?}");
    // The invocations above touch nothing: no x.json etc. in the working directory.
    for name in ["x.json", "x.svg", "x.gif", "x.bvh"] {
        assert!(!Path::new(env!("CARGO_MANIFEST_DIR")).join(name).exists());
    }
}

// stderr is not a terminal here: a fit (and a compare) long enough to draw a progress bar
// leaves no bar, carriage return or escape on it, even with a colour terminal's TERM.
#[test]
fn progress_bars_stay_off_stderr_when_it_is_not_a_terminal() {
    let set = synth_set();
    let params = set.dir.path().join("p.json");
    let env = [("TERM", "xterm-256color")];
    let unset = ["NO_COLOR", "CLICOLOR_FORCE", "CLICOLOR"];
    let o = kinergy_env(
        &[
            "fit",
            utf8(&set.root),
            "--model",
            "sc",
            "--budget",
            "200",
            "-o",
            utf8(&params),
        ],
        &env,
        &unset,
    );
    succeed(&o, "fit");
    assert!(params.exists());
    let said = stdout(&o);
    assert!(!said.contains("\x1b[") && !said.contains('\r'), "{said:?}");
    let out = set.dir.path().join("cmp");
    let o = kinergy_env(
        &[
            "compare",
            utf8(&set.clips[0]),
            "--budget",
            "30",
            "--no-baselines",
            "--optimizers",
            "svd",
            "-o",
            utf8(&out),
        ],
        &env,
        &unset,
    );
    succeed(&o, "compare");
}
