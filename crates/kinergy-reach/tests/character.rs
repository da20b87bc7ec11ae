//! The 21-bone, 43-DoF character: counts, the rest pose, DoF directions, BVH round trips,
//! limb chains against the character's own FK, centre of mass and support, proportions
//! measured on a CMU capture and on keypoints without hands or feet, and bad input.

use std::f64::consts::TAU;
use std::path::PathBuf;

use approx::assert_relative_eq;
use kinergy_motion::nalgebra::{Point2, Point3};
use kinergy_motion::{
    ExportOptions, ImportOptions, LengthUnit, Motion, Skeleton, read_clip, write_clip,
};
use kinergy_reach::ReachError;
use kinergy_reach::character::{
    BONE_COUNT, Character, DOF_COUNT, Limb, OVERHEAD_TWIST_FROM, Pose, Proportions, Ratios,
    SpineJoint, dof, joint,
};
use proptest::prelude::*;
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

#[path = "../../../tests/support/keypoints.rs"]
mod keypoints;

fn body() -> Character {
    Character::from_height(1.75).expect("a 1.75 m character")
}

/// A pose with every rotation uniformly inside its limits (swings uniform in their
/// ellipse) and the root moved about.
fn random_pose(body: &Character, rng: &mut Xoshiro256PlusPlus) -> Pose {
    let mut pose = body.rest_pose();
    pose[dof::ROOT_X] = rng.random_range(-0.5..0.5);
    pose[dof::ROOT_Y] += rng.random_range(-0.3..0.1);
    pose[dof::ROOT_Z] = rng.random_range(-0.5..0.5);
    for j in body.joints() {
        let mut k = j.first_dof + if j.translates { 3 } else { 0 };
        for m in &j.motions {
            match *m {
                Motion::Revolute { min, max, .. } => pose[k] = rng.random_range(min..=max),
                Motion::Swing { rx, ry } => {
                    let r = rng.random::<f64>().sqrt();
                    let a = rng.random_range(0.0..TAU);
                    pose[k] = rx * r * a.cos();
                    pose[k + 1] = ry * r * a.sin();
                }
            }
            k += m.dof_count();
        }
    }
    pose
}

fn setting_field(e: ReachError) -> String {
    match e {
        ReachError::Setting(s) => s.field,
        other => panic!("expected a Setting error, got {other}"),
    }
}

fn workspace_file(rel: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../..")
        .join(rel)
}

#[test]
fn twenty_one_bones_and_forty_three_dofs() {
    let b = body();
    assert_eq!((b.bone_count(), BONE_COUNT), (21, 21));
    assert_eq!((b.dof_count(), DOF_COUNT), (43, 43));
    assert_eq!(b.joints().len(), joint::COUNT);
    // 6 + 3 + 3 + 3 + 4 × 7, joint by joint.
    let per_joint: Vec<usize> = b
        .joints()
        .iter()
        .map(|j| j.dofs.len())
        .filter(|&n| n > 0)
        .collect();
    assert_eq!(per_joint[..4], [6, 3, 3, 3]);
    assert_eq!(per_joint[4..].iter().sum::<usize>(), 4 * 7);
    // Bones have length, and each joint but the root and the clavicle joints (which sit on
    // the thorax) ends exactly one bone.
    let rest = b.world_positions(&b.rest_pose());
    for bone in b.bones() {
        assert!((rest[bone.to] - rest[bone.from]).norm() > 0.01, "{bone:?}");
    }
    for (i, j) in b.joints().iter().enumerate() {
        let ends = b.bones().iter().filter(|bone| bone.to == i).count();
        let expected = usize::from(
            j.parent.is_some() && i != joint::RIGHT_SHOULDER && i != joint::LEFT_SHOULDER,
        );
        assert_eq!(ends, expected, "{}", j.name);
    }
    // Names are unique, DoF ranges match the limbs and the spine.
    let mut names = b.dof_names().to_vec();
    names.sort();
    names.dedup();
    assert_eq!(names.len(), 43);
    assert_eq!(b.dof_index("right_elbow_flexion"), Some(18));
    assert_eq!(b.dof_index("left_knee_flexion"), Some(39));
    assert_eq!(b.dof_index("root_ty"), Some(dof::ROOT_Y));
    assert_eq!(SpineJoint::Cervical.rotation_dofs(), dof::CERVICAL);
    assert_eq!(SpineJoint::Sacral.rotation_dofs(), dof::ROOT_ROTATION);
    for (limb, range) in
        Limb::ALL
            .into_iter()
            .zip([dof::RIGHT_ARM, dof::LEFT_ARM, dof::RIGHT_LEG, dof::LEFT_LEG])
    {
        assert_eq!(b.limb_dofs(limb), range);
        let base = &b.joints()[b.limb_joints(limb)[0]];
        assert_eq!(base.first_dof, range.start);
        let chain_names: Vec<_> = b.limb_chain(limb).dof_names().collect();
        for (i, n) in chain_names.iter().enumerate() {
            assert!(b.dof_names()[range.start + i].ends_with(n));
        }
    }
    // The exported skeleton: 3 rotation channels per rotating joint, 6 on the root; the
    // clavicles rotate with the girdle (no DoFs of the pose, 3 channels each).
    let s = b.to_skeleton();
    assert_eq!(s.joint_count(), joint::COUNT);
    assert_eq!(s.dof_count(), 6 + 3 * 3 + 2 * 3 + 4 * 3 * 3);
    assert_eq!(s.joint(joint::RIGHT_SHOULDER).dofs.len(), 3);
    assert_eq!(s.joint(joint::HEAD).dofs.len(), 0);
    for (cj, sj) in b.joints().iter().zip(s.joints()) {
        assert_eq!(cj.name, sj.name);
    }
}

