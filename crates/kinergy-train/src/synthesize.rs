//! A synergy reach on a capture's skeleton, as `kinergy synthesize` and Python's
//! `synthesize` make it: the capture's frames where the reach starts (those a parameters file
//! was fitted on, the main reach, all, a window or a numbered segment), its arm, toward its
//! final hand position or a given target, driven by a person's parameters or a neutral model,
//! with the capture's torso replayed; the motion written back into the capture and a report
//! of how it ended.

use std::path::{Path, PathBuf};

use kinergy_io::{Classify, ErrorKind, InvalidSetting};
use kinergy_motion::nalgebra::Point3;
use kinergy_motion::{Clip, Side};
use kinergy_solver::{BaseMode, FieldUse, FittedArm, Model, Optimizer, PersonStyle, StopReason};
use serde::Serialize;

use crate::captured::{CapturedReach, ReachDrive, Replay};
use crate::error::TrainError;
use crate::limits;
use crate::person::PersonParams;
use crate::source::{ArmChoice, ControllerKind, FrameChoice};

/// What drives the synthesized arm.
#[derive(Debug, Clone)]
pub enum Drive {
    /// A person's parameters or field, read from `path` (errors name it).
    Person {
        /// The parameters (boxed: a field is large).
        params: Box<PersonParams>,
        /// Their file, for messages (`None` when they came from memory).
        path: Option<PathBuf>,
    },
    /// A model's neutral parameters.
    Neutral {
        /// The model.
        model: Model,
        /// The optimizer.
        optimizer: Optimizer,
    },
}

/// A synthesize request ([module docs](self)).
#[derive(Debug, Clone)]
pub struct SynthesizeRequest {
    /// Which frames of the capture the reach covers.
    pub frames: FrameChoice,
    /// Which arm (default: the one the parameters were fitted on, else right).
    pub arm: Option<Side>,
    /// The arm's joints by name, overriding the search.
    pub chain: Option<Vec<String>>,
    /// Whether the shoulder replays the capture's torso or stays where it starts.
    pub base: BaseMode,
    /// The synergy controller; `None`: the one the parameters were fitted under (their
    /// record's `controller`), else the smooth one.
    pub controller: Option<ControllerKind>,
    /// The target in world meters (default: the capture's final hand position).
    pub target: Option<Point3<f64>>,
    /// What drives the arm.
    pub drive: Drive,
    /// ε: the target counts as reached within this many meters.
    pub tolerance: f64,
    /// The longest motion synthesized, seconds.
    pub max_seconds: f64,
    /// Stop as soon as the target is reached (otherwise track it at least until the
    /// capture's last frame).
    pub stop_at_reach: bool,
}

/// At which step a synthesis failed: what the front ends name (the frames' source, the
/// target, the parameters file, the capture).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// The capture's frames for the reach.
    Frames,
    /// The reach on the capture (its arm, its frames).
    Reach,
    /// The target given.
    Target,
    /// The person's parameters on this reach.
    Params,
    /// The synthesis.
    Synthesis,
    /// Writing the motion back into the capture.
    Clip,
}

/// A synthesis that failed, at `step`.
#[derive(Debug, thiserror::Error)]
#[error("{source}")]
pub struct SynthesizeError {
    /// Where.
    pub step: Step,
    /// Why.
    pub source: TrainError,
}

impl Classify for SynthesizeError {
    /// The capture, its frames and the target are the input's fault, the person's
    /// parameters their file's; the synthesis's own errors by their kind.
    fn kind(&self) -> ErrorKind {
        match self.step {
            Step::Params => ErrorKind::Params,
            Step::Synthesis => self.source.kind(),
            Step::Frames | Step::Reach | Step::Target | Step::Clip => {
                let kind = self.source.kind();
                if kind.is_input() {
                    kind
                } else {
                    ErrorKind::Input
                }
            }
        }
    }

    fn location(&self) -> Option<kinergy_io::Location> {
        self.source.location()
    }
}

fn at<E: Into<TrainError>>(step: Step) -> impl FnOnce(E) -> SynthesizeError {
    move |e| SynthesizeError {
        step,
        source: e.into(),
    }
}

