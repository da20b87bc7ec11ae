//! The arm chain by joint role (clavicle → shoulder → elbow → wrist → hand).
//!
//! The chain is found from the hand upward, skipping twist, roll, share, helper, bend and
//! adjust bones, so the conventions below all work, including the ambiguity of `Shoulder`
//! (the clavicle in CMU's naming, the upper arm in the Collar style):
//!
//! | convention | clavicle | shoulder | elbow | wrist |
//! |---|---|---|---|---|
//! | CMU, Mixamo | `RightShoulder` | `RightArm` | `RightForeArm` | `RightHand` |
//! | Bandai Namco | `Shoulder_R` | `UpperArm_R` | `LowerArm_R` | `Hand_R` |
//! | Character Creator | `CC_Base_R_Clavicle` | `CC_Base_R_Upperarm` | `CC_Base_R_Forearm` | `CC_Base_R_Hand` |
//! | Collar style | `RightCollar` | `RightShoulder` | `RightElbow` | `RightWrist` |
//! | Human3.6M, COCO (`from-positions`) | — | `right_shoulder` | `right_elbow` | its End Site |
//!
//! A wrist that is a leaf, as in keypoint sets without hands (Human3.6M's 17 joints, COCO's
//! keypoints), is the forearm's End Site in the BVH `from-positions` writes: without a wrist
//! by name, a forearm whose only children are an End Site (and helpers) ends the arm there.

use crate::clip::Clip;
use crate::error::{MotionError, Result};
use crate::side::Side;
use crate::skeleton::Skeleton;

use super::names::{name_tokens, role_word, side_of};

/// The joints of one arm, by role. Indices are into the skeleton's joints.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ArmJoints {
    /// Which arm (`None` when given by explicit names whose side is unclear).
    pub side: Option<Side>,
    /// The clavicle (collar), if the skeleton has one.
    pub clavicle: Option<usize>,
    /// The shoulder joint (the upper arm bone starts here).
    pub shoulder: usize,
    /// The elbow (the forearm bone starts here).
    pub elbow: usize,
    /// The wrist (the hand bone starts here); an End Site where the wrist is a leaf (keypoints
    /// without hands), which has no rotation of its own.
    pub wrist: usize,
    /// A point on the hand beyond the wrist, used as the end effector: the middle finger's
    /// base, an End Site, the index finger's base or a finger-base joint, in that order of
    /// preference; `None` when the wrist has no child with a length (Bandai Namco's `Hand_R`,
    /// whose End Site has offset 0 in some sets). Without one the wrist is the end effector
    /// ([`ArmJoints::end_effector`]) and a hand length, where one is needed, is
    /// [`ArmLengths::hand_or_default`].
    pub hand: Option<usize>,
}

/// Lengths of an arm's bones in one pose, meters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArmLengths {
    /// Shoulder to elbow.
    pub upper_arm: f64,
    /// Elbow to wrist.
    pub forearm: f64,
    /// Wrist to the hand point (0 without one).
    pub hand: f64,
}

/// The hand's length (wrist to fingertip) per unit of forearm length, used where an arm has
/// no hand point below its wrist (Bandai Namco's `Hand_R` ends in an End Site of length 0, or
/// nothing): Drillis & Contini's hand 0.108 H over forearm 0.146 H (Winter, *Biomechanics and
/// Motor Control of Human Movement*, Fig. 4.1), about 0.74.
pub const HAND_PER_FOREARM: f64 = 0.108 / 0.146;

impl ArmLengths {
    /// Upper arm + forearm + hand.
    pub fn total(&self) -> f64 {
        self.upper_arm + self.forearm + self.hand
    }

    /// The hand's length: the measured one, or, without a hand point (`hand` 0),
    /// [`HAND_PER_FOREARM`] × the forearm.
    pub fn hand_or_default(&self) -> f64 {
        if self.hand > 0.0 {
            self.hand
        } else {
            HAND_PER_FOREARM * self.forearm
        }
    }
}

impl ArmJoints {
    /// The joints the motion distance compares, in order: shoulder, elbow, wrist and, when
    /// there is one, the hand point (the end effector).
    pub fn metric_joints(&self) -> Vec<usize> {
        let mut j = vec![self.shoulder, self.elbow, self.wrist];
        j.extend(self.hand);
        j
    }

    /// The end effector: the hand point, or the wrist without one.
    pub fn end_effector(&self) -> usize {
        self.hand.unwrap_or(self.wrist)
    }

