//! End-to-end tests of `kinergy plan` on the bookshelf example.

mod common;
use common::{kinergy, repo, text};

fn scene() -> String {
    repo()
        .join("examples/bookshelf/scene.json")
        .display()
        .to_string()
}

#[test]
fn relocation_writes_a_bvh_and_reports_the_book_at_its_destination() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("relocate.bvh");
    let out_s = out.to_str().expect("utf-8");
    let args = [
        "plan",
        "--scene",
        &scene(),
        "--task",
        "relocate",
        "--object",
        "blue_book",
        "--to",
        "-0.22,1.49,0.50",
        "--seed",
        "3",
        "-o",
        out_s,
        "--json",
    ];
    let o = kinergy(&args);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(report["triangles"], 11900);
    let names: Vec<&str> = report["phases"]
        .as_array()
        .expect("phases")
        .iter()
        .map(|p| p["name"].as_str().expect("name"))
        .collect();
    assert_eq!(
        names,
        [
            "reach", "approach", "close", "transfer", "open", "retreat", "return"
        ]
    );
    let end = &report["objects"][0]["end"]["position_m"];
    for (k, want) in [-0.22, 1.49, 0.50].iter().enumerate() {
        assert!(
            (end[k].as_f64().expect("number") - want).abs() < 1e-9,
            "{end}"
        );
    }
    let (clip, _) = kinergy_motion::read_clip(&out, &Default::default()).expect("read");
    assert_eq!(
        clip.frame_count() as u64,
        report["frames"].as_u64().expect("frames")
    );
    assert!(
        clip.skeleton()
            .joints()
            .iter()
            .any(|j| j.name == "RightIndex3")
    );
    // The motion starts and ends in the same posture, and the right hand moves in between.
    let s = clip.skeleton();
    let hand = s
        .joints()
        .iter()
        .position(|j| j.name == "RightHand")
        .expect("hand");
    let at = |f: usize| {
        s.world_positions(clip.frame(f).expect("frame"))
            .expect("fk")[hand]
    };
    let last = clip.frame_count() - 1;
    assert!((at(0) - at(last)).norm() < 1e-4);
    let transfer_end = report["phases"][3]["last_frame"].as_u64().expect("frame") as usize;
    assert!((at(transfer_end) - at(0)).norm() > 0.4);
    // Same seed, same bytes.
    let first = std::fs::read(&out).expect("read");
    let o = kinergy(&args);
    assert_eq!(o.status.code(), Some(0));
    assert_eq!(std::fs::read(&out).expect("read"), first);
}

#[test]
fn task_failures_exit_1_and_bad_input_exits_2_without_output() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("x.bvh");
    let out_s = out.to_str().expect("utf-8");
    let bad_scene = dir.path().join("bad.json");
    std::fs::write(
        &bad_scene,
        r#"{"format_version": 1, "objects": [{"name": "b", "shape": {"type": "box", "half_extents": [1, 1]}, "position": [0, 0, 0]}]}"#,
    )
    .expect("write");
    let bad_scene = bad_scene.display().to_string();
    let cases: [(Vec<&str>, i32, &str); 6] = [
        (vec!["--target", "-0.25,1.1,3"], 1, "unreachable"),
        (
            vec!["--target", "-0.25,1.1,0.3", "--scene", &bad_scene],
            2,
            "objects[0].shape.half_extents",
        ),
        (vec!["--target", "-0.25,NaN,0.3"], 2, "finite"),
        (vec!["--target", "1,2"], 2, "3 or 7 numbers"),
        (
            vec![
                "--task", "relocate", "--object", "unicorn", "--to", "0,1,0.5",
            ],
            2,
            "unicorn",
        ),
        (
            vec!["--task", "pull", "--object", "blue_book"],
            2,
            "not a drawer",
        ),
    ];
    for (extra, code, needle) in cases {
        let scene = scene();
        let mut args = vec!["plan", "--scene", &scene, "-o", out_s];
        if extra.contains(&"--scene") {
            args = vec!["plan", "-o", out_s];
        }
        args.extend(extra.iter().copied());
        let o = kinergy(&args);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
        assert!(err.contains(needle), "{args:?}: {err}");
        assert!(!out.exists(), "{args:?} left an output file");
    }
}

