//! End-to-end tests of `kinergy reach` and `kinergy synth`.

mod common;
use common::{kinergy, repo, text};

use std::path::{Path, PathBuf};

#[test]
fn reach_writes_a_clip_whose_hand_ends_on_the_target() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("reach.bvh");
    let o = kinergy(&[
        "reach",
        "--target",
        "0.3,1.1,0.4",
        "--seed",
        "4",
        "-o",
        out.to_str().expect("utf-8"),
        "--json",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let report: serde_json::Value = serde_json::from_slice(&o.stdout).expect("json");
    assert_eq!(report["stop"], "reached");
    let (clip, _) = kinergy_motion::read_clip(&out, &Default::default()).expect("read");
    assert_eq!(clip.frame_time(), 1.0 / 120.0);
    assert_eq!(
        clip.frame_count() as u64,
        report["frames"].as_u64().expect("frames")
    );
    // The hand's end (read back from the file by FK) is on the target.
    let arm = if report["arm"] == "left_arm" {
        "LeftHand_End"
    } else {
        "RightHand_End"
    };
    let j = clip.skeleton().require_joint(arm).expect("hand");
    let t = clip.trajectory(&[j]).expect("fk");
    let hand = t.frame(t.frame_count() - 1)[0];
    let error = ((hand.x - 0.3).powi(2) + (hand.y - 1.1).powi(2) + (hand.z - 0.4).powi(2)).sqrt();
    assert!(error < 0.01, "hand {error} m from the target");
}

#[test]
fn reach_exit_codes() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("reach.bvh");
    let out_s = out.to_str().expect("utf-8");
    let o = kinergy(&[
        "reach",
        "--target",
        "0.3,3.5,0.3",
        "--timeout",
        "3",
        "-o",
        out_s,
    ]);
    assert_eq!(o.status.code(), Some(1), "{}", text(&o.stderr));
    assert!(
        out.exists(),
        "the motion toward an unreachable target is still written"
    );
    std::fs::remove_file(&out).expect("remove");
    for (args, needle) in [
        (vec!["reach", "--target", "0.3,nan,0.3", "-o", out_s], "nan"),
        (
            vec![
                "reach",
                "--target",
                "0.3,1.1,0.3",
                "--height",
                "7",
                "-o",
                out_s,
            ],
            "height",
        ),
        (
            vec![
                "reach",
                "--target",
                "0.3,1.1,0.3",
                "--flexibility",
                "0",
                "-o",
                out_s,
            ],
            "flexibility",
        ),
        (
            vec![
                "reach",
                "--target",
                "0.3,1.1,0.3",
                "--person",
                "/nonexistent/p.bvh",
                "-o",
                out_s,
            ],
            "p.bvh",
        ),
    ] {
        let o = kinergy(&args);
        let err = text(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(
            err.contains(needle),
            "{args:?}: `{err}` does not mention {needle}"
        );
        assert!(!out.exists(), "{args:?} left an output file");
    }
}

/// Every file under `dir`, relative path → bytes.
fn files(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).expect("read_dir") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                stack.push(p);
            } else {
                let rel = p.strip_prefix(dir).expect("prefix").to_path_buf();
                out.push((rel, std::fs::read(&p).expect("read")));
            }
        }
    }
    out.sort();
    out
}

// The committed synthetic set is what `kinergy synth` writes, byte for byte.
#[test]
fn synth_regenerates_the_committed_set_byte_for_byte() {
    let committed = repo().join("data-synthetic");
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("set");
    let o = kinergy(&["synth", "-o", out.to_str().expect("utf-8")]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o.stderr));
    let (a, b) = (files(&committed), files(&out));
    assert_eq!(
        a.iter().map(|f| &f.0).collect::<Vec<_>>(),
        b.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    for (x, y) in a.iter().zip(&b) {
        assert!(
            x.1 == y.1,
            "{} differs from a fresh `kinergy synth`",
            x.0.display()
        );
    }
    // 4 persons × 14 reaches and the manifest.
    assert_eq!(a.len(), 4 * 14 + 1);
    let manifest = String::from_utf8(std::fs::read(out.join("manifest.csv")).expect("manifest"))
        .expect("utf-8");
    assert_eq!(manifest.lines().count(), 1 + 4 * 14);
    assert!(manifest.starts_with("clip,person,height_m,flexibility"));
}