/// A synthesized reach: the capture with the arm synthesized, the report, and a warning
/// when the capture's arm or the controller is not the one the parameters were fitted on.
#[derive(Debug, Clone)]
pub struct Synthesized {
    /// The capture's skeleton and frames, the arm replaced by the synthesis.
    pub clip: Clip,
    /// How it went.
    pub report: SynthesisReport,
    /// The arm driven differs from the fitted one (the other side, or bones more than 10 %
    /// longer or shorter), or the controller from the one they were fitted under: what the
    /// front ends warn of.
    pub warning: Option<String>,
}

/// How a synthesis went (`kinergy synthesize --json`, Python's `Clip.report`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SynthesisReport {
    /// The capture, as named.
    pub input: String,
    /// The file written (set by the front end that writes one).
    pub output: Option<String>,
    /// The arm's joints.
    pub arm: Vec<String>,
    /// The arm's side, where known.
    pub side: Option<String>,
    /// The synergy model.
    pub model: String,
    /// The optimizer.
    pub optimizer: String,
    /// `fixed` or `replayed`.
    pub base: &'static str,
    /// The synergy controller that ran: `smooth` or `paper`.
    pub controller: &'static str,
    /// The target, world meters.
    pub target_m: [f64; 3],
    /// `--target` or the capture's final hand position.
    pub target_from: &'static str,
    /// `vector` (a parameters file), `field` (predicted by a field file) or `neutral`.
    pub params_from: &'static str,
    /// With a field file: what it predicted from.
    pub field: Option<FieldUse>,
    /// The capture's frames the reach covers.
    pub capture_frames: [usize; 2],
    /// Why the synthesis stopped.
    pub stop: &'static str,
    /// Frames synthesized.
    pub frames: usize,
    /// Their duration, seconds.
    pub duration_s: f64,
    /// The hand's distance to the target at the end, meters.
    pub final_error_m: f64,
    /// The shoulder's distance to the target on the last frame, meters.
    pub shoulder_to_target_m: f64,
    /// The arm's length, shoulder to end effector fully stretched, meters.
    pub arm_length_m: f64,
    /// The mean joint-position distance of the synthesized arm to the captured one on the
    /// same frames, meters (toward a given target too: then how the motion toward it differs
    /// from the captured one).
    pub distance_to_capture_m: Option<f64>,
    /// Limits widened to include the captured start.
    pub widened_limits: Vec<String>,
    /// DoFs at their limits on the last frame.
    pub at_limits_at_end: Vec<String>,
}

impl SynthesisReport {
    /// `Ok` when the target was reached; otherwise [`TrainError::NotReached`], saying how
    /// far beyond the arm the target is, or how far from it the motion ends.
    pub fn ending(&self) -> Result<(), TrainError> {
        if self.stop == StopReason::Reached.name() {
            return Ok(());
        }
        Err(TrainError::NotReached {
            stop: self.stop.to_string(),
            final_error_m: self.final_error_m,
            shoulder_to_target_m: self.shoulder_to_target_m,
            arm_length_m: self.arm_length_m,
        })
    }
}

impl SynthesizeRequest {
    /// The main reach of a capture replayed by `drive` on its captured torso, everything else
    /// at `kinergy synthesize`'s defaults (the arm `arm`, else the one the parameters were
    /// fitted on; the capture's final hand position as the target; ε
    /// [`DEFAULT_TOLERANCE`](crate::captured::DEFAULT_TOLERANCE), at most 10 s): what
    /// `kinergy retarget --params` runs on the retargeted motion.
    pub fn main_reach(drive: Drive, arm: Option<Side>) -> SynthesizeRequest {
        SynthesizeRequest {
            frames: FrameChoice::Main,
            arm,
            chain: None,
            base: BaseMode::Replay,
            controller: None,
            target: None,
            drive,
            tolerance: crate::captured::DEFAULT_TOLERANCE,
            max_seconds: 10.0,
            stop_at_reach: false,
        }
    }

