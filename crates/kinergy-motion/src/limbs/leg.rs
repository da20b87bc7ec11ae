//! The leg by joint role (hip → knee → ankle → toe tip).
//!
//! The ankle is a `Foot`/`Ankle` joint of the side; its parent (twist, roll, share and helper
//! bones skipped) must be a knee — `Leg` (not `UpLeg`/`UpperLeg`), `LowerLeg`/`LowLeg`,
//! `Knee`, `Shin` or `Calf` — and the knee's a hip — `UpLeg`/`UpperLeg`, `Thigh` or `Hip`
//! (so CMU's `RHipJoint`, role `hipjoint`, is not one). The toe tip is the ankle's farthest
//! descendant in the zero pose. CMU's and Mixamo's `RightUpLeg` → `RightLeg` → `RightFoot`
//! → `RightToeBase` is one such leg.

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
    /// The ankle (the foot bone starts here).
    pub ankle: usize,
    /// The toe tip: the ankle's farthest descendant in the zero pose (a joint or End Site).
    pub toe: usize,
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
    /// that side, in joint order, with a knee and a hip above it. Errors:
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
        for ankle in (0..skeleton.joint_count()).filter(|&j| {
            !skeleton.joint(j).end_site && info[j].0 == Some(side) && is_ankle_role(&info[j].1)
        }) {
            let Some(knee) = parent_skipping_helpers(ankle).filter(|&k| is_knee_role(&info[k].1))
            else {
                continue;
            };
            let Some(hip) = parent_skipping_helpers(knee).filter(|&h| is_hip_role(&info[h].1))
            else {
                continue;
            };
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
                toe,
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