    /// Bone lengths measured in the clip's first frame (position channels on non-root
    /// joints can change bone lengths, so the offsets alone are not enough).
    pub fn lengths(&self, clip: &Clip) -> Result<ArmLengths> {
        let pose = clip.frame(0).ok_or(MotionError::EmptyClip)?;
        let p = clip.skeleton().world_positions(pose)?;
        let d = |a: usize, b: usize| (p[a] - p[b]).norm();
        Ok(ArmLengths {
            upper_arm: d(self.shoulder, self.elbow),
            forearm: d(self.elbow, self.wrist),
            hand: self.hand.map_or(0.0, |h| d(self.wrist, h)),
        })
    }

    /// Names of the chain's joints, clavicle (if any) to hand point (if any).
    pub fn names<'a>(&self, skeleton: &'a Skeleton) -> Vec<&'a str> {
        self.clavicle
            .into_iter()
            .chain([self.shoulder, self.elbow, self.wrist])
            .chain(self.hand)
            .map(|j| skeleton.joint(j).name.as_str())
            .collect()
    }
}

fn is_helper(word: &str) -> bool {
    ["twist", "roll", "share", "helper", "bend", "adjust"]
        .iter()
        .any(|k| word.contains(k))
}

fn is_hand(word: &str) -> bool {
    matches!(word, "hand" | "wrist")
}

fn is_forearm(word: &str) -> bool {
    matches!(word, "forearm" | "lowerarm" | "elbow" | "lowarm")
}

fn is_clavicle(word: &str) -> bool {
    matches!(word, "shoulder" | "collar" | "clavicle" | "collarbone")
}

fn is_arm_like(word: &str) -> bool {
    [
        "arm", "hand", "wrist", "elbow", "shoulder", "clavicle", "collar", "humerus",
    ]
    .iter()
    .any(|k| word.contains(k))
}

impl ArmJoints {
    /// Finds the `side` arm by joint names (see the [module docs](self) and [`super`] for the names); the error lists
    /// the arm-like joints it saw.
    pub fn find(skeleton: &Skeleton, side: Side) -> Result<ArmJoints> {
        let info: Vec<(Option<Side>, String)> = skeleton
            .joints()
            .iter()
            .map(|j| {
                let t = name_tokens(&j.name);
                (side_of(&t), role_word(&t))
            })
            .collect();
        let non_helper_parent = |mut j: usize| -> Option<usize> {
            loop {
                j = skeleton.joint(j).parent?;
                if !is_helper(&info[j].1) {
                    return Some(j);
                }
            }
        };
        let mut hands: Vec<usize> = (0..skeleton.joint_count())
            .filter(|&j| {
                !skeleton.joint(j).end_site && info[j].0 == Some(side) && is_hand(&info[j].1)
            })
            .collect();
        hands.sort_by_key(|&j| depth(skeleton, j));
        // Then, without a wrist by name, forearms ending in an End Site of some length, their
        // only other children helpers: leaf wrists.
        let mut leaves: Vec<usize> = (0..skeleton.joint_count())
            .filter(|&e| {
                !skeleton.joint(e).end_site && info[e].0 == Some(side) && is_forearm(&info[e].1)
            })
            .filter_map(|e| super::leaf_end(skeleton, e, |c| is_helper(&info[c].1)))
            .collect();
        leaves.sort_by_key(|&j| depth(skeleton, j));
        let named = hands.len();
        for (k, wrist) in hands.into_iter().chain(leaves).enumerate() {
            // A leaf wrist's forearm is its parent, found above.
            let elbow = if k < named {
                non_helper_parent(wrist)
            } else {
                skeleton.joint(wrist).parent
            };
            let Some(elbow) = elbow.filter(|&e| is_forearm(&info[e].1)) else {
                continue;
            };
            let Some(shoulder) = non_helper_parent(elbow) else {
                continue;
            };
            let clavicle = non_helper_parent(shoulder)
                .filter(|&c| is_clavicle(&info[c].1) && info[c].0 == Some(side));
            return Ok(ArmJoints {
                side: Some(side),
                clavicle,
                shoulder,
                elbow,
                wrist,
                hand: hand_point(skeleton, wrist, &info),
            });
        }
        Err(MotionError::ArmNotFound {
            side,
            candidates: skeleton
                .joints()
                .iter()
                .zip(&info)
                .filter(|(j, (_, w))| !j.end_site && is_arm_like(w))
                .map(|(j, _)| j.name.clone())
                .collect(),
        })
    }

