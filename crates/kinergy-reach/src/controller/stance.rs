//! The body's stance, for a planner that moves the body only so the arm can reach (Kallmann
//! 2005, "Spine Motion and Leg Flexion": the spine rotated toward the target and the root
//! lowered, the feet kept where they are by the legs' IK, before the arm's IK), made of this
//! crate's spine and leg controllers:
//!
//! - [`Stance`]: the spine's total swing φ about `s = d × y` (eq. 7) and twist θ (eq. 5), each
//!   split equally over the sacral, lumbar and thoracic joints, and the squat (the root
//!   lowered); [`pose_stance`] poses them as the reach's plan does — twist, squat, swing with
//!   eq. 8's COM shift `r = −k|φ| d_p` (`k = r_max / φ_max`) — and solves both legs for the
//!   planted feet ([`PlantedLegs`]);
//! - [`standing_stances`]: the stances the reach's posture search tries when the feet stay
//!   where they are (no step), in its order, each with the swing that brings the hand nearest;
//! - [`stance_limits`]: how far each of the three may go.
//!
//! The reach animates a stance over time with the step, the head and the balance correction;
//! a stance here is one posture, and whether the feet stayed planted — the toes where they
//! stand, a heel risen or not — is the caller's check ([`PlantedLegs::drift`]).

use kinergy_motion::Side;
use kinergy_motion::nalgebra::{IsometryMatrix3, Point3, Vector3};
use kinergy_solver::analytic::LimbIk;

use super::legs::{leg_iks, solve_legs};
use super::settings::ReachSettings;
use super::spine::{apply_swing, max_squat, max_swing_split, max_twist_split, set_twist};
use crate::character::{Character, Pose, dof, joint};
use crate::error::Result;

/// A posture of the spine and the legs with the feet where they stand ([`pose_stance`]
/// poses it): the spine's swing and twist, the squat, and the swing's axis and the COM
/// shift's direction, fixed for a reach by its target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stance {
    /// φ, the spine's total swing about [`Stance::axis`], radians (eq. 7).
    pub swing: f64,
    /// θ, the spine's total twist about its joints' z axes, radians (eq. 5; > 0 turns left).
    pub twist: f64,
    /// How far the root is lowered, meters (≥ 0).
    pub squat: f64,
    /// `s = d × y`, normalized: the swing's world axis (`d` from the shoulder to the target).
    pub axis: Vector3<f64>,
    /// d_p: the ground direction (unit, world) along which eq. 8 shifts the root back.
    pub dp: Vector3<f64>,
}

impl Stance {
    /// Standing upright: no swing, twist or squat (the axis +X, d_p +Z: the character's
    /// forward bend, should either be used).
    pub fn upright() -> Stance {
        Stance {
            swing: 0.0,
            twist: 0.0,
            squat: 0.0,
            axis: Vector3::x(),
            dp: Vector3::z(),
        }
    }

    /// True when swing, twist and squat are all zero.
    pub fn is_upright(&self) -> bool {
        self.swing == 0.0 && self.twist == 0.0 && self.squat == 0.0
    }
}

/// Both legs solved for planted feet by the leg controller's analytic IK (knees forward; a
/// foot the ankle cannot keep flat rises about its toe, as the reach's legs do in a deep
/// squat).
///
/// A foot is planted, as the reach's tests hold it, when no point of it on the ground slides:
/// its toe tip stays where it stands and its heel rises about it or stays, the foot turning
/// only about its own lateral axis ([`PlantedLegs::drift`]).
#[derive(Debug, Clone)]
pub struct PlantedLegs {
    iks: [LimbIk; 2],
    feet: [IsometryMatrix3<f64>; 2],
    /// The toe tips, world.
    toes: [Point3<f64>; 2],
    /// The heels' points in the ankle frames, and their heights in world.
    heels: [(Point3<f64>, f64); 2],
}

/// The ankle, toe-tip and heel joints of the right and the left foot.
const FEET: [(usize, usize, Side); 2] = [
    (joint::RIGHT_FOOT, joint::RIGHT_FOOT_END, Side::Right),
    (joint::LEFT_FOOT, joint::LEFT_FOOT_END, Side::Left),
];

