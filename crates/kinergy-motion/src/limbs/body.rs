//! The whole body by joint role: the pelvis, the spine up to the chest, the neck up to the
//! head, both arms and both legs ([`BodyJoints`]) — what retargeting maps between skeletons.
//!
//! Found ([`BodyJoints::find`]) from the limbs ([`ArmJoints::find`], [`LegJoints::find`]):
//! the **chest** is the joint both arms hang from (the lowest common ancestor of the two
//! clavicles, or shoulders without them), the **pelvis** the lowest common ancestor of both
//! hips and the chest (CMU's `Hips`, Character Creator's `CC_Base_Hip` above its separate
//! `Pelvis` and `Waist`), the **spine** the joints from the pelvis up to the chest, the
//! **head** the first joint below the chest named `Head` (no side), the **neck** the joints
//! between. Or given by name ([`BodyJoints::from_names`], a JSON object of roles:
//! [`BodyJoints::from_json`]), with built-in names for the rigs Kinergy is tested on
//! ([`BodyJoints::built_in`]).

use std::collections::BTreeMap;

use crate::error::{MotionError, Result};
use crate::side::Side;
use crate::skeleton::Skeleton;

use super::arm::ArmJoints;
use super::leg::LegJoints;
use super::names::{name_tokens, side_of};

/// The joints of a whole body, by role. Indices are into the skeleton's joints.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct BodyJoints {
    /// The pelvis: the joint the legs and the spine hang from.
    pub pelvis: usize,
    /// The spine from the pelvis (exclusive) up to the chest (inclusive, last).
    pub spine: Vec<usize>,
    /// The neck from the chest (exclusive) up to the head (exclusive); empty without a head.
    pub neck: Vec<usize>,
    /// The head, if the skeleton has one.
    pub head: Option<usize>,
    /// The arms, right then left.
    pub arms: [ArmJoints; 2],
    /// The legs, right then left.
    pub legs: [LegJoints; 2],
}

/// The roles a map names ([`BodyJoints::from_names`]): each a joint name; `spine` and `neck`
/// are lists.
pub const ROLES: [&str; 18] = [
    "pelvis",
    "spine",
    "neck",
    "head",
    "right_clavicle",
    "right_shoulder",
    "right_elbow",
    "right_wrist",
    "left_clavicle",
    "left_shoulder",
    "left_elbow",
    "left_wrist",
    "right_hip",
    "right_knee",
    "right_ankle",
    "left_hip",
    "left_knee",
    "left_ankle",
];

fn all_roles() -> impl Iterator<Item = &'static str> {
    ROLES.into_iter()
}

