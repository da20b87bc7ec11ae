//! The synergy controller: iterative IK where each iteration is one frame of the motion
//! (Aubry et al. 2009, Fig. 1), with the synergy transform between optimizer and
//! integration: Θ ← clamp(Θ + S(t) · O(ΔX)).
//!
//! Beyond the paper, a position target near or beyond the edge of an arm's reach sphere is
//! guided ([`crate::reachability`]): the elbow (then the wrist) takes the distance by the law
//! of cosines, the optimizer O the rest, so fully extended reaches end on their target.

use std::borrow::Cow;

use kinergy_io::InvalidSetting;
use kinergy_motion::nalgebra::{IsometryMatrix3, Point3, Vector3};
use kinergy_motion::{Chain, Linearization, Trajectory};

use crate::error::{Result, SolverError};
use crate::optimizer::{Optimizer, StepScratch};
use crate::reachability::{Guidance, Pace, ReachSphere, StraightArm};
use crate::smoothing::{Frame, Smoother, Smoothing};

mod limits;
use crate::synergy::Synergy;
use crate::task::Task;
use limits::{Lock, clamp_moved, lock_limits};

/// Where the chain's base (the shoulder) is on each frame.
#[derive(Debug, Clone, PartialEq)]
pub enum Base {
    /// The same world frame throughout.
    Fixed(IsometryMatrix3<f64>),
    /// One world frame per frame (e.g. the capture's own shoulder, replayed); the last is
    /// held once the motion outlasts it.
    Replay(Vec<IsometryMatrix3<f64>>),
}

impl Base {
    /// The base frame on frame `i`.
    pub fn at(&self, i: usize) -> &IsometryMatrix3<f64> {
        match self {
            Base::Fixed(b) => b,
            Base::Replay(frames) => &frames[i.min(frames.len() - 1)],
        }
    }

    /// True when the base no longer moves from frame `i` on.
    pub fn is_still_from(&self, i: usize) -> bool {
        match self {
            Base::Fixed(_) => true,
            Base::Replay(frames) => i + 1 >= frames.len(),
        }
    }

    fn validate(&self) -> Result<()> {
        let frames: &[IsometryMatrix3<f64>] = match self {
            Base::Fixed(b) => std::slice::from_ref(b),
            Base::Replay(f) => f,
        };
        InvalidSetting::require(!frames.is_empty(), "base", "at least one frame")?;
        for (i, f) in frames.iter().enumerate() {
            let finite = f.translation.vector.iter().all(|v| v.is_finite())
                && f.rotation.matrix().iter().all(|v| v.is_finite());
            if !finite {
                return Err(SolverError::NonFinite(format!("the base frame {i}")));
            }
        }
        Ok(())
    }
}

/// When a motion counts as stalled: over the last `window` seconds, during which the base
/// stood still, the task error never got more than `min_progress` meters below its value
/// at the window's start.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StallRule {
    /// Seconds looked back.
    pub window: f64,
    /// Meters of improvement that count as progress.
    pub min_progress: f64,
}

impl Default for StallRule {
    fn default() -> StallRule {
        StallRule {
            window: 0.25,
            min_progress: 1e-5,
        }
    }
}

/// The most frames one synthesis may run ([`ControllerSettings::max_frames`]): 600,000,
/// e.g. 10 minutes at 1 kHz. Frame counts computed as seconds ÷ frame time are clamped to
/// it, so memory stays bounded whatever the rate.
pub const MAX_FRAMES: usize = 600_000;

/// How the controller runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControllerSettings {
    /// Seconds per frame (synthesize at the capture's rate to compare frame by frame).
    pub frame_time: f64,
    /// The motion ends with [`StopReason::MaxFrames`] after this many frames (1 to
    /// [`MAX_FRAMES`]).
    pub max_frames: usize,
    /// ε: the target is reached when the task error is below this, meters.
    pub tolerance: f64,
    /// The controller keeps running (tracking the target as the base moves) until at
    /// least this many frames exist, even once the target is reached; 0 stops at once.
    pub min_frames: usize,
    /// When the motion is stalled.
    pub stall: StallRule,
    /// How joint limits enter the step.
    pub limits: LimitHandling,
    /// The smooth controller ([`crate::smoothing`]): bounded accelerations, a progress floor,
    /// the finish blend to the plain optimizer, guidance of a near-straight arm. `None` is the
    /// paper's controller, whose step can change without bound from one frame to the next.
    pub smoothing: Option<Smoothing>,
}

