//! The joint table: one row per joint (its BVH name, its parent, where it sits and how it
//! moves), the bones, and the [`Character`] built by walking the rows in order.

use std::sync::Arc;

use kinergy_motion::rotation::Axis;
use kinergy_motion::{Chain, Dof, Joint, Motion, PositionReading, Side, Skeleton};
use nalgebra::{Rotation3, Vector3};

use super::{Bone, Character, CharacterJoint, GirdleRole};
use crate::character::layout::{
    DOF_COUNT, DofKind, LIMB_ORDER, Limb, SPINE_ORDER, SpineJoint, arm_frame, joint, leg_frame,
    spine_frame,
};
use crate::character::limits::{arm_chain, leg_chain, spine_motions};
use crate::character::proportions::{Proportions, SpineSegments};
use crate::error::Result;

/// A length of the spine a joint sits up its parent's +z by.
#[derive(Debug, Clone, Copy)]
enum Rise {
    Sacrum,
    Lumbar,
    Thoracic,
    Neck,
    Head,
    /// From the thoracic joint to the clavicles: thoracic − shoulder drop.
    Clavicle,
}

impl Rise {
    fn length(self, s: &SpineSegments) -> f64 {
        match self {
            Rise::Sacrum => s.sacrum,
            Rise::Lumbar => s.lumbar,
            Rise::Thoracic => s.thoracic,
            Rise::Neck => s.neck,
            Rise::Head => s.head,
            Rise::Clavicle => s.thoracic - s.shoulder_drop,
        }
    }
}

/// Where a joint sits in its parent's frame, and its rest rotation there.
#[derive(Debug, Clone, Copy)]
enum At {
    /// The root: at the origin (its translation DoFs place it), turned into the spine frame.
    Root,
    /// Up the parent's +z (the spine) by a spine length, not turned.
    Up(Rise),
    /// A limb's base joint: sideways from its parent by half the shoulder or hip width (a hip
    /// also down to its leg's hip height), turned into the limb's rest frame.
    Beside(Limb),
    /// Where its limb's chain puts it: the chain joint's offset and rest rotation.
    InChain,
    /// A limb's tip: its chain's end effector, not turned.
    Tip(Limb),
}

/// How a joint moves.
#[derive(Debug, Clone, Copy)]
enum Moves {
    /// A spine joint's swing + twist, within its limits (the root also translates).
    Spine(SpineJoint),
    /// Joint `i` (0 base, 1 mid, 2 end) of a limb's chain: the chain joint's motions.
    InLimb(Limb, usize),
    /// Not at all (0 DoFs).
    Fixed,
    /// By the girdle of this arm (0 DoFs: a function of the arm's elevation).
    Girdle(Limb),
    /// Not at all: an End Site.
    EndSite,
}

