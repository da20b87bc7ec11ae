//! A reach at Kallmann's levels ([`crate::level`]): the straight hand line with the IK on every
//! frame, with or without collision avoidance, and the escalation from one level to the next.

use std::time::Instant;

use kinergy_io::{Classify, ErrorKind, InvalidSetting};
use kinergy_solver::analytic::OrbitSearch;
use nalgebra::{Point3, UnitQuaternion};

use super::builder::Builder;
use super::{Manipulation, Phase, Planner};
use crate::error::{PlanError, Result};
use crate::hand::HandShape;
use crate::level::{Level, LevelTry};
use crate::posture::BodyDofs;
use crate::space::{ArmConfig, HandTarget, body_of};

/// The orbit search's first increment along a hand line: small, so a frame's elbow stays
/// near the interpolated one.
const LINE_ORBIT_STEP_DEG: f64 = 2.0;

/// How a hand line is checked.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Line {
    /// The `ik` level: every frame within the joint limits; collisions looked at only when
    /// `checked` (under `auto`).
    Ik {
        /// Frames and the motion between them tested for collisions after the IK.
        checked: bool,
    },
    /// The `straight` level: the orbit search rejects colliding postures; the motion between
    /// frames tested.
    Straight,
}

impl Planner {
    /// A reach to `target` at `level` ([`crate::level`]), the hand taking `shape`: the motion of
    /// the level that solved it, every level tried in [`Manipulation::levels`] (the last is the
    /// one that solved it).
    ///
    /// `auto` goes on to the next level when one's motion is blocked
    /// ([`PlanError::PathBlocked`]); it stops where no level can do better (the goal beyond
    /// reach or colliding at every orbit angle, the start colliding). A task failure is
    /// [`PlanError::Level`], naming the levels tried and why each failed; bad input is
    /// returned as it is.
    ///
    /// The body moves only where the arm alone cannot reach: when the arm's goal in the
    /// reference posture is beyond reach or collides at every orbit angle, the body's goal
    /// posture is searched first — the reach layer's standing stances, with more swing and
    /// twist ([`EXTRA_SWING_DEG`](crate::task::EXTRA_SWING_DEG)) — and every level moves the
    /// spine and the legs with the arm ([`Manipulation::body`] says how); where no stance
    /// helps, the levels fail as the arm alone does, the error saying the body was tried.
    pub fn reach_by(
        &self,
        target: &HandTarget,
        shape: HandShape,
        level: Level,
    ) -> Result<Manipulation> {
        let mut body = None;
        let mut body_note = None;
        if let Err(e @ (PlanError::GoalUnreachable { .. } | PlanError::GoalInCollision { .. })) =
            self.space.solve(target)
        {
            match self.body_goal(target, &e)? {
                Ok(goal) => body = Some(goal),
                Err(note) => body_note = Some(note),
            }
        }
        let order = level.order();
        let mut tried: Vec<LevelTry> = Vec::with_capacity(order.len());
        for (i, &at) in order.iter().enumerate() {
            let checked = at != Level::Ik || level == Level::Auto;
            let clock = Instant::now();
            let builder = match &body {
                Some(g) => self.builder_in(g.space.clone(), Some((g.alpha, g.q))),
                None => self.builder(),
            };
            let attempt = builder.and_then(|mut b| {
                match at {
                    Level::Ik => b.line_reach(target, shape, Line::Ik { checked })?,
                    Level::Straight => b.line_reach(target, shape, Line::Straight)?,
                    Level::Planner | Level::Auto => b.planned_reach(target, shape)?,
                }
                Ok(b.out)
            });
            let seconds = clock.elapsed().as_secs_f64();
            match attempt {
                Ok(mut out) => {
                    tried.push(LevelTry {
                        level: at,
                        seconds,
                        failure: None,
                        motion_checked: checked,
                    });
                    out.levels = tried;
                    out.body = body.map(|g| g.used);
                    return Ok(out);
                }
                Err(e) if e.kind() == ErrorKind::Input => return Err(e),
                Err(e) => {
                    tried.push(LevelTry {
                        level: at,
                        seconds,
                        failure: Some(e.to_string()),
                        motion_checked: checked,
                    });
                    let mendable = matches!(e, PlanError::PathBlocked { .. });
                    if !mendable || i + 1 == order.len() {
                        return Err(PlanError::Level {
                            asked: level,
                            tried,
                            cause: Box::new(with_note(e, body_note.as_deref())),
                        });
                    }
                }
            }
        }
        // `order` is never empty: the loop has returned.
        Err(PlanError::Setting(InvalidSetting::new(
            "level",
            "no level to try",
        )))
    }
}

