//! Delivery, end to end: what `synthesize` makes from fitted parameters has no
//! hand-speed jump its capture does not have, reaches the target the fit aimed at (within
//! 1 cm), and starts from rest where the capture does (first-frame hand speed within 0.3 m/s).
//! Hand speed relative to the shoulder, as `plot speed --relative` computes it; a jump is
//! `kinergy_motion::jumps::speed_jumps` (> 0.25 m/s and > 4× the clip's median change).
//! On reaches of the synthetic set that the paper's controller spoiled (a spike, a stall),
//! and on held-out takes of the shared people (fit per person on takes 1–4, replay 5–8).

mod common;

use std::path::Path;

use common::{fit_person_seeded, json, kinergy, s, shared, stderr, style_report};
use kinergy_motion::fidelity::{Speeds, largest_change, realtime_error};
use kinergy_motion::jumps::speed_jumps;

/// The hand speeds (relative to the shoulder) of `plot speed --relative --csv` for each clip.
fn speeds(clips: &[&Path], arm: &str, dir: &Path) -> Vec<Vec<f64>> {
    let csv = dir.join("speed.csv");
    let mut args = vec!["plot", "speed"];
    args.extend(clips.iter().map(|c| s(c)));
    let svg = dir.join("speed.svg");
    args.extend([
        "--relative",
        "--arm",
        arm,
        "-o",
        s(&svg),
        "--csv",
        s(&csv),
        "-q",
    ]);
    let o = kinergy(&args);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let text = std::fs::read_to_string(&csv).expect("csv");
    let mut out: Vec<(String, Vec<f64>)> = Vec::new();
    for line in text.lines().skip(1) {
        let cells: Vec<&str> = line.split(',').collect();
        let v: f64 = cells[2].parse().expect("speed");
        match out.last_mut() {
            Some((name, list)) if name == cells[0] => list.push(v),
            _ => out.push((cells[0].to_string(), vec![v])),
        }
    }
    out.into_iter().map(|(_, v)| v).collect()
}

/// How `check_delivery` judges the synthesis's hand-speed changes against the capture's.
#[derive(Clone, Copy)]
enum Jumps {
    /// At most this many more `speed_jumps` (a change > 0.25 m/s and > 4× the clip's median
    /// change) than the capture: a spike or a stall.
    More(usize),
    /// In real time: its largest frame-to-frame change at most this many times the
    /// capture's (`kinergy_motion::fidelity::largest_change`), or 0.1 m/s where the capture's
    /// is smaller.
    Steeper(f64),
}

