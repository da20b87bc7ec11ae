//! The reaching arm's phases: who drives the arm on a frame, and the hand-over between them
//! (module [`super`], "Arm driven by a person's synergy").
//!
//! - [`ArmPhase::Waiting`]: before state 1 the arm hangs as the body carries it;
//! - [`Analytic`]: the speed profile along the straight line to the target, the arm solved
//!   by analytic IK (Huang et al.) — the whole reach with [`ArmDrive::Profile`], or, after
//!   plain IK gave up, a minimum-jerk path from where the hand is then;
//! - [`Synergy`]: a person's synergy controller, from state 1 on with
//!   [`ArmDrive::Synergy`] (the smooth controller, bounded by the reach's profile);
//!   stalled once the body has stopped, slower than its
//!   [time budget](SynergyArm::time_budget) or not finite, it hands over to
//! - [`PlainIk`]: damped least squares from the posture the synergy left; stalled, not
//!   finite or slower than [`PLAIN_IK_TIME`], it gives up to the analytic IK.
//!
//! A frame's phase poses the arm at the frame's start ([`ArmPhase::begin`]), gives the arm's
//! path to the limbs' solver ([`ArmPhase::follow`]) and holds the analytic arm to its speed
//! ([`ArmPhase::hold`]); at the frame's end each phase's `step` returns the next phase (or
//! itself) and whether the hand is done.

use kinergy_motion::nalgebra::{IsometryMatrix3, Point3};
use kinergy_solver::{ControllerKind, Optimizer};

use super::SynergyStart;
use super::arm::{ArmFollower, ProfileTime};
use super::plan::Plan;
use super::report::{HandOver, HandOverWhy, SynergyTempo};
use super::settings::ReachSettings;
use super::synergy::{
    ArmDrive, PLAIN_IK_TIME, PersonController, STALL_PROGRESS, STALL_WINDOW, SynergyArm,
    reach_smoothing,
};
use super::timeline::Timeline;
use crate::character::{Character, Pose};
use crate::error::Result;
use crate::profile::{BellTiming, SpeedProfile};

/// The hand's mean speed when the analytic IK finishes a reach the synergy arm and plain IK
/// could not, m/s.
const FINAL_APPROACH_SPEED: f64 = 0.3;

/// What every phase of one reach reads.
pub(super) struct ArmRules<'a> {
    character: &'a Character,
    rest: &'a Pose,
    plan: &'a Plan,
    drive: &'a ArmDrive,
    timeline: Timeline,
    /// The reach's speed profile.
    profile: SpeedProfile,
    /// The analytic IK's path after plain IK gave up.
    approach: SpeedProfile,
    dt: f64,
    tolerance: f64,
    /// The synergy arm's controller when the settings choose one (`None`: the person's own).
    controller: Option<ControllerKind>,
    /// The synergy arm has arrived within half the tolerance (it approaches its target
    /// asymptotically: stopping at the tolerance would stop it still moving).
    arrived: f64,
    /// The least progress over the stall window that is not a stall, meters.
    min_progress: f64,
    /// [`STALL_WINDOW`] in frames.
    stall_window: usize,
    /// Where and how fast the synergy arm starts ([`ReachSettings::synergy_start`]).
    start: Option<SynergyStart>,
}

impl<'a> ArmRules<'a> {
    /// The rules of a reach of `plan` driven by `drive`, at `dt` seconds per frame.
    pub(super) fn new(
        character: &'a Character,
        rest: &'a Pose,
        plan: &'a Plan,
        s: &ReachSettings,
        drive: &'a ArmDrive,
        timeline: Timeline,
        dt: f64,
    ) -> Result<ArmRules<'a>> {
        let approach = SpeedProfile::minimum_jerk(BellTiming::MeanSpeed {
            speed: FINAL_APPROACH_SPEED,
        })?;
        let arrived = 0.5 * s.tolerance;
        Ok(ArmRules {
            character,
            rest,
            plan,
            drive,
            timeline,
            profile: s.profile,
            approach,
            dt,
            tolerance: s.tolerance,
            controller: s.synergy_controller,
            arrived,
            // A tight tolerance (a synthetic set's) is approached with progress below
            // STALL_PROGRESS well before arrival: the least progress is then a tenth of the
            // arrival distance.
            min_progress: STALL_PROGRESS.min(0.1 * arrived),
            stall_window: ((STALL_WINDOW / dt).ceil() as usize).max(1),
            start: s.synergy_start,
        })
    }

    fn target(&self) -> Point3<f64> {
        self.plan.target
    }
}

