//! The character's body: its joints, built by walking one table of joint rows
//! ([`Character::new`]), its bones, its exported skeleton, forward kinematics, and a pose
//! checked against and clamped into the joints' limits.
//!
//! Each row names a joint, its parent, where it sits in the parent's frame and how it moves
//! (the [character docs](super#the-skeleton-and-its-count) list the skeleton); walking the
//! rows in order assigns the DoF indices of a [`Pose`]. The spine joints stack up the spine
//! frame's +z by the [`SpineSegments`]; each limb hangs from its clavicle (arms) or from the
//! root (legs), its base joint turned into the limb's rest frame and the rest placed by the
//! limb's [`Chain`].

use std::ops::Range;
use std::sync::Arc;

use kinergy_motion::rotation::{Axis, axis_rotation, swing_rotation};
use kinergy_motion::{Chain, Dof, Joint, Motion, PositionReading, Side, Skeleton};
use nalgebra::{IsometryMatrix3, Point3, Rotation3, Vector3};

use super::girdle::{ArmGirdle, Girdle, GirdleAngles};
use super::layout::{
    DOF_COUNT, DofKind, LIMB_ORDER, Limb, Pose, SPINE_ORDER, SpineJoint, arm_frame, dof, joint,
    leg_frame, spine_frame,
};
use super::limits::{arm_chain, leg_chain, spine_motions};
use super::proportions::{Proportions, SpineSegments};
use crate::error::Result;

/// One joint of the [`Character`].
#[derive(Debug, Clone, PartialEq)]
pub struct CharacterJoint {
    /// The BVH name (see the [character docs](super#the-skeleton-and-its-count)).
    pub name: String,
    /// The parent joint, `None` for the root.
    pub parent: Option<usize>,
    /// Position in the parent's joint frame (world for the root), meters.
    pub offset: Vector3<f64>,
    /// Fixed rotation in the parent's frame, applied before the motions.
    pub rest: Rotation3<f64>,
    /// True for the root: three world translations come first among its DoFs.
    pub translates: bool,
    /// The rotational motions, in order (with their limits).
    pub motions: Vec<Motion>,
    /// Every DoF, translations first.
    pub dofs: Vec<DofKind>,
    /// The index of its first DoF in a [`Pose`].
    pub first_dof: usize,
    /// True for an End Site (a 0-DoF tip).
    pub end_site: bool,
    /// The BVH rotation channel order (used when it has motions or a girdle role).
    pub channel_order: [Axis; 3],
    /// Its part in the shoulder girdle, if any ([`GirdleRole`]).
    pub girdle: Option<GirdleRole>,
}

/// A joint's part in the shoulder girdle ([girdle](super::girdle)): the clavicle turns with
/// the arm's elevation, and the arm's base joint turns back by as much, so the arm's DoFs
/// stay humerothoracic (measured in a frame fixed to the thorax) while its shoulder rides the
/// clavicle's end.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum GirdleRole {
    /// The sternoclavicular joint of this arm: rotated by the girdle, 0 DoFs of its own.
    Clavicle(Limb),
    /// This arm's base joint (the shoulder): the clavicle's rotation undone before its rest.
    Shoulder(Limb),
}

impl CharacterJoint {
    /// True when it rotates: it has motions or is a clavicle (the export gives it channels).
    pub fn rotates(&self) -> bool {
        !self.motions.is_empty() || matches!(self.girdle, Some(GirdleRole::Clavicle(_)))
    }

    /// Its DoFs' indices in a [`Pose`].
    pub fn dof_range(&self) -> Range<usize> {
        self.first_dof..self.first_dof + self.dofs.len()
    }
}

/// A rigid segment between two joints.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Bone {
    /// E.g. `thorax`, `right_clavicle`, `left_shank`.
    pub name: &'static str,
    /// The joint it hangs from.
    pub from: usize,
    /// The joint at its other end.
    pub to: usize,
}

