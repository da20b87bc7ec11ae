//! The character's arm convention and the fitted (capture) one (module docs of [`super`],
//! "Conventions"): the constant rotation `K` between their bases at rest, made as a fit makes
//! it, and the conversion of an arm between them through the girdle's turn.

use kinergy_io::InvalidSetting;
use kinergy_motion::limbs::ArmJoints;
use kinergy_motion::nalgebra::{Rotation3, Vector3};
use kinergy_motion::rotation::{swing_rotation, swing_twist, unwrap_near};
use kinergy_solver::{BaseMode, CaptureArm};

use crate::character::{Character, GirdleTurn, Limb, Pose};
use crate::error::{ReachError, Result};

/// `K`, the rotation from the character's base of `limb` to the capture-convention base a fit
/// of the character's own motion would use: made exactly as the fit makes it, by a
/// [`CaptureArm`] on the exported rest posture (both bases ride the clavicle, so `K` holds
/// on every frame).
pub(super) fn capture_rotation(
    character: &Character,
    limb: Limb,
    rest: &Pose,
) -> Result<Rotation3<f64>> {
    let capture_base = captured_arm(character, limb, rest)?
        .base(BaseMode::Fixed)
        .at(0)
        .rotation;
    let character_base = character.limb_base_frame(limb, rest).rotation;
    Ok(character_base.inverse() * capture_base)
}

/// The [`CaptureArm`] a fit makes of `limb` in a one-frame export of `pose`.
fn captured_arm(character: &Character, limb: Limb, pose: &Pose) -> Result<CaptureArm> {
    let setting = |why: String| ReachError::Setting(InvalidSetting::new("character", why));
    let clip = character.to_clip(std::slice::from_ref(pose), 1.0 / 60.0)?;
    let joints =
        ArmJoints::find(clip.skeleton(), limb.side()).map_err(|e| setting(e.to_string()))?;
    CaptureArm::new(&clip, &joints).map_err(|e| setting(e.to_string()))
}

/// The arm of `limb` in `pose` as a fit of the exported motion reads it: [`CaptureArm`]'s
/// configuration of the arm's joint positions, in the capture convention.
#[cfg(test)]
fn read_as_captured(character: &Character, limb: Limb, pose: &Pose) -> Result<Vec<f64>> {
    Ok(captured_arm(character, limb, pose)?.start().to_vec())
}

/// The character's arm convention and the fitted (capture) one (module docs,
/// "Conventions"): the capture base is the character's base turned by the girdle's turn
/// `G̃(q)` of the clavicle ([`GirdleTurn`]) and the constant `K` between the two at rest; the
/// shoulder rotations relate as `R_character = G̃(q) · K · R_capture`, the elbow and wrist DoFs
/// are the same.
#[derive(Debug, Clone, Copy)]
pub(super) struct Conventions {
    /// Character base → capture base at rest.
    k: Rotation3<f64>,
    /// The girdle's turn of the base.
    girdle: GirdleTurn,
}

impl Conventions {
    /// The conventions of `limb`, `K` from the character's `rest` posture.
    pub(super) fn new(character: &Character, limb: Limb, rest: &Pose) -> Result<Conventions> {
        Ok(Conventions {
            k: capture_rotation(character, limb, rest)?,
            girdle: character.girdle_turn(limb),
        })
    }

    /// Character base → capture base for the character's arm `q`: `G̃(q) · K`.
    pub(super) fn base_turn(self, q: &[f64]) -> Rotation3<f64> {
        self.girdle.in_base(q) * self.k
    }

    /// The capture-convention arm `q` (shoulder swing x, y, twist; elbow, wrist) as the
    /// character's DoFs, the twist unwrapped near `twist`. The girdle's turn depends on the
    /// character's arm itself: a fixed point, contracting by the rhythm's slope (≤ 0.3 a
    /// step), to 1e-14 rad.
    pub(super) fn to_character(self, q: &[f64], twist: f64) -> [f64; 7] {
        self.to_character_from(q, twist, &Rotation3::identity()).0
    }