#[test]
fn rest_pose_stands_on_the_floor_facing_z_with_arms_down() {
    for height in [0.9, 1.6, 1.75, 2.1] {
        let b = Character::from_height(height).expect("character");
        let rest = b.rest_pose();
        assert_eq!(b.joint_limits_ok(&rest), Ok(()));
        let p = b.world_positions(&rest);
        for foot in b.foot_points(&rest) {
            assert!(foot.y.abs() < 1e-12, "{foot}");
        }
        // Top of the head at the given height (within 2 %; it is exact by construction).
        let top = p[joint::HEAD_END].y;
        assert!((top - height).abs() < 0.02 * height, "{top} vs {height}");
        assert_relative_eq!(top, height, epsilon = 1e-12);
        assert_relative_eq!(b.proportions().height(), height, epsilon = 1e-12);
        // At the origin: the root above (0, 0).
        assert_relative_eq!(p[joint::HIPS].x, 0.0);
        assert_relative_eq!(p[joint::HIPS].z, 0.0);
        // Facing +Z: toes ahead of heels; left is +X.
        let [rh, rt, lh, lt] = b.foot_points(&rest);
        assert!(rt.z > 0.0 && rh.z < 0.0 && lt.z > 0.0 && lh.z < 0.0);
        assert!(p[joint::LEFT_HAND_END].x > 0.0 && p[joint::RIGHT_HAND_END].x < 0.0);
        assert!(lt.x > 0.0 && rt.x < 0.0);
        // Arms hang straight down from the shoulders.
        for limb in [Limb::RightArm, Limb::LeftArm] {
            let [s, e, w, t] = b.limb_joints(limb);
            let arm = b.proportions().arm(limb.side());
            assert_relative_eq!(p[t].x, p[s].x, epsilon = 1e-12);
            assert_relative_eq!(p[t].z, p[s].z, epsilon = 1e-12);
            assert_relative_eq!(p[s].y - p[e].y, arm.upper_arm, epsilon = 1e-12);
            assert_relative_eq!(p[e].y - p[w].y, arm.forearm, epsilon = 1e-12);
            assert_relative_eq!(p[w].y - p[t].y, arm.hand, epsilon = 1e-12);
        }
        // Shoulders at Drillis & Contini's 0.818 H.
        assert_relative_eq!(p[joint::RIGHT_ARM].y, 0.818 * height, epsilon = 1e-12);
    }
}

