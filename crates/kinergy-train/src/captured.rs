//! A captured reach prepared for fitting: the person's arm as a 7-DoF synthesis chain, the
//! start posture (the segment's first frame), the target (the hand's position on the
//! segment's last frame), the captured torso motion the synthesized arm rides on, and the
//! captured arm trajectory the synthesis is scored against with the joint-position motion
//! distance (DESIGN §1.1).
//!
//! A synthesis for fitting runs exactly as many frames as the captured segment at the
//! capture's frame rate, tracking the target once it is reached, so the two motions compare
//! frame by frame over their whole length.

use std::ops::Range;

use kinergy_motion::nalgebra::Point3;
use kinergy_motion::{ArmJoints, Clip, Trajectory, motion_distance};
use kinergy_solver::{
    ArmTask, Base, BaseMode, CaptureArm, Controller, ControllerSettings, FittedArm, Optimizer,
    StopReason, Synergy, Synthesis, Task,
};

use crate::error::{Result, TrainError};

/// The default ε of a fitting synthesis, meters (the controller's default).
pub const DEFAULT_TOLERANCE: f64 = 0.005;

/// One captured reach, ready to be synthesized and scored.
#[derive(Debug, Clone)]
pub struct CapturedReach {
    name: String,
    frames: Range<usize>,
    arm: CaptureArm,
    base: Base,
    mode: BaseMode,
    target: Point3<f64>,
    captured: Trajectory,
    frame_time: f64,
    fitted_arm: FittedArm,
}

impl CapturedReach {
    /// The reach of `clip` over `frames` (indices into the clip), with the arm `joints`;
    /// `name` names it in messages and reports (e.g. the file name). The base follows the
    /// capture (`BaseMode::Replay`) or stays at the segment's first frame (`Fixed`).
    pub fn new(
        name: &str,
        clip: &Clip,
        joints: &ArmJoints,
        frames: Range<usize>,
        mode: BaseMode,
    ) -> Result<CapturedReach> {
        let bad = |why: String| TrainError::Reach {
            clip: name.to_string(),
            why,
        };
        if frames.start >= frames.end || frames.end > clip.frame_count() {
            return Err(bad(format!(
                "frames {}..{} are not within the clip's {} frames",
                frames.start,
                frames.end,
                clip.frame_count()
            )));
        }
        if frames.len() < 2 {
            return Err(bad("a reach needs at least 2 frames".into()));
        }
        let segment = clip.slice(frames.clone())?;
        let arm = CaptureArm::new(&segment, joints)?;
        let lengths = joints.lengths(&segment)?;
        let fitted_arm = FittedArm {
            side: joints.side,
            joints: joints
                .names(clip.skeleton())
                .into_iter()
                .map(String::from)
                .collect(),
            upper_arm_m: lengths.upper_arm,
            forearm_m: lengths.forearm,
            hand_m: lengths.hand,
        };
        let captured = arm.captured_trajectory(&segment)?;
        let last = captured.frame(captured.frame_count() - 1);
        let target = *last
            .last()
            .ok_or_else(|| bad("the arm has no joints".into()))?;
        Ok(CapturedReach {
            name: name.to_string(),
            base: arm.base(mode),
            frames,
            arm,
            mode,
            target,
            captured,
            frame_time: clip.frame_time(),
            fitted_arm,
        })
    }

    /// The reach's name.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The captured frames (indices into the original clip).
    pub fn frames(&self) -> Range<usize> {
        self.frames.clone()
    }

    /// Frames synthesized per evaluation (the segment's length).
    pub fn frame_count(&self) -> usize {
        self.frames.len()
    }

    /// Seconds per frame.
    pub fn frame_time(&self) -> f64 {
        self.frame_time
    }

    /// The hand's captured position on the segment's last frame, world meters.
    pub fn target(&self) -> Point3<f64> {
        self.target
    }

    /// The target in the arm's base frame on the reach's first frame (meters; origin at the
    /// shoulder, z lateral outward, y up, x = y × z: the capture convention of
    /// [`CaptureArm`]): where the target is for the person, wherever they stand and
    /// whichever way they face. A parameter field's targets are these.
    pub fn local_target(&self) -> Point3<f64> {
        self.to_local(&self.target)
    }

    /// A world point in the arm's base frame on the reach's first frame (see
    /// [`CapturedReach::local_target`]).
    pub fn to_local(&self, world: &Point3<f64>) -> Point3<f64> {
        self.base.at(0).inverse_transform_point(world)
    }

