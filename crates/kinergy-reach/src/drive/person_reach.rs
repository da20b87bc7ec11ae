//! A full-body reach as `kinergy reach` and Python's `reach` ask for it: a character of a
//! height or a capture's proportions, a target, the scheduler's settings, and a person's
//! parameters driving the reaching arm or the hand's speed profile; the motion as a clip, a
//! report both front ends serialize, and how it ended.

use std::fmt;
use std::str::FromStr;

use kinergy_io::{Classify, ErrorKind, InvalidSetting};
use kinergy_motion::Clip;
use kinergy_motion::nalgebra::Point3;
use kinergy_solver::{FieldUse, PersonStyle};
use serde::Serialize;

use super::PersonArm;
use crate::character::{Character, Proportions};
use crate::controller::{ArmDrive, Ending, ReachReport, ReachSettings, reach_full_body_driven};
use crate::error::Result;
use crate::profile::{BellTiming, SpeedProfile};

/// The character's height range, meters.
pub const HEIGHT_M: (f64, f64) = (0.5, 2.5);
/// The character's height when none is given, meters.
pub const DEFAULT_HEIGHT_M: f64 = 1.75;
/// The leg flexibility range.
pub const FLEXIBILITY: (f64, f64) = (0.1, 10.0);
/// The longest reach's range, seconds.
pub const TIMEOUT_S: (f64, f64) = (0.1, 60.0);
/// The farthest target from the character (standing at the origin) any body reaches, meters:
/// farther is a target in another unit, or a typo.
pub const MAX_TARGET_M: f64 = 10.0;

/// The hand's speed profile, by name.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Profile {
    /// Huang's: constant speed, then constant deceleration (v_s = 20 cm/s, r_s = 0.8).
    #[default]
    EaseOut,
    /// A minimum-jerk bell, like human hand speed.
    MinimumJerk,
}

impl Profile {
    /// Both, in the order the front ends list them.
    pub const ALL: [Profile; 2] = [Profile::EaseOut, Profile::MinimumJerk];

    /// `ease-out` or `minimum-jerk`.
    pub fn name(self) -> &'static str {
        match self {
            Profile::EaseOut => "ease-out",
            Profile::MinimumJerk => "minimum-jerk",
        }
    }

    /// The speed profile the scheduler runs.
    pub fn speed_profile(self) -> SpeedProfile {
        match self {
            Profile::EaseOut => SpeedProfile::default(),
            Profile::MinimumJerk => SpeedProfile::MinimumJerk {
                timing: BellTiming::default(),
            },
        }
    }
}

impl fmt::Display for Profile {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Profile {
    type Err = InvalidSetting;
    fn from_str(s: &str) -> std::result::Result<Profile, InvalidSetting> {
        Profile::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| {
                InvalidSetting::new(
                    "profile",
                    format!("`{s}`: expected ease-out or minimum-jerk"),
                )
            })
    }
}

/// A full-body reach request: a character, a target, the settings and who drives the arm.
pub struct PersonReach<'a> {
    /// The target hand position, world meters.
    pub target: Point3<f64>,
    /// The character's proportions.
    pub proportions: Proportions,
    /// The scheduler's settings (flexibility, seed, timeout, arm, profile …).
    pub settings: ReachSettings,
    /// The person whose synergy drives the reaching arm; `None`: the hand follows
    /// `settings.profile` by the analytic IK.
    pub person: Option<&'a dyn PersonStyle>,
}

/// How a full-body reach went (`kinergy reach --json`, Python's `Clip.report`).
#[derive(Debug, Clone, Serialize)]
pub struct PersonReachReport {
    /// The file written (set by the front end that writes one).
    pub output: Option<String>,
    /// The character's height, meters.
    pub height_m: f64,
    /// The target, world meters.
    pub target_m: [f64; 3],
    /// With a person's field: how it was used.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub field: Option<FieldUse>,
    /// The scheduler's report.
    #[serde(flatten)]
    pub reach: ReachReport,
}

/// A full-body reach made: the motion, its report and how it ended.
#[derive(Debug, Clone)]
pub struct PersonReachOutcome {
    /// The character's motion (120 Hz).
    pub clip: Clip,
    /// The report.
    pub report: PersonReachReport,
    /// How it ended.
    pub ending: Ending,
    /// The longest reach it was given, seconds.
    pub timeout_s: f64,
}

/// A reach that did not arrive: its ending, the hand's distance left and the timeout.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{}", ending.describe(*final_error_m, *timeout_s))]
pub struct NotReached {
    /// How it ended.
    pub ending: Ending,
    /// The hand's distance to the target at the end, meters.
    pub final_error_m: f64,
    /// The longest reach, seconds.
    pub timeout_s: f64,
}

impl Classify for NotReached {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Unreachable
    }
}

impl Ending {
    /// How the reach ended, in words: `reached`, `beyond reach by 0.33 m`, or the timeout
    /// with the hand still moving.
    pub fn describe(&self, final_error_m: f64, timeout_s: f64) -> String {
        match self {
            Ending::Reached => "reached".into(),
            Ending::Beyond(by) => format!(
                "the target is beyond reach by {by:.3} m: the motion ends with the hand at the \
                 nearest point it reaches"
            ),
            Ending::StillMoving => format!(
                "the hand was still moving when the timeout of {timeout_s} s ran out, \
                 {final_error_m:.3} m from the target: raise the timeout"
            ),
        }
    }
}