/// One joint: its BVH name, its parent, where it sits and how it moves.
#[derive(Debug, Clone, Copy)]
struct Row(&'static str, Option<usize>, At, Moves);

/// The joints, parents first, in the order of [`joint`].
#[rustfmt::skip]
const JOINTS: [Row; joint::COUNT] = {
    use At::{Beside, InChain, Root, Tip, Up};
    use Limb::{LeftArm, LeftLeg, RightArm, RightLeg};
    use Moves::{EndSite, Fixed, Girdle, InLimb, Spine};
    use SpineJoint::{Cervical, Lumbar, Sacral, Thoracic};
    use joint as j;
    [
        //  BVH name         parent                   where it sits       how it moves
        Row("Hips",          None,                    Root,               Spine(Sacral)),
        Row("Spine",         Some(j::HIPS),           Up(Rise::Sacrum),   Spine(Lumbar)),
        Row("Chest",         Some(j::SPINE),          Up(Rise::Lumbar),   Spine(Thoracic)),
        Row("Neck",          Some(j::CHEST),          Up(Rise::Thoracic), Spine(Cervical)),
        Row("Head",          Some(j::NECK),           Up(Rise::Neck),     Fixed),
        Row("Head_End",      Some(j::HEAD),           Up(Rise::Head),     EndSite),
        Row("RightShoulder", Some(j::CHEST),          Up(Rise::Clavicle), Girdle(RightArm)),
        Row("RightArm",      Some(j::RIGHT_SHOULDER), Beside(RightArm),   InLimb(RightArm, 0)),
        Row("RightForeArm",  Some(j::RIGHT_ARM),      InChain,            InLimb(RightArm, 1)),
        Row("RightHand",     Some(j::RIGHT_FOREARM),  InChain,            InLimb(RightArm, 2)),
        Row("RightHand_End", Some(j::RIGHT_HAND),     Tip(RightArm),      EndSite),
        Row("LeftShoulder",  Some(j::CHEST),          Up(Rise::Clavicle), Girdle(LeftArm)),
        Row("LeftArm",       Some(j::LEFT_SHOULDER),  Beside(LeftArm),    InLimb(LeftArm, 0)),
        Row("LeftForeArm",   Some(j::LEFT_ARM),       InChain,            InLimb(LeftArm, 1)),
        Row("LeftHand",      Some(j::LEFT_FOREARM),   InChain,            InLimb(LeftArm, 2)),
        Row("LeftHand_End",  Some(j::LEFT_HAND),      Tip(LeftArm),       EndSite),
        Row("RightUpLeg",    Some(j::HIPS),           Beside(RightLeg),   InLimb(RightLeg, 0)),
        Row("RightLeg",      Some(j::RIGHT_UP_LEG),   InChain,            InLimb(RightLeg, 1)),
        Row("RightFoot",     Some(j::RIGHT_LEG),      InChain,            InLimb(RightLeg, 2)),
        Row("RightFoot_End", Some(j::RIGHT_FOOT),     Tip(RightLeg),      EndSite),
        Row("LeftUpLeg",     Some(j::HIPS),           Beside(LeftLeg),    InLimb(LeftLeg, 0)),
        Row("LeftLeg",       Some(j::LEFT_UP_LEG),    InChain,            InLimb(LeftLeg, 1)),
        Row("LeftFoot",      Some(j::LEFT_LEG),       InChain,            InLimb(LeftLeg, 2)),
        Row("LeftFoot_End",  Some(j::LEFT_FOOT),      Tip(LeftLeg),       EndSite),
    ]
};

/// The 21 bones: the spine's four and the head, then per arm the clavicle, upper arm,
/// forearm and hand, per leg the pelvic bone, thigh, shank and foot.
const BONES: [Bone; 21] = {
    use joint as j;
    const fn bone(name: &'static str, from: usize, to: usize) -> Bone {
        Bone { name, from, to }
    }
    [
        bone("sacrum", j::HIPS, j::SPINE),
        bone("lumbar", j::SPINE, j::CHEST),
        bone("thorax", j::CHEST, j::NECK),
        bone("neck", j::NECK, j::HEAD),
        bone("head", j::HEAD, j::HEAD_END),
        bone("right_clavicle", j::RIGHT_SHOULDER, j::RIGHT_ARM),
        bone("right_upper_arm", j::RIGHT_ARM, j::RIGHT_FOREARM),
        bone("right_forearm", j::RIGHT_FOREARM, j::RIGHT_HAND),
        bone("right_hand", j::RIGHT_HAND, j::RIGHT_HAND_END),
        bone("left_clavicle", j::LEFT_SHOULDER, j::LEFT_ARM),
        bone("left_upper_arm", j::LEFT_ARM, j::LEFT_FOREARM),
        bone("left_forearm", j::LEFT_FOREARM, j::LEFT_HAND),
        bone("left_hand", j::LEFT_HAND, j::LEFT_HAND_END),
        bone("right_pelvis", j::HIPS, j::RIGHT_UP_LEG),
        bone("right_thigh", j::RIGHT_UP_LEG, j::RIGHT_LEG),
        bone("right_shank", j::RIGHT_LEG, j::RIGHT_FOOT),
        bone("right_foot", j::RIGHT_FOOT, j::RIGHT_FOOT_END),
        bone("left_pelvis", j::HIPS, j::LEFT_UP_LEG),
        bone("left_thigh", j::LEFT_UP_LEG, j::LEFT_LEG),
        bone("left_shank", j::LEFT_LEG, j::LEFT_FOOT),
        bone("left_foot", j::LEFT_FOOT, j::LEFT_FOOT_END),
    ]
};

/// The prefix of a spine joint's DoF names.
fn spine_dof_prefix(joint: SpineJoint) -> &'static str {
    match joint {
        SpineJoint::Sacral => "root",
        SpineJoint::Lumbar => "lumbar",
        SpineJoint::Thoracic => "thoracic",
        SpineJoint::Cervical => "cervical",
    }
}

