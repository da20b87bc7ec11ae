//! `kinergy from-positions`: a capture's joint positions, written as CSV the ways the command
//! reads them (long and wide, meters Y up and millimeters Z up), come back as BVH whose own
//! forward kinematics puts every joint within 1 mm of the input, its arms past the human limits
//! as the capture's are; bad tables name the line.

mod common;
#[path = "../../../tests/support/keypoints.rs"]
mod keypoints;
use common::{fixture, json, kinergy, s, stderr};

use std::fmt::Write as _;
use std::path::Path;

/// The fixture's names and world positions per frame (Kinergy's FK).
fn capture() -> (Vec<String>, Vec<Vec<[f64; 3]>>) {
    let (clip, _) =
        kinergy_motion::read_clip(&fixture("006_14.bvh"), &Default::default()).expect("read");
    let names: Vec<String> = clip
        .skeleton()
        .joints()
        .iter()
        .map(|j| j.name.clone())
        .collect();
    let world = clip.world_positions().expect("fk");
    let frames = world
        .chunks(names.len())
        .map(|f| f.iter().map(|p| [p.x, p.y, p.z]).collect())
        .collect();
    (names, frames)
}

fn positions_of(path: &Path) -> Vec<[f64; 3]> {
    let (clip, _) = kinergy_motion::read_clip(path, &Default::default()).expect("read output");
    clip.world_positions()
        .expect("fk")
        .iter()
        .map(|p| [p.x, p.y, p.z])
        .collect()
}

fn worst(a: &[[f64; 3]], b: &[[f64; 3]]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(p, q)| {
            ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
        })
        .fold(0.0, f64::max)
}

#[test]
fn a_captures_positions_come_back_long_and_wide_in_any_unit_and_up_axis() {
    let dir = tempfile::tempdir().expect("tmp");
    let (names, frames) = capture();
    let truth: Vec<[f64; 3]> = frames.iter().flatten().copied().collect();
    // Long, meters, Y up.
    let mut long = String::from("frame,joint,x,y,z\n");
    for (f, frame) in frames.iter().enumerate() {
        for (name, p) in names.iter().zip(frame) {
            let _ = writeln!(long, "{f},{name},{},{},{}", p[0], p[1], p[2]);
        }
    }
    // Wide, millimeters, Z up (Y-up (x, y, z) is Z-up (x, -z, y)).
    let mut wide = String::from("frame");
    for name in &names {
        let _ = write!(wide, ",{name}_x,{name}_y,{name}_z");
    }
    wide.push('\n');
    for (f, frame) in frames.iter().enumerate() {
        let _ = write!(wide, "{f}");
        for p in frame {
            let _ = write!(wide, ",{},{},{}", 1e3 * p[0], -1e3 * p[2], 1e3 * p[1]);
        }
        wide.push('\n');
    }
    let template = fixture("006_14.bvh");
    // The wide mm Z-up table twice: given, and detected (the body's size says mm, the names
    // say Z up) — the report says which.
    let cases = [
        (long, vec![], ("m", "y")),
        (wide.clone(), vec!["--unit", "mm", "--up", "z"], ("mm", "z")),
        (wide, vec![], ("mm", "z")),
    ];
    for (text, extra, (unit, up)) in cases {
        let guessed = extra.is_empty();
        let input = dir.path().join("p.csv");
        std::fs::write(&input, text).expect("write");
        let out = dir.path().join("out.bvh");
        let mut args = vec![
            "from-positions",
            s(&input),
            "--skeleton",
            s(&template),
            "--frame-rate",
            "60",
            "-o",
            s(&out),
            "--json",
        ];
        args.extend(extra);
        let o = kinergy(&args);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let report = json(&o);
        assert_eq!(report["frames"], frames.len());
        assert_eq!(report["joints"], names.len());
        let back = positions_of(&out);
        let e = worst(&back, &truth);
        assert!(e < 1e-3, "{args:?}: a joint {e} m off");
        assert!(report["max_error_m"].as_f64().expect("error") < 1e-3);
        assert_eq!(
            (report["unit"].as_str(), report["up"].as_str()),
            (Some(unit), Some(up))
        );
        assert_eq!(report["unit_guessed"], guessed, "{report}");
        // The rotations made read as the capture's own do against the arm's human limits:
        // the same arms past them, by the same DoFs (the capture's right shoulder twists past
        // its ±90°).
        let (original, _) =
            kinergy_motion::read_clip(&fixture("006_14.bvh"), &Default::default()).expect("read");
        let expected = kinergy_solver::arms_beyond_limits(&original).expect("limits");
        assert!(!expected.is_empty());
        assert_eq!(
            report["arms_beyond_limits"],
            serde_json::to_value(&expected).expect("json"),
            "{report}"
        );
    }
}