/// A phase's frame end: the phase of the next frame, the hand's distance from the target
/// and whether the hand is done.
pub(super) struct Stepped {
    /// The next frame's phase.
    pub(super) phase: ArmPhase,
    /// The reaching hand's distance from the target, meters.
    pub(super) error: f64,
    /// Whether the arm's driver has finished (the reach may end once the body has too).
    pub(super) hand_done: bool,
    /// Whether the person's synergy arm was held off its own step on this frame
    /// ([`SynergyArm::limited`]).
    pub(super) limited: bool,
}

/// Who drives the reaching arm (module docs).
pub(super) enum ArmPhase {
    /// Before state 1: the arm hangs, held as the analytic arm is before its clock starts.
    Waiting,
    /// The speed profile and the analytic IK.
    Analytic(Analytic),
    /// A person's synergy controller.
    Synergy(Synergy),
    /// Plain inverse kinematics after a hand-over.
    PlainIk(PlainIk),
}

impl ArmPhase {
    /// The frame's start at `t`, its body (and head) posed in `pose`: state 1 starts the
    /// drive's phase, and the person's arm (synergy or plain IK) is put into `pose`.
    pub(super) fn begin(self, rules: &ArmRules<'_>, t: f64, pose: &mut Pose) -> Result<ArmPhase> {
        let mut phase = match self {
            ArmPhase::Waiting if t >= rules.timeline.t_arm => match rules.drive {
                ArmDrive::Profile => ArmPhase::Analytic(Analytic::from_state_1(rules)),
                ArmDrive::Synergy {
                    optimizer,
                    synergy,
                    tempo,
                    controller,
                } => {
                    let smooth = rules.controller.or(*controller).unwrap_or_default()
                        == ControllerKind::Smooth;
                    ArmPhase::Synergy(Synergy::start(
                        rules, optimizer, synergy, *tempo, smooth, pose,
                    )?)
                }
            },
            phase => phase,
        };
        match &mut phase {
            ArmPhase::Synergy(Synergy { arm, .. }) | ArmPhase::PlainIk(PlainIk { arm, .. }) => {
                arm.pose_arm(rules.character, rules.plan.arm, pose);
            }
            ArmPhase::Waiting | ArmPhase::Analytic(_) => {}
        }
        Ok(phase)
    }

    /// The profile and the seconds into it at `t`, when the analytic IK follows it.
    pub(super) fn follow(&self, rules: &ArmRules<'_>, t: f64) -> Option<ProfileTime<'_>> {
        match self {
            ArmPhase::Analytic(a) if t >= a.from && t >= rules.timeline.t_arm => {
                Some(ProfileTime {
                    profile: &a.profile,
                    elapsed: t - a.from,
                })
            }
            _ => None,
        }
    }

    /// Holds the analytic arm (or the waiting one) to its speed after the frame's balance,
    /// its orbit angle `alpha` when it was solved; returns the hand's distance from the
    /// target when the arm was held back. The person's arm is not held.
    ///
    /// `base` is the reaching arm's base frame for the arm `pose` has before it is held.
    pub(super) fn hold(
        &self,
        rules: &ArmRules<'_>,
        arm: &mut ArmFollower,
        pose: &mut Pose,
        alpha: Option<f64>,
        base: &IsometryMatrix3<f64>,
    ) -> Option<f64> {
        match self {
            ArmPhase::Waiting => {
                Analytic::from_state_1(rules).hold(rules, arm, pose, alpha, base, false)
            }
            ArmPhase::Analytic(a) => a.hold(rules, arm, pose, alpha, base, true),
            ArmPhase::Synergy(_) | ArmPhase::PlainIk(_) => None,
        }
    }

    /// The frame's end at `t`, its final posture `pose` (within the limits) and the hand
    /// `error` meters from the target: each phase steps.
    pub(super) fn step(
        self,
        rules: &ArmRules<'_>,
        arm: &mut ArmFollower,
        pose: &Pose,
        t: f64,
        error: f64,
    ) -> Result<Stepped> {
        match self {
            ArmPhase::Waiting => {
                let hand_done = Analytic::from_state_1(rules).hand_done(arm);
                Ok(Stepped {
                    phase: ArmPhase::Waiting,
                    error,
                    hand_done,
                    limited: false,
                })
            }
            ArmPhase::Analytic(a) => Ok(a.step(arm, error)),
            ArmPhase::Synergy(s) => s.step(rules, pose, t, error),
            ArmPhase::PlainIk(p) => p.step(rules, arm, pose, t, error),
        }
    }

    /// The tempo the synergy's smooth controller is bounded by, while the synergy drives.
    pub(super) fn synergy_tempo(&self) -> Option<SynergyTempo> {
        match self {
            ArmPhase::Synergy(s) => s.tempo,
            _ => None,
        }
    }

    /// When plain IK took the hand over from the synergy, if it did.
    pub(super) fn hand_over(&self) -> Option<HandOver> {
        match self {
            ArmPhase::Waiting | ArmPhase::Synergy(_) => None,
            ArmPhase::Analytic(a) => a.hand_over,
            ArmPhase::PlainIk(p) => Some(p.hand_over),
        }
    }
}

/// The analytic IK on a speed profile, its clock started at `from`.
pub(super) struct Analytic {
    from: f64,
    profile: SpeedProfile,
    /// The hand-over before it, when plain IK gave up to it.
    hand_over: Option<HandOver>,
}

impl Analytic {
    /// The reach's own profile from state 1.
    fn from_state_1(rules: &ArmRules<'_>) -> Analytic {
        Analytic {
            from: rules.timeline.t_arm,
            profile: rules.profile,
            hand_over: None,
        }
    }

