//! `kinergy inspect` says how a capture was read: its up axis, why the root's position
//! channels read as they do, and the one-frame glitches it holds.

mod common;
use common::{fixture, json, kinergy, stderr, stdout};

use std::path::Path;

/// A standing figure in centimeters, Z up: head 180 cm above the feet's End Sites.
const ZUP: &str = "HIERARCHY
ROOT Hips
{
  OFFSET 0 0 90
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Spine
  {
    OFFSET 0 0 20
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT Head
    {
      OFFSET 0 0 50
      CHANNELS 3 Zrotation Xrotation Yrotation
      End Site
      {
        OFFSET 0 0 20
      }
    }
  }
  JOINT LeftUpLeg
  {
    OFFSET 10 0 -5
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT LeftFoot
    {
      OFFSET 0 0 -80
      CHANNELS 3 Zrotation Xrotation Yrotation
      End Site
      {
        OFFSET 0 -10 -5
      }
    }
  }
  JOINT RightUpLeg
  {
    OFFSET -10 0 -5
    CHANNELS 3 Zrotation Xrotation Yrotation
    JOINT RightFoot
    {
      OFFSET 0 0 -80
      CHANNELS 3 Zrotation Xrotation Yrotation
      End Site
      {
        OFFSET 0 -10 -5
      }
    }
  }
}
MOTION
Frames: 3
Frame Time: 0.0333333
0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0
1 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0
2 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0
";