    /// The arm given by joint names: `[shoulder, elbow, wrist]` or
    /// `[clavicle, shoulder, elbow, wrist]`, each the parent-side ancestor of the next.
    pub fn from_names(skeleton: &Skeleton, names: &[&str]) -> Result<ArmJoints> {
        let idx: Vec<usize> = names
            .iter()
            .map(|n| skeleton.require_joint(n.trim()))
            .collect::<Result<_>>()?;
        if !(3..=4).contains(&idx.len()) {
            return Err(MotionError::Invalid {
                what: "arm chain",
                why: format!(
                    "expected 3 or 4 joint names (clavicle,shoulder,elbow,wrist), got {}",
                    idx.len()
                ),
            });
        }
        for w in idx.windows(2) {
            if w[0] == w[1] || !skeleton.is_ancestor_or_self(w[0], w[1]) {
                return Err(MotionError::NotAChain {
                    ancestor: skeleton.joint(w[0]).name.clone(),
                    child: skeleton.joint(w[1]).name.clone(),
                });
            }
        }
        let (clavicle, rest) = if idx.len() == 4 {
            (Some(idx[0]), &idx[1..])
        } else {
            (None, &idx[..])
        };
        let info: Vec<(Option<Side>, String)> = skeleton
            .joints()
            .iter()
            .map(|j| {
                let t = name_tokens(&j.name);
                (side_of(&t), role_word(&t))
            })
            .collect();
        Ok(ArmJoints {
            side: info[rest[2]].0,
            clavicle,
            shoulder: rest[0],
            elbow: rest[1],
            wrist: rest[2],
            hand: hand_point(skeleton, rest[2], &info),
        })
    }
}

fn depth(skeleton: &Skeleton, mut j: usize) -> usize {
    let mut d = 0;
    while let Some(p) = skeleton.joint(j).parent {
        j = p;
        d += 1;
    }
    d
}