#[test]
fn dofs_move_the_body_the_documented_way() {
    let b = body();
    let rest = b.rest_pose();
    let p0 = b.world_positions(&rest);
    let moved = |name: &str, value: f64| {
        let mut pose = rest;
        pose[b.dof_index(name).expect(name)] = value;
        b.world_positions(&pose)
    };
    // Elbow flexion brings the hand forward; shoulder swing_x raises the arm forward.
    assert!(moved("right_elbow_flexion", 1.0)[joint::RIGHT_HAND].z > 0.1);
    assert!(moved("left_shoulder_swing_x", 0.5)[joint::LEFT_FOREARM].z > 0.1);
    // Shoulder swing_y swings the arm toward −X: out for the right arm.
    assert!(
        moved("right_shoulder_swing_y", 0.5)[joint::RIGHT_FOREARM].x
            < p0[joint::RIGHT_FOREARM].x - 0.1
    );
    // Knee flexion takes the ankle back; negative hip swing_x raises the thigh forward.
    assert!(moved("right_knee_flexion", 1.0)[joint::RIGHT_FOOT].z < -0.2);
    assert!(moved("left_hip_swing_x", -0.8)[joint::LEFT_LEG].z > 0.2);
    // Ankle swing_x points the toe down.
    assert!(moved("right_ankle_swing_x", 0.4)[joint::RIGHT_FOOT_END].y < -0.01);
    // Spine: swing_x bends forward, swing_y to the left (+X), twist turns to the left.
    assert!(moved("lumbar_swing_x", 0.4)[joint::HEAD].z > 0.1);
    assert!(moved("thoracic_swing_y", 0.3)[joint::HEAD].x > 0.05);
    let turned = moved("root_twist", std::f64::consts::FRAC_PI_2);
    assert!(
        turned[joint::LEFT_ARM].z < -0.1,
        "the left shoulder goes back"
    );
    assert!(
        turned[joint::RIGHT_FOOT_END].x > 0.1,
        "the toes point to +X"
    );
}

#[test]
fn rest_pose_exports_as_zero_rotations() {
    let b = body();
    let clip = b.to_clip(&[b.rest_pose()], 1.0 / 30.0).expect("clip");
    let values = clip.frame(0).expect("frame");
    assert_eq!(values[1], b.proportions().root_height());
    for (i, v) in values.iter().enumerate().filter(|&(i, _)| i != 1) {
        assert!(v.abs() < 1e-15, "channel {i} = {v}");
    }
    let fk = clip.skeleton().world_positions(values).expect("fk");
    for (a, c) in fk.iter().zip(b.world_positions(&b.rest_pose())) {
        assert_relative_eq!(*a, c, epsilon = 1e-15);
    }
}

#[test]
fn bvh_round_trip_keeps_every_joint_in_place() {
    let b = Character::from_height(1.68).expect("character");
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(43);
    // Generated motions start standing, which is what the unit guess looks at.
    let mut poses = vec![b.rest_pose()];
    poses.extend((0..300).map(|_| random_pose(&b, &mut rng)));
    for pose in &poses {
        assert_eq!(b.joint_limits_ok(pose), Ok(()));
    }
    let clip = b.to_clip(&poses, 1.0 / 60.0).expect("clip");
    let dir = tempfile::tempdir().expect("temp dir");
    let mut worst = 0.0f64;
    for unit in [LengthUnit::Centimeter, LengthUnit::Meter] {
        let path = dir.path().join(format!("character_{unit}.bvh"));
        write_clip(
            &path,
            &clip,
            &ExportOptions {
                unit,
                ..Default::default()
            },
        )
        .expect("write");
        let (back, report) = read_clip(&path, &ImportOptions::default()).expect("read");
        assert_eq!(report.unit, unit, "the unit guess finds the written unit");
        assert_eq!(back.frame_count(), poses.len());
        let names: Vec<&str> = back
            .skeleton()
            .joints()
            .iter()
            .map(|j| j.name.as_str())
            .collect();
        let ours: Vec<&str> = b.joints().iter().map(|j| j.name.as_str()).collect();
        assert_eq!(names, ours);
        for (frame, pose) in back.frames().zip(&poses) {
            let read = back.skeleton().world_positions(frame).expect("fk");
            let truth = b.world_positions(pose);
            for (r, t) in read.iter().zip(&truth) {
                worst = worst.max((r - t).norm());
            }
        }
    }
    assert!(
        worst < 1e-12,
        "worst joint error after the round trip: {worst:e} m"
    );
    // Also in memory, with the trajectory API.
    let all: Vec<usize> = (0..joint::COUNT).collect();
    let traj = clip.trajectory(&all).expect("trajectory");
    for (f, pose) in poses.iter().enumerate() {
        for (a, t) in traj.frame(f).iter().zip(b.world_positions(pose)) {
            assert_relative_eq!(*a, t, epsilon = 1e-12);
        }
    }
}