impl ControllerSettings {
    /// Settings at `frame_time` with a 10-second budget, ε = 5 mm and the default stall
    /// rule.
    pub fn at_frame_time(frame_time: f64) -> ControllerSettings {
        ControllerSettings {
            frame_time,
            max_frames: if frame_time > 0.0 && frame_time.is_finite() {
                ((10.0 / frame_time).ceil() as usize)
                    .saturating_add(1)
                    .min(MAX_FRAMES)
            } else {
                1
            },
            tolerance: 0.005,
            min_frames: 0,
            stall: StallRule::default(),
            limits: LimitHandling::default(),
            smoothing: None,
        }
    }

    /// Checks every setting, naming the field otherwise.
    pub fn validate(&self) -> Result<()> {
        InvalidSetting::require(
            self.frame_time.is_finite() && self.frame_time > 0.0,
            "frame_time",
            "a positive number of seconds",
        )?;
        InvalidSetting::require(
            (1..=MAX_FRAMES).contains(&self.max_frames),
            "max_frames",
            "1 to 600000",
        )?;
        InvalidSetting::require(
            self.tolerance.is_finite() && self.tolerance > 0.0,
            "tolerance",
            "a positive number of meters",
        )?;
        InvalidSetting::require(
            self.stall.window.is_finite() && self.stall.window > 0.0,
            "stall.window",
            "a positive number of seconds",
        )?;
        InvalidSetting::require(
            self.stall.min_progress.is_finite() && self.stall.min_progress >= 0.0,
            "stall.min_progress",
            "a non-negative number of meters",
        )?;
        match &self.smoothing {
            Some(smoothing) => smoothing.validate(),
            None => Ok(()),
        }
    }
}

/// Why a synthesized motion ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum StopReason {
    /// The task error fell below ε.
    Reached,
    /// The frame budget ran out first.
    MaxFrames,
    /// No progress any more: the target is out of reach (or the limits block the way); the
    /// motion ends at the closest point it reached. A target beyond an arm's full reach ends
    /// this way with the arm stretched toward it, at the reachable point nearest it
    /// ([`crate::reachability`]).
    Stalled,
    /// A step produced NaN or infinity; the motion ends at the last finite frame.
    NonFinite,
}

impl StopReason {
    /// `reached`, `max_frames`, `stalled` or `non_finite`.
    pub fn name(self) -> &'static str {
        match self {
            StopReason::Reached => "reached",
            StopReason::MaxFrames => "max_frames",
            StopReason::Stalled => "stalled",
            StopReason::NonFinite => "non_finite",
        }
    }
}

impl std::fmt::Display for StopReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// A synthesized motion.
#[derive(Debug, Clone, PartialEq)]
pub struct Synthesis {
    /// Seconds per frame.
    pub frame_time: f64,
    /// DoFs per configuration.
    pub dof_count: usize,
    /// Configurations, frame after frame (`frames × dof_count`).
    pub configurations: Vec<f64>,
    /// World positions per frame: each chain joint, then the end effector.
    pub points: Vec<Point3<f64>>,
    /// Why it ended.
    pub stop: StopReason,
    /// Task error on the last frame, meters.
    pub final_error: f64,
}

impl Synthesis {
    /// The number of frames.
    pub fn frame_count(&self) -> usize {
        self.configurations
            .len()
            .checked_div(self.dof_count)
            .unwrap_or(0)
    }

    /// The configuration of frame `i`.
    pub fn configuration(&self, i: usize) -> &[f64] {
        &self.configurations[i * self.dof_count..(i + 1) * self.dof_count]
    }

    /// The end effector's world position on frame `i`.
    pub fn end(&self, i: usize) -> Point3<f64> {
        let per = self.points.len() / self.frame_count();
        self.points[i * per + per - 1]
    }