/// `plan --params`: the planned phases are played with the person's bell (reported), the
/// reach is finished by their synergy (reported, then a `settle` phase), the other phases are
/// those of a plan without, and a parameters file for another chain is refused before any
/// planning.
#[test]
fn plan_with_a_persons_params_plays_their_bell_and_synergy() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("p.bvh");
    let params = repo().join("tests/data/params/synthetic-p01-r09-sc.json");
    let run = |extra: &[&str]| {
        let mut args = vec![
            "plan".to_string(),
            "--scene".into(),
            scene(),
            "--task".into(),
            "relocate".into(),
            "--object".into(),
            "blue_book".into(),
            "--to".into(),
            "-0.22,1.49,0.50".into(),
            "--seed".into(),
            "3".into(),
            "-o".into(),
            out.to_str().expect("utf-8").into(),
            "--json".into(),
        ];
        args.extend(extra.iter().map(|s| s.to_string()));
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        kinergy(&args)
    };
    let o = run(&["--params", params.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let with: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(with["timing"]["warp"], "person");
    let peak = with["timing"]["peak"].as_f64().expect("peak");
    assert!(
        peak > 0.0 && peak < 1.0 && (peak - 0.5).abs() > 1e-3,
        "{peak}"
    );
    let o = run(&[]);
    let without: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(without["timing"]["warp"], "cubic");
    let names = |v: &serde_json::Value| -> Vec<String> {
        v["phases"]
            .as_array()
            .expect("phases")
            .iter()
            .map(|p| p["name"].as_str().expect("name").to_string())
            .collect()
    };
    let mut expected = names(&without);
    expected.insert(1, "settle".into());
    assert_eq!(names(&with), expected);
    let synergy = &with["phases"][0]["synergy"];
    let (from, length) = (
        synergy["from_m"].as_f64().expect("from_m"),
        synergy["path_m"].as_f64().expect("path_m"),
    );
    assert!(from >= 0.0 && from < length, "{synergy}");
    assert!(synergy["frames"].as_u64().expect("frames") > 10);
    assert!(synergy["distance_m"].as_f64().expect("distance") <= 0.005);
    assert!(without["phases"][0].get("synergy").is_none());
    assert!(
        with["phases"]
            .as_array()
            .expect("phases")
            .iter()
            .skip(1)
            .all(|p| p.get("synergy").is_none())
    );

    let text_params = std::fs::read_to_string(&params).expect("params");
    let mut v: serde_json::Value = serde_json::from_str(&text_params).expect("json");
    v["dof_names"] = serde_json::json!(["a", "b", "c"]);
    let bad = dir.path().join("bad.json");
    std::fs::write(&bad, v.to_string()).expect("write");
    std::fs::remove_file(&out).expect("remove");
    let o = run(&["--params", bad.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o.stderr));
    assert!(!out.exists());
}

fn levels_scene(name: &str) -> String {
    repo()
        .join("examples/levels")
        .join(name)
        .display()
        .to_string()
}

/// `--level auto` (the default) ends at the level each example scene was made for
/// (`examples/levels/`), and the report says which level solved the reach and how each one
/// tried went, with its time.
#[test]
fn plan_level_auto_ends_at_the_level_each_scene_was_made_for() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("reach.bvh");
    for (name, target, expected) in [
        ("open.json", "-0.2,1.2,0.4", vec![("ik", true)]),
        (
            "post.json",
            "-0.2,1.2,0.4",
            vec![("ik", false), ("straight", true)],
        ),
        (
            "board.json",
            "-0.2,1.15,0.35",
            vec![("ik", false), ("straight", false), ("planner", true)],
        ),
    ] {
        let scene = levels_scene(name);
        let target = format!("--target={target}");
        let o = kinergy(&[
            "plan",
            "--scene",
            &scene,
            &target,
            "-o",
            out.to_str().expect("utf-8"),
            "--json",
        ]);
        assert_eq!(o.status.code(), Some(0), "{name}: {}", text(&o.stderr));
        let report: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
        let levels: Vec<(&str, bool)> = report["levels"]
            .as_array()
            .expect("levels")
            .iter()
            .map(|l| {
                assert!(l["ms"].as_f64().expect("ms") > 0.0, "{l}");
                assert_eq!(l["motion_checked"], true, "{l}");
                (
                    l["level"].as_str().expect("level"),
                    l["solved"].as_bool().expect("solved"),
                )
            })
            .collect();
        assert_eq!(levels, expected, "{name}");
        assert_eq!(report["level"], expected.last().expect("a level").0);
        let planned = report["phases"][0].get("planned").is_some();
        assert_eq!(planned, report["level"] == "planner", "{name}");
    }
}