#[test]
fn consecutive_frames_do_not_jump_by_whole_turns() {
    // The root turning through ±180°: the written heading must keep going, not wrap.
    let b = body();
    let poses: Vec<Pose> = (0..100)
        .map(|i| {
            let mut p = b.rest_pose();
            let heading = 2.5 + 0.02 * i as f64;
            let wrapped = if heading > std::f64::consts::PI {
                heading - TAU
            } else {
                heading
            };
            p[dof::ROOT_ROTATION.start + dof::TWIST] = wrapped;
            p[dof::LUMBAR.start + dof::SWING_X] = 0.3;
            p
        })
        .collect();
    let clip = b.to_clip(&poses, 0.01).expect("clip");
    let frames: Vec<&[f64]> = clip.frames().collect();
    for w in frames.windows(2) {
        for (a, c) in w[0].iter().zip(w[1]) {
            assert!((a - c).abs() < 0.05, "{a} → {c}");
        }
    }
}

#[test]
fn limb_chains_reach_the_character_s_own_joints() {
    let b = Character::from_height(1.82).expect("character");
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    for _ in 0..500 {
        let pose = random_pose(&b, &mut rng);
        let p = b.world_positions(&pose);
        for limb in Limb::ALL {
            let chain = b.limb_chain(limb);
            let base = b.limb_base_frame(limb, &pose);
            let q = &pose[b.limb_dofs(limb)];
            let [j0, j1, j2, tip] = b.limb_joints(limb);
            let end = chain.end_position(&base, q).expect("fk");
            assert_relative_eq!(end, p[tip], epsilon = 1e-12);
            let fk = chain.fk(&base, q).expect("fk");
            for (i, j) in [j0, j1, j2].into_iter().enumerate() {
                assert_relative_eq!(fk.joint_position(i), p[j], epsilon = 1e-12);
            }
            assert!(chain.within_limits(q));
        }
    }
}

/// Forward kinematics of one joint's ancestors gives exactly what the full pass gives it,
/// and a limb's base frame is the full pass's.
#[test]
fn one_joints_frame_is_the_full_passs() {
    let c = body();
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(7);
    for _ in 0..50 {
        let pose = random_pose(&c, &mut rng);
        let all = c.world_frames(&pose);
        for (j, frame) in all.iter().enumerate() {
            assert_eq!(c.joint_frame(j, &pose), *frame, "joint {j}");
        }
        for limb in [Limb::RightArm, Limb::LeftArm, Limb::RightLeg, Limb::LeftLeg] {
            // The arm's base turns back by the girdle: the same frame up to rounding.
            let (a, b) = (
                c.limb_base_frame(limb, &pose),
                c.limb_base_frame_in(limb, &all),
            );
            assert_relative_eq!(a.translation.vector, b.translation.vector, epsilon = 1e-12);
            assert_relative_eq!(a.rotation.matrix(), b.rotation.matrix(), epsilon = 1e-12);
        }
    }
}

#[test]
fn limb_rest_frames_hang_the_limbs_along_their_z() {
    let b = body();
    let rest = b.rest_pose();
    for limb in Limb::ALL {
        let frame = b.limb_base_frame(limb, &rest);
        let z = frame.rotation * kinergy_motion::nalgebra::Vector3::z();
        assert_relative_eq!(z, -kinergy_motion::nalgebra::Vector3::y(), epsilon = 1e-15);
    }
    // Arms are Chain::arm with the character's lengths, the shoulder's swing widened to the
    // humerothoracic 180° of the girdle (character::girdle).
    let arm = b.proportions().right_arm;
    let expected = kinergy_motion::Chain::arm(arm.upper_arm, arm.forearm, arm.hand).expect("arm");
    let ours = b.limb_chain(Limb::RightArm);
    assert_eq!(ours.end_effector(), expected.end_effector());
    for (i, (a, e)) in ours.joints().iter().zip(expected.joints()).enumerate() {
        assert_eq!((a.offset, a.rest), (e.offset, e.rest));
        if i > 0 {
            assert_eq!(a.motions, e.motions);
        }
    }
    match ours.joints()[0].motions[0] {
        kinergy_motion::Motion::Swing { rx, ry } => {
            assert_relative_eq!(rx, std::f64::consts::PI, epsilon = 1e-9);
            assert_relative_eq!(ry, std::f64::consts::PI, epsilon = 1e-9);
        }
        _ => panic!("the shoulder swings first"),
    }
}

