//! The body's goal posture for a reach the arm alone cannot make (Kallmann 2005, "Spine
//! Motion and Leg Flexion": "if h is too low and not reachable, leg flexion might turn h into
//! a reachable location"; the spine rotated toward the target), found before the arm's IK.
//!
//! A reach first asks the arm alone, the body in its reference posture. Only when that goal
//! is beyond reach or collides at every orbit angle does the body move
//! ([`Planner::body_goal`]; the search's order is [`BodyUse`]'s docs').

use std::time::Instant;

use kinergy_motion::Side;
use kinergy_reach::character::{Character, Pose};
use kinergy_reach::controller::{ReachSettings, Stance, StanceCandidate, standing_stances};
use kinergy_solver::analytic::OrbitSearch;
use nalgebra::Point2;

use super::Planner;
use crate::error::{PlanError, Result};
use crate::posture::{BodyDofs, BodyMotion, used_dofs};
use crate::space::{ArmConfig, ArmSpace, HandTarget};

/// The twists tried beyond each stance's own, degrees, in order (turning the acting side's
/// shoulder forward).
pub const EXTRA_TWIST_DEG: [f64; 4] = [0.0, 10.0, 20.0, 30.0];

/// The swings tried beyond each stance's own, degrees, in order (toward the target): every
/// 3° to 30°.
pub const EXTRA_SWING_DEG: [f64; 11] =
    [0.0, 3.0, 6.0, 9.0, 12.0, 15.0, 18.0, 21.0, 24.0, 27.0, 30.0];

/// How a reach moved the body: its goal posture and why.
///
/// The goal posture is searched only where the arm alone fails (Kallmann 2005, "Spine
/// Motion and Leg Flexion", before the arm's IK): the stances the reach layer's posture
/// search tries with the feet where they stand
/// ([`standing_stances`](kinergy_reach::controller::standing_stances): its twist, the squat
/// its leg flexibility asks for, the swing raised until the hand reaches, then squats 2 cm
/// deeper each), each with the trunk turned [`EXTRA_TWIST_DEG`] further (bringing the acting
/// shoulder forward) and the swing raised [`EXTRA_SWING_DEG`] further (the reach's hand is
/// its fingertip, the planner's its grip point, nearer the wrist; and a deeper bend or a turn
/// can clear an obstacle). The first stance whose feet stay planted, whose body but the arm
/// touches nothing, from which the arm's IK with collision avoidance finds a posture and
/// whose centre of mass stays over the feet is the goal.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyUse {
    /// The goal posture's body DoFs: the spine's swing and twist (radians), the squat
    /// (meters) ([`crate::posture::body_dof`]).
    pub goal: BodyDofs,
    /// The names of the body DoFs the motion moves (those not zero at the goal).
    pub dofs: Vec<&'static str>,
    /// The goal's stance, with the swing's axis and d_p the motion moves about
    /// ([`Planner::body_space`]).
    pub stance: Stance,
    /// Why the arm alone could not reach: its goal's failure.
    pub arm_alone: String,
    /// Stances tried, the one taken included.
    pub tried: usize,
    /// The search's wall time, seconds.
    pub seconds: f64,
}

/// A reach's goal with the body moving: the space it moves in, the goal's orbit angle and
/// configuration, and how it was found.
#[derive(Debug, Clone)]
pub(super) struct BodyGoal {
    pub(super) space: ArmSpace,
    pub(super) alpha: f64,
    pub(super) q: ArmConfig,
    pub(super) used: BodyUse,
}

/// The reach settings the body's stances are searched and posed under: the acting arm's,
/// the rest the reach's defaults.
fn stance_settings(planner: &Planner) -> ReachSettings {
    ReachSettings {
        arm: Some(planner.settings.limb.side()),
        ..ReachSettings::default()
    }
}

impl Planner {
    /// The space a reach's body moved in ([`crate::task::Manipulation::body`]): the arm's
    /// space at the start, the body moving toward `body`'s goal stance.
    pub fn body_space(&self, body: &BodyUse) -> Result<ArmSpace> {
        let motion = BodyMotion::new(
            &self.character,
            &self.start,
            &body.stance,
            &stance_settings(self),
        )?;
        self.space()?.with_body(motion)
    }

    /// The goal posture of a reach to `target` with the body moving ([module docs](self)),
    /// after the arm alone failed with `arm_alone`: `Ok(Err(why))` when no stance gives one,
    /// `why` saying how many were tried and what stopped the first.
    pub(super) fn body_goal(
        &self,
        target: &HandTarget,
        arm_alone: &PlanError,
    ) -> Result<std::result::Result<BodyGoal, String>> {
        let clock = Instant::now();
        let settings = stance_settings(self);
        let candidates =
            standing_stances(&self.character, &self.start, &target.position, &settings)?;
        let mut tried = 0;
        let mut first: Option<String> = None;
        // Turning the trunk toward the acting side brings its shoulder forward.
        let forward = match self.settings.limb.side() {
            Side::Right => 1.0,
            Side::Left => -1.0,
        };
        for StanceCandidate { stance, .. } in candidates {
            // Toward the target the swing about s = d × y is negative ([`crate::posture`]).
            let toward = if stance.swing != 0.0 {
                stance.swing.signum()
            } else {
                -1.0
            };
            for turn in EXTRA_TWIST_DEG {
                for extra in EXTRA_SWING_DEG {
                    let mut s = stance;
                    s.twist += forward * turn.to_radians();
                    s.swing += toward * extra.to_radians();
                    if s.is_upright() {
                        continue;
                    }
                    let b: BodyDofs = [s.swing, s.twist, s.squat];
                    let motion = BodyMotion::new(&self.character, &self.start, &s, &settings)?;
                    if !motion.within_limits(&b) {
                        continue;
                    }
                    tried += 1;
                    let space = self.space.clone().with_body(motion)?;
                    let why = match space.solve_at(target, &b, &OrbitSearch::default(), true) {
                        Ok((alpha, q)) => {
                            let pose = space.pose_with(&self.start, &q);
                            match balance(&self.character, &pose) {
                                None => {
                                    return Ok(Ok(BodyGoal {
                                        space,
                                        alpha,
                                        q,
                                        used: BodyUse {
                                            goal: b,
                                            dofs: used_dofs(&b),
                                            stance: s,
                                            arm_alone: arm_alone.to_string(),
                                            tried,
                                            seconds: clock.elapsed().as_secs_f64(),
                                        },
                                    }));
                                }
                                Some(why) => why,
                            }
                        }
                        Err(e) => e.to_string(),
                    };
                    first.get_or_insert_with(|| {
                        format!(
                            "swing {:.0}°, twist {:.0}°, squat {:.2} m: {why}",
                            s.swing.to_degrees(),
                            s.twist.to_degrees(),
                            s.squat
                        )
                    });
                }
            }
        }
        Ok(Err(format!(
            "moving the body did not help ({tried} stances of the spine and legs tried{})",
            first
                .map(|f| format!("; the first, {f}"))
                .unwrap_or_default()
        )))
    }
}

/// Why the centre of mass of `pose` is not over its feet (inside their support polygon, as
/// the reach holds it on every frame), if it is not.
fn balance(character: &Character, pose: &Pose) -> Option<String> {
    let com = character.com(pose);
    let inside = character
        .support_polygon(pose)
        .margin(Point2::new(com.x, com.z));
    (inside < 0.0).then(|| {
        format!(
            "the centre of mass is {:.0} mm outside the feet's support",
            -inside * 1e3
        )
    })
}
