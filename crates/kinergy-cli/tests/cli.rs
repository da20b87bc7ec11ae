//! End-to-end tests of the `kinergy` binary: outputs and their content, exit codes, and
//! that bad input never leaves a file behind.

mod common;
use common::{assert_bad_input, fixture, json, kinergy, stderr, stdout};

use std::path::Path;
use std::process::Command;

#[test]
fn inspect_json_describes_the_cmu_walk() {
    let path = fixture("cmu_12_01_walk.bvh");
    let out = kinergy(&["inspect", path.to_str().expect("utf-8"), "--json"]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!(v["joint_count"], 31);
    assert_eq!(v["end_site_count"], 7);
    assert_eq!(v["channel_count"], 96);
    assert_eq!(v["frame_count"], 524);
    assert_eq!(v["unit"], "cmu");
    assert_eq!(v["unit_guessed"], true);
    assert_eq!(v["root_reading"], "add");
    let arms = v["arms"].as_array().expect("arms");
    assert_eq!(arms.len(), 2);
    assert_eq!(arms[0]["side"], "right");
    assert_eq!(arms[0]["joints"][1], "RightArm");
    let upper = arms[0]["upper_arm_m"].as_f64().expect("length");
    assert!((0.2..0.35).contains(&upper), "upper arm {upper}");
    assert!(arms[0]["peak_hand_speed_m_s"].as_f64().expect("speed") > 0.0);
}

#[test]
fn inspect_text_names_units_root_reading_and_arms() {
    let path = fixture("006_14.bvh");
    let out = kinergy(&["inspect", path.to_str().expect("utf-8")]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let text = stdout(&out);
    assert!(text.contains("100 (+41 End Sites), 303 channels"), "{text}");
    assert!(text.contains("cm (guessed"), "{text}");
    assert!(text.contains("add to the OFFSET"), "{text}");
    assert!(
        text.contains(
            "CC_Base_R_Clavicle → CC_Base_R_Upperarm → CC_Base_R_Forearm → CC_Base_R_Hand"
        ),
        "{text}"
    );
}

#[test]
fn inspect_with_an_explicit_chain_and_a_forced_unit() {
    let path = fixture("cmu_12_01_walk.bvh");
    let out = kinergy(&[
        "inspect",
        path.to_str().expect("utf-8"),
        "--json",
        "--from-unit",
        "in",
        "--chain",
        "LeftShoulder,LeftArm,LeftForeArm,LeftHand",
    ]);
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).expect("json");
    assert_eq!(v["unit"], "in");
    assert_eq!(v["unit_guessed"], false);
    assert_eq!(v["arms"][0]["side"], "left");
    let upper = v["arms"][0]["upper_arm_m"].as_f64().expect("length");
    assert!((upper - 4.92 * 0.0254).abs() < 0.01, "{upper}");
}

#[test]
fn convert_round_trips_and_changes_units() {
    let dir = tempfile::tempdir().expect("tempdir");
    let input = fixture("cmu_12_01_walk.bvh");
    let out_m = dir.path().join("walk_m.bvh");
    let o = kinergy(&[
        "convert",
        input.to_str().expect("utf-8"),
        "-o",
        out_m.to_str().expect("utf-8"),
        "--unit",
        "m",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // Read back in meters: the hips are 16.2134 CMU units = 0.9152 m high in frame 0.
    let back = kinergy(&[
        "inspect",
        out_m.to_str().expect("utf-8"),
        "--json",
        "--from-unit",
        "m",
    ]);
    let v: serde_json::Value = serde_json::from_slice(&back.stdout).expect("json");
    assert_eq!(v["frame_count"], 524);
    assert_eq!(v["channel_count"], 96);
    let text = std::fs::read_to_string(&out_m).expect("written");
    let first = text
        .lines()
        .skip_while(|l| !l.starts_with("Frame Time"))
        .nth(1)
        .expect("frame 0");
    let y: f64 = first
        .split_whitespace()
        .nth(1)
        .expect("Y")
        .parse()
        .expect("number");
    assert!((y - 16.2134 * 0.0254 / 0.45).abs() < 1e-9, "{y}");
    // No temporary files left next to the output.
    let names: Vec<_> = std::fs::read_dir(dir.path())
        .expect("dir")
        .map(|e| e.expect("entry").file_name())
        .collect();
    assert_eq!(names.len(), 1, "{names:?}");
}

#[test]
fn bad_input_exits_2_names_the_problem_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out.bvh");
    let out_s = out.to_str().expect("utf-8");
    let malformed = dir.path().join("malformed.bvh");
    std::fs::write(
        &malformed,
        "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Xposition Yposition Zposition\n}\nMOTION\nFrames: 2\nFrame Time: 0.1\n0 0 0\n0 nan 0\n",
    )
    .expect("write");
    let truncated = dir.path().join("truncated.bvh");
    let full = std::fs::read(fixture("cmu_12_01_walk.bvh")).expect("fixture");
    std::fs::write(&truncated, &full[..full.len() / 2]).expect("write");
    let missing = dir.path().join("missing.bvh");
    let walk = fixture("cmu_12_01_walk.bvh");
    let walk = walk.to_str().expect("utf-8");
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["convert", missing.to_str().expect("utf-8"), "-o", out_s],
            "missing.bvh",
        ),
        (
            vec!["convert", malformed.to_str().expect("utf-8"), "-o", out_s],
            "line 11",
        ),
        (
            vec!["convert", truncated.to_str().expect("utf-8"), "-o", out_s],
            "truncated.bvh",
        ),
        (
            vec!["inspect", walk, "--chain", "LeftArm,Nope,LeftHand"],
            "Nope",
        ),
        (
            vec!["convert", walk, "-o", out_s, "--unit", "furlong"],
            "furlong",
        ),
    ];
    for (args, needle) in cases {
        assert_bad_input(&args, needle, &out);
    }
}