/// Synthesizes `clip`'s reach with `params` (`extra` arguments added), cuts the capture to
/// the same frames, and checks the three promises (the hand-speed changes judged by `jumps`).
/// Returns the two hand-speed series (the capture's, the synthesis's) over their common
/// frames and the synthesis's extra jumps.
fn check_delivery(
    clip: &Path,
    params: &Path,
    arm: &str,
    extra: &[&str],
    dir: &Path,
    jumps: Jumps,
) -> (Vec<f64>, Vec<f64>, usize) {
    let syn = dir.join("syn.bvh");
    let mut args = vec![
        "synthesize",
        s(clip),
        "--params",
        s(params),
        "-o",
        s(&syn),
        "--json",
    ];
    args.extend(extra);
    let o = kinergy(&args);
    assert_eq!(
        o.status.code(),
        Some(0),
        "{}: {}",
        clip.display(),
        stderr(&o)
    );
    let report = json(&o);
    let error = report["final_error_m"].as_f64().expect("error");
    assert!(
        error < 0.01,
        "{}: ends {error} m from the target",
        clip.display()
    );
    let frames = &report["capture_frames"];
    let (a, b) = (
        frames[0].as_u64().expect("a"),
        frames[1].as_u64().expect("b"),
    );
    let cap = dir.join("cap.bvh");
    let range = format!("{a}..{}", b + 1);
    let o = kinergy(&["convert", s(clip), "--frames", &range, "-o", s(&cap), "-q"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v = speeds(&[&cap, &syn], arm, dir);
    let n = v[0].len().min(v[1].len());
    let (jc, js) = (speed_jumps(&v[0][..n]).len(), speed_jumps(&v[1][..n]).len());
    match jumps {
        Jumps::More(more) => assert!(
            js <= jc + more,
            "{}: {js} speed jumps, its capture {jc}: {:?}",
            clip.display(),
            &v[1][..n]
        ),
        Jumps::Steeper(ratio) => {
            let (lc, ls) = (largest_change(&v[0][..n]), largest_change(&v[1][..n]));
            println!(
                "{}: largest change {ls:.3} m/s, the capture's {lc:.3} ({:.2}×)",
                clip.display(),
                ls / lc
            );
            assert!(
                ls <= ratio * lc.max(0.1),
                "{}: the hand speed changes by {ls:.3} m/s in a frame, the capture's by at \
                 most {lc:.3}: {:?}",
                clip.display(),
                &v[1][..n]
            );
        }
    }
    (
        v[0][..n].to_vec(),
        v[1][..n].to_vec(),
        js.saturating_sub(jc),
    )
}

#[test]
fn reaches_the_paper_controller_spoiled_are_smooth_and_arrive() {
    let dir = tempfile::tempdir().expect("tempdir");
    // p01/r09 is the guide's Fig. 5 (docs/guide/fitting.md) (S_C spiked 0.30 → 0.95 → 0.36 m/s); p04/r03 spiked to
    // 5.4 m/s from a straight arm; p02/r05 and p04/r06 stalled 7 and 206 mm short. p01/r03
    // (its S_D vector bends the elbow with a negative gain) stalled 18.7 mm short after the
    // finish, its elbow straight and its wrist bent on both swing limits: the near-straight
    // arm's guidance read the elbow from the shoulder–hand distance, which the bent wrist
    // shortened, so the plain step sat at the hinge's singularity.
    for (clip, model) in [
        ("p01/r09", "sc"),
        ("p04/r03", "sd"),
        ("p02/r05", "sd"),
        ("p04/r06", "sd"),
        ("p01/r03", "sd"),
    ] {
        let path = common::repo()
            .join("data-synthetic")
            .join(format!("{clip}.bvh"));
        let params = dir.path().join("p.json");
        let o = kinergy(&[
            "fit",
            s(&path),
            "--model",
            model,
            "--per",
            "clip",
            "-o",
            s(&params),
            "-q",
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        let (cap, syn, _) =
            check_delivery(&path, &params, "right", &[], dir.path(), Jumps::More(0));
        let (cap, syn) = (cap[0], syn[0]);
        assert!(
            (syn - cap).abs() <= 0.3,
            "{clip}: starts at {syn} m/s, capture {cap}"
        );
    }
}

/// How much steeper than its capture a replay of a held-out take may change speed in a frame
/// ([`Jumps::Steeper`]). The smooth controller bounds the hand's acceleration at 5 V/T, about
/// 1.4× the steepest change of *active*'s and *normal*'s takes (a·T/V ≈ 3.5): measured
/// 1.17–1.53× on their held-out takes with S_C, up to 1.72× of *elderly*'s 0.045 m/s changes.
/// Bounding it at the person's own 3.5 V/T made the reaches longer and slower (*normal*'s
/// real-time e 1.7 → 3.5× the ceiling), so the strict real-time check (no change above the capture's) is reported, not asserted: the
/// person's own takes fail it against each other on 6 of 12 pairs.
const STEEPER: f64 = 1.6;

/// [`STEEPER`] for S_E, whose fitted acceleration factor scales the bound (measured up to
/// 1.61× on *normal* take 5).
const STEEPER_S_E: f64 = 1.75;

/// The S_C replays of the shared people's held-out takes arrive, start as captured and change
/// speed at most [`STEEPER`] times as steeply as their captures.
#[test]
fn held_out_takes_of_the_shared_people_are_smooth_arrive_and_start_as_captured() {
    let Some(folder) = shared("bandai-raise-left", "") else {
        return;
    };
    let dir = tempfile::tempdir().expect("tempdir");
    for person in ["active", "elderly", "normal"] {
        let params = dir.path().join(format!("{person}.json"));
        fit_person(&folder, person, &[1, 2, 3, 4], "sc", &params);
        for t in 5..=8 {
            let clip = folder.join(format!("{person}_00{t}.bvh"));
            let (cap, syn, _) = check_delivery(
                &clip,
                &params,
                "left",
                &["--frames", "auto"],
                dir.path(),
                Jumps::Steeper(STEEPER),
            );
            let (cap, syn) = (cap[0], syn[0]);
            // From rest where the capture starts from rest (the active takes are cut while
            // the hand already moves at 1.7–3.2 m/s).
            if cap < 1.0 {
                assert!(
                    (syn - cap).abs() <= 0.3,
                    "{}: starts at {syn} m/s, capture {cap}",
                    clip.display()
                );
            }
        }
    }
}

/// Pearson's correlation of two series of the same length.
fn pearson(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let va: f64 = a.iter().map(|x| (x - ma).powi(2)).sum();
    let vb: f64 = b.iter().map(|y| (y - mb).powi(2)).sum();
    cov / (va * vb).sqrt()
}

/// [`fit_person_with`] the default optimizer, SVD.
fn fit_person(folder: &Path, person: &str, takes: &[usize], model: &str, params: &Path) {
    fit_person_with(folder, person, takes, model, "svd", params);
}

/// On the shared data, *active*'s raises end with the arm 95–96 % extended (the
/// nearest the shared captures come to pointing at full extension). With S_D fitted per person on takes 1–4 with each optimizer — JT, NJT, SVD,
/// DLS — every held-out take 5–8 ends within 1.5 % of the arm's length of its captured end
/// point, reached in the default time budget (measured: at most 1.0 %, JT in 14–19 frames).
#[test]
fn every_optimizer_reaches_the_near_straight_held_out_raises() {
    let Some(folder) = shared("bandai-raise-left", "") else {
        return;
    };
    let dir = tempfile::tempdir().expect("tempdir");
    for optimizer in ["jt", "njt", "svd", "dls"] {
        let params = dir.path().join(format!("{optimizer}.json"));
        fit_person_with(&folder, "active", &[1, 2, 3, 4], "sd", optimizer, &params);
        for t in 5..=8 {
            let clip = folder.join(format!("active_00{t}.bvh"));
            let out = dir.path().join("s.bvh");
            let o = kinergy(&[
                "synthesize",
                s(&clip),
                "--params",
                s(&params),
                "--frames",
                "auto",
                "-o",
                s(&out),
                "--json",
            ]);
            assert_eq!(
                o.status.code(),
                Some(0),
                "{optimizer} take {t}: {}",
                stderr(&o)
            );
            let report = json(&o);
            let number = |k: &str| report[k].as_f64().expect("number");
            let (error, arm) = (number("final_error_m"), number("arm_length_m"));
            let extension = number("shoulder_to_target_m") / arm;
            assert!(
                extension >= 0.94,
                "take {t}: the arm ends {extension} extended"
            );
            assert_eq!(report["stop"], "reached", "{optimizer} take {t}");
            assert!(
                error <= 0.015 * arm,
                "{optimizer} take {t}: {error} m from the captured end, arm {arm} m"
            );
        }
    }
}

/// Fits `model` per person on `takes` of the shared `person` (left arm, seed 1) into `params`,
/// with the optimizer `optimizer`.
fn fit_person_with(
    folder: &Path,
    person: &str,
    takes: &[usize],
    model: &str,
    optimizer: &str,
    params: &Path,
) {
    fit_person_seeded(folder, person, takes, model, optimizer, 1, params);
}

/// S_E and S_D fitted per person on takes 1–4, every held-out take 5–8
/// synthesized on its captured torso under the person's tempo law. S_E arrives and follows
/// the capture's hand speed at least as well as S_D for every person — correlation ≥ 0.95 for
/// *active* and *normal* (measured 0.992 and 0.991; S_D 0.979, 0.985), and higher than S_D's
/// for *elderly* (0.730 against 0.626; the 0.95 is not reached: the synthesis peaks
/// later than this slow, early-peaking person) — starts within 0.4 m/s of the capture
/// (measured at most 0.36, *active* take 7, whose capture is cut at 1.7 m/s), and changes
/// speed in a frame at most [`STEEPER_S_E`] times as steeply as the capture.
#[test]
fn held_out_takes_replayed_with_s_e_follow_the_captured_speed_closer_than_s_d() {
    let Some(folder) = shared("bandai-raise-left", "") else {
        return;
    };
    let dir = tempfile::tempdir().expect("tempdir");
    for person in ["active", "elderly", "normal"] {
        let mut mean = Vec::new();
        for model in ["sd", "se"] {
            let params = dir.path().join(format!("{person}-{model}.json"));
            fit_person(&folder, person, &[1, 2, 3, 4], model, &params);
            let mut r = Vec::new();
            for t in 5..=8 {
                let clip = folder.join(format!("{person}_00{t}.bvh"));
                let (cap, syn, _) = check_delivery(
                    &clip,
                    &params,
                    "left",
                    &["--frames", "auto"],
                    dir.path(),
                    // S_E's fitted acceleration factor (> 1 for these people) steepens it.
                    Jumps::Steeper(if model == "se" { STEEPER_S_E } else { STEEPER }),
                );
                r.push(pearson(&cap, &syn));
                if model == "se" {
                    assert!(
                        (syn[0] - cap[0]).abs() <= 0.4,
                        "{}: starts at {} m/s, capture {}",
                        clip.display(),
                        syn[0],
                        cap[0]
                    );
                }
            }
            mean.push(r.iter().sum::<f64>() / r.len() as f64);
        }
        let (sd, se) = (mean[0], mean[1]);
        println!("{person}: hand-speed correlation S_D {sd:.3}, S_E {se:.3}");
        assert!(se >= sd, "{person}: S_E {se} < S_D {sd}");
        if person != "elderly" {
            assert!(se >= 0.95, "{person}: S_E {se} < 0.95");
        }
    }
}

/// On the shared people's takes 7–8, each person's S_E (fitted on
/// takes 1–6, nested after S_D; `compare --per person --holdout 2 --models sd,se`) is at least
/// as close as their S_D on both seeds 1 and 2, and over the two seeds at least 15 % closer.
/// Measured with each held-out take synthesized under the person's tempo law (the
/// fits run under it too): *active* 59.9 → 49.8 mm summed over the seeds, −17 %; *elderly*
/// 96.8 → 63.9 mm, −34 %; *normal* 77.5 → 55.5 mm, −28 % (seed 1 a tie, 37.8 and 37.7 mm).
/// Before the law, with each held-out take told its own capture's speed, S_E gained 38 / 33 /
/// 23 %: its tempo factors had partly learned what the law now predicts.
#[test]
fn on_held_out_takes_s_e_is_closer_than_s_d_for_every_person() {
    let Some(folder) = shared("bandai-raise-left", "") else {
        return;
    };
    let dir = tempfile::tempdir().expect("tempdir");
    let mut sums = std::collections::BTreeMap::<String, (f64, f64)>::new();
    for seed in ["1", "2"] {
        let report = common::held_out_per_person(&folder, seed, &["--models", "sd,se"], dir.path());
        for line in report["own"].as_array().expect("own") {
            let Some(person) = line["person"].as_str() else {
                continue;
            };
            let models = line["models"].as_array().expect("models");
            let mean = |name: &str| {
                models
                    .iter()
                    .find(|m| m[0] == name)
                    .and_then(|m| m[1]["mean"].as_f64())
                    .expect("model mean")
            };
            let (sd, se) = (mean("sd"), mean("se"));
            println!(
                "seed {seed}, {person}: S_D {:.2} mm, S_E {:.2} mm",
                sd * 1e3,
                se * 1e3
            );
            assert!(se <= sd, "seed {seed}, {person}: S_E {se} > S_D {sd}");
            let sum = sums.entry(person.to_string()).or_default();
            sum.0 += sd;
            sum.1 += se;
        }
    }
    assert_eq!(sums.len(), 3, "three persons: {sums:?}");
    for (person, (sd, se)) in sums {
        assert!(
            se <= 0.85 * sd,
            "{person}: S_E {se} is not 15 % below S_D {sd}"
        );
    }
}

/// A speed series of the shared takes' rate, 30 Hz (the character that reaches for them runs
/// at its capture's rate).
fn at_30_hz(values: &[f64]) -> Speeds<'_> {
    Speeds {
        values,
        frame_time: 1.0 / 30.0,
    }
}

/// The body's real-time figures in a `style` report: (e of the body, e of the person's own
/// repeats, e of minimum jerk), means over the takes.
fn body_ceiling_jerk(report: &serde_json::Value) -> (f64, f64, f64) {
    let e = |name: &str| common::fidelity_error(report, name);
    (e("body"), e("ceiling"), e("minimum_jerk"))
}

/// Each shared person's S_C vector fitted on takes 1–4 with seeds
/// 1–6, the full body toward the targets of takes 5–8 (`style`), judged in real time. The DoFs
/// no capture sees are held neutral, so the seed no longer steers the character: on every
/// seed the body beats minimum jerk and stays within a bound of the person's own repeats
/// (measured over seeds 1–6, × the ceiling: *active* 0.65–0.68, *elderly* 1.47–1.74,
/// *normal* 1.63–1.76, against minimum jerk's 4.51 / 1.85 / 7.29; 1.5× is met by *active* on
/// every seed and by *elderly* on seed 4 only; docs/guide/fitting.md, "Judging a person's
/// motion in real time"); and seeds 2–6 deliver the same motion as seed 1 to within the person's own
/// variation — the real-time e between a seed's body and seed 1's, mean over the takes, is
/// below the person's noise ceiling (measured at most 0.20 / 0.77 / 0.16 of it).
#[test]
fn over_seeds_the_full_body_delivers_the_same_person_within_their_own_variation() {
    let Some(folder) = shared("bandai-raise-left", "") else {
        return;
    };
    let dir = tempfile::tempdir().expect("tempdir");
    for (person, bound) in [("active", 0.85), ("elderly", 2.0), ("normal", 2.0)] {
        let mut first: Vec<Vec<f64>> = Vec::new();
        for seed in 1..=6 {
            let params = dir.path().join(format!("{person}-{seed}.json"));
            fit_person_seeded(&folder, person, &[1, 2, 3, 4], "sc", "svd", seed, &params);
            let out = dir.path().join(format!("style-{person}-{seed}"));
            let report = style_report(&folder, person, &[5, 6, 7, 8], &params, &out);
            let (body, ceiling, jerk) = body_ceiling_jerk(&report);
            println!(
                "{person} seed {seed}: body {:.2}× the ceiling {ceiling:.3}, minimum jerk {:.2}×",
                body / ceiling,
                jerk / ceiling
            );
            assert!(body < jerk, "{person} seed {seed}: {}", report["fidelity"]);
            assert!(
                body <= bound * ceiling,
                "{person} seed {seed}: body {body} > {bound} × ceiling {ceiling}"
            );
            let bodies: Vec<Vec<f64>> = (5..=8)
                .map(|t| {
                    let clip = out.join(format!("{person}_00{t}.params.bvh"));
                    speeds(&[&clip], "left", dir.path()).remove(0)
                })
                .collect();
            if seed == 1 {
                first = bodies;
                continue;
            }
            let spread = bodies
                .iter()
                .zip(&first)
                .map(|(b, f)| realtime_error(at_30_hz(b), at_30_hz(f)))
                .sum::<f64>()
                / bodies.len() as f64;
            println!(
                "{person} seed {seed}: e against seed 1 {spread:.3} ({:.2} of the ceiling)",
                spread / ceiling
            );
            assert!(
                spread < ceiling,
                "{person} seed {seed}: {spread} from seed 1's body, ceiling {ceiling}"
            );
        }
    }
}

/// The shared captures have no hand bone: a fit records the forearm's twist and the wrist as
/// unobserved (`fit.unobserved`), and indeed their gains change nothing of the captured arm's
/// motion — the synthesis with them set elsewhere moves the hand at the same speeds, frame for
/// frame — while every observed gain does.
#[test]
fn the_dofs_a_fit_records_as_unobserved_do_not_move_the_captured_hand() {
    let Some(folder) = shared("bandai-raise-left", "") else {
        return;
    };
    let dir = tempfile::tempdir().expect("tempdir");
    let params = dir.path().join("normal.json");
    fit_person(&folder, "normal", &[1, 2], "sb", &params);
    let file: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&params).expect("params")).expect("json");
    let unobserved: Vec<&str> = file["fit"]["unobserved"]
        .as_array()
        .expect("unobserved DoFs recorded")
        .iter()
        .map(|v| v.as_str().expect("name"))
        .collect();
    assert_eq!(
        unobserved,
        ["elbow_twist", "wrist_swing_x", "wrist_swing_y"]
    );
    let clip = folder.join("normal_005.bvh");
    let speeds_with = |change: &[&str], value: f64, name: &str| {
        let mut edited = file.clone();
        for dof in change {
            edited["values"][format!("g_{dof}")] = serde_json::json!(value);
        }
        let path = dir.path().join(format!("{name}.json"));
        std::fs::write(&path, serde_json::to_vec(&edited).expect("json")).expect("write");
        let out = dir.path().join(format!("{name}.bvh"));
        let o = kinergy(&[
            "synthesize",
            s(&clip),
            "--params",
            s(&path),
            "--arm",
            "left",
            "--frames",
            "auto",
            "-o",
            s(&out),
        ]);
        assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
        speeds(&[&out], "left", dir.path()).remove(0)
    };
    let fitted = speeds_with(&[], 0.0, "fitted");
    for value in [-3.0, 4.0] {
        let moved = speeds_with(&unobserved, value, &format!("unobserved{value}"));
        assert_eq!(moved.len(), fitted.len());
        for (a, b) in moved.iter().zip(&fitted) {
            assert!((a - b).abs() < 1e-9, "gains {value}: {a} against {b}");
        }
    }
    let observed = speeds_with(&["elbow_flexion"], 3.0, "observed");
    let largest = observed
        .iter()
        .zip(&fitted)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(
        largest > 0.05,
        "an observed gain moved the hand by {largest} m/s at most"
    );
}

/// On the shared people (S_C per person on takes 1–4, seed 1, `style` on 5–8, in real
/// time): the full body delivers the arm as fitted — its mean real-time error is within 15 % of
/// the arm's on the captured torso (measured 0.66× / 1.52× / 1.71× the ceiling against the
/// arm's 0.76× / 1.58× / 1.76×; before, the body was at 4.2× / 3.6× / 8.5×), both beat minimum
/// jerk for every person, and the body's duration and peak speed are within 15 % of the
/// captures' (measured 1.11 / 0.98 / 1.00 and 1.07 / 1.09 / 0.96). What is not yet met is
/// written down, not asserted: the 1.25× and 1.5× of the ceiling for *elderly* and
/// *normal*, and its real-time jump check (docs/guide/fitting.md, "Judging a person's motion in real time").
#[test]
fn the_full_body_delivers_the_arm_as_fitted_in_real_time() {
    let Some(folder) = shared("bandai-raise-left", "") else {
        return;
    };
    let dir = tempfile::tempdir().expect("tempdir");
    for person in ["active", "elderly", "normal"] {
        let params = dir.path().join(format!("{person}.json"));
        fit_person(&folder, person, &[1, 2, 3, 4], "sc", &params);
        let out = dir.path().join(format!("style-{person}"));
        let fidelity =
            style_report(&folder, person, &[5, 6, 7, 8], &params, &out)["fidelity"].clone();
        let summary = |name: &str| {
            fidelity["summaries"]
                .as_array()
                .expect("summaries")
                .iter()
                .find(|s| s["predictor"] == name)
                .cloned()
                .unwrap_or_else(|| panic!("{person}: no {name} in {fidelity}"))
        };
        let (arm, body, mj) = (summary("arm"), summary("body"), summary("minimum_jerk"));
        let e = |s: &serde_json::Value| s["error"].as_f64().expect("e");
        assert!(
            e(&body) <= 1.15 * e(&arm),
            "{person}: body {body}, arm {arm}"
        );
        assert!(
            e(&arm) < e(&mj) && e(&body) < e(&mj),
            "{person}: {fidelity}"
        );
        for k in ["duration_ratio", "peak_ratio"] {
            let r = body[k].as_f64().expect("ratio");
            assert!((0.85..=1.15).contains(&r), "{person}: body {k} {r}");
        }
        assert!(out.join("realtime.png").is_file() && out.join("realtime.svg").is_file());
    }
}