/// The 21-bone, 43-DoF character (see the [character docs](super)). Immutable; poses are
/// [`Pose`]s.
#[derive(Debug, Clone)]
pub struct Character {
    pub(super) proportions: Proportions,
    pub(super) joints: Vec<CharacterJoint>,
    pub(super) bones: Vec<Bone>,
    pub(super) dof_names: Vec<String>,
    pub(super) chains: [Chain; 4],
    /// Per joint: the world orientation of its frame at rest.
    pub(super) rest_world: Vec<Rotation3<f64>>,
    pub(super) skeleton: Arc<Skeleton>,
}

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

    /// Its proportions.
    pub fn proportions(&self) -> &Proportions {
        &self.proportions
    }

    /// The joints, parents first (End Sites included); indices as in [`joint`].
    pub fn joints(&self) -> &[CharacterJoint] {
        &self.joints
    }

    /// The joint named `name`.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The 21 bones.
    pub fn bones(&self) -> &[Bone] {
        &self.bones
    }

    /// 21.
    pub fn bone_count(&self) -> usize {
        self.bones.len()
    }

    /// 43.
    pub fn dof_count(&self) -> usize {
        self.dof_names.len()
    }

    /// Every DoF's name, in [`Pose`] order (e.g. `root_ty`, `right_elbow_flexion`).
    pub fn dof_names(&self) -> &[String] {
        &self.dof_names
    }

    /// The index of the DoF named `name`.
    pub fn dof_index(&self, name: &str) -> Option<usize> {
        self.dof_names.iter().position(|n| n == name)
    }

    /// The limb as a chain for IK, in the limb's rest frame
    /// ([`Character::limb_base_frame`]); its configuration is `&pose[limb_dofs(limb)]`.
    /// Arms are [`Chain::arm`]; legs have the hip, knee and ankle limits of the
    /// [limits](super::limits) and the toe tip `(0, toe, ankle_height)` in the ankle
    /// frame as their end effector.
    pub fn limb_chain(&self, limb: Limb) -> &Chain {
        &self.chains[limb.index()]
    }

    /// The limb's DoFs in a [`Pose`].
    pub fn limb_dofs(&self, limb: Limb) -> Range<usize> {
        limb.dofs()
    }

    /// The limb's joints: base, mid, end and tip.
    pub fn limb_joints(&self, limb: Limb) -> [usize; 4] {
        limb.joints()
    }

    /// The world frame of the limb's chain base at `pose`: its base joint's frame before the
    /// joint's own motions (parent frame · offset · rest rotation).
    pub fn limb_base_frame(&self, limb: Limb, pose: &Pose) -> IsometryMatrix3<f64> {
        let j = &self.joints[limb.joints()[0]];
        let mut frame = j
            .parent
            .map_or(IsometryMatrix3::identity(), |p| self.joint_frame(p, pose));
        frame.translation.vector += frame.rotation * j.offset;
        if limb.is_arm() {
            frame.rotation *= self.girdle_rotation(limb, &pose[limb.dofs()]).inverse();
        }
        frame.rotation *= j.rest;
        frame
    }

    /// [`Character::limb_base_frame`] from world frames already computed
    /// ([`Character::world_frames`]); only the frames above the limb matter.
    pub fn limb_base_frame_in(
        &self,
        limb: Limb,
        frames: &[IsometryMatrix3<f64>],
    ) -> IsometryMatrix3<f64> {
        let base = limb.joints()[0];
        let j = &self.joints[base];
        let mut frame = j.parent.map_or(IsometryMatrix3::identity(), |p| frames[p]);
        frame.translation.vector += frame.rotation * j.offset;
        if limb.is_arm() {
            // The clavicle's parent's orientation: the girdle's rotation left out.
            let clavicle = &self.joints[j.parent.unwrap_or(joint::CHEST)];
            let above = clavicle
                .parent
                .map_or(IsometryMatrix3::identity(), |p| frames[p]);
            frame.rotation = above.rotation * clavicle.rest;
        }
        frame.rotation *= j.rest;
        frame
    }

    /// Standing at the origin, feet flat on y = 0, facing +Z, arms hanging: every DoF 0
    /// except `root_ty` = [`Proportions::root_height`].
    pub fn rest_pose(&self) -> Pose {
        let mut pose = [0.0; DOF_COUNT];
        pose[dof::ROOT_Y] = self.proportions.root_height();
        pose
    }

    /// Forward kinematics: every joint's world frame (after its motions).
    pub fn world_frames(&self, pose: &Pose) -> Vec<IsometryMatrix3<f64>> {
        let mut out: Vec<IsometryMatrix3<f64>> = Vec::with_capacity(self.joints.len());
        for (i, j) in self.joints.iter().enumerate() {
            let parent = j.parent.map_or(IsometryMatrix3::identity(), |p| out[p]);
            out.push(self.joint_frame_from(i, &parent, pose));
        }
        out
    }

    /// The world frame of `joint` (after its motions) at `pose`: forward kinematics of its
    /// ancestors only, the same values [`Character::world_frames`] gives it.
    pub fn joint_frame(&self, joint: usize, pose: &Pose) -> IsometryMatrix3<f64> {
        // Joints come after their parents: walk up, then down.
        let mut path = [0usize; 32];
        let mut depth = 0;
        let mut at = Some(joint);
        while let Some(j) = at {
            if depth == path.len() {
                // Deeper than any body: the full pass.
                return self.world_frames(pose)[joint];
            }
            path[depth] = j;
            depth += 1;
            at = self.joints[j].parent;
        }
        path[..depth]
            .iter()
            .rev()
            .fold(IsometryMatrix3::identity(), |parent, &j| {
                self.joint_frame_from(j, &parent, pose)
            })
    }

    /// Joint `i`'s world frame given its parent's.
    fn joint_frame_from(
        &self,
        i: usize,
        parent: &IsometryMatrix3<f64>,
        pose: &Pose,
    ) -> IsometryMatrix3<f64> {
        let j = &self.joints[i];
        let mut frame = *parent;
        let mut k = j.first_dof;
        let mut offset = j.offset;
        if j.translates {
            offset += Vector3::new(pose[k], pose[k + 1], pose[k + 2]);
            k += 3;
        }
        frame.translation.vector += frame.rotation * offset;
        match j.girdle {
            Some(GirdleRole::Clavicle(limb)) => {
                frame.rotation *= j.rest * self.girdle_rotation(limb, &pose[limb.dofs()]);
            }
            Some(GirdleRole::Shoulder(limb)) => {
                frame.rotation *= self.girdle_rotation(limb, &pose[limb.dofs()]).inverse() * j.rest;
            }
            None => frame.rotation *= j.rest,
        }
        for m in &j.motions {
            frame.rotation *= motion_rotation(m, &pose[k..]);
            k += m.dof_count();
        }
        frame
    }

    /// Forward kinematics: every joint's world position, End Sites included, in
    /// [`Character::joints`] order.
    pub fn world_positions(&self, pose: &Pose) -> Vec<Point3<f64>> {
        self.world_frames(pose)
            .iter()
            .map(|f| Point3::from(f.translation.vector))
            .collect()
    }
}