#[test]
fn a_closed_pipe_is_not_a_crash() {
    use std::io::Read;
    use std::process::Stdio;
    let mut child = Command::new(env!("CARGO_BIN_EXE_kinergy"))
        .args(["inspect", fixture("006_14.bvh").to_str().expect("utf-8")])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("spawn");
    drop(child.stdout.take());
    let mut err = String::new();
    child
        .stderr
        .take()
        .expect("stderr")
        .read_to_string(&mut err)
        .expect("read");
    let status = child.wait().expect("wait");
    assert!(!err.contains("panicked"), "{err}");
    assert!(status.code().is_some_and(|c| c == 0), "{status:?} {err}");
}

/// Reads a BVH file the way the library does (SI units, radians).
fn read_clip(path: &Path) -> kinergy_motion::Clip {
    kinergy_motion::read_clip(path, &Default::default())
        .expect("read clip")
        .0
}

fn point(v: &serde_json::Value) -> [f64; 3] {
    let a = v.as_array().expect("array");
    [0, 1, 2].map(|i| a[i].as_f64().expect("number"))
}

/// The world position of `joint` on the clip's last frame, by forward kinematics of the file.
fn last_position(clip: &kinergy_motion::Clip, joint: &str) -> [f64; 3] {
    position(clip, joint, clip.frame_count() - 1)
}

/// The world position of `joint` on `frame`, by forward kinematics of the file.
fn position(clip: &kinergy_motion::Clip, joint: &str, frame: usize) -> [f64; 3] {
    let j = clip.skeleton().require_joint(joint).expect("joint");
    let p = clip.trajectory(&[j]).expect("trajectory").frame(frame)[0];
    [p.x, p.y, p.z]
}

