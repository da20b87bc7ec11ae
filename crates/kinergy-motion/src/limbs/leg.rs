//! The leg by joint role (hip → knee → ankle → toe tip).
//!
//! The ankle is a `Foot`/`Ankle` joint of the side; its parent (twist, roll, share and helper
//! bones skipped) must be a knee — `Leg` (not `UpLeg`/`UpperLeg`), `LowerLeg`/`LowLeg`,
//! `Knee`, `Shin` or `Calf` — and the knee's a hip — `UpLeg`/`UpperLeg`, `Thigh` or `Hip`
//! (so CMU's `RHipJoint`, role `hipjoint`, is not one). The toe tip is the ankle's farthest
//! descendant in the zero pose. CMU's and Mixamo's `RightUpLeg` → `RightLeg` → `RightFoot`
//! → `RightToeBase` is one such leg.
//!
//! Keypoints without feet (Human3.6M's 17, COCO's 17, as `from-positions` writes them) have
//! leaf ankles: the knee's End Site. Without an ankle by name, a knee whose only children are
//! an End Site of some length (and helpers) ends the leg there, with no toe.

use crate::error::{MotionError, Result};
use crate::side::Side;
use crate::skeleton::Skeleton;

use super::names::{name_tokens, role_word, side_token};

/// The joints of one leg, by role. Indices are into the skeleton's joints.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LegJoints {
    /// The hip (the thigh bone starts here).
    pub hip: usize,
    /// The knee (the shank bone starts here).
    pub knee: usize,
    /// The ankle (the foot bone starts here); the knee's End Site where the ankle is a leaf
    /// (keypoints without feet).
    pub ankle: usize,
    /// The toe tip: the ankle's farthest descendant in the zero pose (a joint or End Site);
    /// `None` for a leaf ankle, whose foot the skeleton does not have.
    pub toe: Option<usize>,
}

/// The side a name's tokens give (the last side token), and its role: the other tokens
/// joined (`RightUpLeg` → `upleg`, `CC_Base_L_Calf` → `calf`).
fn side_and_role(name: &str) -> (Option<Side>, String) {
    let tokens = name_tokens(name);
    let side = tokens.iter().rev().find_map(|t| side_token(t));
    (side, role_word(&tokens))
}

fn is_ankle_role(role: &str) -> bool {
    role.ends_with("foot") || role.ends_with("ankle")
}

fn is_knee_role(role: &str) -> bool {
    ["lowerleg", "lowleg", "knee", "shin", "calf"]
        .iter()
        .any(|k| role.ends_with(k))
        || (role.ends_with("leg") && !role.ends_with("upleg") && !role.ends_with("upperleg"))
}

fn is_hip_role(role: &str) -> bool {
    ["upleg", "upperleg", "thigh", "hip"]
        .iter()
        .any(|k| role.ends_with(k))
}

fn is_helper_role(role: &str) -> bool {
    ["twist", "roll", "share", "helper"]
        .iter()
        .any(|k| role.contains(k))
}

