//! The reaching arm on a person's synergy controller, frame by frame ([`SynergyArm`]), and
//! the chain it steps in the capture convention.

use std::ops::Range;

use kinergy_io::InvalidSetting;
use kinergy_motion::Chain;
use kinergy_motion::nalgebra::{IsometryMatrix3, Point3, Rotation3};
use kinergy_solver::{
    ArmStepper, Controller, ControllerSettings, Optimizer, OptimizerKind, Smoothing, StallRule,
    Synergy, Task, widen_to_include,
};

use super::brake::{TWIST_BRAKE_BELOW, brake_before_limits};
use super::conventions::Conventions;
use super::{PLAIN_IK_TIME, RELAXED_ELBOW, STALL_PROGRESS, STALL_WINDOW, SYNERGY_TIME};
use crate::character::{Character, Limb, Pose, angle_difference};
use crate::controller::SynergyStart;
use crate::error::{ReachError, Result};

/// The reaching arm on the person's synergy controller, frame by frame: the full-body
/// scheduler drives it, and so does a plan's final approach (`kinergy-plan`).
///
/// Each frame: [`SynergyArm::pose_arm`] puts the controller's arm into the frame's pose, the
/// caller finishes the frame (body, limits) and [`SynergyArm::end_frame`] lets the controller
/// see the final posture and take its step.
#[derive(Debug, Clone)]
pub struct SynergyArm {
    dofs: Range<usize>,
    stepper: ArmStepper<'static>,
    /// The character's convention and the fitted one.
    conventions: Conventions,
    /// The last twist given to the character's shoulder (unwrapped against it).
    twist: f64,
    /// The smooth controller's bounds (`None`: the paper's controller): plain IK after a
    /// hand-over moves under them too, from the arm's velocity then.
    smoothing: Option<Smoothing>,
    task: Task,
    target: Point3<f64>,
    /// The progress of every frame so far (for the stall rule).
    progress: Vec<f64>,
    /// Frames before which the smooth controller cannot stall: its finish and a stall window
    /// (as [`Controller::synthesize`]'s rule; 0 for the paper's controller).
    settles_after: usize,
    /// The controller's configuration after each frame's step, stacked (the smooth controller
    /// does not stall while a DoF still moves on faster than [`COASTING`], net over the
    /// stall window).
    history: Vec<f64>,
    /// Seconds per frame.
    frame_time: f64,
    /// When the smooth controller's finish blend is over, seconds after the start (0 for the
    /// paper's controller).
    finished_at: f64,
    /// Whether the last frame's posture held the arm off the controller's own step.
    limited: bool,
    /// The girdle's turn of the arm last converted to the character's DoFs.
    turn: Rotation3<f64>,
    /// The last configuration converted to the character's DoFs, and its conversion.
    shown: Option<([f64; 7], [f64; 7])>,
    /// The arm the last frame ended with (character DoFs).
    last: Option<[f64; 7]>,
}

/// A DoF moving on faster than this (rad/s, net over the stall window) is still coasting
/// under the smooth controller's acceleration bound, not stalled (the solver's own stall
/// rule's value; an arm chattering on a limit is not coasting).
const COASTING: f64 = 0.05;

/// A person's controller as a [`SynergyArm`] runs it: their optimizer and synergy (a fit's),
/// stepped every `frame_time` seconds, under the smooth controller's bounds or the paper's.
#[derive(Debug, Clone, Copy)]
pub struct PersonController<'a> {
    /// The person's optimizer.
    pub optimizer: &'a Optimizer,
    /// The person's synergy.
    pub synergy: &'a Synergy,
    /// Seconds per frame.
    pub frame_time: f64,
    /// The smooth controller's bounds ([`reach_smoothing`](super::reach_smoothing) for a
    /// planned reach), `None` for the paper's controller.
    pub smoothing: Option<Smoothing>,
}