fn distance(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

// The synthesized file, read back independently: the same skeleton, the report's frame count,
// the hand (the arm's end joint) within ε of the target on the last frame by FK of the
// written channels, and every channel outside the arm exactly the capture's (the torso is
// replayed, not synthesized).
#[test]
fn synthesize_writes_the_reach_on_the_capture_skeleton() {
    let dir = tempfile::tempdir().expect("tempdir");
    let input = fixture("006_14.bvh");
    let out = dir.path().join("reach.bvh");
    // JT with the default rate ends 9.4 mm short after 10 s on this capture (exit 1); the
    // others reach.
    for optimizer in ["njt", "svd", "dls"] {
        let o = kinergy(&[
            "synthesize",
            "--from",
            input.to_str().expect("utf-8"),
            "--optimizer",
            optimizer,
            "--model",
            "sc",
            "-o",
            out.to_str().expect("utf-8"),
            "--unit",
            "m",
            "--json",
        ]);
        assert_eq!(o.status.code(), Some(0), "{optimizer}: {}", stderr(&o));
        let report = json(&o);
        assert_eq!(report["stop"], "reached", "{optimizer}: {report}");
        let captured = read_clip(&input);
        let synthesized = read_clip(&out);
        let names = |c: &kinergy_motion::Clip| {
            c.skeleton()
                .joints()
                .iter()
                .map(|j| j.name.clone())
                .collect::<Vec<_>>()
        };
        assert_eq!(names(&captured), names(&synthesized));
        assert_eq!(
            synthesized.frame_count() as u64,
            report["frames"].as_u64().expect("frames")
        );
        let arm: Vec<String> = report["arm"]
            .as_array()
            .expect("arm")
            .iter()
            .map(|v| v.as_str().expect("name").to_string())
            .collect();
        let target = point(&report["target_m"]);
        let error = distance(
            last_position(&synthesized, arm.last().expect("end")),
            target,
        );
        assert!(
            error < 0.005 + 1e-9,
            "{optimizer}: hand {error} m from the target"
        );
        assert!(
            (error - report["final_error_m"].as_f64().expect("error")).abs() < 1e-9,
            "{optimizer}: the report says {}, the file {error}",
            report["final_error_m"]
        );
        // The capture's final hand position is the default target.
        let captured_end = last_position(&captured, arm.last().expect("end"));
        assert!(distance(captured_end, target) < 1e-9);
        // Every joint off the arm moves as captured (compared as local transforms: the written
        // root carries its OFFSET in its position channels, so its DoF values differ).
        let skeleton = synthesized.skeleton();
        let arm_joints: Vec<usize> = arm[1..]
            .iter()
            .map(|n| skeleton.require_joint(n).expect("joint"))
            .collect();
        let frames = synthesized.frame_count().min(captured.frame_count());
        for f in 0..frames {
            let (a, b) = (
                captured.frame(f).expect("frame"),
                synthesized.frame(f).expect("frame"),
            );
            for j in (0..skeleton.joint_count()).filter(|j| !arm_joints.contains(j)) {
                let (ta, tb) = (
                    captured.skeleton().local_transform(j, a),
                    skeleton.local_transform(j, b),
                );
                assert!(
                    (ta.to_homogeneous() - tb.to_homogeneous()).amax() < 1e-9,
                    "{optimizer}: frame {f}, joint {} changed",
                    skeleton.joint(j).name
                );
            }
        }
    }
}

// An explicit target is honored; an unreachable one ends at exit code 1 with the motion
// still written, ended as close as the arm gets (the shoulder–target distance minus the
// arm's length, within a few centimeters: the shoulder rides on the replayed torso).
#[test]
fn synthesize_target_reachable_and_unreachable() {
    let dir = tempfile::tempdir().expect("tempdir");
    let input = fixture("006_14.bvh");
    let input = input.to_str().expect("utf-8");
    let out = dir.path().join("reach.bvh");
    let out_s = out.to_str().expect("utf-8");
    let o = kinergy(&[
        "synthesize",
        "--from",
        input,
        "--target",
        "0.35,1.2,0.2",
        "-o",
        out_s,
        "--json",
        "--stop-at-reach",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let report = json(&o);
    assert_eq!(point(&report["target_m"]), [0.35, 1.2, 0.2]);
    let arm = report["arm"].as_array().expect("arm");
    let end = arm.last().and_then(|v| v.as_str()).expect("end");
    let synthesized = read_clip(&out);
    assert!(distance(last_position(&synthesized, end), [0.35, 1.2, 0.2]) < 0.005);
    assert_eq!(
        synthesized.frame_count() as u64,
        report["frames"].as_u64().expect("frames")
    );
    std::fs::remove_file(&out).expect("remove");

    // 1.5 m straight ahead of the shoulder (fixed on its first-frame place) at its height,
    // ahead being up × the line from the left shoulder to the right: beyond the arm's reach,
    // inside its limits (the arm swung forward). The arm straightens toward it.
    let captured = read_clip(&fixture("006_14.bvh"));
    let shoulder = position(&captured, arm[1].as_str().expect("name"), 0);
    let other = position(&captured, "CC_Base_L_Upperarm", 0);
    let (lx, lz) = (shoulder[0] - other[0], shoulder[2] - other[2]);
    let across = (lx * lx + lz * lz).sqrt();
    // up × (lx, 0, lz) = (lz, 0, -lx).
    let ahead = [lz / across, 0.0, -lx / across];
    let far: Vec<String> = (0..3)
        .map(|i| (shoulder[i] + 1.5 * ahead[i]).to_string())
        .collect();
    let far = far.join(",");
    let o = kinergy(&[
        "synthesize",
        "--from",
        input,
        "--target",
        &far,
        "-o",
        out_s,
        "--json",
        "--fixed-base",
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    let report = json(&o);
    assert_eq!(report["stop"], "stalled", "{report}");
    assert!(out.exists(), "the closest motion is still written");
    let gap = report["shoulder_to_target_m"].as_f64().expect("distance")
        - report["arm_length_m"].as_f64().expect("length");
    let error = report["final_error_m"].as_f64().expect("error");
    assert!(
        (error - gap).abs() < 1e-3,
        "ended {error} m away, the fixed shoulder is {gap} m beyond reach"
    );
}

// A parameters file is read and honored: S_A with every gain 0 freezes the arm (exit 1, the
// hand never gets closer), the neutral S_A from the same file format reaches.
#[test]
fn synthesize_reads_a_parameters_file() {
    use kinergy_solver::{Model, OptimizerKind, ParamSpace, ParamsFile};
    let dir = tempfile::tempdir().expect("tempdir");
    let input = fixture("006_14.bvh");
    let input = input.to_str().expect("utf-8");
    let out = dir.path().join("reach.bvh");
    let out_s = out.to_str().expect("utf-8");
    let names: Vec<String> = kinergy_motion::Chain::arm(0.3, 0.25, 0.1)
        .expect("arm")
        .dof_names()
        .map(String::from)
        .collect();
    let space = ParamSpace::new(Model::Sa, &names, Default::default()).expect("space");
    for (gain, code) in [(1.0, 0), (0.0, 1)] {
        let file = ParamsFile::new(&space, OptimizerKind::Svd.default_optimizer(), &[gain])
            .expect("params");
        let params = dir.path().join(format!("g{gain}.json"));
        file.write(&params).expect("write");
        let o = kinergy(&[
            "synthesize",
            "--from",
            input,
            "--params",
            params.to_str().expect("utf-8"),
            "-o",
            out_s,
            "--json",
        ]);
        assert_eq!(o.status.code(), Some(code), "g = {gain}: {}", stderr(&o));
        let report = json(&o);
        assert_eq!(report["model"], "sa");
        if gain == 0.0 {
            assert!(
                report["final_error_m"].as_f64().expect("error") > 0.05,
                "{report}"
            );
        }
    }
}

// Each kind of bad input to `synthesize` exits 2, names the problem and writes nothing.
#[test]
fn synthesize_bad_input_exits_2_and_writes_nothing() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("out.bvh");
    let out_s = out.to_str().expect("utf-8");
    let input = fixture("006_14.bvh");
    let input = input.to_str().expect("utf-8");
    let write = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).expect("write");
        p.to_str().expect("utf-8").to_string()
    };
    let not_json = write("not_json.json", "{ \"format_version\": 1,\n  \"model\": ");
    let wrong_version = write(
        "v9.json",
        r#"{"format_version": 9, "model": "sa", "optimizer": {"kind": "svd", "rate": 4.0, "threshold": 0.01}, "dof_names": [], "bounds": {"gain": {"lower": -5, "upper": 5}, "slope": {"lower": 1, "upper": 10}, "offset": {"lower": 0, "upper": 20}}, "values": {}}"#,
    );
    let out_of_bounds = write(
        "oob.json",
        r#"{"format_version": 1, "model": "sa", "optimizer": {"kind": "svd", "rate": 4.0, "threshold": 0.01}, "dof_names": ["shoulder_swing_x", "shoulder_swing_y", "shoulder_twist", "elbow_flexion", "elbow_twist", "wrist_swing_x", "wrist_swing_y"], "bounds": {"gain": {"lower": -5, "upper": 5}, "slope": {"lower": 1, "upper": 10}, "offset": {"lower": 0, "upper": 20}}, "values": {"g": 7.5}}"#,
    );
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec!["--target", "0,nan,0"], "nan"),
        (vec!["--target", "0.3,1.2"], "three"),
        (vec!["--target", "0.3,1.2,abc"], "abc"),
        (vec!["--params", &not_json], "not_json.json"),
        (vec!["--params", &wrong_version], "format_version"),
        (vec!["--params", &out_of_bounds], "`g`"),
        (vec!["--params", "/nonexistent/p.json"], "p.json"),
        (vec!["--model", "sf"], "sf"),
        (vec!["--tolerance=-1"], "tolerance"),
        (
            vec!["--chain", "CC_Base_R_Upperarm,Nope,CC_Base_R_Hand"],
            "Nope",
        ),
    ];
    for (extra, needle) in cases {
        let mut args = vec!["synthesize", "--from", input, "-o", out_s];
        args.extend(&extra);
        let o = kinergy(&args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {err}");
        assert!(
            err.contains(needle),
            "{extra:?}: `{err}` does not mention {needle}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert!(!out.exists(), "{extra:?} left an output file");
    }
}