// The shoulder girdle: the clavicle's rotation as a function of the arm's DoFs.
impl Character {
    /// The girdle of `arm` (an arm) whose DoFs are `q` (at least its shoulder swing): the
    /// rhythm's angles at the arm's humerothoracic elevation `|(sx, sy)|`.
    pub fn girdle_angles(&self, arm: Limb, q: &[f64]) -> GirdleAngles {
        if !arm.is_arm() {
            return Girdle::angles(0.0);
        }
        Girdle::angles(ArmGirdle::elevation(q))
    }

    /// `arm`'s girdle: what moves its shoulder (identity for a leg).
    pub fn arm_girdle(&self, arm: Limb) -> ArmGirdle {
        let base = &self.joints[arm.joints()[0]];
        if !arm.is_arm() {
            return ArmGirdle::new(arm.side(), Vector3::zeros(), base.rest);
        }
        let clavicle = &self.joints[base.parent.unwrap_or(joint::CHEST)];
        ArmGirdle::new(
            arm.side(),
            clavicle.rest * base.offset,
            clavicle.rest * base.rest,
        )
    }

    /// The rotation of `arm`'s clavicle joint in its parent's (the thorax's) frame for the
    /// arm's DoFs `q` ([`ArmGirdle::rotation`]); identity for a leg.
    pub fn girdle_rotation(&self, arm: Limb, q: &[f64]) -> Rotation3<f64> {
        if !arm.is_arm() {
            return Rotation3::identity();
        }
        self.arm_girdle(arm).rotation(q)
    }

