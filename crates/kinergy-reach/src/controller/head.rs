//! The head controller (Huang, Kapadia & Terzopoulos §3.2): once the arm starts, the
//! cervical joint turns the head toward the target at a bounded angular speed, then tracks
//! it.

use kinergy_motion::nalgebra::{IsometryMatrix3, Point3};

use crate::character::{Character, Pose, dof, joint};

/// The head's turn: the cervical twist and forward swing, radians.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Head {
    twist: f64,
    swing_x: f64,
}

impl Head {
    /// Turns toward `target` as seen from `pose`, each angle by at most `max_step` radians.
    pub(super) fn turn_toward(
        &mut self,
        character: &Character,
        pose: &Pose,
        target: &Point3<f64>,
        max_step: f64,
    ) {
        let want = head_angles(character, pose, target);
        self.twist += (want.0 - self.twist).clamp(-max_step, max_step);
        self.swing_x += (want.1 - self.swing_x).clamp(-max_step, max_step);
    }

    /// Writes the turn into the cervical DoFs of `pose`.
    pub(super) fn apply(&self, pose: &mut Pose) {
        pose[dof::CERVICAL.start + dof::TWIST] = self.twist;
        pose[dof::CERVICAL.start + dof::SWING_X] = self.swing_x;
    }
}

/// The cervical twist and forward swing that face the head toward the target.
fn head_angles(character: &Character, pose: &Pose, target: &Point3<f64>) -> (f64, f64) {
    let neck = &character.joints()[joint::NECK];
    let parent = neck.parent.map_or(IsometryMatrix3::identity(), |p| {
        character.joint_frame(p, pose)
    });
    let frame_rot = parent.rotation * neck.rest;
    let origin = parent * Point3::from(neck.offset);
    let d = frame_rot.inverse() * (target - origin);
    // In the spine frames forward is −y, up is +z, left is +x.
    let yaw = (d.x).atan2(-d.y);
    let horizontal = (d.x * d.x + d.y * d.y).sqrt();
    let pitch = (-d.z).atan2(horizontal);
    let lim = |v: f64, l: f64| v.clamp(-l, l);
    (lim(yaw, 70f64.to_radians()), lim(pitch, 50f64.to_radians()))
}
