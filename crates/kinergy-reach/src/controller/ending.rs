//! How a reach ended, for people: reached, beyond reach, or still moving when time ran out.

use crate::character::Character;

use super::report::{ReachMotion, ReachStop};

/// How a full-body reach ended ([`Ending::of`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Ending {
    /// The hand arrived.
    Reached,
    /// The hand came to rest this many meters short of the target: it is beyond reach.
    Beyond(f64),
    /// The timeout came while the hand still moved toward the target.
    StillMoving,
}

impl Ending {
    /// A reach that was not reached is beyond reach when its hand came to rest short of the
    /// target, or when the timeout found it creeping so slowly that it could not close the gap:
    /// over its last second it moved less than a tenth of the distance left (a far target's
    /// ease-out keeps the stretched hand inching on for seconds).
    pub fn of(character: &Character, motion: &ReachMotion) -> Ending {
        let r = &motion.report;
        if r.stop == ReachStop::Reached {
            return Ending::Reached;
        }
        let wrist = r.arm.joints()[3];
        let last = motion.poses.len();
        let window = ((1.0 / motion.frame_time).ceil() as usize).max(1);
        let settled = last > window && {
            let hand = |k: usize| character.world_positions(&motion.poses[k])[wrist];
            (hand(last - 1) - hand(last - 1 - window)).norm() < 0.1 * r.final_error
        };
        if r.stop == ReachStop::Unreachable || settled {
            Ending::Beyond(r.final_error)
        } else {
            Ending::StillMoving
        }
    }
}