    /// The girdle's turn of `arm`'s base frame ([`GirdleTurn`]): a value that needs no
    /// character to evaluate.
    pub fn girdle_turn(&self, arm: Limb) -> GirdleTurn {
        GirdleTurn {
            girdle: arm.is_arm().then(|| self.arm_girdle(arm)),
            rest: self.joints[arm.joints()[0]].rest,
        }
    }

    /// Where `arm`'s base frame moves when the arm's DoFs go from `from` to `to` and nothing
    /// else changes: `base` (the frame for `from`) shifted by the clavicle's end, turned the
    /// same (the base frame does not turn with the girdle, [`GirdleRole`]).
    pub fn arm_base_moved(
        &self,
        arm: Limb,
        base: &IsometryMatrix3<f64>,
        from: &[f64],
        to: &[f64],
    ) -> IsometryMatrix3<f64> {
        if !arm.is_arm() {
            return *base;
        }
        let g = self.arm_girdle(arm);
        let mut moved = *base;
        moved.translation.vector += base.rotation * (g.shift(to) - g.shift(from));
        moved
    }
}

// The joint limits' values are `limits.rs`'s; the check and the clamp walk the joints here.
impl Character {
    /// The radii `(rx, ry)` of the swing ellipse whose first DoF is `k` (the swing `(k, k + 1)`
    /// lies within it when `(q_k / rx)² + (q_(k+1) / ry)² ≤ 1`); `None` when DoF `k` does not
    /// start a swing.
    pub fn swing_radii(&self, k: usize) -> Option<(f64, f64)> {
        for j in &self.joints {
            let mut at = j.first_dof + if j.translates { 3 } else { 0 };
            for m in &j.motions {
                if let Motion::Swing { rx, ry } = *m
                    && at == k
                {
                    return Some((rx, ry));
                }
                at += m.dof_count();
            }
        }
        None
    }

    /// The limits of `limb`'s seven DoFs at `pose` (in the limb's DoF order, as
    /// [`Character::revolute_range`] and [`Character::swing_radii`] give them one DoF at a
    /// time), walking the limb's own joints once: what a controller bounding every DoF of an
    /// arm each frame needs.
    pub fn limb_limits(&self, limb: Limb, pose: &Pose) -> [DofLimit; 7] {
        let mut out = [DofLimit::Free; 7];
        let start = self.limb_dofs(limb).start;
        for &ji in &limb.joints()[..3] {
            let j = &self.joints[ji];
            let mut at = j.first_dof + if j.translates { 3 } else { 0 };
            for m in &j.motions {
                let Some(i) = at.checked_sub(start).filter(|&i| i < 7) else {
                    at += m.dof_count();
                    continue;
                };
                match *m {
                    Motion::Revolute { min, max, .. } => {
                        let (min, max) = revolute_range(j, min, max, pose, at);
                        out[i] = DofLimit::Revolute { min, max };
                    }
                    Motion::Swing { rx, ry } => {
                        out[i] = DofLimit::Swing { rx, ry };
                        if i + 1 < 7 {
                            out[i + 1] = DofLimit::SwingSecond;
                        }
                    }
                }
                at += m.dof_count();
            }
        }
        out
    }

    /// The range `[min, max]` of DoF `k` of `pose` when it is a revolute one (at `pose`: the
    /// shoulder's twist range widens with the arm's elevation); `None` for a swing's or a
    /// root's DoF, or `k` out of range.
    pub fn revolute_range(&self, k: usize, pose: &Pose) -> Option<(f64, f64)> {
        for j in &self.joints {
            let mut at = j.first_dof + if j.translates { 3 } else { 0 };
            for m in &j.motions {
                if let Motion::Revolute { min, max, .. } = *m
                    && at == k
                {
                    return Some(revolute_range(j, min, max, pose, at));
                }
                at += m.dof_count();
            }
        }
        None
    }