/// Issue 43: Huang et al.'s knobs are the user's, each checked (exit 2 naming the flag), and
/// each moves the motion as the paper says: a faster v_s ends the ease-out reach sooner, and
/// P_max = P_min = 1 makes every step toward a target between the CRR and the MRR a half step,
/// P_max = P_min = 0 a full one.
#[test]
fn reach_takes_huangs_knobs() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("r.bvh");
    let run = |extra: &[&str]| {
        let mut args = vec!["reach", "--json", "-o", out.to_str().expect("utf-8")];
        args.extend(extra);
        let o = kinergy(&args);
        (o.status.code(), text(&o.stdout), text(&o.stderr))
    };
    for (flag, value) in [
        ("--v-s", "0"),
        ("--r-s", "1.5"),
        ("--r-st", "-0.1"),
        ("--r-tw", "NaN"),
        ("--comfortable-angle-deg", "180"),
        ("--start-swing-distance-m", "-1"),
        ("--head-speed-deg-s", "inf"),
        ("--p-min", "0.95"),
    ] {
        let given = format!("{flag}={value}");
        let (code, _, err) = run(&["--target", "0.3,1.1,0.4", &given]);
        assert_eq!(code, Some(2), "{flag} {value}: {err}");
        assert!(err.contains(flag), "{flag} {value}: {err}");
        assert!(!out.exists(), "{flag} {value} wrote a clip");
    }
    let duration = |extra: &[&str]| {
        let mut args = vec!["--target", "0.3,1.1,0.4"];
        args.extend(extra);
        let (code, json, err) = run(&args);
        assert_eq!(code, Some(0), "{err}");
        let report: serde_json::Value = serde_json::from_str(&json).expect("json");
        report["duration"].as_f64().expect("duration")
    };
    let (paper, fast) = (duration(&[]), duration(&["--v-s", "0.4"]));
    assert!(fast < 0.75 * paper, "v_s 0.4: {fast} s against {paper} s");
    let steps = |p: &str| {
        (0..8)
            .map(|seed| {
                let seed = seed.to_string();
                let (code, json, err) = run(&[
                    "--target",
                    "0.0,1.1,0.85",
                    "--seed",
                    &seed,
                    "--p-max",
                    p,
                    "--p-min",
                    p,
                ]);
                assert_eq!(code, Some(0), "{err}");
                let report: serde_json::Value = serde_json::from_str(&json).expect("json");
                report["step"].as_str().expect("step").to_string()
            })
            .filter(|s| s != "none")
            .collect::<Vec<_>>()
    };
    let halves = steps("1");
    assert!(!halves.is_empty(), "no step drawn in 8 seeds");
    assert!(halves.iter().all(|s| s.starts_with("half")), "{halves:?}");
    let fulls = steps("0");
    assert!(!fulls.is_empty(), "no step drawn in 8 seeds");
    assert!(fulls.iter().all(|s| s == "full"), "{fulls:?}");
}

/// Issue 43, item 7: Huang et al.'s Fig. 4 gallery (`examples/huang-fig4/gallery.csv`, drawn
/// by `docs/make-pictures.sh`): each situation does what its caption says — the step (none, a
/// half or a full one), the posture (upright, stoop, squat), the twist and the swing — and
/// reaches its target within a centimetre.
#[test]
fn huangs_fig_4_gallery_does_what_its_captions_say() {
    let dir = tempfile::tempdir().expect("tempdir");
    let csv = std::fs::read_to_string(repo().join("examples/huang-fig4/gallery.csv"))
        .expect("the gallery");
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().expect("header").split(',').collect();
    let mut panels = 0;
    for line in lines {
        let cells: Vec<&str> = line.split(',').collect();
        let cell = |name: &str| {
            cells[header
                .iter()
                .position(|&h| h == name)
                .unwrap_or_else(|| panic!("no `{name}` column"))]
        };
        let target = format!(
            "{},{},{}",
            cell("target_x"),
            cell("target_y"),
            cell("target_z")
        );
        let out = dir.path().join(format!("{}.bvh", cell("panel")));
        let o = kinergy(&[
            "reach",
            "--target",
            &target,
            "--flexibility",
            cell("flexibility"),
            "--seed",
            cell("seed"),
            "--p-max",
            cell("p_max"),
            "--p-min",
            cell("p_min"),
            // A high target after a step is a long path at the paper's v_s.
            "--timeout",
            "30",
            "--json",
            "-o",
            out.to_str().expect("utf-8"),
        ]);
        let what = format!("({}) {}", cell("panel"), cell("caption"));
        assert_eq!(o.status.code(), Some(0), "{what}: {}", text(&o.stderr));
        let report: serde_json::Value = serde_json::from_slice(&o.stdout).expect("JSON");
        let r = report.get("reach").unwrap_or(&report);
        assert_eq!(r["stop"], "reached", "{what}: {r}");
        assert!(
            r["final_error"].as_f64().expect("error") <= 0.01,
            "{what}: {r}"
        );
        let step = r["step"].as_str().expect("step");
        let step_ok = match cell("step") {
            "any" => true,
            "any-step" => step != "none",
            "half" => step.starts_with("half"),
            kind => step == kind,
        };
        assert!(step_ok, "{what}: step {step}, wanted {}", cell("step"));
        let posture = r["posture"].as_str().expect("posture");
        assert!(
            cell("posture") == "any" || posture == cell("posture"),
            "{what}: posture {posture}, wanted {}",
            cell("posture")
        );
        let twist = r["twist_deg"].as_f64().expect("twist").abs();
        match cell("twist") {
            "yes" => assert!(twist > 1.0, "{what}: no twist ({twist}°)"),
            "no" => assert!(twist <= 1.0, "{what}: a twist of {twist}°"),
            _ => {}
        }
        let swing = r["swing_deg"].as_f64().expect("swing").abs();
        match cell("swing") {
            "yes" => assert!(swing > 1.0, "{what}: no swing ({swing}°)"),
            "no" => assert!(swing <= 1.0, "{what}: a swing of {swing}°"),
            _ => {}
        }
        panels += 1;
    }
    assert_eq!(panels, 8, "Huang's Fig. 4 has panels a–h");
}