impl SynergyArm {
    /// The synergy arm of `limb` toward `target` on the `person`'s controller, starting from the
    /// arm of `pose` (the frame the arm controller starts on). `rest` is the character's rest
    /// posture (it fixes the rotation between the character's arm base and the fitted one). The
    /// elbow starts flexed at least [`RELAXED_ELBOW`]. The arm starts at rest, or as `start`
    /// says.
    pub fn new(
        character: &Character,
        limb: Limb,
        rest: &Pose,
        pose: &Pose,
        target: Point3<f64>,
        person: PersonController<'_>,
        start: Option<&SynergyStart>,
    ) -> Result<SynergyArm> {
        let PersonController {
            optimizer,
            synergy,
            frame_time,
            smoothing,
        } = person;
        let setting = |e: kinergy_solver::SolverError| {
            ReachError::Setting(InvalidSetting::new("params", e.to_string()))
        };
        let settings = ControllerSettings {
            stall: StallRule::default(),
            smoothing,
            ..ControllerSettings::at_frame_time(frame_time)
        };
        let settles_after = smoothing.map_or(0, |sm| {
            ((sm.finished_at() + STALL_WINDOW) / frame_time).ceil() as usize
        });
        let controller = Controller::new(*optimizer, synergy.clone(), settings).map_err(setting)?;
        let conventions = Conventions::new(character, limb, rest)?;
        let dofs = character.limb_dofs(limb);
        let mut q: [f64; 7] = std::array::from_fn(|i| pose[dofs.start + i]);
        q[3] = q[3].max(RELAXED_ELBOW);
        // The arm as it is (a fit of this motion would read a straight arm's twist as 0,
        // which is not in its positions, and start from there: see the README), with the
        // limits widened to include it, as a captured arm's are.
        let given = start;
        let start = match given {
            Some(s) => s.configuration.to_vec(),
            None => conventions.to_capture(&q),
        };
        let chain = synergy_chain(character, limb, &start, given.and_then(|s| s.hand_m))
            .map_err(setting)?;
        let mut stepper = controller
            .stepper(&chain, &start)
            .map_err(setting)?
            .into_owned();
        if let Some(s) = given {
            stepper.set_start_velocity(&s.velocity).map_err(setting)?;
        }
        // The bounds the person's controller moves under (S_E scales them by the person's
        // tempo): the brake before the character's limits and plain IK after a hand-over
        // keep to them too.
        let smoothing = smoothing.map(|sm| synergy.tempo().map_or(sm, |f| sm.scaled(f)));
        Ok(SynergyArm {
            dofs,
            stepper,
            twist: conventions.to_character(&start, q[2])[2],
            smoothing,
            conventions,
            task: Task::Position(target),
            target,
            progress: Vec::new(),
            settles_after,
            history: Vec::new(),
            frame_time,
            finished_at: smoothing.map_or(0.0, |sm| sm.finished_at()),
            limited: false,
            turn: Rotation3::identity(),
            shown: None,
            last: None,
        })
    }

    /// Hands the arm over to plain inverse kinematics (damped least squares, no synergy) from
    /// where it is (module docs); its progress is watched afresh. Under the smooth controller
    /// plain IK keeps its acceleration bounds (at once, no onset; no finish: it is the plain
    /// step already) and starts at the speed the arm moved on the last frame: started at the
    /// plain step's own speed, the hand jumped from 0.25 to 2.5 m/s at the seam.
    pub fn hand_over(&mut self, frame_time: f64) -> Result<()> {
        let setting = |e: kinergy_solver::SolverError| {
            ReachError::Setting(InvalidSetting::new("hand-over", e.to_string()))
        };
        let chain = self.stepper.chain();
        let n = chain.dof_count();
        let smoothing = self.smoothing.map(|sm| Smoothing {
            finish: None,
            onset: 0.0,
            ..sm
        });
        let controller = Controller::new(
            OptimizerKind::Dls.default_optimizer(),
            Synergy::identity(n),
            ControllerSettings {
                smoothing,
                ..ControllerSettings::at_frame_time(frame_time)
            },
        )
        .map_err(setting)?;
        // The arm's velocity over the last frame, in the controller's convention.
        let frames = self.history.len() / n.max(1);
        let velocity: Vec<f64> = if frames >= 2 {
            let now = &self.history[(frames - 1) * n..frames * n];
            let then = &self.history[(frames - 2) * n..(frames - 1) * n];
            now.iter()
                .zip(then)
                .map(|(a, b)| (a - b) / frame_time)
                .collect()
        } else {
            vec![0.0; n]
        };
        let mut stepper = controller
            .stepper(chain, self.stepper.configuration())
            .map_err(setting)?
            .into_owned();
        if smoothing.is_some() {
            stepper.set_start_velocity(&velocity).map_err(setting)?;
        }
        self.stepper = stepper;
        self.progress.clear();
        self.settles_after = 0;
        self.history.clear();
        Ok(())
    }

