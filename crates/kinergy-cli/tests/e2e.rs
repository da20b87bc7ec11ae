//! End-to-end tests of every `kinergy` subcommand on a small synthetic set (one person,
//! three reaches, made afresh by `kinergy synth` in each test): the files written and their
//! content, pictures checked for their format, size and number of series or frames. Bad input
//! and the terminal are in `e2e_input.rs`.

mod common;
mod e2e_support;
use e2e_support::*;

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
            "summary.md",
            "view.html"
        ]
    );

    let csv = std::fs::read_to_string(out.join("results.csv")).expect("results.csv");
    let mut lines = csv.lines();
    assert_eq!(
        lines.next(),
        Some("clip,arm,onset,end,model,optimizer,method,distance_m,frames,evaluations,seconds")
    );
    // The reach's arm, onset and end (columns 1–3) aside, the columns as they always were.
    let rows: Vec<Vec<&str>> = lines
        .map(|l| {
            let mut r: Vec<&str> = l.split(',').collect();
            r.drain(1..4);
            r
        })
        .collect();
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