    /// The tracked points (chain joints + end effector) as a trajectory, optionally
    /// without the end effector (when it coincides with the last joint).
    pub fn trajectory(&self, with_end: bool) -> Result<Trajectory> {
        let frames = self.frame_count();
        let per = self.points.len() / frames.max(1);
        let keep = if with_end { per } else { per - 1 };
        let points = self
            .points
            .chunks(per)
            .flat_map(|c| c[..keep].iter().copied())
            .collect();
        Ok(Trajectory::new(self.frame_time, keep, points)?)
    }
}

/// An arm task for the controller: a chain, where its base is, the start posture and the
/// task of its end effector (one reach to synthesize).
#[derive(Debug, Clone)]
pub struct ArmTask<'a> {
    /// The chain (a person's bone lengths and joint limits).
    pub chain: &'a Chain,
    /// The base frames.
    pub base: &'a Base,
    /// The start configuration (clamped into the limits before the first frame).
    pub start: &'a [f64],
    /// The task.
    pub task: Task,
    /// The arm's joint velocity at the start, rad/s per DoF (e.g. a capture's own, where it
    /// starts in motion); `None`: at rest. Only the smooth controller
    /// ([`ControllerSettings::smoothing`]) carries it on: it bounds the first step's change
    /// from it.
    pub start_velocity: Option<&'a [f64]>,
}

/// The synergy controller: an optimizer, a synergy and settings.
#[derive(Debug, Clone)]
pub struct Controller {
    /// Turns the task error into a joint step.
    pub optimizer: Optimizer,
    /// Shapes the step over DoFs and time.
    pub synergy: Synergy,
    /// Frame time, budget, ε, stall rule.
    pub settings: ControllerSettings,
}

/// How the controller treats joint limits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum LimitHandling {
    /// The paper's Θ ← clamp(Θ + Δθ'): a DoF pushed against its limit stays there and the
    /// others do not compensate, so reaches can stall on a limit.
    Clamp,
    /// DoFs on a limit that the step pushes outward are removed from the Jacobian (a swing
    /// on its ellipse keeps its tangent direction and slides along the ellipse) and the step
    /// is solved again with the others (then clamped as above), so the free DoFs carry the
    /// motion on (Baerlocher & Boulic 2004). The default.
    #[default]
    Deactivate,
}

impl Controller {
    /// A controller, with its optimizer and settings validated.
    pub fn new(
        optimizer: Optimizer,
        synergy: Synergy,
        settings: ControllerSettings,
    ) -> Result<Controller> {
        optimizer.validate()?;
        settings.validate()?;
        let mut settings = settings;
        // S_E carries the person's own acceleration and onset: factors on the bounds (× 1
        // for the neutral factors, exactly S_D's controller).
        if let (Some(f), Some(sm)) = (synergy.tempo(), settings.smoothing.as_mut()) {
            *sm = sm.scaled(f);
        }
        Ok(Controller {
            optimizer,
            synergy,
            settings,
        })
    }

    /// Synthesizes the reach frame by frame: frame 0 is the start posture; each frame
    /// computes ΔX, Δθ = O(ΔX), Δθ' = S(t)Δθ at t = frame · frame_time, and Θ ←
    /// clamp(Θ + Δθ'). Ends when the task error is below ε (and `min_frames` exist), the
    /// budget runs out, progress stalls or a step is not finite. Near the reach sphere's edge
    /// Δθ is guided ([`crate::reachability`]) and the stall rule watches the guided error.
    pub fn synthesize(&self, arm: &ArmTask<'_>) -> Result<Synthesis> {
        Ok(self.run(arm, &mut |_| true)?.0)
    }

    /// [`Controller::synthesize`], shown the motion so far after each frame is recorded
    /// (`keep_going(&synthesis)`); it stops and returns `None` as soon as `keep_going` says
    /// `false` — for a caller that scores the motion as it grows, such as the trainer, which
    /// abandons a motion already worse than it could accept. Every frame is computed exactly
    /// as [`Controller::synthesize`] computes it.
    pub fn synthesize_while(
        &self,
        arm: &ArmTask<'_>,
        mut keep_going: impl FnMut(&Synthesis) -> bool,
    ) -> Result<Option<Synthesis>> {
        let (synthesis, abandoned) = self.run(arm, &mut keep_going)?;
        Ok((!abandoned).then_some(synthesis))
    }