#[test]
fn rest_com_is_over_the_feet_at_a_human_height() {
    for height in [1.5, 1.75, 1.95] {
        let b = Character::from_height(height).expect("character");
        let rest = b.rest_pose();
        let segments = b.mass_segments(&rest);
        assert_eq!(segments.len(), 16);
        let total: f64 = segments.iter().map(|s| s.mass_fraction).sum();
        assert_relative_eq!(total, 1.0, epsilon = 1e-12);
        let com = b.com(&rest);
        let ratio = com.y / height;
        assert!((0.53..0.60).contains(&ratio), "COM at {ratio} H");
        assert_relative_eq!(com.x, 0.0, epsilon = 1e-12);
        let support = b.support_polygon(&rest);
        assert_eq!(support.vertices().len(), 4);
        let margin = support.margin(Point2::new(com.x, com.z));
        assert!(margin > 0.02, "COM only {margin} m inside the feet");
        assert!(support.contains(Point2::new(com.x, com.z)));
    }
}

#[test]
fn a_lifted_foot_leaves_the_support_polygon() {
    let b = body();
    let mut pose = b.rest_pose();
    pose[b.dof_index("left_hip_swing_x").expect("dof")] = -0.6;
    pose[b.dof_index("left_knee_flexion").expect("dof")] = 1.0;
    let support = b.support_polygon(&pose);
    let [rh, rt, ..] = b.foot_points(&pose);
    assert_eq!(
        support.vertices().len(),
        4,
        "only the right sole: heel and toe, each widened by half the foot breadth"
    );
    assert!(support.contains(Point2::new(rh.x, rh.z)) && support.contains(Point2::new(rt.x, rt.z)));
    let com = b.com(&pose);
    assert!(!support.contains(Point2::new(com.x, com.z)));
}

#[test]
fn proportions_from_the_cmu_capture_keep_its_bone_lengths() {
    let path = workspace_file("tests/data/cmu_12_01_walk.bvh");
    let (clip, report) = read_clip(&path, &ImportOptions::default()).expect("CMU fixture");
    assert_eq!(report.unit, LengthUnit::Cmu);
    let s: &Skeleton = clip.skeleton();
    let zero = s.world_positions(&s.rest_pose()).expect("fk");
    let at = |name: &str| zero[s.require_joint(name).expect(name)];
    let d = |a: &str, b: &str| (at(a) - at(b)).norm();
    for p in [
        Proportions::from_clip(&clip).expect("from clip"),
        Proportions::from_skeleton(s).expect("from skeleton"),
    ] {
        for (side, arm, leg) in [
            ("Right", &p.right_arm, &p.right_leg),
            ("Left", &p.left_arm, &p.left_leg),
        ] {
            let n = |role: &str| format!("{side}{role}");
            assert_relative_eq!(arm.upper_arm, d(&n("Arm"), &n("ForeArm")), epsilon = 1e-12);
            assert_relative_eq!(arm.forearm, d(&n("ForeArm"), &n("Hand")), epsilon = 1e-12);
            assert_relative_eq!(arm.hand, d(&n("Hand"), &n("HandIndex1")), epsilon = 1e-12);
            assert_relative_eq!(leg.thigh, d(&n("UpLeg"), &n("Leg")), epsilon = 1e-12);
            assert_relative_eq!(leg.shank, d(&n("Leg"), &n("Foot")), epsilon = 1e-12);
            assert_relative_eq!(
                leg.foot(),
                d(&n("Foot"), &n("ToeBase_End")),
                epsilon = 1e-12
            );
        }
        assert_relative_eq!(p.shoulder_width, d("RightArm", "LeftArm"), epsilon = 1e-12);
        assert_relative_eq!(p.hip_width, d("RightUpLeg", "LeftUpLeg"), epsilon = 1e-12);
        let h = p.height();
        assert!((1.3..2.0).contains(&h), "measured height {h} m");
        // The character built from them has the capture's limbs and stands on the floor.
        let b = Character::new(&p).expect("character");
        let upper = b.limb_chain(Limb::LeftArm).joints()[1].offset.z;
        assert_relative_eq!(upper, p.left_arm.upper_arm, epsilon = 1e-15);
        let rest = b.rest_pose();
        for foot in b.foot_points(&rest) {
            assert!(foot.y.abs() < 1e-12, "{foot}");
        }
        assert_relative_eq!(
            b.world_positions(&rest)[joint::HEAD_END].y,
            h,
            epsilon = 1e-12
        );
    }
}

