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

use kinergy_io::InvalidSetting;
use kinergy_motion::Side;
use kinergy_motion::nalgebra::Point3;
use kinergy_motion::{ArmJoints, Clip, Trajectory, frame_distance, motion_distance, speed_series};
use kinergy_solver::{
    ArmTask, Base, BaseMode, CaptureArm, Controller, ControllerKind, ControllerSettings, FieldUse,
    FitObjective, FittedArm, Model, Optimizer, ParamSpace, PersonStyle, PersonTempo, ReachTempo,
    Smoothing, StopReason, StyleError, Synergy, Synthesis, Task,
};

use crate::error::{Result, TrainError};

/// The default ε of a fitting synthesis, meters (the controller's default).
pub const DEFAULT_TOLERANCE: f64 = 0.005;

/// The farthest a reach's target may lie from the arm's base (the clavicle) on the reach's
/// last frame, meters: beyond any arm with the trunk bending and a step (the synthetic set's
/// farthest stepping reach ends 1.3 m from the shoulder); a farther target is bad input.
pub const MAX_TARGET_DISTANCE: f64 = 10.0;

/// The arm `joints` of `clip` as a fit records it: its side, its joints' names and its
/// bones on the clip's first frame.
pub fn measured_arm(clip: &Clip, joints: &ArmJoints) -> Result<FittedArm> {
    let lengths = joints.lengths(clip)?;
    Ok(FittedArm {
        side: joints.side,
        joints: joints
            .names(clip.skeleton())
            .into_iter()
            .map(String::from)
            .collect(),
        upper_arm_m: lengths.upper_arm,
        forearm_m: lengths.forearm,
        hand_m: lengths.hand,
    })
}

/// What drives a replay of a captured reach ([`CapturedReach::replay`]): an optimizer and a
/// synergy on the reach's DoFs — a person's, or a model's neutral one.
#[derive(Debug, Clone, PartialEq)]
pub struct ReachDrive {
    /// Turns the task error into a joint step.
    pub optimizer: Optimizer,
    /// The synergy on the reach's DoFs.
    pub synergy: Synergy,
    /// How a person's field gave them (`None`: one vector, or no person).
    pub field: Option<FieldUse>,
    /// The person's tempo law the replay runs under ([`kinergy_solver::FitRecord::tempo`]:
    /// the law the fit recorded, or for a file written before it the medians of its reaches'
    /// tempos, as the full body runs it); `None`: the capture's own speed, for a neutral model
    /// or a file without a fit record.
    pub tempo: Option<PersonTempo>,
    /// The controller the person's parameters were fitted under (their record's
    /// `controller`); `None`: a neutral model, or a file that does not record it.
    pub controller: Option<ControllerKind>,
}

impl ReachDrive {
    /// `person`'s drive of `reach`: their parameters for its target in its arm's base frame
    /// (one vector, or a field's prediction there; a field fitted on the other arm is asked
    /// mirrored), on its DoFs. `side` is the arm asked for when the reach does not know its
    /// own. Errors are the parameters': a field's prediction out of bounds, other DoF names.
    pub fn person(
        reach: &CapturedReach,
        person: &dyn PersonStyle,
        side: Side,
    ) -> std::result::Result<ReachDrive, StyleError> {
        let side = reach.fitted_arm().side.unwrap_or(side);
        let at = person.params_for_arm(&reach.local_target(), side)?;
        let synergy = at.params.synergy_for(&reach.dof_names())?;
        Ok(ReachDrive {
            optimizer: at.params.optimizer,
            synergy,
            field: at.field,
            tempo: at.params.fit.as_ref().and_then(|f| f.tempo()),
            controller: at.params.fit.as_ref().and_then(|f| f.controller),
        })
    }

    /// `model`'s neutral synergy on `reach`'s DoFs ([`ParamSpace::neutral`]: gains 1, the
    /// sigmoids on from the start) with `optimizer`.
    pub fn neutral(
        reach: &CapturedReach,
        model: Model,
        optimizer: Optimizer,
    ) -> kinergy_solver::Result<ReachDrive> {
        let space = ParamSpace::new(model, &reach.dof_names(), Default::default())?;
        Ok(ReachDrive {
            optimizer,
            synergy: Synergy::new(&space, &space.neutral())?,
            field: None,
            tempo: None,
            controller: None,
        })
    }
}