/// The best end-effector point below the wrist. Zero-length joints (CMU's `RightFingerBase`)
/// are looked through to their children; thumbs and helper bones are never chosen.
fn hand_point(skeleton: &Skeleton, wrist: usize, info: &[(Option<Side>, String)]) -> Option<usize> {
    let has = |j: usize, keys: &[&str]| keys.iter().any(|k| info[j].1.contains(k));
    let mut candidates = Vec::new();
    let mut stack: Vec<(usize, usize)> = skeleton.children(wrist).map(|c| (c, 0)).collect();
    while let Some((j, depth)) = stack.pop() {
        if has(j, &["thumb", "twist", "share", "roll"]) {
            continue;
        }
        if skeleton.joint(j).offset.norm() > 0.0 {
            candidates.push(j);
        } else if depth < 3 {
            stack.extend(skeleton.children(j).map(|c| (c, depth + 1)));
        }
    }
    let rank = |j: usize| -> u8 {
        if has(j, &["mid", "middle"]) {
            0
        } else if skeleton.joint(j).end_site {
            1
        } else if has(j, &["index"]) {
            2
        } else if has(j, &["fingerbase", "finger", "palm"]) {
            3
        } else {
            4
        }
    };
    candidates
        .into_iter()
        .map(|c| (rank(c), c))
        .min()
        .map(|(_, c)| c)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::{Joint, PositionReading};
    use nalgebra::Vector3;

    fn chain_skeleton(names: &[&str]) -> Skeleton {
        let mut joints = vec![Joint {
            name: "Hips".into(),
            parent: None,
            offset: Vector3::zeros(),
            dofs: vec![],
            end_site: false,
            position_reading: PositionReading::AddToOffset,
        }];
        for (i, n) in names.iter().enumerate() {
            joints.push(Joint {
                name: (*n).into(),
                parent: Some(i),
                offset: Vector3::new(-0.1, 0.0, 0.0),
                dofs: vec![],
                end_site: false,
                position_reading: PositionReading::AddToOffset,
            });
        }
        Skeleton::new(joints).expect("valid")
    }

    fn found(names: &[&str], side: Side) -> Vec<String> {
        let s = chain_skeleton(names);
        let arm = ArmJoints::find(&s, side).expect("arm");
        arm.names(&s).into_iter().map(String::from).collect()
    }

    #[test]
    fn finds_every_naming_convention() {
        let cmu = [
            "Spine",
            "RightShoulder",
            "RightArm",
            "RightForeArm",
            "RightHand",
            "RightFingerBase",
        ];
        assert_eq!(found(&cmu, Side::Right), &cmu[1..]);
        let bandai = ["Chest", "Shoulder_L", "UpperArm_L", "LowerArm_L", "Hand_L"];
        assert_eq!(found(&bandai, Side::Left), &bandai[1..]);
        let mixamo = [
            "mixamorig:Spine2",
            "mixamorig:RightShoulder",
            "mixamorig:RightArm",
            "mixamorig:RightForeArm",
            "mixamorig:RightHand",
            "mixamorig:RightHandMiddle1",
        ];
        assert_eq!(found(&mixamo, Side::Right), &mixamo[1..]);
        let collar = [
            "Chest",
            "RightCollar",
            "RightShoulder",
            "RightElbow",
            "RightWrist",
        ];
        assert_eq!(found(&collar, Side::Right), &collar[1..]);
        let cc = [
            "CC_Base_Spine02",
            "CC_Base_R_Clavicle",
            "CC_Base_R_Upperarm",
            "CC_Base_R_UpperarmTwist01",
            "CC_Base_R_Forearm",
            "CC_Base_R_ForearmTwist01",
            "CC_Base_R_Hand",
        ];
        assert_eq!(
            found(&cc, Side::Right),
            [
                "CC_Base_R_Clavicle",
                "CC_Base_R_Upperarm",
                "CC_Base_R_Forearm",
                "CC_Base_R_Hand"
            ]
        );
    }

    /// `chain_skeleton(names)` with an End Site of `length` below its last joint, and a joint
    /// `extra` beside it when given.
    fn with_end_site(names: &[&str], length: f64, extra: Option<&str>) -> Skeleton {
        let mut joints = chain_skeleton(names).joints().to_vec();
        let last = joints.len() - 1;
        let leaf = |name: String, end_site: bool| Joint {
            name,
            parent: Some(last),
            offset: Vector3::new(-length, 0.0, 0.0),
            dofs: vec![],
            end_site,
            position_reading: PositionReading::AddToOffset,
        };
        let end = leaf(format!("{}_End", names[names.len() - 1]), true);
        let extra = extra.map(|n| leaf(n.into(), false));
        joints.push(end);
        joints.extend(extra);
        Skeleton::new(joints).expect("valid")
    }

    #[test]
    fn a_leaf_wrist_is_the_forearms_end_site() {
        // Human3.6M's keypoints as `from-positions` writes them: no wrist joint.
        let h36m = ["thorax", "left_shoulder", "left_elbow"];
        let s = with_end_site(&h36m, 0.25, None);
        let arm = ArmJoints::find(&s, Side::Left).expect("arm");
        assert_eq!(
            arm.names(&s),
            ["left_shoulder", "left_elbow", "left_elbow_End"]
        );
        assert_eq!((arm.clavicle, arm.hand), (None, None));
        assert!(s.joint(arm.wrist).end_site);
        assert_eq!(arm.end_effector(), arm.wrist);
        assert_eq!(arm.metric_joints(), [2, 3, 4]);
        // A twist helper beside the End Site changes nothing.
        let s = with_end_site(&h36m, 0.25, Some("left_elbow_twist"));
        assert_eq!(ArmJoints::find(&s, Side::Left).expect("arm").wrist, 4);
        // Not from an End Site of no length, nor from a forearm with a joint below it that
        // is not a helper (an unknown hand), nor on the other side.
        for s in [
            with_end_site(&h36m, 0.0, None),
            with_end_site(&h36m, 0.25, Some("left_palm")),
        ] {
            assert!(ArmJoints::find(&s, Side::Left).is_err());
        }
        assert!(ArmJoints::find(&with_end_site(&h36m, 0.25, None), Side::Right).is_err());
        // A wrist by name comes first, its End Site below it the hand point.
        let named = ["thorax", "left_shoulder", "left_elbow", "left_wrist"];
        let s = with_end_site(&named, 0.08, None);
        let arm = ArmJoints::find(&s, Side::Left).expect("arm");
        assert_eq!(
            arm.names(&s),
            [
                "left_shoulder",
                "left_elbow",
                "left_wrist",
                "left_wrist_End"
            ]
        );
    }

    #[test]
    fn missing_arm_lists_candidates() {
        let s = chain_skeleton(&[
            "Spine",
            "RightShoulder",
            "RightArm",
            "RightForeArm",
            "RightHand",
        ]);
        let e = ArmJoints::find(&s, Side::Left).expect_err("no left arm");
        let msg = e.to_string();
        assert!(
            // Which options to suggest is the command line's business.
            msg.contains("RightForeArm") && !msg.contains("--chain"),
            "{msg}"
        );
    }

    #[test]
    fn explicit_names_must_form_a_chain() {
        let s = chain_skeleton(&["Spine", "A", "B", "C", "D"]);
        let arm = ArmJoints::from_names(&s, &["A", "B", "C", "D"]).expect("chain");
        assert_eq!((arm.clavicle, arm.shoulder, arm.wrist), (Some(2), 3, 5));
        assert!(matches!(
            ArmJoints::from_names(&s, &["B", "A", "C"]),
            Err(MotionError::NotAChain { .. })
        ));
        assert!(matches!(
            ArmJoints::from_names(&s, &["A", "Nope", "C"]),
            Err(MotionError::UnknownJoint { .. })
        ));
    }
}
