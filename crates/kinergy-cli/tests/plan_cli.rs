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