impl PlantedLegs {
    /// The legs of `character` with the feet planted where they are in `pose`.
    pub fn new(character: &Character, pose: &Pose) -> Result<PlantedLegs> {
        let frames = character.world_frames(pose);
        let heel = |(ankle, _, side): (usize, usize, Side)| {
            let leg = character.proportions().leg(side);
            let local = Point3::new(0.0, -leg.heel, leg.ankle_height);
            (local, (frames[ankle] * local).y)
        };
        let toe = |(_, tip, _): (usize, usize, Side)| Point3::from(frames[tip].translation.vector);
        Ok(PlantedLegs {
            iks: leg_iks(character)?,
            feet: [frames[joint::RIGHT_FOOT], frames[joint::LEFT_FOOT]],
            toes: FEET.map(toe),
            heels: FEET.map(heel),
        })
    }

    /// The planted ankle frames, `[right, left]`, world.
    pub fn feet(&self) -> &[IsometryMatrix3<f64>; 2] {
        &self.feet
    }

    /// Solves both legs of `pose` (the body above the hips as it is) for the planted feet.
    pub fn solve(&self, character: &Character, pose: &mut Pose) {
        solve_legs(character, pose, &self.iks, &self.feet);
    }

    /// How far the feet of the pose whose world frames are `frames` are from planted: the
    /// largest of the toe tips' slides, the heels' sinking below where they stand (meters)
    /// and the turn of the feet's lateral axes (radians). Zero (to rounding) when the legs
    /// kept them, heels risen or not.
    pub fn drift(&self, frames: &[IsometryMatrix3<f64>]) -> f64 {
        let mut drift: f64 = 0.0;
        for (i, (ankle, tip, _)) in FEET.into_iter().enumerate() {
            let toe = Point3::from(frames[tip].translation.vector);
            let (local, height) = self.heels[i];
            let heel = frames[ankle] * local;
            let lateral = frames[ankle].rotation * Vector3::x();
            let planted = self.feet[i].rotation * Vector3::x();
            drift = drift
                .max((toe - self.toes[i]).norm())
                .max(height - heel.y)
                .max((lateral - planted).norm());
        }
        drift
    }
}

/// `rest` posed in `stance` as the reach's plan poses a posture: the twist split over the
/// lower spine (eq. 5), the root lowered by the squat, the swing about the stance's axis split
/// likewise (eq. 7) with the root shifted by `r = −k_com |φ| d_p` (eq. 8), then both legs solved
/// for the planted feet. An upright stance gives `rest` itself.
pub fn pose_stance(
    character: &Character,
    rest: &Pose,
    stance: &Stance,
    k_com: f64,
    legs: &PlantedLegs,
) -> Pose {
    let mut pose = *rest;
    if stance.is_upright() {
        return pose;
    }
    set_twist(&mut pose, stance.twist);
    pose[dof::ROOT_Y] -= stance.squat;
    if stance.swing != 0.0 {
        apply_swing(character, &mut pose, &stance.axis, stance.swing);
        let shift = -k_com * stance.swing.abs() * stance.dp;
        pose[dof::ROOT_X] += shift.x;
        pose[dof::ROOT_Z] += shift.z;
    }
    legs.solve(character, &mut pose);
    pose
}

/// How far a stance may go.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StanceLimits {
    /// The largest |swing|, radians: φ_max, or less where the three joints' swing limits
    /// split equally allow less.
    pub swing: f64,
    /// The largest |twist|, radians, split equally within the three joints' limits.
    pub twist: f64,
    /// The deepest squat, meters.
    pub squat: f64,
}

/// The limits of `character`'s stance under `settings` (φ_max).
pub fn stance_limits(character: &Character, settings: &ReachSettings) -> StanceLimits {
    StanceLimits {
        swing: settings.phi_max.min(max_swing_split(character)),
        twist: max_twist_split(character),
        squat: max_squat(character),
    }
}

/// One stance the reach's posture search tries, and how near the hand comes to the target
/// from it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StanceCandidate {
    /// The stance.
    pub stance: Stance,
    /// The hand's (fingertip's) distance from the target with the arm solved there, meters.
    pub hand_error: f64,
}