    /// [`ArmPhase::hold`]; `reaching` while the profile drives the arm (the hand held to its
    /// world-frame path), not while it hangs before its reach.
    fn hold(
        &self,
        rules: &ArmRules<'_>,
        arm: &mut ArmFollower,
        pose: &mut Pose,
        alpha: Option<f64>,
        base: &IsometryMatrix3<f64>,
        reaching: bool,
    ) -> Option<f64> {
        let c = rules.character;
        let limb = rules.plan.arm;
        let start = c.limb_dofs(limb).start;
        let before: [f64; 7] = std::array::from_fn(|i| pose[start + i]);
        let held = arm.end_frame(c, pose, alpha, rules.dt, reaching.then_some(base));
        if !held {
            return None;
        }
        // Only the arm moved: its base moves with the girdle alone (no body FK).
        let after: [f64; 7] = std::array::from_fn(|i| pose[start + i]);
        let moved = c.arm_base_moved(limb, base, &before, &after);
        let target = rules.target();
        Some((arm.hand(c, &moved, pose, target) - target).norm())
    }

    /// Whether the profile's clock has run its course and the arm has caught up with it.
    fn hand_done(&self, arm: &ArmFollower) -> bool {
        arm.profile_finished(&self.profile) && arm.caught_up()
    }

    /// Stays: the analytic IK finishes the reach.
    fn step(self, arm: &ArmFollower, error: f64) -> Stepped {
        let hand_done = self.hand_done(arm);
        Stepped {
            phase: ArmPhase::Analytic(self),
            error,
            hand_done,
            limited: false,
        }
    }
}

/// A person's synergy controller drives the arm.
pub(super) struct Synergy {
    arm: SynergyArm,
    /// The tempo the smooth controller's bounds were made for (`None`: the paper's
    /// controller, or bounds given by the reach's start).
    tempo: Option<SynergyTempo>,
}

/// The least peak hand speed the synergy arm's bounds assume, m/s: a typical person's
/// reaching speed (the shared raises peak at 0.8–5 m/s, the synthetic set's reaches at
/// 0.5–1.5 m/s).
pub const SYNERGY_PEAK_SPEED: f64 = 1.0;

impl Synergy {
    /// The person's controller (their `optimizer` and `person`al synergy), started on the
    /// frame `pose` of state 1.
    fn start(
        rules: &ArmRules<'_>,
        optimizer: &Optimizer,
        person: &kinergy_solver::Synergy,
        tempo: Option<kinergy_solver::PersonTempo>,
        smooth: bool,
        pose: &Pose,
    ) -> Result<Synergy> {
        let plan = rules.plan;
        // The smooth controller bounded as the person's own reach over the hand's distance
        // (their tempo: peak speed and duration from their fitted reaches); without a tempo,
        // a reach peaking at the profile's speed, or at a typical person's reaching speed
        // where the profile is slower (the paper's ease-out default: 0.2 m/s), with the
        // minimum-jerk duration at that peak, 1.875 d / V. Bounds from a slower reach than the
        // person's made their synergy overshoot and miss, or crawl: Bandai's *active* raises
        // (4–5 m/s captured) ran at 1.3 m/s under the 1 m/s bounds and handed over on 2 of 4
        // takes.
        let hand = rules.character.joint_frame(plan.arm.joints()[3], pose);
        let distance = (Point3::from(hand.translation.vector) - plan.target).norm();
        let least = rules.profile.peak_speed(distance).max(SYNERGY_PEAK_SPEED);
        let segments = rules.character.proportions().arm(plan.arm.side());
        let arm_m = segments.upper_arm + segments.forearm;
        let (peak, duration) = match tempo.map(|t| t.for_reach_by(distance, arm_m)) {
            Some((peak, duration)) if peak > least && duration > 0.0 => (peak, duration),
            _ => (least, 1.875 * distance / least),
        };
        let given = rules.start.and_then(|s| s.smoothing);
        let smoothing =
            given.unwrap_or_else(|| reach_smoothing(rules.character, plan.arm, peak, duration));
        let tempo = (smooth && given.is_none()).then_some(SynergyTempo {
            peak_speed_m_s: peak,
            duration_s: duration,
        });
        let arm = SynergyArm::new(
            rules.character,
            plan.arm,
            rules.rest,
            pose,
            plan.target,
            PersonController {
                optimizer,
                synergy: person,
                frame_time: rules.dt,
                smoothing: smooth.then_some(smoothing),
            },
            rules.start.as_ref(),
        )?;
        Ok(Synergy { arm, tempo })
    }