#[test]
fn bad_input_names_the_field() {
    assert_eq!(
        setting_field(Proportions::from_height(0.0).unwrap_err()),
        "height"
    );
    assert_eq!(
        setting_field(Proportions::from_height(f64::NAN).unwrap_err()),
        "height"
    );
    assert_eq!(
        setting_field(Proportions::from_height(-1.7).unwrap_err()),
        "height"
    );
    assert_eq!(
        setting_field(Character::from_height(3.0).unwrap_err()),
        "height"
    );
    for edge in [Proportions::MIN_HEIGHT, Proportions::MAX_HEIGHT] {
        assert!(Character::from_height(edge).is_ok(), "{edge} m is accepted");
    }
    let negative = Ratios {
        thigh: -0.245,
        ..Ratios::default()
    };
    assert_eq!(
        setting_field(Proportions::from_ratios(1.7, &negative).unwrap_err()),
        "ratios.thigh"
    );
    let nan = Ratios {
        hand: f64::NAN,
        ..Ratios::default()
    };
    assert_eq!(
        setting_field(Proportions::from_ratios(1.7, &nan).unwrap_err()),
        "ratios.hand"
    );
    let unbalanced = Ratios {
        head: 0.2,
        ..Ratios::default()
    };
    assert_eq!(
        setting_field(Proportions::from_ratios(1.7, &unbalanced).unwrap_err()),
        "ratios"
    );
    let mut p = Proportions::from_height(1.7).expect("proportions");
    p.right_arm.forearm = -0.2;
    assert_eq!(
        setting_field(Character::new(&p).unwrap_err()),
        "right_arm.forearm"
    );
    let mut p = Proportions::from_height(1.7).expect("proportions");
    p.spine.shoulder_drop = p.spine.thoracic;
    assert_eq!(
        setting_field(Character::new(&p).unwrap_err()),
        "spine.shoulder_drop"
    );

    // A skeleton without legs: the error says which leg is missing.
    let b = body();
    let arms_only: Vec<_> = b.to_skeleton().joints()[..joint::RIGHT_UP_LEG].to_vec();
    let s = Skeleton::new(arms_only).expect("skeleton");
    let e = Proportions::from_skeleton(&s).unwrap_err();
    assert!(e.to_string().contains("no right leg"), "{e}");

    // Limits name the DoF.
    let mut pose = b.rest_pose();
    pose[b.dof_index("right_elbow_flexion").expect("dof")] = 3.0;
    let why = b.joint_limits_ok(&pose).unwrap_err();
    assert!(why.contains("right_elbow_flexion"), "{why}");
    let mut pose = b.rest_pose();
    pose[dof::CERVICAL.start] = 1.5;
    let why = b.joint_limits_ok(&pose).unwrap_err();
    assert!(why.contains("cervical_swing_x"), "{why}");
    let mut pose = b.rest_pose();
    pose[dof::ROOT_X] = f64::NAN;
    assert!(b.joint_limits_ok(&pose).unwrap_err().contains("root_tx"));
}