/// A replayed reach ([`CapturedReach::replay`]).
#[derive(Debug, Clone)]
pub struct Replay {
    /// The synthesized motion.
    pub synthesis: Synthesis,
    /// Its motion distance to the captured reach, meters (`None` when they cannot be
    /// compared).
    pub distance_to_capture_m: Option<f64>,
}

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
    /// The joint velocity the synthesis starts with (the captured hand's, see
    /// [`start_velocity`]); `None`: at rest.
    start_velocity: Option<Vec<f64>>,
    /// The smooth controller's bounds; `None`: the paper's controller.
    smoothing: Option<Smoothing>,
    /// The known tempo (peak speed, duration) of the controller that made the motion
    /// ([`CapturedReach::with_known_tempo`]), whose bounds no person's law replaces.
    known_tempo: Option<(f64, f64)>,
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
        let fitted_arm = measured_arm(&segment, joints)?;
        let captured = arm.captured_trajectory(&segment)?;
        let last = captured.frame(captured.frame_count() - 1);
        let target = *last
            .last()
            .ok_or_else(|| bad("the arm has no joints".into()))?;
        let start_velocity = start_velocity(&arm, &captured, clip.frame_time())?;
        let smoothing = Some(reach_smoothing(
            &arm,
            &captured,
            clip.frame_time(),
            &fitted_arm,
        ));
        Ok(CapturedReach {
            smoothing,
            known_tempo: None,
            start_velocity: Some(start_velocity),
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

    /// How fast the captured hand moved over the reach, relative to the shoulder.
    pub fn tempo(&self) -> ReachTempo {
        reach_tempo(&self.captured, self.frame_time)
    }

    /// [`CapturedReach::tempo`] with the peak speed the smooth controller's bounds take (the
    /// base-frame rule of `reach_smoothing`), or the [known tempo](Self::with_known_tempo)
    /// over the reach's travel: what a [`PersonTempo`] is made of.
    pub fn bound_tempo(&self) -> ReachTempo {
        match self.known_tempo {
            Some((peak_speed_m_s, duration_s)) => ReachTempo {
                peak_speed_m_s,
                duration_s,
                ..self.tempo()
            },
            None => ReachTempo {
                peak_speed_m_s: bound_peak_speed(&self.arm, &self.captured, self.frame_time),
                ..self.tempo()
            },
        }
    }

    /// The reach under the person's tempo `law` (the smooth controller bounded as their reach
    /// over this one's travel, [`PersonTempo::for_distance`]) instead of its own capture's
    /// speed; unchanged under the paper's controller.
    pub fn under_tempo(mut self, law: &PersonTempo) -> CapturedReach {
        self.smoothing = self.smoothing_under(Some(law));
        self
    }

    /// The smooth controller's bounds of this reach under `law` (the person's reach over this
    /// one's travel), or its own capture's without one; `None` under the paper's controller.
    /// A reach whose bounds are a [known tempo](CapturedReach::with_known_tempo) keeps them.
    pub fn smoothing_under(&self, law: Option<&PersonTempo>) -> Option<Smoothing> {
        match (self.smoothing, law) {
            (Some(_), Some(law)) if self.known_tempo.is_none() => {
                let f = &self.fitted_arm;
                let (peak, duration) =
                    law.for_reach_by(self.tempo().travel_m, f.upper_arm_m + f.forearm_m);
                Some(self.smoothing_for(peak, duration))
            }
            (own, _) => own,
        }
    }

    /// The smooth controller's bounds of a reach on this arm peaking at `peak` m/s over
    /// `duration` seconds ([`Smoothing::for_reach`]).
    fn smoothing_for(&self, peak: f64, duration: f64) -> Smoothing {
        let f = &self.fitted_arm;
        Smoothing::for_reach(peak, duration, f.upper_arm_m + f.forearm_m + f.hand_m)
    }

    /// The reach bounded by the smooth controller as a reach peaking at `peak_speed_m_s` over
    /// `duration_s` (the tempo the controller that made the motion was bounded by: a segments
    /// file's `peak_speed_m_s` and `duration_s`), started from rest as that controller was,
    /// whatever tempo law a fit or a replay brings, on the arm's chain with the shoulder open
    /// as that controller's chain has it ([`CaptureArm::with_open_shoulder`]: limits at the
    /// captured extremes would brake the arm before them); unchanged under the paper's
    /// controller. A fit of a motion made by Kinergy's full-body synergy arm (`kinergy synth
    /// --params`) then runs that controller again.
    pub fn with_known_tempo(
        mut self,
        peak_speed_m_s: f64,
        duration_s: f64,
    ) -> Result<CapturedReach> {
        if self.smoothing.is_some() {
            self.smoothing = Some(self.smoothing_for(peak_speed_m_s, duration_s));
            self.known_tempo = Some((peak_speed_m_s, duration_s));
            self.start_velocity = None;
            self.arm = self.arm.with_open_shoulder()?;
        }
        Ok(self)
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
    /// against stays the same). The target must be finite and within [`MAX_TARGET_DISTANCE`]
    /// of the arm's base (the clavicle) on the reach's first and last frames: farther, no body reaches
    /// it, and a fit's distances would overflow (a target of 1e308 m would be fitted to "inf mm"
    /// and stored as 1.797e308). Else [`TrainError::Setting`] naming `target`.
    pub fn with_target(self, target: Point3<f64>) -> Result<CapturedReach> {
        let field = || "target".to_string();
        if !target.iter().all(|v| v.is_finite()) {
            return Err(TrainError::Setting(InvalidSetting::new(
                field(),
                "the target's coordinates must be finite numbers",
            )));
        }
        // From the shoulder on the last frame and on the first (where the field reads its
        // target: one check for both, so a field never refuses a reach this accepted).
        // `hypot` does not overflow where the squares would (a target of 1e155 m).
        let distance = [0, self.frame_count().saturating_sub(1)]
            .map(|f| {
                let d = target - Point3::from(self.base.at(f).translation.vector);
                d.x.hypot(d.y).hypot(d.z)
            })
            .into_iter()
            .fold(0.0, f64::max);
        if distance > MAX_TARGET_DISTANCE {
            return Err(TrainError::Setting(InvalidSetting::new(
                field(),
                format!(
                    "the target is {} from the arm's shoulder on the reach's first or last frame, \
                     beyond what any body reaches (at most {MAX_TARGET_DISTANCE} m): a target \
                     in another unit, or a typo?",
                    kinergy_io::meters(distance)
                ),
            )));
        }
        Ok(CapturedReach { target, ..self })
    }

    /// The joint velocity the synthesis starts with (rad/s; the captured hand's, by least
    /// squares), `None` at rest.
    pub fn start_velocity(&self) -> Option<&[f64]> {
        self.start_velocity.as_deref()
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
            start_velocity: self.start_velocity.as_deref(),
        }
    }

    /// Controller settings of a fitting synthesis: the capture's frame time, exactly the
    /// segment's frame count, ε = `tolerance`.
    pub fn settings(&self, tolerance: f64) -> ControllerSettings {
        ControllerSettings {
            max_frames: self.frame_count(),
            min_frames: self.frame_count(),
            tolerance,
            smoothing: self.smoothing,
            ..ControllerSettings::at_frame_time(self.frame_time)
        }
    }

    /// The controller's smoothing for this reach: by default the smooth controller with the
    /// bounds of [`Smoothing::for_reach`] from the capture's peak hand speed relative to the
    /// shoulder, its duration and the arm's length, the finish after the captured frames;
    /// `None` for the paper's controller ([`CapturedReach::with_smoothing`]).
    pub fn smoothing(&self) -> Option<Smoothing> {
        self.smoothing
    }

    /// The reach synthesized with `smoothing` instead (`None`: the paper's controller), e.g.
    /// to fit a motion made with known settings by the same controller.
    pub fn with_smoothing(mut self, smoothing: Option<Smoothing>) -> CapturedReach {
        self.smoothing = smoothing;
        self
    }

    /// The reach set up for `controller`: unchanged for the smooth controller (how a reach
    /// is made), [`CapturedReach::with_paper_controller`] for the paper's.
    pub fn under(self, controller: ControllerKind) -> CapturedReach {
        match controller {
            ControllerKind::Smooth => self,
            ControllerKind::Paper => self.with_paper_controller(),
        }
    }

    /// The controller this reach is synthesized by: the paper's without smoothing, else the
    /// smooth one.
    pub fn controller(&self) -> ControllerKind {
        match self.smoothing {
            Some(_) => ControllerKind::Smooth,
            None => ControllerKind::Paper,
        }
    }

    /// The reach synthesized by the paper's controller (no smoothing) from rest, as Aubry et
    /// al. have it.
    pub fn with_paper_controller(self) -> CapturedReach {
        self.with_smoothing(None).from_rest()
    }

    /// The reach synthesized from rest instead of with the captured hand's start velocity.
    pub fn from_rest(mut self) -> CapturedReach {
        self.start_velocity = None;
        self
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
            smoothing: self.smoothing,
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

    /// Replays this reach driven by `drive` (`kinergy synthesize`, Python's `synthesize`): the
    /// synthesis under [`CapturedReach::open_settings`] and its motion distance to the
    /// captured one (`None` when the two cannot be compared). Errors are the controller's: its
    /// settings, a non-finite base or target.
    pub fn replay(
        &self,
        drive: &ReachDrive,
        tolerance: f64,
        max_seconds: f64,
        stop_at_reach: bool,
    ) -> kinergy_solver::Result<Replay> {
        let settings = ControllerSettings {
            smoothing: self.smoothing_under(drive.tempo.as_ref()),
            ..self.open_settings(tolerance, max_seconds, stop_at_reach)
        };
        let controller = Controller::new(drive.optimizer, drive.synergy.clone(), settings)?;
        let synthesis = controller.synthesize(&self.task())?;
        // Also toward another target: the capture's own target may be unknown to its last
        // hand position (a reach handed over before it arrived, a segments file's target),
        // and the distance then says how far the motion toward the given target is from the
        // captured one.
        let distance_to_capture_m = self
            .arm
            .synthesized_trajectory(&synthesis)
            .ok()
            .and_then(|synthesized| motion_distance(&self.captured, &synthesized).ok());
        Ok(Replay {
            synthesis,
            distance_to_capture_m,
        })
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
        self.distance_of(&self.arm.synthesized_trajectory(synthesis)?)
    }

    /// [`CapturedReach::distance`] of a synthesized trajectory.
    fn distance_of(&self, synthesized: &Trajectory) -> Result<f64> {
        let d = motion_distance(synthesized, &self.captured)?;
        Ok(if d.is_finite() { d } else { f64::MAX })
    }

    /// The hand's speed error of `synthesis`, m/s: the root-mean-square difference of the
    /// synthesized and the captured hand speed (world, [`speed_series`]'s central
    /// differences) over the captured frames (a synthesis that ran on is compared on those;
    /// one that stopped earlier holds its last frame).
    pub fn speed_error(&self, synthesis: &Synthesis) -> Result<f64> {
        Ok(self.speed_error_of(&self.arm.synthesized_trajectory(synthesis)?))
    }

    /// [`CapturedReach::speed_error`] of a synthesized trajectory.
    fn speed_error_of(&self, synthesized: &Trajectory) -> f64 {
        let hand = self.captured.joint_count() - 1;
        let n = self.captured.frame_count();
        let captured = speed_series(&self.captured.path(hand), self.frame_time);
        let mut path = synthesized.path(hand);
        if let Some(&last) = path.last() {
            path.resize(n.max(path.len()), last);
        }
        path.truncate(n);
        let made = speed_series(&path, synthesized.frame_time());
        let sum: f64 = captured
            .iter()
            .zip(&made)
            .map(|(a, b)| (a - b).powi(2))
            .sum();
        (sum / n.max(1) as f64).sqrt()
    }

    /// What a fit minimizing `objective` charges `synthesis`: its [distance](Self::distance),
    /// plus the weighted [speed error](Self::speed_error) for
    /// [`FitObjective::PositionsSpeed`].
    pub fn score(&self, synthesis: &Synthesis, objective: FitObjective) -> Result<f64> {
        let w = objective.speed_weight();
        if w == 0.0 || synthesis.stop == StopReason::NonFinite {
            return self.distance(synthesis);
        }
        // One synthesized trajectory for both terms.
        let synthesized = self.arm.synthesized_trajectory(synthesis)?;
        let d = self.distance_of(&synthesized)?;
        if d == f64::MAX {
            return Ok(d);
        }
        let total = d + w * self.speed_error_of(&synthesized);
        Ok(if total.is_finite() { total } else { f64::MAX })
    }

    /// Synthesizes and scores in one go.
    pub fn evaluate(&self, optimizer: Optimizer, synergy: Synergy, tolerance: f64) -> Result<f64> {
        self.evaluate_for(optimizer, synergy, tolerance, FitObjective::Positions)
    }

    /// [`CapturedReach::evaluate`] scored for `objective` ([`CapturedReach::score`]).
    pub fn evaluate_for(
        &self,
        optimizer: Optimizer,
        synergy: Synergy,
        tolerance: f64,
        objective: FitObjective,
    ) -> Result<f64> {
        let synthesis = self.synthesize(optimizer, synergy, tolerance)?;
        self.score(&synthesis, objective)
    }

    /// [`CapturedReach::evaluate`] for a caller that needs the distance only where it is at
    /// most `limit` (a search about to reject anything worse): the synthesis is abandoned on
    /// the first frame after which the distance is sure to exceed `limit` — the frames' terms
    /// so far, summed in order over the reach's frame count, are a lower bound of the
    /// distance, every term being non-negative — and that lower bound, greater than `limit`,
    /// is returned. A distance of at most `limit` is [`CapturedReach::evaluate`]'s to the bit,
    /// and so is every distance when `limit` is not finite.
    pub fn evaluate_within(
        &self,
        optimizer: Optimizer,
        synergy: Synergy,
        tolerance: f64,
        limit: f64,
    ) -> Result<f64> {
        self.evaluate_within_for(
            optimizer,
            synergy,
            tolerance,
            FitObjective::Positions,
            limit,
        )
    }

    /// [`CapturedReach::evaluate_within`] scored for `objective`: the speed term being ≥ 0,
    /// the distance's running lower bound is the score's too.
    pub fn evaluate_within_for(
        &self,
        optimizer: Optimizer,
        synergy: Synergy,
        tolerance: f64,
        objective: FitObjective,
        limit: f64,
    ) -> Result<f64> {
        let captured = &self.captured;
        if !limit.is_finite()
            || (captured.frame_time() - self.frame_time).abs() > 1e-9 * self.frame_time
        {
            return self.evaluate_for(optimizer, synergy, tolerance, objective);
        }
        let controller = Controller::new(optimizer, synergy, self.settings(tolerance))?;
        let frames = captured.frame_count();
        let tracked = captured.joint_count();
        let per = self.arm.chain().joints().len() + 1;
        let (mut sum, mut bound) = (0.0, 0.0);
        let synthesis = controller.synthesize_while(&self.task(), |s| {
            let k = s.frame_count() - 1;
            let Some(points) = s.points.get(k * per..k * per + tracked) else {
                return true;
            };
            if k >= frames {
                return true;
            }
            sum += frame_distance(points, captured.frame(k));
            bound = sum / frames as f64;
            bound <= limit
        })?;
        match synthesis {
            Some(synthesis) => self.score(&synthesis, objective),
            None => Ok(bound),
        }
    }
}

/// [`CapturedReach::smoothing`] of a captured arm trajectory (shoulder first, hand last).
///
/// The bounds limit the hand's motion relative to the chain's base, frame and all, but their
/// peak speed V is the hand's relative to the shoulder's position (what the bounds were tuned
/// on, on the shared people's raises). The two agree within a few percent for raises and
/// pointing (the base barely turns: 0.98–1.02 × on the Bandai takes). A trunk that bends while
/// the arm hangs — a pick-up — turns the base under a hand that barely moves relative to the
/// shoulder, and the arm must swing as fast as the base turns (CMU 26_11: 0.37 m/s relative,
/// 1.06 m/s in the base frame; with V = 0.37 the synthesis lagged the capture by 2 s and ended
/// 126 mm from it). So V is the base-frame peak beyond [`BASE_TURN_SLACK`] × the relative one,
/// when that is more: max(v_rel, v_base − 0.25 v_rel), continuous, the same for raises.
fn reach_smoothing(
    arm: &CaptureArm,
    captured: &Trajectory,
    frame_time: f64,
    fitted: &FittedArm,
) -> Smoothing {
    let t = reach_tempo(captured, frame_time);
    Smoothing::for_reach(
        bound_peak_speed(arm, captured, frame_time),
        t.duration_s,
        fitted.upper_arm_m + fitted.forearm_m + fitted.hand_m,
    )
}

/// The peak speed [`reach_smoothing`] bounds a reach by: max(v_rel, v_base − 0.25 v_rel).
fn bound_peak_speed(arm: &CaptureArm, captured: &Trajectory, frame_time: f64) -> f64 {
    let relative = reach_tempo(captured, frame_time).peak_speed_m_s;
    let base = base_peak_speed(arm, captured, frame_time);
    relative.max(base - BASE_TURN_SLACK * relative)
}

/// The tempo law of a fit of `reaches` ([`PersonTempo::of`] of their [bound
/// tempos](CapturedReach::bound_tempo)); `None` under the paper's controller or without a
/// usable reach.
pub fn person_tempo(reaches: &[CapturedReach]) -> Option<PersonTempo> {
    if reaches.iter().any(|r| r.smoothing.is_none()) {
        return None;
    }
    let arms: Vec<f64> = reaches
        .iter()
        .map(|r| r.fitted_arm.upper_arm_m + r.fitted_arm.forearm_m)
        .collect();
    let law = PersonTempo::of(
        &reaches
            .iter()
            .map(CapturedReach::bound_tempo)
            .collect::<Vec<_>>(),
    )?;
    Some(law.with_arm(kinergy_motion::jumps::median(&arms)))
}

/// `reaches` as a fit of them runs them: two or more under their person's tempo law
/// ([`person_tempo`], the bounds every synthesis in the person's style will run under), one
/// under its own capture's (which is the law of one reach).
pub fn under_person_tempo(reaches: &[CapturedReach]) -> Vec<CapturedReach> {
    match person_tempo(reaches) {
        Some(law) if reaches.len() >= 2 => reaches
            .iter()
            .cloned()
            .map(|r| r.under_tempo(&law))
            .collect(),
        _ => reaches.to_vec(),
    }
}

/// How much faster than relative to the shoulder the hand may move in the base frame before
/// the base-frame speed sets the smooth controller's bounds ([`reach_smoothing`]).
const BASE_TURN_SLACK: f64 = 0.25;

/// The captured hand's peak speed in the arm's base frame (the replayed base of each frame).
fn base_peak_speed(arm: &CaptureArm, captured: &Trajectory, frame_time: f64) -> f64 {
    let Base::Replay(bases) = arm.base(BaseMode::Replay) else {
        return 0.0;
    };
    let last = captured.joint_count() - 1;
    let in_base =
        |i: usize| bases[i.min(bases.len() - 1)].inverse_transform_point(&captured.frame(i)[last]);
    (1..captured.frame_count())
        .map(|i| (in_base(i) - in_base(i - 1)).norm() / frame_time)
        .fold(0.0, f64::max)
}

/// The captured hand's [`ReachTempo`] relative to the shoulder (the trajectory's first and
/// last joints).
fn reach_tempo(captured: &Trajectory, frame_time: f64) -> ReachTempo {
    let last = captured.joint_count() - 1;
    let n = captured.frame_count();
    let relative = |i: usize| captured.frame(i)[last] - captured.frame(i)[0];
    ReachTempo {
        peak_speed_m_s: (1..n)
            .map(|i| (relative(i) - relative(i - 1)).norm() / frame_time)
            .fold(0.0, f64::max),
        duration_s: n.saturating_sub(1) as f64 * frame_time,
        travel_m: (relative(n - 1) - relative(0)).norm(),
    }
}

/// The damping of [`start_velocity`]'s least squares, m/rad.
const START_DAMPING: f64 = 0.05;

/// The joint velocity of least norm that moves the hand, relative to the chain's base, as the
/// capture's does over its first frame (Jᵀ(JJᵀ + λ²I)⁻¹ ḣ, λ = [`START_DAMPING`]):
/// the synthesis starts moving as the person did. Not the captured joints' own velocity: a DoF
/// that does not move the hand (the twist of a straight arm) can turn fast in a capture,
/// and a synthesis carrying it on would swing the hand once the arm bends.
fn start_velocity(arm: &CaptureArm, captured: &Trajectory, frame_time: f64) -> Result<Vec<f64>> {
    let n = arm.chain().dof_count();
    if captured.frame_count() < 2 {
        return Ok(vec![0.0; n]);
    }
    let bases = match arm.base(BaseMode::Replay) {
        Base::Replay(b) => b,
        Base::Fixed(b) => vec![b],
    };
    let last = captured.joint_count() - 1;
    let in_base =
        |i: usize| bases[i.min(bases.len() - 1)].inverse_transform_point(&captured.frame(i)[last]);
    let velocity = (in_base(1) - in_base(0)) / frame_time;
    let jacobian = arm.chain().jacobian(
        &kinergy_motion::nalgebra::IsometryMatrix3::identity(),
        arm.start(),
    )?;
    // Damped least squares, λ = 5 cm/rad: near a straight arm a pseudo-inverse would turn a
    // small radial hand velocity into a fast elbow.
    let gram = &jacobian * jacobian.transpose()
        + kinergy_motion::nalgebra::Matrix3::identity() * START_DAMPING * START_DAMPING;
    let Some(inverse) = gram.try_inverse() else {
        return Ok(vec![0.0; n]);
    };
    let v = jacobian.transpose() * (inverse * velocity);
    Ok(v.iter().copied().collect())
}
