//! A space whose body moves ([`ArmSpace::with_body`]): the body posed from a configuration's
//! body DoFs, the arm's frames and the tracked points read from the whole body's forward
//! kinematics, and the whole-body collision test.
//!
//! # What is tested
//! - the feet: where they stand — a posture whose legs cannot keep them there is refused
//!   (`the legs cannot keep the feet planted`);
//! - every enabled pair of body parts ([`BodyGeometry::is_disabled`]): a pair with an arm
//!   part with the clearance (as the arm alone is), the others without (body parts near each
//!   other at rest, such as a hanging hand by the thigh, are not a contact);
//! - every part but the feet against every scene object not ignored, grown by the
//!   clearance (the feet stand on the floor: they touch it, and they do not move);
//! - a held object against every body part but the holding arm's, and the scene.
//!
//! # Tracked points
//! Beyond the arm's (elbow, wrist, fingertip, a held box's corners): the head's top, both
//! shoulders, the other hand's fingertip and both knees — the joints farthest from where the
//! spine and the legs turn, so that an interpolation's largest displacement, which the edge
//! checks are spaced by, is the whole body's.

use kinergy_reach::character::{ArmGirdle, Character, Limb, Pose, dof, joint};
use nalgebra::{IsometryMatrix3, Point3};
use parry3d::math::Pose as PPose;
use parry3d::shape::Capsule as PCapsule;

use super::{ArmSpace, arm_of, body_of};
use crate::body::{BodyGeometry, BodyPart, Capsule};
use crate::colliders::{hit, overlaps, pvec};
use crate::error::Result;
use crate::posture::{ARM_DOFS, BodyDofs, BodyMotion, PLANTED};

/// The tracked body joints ([module docs](self#tracked-points)).
pub(super) const TRACKED: usize = 6;

/// The body's motion and what the whole-body test needs of the geometry.
#[derive(Debug, Clone)]
pub(crate) struct BodyMode {
    pub(super) motion: BodyMotion,
    /// Every body part.
    parts: Vec<BodyPart>,
    /// The acting arm's parts (indices into `parts`).
    arm: Vec<usize>,
    /// The enabled pairs, each with whether the clearance applies (a pair with an arm part),
    /// the arm's pairs first, the arm part named first.
    pairs: Vec<(usize, usize, bool)>,
    /// The parts tested against the scene: every one but the feet, the arm's first.
    scene_parts: Vec<usize>,
    /// The tracked joints.
    tracked: [usize; TRACKED],
}

/// A configuration posed: the full-body pose and its joints' world frames.
pub(super) struct Posed {
    pose: Pose,
    frames: Vec<IsometryMatrix3<f64>>,
}

impl Posed {
    /// The acting arm's shoulder, elbow and wrist frames.
    pub(super) fn arm_frames(&self, limb: Limb) -> [IsometryMatrix3<f64>; 3] {
        let [s, e, w, _] = limb.joints();
        [self.frames[s], self.frames[e], self.frames[w]]
    }
}

impl BodyMode {
    pub(super) fn new(geometry: &BodyGeometry, limb: Limb, motion: BodyMotion) -> Result<BodyMode> {
        let parts = geometry.parts().to_vec();
        let arm = geometry.limb_parts(limb);
        let n = parts.len();
        let mut pairs = Vec::new();
        for &a in &arm {
            for j in 0..n {
                let counted = arm.contains(&j) && j <= a;
                if j != a && !counted && !geometry.is_disabled(a, j) {
                    pairs.push((a, j, true));
                }
            }
        }
        for i in (0..n).filter(|i| !arm.contains(i)) {
            for j in (i + 1..n).filter(|j| !arm.contains(j)) {
                if !geometry.is_disabled(i, j) {
                    pairs.push((i, j, false));
                }
            }
        }
        let feet = [joint::RIGHT_FOOT, joint::LEFT_FOOT];
        let scene_parts = arm
            .iter()
            .copied()
            .chain((0..n).filter(|i| !arm.contains(i) && !feet.contains(&parts[*i].joint)))
            .collect();
        let other = match limb.side() {
            kinergy_motion::Side::Right => Limb::LeftArm,
            kinergy_motion::Side::Left => Limb::RightArm,
        };
        let tracked = [
            joint::HEAD_END,
            joint::RIGHT_ARM,
            joint::LEFT_ARM,
            other.joints()[3],
            joint::RIGHT_LEG,
            joint::LEFT_LEG,
        ];
        Ok(BodyMode {
            motion,
            parts,
            arm,
            pairs,
            scene_parts,
            tracked,
        })
    }

    fn character(&self) -> &Character {
        self.motion.character()
    }

    /// The body at `b`, the arm as in the reference posture.
    pub(super) fn posed_body(&self, b: &BodyDofs) -> Posed {
        let pose = self.motion.pose(b);
        let frames = self.character().world_frames(&pose);
        Posed { pose, frames }
    }

    /// The configuration `q` posed.
    pub(super) fn posed(&self, limb: Limb, q: &super::ArmConfig) -> Posed {
        let mut pose = self.motion.pose(&body_of(q));
        pose[limb.dofs()].copy_from_slice(&arm_of(q));
        let frames = self.character().world_frames(&pose);
        Posed { pose, frames }
    }