    /// Checks the request before any work: ε and the longest motion within their ranges
    /// ([`limits::TOLERANCE_M`], [`limits::SYNTHESIZE_SECONDS`]), and one reach asked for.
    pub fn validate(&self) -> Result<(), InvalidSetting> {
        let within = |v: f64, (lo, hi): (f64, f64)| lo <= v && v <= hi;
        InvalidSetting::require(
            within(self.tolerance, limits::TOLERANCE_M),
            "tolerance",
            format!(
                "{}: expected {} to {}",
                self.tolerance,
                limits::TOLERANCE_M.0,
                limits::TOLERANCE_M.1
            ),
        )?;
        InvalidSetting::require(
            within(self.max_seconds, limits::SYNTHESIZE_SECONDS),
            "max_seconds",
            format!(
                "{}: expected {} to {}",
                self.max_seconds,
                limits::SYNTHESIZE_SECONDS.0,
                limits::SYNTHESIZE_SECONDS.1
            ),
        )
    }

    /// The arm's side: the one asked for, else the one the parameters were fitted on for
    /// this capture, else right; and that fitted arm.
    fn side(&self, from: &Path) -> (Side, Option<FittedArm>) {
        let fitted = match &self.drive {
            Drive::Person { params, .. } => params
                .record()
                .and_then(|r| r.arm(|clip| crate::source::names_clip(clip, from)).cloned()),
            Drive::Neutral { .. } => None,
        };
        let side = self
            .arm
            .or(fitted.as_ref().and_then(|a| a.side))
            .unwrap_or(Side::Right);
        (side, fitted)
    }

    /// Synthesizes the reach on `whole`, the capture read from `from`.
    pub fn run(&self, whole: &Clip, from: &Path) -> Result<Synthesized, SynthesizeError> {
        let (side, fitted) = self.side(from);
        let joints = ArmChoice {
            side,
            joints: self.chain.clone(),
        }
        .find(whole, from)
        .map_err(at(Step::Reach))?;
        let record = match &self.drive {
            Drive::Person { params, .. } => params.record(),
            Drive::Neutral { .. } => None,
        };
        // The arm ends where the person's fit ended it (the wrist, for captures without a
        // hand).
        let joints = match &self.drive {
            Drive::Person { params, .. } => params.arm_as_fitted(&joints),
            Drive::Neutral { .. } => joints,
        };
        let frames = self
            .frames
            .resolve(whole, from, &joints, record.as_ref())
            .map_err(at(Step::Frames))?;
        let name = from.display().to_string();
        let recorded = record.as_ref().and_then(|r| r.controller);
        let controller = self.controller.or(recorded).unwrap_or_default();
        let reach = CapturedReach::new(&name, whole, &joints, frames.clone(), self.base)
            .map(|r| r.under(controller))
            .map_err(at(Step::Reach))?;
        let warnings: Vec<String> = [
            fitted
                .as_ref()
                .and_then(|f| arm_mismatch(f, reach.fitted_arm())),
            controller_mismatch(recorded, controller),
        ]
        .into_iter()
        .flatten()
        .collect();
        let warning = (!warnings.is_empty()).then(|| warnings.join("; "));
        let (reach, target_from) = match self.target {
            Some(t) => (reach.with_target(t).map_err(at(Step::Target))?, "--target"),
            None => (reach, "the capture's final hand position"),
        };
        let drive = match &self.drive {
            Drive::Person { params, path } => {
                ReachDrive::person(&reach, params.as_ref() as &dyn PersonStyle, side).map_err(
                    |e| SynthesizeError {
                        step: Step::Params,
                        source: TrainError::File {
                            path: path.clone(),
                            why: e.to_string(),
                        },
                    },
                )?
            }
            Drive::Neutral { model, optimizer } => {
                ReachDrive::neutral(&reach, *model, *optimizer).map_err(at(Step::Synthesis))?
            }
        };
        let Replay {
            synthesis,
            distance_to_capture_m,
        } = reach
            .replay(&drive, self.tolerance, self.max_seconds, self.stop_at_reach)
            .map_err(at(Step::Synthesis))?;
        let clip = reach.to_clip(whole, &synthesis).map_err(at(Step::Clip))?;
        let arm = reach.arm();
        let dof_names = reach.dof_names();
        let last = synthesis.frame_count() - 1;
        let target = reach.target();
        let report = SynthesisReport {
            input: name,
            output: None,
            arm: joints
                .names(whole.skeleton())
                .into_iter()
                .map(String::from)
                .collect(),
            side: reach.fitted_arm().side.map(|s| s.to_string()),
            model: drive.synergy.model().name().to_string(),
            optimizer: drive.optimizer.to_string(),
            base: match self.base {
                BaseMode::Fixed => "fixed",
                BaseMode::Replay => "replayed",
            },
            controller: controller.name(),
            target_m: [target.x, target.y, target.z],
            target_from,
            params_from: match (&self.drive, &drive.field) {
                (Drive::Neutral { .. }, _) => "neutral",
                (Drive::Person { .. }, None) => "vector",
                (Drive::Person { .. }, Some(_)) => "field",
            },
            field: drive.field,
            capture_frames: [frames.start, frames.end],
            stop: synthesis.stop.name(),
            frames: synthesis.frame_count(),
            duration_s: synthesis.frame_count().saturating_sub(1) as f64 * reach.frame_time(),
            final_error_m: synthesis.final_error,
            shoulder_to_target_m: (target - reach.base().at(last).translation.vector)
                .coords
                .norm(),
            arm_length_m: arm_length(arm.chain()),
            distance_to_capture_m,
            widened_limits: arm.widened_limits().to_vec(),
            at_limits_at_end: arm
                .chain()
                .dofs_at_limits(synthesis.configuration(last), 1e-6)
                .into_iter()
                .map(|k| dof_names[k].clone())
                .collect(),
        };
        Ok(Synthesized {
            clip,
            report,
            warning,
        })
    }
}