    /// The synthesis loop; true beside the motion when `keep_going` stopped it.
    fn run(
        &self,
        arm: &ArmTask<'_>,
        keep_going: &mut dyn FnMut(&Synthesis) -> bool,
    ) -> Result<(Synthesis, bool)> {
        let chain = arm.chain;
        let n = chain.dof_count();
        arm.base.validate()?;
        arm.task.validate()?;
        let mut stepper = self.stepper(chain, arm.start)?;
        if let Some(v) = arm.start_velocity {
            stepper.set_start_velocity(v)?;
        }

        let s = &self.settings;
        let dt = s.frame_time;
        let window = ((s.stall.window / dt).ceil() as usize).max(1);
        let per = chain.joints().len() + 1;
        let mut out = Synthesis {
            frame_time: dt,
            dof_count: n,
            configurations: Vec::with_capacity(n * s.max_frames.min(4096)),
            points: Vec::with_capacity(per * s.max_frames.min(4096)),
            stop: StopReason::MaxFrames,
            final_error: f64::INFINITY,
        };
        // The task error of every frame so far.
        let mut errors: Vec<f64> = Vec::with_capacity(s.max_frames.min(4096));
        let mut frame = 0;
        loop {
            let seen = stepper.observe(arm.base.at(frame), &arm.task)?;
            let e = seen.error;
            if !e.is_finite() {
                out.stop = StopReason::NonFinite;
                break;
            }
            out.configurations.extend_from_slice(&stepper.q);
            out.points.extend_from_slice(&stepper.lin.joints);
            out.points.push(stepper.lin.end);
            out.final_error = e;
            if !keep_going(&out) {
                return Ok((out, true));
            }
            errors.push(seen.progress);
            let frames = frame + 1;
            let long_enough = frames >= s.min_frames;
            if e < s.tolerance && long_enough {
                out.stop = StopReason::Reached;
                break;
            }
            if frames >= s.max_frames {
                out.stop = StopReason::MaxFrames;
                break;
            }
            // The smooth controller does not stall before its finish is over, nor while the
            // arm still turns back under its acceleration bound: a DoF that moved on by more
            // than COASTING rad/s over the stall window (its net motion: an arm chattering on
            // a limit, a few hundredths of a radian back and forth, is not coasting).
            let settled = match &s.smoothing {
                Some(sm) => {
                    frame as f64 * dt >= sm.finished_at() + s.stall.window
                        && (frame < window
                            || !coasting(&out.configurations, frame, window, COASTING * dt))
                }
                None => true,
            };
            if long_enough
                && settled
                && frame >= window
                && arm.base.is_still_from(frame - window)
                && errors[frame - window]
                    - errors[frame - window + 1..=frame]
                        .iter()
                        .fold(f64::INFINITY, |a, &b| a.min(b))
                    < s.stall.min_progress
            {
                out.stop = StopReason::Stalled;
                break;
            }
            if !stepper.advance() {
                out.stop = StopReason::NonFinite;
                break;
            }
            frame += 1;
        }
        Ok((out, false))
    }

