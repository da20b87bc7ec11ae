//! A person's style on one of their captures, every predictor made at once (`kinergy style`,
//! Python's `style`): the full-body character reaches the capture's target with the person's
//! parameters and with the default profile ([`kinergy_reach::style::StyleCapture::compare`]),
//! the person's controller replays the capture on its own torso ([`CapturedReach::replay`]),
//! and the hand speeds of all of them, relative to the shoulder and in real time, become a
//! [`TakeMotions`] for [`crate::fidelity::PersonFidelity`].

use kinergy_motion::nalgebra::Point3;
use kinergy_motion::{ArmJoints, Clip, Side};
use kinergy_reach::controller::SynergyStart;
use kinergy_reach::style::{StyleCapture, StyleRun};
use kinergy_solver::{BaseMode, PersonStyle};

use crate::captured::{CapturedReach, DEFAULT_TOLERANCE, ReachDrive, Replay};
use crate::error::Result;
use crate::fidelity::{Series, TakeMotions};

/// How long the replay on the captured torso may run, seconds (as `synthesize`'s default).
pub const REPLAY_SECONDS: f64 = 10.0;

/// One capture of a person, with every motion made toward it.
#[derive(Debug, Clone)]
pub struct StyleTake {
    /// The capture's main reach, target and character.
    pub capture: StyleCapture,
    /// The two full-body reaches and their time-normalized scores.
    pub run: StyleRun,
    /// The person's controller on the captured torso.
    pub replay: Replay,
    /// Every motion's hand speed in real time.
    pub motions: TakeMotions,
}

impl StyleTake {
    /// The capture `clip` (named `name`), its arm `joints` on `side`, against `person`'s
    /// parameters. Errors: the capture's (no main reach, an arm without length: input), the
    /// parameters' on the character or the reach (input), the body's reach.
    pub fn run(
        clip: &Clip,
        joints: &ArmJoints,
        name: &str,
        person: &dyn PersonStyle,
        side: Side,
    ) -> Result<StyleTake> {
        // The arm ends where the person's fit ended it (the wrist, for captures without a
        // hand): the capture, its replay and the body are measured at that point.
        let joints = &person.arm_as_fitted(joints);
        let capture = StyleCapture::new(clip, joints, name)?;
        let [onset, end] = capture.frames();
        let reach = CapturedReach::new(name, clip, joints, onset..end, BaseMode::Replay)?;
        let drive = ReachDrive::person(&reach, person, side)
            .map_err(|e| kinergy_reach::ReachError::Params { source: e })?;
        // Under the controller the person was fitted under (the body's arm runs it too).
        let reach = reach.under(drive.controller.unwrap_or_default());
        // The body's arm starts as the fit's replay does: the capture's start posture and
        // velocity (a take cut mid-motion starts moving; the paper's controller from rest).
        let start = match (reach.arm().start(), reach.start_velocity()) {
            (q, v) if q.len() == 7 && v.is_none_or(|v| v.len() == 7) => Some(SynergyStart {
                configuration: std::array::from_fn(|i| q[i]),
                velocity: std::array::from_fn(|i| v.map_or(0.0, |v| v[i])),
                // The bounds the replay runs under: the person's law, or the capture's own.
                smoothing: reach.smoothing_under(drive.tempo.as_ref()),
                hand_m: Some(reach.fitted_arm().hand_m),
            }),
            _ => None,
        };
        let run = capture.compare_from(side, person, start)?;

        let replay = reach.replay(&drive, DEFAULT_TOLERANCE, REPLAY_SECONDS, false)?;
        let arm = reach.arm().synthesized_trajectory(&replay.synthesis)?;
        let last = arm.joint_count() - 1;
        let arm_relative: Vec<Point3<f64>> = (0..arm.frame_count())
            .map(|i| {
                let f = arm.frame(i);
                Point3::from(f[last] - f[0])
            })
            .collect();
        let character = capture.character();
        let wrist = !capture.has_hand();
        let body = |m: &kinergy_reach::controller::ReachMotion| {
            Series::of_relative(&m.arm_relative(character, wrist), m.frame_time)
        };
        let motions = TakeMotions {
            name: name.to_string(),
            capture: Series::of_relative(capture.relative_hand(), capture.frame_time()),
            arm: Some(Series::of_relative(&arm_relative, reach.frame_time())),
            body: Some(body(&run.params_motion)),
            profile: Some(body(&run.profile_motion)),
        };
        Ok(StyleTake {
            capture,
            run,
            replay,
            motions,
        })
    }
}