/// The stances from which the arm `side` of the settings reaches for `target` with the feet
/// where they stand in `rest`, in the order the reach's posture search tries them without a
/// step: the paper's decisions (the twist into the comfortable angle, the squat the leg
/// flexibility asks for, the swing raised until the hand reaches), then squats 2 cm deeper
/// each, to the deepest — each with its twist and the swing that brings the hand nearest. The
/// swing's axis and d_p are each stance's own (from its shoulder to the target).
pub fn standing_stances(
    character: &Character,
    rest: &Pose,
    target: &Point3<f64>,
    settings: &ReachSettings,
) -> Result<Vec<StanceCandidate>> {
    settings.validate()?;
    super::plan::standing_stances(character, rest, target, settings)
}

#[cfg(test)]
mod tests {
    use approx::assert_relative_eq;
    use kinergy_motion::Side;

    use super::*;
    use crate::controller::{ReachStop, reach_full_body};

    /// The first standing stance is the posture the reach itself plans when it does not step
    /// (its report's swing, twist and squat), posed with the feet planted and the hand within
    /// reach; the later ones squat deeper, 2 cm at a time.
    #[test]
    fn the_first_standing_stance_is_the_reachs_own_posture() {
        let c = Character::from_height(1.75).unwrap();
        let rest = c.rest_pose();
        let target = Point3::new(-0.25, 0.45, 0.4);
        let settings = ReachSettings {
            arm: Some(Side::Right),
            ..ReachSettings::default()
        };
        let motion = reach_full_body(&c, target, &settings).unwrap();
        assert_eq!(motion.report.stop, ReachStop::Reached);
        assert_eq!(motion.report.step_length, 0.0);
        let stances = standing_stances(&c, &rest, &target, &settings).unwrap();
        let first = &stances[0];
        assert_relative_eq!(first.stance.swing.to_degrees(), motion.report.swing_deg);
        assert_relative_eq!(first.stance.twist.to_degrees(), motion.report.twist_deg);
        assert_relative_eq!(first.stance.squat, motion.report.squat_m);
        assert!(first.hand_error <= 0.5 * settings.tolerance);
        for w in stances.windows(2) {
            assert!(w[1].stance.squat > w[0].stance.squat);
            assert!(w[1].stance.squat - w[0].stance.squat <= 0.02 + 1e-12);
        }
        let limits = stance_limits(&c, &settings);
        assert_relative_eq!(stances.last().unwrap().stance.squat, limits.squat);
        let legs = PlantedLegs::new(&c, &rest).unwrap();
        let k = settings.r_max / settings.phi_max;
        let pose = pose_stance(&c, &rest, &first.stance, k, &legs);
        assert!(legs.drift(&c.world_frames(&pose)) < 1e-9);
        assert_relative_eq!(pose[dof::ROOT_Y], rest[dof::ROOT_Y] - first.stance.squat);
        c.joint_limits_ok(&pose).unwrap();
    }

    /// Upright is the rest posture itself; a heel risen about its toe is planted, a toe slid
    /// is not.
    #[test]
    fn planted_feet_keep_their_toes_where_they_stand() {
        let c = Character::from_height(1.75).unwrap();
        let rest = c.rest_pose();
        let legs = PlantedLegs::new(&c, &rest).unwrap();
        let upright = pose_stance(&c, &rest, &Stance::upright(), 0.05, &legs);
        assert_eq!(upright, rest);
        let frames = c.world_frames(&rest);
        assert!(legs.drift(&frames) < 1e-12);
        // The deepest squat, straight down: the ankles cannot bend that far, the heels rise.
        let deep = Stance {
            squat: stance_limits(&c, &ReachSettings::default()).squat,
            ..Stance::upright()
        };
        let pose = pose_stance(&c, &rest, &deep, 0.05, &legs);
        let f = c.world_frames(&pose);
        assert!(legs.drift(&f) < 1e-9, "{}", legs.drift(&f));
        let heel_up = c.foot_points(&pose)[0].y;
        assert!(heel_up > 0.01, "the right heel at {heel_up}");
        // The root raised 30 cm: no leg reaches its toe, tiptoe or not.
        let mut slid = rest;
        slid[dof::ROOT_Y] += 0.3;
        legs.solve(&c, &mut slid);
        assert!(legs.drift(&c.world_frames(&slid)) > 0.01);
    }
}
