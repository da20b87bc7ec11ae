//! Balance (beyond the paper): the centre of mass's ground projection kept inside the support
//! polygon by shifting the root horizontally toward the polygon's centroid ([`rebalance`]).
//! Planning shifts the final posture until it keeps the COM 2 cm further in than required
//! ([`plan_com_shift`]); every animated frame is corrected again, the limbs solved anew after
//! each shift.

use kinergy_motion::nalgebra::{IsometryMatrix3, Point2, Point3, Vector2, Vector3};
use kinergy_solver::analytic::{LimbIk, OrbitSearch};

use super::arm::solve_arm;
use super::legs::{leg_iks, lower_root_for_legs, solve_legs};
use crate::character::{Character, Limb, Pose, dof};
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
/// ankles at `feet` (where the step leaves them) and the `arm` solved for `target`.
#[allow(clippy::too_many_arguments)]
pub(super) fn plan_com_shift(
    character: &Character,
    posture: &Pose,
    feet: &[IsometryMatrix3<f64>; 2],
    arm: Limb,
    arm_ik: &LimbIk,
    target: &Point3<f64>,
    start: Vector3<f64>,
    wanted: f64,
) -> Result<Vector3<f64>> {
    let legs = leg_iks(character)?;
    let mut com_shift = start;
    for _ in 0..40 {
        let mut q = *posture;
        q[dof::ROOT_X] += com_shift.x;
        q[dof::ROOT_Z] += com_shift.z;
        lower_root_for_legs(character, &mut q, feet);
        solve_legs(character, &mut q, &legs, feet);
        let base = character.limb_base_frame(arm, &q);
        if let Some(a) = solve_arm(arm_ik, &base, target, &OrbitSearch::default()) {
            q[character.limb_dofs(arm)].copy_from_slice(&a);
        }
        match rebalance(character, &character.world_frames(&q), wanted, 0.5).shift {
            None => break,
            Some(shift) => com_shift += Vector3::new(shift.x, 0.0, shift.y),
        }
    }
    Ok(com_shift)
}