    /// Puts the controller's current arm into `pose` (character DoFs) of `limb`. The smooth
    /// controller's shoulder and elbow brake before the character's limits at `pose` (its own
    /// chain does not know the shoulder's, module docs "Limits"): a DoF heading for one no
    /// faster than it can stop in the gap at half the controller's joint acceleration, the
    /// shoulder twist only below [`TWIST_BRAKE_BELOW`] of elevation. The clamp stopped such a
    /// DoF within a frame: a speed jump on 4 of the 20 person-synergy reaches of the `reach`
    /// grid (`tests/synergy.rs`), none with the brake (the shoulder alone left one). The
    /// forearm's twist and the wrist do not brake: their limits are the controller's own, and
    /// braking them held the wrist off its synergy near its limits (held-out Bandai *normal*
    /// take 5 then ended its full-body reach with three speed jumps, 1.8 → 0.3 m/s within
    /// 0.1 s). The frames the brake holds the arm off the controller's step are
    /// [limited](SynergyArm::limited).
    pub fn pose_arm(&mut self, character: &Character, limb: Limb, pose: &mut Pose) {
        let mut q = self.shown();
        if let (Some(sm), Some(before)) = (self.smoothing, self.last) {
            let mut limits = character.limb_limits(limb, pose);
            if before[0].hypot(before[1]) > TWIST_BRAKE_BELOW {
                limits[2] = crate::character::DofLimit::Free;
            }
            // The forearm's twist and the wrist have the controller's own limits.
            for l in &mut limits[4..] {
                *l = crate::character::DofLimit::Free;
            }
            brake_before_limits(
                &limits,
                &before,
                &mut q,
                sm.joint_acceleration,
                self.frame_time,
            );
        }
        self.twist = q[2];
        pose[self.dofs.clone()].copy_from_slice(&q);
    }

    /// The controller's current arm in the character's DoFs, computed once per configuration
    /// (the frame's start poses it, its end compares the final posture with it), the girdle's
    /// fixed point started from the last frame's turn.
    fn shown(&mut self) -> [f64; 7] {
        let config = self.stepper.configuration();
        if let Some((at, shown)) = &self.shown
            && at.as_slice() == config
        {
            return *shown;
        }
        let at: [f64; 7] = std::array::from_fn(|i| config.get(i).copied().unwrap_or(0.0));
        let (shown, turn) = self
            .conventions
            .to_character_from(config, self.twist, &self.turn);
        self.turn = turn;
        self.shown = Some((at, shown));
        shown
    }

    /// Ends a frame whose final posture is `pose` (the arm clamped into the character's
    /// limits) with the arm's base at `base` (the character's convention): the controller
    /// continues from the clamped arm, sees this frame's error and takes its step. Returns the
    /// hand–target distance of the arm in `pose`, or `None` when the step was not finite.
    pub fn end_frame(&mut self, pose: &Pose, base: &IsometryMatrix3<f64>) -> Result<Option<f64>> {
        let q: [f64; 7] = std::array::from_fn(|i| pose[self.dofs.start + i]);
        self.last = Some(q);
        let shown = self.shown();
        // A twist a whole turn away is the same arm (`wrap_or_clamp`): not a limit.
        self.limited = q
            .iter()
            .zip(&shown)
            .any(|(a, b)| angle_difference(*a, *b).abs() > 1e-12);
        // The next frame's conversion continues from the twist the character shows.
        self.twist = q[2];
        if self.limited {
            self.stepper
                .set_configuration(&self.conventions.to_capture(&q));
        }
        let capture_base = IsometryMatrix3::from_parts(
            base.translation,
            base.rotation * self.conventions.base_turn(&q),
        );
        let seen = self
            .stepper
            .observe(&capture_base, &self.task)
            .map_err(|e| ReachError::Setting(InvalidSetting::new("params", e.to_string())))?;
        self.progress.push(seen.progress);
        if !seen.error.is_finite() || !self.stepper.advance() {
            return Ok(None);
        }
        self.history.extend_from_slice(self.stepper.configuration());
        // The distance of the arm shown (the controller's own chain clamps into its own
        // limits, which can leave its arm a little off the character's).
        let shown = self.stepper.chain().end_position(base, &q).map_err(|e| {
            ReachError::Setting(InvalidSetting::new("character.arm", e.to_string()))
        })?;
        Ok(Some((shown - self.target).norm()))
    }

    /// Whether the last frame [ended](SynergyArm::end_frame) with the arm off the controller's
    /// own step: the character's limits (or the arm's speed limit) moved it, so the frames
    /// from there on are not the person's synergy alone (a fit of them could not retrace it).
    pub fn limited(&self) -> bool {
        self.limited
    }

