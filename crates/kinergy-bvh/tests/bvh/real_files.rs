//! Real mocap files: the counts and values their README gives.

use std::path::Path;

use approx::assert_relative_eq;

use kinergy_bvh::{Bvh, Channel};

use crate::common::{COMMITTED_DIR, read, shared_dir};

use Channel::{Xposition, Xrotation, Yposition, Yrotation, Zposition, Zrotation};

struct Expected {
    joints: usize,
    end_sites: usize,
    channels: usize,
    frames: usize,
    frame_time: f64,
}

fn check(bvh: &Bvh, expected: &Expected) {
    bvh.validate().unwrap();
    assert_eq!(bvh.joints.len() - bvh.end_site_count(), expected.joints);
    assert_eq!(bvh.end_site_count(), expected.end_sites);
    assert_eq!(bvh.channel_count(), expected.channels);
    assert_eq!(bvh.frame_count, expected.frames);
    assert_eq!(bvh.motion.len(), expected.frames * expected.channels);
    assert_eq!(bvh.frame_time, expected.frame_time);
}

#[test]
fn cmu_walk() {
    let bvh = read(&Path::new(COMMITTED_DIR).join("cmu_12_01_walk.bvh"));
    check(
        &bvh,
        &Expected {
            joints: 31,
            end_sites: 7,
            channels: 96,
            frames: 524,
            frame_time: 0.0083333,
        },
    );
    assert_relative_eq!(bvh.frame_rate(), 120.0, max_relative = 1e-5);
    let names: Vec<&str> = bvh
        .joints
        .iter()
        .filter(|j| !j.end_site)
        .map(|j| j.display_name())
        .collect();
    assert_eq!(
        names[..17],
        [
            "Hips",
            "LHipJoint",
            "LeftUpLeg",
            "LeftLeg",
            "LeftFoot",
            "LeftToeBase",
            "RHipJoint",
            "RightUpLeg",
            "RightLeg",
            "RightFoot",
            "RightToeBase",
            "LowerBack",
            "Spine",
            "Spine1",
            "Neck",
            "Neck1",
            "Head",
        ]
    );
    assert_eq!(
        bvh.joints[0].channels,
        [
            Xposition, Yposition, Zposition, Zrotation, Yrotation, Xrotation
        ]
    );
    for joint in bvh.joints.iter().skip(1).filter(|j| !j.end_site) {
        assert_eq!(
            joint.channels,
            [Zrotation, Yrotation, Xrotation],
            "{}",
            joint.display_name()
        );
    }
    for zero in [
        "LHipJoint",
        "RHipJoint",
        "LowerBack",
        "Neck",
        "LeftShoulder",
        "RightShoulder",
        "LThumb",
        "RThumb",
    ] {
        assert_eq!(
            bvh.joints[bvh.joint_index(zero).unwrap()].offset,
            [0.0; 3],
            "{zero}"
        );
    }
    assert_eq!(bvh.joints[2].offset, [2.10660, -1.59283, 1.11709]);
    assert_eq!(bvh.frame(0).unwrap()[..3], [0.0265, 16.2134, -25.4911]);
    // `ROOT Hips` is one of the LF-only lines among CRLF lines.
    assert_eq!(bvh.joints[0].line, 2);
}

#[test]
fn cc_rig_006_14() {
    let bvh = read(&Path::new(COMMITTED_DIR).join("006_14.bvh"));
    check(
        &bvh,
        &Expected {
            joints: 100,
            end_sites: 41,
            channels: 303,
            frames: 239,
            frame_time: 0.016667,
        },
    );
    assert_eq!(bvh.joints[0].display_name(), "CC_Base_Hip");
    assert_eq!(bvh.joints[0].offset, [0.0, 105.214226, 0.000021]);
    assert_eq!(
        bvh.joints[0].channels,
        [
            Xposition, Yposition, Zposition, Zrotation, Yrotation, Xrotation
        ]
    );
    for joint in bvh.joints.iter().skip(1).filter(|j| !j.end_site) {
        assert_eq!(
            joint.channels,
            [Zrotation, Yrotation, Xrotation],
            "{}",
            joint.display_name()
        );
    }
    assert_eq!(bvh.joints[1].offset[0].to_bits(), (-0.0f64).to_bits());
    for name in [
        "CC_Base_R_Clavicle",
        "CC_Base_R_Upperarm",
        "CC_Base_R_Forearm",
        "CC_Base_R_Hand",
        "CC_Base_R_UpperarmTwist01",
    ] {
        assert!(bvh.joint_index(name).is_some(), "{name}");
    }
    assert_eq!(
        bvh.frame(0).unwrap()[..6],
        [
            0.257992, 3.547104, -0.011680, 174.721527, 77.856903, 173.636551
        ]
    );
}

#[test]
fn bandai_guide_and_bye() {
    let Some(dir) = shared_dir() else { return };
    for (file, frames, hips_offset) in [
        (
            "dataset-1_guide_normal_001.bvh",
            86,
            [-3.80622, 93.0864, 3.55978],
        ),
        (
            "dataset-1_bye_normal_001.bvh",
            111,
            [0.0408292, 93.9915, 0.0639531],
        ),
    ] {
        let bvh = read(&dir.join(file));
        check(
            &bvh,
            &Expected {
                joints: 22,
                end_sites: 5,
                channels: 132,
                frames,
                frame_time: 0.0333333,
            },
        );
        for joint in bvh.joints.iter().filter(|j| !j.end_site) {
            assert_eq!(
                joint.channels,
                [
                    Xposition, Yposition, Zposition, Zrotation, Xrotation, Yrotation
                ],
                "{file}: {}",
                joint.display_name()
            );
        }
        assert_eq!(bvh.joints[0].display_name(), "joint_Root");
        assert_eq!(bvh.joints[1].display_name(), "Hips");
        assert_eq!(bvh.joints[1].offset, hips_offset);
        for name in ["Shoulder_R", "UpperArm_R", "LowerArm_R", "Hand_R", "Hand_L"] {
            assert!(bvh.joint_index(name).is_some(), "{file}: {name}");
        }
        // `-0` and scientific notation in the first frame.
        let first = bvh.frame(0).unwrap();
        assert_eq!(first[5].to_bits(), (-0.0f64).to_bits());
        assert_eq!(first[13], 5.1072e-06);
    }
}

#[test]
fn shared_copies_of_the_committed_files_are_identical() {
    let Some(dir) = shared_dir() else { return };
    for file in crate::common::COMMITTED_FILES {
        let committed = read(&Path::new(COMMITTED_DIR).join(file));
        assert_eq!(committed, read(&dir.join(file)), "{file}");
    }
}