    /// The controller run one frame at a time ([`ArmStepper`]) on `chain` from `start`
    /// (clamped into the limits): for a caller that moves the chain's base itself, frame by
    /// frame, such as a full-body character whose trunk a scheduler moves. [`Controller::
    /// synthesize`] is this stepper with its stop rules.
    ///
    /// The stepper borrows the controller and the chain (a fit synthesizes thousands of
    /// times: nothing is copied); [`ArmStepper::into_owned`] keeps them for longer.
    pub fn stepper<'c>(&'c self, chain: &'c Chain, start: &[f64]) -> Result<ArmStepper<'c>> {
        let n = chain.dof_count();
        if start.len() != n {
            return Err(kinergy_motion::MotionError::PoseLength {
                expected: n,
                found: start.len(),
            }
            .into());
        }
        if self.synergy.dof_count() != n {
            return Err(SolverError::Setting(InvalidSetting::new(
                "synergy",
                format!(
                    "made for {} DoFs, the chain has {n}",
                    self.synergy.dof_count()
                ),
            )));
        }
        if !start.iter().all(|v| v.is_finite()) {
            return Err(SolverError::NonFinite("the start posture".into()));
        }
        let mut q = start.to_vec();
        chain.clamp(&mut q);
        Ok(ArmStepper {
            controller: Cow::Borrowed(self),
            chain: Cow::Borrowed(chain),
            sphere: ReachSphere::of(chain),
            q,
            lin: Linearization::default(),
            scratch: StepScratch::default(),
            step: vec![0.0; n],
            smoother: self.settings.smoothing.map(|_| Smoother::new(n)),
            locks: vec![Lock::Free; n],
            frame: 0,
            pending: None,
        })
    }
}

/// The synergy controller one frame at a time, on a base the caller moves (made by
/// [`Controller::stepper`]). Each frame the caller says where the base is
/// ([`ArmStepper::observe`]: the task error of the current configuration there), then
/// [`ArmStepper::advance`]s it: Θ ← clamp(Θ + S(t)·O(ΔX)) at t = frame · frame_time — exactly
/// the step of [`Controller::synthesize`], which is built on it. The stop rules are the
/// caller's.
#[derive(Debug, Clone)]
pub struct ArmStepper<'c> {
    controller: Cow<'c, Controller>,
    chain: Cow<'c, Chain>,
    sphere: Option<ReachSphere>,
    q: Vec<f64>,
    lin: Linearization,
    scratch: StepScratch,
    step: Vec<f64>,
    /// The smooth controller's memory of the previous frame ([`ControllerSettings::
    /// smoothing`]).
    smoother: Option<Smoother>,
    locks: Vec<Lock>,
    frame: usize,
    /// The last observation's task error and guidance, for the next advance.
    pending: Option<(crate::task::TaskError, Option<Guidance>)>,
}

/// What [`ArmStepper::observe`] sees on a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// The task error's norm (meters for a position task).
    pub error: f64,
    /// The error the stall rule watches: the guided error near the reach sphere's edge, the
    /// task error elsewhere.
    pub progress: f64,
}

