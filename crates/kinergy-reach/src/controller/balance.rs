//! Balance (beyond the paper): the centre of mass's ground projection kept inside the support
//! polygon by shifting the root horizontally toward the polygon's centroid ([`rebalance`]).
//! Planning shifts the final posture until it keeps the COM 2 cm further in than required
//! ([`plan_com_shift`]); every animated frame is corrected again, the limbs solved anew after
//! each shift, the correction carried from frame to frame at a bounded speed
//! ([`BalanceCorrection`]).

use kinergy_motion::nalgebra::{IsometryMatrix3, Point2, Vector2, Vector3};

use super::arm::ReachingArm;
use super::legs::{leg_iks, lower_root_for_legs, solve_legs};
use crate::character::{Character, Pose, dof};
use crate::error::Result;

/// The COM's margin inside the support polygon and, when short, the root shift that helps.
#[derive(Debug, Clone, Copy)]
pub(super) struct Balance {
    /// How far the COM's ground projection lies inside the support polygon, meters
    /// (negative: outside).
    pub margin: f64,
    /// The horizontal root shift `(x, z)` toward the polygon's centroid, meters; `None` when
    /// the margin is already what was wanted.
    pub shift: Option<Vector2<f64>>,
}

/// The balance of the posture with world `frames`: its margin, and when it is below `wanted`
/// the root shift toward the support polygon's centroid by `gain` × the shortfall + 2 mm.
pub(super) fn rebalance(
    character: &Character,
    frames: &[IsometryMatrix3<f64>],
    wanted: f64,
    gain: f64,
) -> Balance {
    let com = character.com_in(frames);
    let polygon = character.support_polygon_in(frames);
    let c = Point2::new(com.x, com.z);
    let margin = polygon.margin(c);
    if margin >= wanted {
        return Balance {
            margin,
            shift: None,
        };
    }
    let v = polygon.vertices();
    let centroid = v
        .iter()
        .fold(Point2::origin(), |a, p| a + p.coords / v.len() as f64);
    let dir = (centroid - c)
        .try_normalize(1e-12)
        .unwrap_or_else(Vector2::zeros);
    Balance {
        margin,
        shift: Some(dir * (gain * (wanted - margin) + 0.002)),
    }
}

/// The COM adjustment of the final posture: eq. 8's `r = −kφ d_p` (`start`), then — beyond
/// the paper — as much more toward the support polygon's centre as the final `posture` needs
/// to keep the COM's projection `wanted` meters inside the final support polygon, with the
/// ankles at `feet` (where the step leaves them) and the `arm` solved for its target. Returns
/// the shift and the hand's distance from the target in the shifted posture (the root moved
/// back for balance can leave the hand short).
pub(super) fn plan_com_shift(
    arm: &ReachingArm<'_>,
    posture: &Pose,
    feet: &[IsometryMatrix3<f64>; 2],
    start: Vector3<f64>,
    wanted: f64,
) -> Result<(Vector3<f64>, f64)> {
    let character = arm.character;
    let legs = leg_iks(character)?;
    let mut com_shift = start;
    let mut q = *posture;
    for _ in 0..40 {
        q = *posture;
        q[dof::ROOT_X] += com_shift.x;
        q[dof::ROOT_Z] += com_shift.z;
        lower_root_for_legs(character, &mut q, feet);
        solve_legs(character, &mut q, &legs, feet);
        if let Some(a) = arm.solve(&q) {
            q[character.limb_dofs(arm.limb)].copy_from_slice(&a);
        }
        match rebalance(character, &character.world_frames(&q), wanted, 0.5).shift {
            None => break,
            Some(shift) => com_shift += Vector3::new(shift.x, 0.0, shift.y),
        }
    }
    Ok((com_shift, arm.error(&q)))
}

/// The fastest the balance correction moves the root, m/s.
const BALANCE_SPEED: f64 = 0.5;