impl LegJoints {
    /// Finds the `side` leg by joint names (see the [module docs](self)): the first ankle of
    /// that side, in joint order, with a knee and a hip above it; else a leaf ankle (the
    /// [module docs](self)). Errors:
    /// [`MotionError::LegNotFound`] listing the leg-like joints seen, and
    /// [`MotionError::NoToe`] when the ankle has nothing below it.
    pub fn find(skeleton: &Skeleton, side: Side) -> Result<LegJoints> {
        let info: Vec<(Option<Side>, String)> = skeleton
            .joints()
            .iter()
            .map(|j| side_and_role(&j.name))
            .collect();
        let parent_skipping_helpers = |mut j: usize| -> Option<usize> {
            loop {
                j = skeleton.joint(j).parent?;
                if !is_helper_role(&info[j].1) {
                    return Some(j);
                }
            }
        };
        let zero = skeleton.world_positions(&skeleton.rest_pose())?;
        let named = (0..skeleton.joint_count()).filter(|&j| {
            !skeleton.joint(j).end_site && info[j].0 == Some(side) && is_ankle_role(&info[j].1)
        });
        // Then, without an ankle by name, knees ending in an End Site of some length, their
        // only other children helpers: leaf ankles.
        let leaves = (0..skeleton.joint_count())
            .filter(|&k| {
                !skeleton.joint(k).end_site && info[k].0 == Some(side) && is_knee_role(&info[k].1)
            })
            .filter_map(|k| super::leaf_end(skeleton, k, |c| is_helper_role(&info[c].1)));
        for ankle in named.chain(leaves) {
            let leaf = skeleton.joint(ankle).end_site;
            let knee = if leaf {
                skeleton.joint(ankle).parent
            } else {
                parent_skipping_helpers(ankle)
            };
            let Some(knee) = knee.filter(|&k| is_knee_role(&info[k].1)) else {
                continue;
            };
            let Some(hip) = parent_skipping_helpers(knee).filter(|&h| is_hip_role(&info[h].1))
            else {
                continue;
            };
            if leaf {
                return Ok(LegJoints {
                    hip,
                    knee,
                    ankle,
                    toe: None,
                });
            }
            let toe = (ankle + 1..skeleton.joint_count())
                .filter(|&d| skeleton.is_ancestor_or_self(ankle, d))
                .max_by(|&a, &b| {
                    let da = (zero[a] - zero[ankle]).norm();
                    let db = (zero[b] - zero[ankle]).norm();
                    da.total_cmp(&db)
                });
            let Some(toe) = toe else {
                return Err(MotionError::NoToe {
                    side,
                    ankle: skeleton.joint(ankle).name.clone(),
                });
            };
            return Ok(LegJoints {
                hip,
                knee,
                ankle,
                toe: Some(toe),
            });
        }
        Err(MotionError::LegNotFound {
            side,
            candidates: skeleton
                .joints()
                .iter()
                .zip(&info)
                .filter(|(j, (_, r))| {
                    !j.end_site && (is_ankle_role(r) || is_knee_role(r) || is_hip_role(r))
                })
                .map(|(j, _)| j.name.clone())
                .collect(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::skeleton::{Joint, PositionReading};
    use nalgebra::Vector3;

    /// A chain of joints below `Hips`, each 0.4 m below the last, ending in an End Site
    /// `foot` m below its last joint.
    fn leg(names: &[&str], foot: f64) -> Skeleton {
        let joint = |name: &str, parent: Option<usize>, drop: f64, end_site: bool| Joint {
            name: name.into(),
            parent,
            offset: Vector3::new(0.0, -drop, 0.0),
            dofs: vec![],
            end_site,
            position_reading: PositionReading::AddToOffset,
        };
        let mut joints = vec![joint("Hips", None, 0.0, false)];
        for (i, n) in names.iter().enumerate() {
            joints.push(joint(n, Some(i), 0.4, false));
        }
        let last = format!("{}_End", names[names.len() - 1]);
        joints.push(joint(&last, Some(names.len()), foot, true));
        Skeleton::new(joints).expect("valid")
    }

    #[test]
    fn a_leaf_ankle_is_the_knees_end_site_and_has_no_toe() {
        // Human3.6M's keypoints as `from-positions` writes them: no ankle joint.
        let s = leg(&["right_hip", "right_knee"], 0.4);
        let l = LegJoints::find(&s, Side::Right).expect("leg");
        assert_eq!((l.hip, l.knee, l.ankle, l.toe), (1, 2, 3, None));
        assert!(s.joint(l.ankle).end_site);
        // Not from an End Site of no length, nor on the other side.
        assert!(LegJoints::find(&leg(&["right_hip", "right_knee"], 0.0), Side::Right).is_err());
        assert!(LegJoints::find(&s, Side::Left).is_err());
        // An ankle by name keeps its toe (here its End Site).
        let s = leg(&["RightUpLeg", "RightLeg", "RightFoot"], 0.15);
        let l = LegJoints::find(&s, Side::Right).expect("leg");
        assert_eq!((l.ankle, l.toe), (3, Some(4)));
    }

    #[test]
    fn tokens_and_roles_of_common_leg_names() {
        assert_eq!(
            side_and_role("RightUpLeg"),
            (Some(Side::Right), "upleg".into())
        );
        assert_eq!(
            side_and_role("RHipJoint"),
            (Some(Side::Right), "hipjoint".into())
        );
        assert_eq!(side_and_role("Calf_L"), (Some(Side::Left), "calf".into()));
        assert!(is_knee_role("leg") && !is_knee_role("upleg") && is_hip_role("thigh"));
        assert!(!is_hip_role("hipjoint"));
    }
}