/// What to warn of when the parameters replay under another controller than the one they
/// were fitted under (`recorded`): their distances were measured under that one.
pub fn controller_mismatch(
    recorded: Option<ControllerKind>,
    running: ControllerKind,
) -> Option<String> {
    recorded.filter(|&r| r != running).map(|r| {
        format!(
            "the parameters were fitted under the {r} controller and replay under the \
             {running} one: their fit's distances do not carry over"
        )
    })
}

/// Shoulder to end effector, fully stretched.
fn arm_length(chain: &kinergy_motion::Chain) -> f64 {
    chain.joints()[1..]
        .iter()
        .map(|j| j.offset.norm())
        .sum::<f64>()
        + chain.end_effector().norm()
}

/// How much longer or shorter a driven arm's bones may be than the fitted arm's before
/// [`arm_mismatch`] says so.
pub const ARM_LENGTH_TOLERANCE: f64 = 0.10;

/// What differs between the arm parameters were `fitted` on and the arm they drive `here`:
/// the other side, or bones more than [`ARM_LENGTH_TOLERANCE`] longer or shorter; `None`
/// when they match.
pub fn arm_mismatch(fitted: &FittedArm, here: &FittedArm) -> Option<String> {
    let other_side = matches!((fitted.side, here.side), (Some(a), Some(b)) if a != b);
    let difference = fitted.length_difference(here);
    if !other_side && difference <= ARM_LENGTH_TOLERANCE {
        return None;
    }
    let side = |s: Option<Side>| s.map_or_else(|| "named".to_string(), |s| s.to_string());
    Some(format!(
        "the parameters were fitted on a {} arm ({}; upper arm {:.3} m, forearm {:.3} m) and \
         drive a {} arm ({}; {:.3} m, {:.3} m){}",
        side(fitted.side),
        fitted.joints.join(" → "),
        fitted.upper_arm_m,
        fitted.forearm_m,
        side(here.side),
        here.joints.join(" → "),
        here.upper_arm_m,
        here.forearm_m,
        if difference > ARM_LENGTH_TOLERANCE {
            format!(": bones differ by up to {:.0} %", difference * 100.0)
        } else {
            String::new()
        }
    ))
}
