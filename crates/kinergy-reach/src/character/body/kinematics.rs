//! Forward kinematics of the [`Character`]: every joint's world frame, the limbs' base
//! frames, and the shoulder girdle's rotation of the clavicle and turn of the arm's base.

use kinergy_motion::Motion;
use kinergy_motion::rotation::{axis_rotation, swing_rotation};
use nalgebra::{IsometryMatrix3, Point3, Rotation3, Vector3};

use super::{Character, GirdleRole};
use crate::character::girdle::{ArmGirdle, Girdle, GirdleAngles};
use crate::character::layout::{Limb, Pose, joint};

impl Character {
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

    /// Forward kinematics: every joint's world frame (after its motions).
    pub fn world_frames(&self, pose: &Pose) -> Vec<IsometryMatrix3<f64>> {
        let mut out: Vec<IsometryMatrix3<f64>> = Vec::with_capacity(self.joints.len());
        for (i, j) in self.joints.iter().enumerate() {
            let parent = j.parent.map_or(IsometryMatrix3::identity(), |p| out[p]);
            out.push(self.joint_frame_from(i, &parent, pose));
        }
        out
    }

    /// [`Character::world_frames`] of the trunk, head and clavicles only: what the limbs' base
    /// frames need ([`Character::limb_base_frame_in`]) before the limbs are solved. The four
    /// limbs' own joints ([`Limb::joints`]) are left NaN, so a read of one shows.
    pub fn frames_above_limbs(&self, pose: &Pose) -> Vec<IsometryMatrix3<f64>> {
        let nan = IsometryMatrix3::from_parts(
            Vector3::repeat(f64::NAN).into(),
            Rotation3::from_matrix_unchecked(nalgebra::Matrix3::repeat(f64::NAN)),
        );
        let in_limb = |i: usize| Limb::ALL.iter().any(|l| l.joints().contains(&i));
        let mut out: Vec<IsometryMatrix3<f64>> = Vec::with_capacity(self.joints.len());
        for (i, j) in self.joints.iter().enumerate() {
            if in_limb(i) {
                out.push(nan);
                continue;
            }
            let parent = j.parent.map_or(IsometryMatrix3::identity(), |p| out[p]);
            out.push(self.joint_frame_from(i, &parent, pose));
        }
        out
    }

    /// Completes [`Character::frames_above_limbs`]'s `frames` into [`Character::world_frames`]
    /// once the limbs of `pose` are solved: the clavicles (which turn with their arms) and the
    /// limbs' joints, each from its parent's frame; the trunk and head are kept.
    pub fn complete_limb_frames(&self, pose: &Pose, frames: &mut [IsometryMatrix3<f64>]) {
        for (i, j) in self.joints.iter().enumerate() {
            let trunk = !(j.girdle.is_some() || Limb::ALL.iter().any(|l| l.joints().contains(&i)));
            if trunk {
                continue;
            }
            let parent = j.parent.map_or(IsometryMatrix3::identity(), |p| frames[p]);
            frames[i] = self.joint_frame_from(i, &parent, pose);
        }
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
            // Most joints' rest is the identity (the spine's and limbs' frames are set up so).
            None if j.rest == Rotation3::identity() => {}
            None => frame.rotation *= j.rest,
        }
        for m in &j.motions {
            m.apply(&mut frame.rotation, &pose[k..]);
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

/// The rotation of one motion at DoF values `q` (its first one or two).
pub(crate) fn motion_rotation(m: &Motion, q: &[f64]) -> Rotation3<f64> {
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