impl ArmStepper<'_> {
    /// The stepper owning its controller and chain (copied once), to keep beyond them.
    pub fn into_owned(self) -> ArmStepper<'static> {
        ArmStepper {
            controller: Cow::Owned(self.controller.into_owned()),
            chain: Cow::Owned(self.chain.into_owned()),
            sphere: self.sphere,
            q: self.q,
            lin: self.lin,
            scratch: self.scratch,
            step: self.step,
            smoother: self.smoother,
            locks: self.locks,
            frame: self.frame,
            pending: self.pending,
        }
    }

    /// The current configuration.
    pub fn configuration(&self) -> &[f64] {
        &self.q
    }

    /// Frames advanced so far.
    pub fn frame(&self) -> usize {
        self.frame
    }

    /// The chain the stepper moves.
    pub fn chain(&self) -> &Chain {
        &self.chain
    }

    /// Replaces the configuration (clamped into the limits), e.g. after the caller clamped
    /// the arm into limits of its own; the next frame steps from there.
    pub fn set_configuration(&mut self, q: &[f64]) {
        if q.len() == self.q.len() && q.iter().all(|v| v.is_finite()) {
            self.q.copy_from_slice(q);
            self.chain.clamp(&mut self.q);
            self.pending = None;
        }
    }

    /// The arm's joint velocity before the first frame, rad/s per DoF (rest by default): the
    /// smooth controller bounds the first step's change from it; the paper's ignores it.
    pub fn set_start_velocity(&mut self, velocity: &[f64]) -> Result<()> {
        if velocity.len() != self.q.len() {
            return Err(kinergy_motion::MotionError::PoseLength {
                expected: self.q.len(),
                found: velocity.len(),
            }
            .into());
        }
        if !velocity.iter().all(|v| v.is_finite()) {
            return Err(SolverError::NonFinite("the start velocity".into()));
        }
        let dt = self.controller.settings.frame_time;
        if let Some(state) = &mut self.smoother {
            let step: Vec<f64> = velocity.iter().map(|v| v * dt).collect();
            state.set_start_step(&self.chain, &self.q, &step);
        }
        Ok(())
    }

    /// The task error of the current configuration with the chain's base at `base`; keeps
    /// what the next [`ArmStepper::advance`] needs.
    pub fn observe(&mut self, base: &IsometryMatrix3<f64>, task: &Task) -> Result<Observation> {
        // The smooth controller placed the hand at this configuration on the last frame: its
        // sines and cosines are known (the same bits).
        match &mut self.smoother {
            Some(state) => {
                self.chain
                    .linearize_memo_into(base, &self.q, &mut self.lin, &mut state.trig)?
            }
            None => self.chain.linearize_into(base, &self.q, &mut self.lin)?,
        }
        let error = task.error(&self.lin);
        let e = error.norm();
        // Near the reach sphere's edge the controller guides the step (see `reachability`),
        // and the stall rule watches the guided error.
        let guidance = match (&self.sphere, task) {
            (Some(sphere), Task::Position(t)) => sphere.guide(
                &self.q,
                &self.lin,
                t,
                &base.rotation,
                Pace {
                    optimizer: &self.controller.optimizer,
                    dt: self.controller.settings.frame_time,
                },
                self.straight_arm(),
            ),
            _ => None,
        };
        let progress = guidance.as_ref().map_or(e, Guidance::progress);
        self.pending = Some((error, guidance));
        Ok(Observation { error: e, progress })
    }

    /// How the guidance reads a near-straight arm on this frame ([`StraightArm`]).
    fn straight_arm(&self) -> StraightArm {
        match &self.controller.settings.smoothing {
            None => StraightArm::Ignored,
            Some(sm) => {
                let t = self.frame as f64 * self.controller.settings.frame_time;
                if sm.finish.is_some() && sm.finish_weight(t) >= 1.0 {
                    StraightArm::FromHinge
                } else {
                    StraightArm::FromDistance
                }
            }
        }
    }

    /// Δθ' = S(t)·O(ΔX) for the current frame; with [`LimitHandling::Deactivate`], solved
    /// again under the limits the step pushes against until it pushes against none: a
    /// revolute DoF on its limit is removed; a swing on its ellipse first keeps only its
    /// tangent direction (it slides along the ellipse), and is removed only if the synergy
    /// still pushes it outward.
    fn limited_step(
        &mut self,
        error: &crate::task::TaskError,
        guidance: Option<&Guidance>,
        t: f64,
    ) {
        // The stepper's fields borrowed apart: the controller, chain and configuration read,
        // the frame's linearization, scratch, step and locks written.
        let controller: &Controller = &self.controller;
        let (chain, q): (&Chain, &[f64]) = (&self.chain, &self.q);
        let (lin, scratch) = (&mut self.lin, &mut self.scratch);
        let (step, locks): (&mut [f64], &mut [Lock]) = (&mut self.step, &mut self.locks);
        let dt = controller.settings.frame_time;
        locks.fill(Lock::Free);
        let guided;
        let error = match guidance {
            Some(g) => {
                g.hand_over(lin);
                guided = g.optimizer_error();
                &guided
            }
            None => error,
        };
        loop {
            controller.optimizer.step(lin, error, dt, scratch, step);
            if let Some(g) = guidance
                && locks[g.hinge()] != Lock::Blocked
            {
                g.drive(lin, step);
            }
            // A sliding swing's first column holds the tangent direction: its step is the
            // coefficient u along it.
            for k in 0..locks.len() {
                if let Lock::Slide(t0, t1) = locks[k] {
                    let u = step[k];
                    step[k] = u * t0;
                    step[k + 1] = u * t1;
                }
            }
            // The plain step of the progress floor and the finish (the smooth controller's
            // only), without the DoFs a zero gain freezes (they stay frozen).
            if controller.settings.smoothing.is_some() {
                scratch.raw.clear();
                scratch.raw.extend(step.iter().enumerate().map(|(i, v)| {
                    if controller.synergy.gain(i) == 0.0 {
                        0.0
                    } else {
                        *v
                    }
                }));
            }
            controller.synergy.apply(t, step);
            if let Some(sm) = &controller.settings.smoothing {
                let beta = sm.finish_weight(t);
                if beta > 0.0 {
                    for (s, r) in step.iter_mut().zip(&scratch.raw) {
                        *s = (1.0 - beta) * *s + beta * r;
                    }
                }
            }
            if controller.settings.limits == LimitHandling::Clamp
                || !lock_limits(chain, q, step, locks, lin)
            {
                break;
            }
        }
        if let Some(sm) = &controller.settings.smoothing {
            progress_floor(lin, &error.linear, &scratch.raw, step, sm.progress_floor);
        }
        for (s, _) in step
            .iter_mut()
            .zip(locks.iter())
            .filter(|(_, l)| **l == Lock::Blocked)
        {
            *s = 0.0;
        }
    }

    /// One frame's step from the last observation: Θ ← clamp(Θ + S(t)·O(ΔX)). False (and
    /// the configuration unchanged) when the step is not finite or nothing was observed.
    pub fn advance(&mut self) -> bool {
        let Some((error, guidance)) = self.pending.take() else {
            return false;
        };
        let t = self.frame as f64 * self.controller.settings.frame_time;
        self.limited_step(&error, guidance.as_ref(), t);
        if !self.step.iter().all(|v| v.is_finite()) {
            return false;
        }
        // Only the smooth controller needs the previous frame's motion: the paper's controller
        // does no extra work.
        if let (Some(sm), Some(state)) = (&self.controller.settings.smoothing, &mut self.smoother) {
            let dt = self.controller.settings.frame_time;
            state.limit(
                &self.chain,
                &self.q,
                &mut self.step,
                sm,
                Frame {
                    error: error.linear.norm(),
                    t,
                    dt,
                },
            );
            state.begin(&self.q);
        }
        for (qi, d) in self.q.iter_mut().zip(&self.step) {
            *qi += d;
        }
        clamp_moved(&self.chain, &mut self.q, &self.step);
        if let Some(state) = &mut self.smoother {
            state.record(&self.chain, &self.q);
        }
        self.frame += 1;
        true
    }
}