/// The built-in role maps: (name, the rigs it is for, roles → joint names).
const BUILT_IN: [(&str, &str, &str); 4] = [
    (
        "cmu",
        "CMU's BVH conversions (Hips, LowerBack, Spine, Spine1, LeftShoulder, LeftArm, …)",
        r#"{"pelvis":"Hips","spine":["LowerBack","Spine","Spine1"],"neck":["Neck","Neck1"],"head":"Head",
        "right_clavicle":"RightShoulder","right_shoulder":"RightArm","right_elbow":"RightForeArm","right_wrist":"RightHand",
        "left_clavicle":"LeftShoulder","left_shoulder":"LeftArm","left_elbow":"LeftForeArm","left_wrist":"LeftHand",
        "right_hip":"RightUpLeg","right_knee":"RightLeg","right_ankle":"RightFoot",
        "left_hip":"LeftUpLeg","left_knee":"LeftLeg","left_ankle":"LeftFoot"}"#,
    ),
    (
        "bandai",
        "Bandai Namco Research Motion Dataset (joint_Root, Hips, Spine, Chest, Shoulder_L, UpperArm_L, …)",
        r#"{"pelvis":"Hips","spine":["Spine","Chest"],"neck":["Neck"],"head":"Head",
        "right_clavicle":"Shoulder_R","right_shoulder":"UpperArm_R","right_elbow":"LowerArm_R","right_wrist":"Hand_R",
        "left_clavicle":"Shoulder_L","left_shoulder":"UpperArm_L","left_elbow":"LowerArm_L","left_wrist":"Hand_L",
        "right_hip":"UpperLeg_R","right_knee":"LowerLeg_R","right_ankle":"Foot_R",
        "left_hip":"UpperLeg_L","left_knee":"LowerLeg_L","left_ankle":"Foot_L"}"#,
    ),
    (
        "mixamo",
        "Mixamo (mixamorig:Hips, mixamorig:Spine, Spine1, Spine2, LeftShoulder, LeftArm, …)",
        r#"{"pelvis":"mixamorig:Hips","spine":["mixamorig:Spine","mixamorig:Spine1","mixamorig:Spine2"],
        "neck":["mixamorig:Neck"],"head":"mixamorig:Head",
        "right_clavicle":"mixamorig:RightShoulder","right_shoulder":"mixamorig:RightArm","right_elbow":"mixamorig:RightForeArm","right_wrist":"mixamorig:RightHand",
        "left_clavicle":"mixamorig:LeftShoulder","left_shoulder":"mixamorig:LeftArm","left_elbow":"mixamorig:LeftForeArm","left_wrist":"mixamorig:LeftHand",
        "right_hip":"mixamorig:RightUpLeg","right_knee":"mixamorig:RightLeg","right_ankle":"mixamorig:RightFoot",
        "left_hip":"mixamorig:LeftUpLeg","left_knee":"mixamorig:LeftLeg","left_ankle":"mixamorig:LeftFoot"}"#,
    ),
    (
        "cc",
        "Character Creator / iClone (CC_Base_Hip, CC_Base_Waist, CC_Base_Spine01, Spine02, CC_Base_L_Clavicle, …)",
        r#"{"pelvis":"CC_Base_Hip","spine":["CC_Base_Waist","CC_Base_Spine01","CC_Base_Spine02"],
        "neck":["CC_Base_NeckTwist01","CC_Base_NeckTwist02"],"head":"CC_Base_Head",
        "right_clavicle":"CC_Base_R_Clavicle","right_shoulder":"CC_Base_R_Upperarm","right_elbow":"CC_Base_R_Forearm","right_wrist":"CC_Base_R_Hand",
        "left_clavicle":"CC_Base_L_Clavicle","left_shoulder":"CC_Base_L_Upperarm","left_elbow":"CC_Base_L_Forearm","left_wrist":"CC_Base_L_Hand",
        "right_hip":"CC_Base_R_Thigh","right_knee":"CC_Base_R_Calf","right_ankle":"CC_Base_R_Foot",
        "left_hip":"CC_Base_L_Thigh","left_knee":"CC_Base_L_Calf","left_ankle":"CC_Base_L_Foot"}"#,
    ),
];

fn invalid(why: String) -> MotionError {
    MotionError::Invalid {
        what: "body map",
        why,
    }
}

/// The joints strictly between `from` and `to` (an ancestor of it), top first, then `to`.
fn path_below(skeleton: &Skeleton, from: usize, to: usize) -> Vec<usize> {
    skeleton
        .path(from, to)
        .map(|p| p.into_iter().skip(1).collect())
        .unwrap_or_default()
}

impl BodyJoints {
    /// Finds the body by joint role (see the [module docs](self)). Errors name the limb not
    /// found (with the joints that looked like it), or a chest that does not hang from the
    /// pelvis.
    pub fn find(skeleton: &Skeleton) -> Result<BodyJoints> {
        let arms = [
            ArmJoints::find(skeleton, Side::Right)?,
            ArmJoints::find(skeleton, Side::Left)?,
        ];
        let legs = [
            LegJoints::find(skeleton, Side::Right)?,
            LegJoints::find(skeleton, Side::Left)?,
        ];
        let top = |a: &ArmJoints| a.clavicle.unwrap_or(a.shoulder);
        let chest = skeleton.common_ancestor(top(&arms[0]), top(&arms[1]));
        let hips = skeleton.common_ancestor(legs[0].hip, legs[1].hip);
        let pelvis = skeleton.common_ancestor(hips, chest);
        let head = (chest + 1..skeleton.joint_count()).find(|&j| {
            let joint = skeleton.joint(j);
            let tokens = name_tokens(&joint.name);
            !joint.end_site
                && skeleton.is_ancestor_or_self(chest, j)
                && tokens.iter().any(|t| t == "head")
                && side_of(&tokens).is_none()
        });
        Self::assemble(skeleton, pelvis, chest, head, arms, legs)
    }

    fn assemble(
        skeleton: &Skeleton,
        pelvis: usize,
        chest: usize,
        head: Option<usize>,
        arms: [ArmJoints; 2],
        legs: [LegJoints; 2],
    ) -> Result<BodyJoints> {
        let name = |j: usize| skeleton.joint(j).name.clone();
        if chest == pelvis || !skeleton.is_ancestor_or_self(pelvis, chest) {
            return Err(invalid(format!(
                "the chest `{}` (where the arms hang) is not above the pelvis `{}` (where the \
                 legs hang)",
                name(chest),
                name(pelvis)
            )));
        }
        let spine = path_below(skeleton, pelvis, chest);
        let neck = match head {
            Some(h) => {
                let mut n = path_below(skeleton, chest, h);
                n.pop();
                n
            }
            None => Vec::new(),
        };
        Ok(BodyJoints {
            pelvis,
            spine,
            neck,
            head,
            arms,
            legs,
        })
    }