/// Keypoints without hands or feet: the capture's joints as Human3.6M's 17, whose wrists,
/// ankles and head are leaves (End Sites in the BVH written). Each arm ends at its End Site,
/// so `inspect` names both arms, the report reads the arms past the human limits as the
/// capture's own rig reads them, and `fit --arm auto` fits the take's reach of each arm; the
/// body is retargeted and measured for a character.
#[test]
fn keypoints_without_hands_or_feet_are_fitted_retargeted_and_measured() {
    let dir = tempfile::tempdir().expect("tmp");
    let (names, frames) = capture();
    let mut long = String::from("frame,joint,x,y,z\n");
    for (f, frame) in frames.iter().enumerate() {
        for (keypoint, joint) in keypoints::H36M_FROM_CC {
            let p = frame[names.iter().position(|n| n == joint).expect(joint)];
            let _ = writeln!(long, "{f},{keypoint},{},{},{}", p[0], p[1], p[2]);
        }
    }
    let input = dir.path().join("keypoints.csv");
    std::fs::write(&input, long).expect("write");
    let out = dir.path().join("keypoints.bvh");
    let o = kinergy(&[
        "from-positions",
        s(&input),
        "--skeleton",
        "h36m17",
        "--frame-rate",
        "60",
        "-o",
        s(&out),
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let (original, _) =
        kinergy_motion::read_clip(&fixture("006_14.bvh"), &Default::default()).expect("read");
    let expected = kinergy_solver::arms_beyond_limits(&original).expect("limits");
    assert_eq!(
        json(&o)["arms_beyond_limits"],
        serde_json::to_value(&expected).expect("json")
    );
    let o = kinergy(&["inspect", s(&out)]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let report = common::stdout(&o);
    for side in ["left", "right"] {
        let chain = format!("{side}_shoulder → {side}_elbow → {side}_elbow_End");
        assert!(report.contains(&chain), "{report}");
    }
    let fits = dir.path().join("fits");
    let o = kinergy(&[
        "fit",
        s(&out),
        "--arm",
        "auto",
        "--per",
        "clip",
        "--model",
        "sa",
        "--out-dir",
        s(&fits),
        "-q",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let table = std::fs::read_to_string(fits.join("library.csv")).expect("library.csv");
    let arms: Vec<&str> = table
        .lines()
        .skip(1)
        .map(|l| l.split(',').nth(3).expect("arm"))
        .collect();
    assert_eq!(arms, ["right", "left"], "{table}");
    // Its leaf ankles and head too: it is retargeted onto the CMU rig, and a character
    // measured on it reaches.
    let moved = dir.path().join("on-cmu.bvh");
    let walk = fixture("cmu_12_01_walk.bvh");
    let o = kinergy(&["retarget", s(&out), "--to", s(&walk), "-o", s(&moved), "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let reach = dir.path().join("reach.bvh");
    let o = kinergy(&[
        "reach",
        "--person",
        s(&out),
        "--target",
        "0.3,1.1,0.4",
        "-o",
        s(&reach),
        "-q",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
}

#[test]
fn bad_tables_and_skeletons_are_refused_naming_the_place() {
    let dir = tempfile::tempdir().expect("tmp");
    let input = dir.path().join("p.csv");
    std::fs::write(&input, "frame,joint,x,y,z\n0,pelvis,0,1,zero\n").expect("write");
    let out = dir.path().join("out.bvh");
    let o = kinergy(&[
        "from-positions",
        s(&input),
        "--skeleton",
        "smpl24",
        "-o",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("p.csv:2"), "{}", stderr(&o));
    assert!(!out.exists());
    let o = kinergy(&[
        "from-positions",
        s(&input),
        "--skeleton",
        "smpl99",
        "-o",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(2));
    assert!(stderr(&o).contains("smpl24, h36m17"), "{}", stderr(&o));
}
