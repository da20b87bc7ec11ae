//! `kinergy retarget`: a capture moved onto another rig and back keeps its hand path; the
//! output is written in the template's unit with its hierarchy; planted feet hold; `--params`
//! drives the reach on the new body about as close to the (retargeted) capture as on the
//! person's own; bad maps and an output over an input are refused, naming them.

mod common;
use common::{assert_bad_input, fixture, json, kinergy, s, stderr};

fn wrist_path(path: &std::path::Path, name: &str) -> Vec<[f64; 3]> {
    let (clip, _) = kinergy_motion::read_clip(path, &Default::default()).expect("read");
    let j = clip.skeleton().joint_index(name).expect("wrist");
    let n = clip.skeleton().joint_count();
    clip.world_positions()
        .expect("fk")
        .chunks(n)
        .map(|f| [f[j].x, f[j].y, f[j].z])
        .collect()
}

#[test]
fn there_and_back_keeps_the_hands_and_the_template_hierarchy() {
    let dir = tempfile::tempdir().expect("tmp");
    let (walk, cc) = (fixture("cmu_12_01_walk.bvh"), fixture("006_14.bvh"));
    let there = dir.path().join("cc_on_cmu.bvh");
    let back = dir.path().join("back.bvh");
    let o = kinergy(&[
        "retarget",
        s(&cc),
        "--to",
        s(&walk),
        "-o",
        s(&there),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = json(&o);
    assert!(
        report["foot_slide_m"].as_f64().expect("slide") <= 1e-3,
        "{report}"
    );
    assert_eq!(report["roles"].as_array().expect("roles").len(), 21);
    let written = std::fs::read_to_string(&there).expect("out");
    let template = std::fs::read_to_string(&walk).expect("walk");
    let header = |t: &str| {
        t.split("MOTION")
            .next()
            .unwrap_or_default()
            .split_whitespace()
            .filter(|w| w.parse::<f64>().is_err())
            .collect::<Vec<_>>()
            .join(" ")
    };
    assert_eq!(
        header(&written),
        header(&template),
        "the template's hierarchy and channels"
    );
    let o = kinergy(&[
        "retarget",
        s(&there),
        "--to",
        s(&cc),
        "-o",
        s(&back),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Spines of 4 and 3 joints resample each other (within 1.5 cm), and where a foot was out
    // of a leg's reach the pelvis came down (reported), the body with it.
    let drops = report["pelvis_drop_m"].as_f64().expect("drop")
        + json(&o)["pelvis_drop_m"].as_f64().expect("drop");
    let bound = 0.015 + drops;
    for wrist in ["CC_Base_R_Hand", "CC_Base_L_Hand"] {
        let (a, b) = (wrist_path(&cc, wrist), wrist_path(&back, wrist));
        assert_eq!(a.len(), b.len());
        let worst = a
            .iter()
            .zip(&b)
            .map(|(p, q)| {
                ((p[0] - q[0]).powi(2) + (p[1] - q[1]).powi(2) + (p[2] - q[2]).powi(2)).sqrt()
            })
            .fold(0.0, f64::max);
        assert!(
            worst <= bound,
            "{wrist} off by {worst} m after the round trip (bound {bound} m)"
        );
    }
}

#[test]
fn a_persons_parameters_drive_the_reach_on_the_new_body() {
    let dir = tempfile::tempdir().expect("tmp");
    let (walk, cc) = (fixture("cmu_12_01_walk.bvh"), fixture("006_14.bvh"));
    let params = fixture("params/006_14-sc.json");
    let own = dir.path().join("own.bvh");
    let o = kinergy(&[
        "synthesize",
        s(&cc),
        "--params",
        s(&params),
        "-o",
        s(&own),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let on_own = json(&o)["distance_to_capture_m"]
        .as_f64()
        .expect("distance");
    let out = dir.path().join("driven.bvh");
    let o = kinergy(&[
        "retarget",
        s(&cc),
        "--to",
        s(&walk),
        "--params",
        s(&params),
        "-o",
        s(&out),
        "--json",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let report = json(&o);
    let driven = &report["driven"];
    assert_eq!(driven["stop"], "reached", "{report}");
    // Distances scale with the arm: compared at the person's own size, the reach on the CMU
    // body is as close to its capture as on the person's own (measured 6.7 vs 6.3 cm).
    let scale = report["arm_scale"][0].as_f64().expect("scale");
    let on_new = driven["distance_to_capture_m"].as_f64().expect("distance") / scale;
    assert!(
        on_new <= 1.5 * on_own,
        "{on_new} m on the new body vs {on_own} m"
    );
}

#[test]
fn bad_maps_and_outputs_are_refused_naming_them() {
    let dir = tempfile::tempdir().expect("tmp");
    let (walk, cc) = (fixture("cmu_12_01_walk.bvh"), fixture("006_14.bvh"));
    let out = dir.path().join("out.bvh");
    assert_bad_input(
        &[
            "retarget",
            s(&walk),
            "--to",
            s(&cc),
            "--to-map",
            "bandai",
            "-o",
            s(&out),
        ],
        "no joint named `UpperArm_R`",
        &out,
    );
    assert_bad_input(
        &[
            "retarget",
            s(&walk),
            "--to",
            s(&cc),
            "--map",
            "nope",
            "-o",
            s(&out),
        ],
        "--map nope",
        &out,
    );
    let map = dir.path().join("roles.json");
    std::fs::write(&map, r#"{"pelvis": "Hips", "tail": "Tail"}"#).expect("map");
    assert_bad_input(
        &[
            "retarget",
            s(&walk),
            "--to",
            s(&cc),
            "--map",
            s(&map),
            "-o",
            s(&out),
        ],
        "unknown role `tail`",
        &out,
    );
    let copy = dir.path().join("walk.bvh");
    std::fs::copy(&walk, &copy).expect("copy");
    let o = kinergy(&["retarget", s(&copy), "--to", s(&cc), "-o", s(&copy)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert_eq!(
        std::fs::read(&copy).expect("input"),
        std::fs::read(&walk).expect("walk"),
        "the input was replaced"
    );
}
