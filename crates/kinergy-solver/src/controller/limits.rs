//! How joint limits enter the controller's step ([`super::LimitHandling`]): DoFs locked
//! against the limits the step pushes into, and the clamp after a step.

use kinergy_motion::{Chain, Linearization, Motion};

/// What the limits leave of a DoF for the current frame's step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Lock {
    /// Moves freely.
    Free,
    /// Does not move.
    Blocked,
    /// On the first DoF of a swing on its ellipse: the swing moves only along the unit
    /// tangent (t0, t1); the second DoF's entry is [`Lock::Tied`].
    Slide(f64, f64),
    /// The second DoF of a sliding swing.
    Tied,
}

/// Locks the DoFs that `step` pushes out of their limits, and rewrites the Jacobian
/// columns to match (removed columns are zeroed; a sliding swing's two columns become its
/// tangent column and a zero column). Returns whether any lock was added.
pub(super) fn lock_limits(
    chain: &Chain,
    q: &[f64],
    step: &[f64],
    locks: &mut [Lock],
    lin: &mut Linearization,
) -> bool {
    const ON_LIMIT: f64 = 1e-9;
    let mut changed = false;
    let block = |k: usize, locks: &mut [Lock], lin: &mut Linearization| {
        locks[k] = Lock::Blocked;
        lin.linear.column_mut(k).fill(0.0);
        lin.angular.column_mut(k).fill(0.0);
    };
    let mut k = 0;
    for m in chain.joints().iter().flat_map(|j| &j.motions) {
        match *m {
            Motion::Revolute { min, max, .. } => {
                if locks[k] == Lock::Free
                    && ((q[k] <= min + ON_LIMIT && step[k] < 0.0)
                        || (q[k] >= max - ON_LIMIT && step[k] > 0.0))
                {
                    block(k, locks, lin);
                    changed = true;
                }
            }
            Motion::Swing { rx, ry } => {
                let e = (q[k] / rx).powi(2) + (q[k + 1] / ry).powi(2);
                // The ellipse's outward normal at q (the gradient of e / 2).
                let (n0, n1) = (q[k] / (rx * rx), q[k + 1] / (ry * ry));
                let outward = n0 * step[k] + n1 * step[k + 1];
                let scale = (n0.abs() + n1.abs()) * (step[k].abs() + step[k + 1].abs());
                if e >= 1.0 - ON_LIMIT && outward > 1e-12 * scale {
                    match locks[k] {
                        Lock::Free => {
                            let norm = n0.hypot(n1);
                            let (t0, t1) = (-n1 / norm, n0 / norm);
                            for jac in [&mut lin.linear, &mut lin.angular] {
                                for r in 0..jac.nrows() {
                                    jac[(r, k)] = jac[(r, k)] * t0 + jac[(r, k + 1)] * t1;
                                    jac[(r, k + 1)] = 0.0;
                                }
                            }
                            locks[k] = Lock::Slide(t0, t1);
                            locks[k + 1] = Lock::Tied;
                            changed = true;
                        }
                        Lock::Slide(..) => {
                            block(k, locks, lin);
                            block(k + 1, locks, lin);
                            changed = true;
                        }
                        Lock::Blocked | Lock::Tied => {}
                    }
                }
            }
        }
        k += m.dof_count();
    }
    changed
}

/// [`Chain::clamp`] after a step, without moving a DoF the step left alone: a swing pushed out
/// of its ellipse by one DoF while the other's step is zero (frozen by a zero synergy gain,
/// or deactivated) is brought back along the moving DoF's axis instead of being scaled
/// toward zero, which would move the frozen one too.
pub(super) fn clamp_moved(chain: &Chain, q: &mut [f64], step: &[f64]) {
    let mut k = 0;
    for m in chain.joints().iter().flat_map(|j| &j.motions) {
        match *m {
            Motion::Revolute { min, max, .. } => q[k] = q[k].clamp(min, max),
            Motion::Swing { rx, ry } => {
                let (a, b) = (q[k] / rx, q[k + 1] / ry);
                let e = a * a + b * b;
                // A swing neither of whose DoFs moved stays put (it was within its limits,
                // up to the rounding of the previous frame's clamp).
                if e > 1.0 && (step[k] != 0.0 || step[k + 1] != 0.0) {
                    if step[k] == 0.0 {
                        q[k + 1] = ry * (1.0 - a * a).max(0.0).sqrt().copysign(q[k + 1]);
                    } else if step[k + 1] == 0.0 {
                        q[k] = rx * (1.0 - b * b).max(0.0).sqrt().copysign(q[k]);
                    } else {
                        let s = 1.0 / e.sqrt();
                        q[k] *= s;
                        q[k + 1] *= s;
                    }
                }
            }
        }
        k += m.dof_count();
    }
}