    /// The controller sees the frame's final body and arm and steps; it hands over to plain
    /// IK when its step is not finite, its progress stalled once the body has stopped, or it
    /// drove longer than its [time budget](SynergyArm::time_budget) short of the target.
    fn step(mut self, rules: &ArmRules<'_>, pose: &Pose, t: f64, error: f64) -> Result<Stepped> {
        let (seen, error, stalled) = observe(&mut self.arm, rules, pose, t, error)?;
        let limited = self.arm.limited();
        let why = if seen.is_none() {
            Some(HandOverWhy::NotFinite)
        } else if stalled {
            Some(HandOverWhy::Stalled)
        } else if error > rules.arrived && t - rules.timeline.t_arm >= self.arm.time_budget() {
            Some(HandOverWhy::TooLong)
        } else {
            None
        };
        let Some(why) = why else {
            return Ok(Stepped {
                phase: ArmPhase::Synergy(self),
                error,
                hand_done: error <= rules.arrived,
                limited,
            });
        };
        let hand_over = HandOver {
            at_s: t + rules.dt,
            distance_m: error,
            why,
            analytic_at_s: None,
        };
        self.arm.hand_over(rules.dt)?;
        Ok(Stepped {
            phase: ArmPhase::PlainIk(PlainIk {
                arm: self.arm,
                hand_over,
            }),
            error,
            // After a hand-over, within the tolerance: plain IK closes in slowest at the end.
            hand_done: error <= rules.tolerance,
            limited,
        })
    }
}

/// Plain inverse kinematics takes the hand the last centimeters from the synergy's posture.
pub(super) struct PlainIk {
    arm: SynergyArm,
    hand_over: HandOver,
}

impl PlainIk {
    /// Plain IK steps; where it cannot close the gap either (the two chains' limits
    /// disagree) — its step not finite, stalled, or driving longer than [`PLAIN_IK_TIME`] —
    /// the analytic IK finishes, in the character's own limits, from the arm as it is.
    fn step(
        mut self,
        rules: &ArmRules<'_>,
        follower: &mut ArmFollower,
        pose: &Pose,
        t: f64,
        error: f64,
    ) -> Result<Stepped> {
        let (seen, error, stalled) = observe(&mut self.arm, rules, pose, t, error)?;
        let slow = t - self.hand_over.at_s >= PLAIN_IK_TIME;
        let phase = if seen.is_none() || stalled || slow {
            let from = t + rules.dt;
            follower.resume_from();
            ArmPhase::Analytic(Analytic {
                from,
                profile: rules.approach,
                hand_over: Some(HandOver {
                    analytic_at_s: Some(from),
                    ..self.hand_over
                }),
            })
        } else {
            ArmPhase::PlainIk(self)
        };
        Ok(Stepped {
            phase,
            error,
            hand_done: error <= rules.tolerance,
            limited: false,
        })
    }
}

/// The person's controller (synergy or plain IK) sees the frame's final `pose` and steps:
/// the distance it saw (`None`: its step was not finite), the hand's distance from the
/// target (the frame's `error` when it saw none), and whether its progress stalled short of
/// the target once the body had stopped.
fn observe(
    arm: &mut SynergyArm,
    rules: &ArmRules<'_>,
    pose: &Pose,
    t: f64,
    error: f64,
) -> Result<(Option<f64>, f64, bool)> {
    let base = rules.character.limb_base_frame(rules.plan.arm, pose);
    let seen = arm.end_frame(pose, &base)?;
    let error = seen.unwrap_or(error);
    let stalled = error > rules.arrived
        && rules.timeline.body_done(t)
        && arm.stalled_by(rules.stall_window, rules.min_progress);
    Ok((seen, error, stalled))
}