    /// The chest: the spine's last joint.
    pub fn chest(&self) -> usize {
        self.spine[self.spine.len() - 1]
    }

    /// The body of `skeleton` by a user's choice, as `kinergy retarget --map` and Python's
    /// `map=` take it: `auto` ([`BodyJoints::find`]), a built-in map's name
    /// ([`BodyJoints::built_in`]), or the path of a JSON map ending in `.json`
    /// ([`BodyJoints::from_json`], the file read here; errors name it).
    pub fn choose(skeleton: &Skeleton, choice: &str) -> Result<BodyJoints> {
        if choice == "auto" {
            return Self::find(skeleton);
        }
        if !choice.to_ascii_lowercase().ends_with(".json") {
            return Self::built_in(skeleton, choice).unwrap_or_else(|| {
                let names: Vec<&str> = BUILT_IN.iter().map(|b| b.0).collect();
                Err(invalid(format!(
                    "`{choice}`: auto, a built-in map ({}) or a .json map's path",
                    names.join(", ")
                )))
            });
        }
        let text =
            std::fs::read_to_string(choice).map_err(|e| invalid(format!("{choice}: {e}")))?;
        Self::from_json(skeleton, &text).map_err(|e| match e {
            MotionError::Invalid { why, .. } => invalid(format!("{choice}: {why}")),
            e => e,
        })
    }

    /// The names of the built-in maps ([`BodyJoints::built_in`]) with the rigs each is for.
    pub fn built_in_names() -> Vec<(&'static str, &'static str)> {
        BUILT_IN.iter().map(|(n, rigs, _)| (*n, *rigs)).collect()
    }

    /// The body of `skeleton` by the built-in map `name` (`cmu`, `bandai`, `mixamo`, `cc`):
    /// `None` for an unknown name, an error where the skeleton lacks a joint it names.
    pub fn built_in(skeleton: &Skeleton, name: &str) -> Option<Result<BodyJoints>> {
        let (_, _, json) = BUILT_IN.iter().find(|(n, _, _)| *n == name)?;
        Some(Self::from_json(skeleton, json))
    }

    /// The body of `skeleton` from a JSON object of roles ([`ROLES`]) to joint
    /// names; `spine` and `neck` are arrays (`spine` ending at the
    /// chest), the others strings; `head`, `neck` and the clavicles may be left out.
    pub fn from_json(skeleton: &Skeleton, text: &str) -> Result<BodyJoints> {
        let value: serde_json::Value = serde_json::from_str(text)
            .map_err(|e| invalid(format!("not a JSON object of roles: {e}")))?;
        let object = value
            .as_object()
            .ok_or_else(|| invalid("not a JSON object of roles".into()))?;
        let mut names: BTreeMap<String, Vec<String>> = BTreeMap::new();
        for (role, v) in object {
            if !all_roles().any(|r| r == role) {
                let known: Vec<&str> = all_roles().collect();
                return Err(invalid(format!(
                    "unknown role `{role}`; the roles are {}",
                    known.join(", ")
                )));
            }
            let list = match v {
                serde_json::Value::String(s) => vec![s.clone()],
                serde_json::Value::Array(a) => a
                    .iter()
                    .map(|x| {
                        x.as_str().map(str::to_owned).ok_or_else(|| {
                            invalid(format!("role `{role}`: {x} is not a joint name"))
                        })
                    })
                    .collect::<Result<_>>()?,
                other => {
                    return Err(invalid(format!(
                        "role `{role}`: {other} is not a joint name or a list of them"
                    )));
                }
            };
            names.insert(role.clone(), list);
        }
        let lists: BTreeMap<&str, Vec<&str>> = names
            .iter()
            .map(|(k, v)| (k.as_str(), v.iter().map(String::as_str).collect()))
            .collect();
        Self::from_names(skeleton, &lists)
    }