    /// [`Conventions::to_character`] with the fixed point started from the girdle's turn
    /// `turn` (the previous frame's: a frame's arm moves little, so a few passes do); also
    /// returns the girdle's turn it ended on.
    pub(super) fn to_character_from(
        self,
        q: &[f64],
        twist: f64,
        turn: &Rotation3<f64>,
    ) -> ([f64; 7], Rotation3<f64>) {
        let captured = self.k
            * swing_rotation(q[0], q[1])
            * Rotation3::from_axis_angle(&Vector3::z_axis(), q[2]);
        let mut turn = *turn;
        let mut shoulder = turn * captured;
        for _ in 0..60 {
            let (sx, sy, _) = swing_twist(&shoulder);
            let next_turn = self.girdle.in_base(&[sx, sy]);
            let moved = next_turn.angle_to(&turn);
            turn = next_turn;
            shoulder = turn * captured;
            if moved < 1e-14 {
                break;
            }
        }
        let (sx, sy, tau) = swing_twist(&shoulder);
        let mut out = [0.0; 7];
        out[0] = sx;
        out[1] = sy;
        out[2] = unwrap_near(tau, twist);
        out[3..].copy_from_slice(&q[3..7]);
        (out, turn)
    }

    /// The character's arm DoFs `q` in the capture convention.
    pub(super) fn to_capture(self, q: &[f64; 7]) -> Vec<f64> {
        let shoulder = self.base_turn(q).inverse()
            * swing_rotation(q[0], q[1])
            * Rotation3::from_axis_angle(&Vector3::z_axis(), q[2]);
        let (sx, sy, tau) = swing_twist(&shoulder);
        let mut out = vec![sx, sy, tau];
        out.extend_from_slice(&q[3..]);
        out
    }
}

#[cfg(test)]
mod tests {
    use kinergy_motion::nalgebra::IsometryMatrix3;

    use super::*;

    fn character() -> Character {
        Character::from_height(1.75).expect("character")
    }

    /// The capture-convention chain on the capture base puts every arm point where the
    /// character's chain on its own base does, for arms in many postures (an independent
    /// check of K and of both conversions).
    #[test]
    fn both_conventions_place_the_arm_alike() {
        let c = character();
        let rest = c.rest_pose();
        for limb in [Limb::RightArm, Limb::LeftArm] {
            let conventions = Conventions::new(&c, limb, &rest).expect("K");
            let chain = c.limb_chain(limb);
            let mut pose = rest;
            for (i, q) in [
                [0.0; 7],
                [0.4, -0.3, 0.2, 0.9, 0.1, 0.2, -0.1],
                [-0.8, 0.5, -0.6, 1.4, -0.3, -0.4, 0.2],
                [1.2, 0.9, 1.0, 0.3, 0.5, 0.0, 0.1],
            ]
            .into_iter()
            .enumerate()
            {
                pose[3] = 0.1 * i as f64;
                pose[10] = -0.2 * i as f64;
                let base = c.limb_base_frame(limb, &pose);
                let capture_base = IsometryMatrix3::from_parts(
                    base.translation,
                    base.rotation * conventions.base_turn(&q),
                );
                let qc = conventions.to_capture(&q);
                let ours = chain.fk(&base, &q).expect("fk");
                let theirs = chain.fk(&capture_base, &qc).expect("fk");
                for (a, b) in ours.frames.iter().zip(&theirs.frames) {
                    let moved = (a.translation.vector - b.translation.vector).norm();
                    let turned = (a.rotation.matrix() - b.rotation.matrix()).norm();
                    assert!(moved < 1e-12 && turned < 1e-9, "{limb:?} {q:?}: {a} vs {b}");
                }
                assert!((ours.end - theirs.end).norm() < 1e-12);
                let back = conventions.to_character(&qc, q[2]);
                for (a, b) in back.iter().zip(&q) {
                    assert!((a - b).abs() < 1e-9, "{limb:?}: {back:?} vs {q:?}");
                }
            }
        }
    }