/// The fastest it moves the root when the COM would otherwise leave the support polygon, m/s.
const URGENT_BALANCE_SPEED: f64 = 1.5;

/// Where the plan puts a frame's root, before the balance correction.
#[derive(Debug, Clone, Copy)]
pub(super) struct PlannedRoot {
    /// Horizontal `(x, z)`, world meters.
    xz: Vector2<f64>,
    /// The root's height (lowered where the legs need it on every balance pass).
    pub(super) height: f64,
}

/// A frame's limbs solved and balanced.
#[derive(Debug, Clone, Copy)]
pub(super) struct Balanced {
    /// The reaching hand's distance from the target, meters.
    pub(super) error: f64,
    /// The COM's margin inside the support polygon, meters.
    pub(super) margin: f64,
}

/// The balance correction of the root `(x, z)`, carried from frame to frame: each frame the
/// limbs are solved and the root shifted until the COM is the wanted margin inside the
/// support polygon (at most nine shifts), and the correction follows the shift no faster
/// than [`BALANCE_SPEED`] — a support polygon that changes at once (a heel rising) is
/// followed over a few frames, not in one jump — or [`URGENT_BALANCE_SPEED`] when the COM
/// would otherwise leave the polygon.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct BalanceCorrection {
    correction: Vector2<f64>,
}

impl BalanceCorrection {
    /// Moves the root of `pose` (where the plan put it) by the correction so far; returns
    /// where the plan put it.
    pub(super) fn carry(&self, pose: &mut Pose) -> PlannedRoot {
        let planned = PlannedRoot {
            xz: Vector2::new(pose[dof::ROOT_X], pose[dof::ROOT_Z]),
            height: pose[dof::ROOT_Y],
        };
        pose[dof::ROOT_X] += self.correction.x;
        pose[dof::ROOT_Z] += self.correction.y;
        planned
    }

    /// Solves the frame's limbs with `solve` (the pose, whether it is the frame's first pass;
    /// returns the hand's distance from the target and the solved pose's world frames) and
    /// balances it: `wanted_margin` meters of margin, the correction at most `dt` seconds'
    /// worth of speed from the last frame's.
    pub(super) fn balance(
        &mut self,
        character: &Character,
        wanted_margin: f64,
        dt: f64,
        planned: &PlannedRoot,
        pose: &mut Pose,
        mut solve: impl FnMut(&mut Pose, bool) -> (f64, Vec<IsometryMatrix3<f64>>),
    ) -> Balanced {
        let mut error = f64::INFINITY;
        let mut margin = f64::INFINITY;
        for pass in 0..10 {
            let (e, frames) = solve(pose, pass == 0);
            error = e;
            let balance = rebalance(character, &frames, wanted_margin, 1.5);
            match balance.shift {
                Some(shift) if pass < 9 => {
                    pose[dof::ROOT_X] += shift.x;
                    pose[dof::ROOT_Z] += shift.y;
                }
                _ => {
                    margin = balance.margin;
                    break;
                }
            }
        }
        let wanted = Vector2::new(pose[dof::ROOT_X], pose[dof::ROOT_Z]) - planned.xz;
        let change = wanted - self.correction;
        if change.norm() > BALANCE_SPEED * dt {
            let before = self.correction;
            for speed in [BALANCE_SPEED, URGENT_BALANCE_SPEED] {
                let largest = speed * dt;
                self.correction = if change.norm() > largest {
                    before + change * (largest / change.norm())
                } else {
                    wanted
                };
                pose[dof::ROOT_X] = planned.xz.x + self.correction.x;
                pose[dof::ROOT_Z] = planned.xz.y + self.correction.y;
                let (e, frames) = solve(pose, false);
                error = e;
                margin = rebalance(character, &frames, 0.0, 1.0).margin;
                if margin >= 0.0 {
                    break;
                }
            }
        } else {
            self.correction = wanted;
        }
        Balanced { error, margin }
    }
}
