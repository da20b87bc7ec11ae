//! The body's DoFs in the planner's configuration: Kallmann's arm configuration `s` is "the
//! 7-DoF arm configuration plus any additional DoFs in case spine motion and/or leg flexion
//! are considered by the IK solver" (2005, "Planning").
//!
//! An [`ArmConfig`](crate::space::ArmConfig) holds the arm's 7 DoFs and three body DoFs
//! ([`body_dof`]): the spine's swing φ and twist θ and the squat, the reach layer's
//! [`Stance`] (Huang, Kapadia & Terzopoulos's spine and legs, DESIGN §1.2): φ about the swing
//! axis `s = d × y` fixed by the reach's goal posture (negative φ bends toward the target),
//! θ split equally over the sacral, lumbar and thoracic joints, the root lowered by the
//! squat and shifted back by eq. 8's `r = −k|φ| d_p`, both legs solved for the feet where they
//! stand ([`PlantedLegs`]). A [`BodyMotion`] poses them; all three zero is the reference
//! posture itself.
//!
//! The body moves only where the arm alone cannot reach its goal: a space without a body
//! motion keeps the three at zero ([`crate::space::ArmSpace::moves_body`]).

use kinergy_reach::character::{Character, Pose, dof};
use kinergy_reach::controller::{
    PlantedLegs, ReachSettings, Stance, StanceLimits, pose_stance, stance_limits,
};
use nalgebra::{Vector2, Vector3};

use crate::error::Result;

/// The arm's DoFs in a configuration: the first seven.
pub const ARM_DOFS: usize = 7;

/// The body's DoFs in a configuration: the three after the arm's.
pub const BODY_DOFS: usize = 3;

/// A configuration's DoFs: the arm's, then the body's.
pub const CONFIG_DOFS: usize = ARM_DOFS + BODY_DOFS;

/// Indices of the body's DoFs in an [`ArmConfig`](crate::space::ArmConfig).
pub mod body_dof {
    /// φ, the spine's total swing about the reach's swing axis, radians.
    pub const SWING: usize = 7;
    /// θ, the spine's total twist, radians (> 0 turns left).
    pub const TWIST: usize = 8;
    /// How far the root is lowered, meters.
    pub const SQUAT: usize = 9;
}

/// The body DoFs' names, in their order (the plan report's `body_dofs`).
pub const BODY_DOF_NAMES: [&str; BODY_DOFS] = ["spine_swing", "spine_twist", "squat"];

/// The body's three DoFs.
pub type BodyDofs = [f64; BODY_DOFS];

/// How far a planted foot may end from where it stands (meters, or radians of turn) and
/// still count as planted: rounding, not a slide.
pub const PLANTED: f64 = 1e-6;

/// The body's motion in a planning space: the character, its reference posture, the swing's
/// axis and d_p (from the goal posture), the planted legs and the stance's limits.
#[derive(Debug, Clone)]
pub struct BodyMotion {
    character: Character,
    reference: Pose,
    legs: PlantedLegs,
    k_com: f64,
    axis: Vector3<f64>,
    dp: Vector3<f64>,
    limits: StanceLimits,
    goal: BodyDofs,
    /// The sacral joint's swing for a unit total swing, divided by its share (a third): the
    /// direction `pose_stance` gives the root's swing DoFs, which read the swing back.
    sacral: Vector2<f64>,
}

impl BodyMotion {
    /// The body of `character` standing in `reference`, moving toward `goal` (its swing's
    /// axis and d_p are the motion's), under the reach `settings` (φ_max, r_max).
    pub fn new(
        character: &Character,
        reference: &Pose,
        goal: &Stance,
        settings: &ReachSettings,
    ) -> Result<BodyMotion> {
        settings.validate()?;
        let legs = PlantedLegs::new(character, reference)?;
        let k_com = settings.r_max / settings.phi_max;
        // The root's swing does not depend on the other DoFs (its parent is the world):
        // posed with a unit swing, it is the direction to read swings back along.
        let unit = Stance {
            swing: 1.0,
            twist: 0.0,
            squat: 0.0,
            ..*goal
        };
        let posed = pose_stance(character, reference, &unit, k_com, &legs);
        let r = dof::ROOT_ROTATION.start;
        let sacral = Vector2::new(posed[r], posed[r + 1]) * 3.0;
        Ok(BodyMotion {
            character: character.clone(),
            reference: *reference,
            legs,
            k_com,
            axis: goal.axis,
            dp: goal.dp,
            limits: stance_limits(character, settings),
            goal: [goal.swing, goal.twist, goal.squat],
            sacral,
        })
    }

    /// The character.
    pub fn character(&self) -> &Character {
        &self.character
    }