    /// `Ok` when every value is finite and every rotation DoF within its limits (swings
    /// inside their ellipse, 1e-12 of slack); otherwise the first violation, naming the DoF.
    pub fn joint_limits_ok(&self, pose: &Pose) -> std::result::Result<(), String> {
        if let Some(i) = pose.iter().position(|v| !v.is_finite()) {
            return Err(format!("DoF `{}` is {}", self.dof_names[i], pose[i]));
        }
        for j in &self.joints {
            let mut k = j.first_dof + if j.translates { 3 } else { 0 };
            for m in &j.motions {
                match *m {
                    Motion::Revolute { min, max, .. } => {
                        let v = pose[k];
                        let (min, max) = revolute_range(j, min, max, pose, k);
                        if v < min - 1e-12 || v > max + 1e-12 {
                            return Err(format!(
                                "DoF `{}` = {:.3}° is outside [{:.3}°, {:.3}°]",
                                self.dof_names[k],
                                v.to_degrees(),
                                min.to_degrees(),
                                max.to_degrees()
                            ));
                        }
                    }
                    Motion::Swing { rx, ry } => {
                        let (sx, sy) = (pose[k], pose[k + 1]);
                        let e = (sx / rx).powi(2) + (sy / ry).powi(2);
                        if e > 1.0 + 1e-12 {
                            return Err(format!(
                                "DoFs `{}`, `{}` = ({:.3}°, {:.3}°) lie outside their swing ellipse ({:.3}°, {:.3}°)",
                                self.dof_names[k],
                                self.dof_names[k + 1],
                                sx.to_degrees(),
                                sy.to_degrees(),
                                rx.to_degrees(),
                                ry.to_degrees()
                            ));
                        }
                    }
                }
                k += m.dof_count();
            }
        }
        Ok(())
    }

    /// Brings `pose` within the limits: revolute DoFs clamped, swings outside their ellipse
    /// scaled toward zero onto it (as [`Chain::clamp`]); non-finite values become 0.
    pub fn clamp_pose(&self, pose: &mut Pose) {
        for v in pose.iter_mut() {
            if !v.is_finite() {
                *v = 0.0;
            }
        }
        for j in &self.joints {
            let mut k = j.first_dof + if j.translates { 3 } else { 0 };
            for m in &j.motions {
                match *m {
                    Motion::Revolute { min, max, .. } => {
                        let (min, max) = revolute_range(j, min, max, pose, k);
                        pose[k] = wrap_or_clamp(pose[k], min, max);
                    }
                    Motion::Swing { rx, ry } => {
                        let e = (pose[k] / rx).powi(2) + (pose[k + 1] / ry).powi(2);
                        if e > 1.0 {
                            let s = 1.0 / e.sqrt();
                            pose[k] *= s;
                            pose[k + 1] *= s;
                        }
                    }
                }
                k += m.dof_count();
            }
        }
    }
}

/// A DoF's limit ([`Character::limb_limits`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DofLimit {
    /// No limit (or not a rotation DoF).
    Free,
    /// A revolute DoF's range at the pose.
    Revolute {
        /// The least value, radians.
        min: f64,
        /// The largest value, radians.
        max: f64,
    },
    /// The first DoF of a swing, within the ellipse `(q / rx)² + (q_next / ry)² ≤ 1`.
    Swing {
        /// The ellipse's radius along this DoF, radians.
        rx: f64,
        /// Its radius along the next DoF, radians.
        ry: f64,
    },
    /// The second DoF of a swing (its limit is the first's).
    SwingSecond,
}

/// A revolute DoF's value `v` within `[min, max]`: the same rotation a turn away (`v ∓ 2π`)
/// where that lies within the range, else clamped. Near the arm straight up the shoulder's
/// twist range reaches ±180° and a twist carried on continuously passes beyond it: clamped,
/// 3.79 rad became 3.11 — a different arm, the hand thrown 12 cm in a frame — where −2.50 is
/// the same arm within the range.
pub fn wrap_or_clamp(v: f64, min: f64, max: f64) -> f64 {
    use std::f64::consts::TAU;
    if v > max && v - TAU >= min {
        v - TAU
    } else if v < min && v + TAU <= max {
        v + TAU
    } else {
        v.clamp(min, max)
    }
}