/// A forced level that fails exits 1 (as every task failure does) naming the level and why,
/// and writes nothing; a level for a task, or an unknown one, is bad input (exit 2).
#[test]
fn a_forced_level_that_fails_names_itself_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("x.bvh");
    let svg = dir.path().join("x.svg");
    let board = levels_scene("board.json");
    let shelf = scene();
    let cases: [(Vec<&str>, i32, &[&str]); 4] = [
        (
            vec![
                "--scene",
                &board,
                "--target=-0.2,1.15,0.35",
                "--level",
                "straight",
            ],
            1,
            &["level straight failed", "blocked", "board"],
        ),
        (
            vec!["--scene", &board, "--target=-0.2,1.0,0.3", "--level", "ik"],
            1,
            &["level ik failed", "in collision"],
        ),
        (
            vec![
                "--scene",
                &shelf,
                "--task",
                "grasp",
                "--object",
                "blue_book",
                "--level",
                "ik",
            ],
            2,
            &["--level", "a task's moves are planned"],
        ),
        (
            vec![
                "--scene",
                &board,
                "--target=-0.2,1.15,0.35",
                "--level",
                "rrt",
            ],
            2,
            &["rrt"],
        ),
    ];
    for (extra, code, needles) in cases {
        let mut args = vec!["plan", "-o", out.to_str().expect("utf-8")];
        args.extend(["--tree-svg", svg.to_str().expect("utf-8")]);
        args.extend(extra.iter().copied());
        let o = kinergy(&args);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(code), "{args:?}: {err}");
        for needle in needles {
            assert!(err.contains(needle), "{args:?}: {err}");
        }
        assert!(!out.exists() && !svg.exists(), "{args:?} left an output");
    }
}

/// The SVG lines drawn in `colour` (`#RRGGBB`).
fn lines_in(svg: &str, colour: &str) -> usize {
    let stroke = format!("stroke=\"{}\"", colour.to_ascii_uppercase());
    svg.lines()
        .filter(|l| {
            l.trim_start().starts_with("<polyline")
                && l.to_ascii_uppercase()
                    .contains(&stroke.to_ascii_uppercase())
        })
        .count()
}

/// `--tree-svg` (Kallmann's Fig. 4): a planner run writes an SVG whose tree edges — one line
/// each in its tree's colour — are the trees' nodes of the report less their roots, in every
/// planned phase; the same seed draws the same bytes; a reach solved without the planner
/// draws a note and no edge.
#[test]
fn tree_svg_draws_every_edge_of_both_trees() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("x.bvh");
    let svg = dir.path().join("trees.svg");
    let run = |args: &[&str]| {
        let mut all = vec![
            "plan",
            "-o",
            out.to_str().expect("utf-8"),
            "--tree-svg",
            svg.to_str().expect("utf-8"),
            "--json",
        ];
        all.extend(args);
        let o = kinergy(&all);
        assert_eq!(o.status.code(), Some(0), "{all:?}: {}", text(&o.stderr));
        let report: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
        let picture = std::fs::read_to_string(&svg).expect("the picture");
        (report, picture)
    };
    let board = levels_scene("board.json");
    let shelf = scene();
    let relocate = [
        "--scene",
        &shelf,
        "--task",
        "relocate",
        "--object",
        "blue_book",
        "--to=-0.22,1.49,0.50",
        "--seed",
        "3",
    ];
    let reach = [
        "--scene",
        &board,
        "--target=-0.2,1.15,0.35",
        "--level",
        "planner",
    ];
    for args in [&reach[..], &relocate[..]] {
        let (report, picture) = run(args);
        assert!(picture.starts_with("<svg") && picture.trim_end().ends_with("</svg>"));
        let nodes: Vec<[u64; 2]> = report["phases"]
            .as_array()
            .expect("phases")
            .iter()
            .filter_map(|p| p.get("planned"))
            .map(|p| {
                let n = &p["tree_nodes"];
                let pair = [n[0].as_u64().expect("n"), n[1].as_u64().expect("n")];
                assert_eq!(pair[0] + pair[1], p["nodes"].as_u64().expect("nodes"));
                pair
            })
            .collect();
        assert!(!nodes.is_empty(), "{args:?}");
        let start: u64 = nodes.iter().map(|n| n[0] - 1).sum();
        let goal: u64 = nodes.iter().map(|n| n[1] - 1).sum();
        assert!(start + goal > 0, "{args:?}: the trees grew");
        assert_eq!(lines_in(&picture, "#0072B2") as u64, start, "{args:?}");
        assert_eq!(lines_in(&picture, "#D55E00") as u64, goal, "{args:?}");
        // Same seed, same picture.
        let (_, again) = run(args);
        assert_eq!(again, picture, "{args:?}");
    }
    let (report, picture) = run(&[
        "--scene",
        &levels_scene("open.json"),
        "--target=-0.2,1.2,0.4",
    ]);
    assert_eq!(report["level"], "ik");
    assert!(picture.contains("solved by the ik level"));
    assert_eq!(
        lines_in(&picture, "#0072B2") + lines_in(&picture, "#D55E00"),
        0
    );
}

