//! The character as a BVH skeleton and clip: the exported skeleton (built with the character,
//! its channels in the [layout](super::layout)'s orders) and the conversion of a character
//! pose to BVH channel values.
//!
//! # BVH export
//! [`Character::to_skeleton`] writes world-aligned offsets (the rest pose is the zero pose of
//! the BVH, every rotation channel 0), and [`Character::to_clip`] writes each joint's
//! rotation as Euler angles in its channel order: with `C` the joint frame's world
//! orientation at rest and `M` the rotation of its motions, the BVH joint rotates by
//! `C · M · Cᵀ` relative to its parent. The orders keep gimbal lock away from the usual
//! poses: heading–pitch–roll (Y X Z, lock only at a 90° forward bend) for the spine, and
//! CMU's Z Y X for the limbs (lock only at a ±90° twist of the hanging limb). Frame to frame
//! the Euler solution nearest the previous frame is taken, so angles do not jump by 2π.
//! Root translations are written in the export's unit.
//!
//! The clavicle joints (`RightShoulder`, `LeftShoulder`) rotate by the girdle `G`
//! ([girdle](super::girdle)): their BVH rotation is `C · G · Cᵀ`, and the arm's base joint,
//! whose DoFs are measured in the thorax's frame, turns back by it: `(C G Cᵀ)ᵀ · C_a M Cᵀ_a`
//! (`C` the clavicle's rest orientation, `C_a` the arm's), so every joint lands where
//! [`Character::world_frames`] puts it.

use std::sync::Arc;

use kinergy_motion::rotation::{euler_angles, nearest_euler};
use kinergy_motion::{Clip, Skeleton};
use nalgebra::Rotation3;

use super::body::{Character, GirdleRole, motion_rotation};
use super::layout::Pose;
use crate::error::Result;

impl Character {
    /// The exported skeleton (shared): the character's joints with world-aligned offsets and
    /// BVH channels (see the [module docs](self)).
    pub fn skeleton(&self) -> &Arc<Skeleton> {
        &self.skeleton
    }

    /// The exported skeleton, as an owned value.
    pub fn to_skeleton(&self) -> Skeleton {
        (*self.skeleton).clone()
    }

    /// The skeleton pose (BVH channel values, meters and radians) of a character pose.
    /// `near`, the previous frame's skeleton pose, picks the Euler solutions nearest it.
    pub fn skeleton_pose(&self, pose: &Pose, near: Option<&[f64]>) -> Vec<f64> {
        let mut out = Vec::with_capacity(self.skeleton.dof_count());
        for (j, joint) in self.joints.iter().enumerate() {
            let mut k = joint.first_dof;
            if joint.translates {
                out.extend_from_slice(&pose[k..k + 3]);
                k += 3;
            }
            if !joint.rotates() {
                continue;
            }
            let mut m = Rotation3::identity();
            for motion in &joint.motions {
                m *= motion_rotation(motion, &pose[k..]);
                k += motion.dof_count();
            }
            let c = self.rest_world[j];
            let bvh = match joint.girdle {
                Some(GirdleRole::Clavicle(limb)) => {
                    c * self.girdle_rotation(limb, &pose[limb.dofs()]) * c.inverse()
                }
                Some(GirdleRole::Shoulder(limb)) => {
                    let cp = joint.parent.map_or(c, |p| self.rest_world[p]);
                    let g = cp * self.girdle_rotation(limb, &pose[limb.dofs()]) * cp.inverse();
                    g.inverse() * c * m * c.inverse()
                }
                None => c * m * c.inverse(),
            };
            // Three distinct axes always decompose.
            let angles = euler_angles(joint.channel_order, &bvh).unwrap_or_default();
            let start = out.len();
            let angles = match near.and_then(|n| n.get(start..start + 3)) {
                Some(n) => nearest_euler(angles, [n[0], n[1], n[2]]),
                None => angles,
            };
            out.extend_from_slice(&angles);
        }
        out
    }

    /// A clip of the exported skeleton playing `poses` at `frame_time` seconds per frame.
    /// Write it with [`kinergy_motion::write_clip`].
    pub fn to_clip(&self, poses: &[Pose], frame_time: f64) -> Result<Clip> {
        let n = self.skeleton.dof_count();
        let mut values: Vec<f64> = Vec::with_capacity(poses.len() * n);
        let mut previous: Option<Vec<f64>> = None;
        for pose in poses {
            let frame = self.skeleton_pose(pose, previous.as_deref());
            values.extend_from_slice(&frame);
            previous = Some(frame);
        }
        Ok(Clip::new(self.skeleton.clone(), frame_time, values)?)
    }
}
