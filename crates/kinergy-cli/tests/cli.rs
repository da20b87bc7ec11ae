//! End-to-end tests of the `kinergy` binary: outputs and their content, exit codes, and
//! that bad input never leaves a file behind.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn kinergy(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_kinergy"))
        .args(args)
        .output()
        .expect("run kinergy")
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data")
        .join(name)
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

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
        let o = kinergy(&args);
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(needle),
            "{args:?}: `{err}` does not mention {needle}"
        );
        assert!(!err.contains("panicked"), "{err}");
        assert!(!out.exists(), "{args:?} left an output file");
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