    /// `posed` with the arm at `q`.
    pub(super) fn with_arm(&self, posed: &Posed, limb: Limb, q: &[f64; ARM_DOFS]) -> Posed {
        let mut pose = posed.pose;
        pose[limb.dofs()].copy_from_slice(q);
        let frames = self.character().world_frames(&pose);
        Posed { pose, frames }
    }

    /// True when the legs keep the feet where they stand.
    pub(super) fn planted(&self, posed: &Posed) -> bool {
        self.motion.drift(&posed.frames) <= PLANTED
    }

    /// The acting arm's base frame with the body at `b` and the girdle at rest.
    pub(super) fn base_frame(
        &self,
        girdle: &ArmGirdle,
        limb: Limb,
        b: &BodyDofs,
    ) -> IsometryMatrix3<f64> {
        let posed = self.posed_body(b);
        let mut base = self.character().limb_base_frame_in(limb, &posed.frames);
        base.translation.vector -= base.rotation * girdle.shift(&posed.pose[limb.dofs()]);
        base
    }

    /// The acting arm's shoulder, elbow and wrist frames at `q`.
    pub(super) fn arm_frames(&self, limb: Limb, q: &super::ArmConfig) -> [IsometryMatrix3<f64>; 3] {
        self.posed(limb, q).arm_frames(limb)
    }

    /// The tracked body joints' positions.
    pub(super) fn tracked(&self, posed: &Posed) -> [Point3<f64>; TRACKED] {
        self.tracked
            .map(|j| Point3::from(posed.frames[j].translation.vector))
    }

    /// Every part's capsule in world for `posed`.
    pub(super) fn world(&self, posed: &Posed) -> Vec<Capsule> {
        self.parts
            .iter()
            .map(|p| p.capsule.transformed(&posed.frames[p.joint]))
            .collect()
    }

    /// Sets `pose`'s root, spine and legs to the body at `b`.
    pub(super) fn set_body(&self, pose: &mut Pose, b: &BodyDofs) {
        let body = self.motion.pose(b);
        for range in [
            dof::ROOT_TRANSLATION,
            dof::ROOT_ROTATION,
            dof::LUMBAR,
            dof::THORACIC,
            dof::RIGHT_LEG,
            dof::LEFT_LEG,
        ] {
            pose[range.clone()].copy_from_slice(&body[range]);
        }
    }
}

impl ArmSpace {
    /// The first contact of the whole body posed as `posed` ([module docs](self)), or `None`.
    pub(super) fn whole_body_contact(
        &self,
        mode: &BodyMode,
        posed: &Posed,
        clearance: f64,
    ) -> Option<String> {
        let world = mode.world(posed);
        self.body_contact(mode, posed, &world, clearance)
            .or_else(|| self.arm_contact(mode, posed, &world, clearance))
    }

    /// The first contact of the body but the acting arm — which its DoFs do not move: the
    /// feet, the other parts' pairs, the other parts against the scene — or `None`.
    pub(super) fn body_contact(
        &self,
        mode: &BodyMode,
        posed: &Posed,
        world: &[Capsule],
        clearance: f64,
    ) -> Option<String> {
        if !mode.planted(posed) {
            return Some("the legs cannot keep the feet planted".into());
        }
        let name = |i: usize| mode.parts[i].name.as_str();
        for &(i, j, with_arm) in &mode.pairs {
            if !with_arm && world[i].gap(&world[j]) < 0.0 {
                return Some(format!("{} × {}", name(i), name(j)));
            }
        }
        let others = mode.scene_parts.iter().filter(|i| !mode.arm.contains(i));
        self.parts_scene_contact(mode, world, others, clearance)
    }

    /// The first contact of the acting arm (with the body, itself, the scene) and of the held
    /// object, or `None`.
    pub(super) fn arm_contact(
        &self,
        mode: &BodyMode,
        posed: &Posed,
        world: &[Capsule],
        clearance: f64,
    ) -> Option<String> {
        let name = |i: usize| mode.parts[i].name.as_str();
        for &(i, j, with_arm) in &mode.pairs {
            if with_arm && world[i].gap(&world[j]) < clearance {
                return Some(format!("{} × {}", name(i), name(j)));
            }
        }
        if let Some(hit) = self.parts_scene_contact(mode, world, mode.arm.iter(), clearance) {
            return Some(hit);
        }
        if let Some(h) = &self.held {
            let wrist = posed.arm_frames(self.limb)[2];
            let others = (0..mode.parts.len())
                .filter(|i| !mode.arm.contains(i))
                .map(|i| (name(i), &world[i]));
            return self.held_contact(h, &wrist, clearance, others);
        }
        None
    }

    /// The first of `parts` (grown by `clearance`) to touch a scene object not ignored.
    fn parts_scene_contact<'a>(
        &self,
        mode: &BodyMode,
        world: &[Capsule],
        parts: impl Iterator<Item = &'a usize>,
        clearance: f64,
    ) -> Option<String> {
        for &i in parts {
            let mut w = world[i];
            w.radius += clearance;
            let bounds = w.bounds(0.0);
            let cap = PCapsule::new(pvec(&w.a), pvec(&w.b), w.radius as f32);
            for c in &self.colliders {
                if c.ignored || !overlaps(&bounds, &c.min, &c.max) {
                    continue;
                }
                if hit(&PPose::IDENTITY, &cap, &c.pose, c.shape.as_ref()) {
                    return Some(format!("{} × {}", mode.parts[i].name, c.name));
                }
            }
        }
        None
    }
}