impl PersonReachOutcome {
    /// `Ok` when the hand arrived; otherwise [`NotReached`].
    pub fn arrived(&self) -> std::result::Result<(), NotReached> {
        match self.ending {
            Ending::Reached => Ok(()),
            ending => Err(NotReached {
                ending,
                final_error_m: self.report.reach.final_error,
                timeout_s: self.timeout_s,
            }),
        }
    }
}

/// Checks a world target before any work: finite and within [`MAX_TARGET_M`] of the origin.
pub fn check_target(target: &Point3<f64>) -> std::result::Result<(), InvalidSetting> {
    // `hypot` does not overflow where the squares would (a target of 1e155 m).
    let distance = target.x.hypot(target.y).hypot(target.z);
    InvalidSetting::require(
        distance <= MAX_TARGET_M,
        "target",
        format!(
            "the target is {} from the character (standing at the origin), beyond what any body \
             reaches (at most {MAX_TARGET_M} m): a target in another unit, or a typo?",
            kinergy_io::meters(distance)
        ),
    )
}

/// Checks the scheduler's settings a user gives: the flexibility and the timeout within
/// their ranges ([`FLEXIBILITY`], [`TIMEOUT_S`]).
pub fn check_settings(s: &ReachSettings) -> std::result::Result<(), InvalidSetting> {
    let within = |v: f64, (lo, hi): (f64, f64)| lo <= v && v <= hi;
    {
        InvalidSetting::require(
            within(s.flexibility, FLEXIBILITY),
            "flexibility",
            format!(
                "{}: expected {} to {}",
                s.flexibility, FLEXIBILITY.0, FLEXIBILITY.1
            ),
        )?;
        InvalidSetting::require(
            within(s.timeout, TIMEOUT_S),
            "timeout",
            format!("{}: expected {} to {}", s.timeout, TIMEOUT_S.0, TIMEOUT_S.1),
        )
    }
}

impl PersonReach<'_> {
    /// Checks the request before any work: the target ([`check_target`]) and the settings
    /// ([`check_settings`]).
    pub fn validate(&self) -> std::result::Result<(), InvalidSetting> {
        check_target(&self.target)?;
        check_settings(&self.settings)
    }

    /// Builds the character, the person's drive of its arm, and runs the reach.
    /// [`ReachError::Params`](crate::ReachError::Params) when the person's parameters do not fit the character or the
    /// target.
    pub fn run(&self) -> Result<PersonReachOutcome> {
        let character = Character::new(&self.proportions)?;
        let (drive, field) = match self.person {
            Some(person) => {
                let arm = PersonArm::toward(&character, person, &self.target, self.settings.arm)?;
                (arm.drive, arm.field)
            }
            None => (ArmDrive::Profile, None),
        };
        let motion = reach_full_body_driven(&character, self.target, &self.settings, &drive)?;
        let clip = character.to_clip(&motion.poses, motion.frame_time)?;
        let ending = Ending::of(&character, &motion);
        Ok(PersonReachOutcome {
            clip,
            report: PersonReachReport {
                output: None,
                height_m: self.proportions.height(),
                target_m: [self.target.x, self.target.y, self.target.z],
                field,
                reach: motion.report,
            },
            ending,
            timeout_s: self.settings.timeout,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn profile_names_read_back_and_a_stranger_is_named() {
        for p in Profile::ALL {
            assert_eq!(p.name().parse::<Profile>(), Ok(p));
        }
        assert_eq!("fast".parse::<Profile>().unwrap_err().field, "profile");
    }

    #[test]
    fn a_target_beyond_any_body_is_refused_before_any_work() {
        assert!(check_target(&Point3::new(0.3, 1.2, 0.5)).is_ok());
        let e = check_target(&Point3::new(1e155, 0.0, 0.0)).unwrap_err();
        assert_eq!(e.field, "target");
        assert!(e.why.contains("at most 10 m"), "{e}");
        assert!(check_target(&Point3::new(f64::NAN, 0.0, 0.0)).is_err());
    }

    #[test]
    fn a_reach_beyond_the_body_ends_beyond_reach_and_says_by_how_much() {
        let request = PersonReach {
            target: Point3::new(0.0, 1.2, 2.5),
            proportions: Proportions::from_height(1.75).expect("a body"),
            // The nearest posture (a full step, the torso level) leaves the hand 1.5 m of
            // straight path at the paper's v_s: about 14 s.
            settings: ReachSettings {
                timeout: 30.0,
                ..ReachSettings::default()
            },
            person: None,
        };
        request.validate().expect("a valid request");
        let done = request.run().expect("runs");
        let e = done
            .arrived()
            .expect_err("2.5 m ahead is beyond a 1.75 m body");
        assert_eq!(e.kind(), ErrorKind::Unreachable);
        let Ending::Beyond(by) = e.ending else {
            panic!("ends beyond reach, not {:?}", e.ending)
        };
        assert!(by > 0.3, "{by}");
        assert!(
            e.to_string().starts_with("the target is beyond reach by"),
            "{e}"
        );
        assert_eq!(done.clip.frame_count(), done.report.reach.frames);
    }
}