    /// The reference posture (all three DoFs zero).
    pub fn reference(&self) -> &Pose {
        &self.reference
    }

    /// The goal posture's body DoFs.
    pub fn goal(&self) -> BodyDofs {
        self.goal
    }

    /// How far each DoF may go.
    pub fn limits(&self) -> StanceLimits {
        self.limits
    }

    /// The stance of body DoFs `b`.
    pub fn stance(&self, b: &BodyDofs) -> Stance {
        Stance {
            swing: b[0],
            twist: b[1],
            squat: b[2],
            axis: self.axis,
            dp: self.dp,
        }
    }

    /// True when `b` is within the stance's limits (|φ|, |θ| within theirs, the squat from 0
    /// to the deepest) and finite.
    pub fn within_limits(&self, b: &BodyDofs) -> bool {
        let l = &self.limits;
        b.iter().all(|v| v.is_finite())
            && b[0].abs() <= l.swing
            && b[1].abs() <= l.twist
            && (0.0..=l.squat).contains(&b[2])
    }

    /// The reference posture with the body at `b` (the reference itself for zeros), the legs
    /// solved for the planted feet — whether they could keep them is [`BodyMotion::drift`]'s
    /// to say.
    pub fn pose(&self, b: &BodyDofs) -> Pose {
        if b.iter().all(|&v| v == 0.0) {
            return self.reference;
        }
        pose_stance(
            &self.character,
            &self.reference,
            &self.stance(b),
            self.k_com,
            &self.legs,
        )
    }

    /// How far the feet of the pose whose world frames are `frames` lie from where they stand
    /// (meters, or radians of turn): at most [`PLANTED`] when the legs kept them.
    pub fn drift(&self, frames: &[nalgebra::IsometryMatrix3<f64>]) -> f64 {
        self.legs.drift(frames)
    }

    /// The body DoFs of a pose this motion made ([`BodyMotion::pose`]), read back from the
    /// root's swing and twist and its height (to rounding).
    pub fn dofs_of(&self, pose: &Pose) -> BodyDofs {
        let r = dof::ROOT_ROTATION.start;
        let swing = Vector2::new(pose[r], pose[r + 1]);
        let n = self.sacral.norm_squared();
        let phi = if n > 0.0 {
            3.0 * swing.dot(&self.sacral) / n
        } else {
            0.0
        };
        [
            phi,
            3.0 * pose[r + 2],
            self.reference[dof::ROOT_Y] - pose[dof::ROOT_Y],
        ]
    }
}

/// The names of the body DoFs that are not zero in `b`.
pub fn used_dofs(b: &BodyDofs) -> Vec<&'static str> {
    BODY_DOF_NAMES
        .iter()
        .zip(b)
        .filter(|(_, v)| **v != 0.0)
        .map(|(n, _)| *n)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::reference_pose;

    fn motion() -> (Character, Pose, BodyMotion) {
        let c = Character::from_height(1.75).unwrap();
        let reference = reference_pose(&c);
        let goal = Stance {
            swing: -0.5,
            twist: 0.3,
            squat: 0.25,
            ..Stance::upright()
        };
        let m = BodyMotion::new(&c, &reference, &goal, &ReachSettings::default()).unwrap();
        (c, reference, m)
    }

    /// All zeros is the reference posture itself; other DoFs read back from the pose they
    /// make (to rounding), the feet planted along the way to the goal.
    #[test]
    fn body_dofs_read_back_from_the_pose_they_make() {
        let (c, reference, m) = motion();
        assert_eq!(m.pose(&[0.0; BODY_DOFS]), reference);
        assert_eq!(m.goal(), [-0.5, 0.3, 0.25]);
        for k in 1..=10 {
            let t = k as f64 / 10.0;
            let b = m.goal().map(|v| v * t);
            assert!(m.within_limits(&b));
            let pose = m.pose(&b);
            let back = m.dofs_of(&pose);
            for (x, y) in b.iter().zip(&back) {
                assert!((x - y).abs() < 1e-12, "{b:?} read back as {back:?}");
            }
            assert!(m.drift(&c.world_frames(&pose)) <= PLANTED, "{b:?}");
            c.joint_limits_ok(&pose).unwrap();
        }
        let l = m.limits();
        assert!(!m.within_limits(&[l.swing * 1.01, 0.0, 0.0]));
        assert!(!m.within_limits(&[0.0, 0.0, -0.01]));
        assert!(!m.within_limits(&[0.0, f64::NAN, 0.0]));
        assert_eq!(used_dofs(&[0.0, 0.1, 0.2]), ["spine_twist", "squat"]);
    }
}