#[test]
fn the_exported_character_reads_back_as_proportions() {
    // Our own skeleton, measured by role, gives back our limb lengths.
    let b = Character::from_height(1.8).expect("character");
    let p = Proportions::from_skeleton(b.skeleton()).expect("measured");
    let q = b.proportions();
    assert_relative_eq!(
        p.right_arm.upper_arm,
        q.right_arm.upper_arm,
        epsilon = 1e-12
    );
    assert_relative_eq!(p.left_arm.hand, q.left_arm.hand, epsilon = 1e-12);
    assert_relative_eq!(p.right_leg.thigh, q.right_leg.thigh, epsilon = 1e-12);
    assert_relative_eq!(p.left_leg.shank, q.left_leg.shank, epsilon = 1e-12);
    assert_relative_eq!(p.left_leg.foot(), q.left_leg.foot(), epsilon = 1e-12);
    assert_relative_eq!(p.shoulder_width, q.shoulder_width, epsilon = 1e-12);
    assert_relative_eq!(p.hip_width, q.hip_width, epsilon = 1e-12);
    assert_relative_eq!(p.height(), 1.8, epsilon = 1e-9);
}

/// The shoulder's twist range widens overhead: the table's ±90° up to
/// [`OVERHEAD_TWIST_FROM`] of elevation, ±180° at 180°, linearly between. Why (an independent check of the identity the widening
/// rests on): with the arm straight up, a twist is the same rotation as a swing about another
/// horizontal axis, S(πu)·Rz(τ) = S(π·Rz(−τ/2)u), so no twist is out of reach there.
#[test]
fn the_shoulder_twist_range_widens_to_any_twist_straight_up() {
    use kinergy_motion::rotation::{Axis, axis_rotation, swing_rotation};
    use std::f64::consts::PI;
    for (u, tau) in [(0.3f64, -2.9f64), (1.9, 1.2), (-2.4, 3.0)] {
        let (ux, uy) = (u.cos(), u.sin());
        let twisted = swing_rotation(PI * ux, PI * uy) * axis_rotation(Axis::Z, tau);
        let (vx, vy) = ((u - tau / 2.0).cos(), (u - tau / 2.0).sin());
        let swung = swing_rotation(PI * vx, PI * vy);
        assert!(
            (twisted.matrix() - swung.matrix()).norm() < 1e-12,
            "u {u}, tau {tau}"
        );
    }
    let b = body();
    let arm = b.limb_dofs(Limb::RightArm);
    let posed = |elevation_deg: f64, twist: f64| {
        let mut pose = b.rest_pose();
        let e = elevation_deg.to_radians();
        pose[arm.start] = e * 0.6;
        pose[arm.start + 1] = e * 0.8;
        pose[arm.start + 2] = twist;
        pose
    };
    let from = OVERHEAD_TWIST_FROM.to_degrees();
    let between = 0.5 * (from + 180.0);
    for (e, expect) in [(60.0, 90.0), (from, 90.0), (between, 135.0), (180.0, 180.0)] {
        let (low, high) = b
            .revolute_range(arm.start + 2, &posed(e, 0.0))
            .expect("the twist is revolute");
        let (low, high) = (low.to_degrees(), high.to_degrees());
        assert!(
            (low + expect).abs() < 1e-9 && (high - expect).abs() < 1e-9,
            "{e}°: [{low}, {high}]"
        );
        // Clamped, a twist beyond the range is the same rotation a turn away where that lies
        // within it (wide ranges overhead), else the range's end.
        for twist in [-4.0f64, 4.0] {
            let mut pose = posed(e, twist);
            b.clamp_pose(&mut pose);
            assert_eq!(b.joint_limits_ok(&pose), Ok(()));
            let got = pose[arm.start + 2].to_degrees();
            let turned = (twist - twist.signum() * std::f64::consts::TAU).to_degrees();
            let want = if (low..=high).contains(&turned) {
                turned
            } else {
                twist.signum() * expect
            };
            assert!(
                (got - want).abs() < 1e-9,
                "{e}°, twist {twist}: {got}° ({want}°)"
            );
        }
    }
}

#[test]
fn an_angle_difference_is_the_same_for_values_a_turn_apart() {
    use kinergy_reach::character::angle_difference;
    use std::f64::consts::PI;
    assert!((angle_difference(0.3, 0.1) - 0.2).abs() < 1e-12);
    assert!((angle_difference(3.787 - TAU, 3.787)).abs() < 1e-12);
    assert!((angle_difference(-3.0, 3.0) - (TAU - 6.0)).abs() < 1e-12);
    assert!((angle_difference(PI, 0.0) - PI).abs() < 1e-12);
}