/// The joint of `row`, its DoFs starting at `first_dof`, and its DoFs' names.
fn joint_of(
    row: Row,
    p: &Proportions,
    chains: &[Chain; 4],
    first_dof: usize,
) -> (CharacterJoint, Vec<String>) {
    let Row(name, parent, at, moves) = row;
    let spine_rest = spine_frame();
    let (offset, rest) = match at {
        At::Root => (Vector3::zeros(), spine_rest),
        At::Up(rise) => (
            Vector3::new(0.0, 0.0, rise.length(&p.spine)),
            Rotation3::identity(),
        ),
        At::Beside(limb) => {
            let sideways = |width: f64| match limb.side() {
                Side::Right => -0.5 * width,
                Side::Left => 0.5 * width,
            };
            if limb.is_arm() {
                let offset = Vector3::new(sideways(p.shoulder_width), 0.0, 0.0);
                (offset, spine_rest.inverse() * arm_frame())
            } else {
                let hip_y = p.leg(limb.side()).hip_height() - p.root_height();
                // Spine-frame coordinates: world (x, y, 0) is (x, 0, y).
                let offset = Vector3::new(sideways(p.hip_width), 0.0, hip_y);
                (offset, spine_rest.inverse() * leg_frame())
            }
        }
        At::InChain => match moves {
            Moves::InLimb(limb, i) => {
                let cj = &chains[limb.index()].joints()[i];
                (cj.offset, cj.rest)
            }
            _ => unreachable!("a joint placed by a chain moves with it"),
        },
        At::Tip(limb) => (chains[limb.index()].end_effector(), Rotation3::identity()),
    };
    let translates = parent.is_none();
    let (motions, motion_names, channel_order) = match moves {
        Moves::Spine(j) => {
            let prefix = spine_dof_prefix(j);
            let names = ["swing_x", "swing_y", "twist"].map(|d| format!("{prefix}_{d}"));
            (spine_motions(j), names.to_vec(), SPINE_ORDER)
        }
        Moves::InLimb(limb, i) => {
            let cj = &chains[limb.index()].joints()[i];
            let side = limb.side();
            let names = cj.dof_names.iter().map(|n| format!("{side}_{n}")).collect();
            (cj.motions.clone(), names, LIMB_ORDER)
        }
        Moves::Fixed | Moves::EndSite | Moves::Girdle(_) => (Vec::new(), Vec::new(), LIMB_ORDER),
    };
    let girdle = match (moves, at) {
        (Moves::Girdle(limb), _) => Some(GirdleRole::Clavicle(limb)),
        (_, At::Beside(limb)) if limb.is_arm() => Some(GirdleRole::Shoulder(limb)),
        _ => None,
    };
    let mut dofs = Vec::new();
    let mut names = Vec::new();
    if translates {
        dofs.extend([Axis::X, Axis::Y, Axis::Z].map(DofKind::Translation));
        names.extend(["root_tx", "root_ty", "root_tz"].map(String::from));
    }
    names.extend(motion_names);
    for m in &motions {
        match m {
            Motion::Swing { .. } => dofs.extend([DofKind::SwingX, DofKind::SwingY]),
            Motion::Revolute { axis: Axis::Z, .. } => dofs.push(DofKind::Twist),
            Motion::Revolute { .. } => dofs.push(DofKind::Flexion),
        }
    }
    debug_assert_eq!(dofs.len(), names.len());
    let joint = CharacterJoint {
        name: name.to_string(),
        parent,
        offset,
        rest,
        translates,
        motions,
        dofs,
        first_dof,
        end_site: matches!(moves, Moves::EndSite),
        channel_order,
        girdle,
    };
    (joint, names)
}

/// The exported skeleton of the character's `joints` with their frames' world orientations at
/// rest `rest_world`: world-aligned offsets, root translations, and rotation channels in each
/// joint's order on the joints that move.
fn exported_skeleton(joints: &[CharacterJoint], rest_world: &[Rotation3<f64>]) -> Result<Skeleton> {
    let skeleton_joints = joints
        .iter()
        .map(|j| {
            let mut dofs = Vec::new();
            if j.translates {
                dofs.extend([Axis::X, Axis::Y, Axis::Z].map(Dof::Translation));
            }
            if j.rotates() {
                dofs.extend(j.channel_order.map(Dof::Rotation));
            }
            Joint {
                name: j.name.clone(),
                parent: j.parent,
                offset: j.parent.map_or(j.offset, |p| rest_world[p] * j.offset),
                dofs,
                end_site: j.end_site,
                position_reading: PositionReading::AddToOffset,
            }
        })
        .collect();
    Ok(Skeleton::new(skeleton_joints)?)
}

impl Character {
    /// The character with these proportions (validated first): the rows of its joint table
    /// walked in order.
    pub fn new(proportions: &Proportions) -> Result<Character> {
        proportions.validate()?;
        let p = proportions;
        let chains = [
            arm_chain(&p.right_arm)?,
            arm_chain(&p.left_arm)?,
            leg_chain(&p.right_leg)?,
            leg_chain(&p.left_leg)?,
        ];
        let mut joints: Vec<CharacterJoint> = Vec::with_capacity(joint::COUNT);
        let mut dof_names: Vec<String> = Vec::with_capacity(DOF_COUNT);
        let mut rest_world: Vec<Rotation3<f64>> = Vec::with_capacity(joint::COUNT);
        for row in JOINTS {
            let (j, names) = joint_of(row, p, &chains, dof_names.len());
            let parent = j.parent.map_or(Rotation3::identity(), |p| rest_world[p]);
            rest_world.push(parent * j.rest);
            joints.push(j);
            dof_names.extend(names);
        }
        debug_assert_eq!(dof_names.len(), DOF_COUNT);
        let skeleton = Arc::new(exported_skeleton(&joints, &rest_world)?);
        Ok(Character {
            proportions: *proportions,
            joints,
            bones: BONES.to_vec(),
            dof_names,
            chains,
            rest_world,
            skeleton,
        })
    }

    /// A character `height` meters tall with Drillis & Contini's proportions.
    pub fn from_height(height: f64) -> Result<Character> {
        Character::new(&Proportions::from_height(height)?)
    }
}
