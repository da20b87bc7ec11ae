//! The synergy arm's brake before the character's limits ([`super::SynergyArm::pose_arm`]).

use crate::character::angle_difference;

/// The shoulder elevation (radians from the hanging arm) above which the synergy arm's twist
/// does not brake before the character's twist limits: where the character's twist range
/// starts to widen ([`crate::character::OVERHEAD_TWIST_FROM`]), toward the arm straight up,
/// where the twist coordinate is singular (it moves by a lot for a small turn of the arm).
/// Braking the twist higher up held a person's overhead style back: Bandai *active*'s vector
/// fitted on takes 1–6 (`--budget 800 --seed 1`) drove `style` on all 8 takes to r 0.66 with
/// 1 hand-over braking below 90°, 0.32 with 2 braking below 150° (0.56 with 1 without the
/// brake). Braked at every elevation, the twist made high reaches chatter (`synth --params
/// tests/data/params/synthetic-p01-r09-sc.json`: 3 of 56 clips with speed jumps, 36 on
/// p02/r05); never braked, 3 of the `reach` grid's 20 person-synergy reaches kept a jump;
/// braked below 90°, 1 clip (as without the brake) and no grid reach.
pub const TWIST_BRAKE_BELOW: f64 = crate::character::OVERHEAD_TWIST_FROM;

/// Moves `q` (the arm the controller steps to, character DoFs) back toward `before` (the last
/// frame's) where a DoF heads for the character's `limits` faster than √(`a`·gap), over frames
/// of `dt` seconds: it stops in the gap at half the joint acceleration `a` (the margin the
/// analytic arm's brake keeps, `controller::arm`), a revolute DoF toward either end of its range, a
/// swing radially toward its ellipse.
pub(super) fn brake_before_limits(
    limits: &[crate::character::DofLimit; 7],
    before: &[f64; 7],
    q: &mut [f64; 7],
    a: f64,
    dt: f64,
) {
    use crate::character::DofLimit;
    let mut i = 0;
    while i < 7 {
        match limits[i] {
            DofLimit::Revolute { min, max } => {
                let v = angle_difference(q[i], before[i]) / dt;
                let up = (a * (max - before[i]).max(0.0)).sqrt();
                let down = (a * (before[i] - min).max(0.0)).sqrt();
                let braked = v.clamp(-down, up);
                if braked != v {
                    q[i] = before[i] + braked * dt;
                }
            }
            DofLimit::Swing { rx, ry } if i + 1 < 7 => {
                let (sx, sy) = (before[i], before[i + 1]);
                let rho = (sx / rx).hypot(sy / ry);
                let norm = sx.hypot(sy);
                if rho > 0.0 && norm > 1e-9 {
                    let (ox, oy) = (sx / norm, sy / norm);
                    let gap = norm * (1.0 / rho - 1.0).max(0.0);
                    let (vx, vy) = ((q[i] - sx) / dt, (q[i + 1] - sy) / dt);
                    let excess = vx * ox + vy * oy - (a * gap).sqrt();
                    if excess > 0.0 {
                        q[i] -= excess * ox * dt;
                        q[i + 1] -= excess * oy * dt;
                    }
                }
                i += 1;
            }
            _ => {}
        }
        i += 1;
    }
}