    /// At rest the character's hanging arm is, in the capture convention, the arm hanging
    /// down: its upper arm along −y of the capture base.
    #[test]
    fn the_hanging_arm_hangs_in_the_capture_convention_too() {
        let c = character();
        let rest = c.rest_pose();
        for limb in [Limb::RightArm, Limb::LeftArm] {
            let conventions = Conventions::new(&c, limb, &rest).expect("K");
            let k = conventions.k;
            let q = conventions.to_capture(&[0.0; 7]);
            let upper = swing_rotation(q[0], q[1])
                * Rotation3::from_axis_angle(&Vector3::z_axis(), q[2])
                * Vector3::z();
            assert!((upper - -Vector3::y()).norm() < 1e-9, "{limb:?}: {upper}");
            // A fit of the exported motion reads the same arm (the straight arm's twist aside:
            // not in its positions): every joint in the same place.
            let read = read_as_captured(&c, limb, &rest).expect("read");
            let base = c.limb_base_frame(limb, &rest);
            let capture_base = IsometryMatrix3::from_parts(base.translation, base.rotation * k);
            let chain = c.limb_chain(limb);
            let ours = chain.fk(&capture_base, &q).expect("fk");
            let theirs = chain.fk(&capture_base, &read).expect("fk");
            for (a, b) in ours.frames.iter().zip(&theirs.frames) {
                let d = (a.translation.vector - b.translation.vector).norm();
                assert!(d < 1e-9, "{limb:?}: {read:?} vs {q:?}");
            }
            assert!((ours.end - theirs.end).norm() < 1e-9);
        }
    }

    /// A fit of the exported motion reads a raised arm, whose clavicle the girdle has turned,
    /// as the controller's convention has it: the second frame of a two-frame export
    /// (rest, then the arm raised), read by [`CaptureArm`], is `to_capture` of the arm (the
    /// shoulder's three DoFs and the elbow's flexion: a fit reads joint positions, in which
    /// the forearm's twist and the wrist are not all seen).
    #[test]
    fn a_fit_reads_the_raised_arm_in_the_controllers_convention() {
        let c = character();
        let rest = c.rest_pose();
        for limb in [Limb::RightArm, Limb::LeftArm] {
            let conventions = Conventions::new(&c, limb, &rest).expect("K");
            for q in [
                [1.2, 0.9, 0.4, 0.3, 0.5, 0.0, 0.1],
                [2.4, -0.6, -0.5, 0.8, 0.0, 0.2, -0.1],
                [0.3, 2.6, 0.2, 1.1, 0.1, -0.2, 0.0],
            ] {
                let mut raised = rest;
                raised[c.limb_dofs(limb)].copy_from_slice(&q);
                assert!(c.girdle_turn(limb).in_base(&q).angle() > 0.05, "{q:?}");
                let clip = c.to_clip(&[rest, raised], 1.0 / 60.0).expect("clip");
                let joints = ArmJoints::find(clip.skeleton(), limb.side()).expect("joints");
                let arm = CaptureArm::new(&clip, &joints).expect("arm");
                let read = &arm.captured_configurations()[7..14];
                let ours = conventions.to_capture(&q);
                for (a, b) in read[..4].iter().zip(&ours) {
                    assert!(
                        (a - b).abs() < 1e-6,
                        "{limb:?} {q:?}: read {read:?}, ours {ours:?}"
                    );
                }
                let back = conventions.to_character(&ours, q[2]);
                for (a, b) in back.iter().zip(&q) {
                    assert!((a - b).abs() < 1e-6, "{limb:?}: {back:?} vs {q:?}");
                }
            }
        }
    }
}