/// `a − b` wrapped into (−π, π]: a revolute DoF's change, the same for values a turn apart
/// (what [`wrap_or_clamp`] may put between two frames). Not
/// `kinergy_motion::rotation::unwrap_near(a, b) − b`, which is exact where this rounds a
/// negative change by 1e-16: the committed synthetic set was made with this one, and three of
/// its clips part by up to 4.7° from such a rounding.
pub fn angle_difference(a: f64, b: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    let d = (a - b).rem_euclid(TAU);
    if d > PI { d - TAU } else { d }
}

/// Where the shoulder's twist range starts to widen: humerothoracic elevations above 90°
/// (from 120° a synergy that turns the twist hard still met the clamp at 130°–150° and circled
/// the arm overhead: Bandai *active* fitted on takes 1–6, r 0.50 with 120°, 0.81 with 90°).
pub const OVERHEAD_TWIST_FROM: f64 = 90.0 * std::f64::consts::PI / 180.0;

/// The range of the revolute DoF `k` of joint `j` (`[min, max]` in its table) at `pose`: the
/// table's, except the shoulder's twist (the revolute after an arm's swing), whose range widens
/// linearly from the table's at [`OVERHEAD_TWIST_FROM`] of elevation to ±180° at 180°. The
/// twist is that of the swing–twist split from the hanging arm, singular with the arm
/// straight up: there a swing of π about u followed by a twist τ is the swing of π about u
/// turned by −τ/2, with no twist (a π turn about a horizontal axis flips z, so
/// `S(πu)·Rz(τ) = Rz(−τ/2)·S(πu)·Rz(τ/2) = S(π·Rz(−τ/2)u)`); near it, a small turn of the arm
/// moves the twist coordinate by a lot. A fixed ±90° there limited nothing anatomical, and
/// clamping the coordinate turned an overhead arm by up to 1.6 rad on single frames (Bandai
/// *active* raises under the person's synergy).
fn revolute_range(j: &CharacterJoint, min: f64, max: f64, pose: &Pose, k: usize) -> (f64, f64) {
    use std::f64::consts::PI;
    if !matches!(j.girdle, Some(GirdleRole::Shoulder(_))) || k < 2 {
        return (min, max);
    }
    let elevation = pose[k - 2].hypot(pose[k - 1]);
    let w = ((elevation - OVERHEAD_TWIST_FROM) / (PI - OVERHEAD_TWIST_FROM)).clamp(0.0, 1.0);
    (min + w * (-PI - min), max + w * (PI - max))
}

/// The rotation of one motion at DoF values `q` (its first one or two).
pub(super) fn motion_rotation(m: &Motion, q: &[f64]) -> Rotation3<f64> {
    match *m {
        Motion::Revolute { axis, .. } => axis_rotation(axis, q[0]),
        Motion::Swing { .. } => swing_rotation(q[0], q[1]),
    }
}

/// The girdle's turn of an arm's base frame ([`Character::girdle_turn`]): for the arm's DoFs
/// `q`, the rotation from [`Character::limb_base_frame`] (which does not turn with the girdle)
/// to the frame the rotated clavicle carries — the frame a fit of the exported motion reads
/// the arm in ([`kinergy_solver::CaptureArm`]'s base rides the clavicle). Identity for a leg
/// and for an arm below the rhythm's onset.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GirdleTurn {
    /// The arm's girdle (`None`: a leg).
    girdle: Option<ArmGirdle>,
    /// The limb's first joint's rest rotation: the turn is taken in its frame.
    rest: Rotation3<f64>,
}

impl GirdleTurn {
    /// The turn for the arm's DoFs `q` (at least its shoulder swing), in the base's frame.
    pub fn in_base(&self, q: &[f64]) -> Rotation3<f64> {
        match &self.girdle {
            Some(g) => self.rest.inverse() * g.rotation(q) * self.rest,
            None => Rotation3::identity(),
        }
    }
}
