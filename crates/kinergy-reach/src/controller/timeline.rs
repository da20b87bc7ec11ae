//! The body's controllers over time (Huang, Kapadia & Terzopoulos §4): when the scheduler's
//! states start them ([`Timeline`]) and the body each has brought to a moment ([`Body`]) —
//! the step (state 0), the twist (state 1), the swing, COM shift and squat (state 2).

use kinergy_motion::nalgebra::IsometryMatrix3;

use super::legs::Stepping;
use super::plan::Plan;
use super::settings::ReachSettings;
use super::spine::{apply_swing, set_twist};
use crate::character::{Character, Pose, dof};
use crate::error::Result;
use crate::profile::smoothstep;

/// When the controllers start and how long they take, seconds.
#[derive(Debug, Clone, Copy)]
pub(super) struct Timeline {
    /// The step's end (0 without a step).
    step_total: f64,
    /// State 1: arm, head and twist start.
    pub(super) t_arm: f64,
    /// The twist's duration (0 without a twist).
    twist_time: f64,
    /// State 2: swing, COM adjustment and squat start.
    t_swing: f64,
    /// Their duration (0 without any).
    swing_time: f64,
    /// When the squat starts: with the swing, but not before the last foot has landed (a
    /// squat on one leg would drop the root further to keep the swinging foot reachable).
    t_squat: f64,
}

impl Timeline {
    fn new(plan: &Plan, step_total: f64, landed: f64, s: &ReachSettings) -> Timeline {
        let t_arm = if plan.step.step.steps() {
            s.r_st * step_total
        } else {
            0.0
        };
        let twist_time = if plan.twist != 0.0 { s.twist_time } else { 0.0 };
        let swing_time = if plan.swing != 0.0 || plan.squat != 0.0 {
            s.swing_time
        } else {
            0.0
        };
        let t_swing = t_arm + s.r_tw * twist_time;
        Timeline {
            step_total,
            t_arm,
            twist_time,
            t_swing,
            swing_time,
            t_squat: t_swing.max(landed),
        }
    }

    /// The twist's progress at `t`, eased, in [0, 1].
    fn twist_at(&self, t: f64) -> f64 {
        if self.twist_time > 0.0 {
            smoothstep((t - self.t_arm) / self.twist_time)
        } else {
            1.0
        }
    }

    /// The swing's (and COM shift's and squat's) progress at `t`, eased, in [0, 1].
    fn swing_at(&self, t: f64) -> f64 {
        if self.swing_time > 0.0 {
            smoothstep((t - self.t_swing) / self.swing_time)
        } else {
            1.0
        }
    }

    /// The squat's progress at `t`, eased, in [0, 1].
    fn squat_at(&self, t: f64) -> f64 {
        if self.swing_time > 0.0 {
            smoothstep((t - self.t_squat) / self.swing_time)
        } else {
            1.0
        }
    }

    /// Whether every controller but the arm has finished at `t`.
    pub(super) fn body_done(&self, t: f64) -> bool {
        t >= self.t_squat + self.swing_time
            && t >= self.step_total
            && t >= self.t_arm + self.twist_time
    }

    /// Whether a reach whose hand has stopped short may end as unreachable at `t`: the
    /// nearest point held a quarter second after the swing and the arm's start.
    pub(super) fn held_long_enough(&self, t: f64) -> bool {
        t >= self.t_squat + self.swing_time + 0.25 && t >= self.t_arm + 0.25
    }
}

/// The body's controllers of a planned reach: the step's foot and root paths, and the
/// timeline of the twist, swing, COM shift and squat.
pub(super) struct Body<'a> {
    character: &'a Character,
    plan: &'a Plan,
    stepping: Stepping,
    /// When each starts.
    pub(super) timeline: Timeline,
}

impl<'a> Body<'a> {
    /// The body's controllers of `plan` from `rest`.
    pub(super) fn new(
        character: &'a Character,
        rest: &Pose,
        plan: &'a Plan,
        s: &ReachSettings,
    ) -> Result<Body<'a>> {
        let stepping = Stepping::new(character, rest, &plan.step, plan.arm, s)?;
        let timeline = Timeline::new(plan, stepping.total(), stepping.landed(), s);
        Ok(Body {
            character,
            plan,
            stepping,
            timeline,
        })
    }

    /// State 0, the step: the root on its path at `t`.
    pub(super) fn step(&self, pose: &mut Pose, t: f64) {
        let root_path = self.stepping.root(t);
        pose[dof::ROOT_X] = root_path.x;
        pose[dof::ROOT_Y] = root_path.y;
        pose[dof::ROOT_Z] = root_path.z;
    }

    /// The ankle frames at `t`, `[right, left]`.
    pub(super) fn feet(&self, t: f64) -> [IsometryMatrix3<f64>; 2] {
        self.stepping.feet(t)
    }

    /// State 1, the twist: the spine twisted as far as it has progressed at `t`.
    pub(super) fn twist(&self, pose: &mut Pose, t: f64) {
        set_twist(pose, self.plan.twist * self.timeline.twist_at(t));
    }

    /// State 2, the swing, COM adjustment and squat as far as they have progressed at `t`:
    /// the root shifted and lowered, then the spine swung (about its twisted frames).
    pub(super) fn swing(&self, pose: &mut Pose, t: f64) {
        let (plan, timeline) = (self.plan, &self.timeline);
        let sw = timeline.swing_at(t);
        pose[dof::ROOT_X] += plan.com_shift.x * sw;
        pose[dof::ROOT_Y] -= plan.squat * timeline.squat_at(t);
        pose[dof::ROOT_Z] += plan.com_shift.z * sw;
        if t >= timeline.t_swing && plan.swing != 0.0 {
            apply_swing(self.character, pose, &plan.axis, plan.swing * sw);
        }
    }
}