/// The issue's finding (43, item 5): `plan --target=-0.25,0.45,0.4`, a point on the bookshelf's
/// front between its boards at 0.10 m and 0.55 m, was beyond the arm's reach from the standing
/// posture (exit 1, "beyond reach by 0.404 m"). The planner now bends, twists and squats: exit
/// 0, the report names the body DoFs that moved and why, and the BVH's root and spine channels
/// move while a mid-height target's stay still (its report naming none). One or two rayon
/// threads write the same bytes.
#[test]
fn plan_moves_the_body_for_a_low_target_between_the_shelves() {
    let dir = tempfile::tempdir().expect("tempdir");
    let scene = scene();
    let run = |target: &str, out: &std::path::Path, threads: &str| {
        let target = format!("--target={target}");
        let o = std::process::Command::new(env!("CARGO_BIN_EXE_kinergy"))
            .args([
                "plan",
                "--scene",
                &scene,
                &target,
                "-o",
                out.to_str().expect("utf-8"),
                "--json",
            ])
            .env("RAYON_NUM_THREADS", threads)
            .output()
            .expect("run kinergy");
        assert_eq!(o.status.code(), Some(0), "{target}: {}", text(&o.stderr));
        let report: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
        let bvh = kinergy_bvh::read_file(out, &Default::default()).expect("read the BVH");
        (report, bvh)
    };
    // The largest change of any of `joint`'s channels over the motion.
    let moved = |bvh: &kinergy_bvh::Bvh, joint: &str| {
        let j = &bvh.joints[bvh.joint_index(joint).expect(joint)];
        let first = bvh.frame(0).expect("a frame");
        (0..bvh.frame_count)
            .flat_map(|f| {
                let frame = bvh.frame(f).expect("a frame");
                (0..j.channels.len()).map(move |c| {
                    let k = j.first_channel + c;
                    (frame[k] - first[k]).abs()
                })
            })
            .fold(0.0_f64, f64::max)
    };
    let low = dir.path().join("low.bvh");
    let (report, bvh) = run("-0.25,0.45,0.4", &low, "1");
    let dofs: Vec<&str> = report["body_dofs"]
        .as_array()
        .expect("body_dofs")
        .iter()
        .map(|d| d.as_str().expect("a name"))
        .collect();
    assert!(
        dofs.contains(&"squat") && dofs.contains(&"spine_swing"),
        "{dofs:?}"
    );
    let body = &report["body"];
    assert!(body["squat_m"].as_f64().expect("squat") > 0.1, "{body}");
    assert!(
        body["arm_alone"]
            .as_str()
            .expect("why")
            .contains("beyond reach by 0.404 m"),
        "{body}"
    );
    // Hips: position (cm) and rotation; the spine's joints; the knees.
    assert!(moved(&bvh, "Hips") > 10.0, "the root stays");
    for joint in ["Spine", "Chest", "RightLeg", "LeftLeg"] {
        assert!(moved(&bvh, joint) > 5.0, "{joint} stays");
    }
    let again = dir.path().join("low-2.bvh");
    let (report2, _) = run("-0.25,0.45,0.4", &again, "2");
    assert_eq!(report2["body"]["squat_m"], report["body"]["squat_m"]);
    assert_eq!(
        std::fs::read(&low).expect("read"),
        std::fs::read(&again).expect("read")
    );
    // A mid-height target the arm alone reaches: nothing but the arm moves.
    let mid = dir.path().join("mid.bvh");
    let (report, bvh) = run("-0.25,1.1,0.3", &mid, "2");
    assert_eq!(report["body_dofs"], serde_json::json!([]));
    assert!(report.get("body").is_none(), "{report}");
    for joint in [
        "Hips", "Spine", "Chest", "Neck", "RightLeg", "LeftLeg", "LeftArm",
    ] {
        assert_eq!(moved(&bvh, joint), 0.0, "{joint} moves");
    }
    assert!(moved(&bvh, "RightArm") > 5.0);
}
