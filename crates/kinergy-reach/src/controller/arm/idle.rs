//! The arm that does not reach ([`IdleArm`]): it hangs from its shoulder, turned with the
//! trunk, solved by the reaching arm's analytic IK.

use std::ops::Range;

use kinergy_motion::nalgebra::{IsometryMatrix3, Point3, Rotation3, Vector3};
use kinergy_solver::analytic::{LimbIk, OrbitSearch};

use super::solve::{Near, arm_ik, on_girdle, solve_arm_near};
use super::tracking::{ARM_MAX_SPEED, limit_speed};
use crate::character::{Character, Limb, Pose};
use crate::error::Result;

/// The arm that does not reach: it hangs from its shoulder under its own weight while the
/// body steps, twists, bends and squats. Its hand is held where it hangs at rest relative to
/// the shoulder, turned with the trunk about the vertical, a little closer so the elbow
/// relaxes, and never lower than [`IDLE_HAND_CLEARANCE`] above the floor; the arm is solved
/// for it by the same analytic IK as the reaching arm, continuous from frame to frame and no
/// faster than [`ARM_MAX_SPEED`]. (Left at its rest angles the arm would stick out straight
/// behind a bending trunk.)
#[derive(Debug, Clone)]
pub(crate) struct IdleArm {
    limb: Limb,
    dofs: Range<usize>,
    ik: LimbIk,
    search: OrbitSearch,
    /// The hand's offset from the shoulder at rest, world, shortened by [`IDLE_RELAX`].
    hang: Vector3<f64>,
    /// The trunk's heading at rest: the shoulder frame's x axis on the ground.
    heading: Vector3<f64>,
    /// The previous frame's arm DoFs (the rest pose's before the first frame).
    previous: [f64; 7],
    /// The previous frame's orbit angle.
    alpha: Option<f64>,
    /// The last goal in the arm's base frame and the arm solved for it.
    solved: Option<(Point3<f64>, [f64; 7])>,
}

/// How much closer to the shoulder the idle hand hangs than the straight arm at rest (a
/// relaxed elbow bends a little, and a straight arm is the IK's singular posture).
const IDLE_RELAX: f64 = 0.995;

/// The lowest the idle hand goes, meters above the floor (y = 0).
const IDLE_HAND_CLEARANCE: f64 = 0.1;

impl IdleArm {
    /// The `limb`'s idle arm, hanging as in `rest`.
    pub(crate) fn new(character: &Character, limb: Limb, rest: &Pose) -> Result<IdleArm> {
        let ik = arm_ik(character, limb)?;
        let dofs = character.limb_dofs(limb);
        let base = character.limb_base_frame(limb, rest);
        let hand = character
            .limb_chain(limb)
            .end_position(&base, &rest[dofs.clone()])
            .unwrap_or_else(|_| Point3::from(base.translation.vector));
        Ok(IdleArm {
            limb,
            previous: std::array::from_fn(|i| rest[dofs.start + i]),
            dofs,
            ik,
            search: OrbitSearch::default(),
            hang: (hand.coords - base.translation.vector) * IDLE_RELAX,
            heading: ground_heading(&base),
            alpha: None,
            solved: None,
        })
    }

    /// Solves the idle arm into `pose`, the arm's base frame at `base`; keeps the pose's arm
    /// when nothing is found. Returns the orbit angle solved at, if any. The goal depends on
    /// the base's rotation only (and on its height near the floor): while the trunk keeps
    /// its orientation — the root shifted for balance, the body stepping upright — the last
    /// solution is reused.
    pub(crate) fn hang(
        &mut self,
        character: &Character,
        pose: &mut Pose,
        base: &IsometryMatrix3<f64>,
    ) -> Option<f64> {
        // The hand hangs below where the shoulder is with the clavicle at rest.
        let at: [f64; 7] = std::array::from_fn(|i| pose[self.dofs.start + i]);
        let rest = character.arm_base_moved(self.limb, base, &at, &[0.0; 7]);
        let now = ground_heading(&rest);
        let yaw = self.heading.cross(&now).y.atan2(self.heading.dot(&now));
        let turned = Rotation3::from_axis_angle(&Vector3::y_axis(), yaw) * self.hang;
        let mut goal = Point3::from(rest.translation.vector + turned);
        goal.y = goal.y.max(IDLE_HAND_CLEARANCE);
        let local = rest.inverse() * goal;
        if let Some((last, q)) = self.solved
            && (last - local).norm() < 1e-9
        {
            pose[self.dofs.clone()].copy_from_slice(&q);
            return self.alpha;
        }
        let near = match self.alpha {
            Some(a) => Near::Alpha(a),
            None => Near::Posture(self.previous),
        };
        let (ik, search) = (&self.ik, &self.search);
        let (alpha, q) = on_girdle(character, self.limb, base, &at, &self.previous, |b| {
            solve_arm_near(ik, b, &goal, search, near)
        })?;
        pose[self.dofs.clone()].copy_from_slice(&q);
        self.solved = Some((local, q));
        Some(alpha)
    }

    /// Puts the arm of `pose` where it hangs relaxed, its base where `pose` puts it, the pose
    /// clamped to the limits, and keeps it as the previous posture: an arm that starts relaxed
    /// on the first frame instead of bending there from the straight rest arm. The pose is
    /// unchanged where no posture is found.
    pub(crate) fn relax(&mut self, character: &Character, pose: &mut Pose) {
        let base = character.limb_base_frame(self.limb, pose);
        if self.hang(character, pose, &base).is_some() {
            character.clamp_pose(pose);
            self.settle(pose);
        }
    }

    /// Ends a frame of `dt` seconds as
    /// [`ArmFollower::end_frame`](super::ArmFollower::end_frame) does, and keeps the frame's
    /// posture as the previous one.
    pub(crate) fn end_frame(&mut self, pose: &mut Pose, alpha: Option<f64>, dt: f64) {
        if alpha.is_some() {
            self.alpha = alpha;
        }
        limit_speed(
            &mut pose[self.dofs.clone()],
            &self.previous,
            ARM_MAX_SPEED * dt,
        );
    }

    /// Keeps the frame's final arm posture (`pose`, clamped) as the previous one.
    pub(crate) fn settle(&mut self, pose: &Pose) {
        self.previous = std::array::from_fn(|i| pose[self.dofs.start + i]);
    }

    /// Keeps the orbit angle solved in a frame (`alpha`, if any) for the next frame's search,
    /// when another controller holds the arm to its speed
    /// ([`ArmFollower::end_frame`](super::ArmFollower::end_frame): the reaching arm hanging
    /// before it reaches).
    pub(crate) fn solved_at(&mut self, alpha: Option<f64>) {
        if alpha.is_some() {
            self.alpha = alpha;
        }
    }
}

/// The direction of a frame's x axis on the ground (x if it points straight up or down).
fn ground_heading(frame: &IsometryMatrix3<f64>) -> Vector3<f64> {
    let x = frame.rotation * Vector3::x();
    Vector3::new(x.x, 0.0, x.z)
        .try_normalize(1e-9)
        .unwrap_or_else(Vector3::x)
}
