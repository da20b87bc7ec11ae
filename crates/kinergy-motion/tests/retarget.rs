//! Retargeting ([`Retargeter`]) between the rigs Kinergy reads, against independent truths:
//! a round trip (A → B → A) gives back A's hand path, planted feet stay put, the hands and
//! feet reach their scaled goals, a skeleton retargeted onto itself is the identity, the
//! built-in role maps name the joints the finders find, and keypoints without hands or feet
//! move a body as the full rig they were taken from does.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use kinergy_motion::{BodyJoints, Clip, Retargeted, Retargeter, read_clip};
#[path = "../../../tests/support/keypoints.rs"]
mod keypoints;
#[path = "../../../tests/support/require_shared.rs"]
mod require_shared;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn read(path: &Path) -> Clip {
    read_clip(path, &Default::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .0
}

/// A shared capture, or `None` (skipping, saying so, unless required).
fn shared(rel: &str) -> Option<Clip> {
    let path = root().join("../shared/data").join(rel);
    if path.exists() {
        Some(read(&path))
    } else {
        require_shared::shared_absent(&format!("skipping {}: absent", path.display()));
        None
    }
}

fn retarget(clip: &Clip, template: &Arc<kinergy_motion::Skeleton>) -> Retargeted {
    let from = BodyJoints::find(clip.skeleton()).expect("source body");
    let to = BodyJoints::find(template).expect("target body");
    Retargeter::new(clip, from, template.clone(), to)
        .expect("retargeter")
        .run(clip)
        .expect("run")
}

/// The largest distance between two clips' paths of the given joints (same skeleton).
fn path_error(a: &Clip, b: &Clip, joints: &[usize]) -> f64 {
    let (pa, pb) = (
        a.trajectory(joints).expect("fk"),
        b.trajectory(joints).expect("fk"),
    );
    pa.frames()
        .zip(pb.frames())
        .flat_map(|(x, y)| x.iter().zip(y).map(|(p, q)| (p - q).norm()))
        .fold(0.0, f64::max)
}

/// A → B → A: the hands, shoulders, head and pelvis come back; the report holds its bounds.
fn round_trip(a: &Clip, b: &Arc<kinergy_motion::Skeleton>, bound_m: f64) {
    let there = retarget(a, b);
    let back = retarget(&there.clip, a.skeleton());
    assert_eq!(back.clip.frame_count(), a.frame_count());
    assert_eq!(back.clip.frame_time(), a.frame_time());
    let body = BodyJoints::find(a.skeleton()).expect("body");
    let mut joints = vec![body.pelvis];
    for arm in &body.arms {
        joints.extend([arm.shoulder, arm.elbow, arm.wrist]);
    }
    joints.extend(body.head);
    let error = path_error(a, &back.clip, &joints);
    // Where a foot was beyond a leg's reach, the pelvis came down (reported): the body with it.
    let drops = there.report.pelvis_drop_m + back.report.pelvis_drop_m;
    let bound_m = bound_m + drops;
    let (a_name, b_name) = (a.skeleton().joint(0).name.clone(), b.joint(0).name.clone());
    assert!(
        error <= bound_m,
        "{a_name} → {b_name} → back: off by {error} m"
    );
    for r in [&there.report, &back.report] {
        assert!(r.hand_error_m.iter().all(|e| *e < 1e-6), "{r:?}");
    }
}

#[test]
fn bandai_to_cmu_and_back_keeps_the_hand_path_within_a_centimetre() {
    let cmu = read(&root().join("tests/data/cmu_12_01_walk.bvh"));
    let mut takes = 0;
    for style in ["active", "elderly", "normal"] {
        for take in [1, 5] {
            let Some(bandai) = shared(&format!("bandai-raise-left/{style}_{take:03}.bvh")) else {
                return;
            };
            round_trip(&bandai, cmu.skeleton(), 0.01);
            takes += 1;
        }
    }
    assert_eq!(takes, 6);
}

#[test]
fn every_rig_goes_round_trip_through_every_other() {
    let mut clips = vec![
        read(&root().join("tests/data/cmu_12_01_walk.bvh")),
        read(&root().join("tests/data/006_14.bvh")),
    ];
    for rel in [
        "formats/mixamo_walk.bvh",
        "formats/zup_mixed_orders.bvh",
        "real-bvh/dataset-1_bye_normal_001.bvh",
        "cmu-lift/26_10.bvh",
    ] {
        clips.extend(shared(rel));
    }
    for a in &clips {
        for b in &clips {
            // The body of one rig and another's differ (spines of 2 to 4 joints, necks of 0
            // to 2, pelvis and chest bones of other lengths): the round trip is exact where
            // the chains correspond and within 1.5 cm where they resample each other.
            round_trip(a, b.skeleton(), 0.015);
        }
    }
}

#[test]
fn a_skeleton_retargeted_onto_itself_is_unchanged() {
    for rel in ["tests/data/cmu_12_01_walk.bvh", "tests/data/006_14.bvh"] {
        let clip = read(&root().join(rel));
        let same = retarget(&clip, clip.skeleton());
        let all: Vec<usize> = (0..clip.skeleton().joint_count()).collect();
        let error = path_error(&clip, &same.clip, &all);
        // The feet are held where planted: a capture's own slow drift (≤ 2 cm within a
        // plant) is taken out, so only the upper body and the pelvis must match exactly.
        let body = BodyJoints::find(clip.skeleton()).expect("body");
        let mut upper = vec![body.pelvis, body.chest()];
        for arm in &body.arms {
            upper.extend([arm.shoulder, arm.elbow, arm.wrist]);
        }
        let upper_error = path_error(&clip, &same.clip, &upper);
        let drop = same.report.pelvis_drop_m;
        assert!(drop < 0.01, "{rel}: {drop}");
        assert!(
            upper_error < 1e-6 + drop,
            "{rel}: upper body off by {upper_error} m (pelvis lowered {drop} m)"
        );
        // Within a plant the ankle is held at its mean (the capture drifts ≤ 2 cm), the knee
        // and toes with it.
        assert!(error < 0.05, "{rel}: off by {error} m");
        assert_eq!(same.report.leg_scale, 1.0);
    }
}

#[test]
fn planted_feet_do_not_slide_and_reach_their_goals() {
    let walk = read(&root().join("tests/data/cmu_12_01_walk.bvh"));
    let cc = read(&root().join("tests/data/006_14.bvh"));
    let mut pairs = vec![
        (walk.clone(), cc.skeleton().clone()),
        (cc.clone(), walk.skeleton().clone()),
    ];
    if let Some(b) = shared("bandai-raise-left/normal_003.bvh") {
        pairs.push((walk.clone(), b.skeleton().clone()));
        pairs.push((b.clone(), walk.skeleton().clone()));
    }
    for (clip, to) in &pairs {
        let out = retarget(clip, to);
        let r = &out.report;
        assert!(
            r.plants.iter().all(|p| !p.is_empty()),
            "no plant found: {r:?}"
        );
        // The report's measure, and an independent one: the ankle's path on the plant's frames.
        assert!(r.foot_slide_m <= 1e-3, "{r:?}");
        let body = BodyJoints::find(to).expect("body");
        let feet = out
            .clip
            .trajectory(&[body.legs[0].ankle, body.legs[1].ankle])
            .expect("fk");
        let ankles = [feet.path(0), feet.path(1)];
        for (s, plants) in r.plants.iter().enumerate() {
            for p in plants {
                let first = ankles[s][p.first];
                for ankle in &ankles[s][p.first..=p.last] {
                    let moved = (ankle - first).norm();
                    assert!(moved <= 1e-3, "foot {s} slides {moved} m in {p:?}");
                }
            }
        }
        assert!(r.foot_error_m.iter().all(|e| *e < 0.01), "{r:?}");
    }
}

#[test]
fn built_in_maps_name_what_the_finders_find() {
    let cases = [
        ("cmu", "tests/data/cmu_12_01_walk.bvh", false),
        ("cc", "tests/data/006_14.bvh", false),
        (
            "bandai",
            "../shared/data/bandai-raise-left/active_001.bvh",
            true,
        ),
        ("mixamo", "../shared/data/formats/mixamo_walk.bvh", true),
    ];
    for (name, rel, is_shared) in cases {
        let path = root().join(rel);
        if is_shared && !path.exists() {
            require_shared::shared_absent(&format!("skipping the `{name}` map: {rel} absent"));
            continue;
        }
        let clip = read(&path);
        let found = BodyJoints::find(clip.skeleton()).expect("find");
        let mapped = BodyJoints::built_in(clip.skeleton(), name)
            .expect("a built-in map")
            .expect("the rig has the map's joints");
        assert_eq!(found, mapped, "{name}");
    }
    let cmu = read(&root().join("tests/data/cmu_12_01_walk.bvh"));
    assert!(BodyJoints::built_in(cmu.skeleton(), "nope").is_none());
    let wrong = BodyJoints::built_in(cmu.skeleton(), "bandai").expect("known");
    assert!(wrong.is_err());
    let bad = BodyJoints::from_json(cmu.skeleton(), r#"{"pelvis": "Hips", "tail": "X"}"#);
    assert!(bad.unwrap_err().to_string().contains("unknown role `tail`"));
}

/// `TargetArms::Source`: a Bandai Namco take onto the Character Creator rig gets the performer's
/// upper arms and forearms times the bodies' size ratio (every bone of the template between
/// shoulder and elbow, elbow and wrist, scaled by one factor), the hands keep the template's,
/// and the wrists then follow the performer's own shoulder-relative paths × that ratio.
#[test]
fn the_performers_arms_scale_the_templates_arm_bones_and_carry_the_wrists() {
    use kinergy_motion::TargetArms;
    let Some(take) = shared("bandai-raise-left/active_005.bvh") else {
        return;
    };
    let cc = read(&root().join("tests/data/006_14.bvh"));
    let (from, to) = (
        BodyJoints::find(take.skeleton()).expect("source"),
        BodyJoints::find(cc.skeleton()).expect("target"),
    );
    let template = cc.skeleton().clone();
    let own = TargetArms::Template
        .skeleton(&take, &from, template.clone(), &to)
        .expect("template");
    assert!(
        Arc::ptr_eq(&own, &template),
        "the template's arms: the template itself"
    );
    let body = TargetArms::Source
        .skeleton(&take, &from, template.clone(), &to)
        .expect("source arms");
    let done = Retargeter::new(&take, from.clone(), body.clone(), to.clone())
        .expect("retargeter")
        .run(&take)
        .expect("run");
    let size = done.report.leg_scale;
    assert!(
        (done.report.arm_scale[0] - size).abs() < 1e-9,
        "{:?}",
        done.report
    );
    let bone = |clip: &Clip, a: usize, b: usize| {
        let p = clip
            .skeleton()
            .world_positions(clip.frame(0).expect("frame"))
            .expect("fk");
        (p[b] - p[a]).norm()
    };
    let rest = |skeleton: &kinergy_motion::Skeleton, a: usize, b: usize| {
        let p = skeleton.world_positions(&skeleton.rest_pose()).expect("fk");
        (p[b] - p[a]).norm()
    };
    // How far the template's own arm bones are from the performer's: the option changes them.
    let mut changed = 0.0;
    for s in 0..2 {
        let (a, b) = (&from.arms[s], &to.arms[s]);
        for ((sa, sb), (ta, tb)) in [
            ((a.shoulder, a.elbow), (b.shoulder, b.elbow)),
            ((a.elbow, a.wrist), (b.elbow, b.wrist)),
        ] {
            let want = bone(&take, sa, sb) * size;
            assert!((rest(&body, ta, tb) - want).abs() < 1e-9, "arm {s}");
            changed += (rest(&template, ta, tb) - want).abs();
        }
        if let Some(h) = b.hand {
            assert_eq!(
                rest(&body, b.wrist, h),
                rest(&template, b.wrist, h),
                "the hand kept"
            );
        }
        // The wrist's path about the shoulder is the performer's × the size ratio.
        let (sp, tp) = (
            take.trajectory(&[a.shoulder, a.wrist]).expect("source"),
            done.clip
                .trajectory(&[b.shoulder, b.wrist])
                .expect("target"),
        );
        for (x, y) in sp.frames().zip(tp.frames()) {
            let off = ((y[1] - y[0]) - (x[1] - x[0]) * size).norm();
            assert!(off < 1e-3, "arm {s}: the wrist {off} m off its path");
        }
    }
    assert!(
        changed > 0.02,
        "the template's arms are already the performer's ({changed} m)"
    );
}

/// The largest distance, over frames, between `joint` relative to `hips` in two clips of one
/// skeleton.
fn relative_error(a: &Clip, b: &Clip, joint: usize, hips: usize) -> f64 {
    let (pa, pb) = (
        a.trajectory(&[joint, hips]).expect("fk"),
        b.trajectory(&[joint, hips]).expect("fk"),
    );
    pa.frames()
        .zip(pb.frames())
        .map(|(x, y)| ((x[0] - x[1]) - (y[0] - y[1])).norm())
        .fold(0.0, f64::max)
}

// Keypoints without hands or feet (the Character Creator take as Human3.6M's 17: wrists,
// ankles and head are End Sites) retarget onto the CMU rig: the feet plant and stay put, and
// relative to the hips the target's ankles come within 5 cm and its wrists within 7 cm of
// where the full rig's own retarget puts them (measured 3.8 and 5.7 cm: the keypoints' trunk
// has fewer joints, no clavicles and no feet, whose ankles hold their rest angle to the shank).
#[test]
fn keypoints_without_hands_or_feet_move_a_body_as_their_full_rig_does() {
    let walk = read(&root().join("tests/data/cmu_12_01_walk.bvh"));
    let cc = read(&root().join("tests/data/006_14.bvh"));
    let points = keypoints::h36m_keypoints(&cc);
    let body = BodyJoints::find(points.skeleton()).expect("keypoints' body");
    for (arm, leg) in body.arms.iter().zip(&body.legs) {
        assert!(points.skeleton().joint(arm.wrist).end_site && arm.hand.is_none());
        assert!(points.skeleton().joint(leg.ankle).end_site && leg.toe.is_none());
    }
    let from_points = retarget(&points, walk.skeleton());
    let from_rig = retarget(&cc, walk.skeleton());
    let r = &from_points.report;
    assert!(r.plants.iter().all(|p| !p.is_empty()), "{r:?}");
    assert!(r.foot_slide_m <= 1e-3, "{r:?}");
    assert!(r.foot_error_m.iter().all(|e| *e < 0.01), "{r:?}");
    let target = BodyJoints::find(walk.skeleton()).expect("target body");
    let hips = target.pelvis;
    for s in 0..2 {
        let ankle = relative_error(
            &from_points.clip,
            &from_rig.clip,
            target.legs[s].ankle,
            hips,
        );
        let wrist = relative_error(
            &from_points.clip,
            &from_rig.clip,
            target.arms[s].wrist,
            hips,
        );
        eprintln!("leg and arm {s}: ankle {ankle:.3} m, wrist {wrist:.3} m from the full rig's");
        assert!(
            ankle < 0.05 && wrist < 0.07,
            "{s}: ankle {ankle} m, wrist {wrist} m"
        );
    }
}