/// Adds to `step` the least share μ ≥ 0 of the plain optimizer's `raw` step that makes the
/// hand close at least `floor` × what `raw` alone would: (J·step)·e ≥ floor·(J·raw)·e, J the
/// (limit-adjusted) Jacobian of `lin`, e the error the optimizer saw.
fn progress_floor(
    lin: &Linearization,
    e: &Vector3<f64>,
    raw: &[f64],
    step: &mut [f64],
    floor: f64,
) {
    let progress = |d: &[f64]| {
        d.iter()
            .enumerate()
            .map(|(k, dk)| lin.linear.column(k).dot(e) * dk)
            .sum::<f64>()
    };
    let p0 = progress(raw);
    if p0 > 0.0 {
        let mu = floor - progress(step) / p0;
        if mu > 0.0 {
            for (s, r) in step.iter_mut().zip(raw) {
                *s += mu * r;
            }
        }
    }
}

/// The smooth controller's arm still coasts while a DoF moves on faster than this, rad/s
/// (net over the stall window).
pub(crate) const COASTING: f64 = 0.05;

/// True when some DoF of the configurations (`n` = their count per frame, frames stacked)
/// moved by more than `per_frame · window` from frame `frame − window` to `frame`.
fn coasting(configurations: &[f64], frame: usize, window: usize, per_frame: f64) -> bool {
    let n = configurations.len() / (frame + 1);
    let now = &configurations[frame * n..(frame + 1) * n];
    let then = &configurations[(frame - window) * n..(frame - window + 1) * n];
    now.iter()
        .zip(then)
        .any(|(a, b)| (a - b).abs() > per_frame * window as f64)
}