impl Builder<'_> {
    /// A reach along the straight hand line (the [`crate::level`] docs): the goal posture by
    /// the IK with collision avoidance; the grip point lerped and the hand's rotation slerped
    /// from where they are to the goal posture's, timed by the task's warp; on every frame the
    /// IK, its orbit search starting at the angle interpolated between the start's and the
    /// goal's.
    ///
    /// Where the body moves, its DoFs go from the start's to the goal's ahead of the grip
    /// ([`body_lead`]), and each frame's arm is solved on the body there.
    fn line_reach(&mut self, target: &HandTarget, shape: HandShape, line: Line) -> Result<()> {
        let settings = &self.planner.settings;
        let (alpha_goal, goal) = self.reach_goal(target)?;
        let (b0, b1) = (body_of(&self.q), body_of(&goal));
        let rest = self.rest_rotation();
        let frame_of = |q: &ArmConfig| {
            let f = self.space.grip_frame(q);
            let r = UnitQuaternion::from_rotation_matrix(&(f.rotation * rest.inverse()));
            (Point3::from(f.translation.vector), r)
        };
        let (p0, r0) = frame_of(&self.q);
        let (p1, r1) = frame_of(&goal);
        let search = OrbitSearch::default();
        let alpha0 = self.alpha.clamp(search.min, search.max);
        // Where the body moves, its motion counts too: the farthest-moving tracked point (the
        // head's top, a knee) can travel farther than the grip.
        let mut length = (p1 - p0).norm();
        if self.space.moves_body() {
            length = length.max(self.space.distance(&self.q, &goal));
        }
        let frames = self.frames_for(length, settings.reach_speed);
        let fractions = settings.warp.fractions(frames);
        let n = frames - 1;
        let first = self.out.poses.len() - 1;
        let hand0 = self.hand;
        for (k, &t) in fractions.iter().enumerate().skip(1) {
            let step = HandTarget {
                position: p0 + (p1 - p0) * t,
                orientation: Some(r0.slerp(&r1, t)),
            };
            let orbit = OrbitSearch {
                start: (alpha0 + (alpha_goal - alpha0) * t).clamp(search.min, search.max),
                step: LINE_ORBIT_STEP_DEG.to_radians(),
                ..search
            };
            let blocked = |why: String| PlanError::PathBlocked {
                frame: k,
                frames: n,
                fraction: t,
                why,
            };
            let lead = body_lead(t);
            let body: BodyDofs = std::array::from_fn(|i| b0[i] + (b1[i] - b0[i]) * lead);
            let solved = match line {
                // The last frame is the goal posture itself (free, and the target reached).
                Line::Ik { .. } if k == n => Ok((alpha_goal, goal)),
                Line::Ik { .. } => self.space.solve_at(&step, &body, &orbit, false),
                Line::Straight => self.space.solve_at(&step, &body, &orbit, true),
            };
            let (alpha, q) = solved.map_err(|e| blocked(why_unsolved(e)))?;
            let test = match line {
                Line::Ik { checked } => checked,
                Line::Straight => true,
            };
            if test {
                if let Some(contact) = self.space.contact(&q) {
                    return Err(blocked(contact));
                }
                if let Some(contact) = self.space.edge_contact(&self.q, &q) {
                    return Err(blocked(format!("{contact} (moving from frame {})", k - 1)));
                }
            }
            self.q = q;
            self.alpha = alpha;
            self.hand = hand0.lerp(&shape, k as f64 / n as f64);
            self.push_frame();
        }
        self.out.phases.push(Phase {
            name: "reach".into(),
            frames: first..self.out.poses.len(),
            planned: None,
            synergy: None,
        });
        Ok(())
    }
}

/// Why the IK found no posture on a frame of a hand line, as [`PlanError::PathBlocked`] says it.
fn why_unsolved(e: PlanError) -> String {
    match e {
        PlanError::GoalInCollision { tried, contact } => {
            format!("every orbit angle tried collides ({tried} within limits; first {contact})")
        }
        PlanError::GoalUnreachable { why } => format!("no posture within the joint limits: {why}"),
        other => other.to_string(),
    }
}

/// A failure of the arm alone, with `note` (why moving the body did not help) added to what
/// it says.
fn with_note(e: PlanError, note: Option<&str>) -> PlanError {
    let Some(note) = note else { return e };
    match e {
        PlanError::GoalUnreachable { why } => PlanError::GoalUnreachable {
            why: format!("{why}; {note}"),
        },
        PlanError::GoalInCollision { tried, contact } => PlanError::GoalInCollision {
            tried,
            contact: format!("{contact}; {note}"),
        },
        other => other,
    }
}

/// How far (0 to 1) the body's DoFs have gone from the start's to the goal's when the grip has
/// gone the fraction `t` of its line: `1 − (1 − t)²`, ahead of the grip and arriving with it.
/// The body leads because a hand reaching low needs its shoulder lowered first: the arm
/// hangs almost straight at the start, and at the grip's pace the squat leaves the first
/// frames' hand targets beyond its reach.
pub(super) fn body_lead(t: f64) -> f64 {
    let t = t.clamp(0.0, 1.0);
    1.0 - (1.0 - t) * (1.0 - t)
}
