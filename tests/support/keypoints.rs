//! The Character Creator fixture (`tests/data/006_14.bvh`) as Human3.6M's 17 keypoints, made
//! into a clip as `from-positions` makes one: its wrists, ankles and head are leaves (End
//! Sites), as keypoints without hands or feet give them. Shared by the tests of the arm and
//! leg finders' leaf joints.

#![allow(dead_code)]

use kinergy_motion::{Clip, JointMap, PositionArrays};

/// Each Human3.6M keypoint and the fixture's joint at the same place.
pub const H36M_FROM_CC: [(&str, &str); 17] = [
    ("hip", "CC_Base_Hip"),
    ("right_hip", "CC_Base_R_Thigh"),
    ("right_knee", "CC_Base_R_Calf"),
    ("right_foot", "CC_Base_R_Foot"),
    ("left_hip", "CC_Base_L_Thigh"),
    ("left_knee", "CC_Base_L_Calf"),
    ("left_foot", "CC_Base_L_Foot"),
    ("spine", "CC_Base_Spine01"),
    ("thorax", "CC_Base_Spine02"),
    ("neck", "CC_Base_NeckTwist01"),
    ("head", "CC_Base_Head"),
    ("left_shoulder", "CC_Base_L_Upperarm"),
    ("left_elbow", "CC_Base_L_Forearm"),
    ("left_wrist", "CC_Base_L_Hand"),
    ("right_shoulder", "CC_Base_R_Upperarm"),
    ("right_elbow", "CC_Base_R_Forearm"),
    ("right_wrist", "CC_Base_R_Hand"),
];

/// `clip` (the Character Creator fixture) as Human3.6M keypoints, built by
/// `Clip::from_positions` on the `h36m17` hierarchy.
pub fn h36m_keypoints(clip: &Clip) -> Clip {
    let map = JointMap::built_in("h36m17").expect("h36m17");
    let skeleton = clip.skeleton();
    let index: Vec<usize> = map
        .names
        .iter()
        .map(|n| {
            let (_, joint) = H36M_FROM_CC
                .iter()
                .find(|(k, _)| k == n)
                .unwrap_or_else(|| panic!("no source for {n}"));
            skeleton.joint_index(joint).expect("joint")
        })
        .collect();
    let world = clip.world_positions().expect("fk");
    let positions: Vec<[f64; 3]> = world
        .chunks(skeleton.joint_count())
        .flat_map(|frame| index.iter().map(|&j| [frame[j].x, frame[j].y, frame[j].z]))
        .collect();
    Clip::from_positions(PositionArrays {
        joint_names: &map.names,
        parents: &map.parents,
        positions: &positions,
        frame_time: clip.frame_time(),
    })
    .expect("from positions")
    .clip
}