/// A limb's limits read in one walk (`limb_limits`, what the arm controller bounds each
/// frame with) are those read one DoF at a time, for every limb, at poses whose shoulder twist
/// range widens overhead.
#[test]
fn a_limbs_limits_read_at_once_are_those_read_one_dof_at_a_time() {
    use kinergy_reach::character::DofLimit;
    let b = body();
    for limb in Limb::ALL {
        let dofs = b.limb_dofs(limb);
        for elevation in [0.0f64, 100.0, 170.0] {
            let mut pose = b.rest_pose();
            pose[dofs.start] = elevation.to_radians() * 0.6;
            pose[dofs.start + 1] = elevation.to_radians() * 0.8;
            let limits = b.limb_limits(limb, &pose);
            for (i, limit) in limits.iter().enumerate().take(dofs.len().min(7)) {
                let k = dofs.start + i;
                let expected = match (b.revolute_range(k, &pose), b.swing_radii(k)) {
                    (Some((min, max)), _) => DofLimit::Revolute { min, max },
                    (None, Some((rx, ry))) => DofLimit::Swing { rx, ry },
                    (None, None) if i > 0 && b.swing_radii(k - 1).is_some() => {
                        DofLimit::SwingSecond
                    }
                    (None, None) => DofLimit::Free,
                };
                assert_eq!(*limit, expected, "{limb:?} DoF {i} at {elevation}°");
            }
        }
    }
}

proptest! {
    #[test]
    fn clamping_lands_within_limits(values in proptest::collection::vec(-4.0f64..4.0, DOF_COUNT)) {
        let b = body();
        let mut pose: Pose = values.try_into().expect("43 values");
        b.clamp_pose(&mut pose);
        prop_assert_eq!(b.joint_limits_ok(&pose), Ok(()));
    }

    #[test]
    fn chains_match_fk_even_outside_limits(values in proptest::collection::vec(-3.0f64..3.0, DOF_COUNT)) {
        let b = body();
        let pose: Pose = values.try_into().expect("43 values");
        let p = b.world_positions(&pose);
        for limb in Limb::ALL {
            let end = b
                .limb_chain(limb)
                .end_position(&b.limb_base_frame(limb, &pose), &pose[b.limb_dofs(limb)])
                .expect("fk");
            let tip: Point3<f64> = p[b.limb_joints(limb)[3]];
            prop_assert!((end - tip).norm() < 1e-12);
        }
    }
}

// Keypoints without hands or feet (the Character Creator take as Human3.6M's 17: wrists,
// ankles and the head are End Sites) measure as the full rig does where they hold the same
// joints: upper arm, forearm, thigh and shank within 2 mm (the keypoints' bones are held at
// their median lengths). The hand and the foot come from Drillis & Contini, and the height
// from the head's keypoint (the fixture's `CC_Base_Head`, below the crown) within 10 %.
#[test]
fn keypoints_without_hands_or_feet_measure_as_their_full_rig() {
    let path = workspace_file("tests/data/006_14.bvh");
    let cc = read_clip(&path, &ImportOptions::default()).expect("read").0;
    let rig = Proportions::from_clip(&cc).expect("the full rig");
    let points = Proportions::from_clip(&keypoints::h36m_keypoints(&cc)).expect("keypoints");
    let close = |a: f64, b: f64, what: &str| assert!((a - b).abs() < 2e-3, "{what}: {a} vs {b}");
    for (p, r) in [
        (points.right_arm, rig.right_arm),
        (points.left_arm, rig.left_arm),
    ] {
        close(p.upper_arm, r.upper_arm, "upper arm");
        close(p.forearm, r.forearm, "forearm");
        assert_relative_eq!(
            p.hand,
            p.forearm * kinergy_motion::limbs::arm::HAND_PER_FOREARM
        );
    }
    for (p, r) in [
        (points.right_leg, rig.right_leg),
        (points.left_leg, rig.left_leg),
    ] {
        close(p.thigh, r.thigh, "thigh");
        close(p.shank, r.shank, "shank");
        assert_relative_eq!(
            p.toe,
            Ratios::DRILLIS_CONTINI.toe * points.height(),
            epsilon = 1e-12
        );
    }
    let (h, hr) = (points.height(), rig.height());
    eprintln!("height {h:.3} m, the full rig's {hr:.3} m");
    assert!(
        (h / hr - 1.0).abs() < 0.1,
        "height {h} m, the full rig's {hr} m"
    );
}