    /// The body of `skeleton` from roles to joint names (see [`BodyJoints::from_json`]):
    /// every joint must exist, each limb be a chain, the spine run from the pelvis up to the
    /// chest the arms hang from.
    pub fn from_names(
        skeleton: &Skeleton,
        roles: &BTreeMap<&str, Vec<&str>>,
    ) -> Result<BodyJoints> {
        let one = |role: &str| -> Result<Option<usize>> {
            match roles.get(role).map(Vec::as_slice) {
                None | Some([]) => Ok(None),
                Some([name]) => Ok(Some(skeleton.require_joint(name)?)),
                Some(_) => Err(invalid(format!("role `{role}` takes one joint name"))),
            }
        };
        let need = |role: &str| -> Result<usize> {
            one(role)?.ok_or_else(|| invalid(format!("role `{role}` is missing")))
        };
        let arm = |side: &str| -> Result<ArmJoints> {
            let mut names = Vec::new();
            if let Some(c) = roles.get(&*format!("{side}_clavicle")) {
                names.extend(c.iter().copied());
            }
            for r in ["shoulder", "elbow", "wrist"] {
                let role = format!("{side}_{r}");
                names.push(skeleton.joint(need(&role)?).name.as_str());
            }
            ArmJoints::from_names(skeleton, &names)
        };
        let leg = |side: &str| -> Result<LegJoints> {
            let [hip, knee, ankle] = ["hip", "knee", "ankle"].map(|r| need(&format!("{side}_{r}")));
            let (hip, knee, ankle) = (hip?, knee?, ankle?);
            for (a, b) in [(hip, knee), (knee, ankle)] {
                if a == b || !skeleton.is_ancestor_or_self(a, b) {
                    return Err(MotionError::NotAChain {
                        ancestor: skeleton.joint(a).name.clone(),
                        child: skeleton.joint(b).name.clone(),
                    });
                }
            }
            let zero = skeleton.world_positions(&skeleton.rest_pose())?;
            let toe = (ankle + 1..skeleton.joint_count())
                .filter(|&d| skeleton.is_ancestor_or_self(ankle, d))
                .max_by(|&a, &b| {
                    (zero[a] - zero[ankle])
                        .norm()
                        .total_cmp(&(zero[b] - zero[ankle]).norm())
                })
                .ok_or_else(|| MotionError::NoToe {
                    side: if side == "right" {
                        Side::Right
                    } else {
                        Side::Left
                    },
                    ankle: skeleton.joint(ankle).name.clone(),
                })?;
            Ok(LegJoints {
                hip,
                knee,
                ankle,
                toe: Some(toe),
            })
        };
        let arms = [arm("right")?, arm("left")?];
        let legs = [leg("right")?, leg("left")?];
        let pelvis = need("pelvis")?;
        let spine: Vec<usize> = roles
            .get("spine")
            .into_iter()
            .flatten()
            .map(|n| skeleton.require_joint(n))
            .collect::<Result<_>>()?;
        let Some(&chest) = spine.last() else {
            return Err(invalid(
                "role `spine` is missing (the joints up to the chest)".into(),
            ));
        };
        let head = one("head")?;
        let body = Self::assemble(skeleton, pelvis, chest, head, arms, legs)?;
        if body.spine != spine {
            let named = |js: &[usize]| {
                js.iter()
                    .map(|&j| skeleton.joint(j).name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            };
            return Err(invalid(format!(
                "role `spine` lists {}, but the joints from the pelvis to the chest are {}",
                named(&spine),
                named(&body.spine)
            )));
        }
        Ok(body)
    }

    /// Each role with its joint's name, in [`ROLES`] order (`spine` and `neck` one entry per
    /// joint), for reports.
    pub fn named(&self, skeleton: &Skeleton) -> Vec<(String, String)> {
        let name = |j: usize| skeleton.joint(j).name.clone();
        let mut out = vec![("pelvis".to_string(), name(self.pelvis))];
        out.extend(self.spine.iter().map(|&j| ("spine".to_string(), name(j))));
        out.extend(self.neck.iter().map(|&j| ("neck".to_string(), name(j))));
        out.extend(self.head.map(|j| ("head".to_string(), name(j))));
        for (side, arm) in ["right", "left"].iter().zip(&self.arms) {
            out.extend(arm.clavicle.map(|j| (format!("{side}_clavicle"), name(j))));
            out.push((format!("{side}_shoulder"), name(arm.shoulder)));
            out.push((format!("{side}_elbow"), name(arm.elbow)));
            out.push((format!("{side}_wrist"), name(arm.wrist)));
        }
        for (side, leg) in ["right", "left"].iter().zip(&self.legs) {
            out.push((format!("{side}_hip"), name(leg.hip)));
            out.push((format!("{side}_knee"), name(leg.knee)));
            out.push((format!("{side}_ankle"), name(leg.ankle)));
        }
        out
    }
}