    /// The captured arm as a parameters file records it: side, joint names, bone lengths on
    /// the reach's first frame.
    pub fn fitted_arm(&self) -> &FittedArm {
        &self.fitted_arm
    }

    /// The synthesis arm made from the capture.
    pub fn arm(&self) -> &CaptureArm {
        &self.arm
    }

    /// How the base moves.
    pub fn base_mode(&self) -> BaseMode {
        self.mode
    }

    /// The captured arm's tracked points (shoulder, elbow, wrist, hand) per frame.
    pub fn captured(&self) -> &Trajectory {
        &self.captured
    }

    /// The DoF names of the synthesis chain.
    pub fn dof_names(&self) -> Vec<String> {
        self.arm.chain().dof_names().map(String::from).collect()
    }

    /// The same reach toward another target, world meters (the capture it is scored
    /// against stays the same).
    pub fn with_target(self, target: Point3<f64>) -> CapturedReach {
        CapturedReach { target, ..self }
    }

    /// The base the synthesized arm rides on.
    pub fn base(&self) -> &Base {
        &self.base
    }

    /// The controller's task: the synthesis arm on its base, from the captured start
    /// posture, the hand to the target.
    pub fn task(&self) -> ArmTask<'_> {
        ArmTask {
            chain: self.arm.chain(),
            base: &self.base,
            start: self.arm.start(),
            task: Task::Position(self.target),
        }
    }

    /// Controller settings of a fitting synthesis: the capture's frame time, exactly the
    /// segment's frame count, ε = `tolerance`.
    pub fn settings(&self, tolerance: f64) -> ControllerSettings {
        ControllerSettings {
            max_frames: self.frame_count(),
            min_frames: self.frame_count(),
            tolerance,
            ..ControllerSettings::at_frame_time(self.frame_time)
        }
    }

    /// Controller settings of a synthesis that runs until the target is reached (ε =
    /// `tolerance`) for at most `max_seconds`, and unless `stop_at_reach` for at least the
    /// segment's frame count (tracking the target once reached), at the capture's frame time.
    pub fn open_settings(
        &self,
        tolerance: f64,
        max_seconds: f64,
        stop_at_reach: bool,
    ) -> ControllerSettings {
        ControllerSettings {
            max_frames: ((max_seconds / self.frame_time).ceil() as usize)
                .clamp(1, kinergy_solver::controller::MAX_FRAMES),
            tolerance,
            min_frames: if stop_at_reach { 0 } else { self.frame_count() },
            ..ControllerSettings::at_frame_time(self.frame_time)
        }
    }

    /// Synthesizes the reach with `optimizer` and `synergy`.
    pub fn synthesize(
        &self,
        optimizer: Optimizer,
        synergy: Synergy,
        tolerance: f64,
    ) -> Result<Synthesis> {
        let controller = Controller::new(optimizer, synergy, self.settings(tolerance))?;
        Ok(controller.synthesize(&self.task())?)
    }

    /// A synthesis of this reach as a clip on the capture's skeleton: `clip` is the clip the
    /// reach was taken from. The rest of the body moves as captured over the segment and, when
    /// the synthesis is longer, holds the segment's last frame, as the base does: what the
    /// capture does after the segment (walking away, the next gesture) is not this reach's, and
    /// a base that went on with it could carry the shoulder away from the target.
    pub fn to_clip(&self, clip: &Clip, synthesis: &Synthesis) -> Result<Clip> {
        let segment = clip.slice(self.frames.clone())?;
        Ok(self.arm.to_clip(&segment, synthesis, self.mode)?)
    }

    /// The motion distance between a synthesis of this reach and the capture, meters; a
    /// synthesis that went non-finite scores `f64::MAX` (never better than any motion).
    pub fn distance(&self, synthesis: &Synthesis) -> Result<f64> {
        if synthesis.stop == StopReason::NonFinite {
            return Ok(f64::MAX);
        }
        let d = motion_distance(&self.arm.synthesized_trajectory(synthesis)?, &self.captured)?;
        Ok(if d.is_finite() { d } else { f64::MAX })
    }

    /// Synthesizes and scores in one go.
    pub fn evaluate(&self, optimizer: Optimizer, synergy: Synergy, tolerance: f64) -> Result<f64> {
        let synthesis = self.synthesize(optimizer, synergy, tolerance)?;
        self.distance(&synthesis)
    }
}