fn utf8(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

fn f(v: &serde_json::Value) -> f64 {
    v.as_f64().unwrap_or_else(|| panic!("not a number: {v}"))
}

#[test]
fn inspect_detects_a_z_up_file_and_obeys_up() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("zup.bvh");
    std::fs::write(&path, ZUP).expect("write");

    let o = kinergy(&["inspect", utf8(&path), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v = json(&o);
    assert_eq!(v["up_axis"], "z");
    assert_eq!(v["up_detected"], true);
    assert_eq!(v["up_basis"], "joint names");
    // Read Y up: 1.8 m from the feet on y = 0 to the top of the head.
    approx::assert_relative_eq!(f(&v["first_frame_height_m"]), 1.8, epsilon = 1e-9);
    approx::assert_relative_eq!(f(&v["first_frame_lowest_m"]), 0.0, epsilon = 1e-9);
    assert_eq!(v["root_reading"], "add");
    // Added, the feet stand on y = 0; replaced, 90 cm below it.
    assert_eq!(v["root_reading_reason"]["basis"], "nearer the ground");

    let o = kinergy(&["inspect", utf8(&path)]);
    let text = stdout(&o);
    assert!(
        text.contains("up         z (detected from the joint names"),
        "{text}"
    );

    // Told Y up, the body lies along Z: barely 15 cm tall along Y.
    for (given, name) in [("y", "y"), ("-z", "-z")] {
        let o = kinergy(&["inspect", utf8(&path), "--json", "--up", given]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let v = json(&o);
        assert_eq!(
            (v["up_axis"].as_str(), v["up_detected"].as_bool()),
            (Some(name), Some(false))
        );
        assert_eq!(v["up_basis"], "given");
    }
    let o = kinergy(&["inspect", utf8(&path), "--json", "--up", "y"]);
    assert!(f(&json(&o)["first_frame_height_m"]) < 0.2);

    let o = kinergy(&["inspect", utf8(&path), "--up", "w"]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("up axis"), "{}", stderr(&o));
}

#[test]
fn inspect_says_why_the_character_creator_root_adds() {
    let path = fixture("006_14.bvh");
    let o = kinergy(&["inspect", utf8(&path), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v = json(&o);
    let why = &v["root_reading_reason"];
    assert_eq!(v["root_reading"], "add");
    assert_eq!(why["basis"], "nearer the ground");
    // OFFSET 105.2 cm: added, the feet are 9 cm up; replaced, 96 cm under the floor.
    approx::assert_relative_eq!(
        f(&why["lowest_if_added_m"]) - f(&why["lowest_if_replaced_m"]),
        1.052142,
        epsilon = 1e-6
    );
    assert!(
        (0.05..0.12).contains(&f(&why["lowest_if_added_m"])),
        "{why}"
    );
    let text = stdout(&kinergy(&["inspect", utf8(&path)]));
    assert!(
        text.contains("the lowest joint is 9.1 cm above y = 0 added, 96.1 cm below y = 0 replaced"),
        "{text}"
    );
}

/// The committed capture `name` with `meters` added to the root's first channel (Xposition)
/// in frame `frame` alone, written in `dir`.
fn with_root_glitch(name: &str, frame: usize, units: f64, dir: &Path) -> std::path::PathBuf {
    let text = std::fs::read_to_string(fixture(name)).expect("read");
    let mut lines: Vec<String> = text.lines().map(str::to_string).collect();
    let first = lines
        .iter()
        .position(|l| l.starts_with("Frame Time"))
        .expect("frame time")
        + 1;
    let row = &mut lines[first + frame];
    let (x, rest) = row.trim_start().split_once(' ').expect("values");
    let x: f64 = x.parse().expect("number");
    *row = format!("{} {rest}", x + units);
    let out = dir.join(name);
    std::fs::write(&out, lines.join("\n") + "\n").expect("write");
    out
}

#[test]
fn inspect_reports_an_injected_glitch_and_its_hand_speed_ignores_it() {
    let dir = tempfile::tempdir().expect("tempdir");
    // 22 cm in CMU units (1/0.45 inch).
    let bad = with_root_glitch(
        "cmu_12_01_walk.bvh",
        200,
        0.22 / (2.54 / 0.45 / 100.0),
        dir.path(),
    );
    let o = kinergy(&["inspect", utf8(&bad), "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v = json(&o);
    let glitches = v["glitches"].as_array().expect("glitches");
    assert_eq!(glitches.len(), 1, "{glitches:?}");
    assert_eq!(glitches[0]["frame"], 200);
    assert_eq!(glitches[0]["joint"], "Hips");
    approx::assert_relative_eq!(f(&glitches[0]["size_m"]), 0.22, epsilon = 0.005);
    let said = stdout(&kinergy(&["inspect", utf8(&bad)]));
    assert!(
        said.contains("frame 200 (1.667 s) Hips jumps 22."),
        "{said}"
    );
    let clean = json(&kinergy(&[
        "inspect",
        utf8(&fixture("cmu_12_01_walk.bvh")),
        "--json",
    ]));
    assert_eq!(clean["glitches"].as_array().map(Vec::len), Some(0));

    // The Character Creator shot (60 fps, hands peaking at 4.8–5.1 m/s): a 22 cm jump of
    // the body would read as a 6.6 m/s spike; the peak ignores it. The file's own thumb
    // glitch (frame 76) is reported too.
    let bad = with_root_glitch("006_14.bvh", 100, 22.0, dir.path());
    let v = json(&kinergy(&["inspect", utf8(&bad), "--json"]));
    let c = json(&kinergy(&[
        "inspect",
        utf8(&fixture("006_14.bvh")),
        "--json",
    ]));
    let frames = |j: &serde_json::Value| -> Vec<(u64, String)> {
        j["glitches"]
            .as_array()
            .expect("glitches")
            .iter()
            .map(|g| {
                (
                    g["frame"].as_u64().expect("frame"),
                    g["joint"].as_str().expect("joint").to_string(),
                )
            })
            .collect()
    };
    assert_eq!(frames(&c), [(76, "CC_Base_L_Thumb2".to_string())]);
    assert_eq!(
        frames(&v),
        [
            (76, "CC_Base_L_Thumb2".to_string()),
            (100, "CC_Base_Hip".to_string())
        ]
    );
    for arm in 0..2 {
        approx::assert_relative_eq!(
            f(&v["arms"][arm]["peak_hand_speed_m_s"]),
            f(&c["arms"][arm]["peak_hand_speed_m_s"]),
            max_relative = 1e-9
        );
    }
}

#[test]
fn convert_up_out_y_writes_a_y_up_file_with_the_same_body() {
    let dir = tempfile::tempdir().expect("tempdir");
    let path = dir.path().join("zup.bvh");
    std::fs::write(&path, ZUP).expect("write");
    let kept = dir.path().join("kept.bvh");
    let turned = dir.path().join("turned.bvh");
    let o = kinergy(&["convert", utf8(&path), "-o", utf8(&kept)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let o = kinergy(&["convert", utf8(&path), "--up-out", "y", "-o", utf8(&turned)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));

    // Written as read, the file stays Z-up; turned, it is Y-up and read as such without
    // detection's help: the same 1.8 m body standing on y = 0.
    let o = kinergy(&["inspect", utf8(&kept), "--json"]);
    assert_eq!(json(&o)["up_axis"], "z");
    for args in [
        vec!["inspect", utf8(&turned), "--json"],
        vec!["inspect", utf8(&turned), "--json", "--up", "y"],
    ] {
        let o = kinergy(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let v = json(&o);
        assert_eq!(v["up_axis"], "y");
        approx::assert_relative_eq!(f(&v["first_frame_height_m"]), 1.8, epsilon = 1e-9);
        approx::assert_relative_eq!(f(&v["first_frame_lowest_m"]), 0.0, epsilon = 1e-9);
    }
}

/// The sweep's root position of 1e300 (and ±1e308) in one frame: `inspect` said "Hips
/// jumps inf cm" and `fit` "sa inf mm", both exit 0. Now the capture is refused as it is
/// read, naming the file, the line and the channel.
#[test]
fn a_root_position_no_capture_holds_is_refused_on_reading() {
    let dir = tempfile::tempdir().expect("tempdir");
    for (i, units) in [1e300, 1e308, -1e308].into_iter().enumerate() {
        let sub = dir.path().join(i.to_string());
        std::fs::create_dir(&sub).expect("folder");
        let bad = with_root_glitch("cmu_12_01_walk.bvh", 48, units, &sub);
        let params = sub.join("o.json");
        for args in [
            vec!["inspect", utf8(&bad)],
            vec![
                "fit",
                utf8(&bad),
                "--model",
                "sa",
                "--budget",
                "20",
                "-o",
                utf8(&params),
            ],
        ] {
            let o = kinergy(&args);
            let err = stderr(&o);
            assert_eq!(o.status.code(), Some(2), "{units} {args:?}: {err}");
            assert!(
                err.contains("cmu_12_01_walk.bvh")
                    && err.contains("(Hips Xposition) is beyond ±1e9")
                    && !stdout(&o).contains("inf"),
                "{units} {args:?}: {err}"
            );
            assert!(!params.exists());
        }
    }
}
