//! Kallmann's three levels of a reach, and the escalation between them (`plan --level`).
//!
//! Kallmann (2005, "Scalable Specification of Manipulations") offers three ways of computing
//! an arm's motion to a hand target, each slower and able to meet harder constraints:
//!
//! | level | the motion | collisions checked | the paper's time (3 GHz, 2005) |
//! |---|---|---|---|
//! | [`Level::Ik`] | the hand target interpolated along a straight line, IK on every frame | **the goal posture only** | < 1 ms |
//! | [`Level::Straight`] | the same straight hand line, IK *with collision avoidance* on every frame | every frame and the motion between frames | 1–30 ms |
//! | [`Level::Planner`] | RRT-Connect from the current posture to the goal posture, smoothed | every node and edge | 20 ms – 2 s |
//!
//! - **IK** (`ik`): the goal posture is the IK with collision avoidance (the orbit-angle
//!   search accepting the first posture within the joint limits that collides with nothing),
//!   so the hand ends in a free posture. The way there is the paper's IK-based motion: the
//!   grip point moves on the straight line from where it is to the target (lerp, the hand's
//!   rotation by slerp to the goal posture's), timed by the bell, and the IK places the arm on
//!   every frame with the orbit angle interpolated from the start's to the goal's (the nearest
//!   angle within the joint limits when that one is not). **The interpolated motion is not
//!   checked for collisions**: forced with `--level ik` it may pass through an obstacle, as
//!   the paper's time-critical level does; the report says `motion_checked: false`.
//! - **Straight** (`straight`): the same hand line, but on every frame the orbit-angle search
//!   (from the interpolated angle, 2° steps) rejects colliding postures — Kallmann's "IK
//!   collision avoidance only corrects the elbow position during a straight line hand
//!   trajectory" — and the interpolation between consecutive frames is checked at the space's
//!   resolution. It fails where no orbit angle frees a frame (the hand itself would touch) or
//!   a frame-to-frame motion collides.
//! - **Planner** (`planner`): RRT-Connect and smoothing as [`crate::rrt`] describes, the
//!   person's synergy finishing the reach where its motion is free ([`crate::approach`]).
//! - **Auto** (`auto`, the default): IK, then straight, then the planner; a level is accepted
//!   only when its whole motion is collision-free, so under `auto` the IK level's motion *is*
//!   checked after it is made (every frame and between frames), and its first contact is why
//!   `auto` goes on. A failure no level can mend — the goal beyond reach or in collision at
//!   every orbit angle, the start in collision — stops the escalation at once.
//!
//! The levels choose how a *reach* (`plan --target`) moves; a task (grasp, relocate, pull,
//! push) is Kallmann's sequence of planned and straight phases and is planned as before
//! (`auto` or `planner` only).
//!
//! # The body
//! Every level moves the arm alone where it can: the goal is first solved with the body in
//! its reference posture. Where that goal is beyond reach or collides at every orbit angle,
//! the body's goal posture is searched before any level runs (Kallmann's "spine motion and
//! leg flexion" before the IK, [`crate::posture`]), and each level moves the body too: `ik`
//! and `straight` solve every frame's arm on the body part of the way to its goal posture
//! (ahead of the grip, so the shoulder comes down first), and `planner` searches the arm's and
//! the body's DoFs together, the body sampled in a small band ([`crate::rrt::Sampler`]). Every
//! check then tests the whole body. The report's `body_dofs` names the body DoFs that moved.

use std::fmt;
use std::str::FromStr;

use kinergy_io::InvalidSetting;

/// How a reach is computed ([module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Level {
    /// IK along a straight hand line; only the goal posture is checked for collisions.
    Ik,
    /// IK with collision avoidance along a straight hand line; every frame checked.
    Straight,
    /// RRT-Connect and smoothing.
    Planner,
    /// IK, then straight, then the planner, until one gives a collision-free motion.
    #[default]
    Auto,
}

impl Level {
    /// Every level, in the order the front ends list them.
    pub const ALL: [Level; 4] = [Level::Ik, Level::Straight, Level::Planner, Level::Auto];

    /// `ik`, `straight`, `planner` or `auto`.
    pub fn name(self) -> &'static str {
        match self {
            Level::Ik => "ik",
            Level::Straight => "straight",
            Level::Planner => "planner",
            Level::Auto => "auto",
        }
    }

    /// The levels tried, in order: the level itself, or for [`Level::Auto`] the three.
    pub fn order(self) -> &'static [Level] {
        match self {
            Level::Ik => &[Level::Ik],
            Level::Straight => &[Level::Straight],
            Level::Planner => &[Level::Planner],
            Level::Auto => &[Level::Ik, Level::Straight, Level::Planner],
        }
    }
}

impl fmt::Display for Level {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Level {
    type Err = InvalidSetting;
    fn from_str(s: &str) -> Result<Level, InvalidSetting> {
        Level::ALL
            .into_iter()
            .find(|l| l.name() == s)
            .ok_or_else(|| {
                InvalidSetting::new(
                    "level",
                    format!("`{s}`: expected ik, straight, planner or auto"),
                )
            })
    }
}

/// One level tried for a reach: how it went and how long it took.
#[derive(Debug, Clone, PartialEq)]
pub struct LevelTry {
    /// The level.
    pub level: Level,
    /// Its wall time, seconds: the goal posture's IK, the motion and its checks.
    pub seconds: f64,
    /// Why it failed (`None`: it solved the reach).
    pub failure: Option<String>,
    /// Whether its motion was checked for collisions between the start and the goal (false
    /// only for a forced [`Level::Ik`]).
    pub motion_checked: bool,
}

impl LevelTry {
    /// True when the level solved the reach.
    pub fn solved(&self) -> bool {
        self.failure.is_none()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn levels_read_back_by_name_and_auto_escalates_in_the_papers_order() {
        for l in Level::ALL {
            assert_eq!(l.name().parse::<Level>(), Ok(l));
            assert_eq!(l.to_string(), l.name());
        }
        let e = "rrt".parse::<Level>().unwrap_err();
        assert_eq!(e.field, "level");
        assert!(e.why.contains("ik, straight, planner or auto"), "{}", e.why);
        assert_eq!(
            Level::Auto.order(),
            [Level::Ik, Level::Straight, Level::Planner]
        );
        assert_eq!(Level::Straight.order(), [Level::Straight]);
        assert_eq!(Level::default(), Level::Auto);
    }
}