    /// How long the synergy drives before the reach hands over to plain IK, seconds:
    /// [`SYNERGY_TIME`], or for the smooth controller, its finish and then [`PLAIN_IK_TIME`]
    /// for the plain optimizer it blends into, if longer (a slow planned reach finishes
    /// late).
    pub fn time_budget(&self) -> f64 {
        SYNERGY_TIME.max(self.finished_at + PLAIN_IK_TIME)
    }

    /// True when, over the last `window` frames, the hand got no closer than
    /// [`STALL_PROGRESS`]: the worst error of the window's first half against the best of its
    /// second half (a limit clamping the arm can make the error jump for a frame; a reach
    /// still closing in is not a stall).
    pub fn stalled(&self, window: usize) -> bool {
        self.stalled_by(window, STALL_PROGRESS)
    }

    /// True when a DoF moved on by more than [`COASTING`] rad/s, net over the last `window`
    /// frames.
    fn coasting(&self, window: usize) -> bool {
        let n = self.stepper.configuration().len();
        let frames = self.history.len() / n.max(1);
        if frames <= window {
            return true;
        }
        let now = &self.history[(frames - 1) * n..frames * n];
        let then = &self.history[(frames - 1 - window) * n..(frames - window) * n];
        let largest = COASTING * self.frame_time * window as f64;
        now.iter().zip(then).any(|(a, b)| (a - b).abs() > largest)
    }

    /// [`SynergyArm::stalled`] with another least progress, meters: a reach that must arrive
    /// closer than [`STALL_PROGRESS`] allows watches for smaller progress.
    pub fn stalled_by(&self, window: usize, min_progress: f64) -> bool {
        let n = self.progress.len();
        if n <= window || window < 2 {
            return false;
        }
        // The smooth controller starts gently and brakes before the target: it is judged
        // once its finish is over, and not while a DoF still coasts.
        if self.settles_after > 0 && (n < self.settles_after || self.coasting(window)) {
            return false;
        }
        let recent = &self.progress[n - window..];
        let (first, second) = recent.split_at(window / 2);
        let worst = first.iter().fold(f64::NEG_INFINITY, |a, &b| a.max(b));
        let best = second.iter().fold(f64::INFINITY, |a, &b| a.min(b));
        worst - best < min_progress
    }
}

/// The chain the synergy arm of `limb` steps, in the capture convention, from `start` ([module
/// docs](super), "Limits"): the character's bones, elbow and wrist limits (the same DoFs in both
/// conventions); the shoulder [open](kinergy_solver::capture::open_shoulder) (its swing bounded
/// only by [`kinergy_solver::capture::OPEN_SHOULDER_SWING`], its twist open to ±π), widened to
/// include `start`. The shoulder's anatomical limits are the character's (humerothoracic,
/// [`crate::character::girdle`]), which clamp the arm every frame. The generic table's ±90° twist
/// and 130° × 100° ellipse, read in the capture convention, put the hanging arm on the twist limit
/// (left arm −90°, right arm +90°) and held every raise there: on the left arm an overhead raise
/// stopped 0.42 m short with the character's own twist at 55° of its ±90°; on the right arm (the
/// twist was opened on the left arm's side only) a high reach drove the character's twist onto its
/// −90° limit while the synergy's sat on its +90°, both clamped frame after frame (`synth
/// --params`: 14 of 56 clips with speed jumps; 1 with the twist open both ways).
///
/// A fit reads a capture on the table's chain widened to include the captured motion
/// ([`CaptureArm`](kinergy_solver::CaptureArm)), the person's own range: a clip this arm turned
/// past the table's twist is fitted with that DoF's limit at its captured peak, unless the segments
/// file says the motion was made by this arm (its tempo given:
/// [`CaptureArm::with_open_shoulder`](kinergy_solver::CaptureArm::with_open_shoulder)).
fn synergy_chain(
    character: &Character,
    limb: Limb,
    start: &[f64],
    hand_m: Option<f64>,
) -> std::result::Result<Chain, kinergy_solver::SolverError> {
    let segments = character.proportions().arm(limb.side());
    let default = Chain::arm(
        segments.upper_arm,
        segments.forearm,
        hand_m.unwrap_or(segments.hand),
    )?;
    let chain = kinergy_solver::capture::open_shoulder(&default)?;
    Ok(widen_to_include(&chain, start)?.0)
}
