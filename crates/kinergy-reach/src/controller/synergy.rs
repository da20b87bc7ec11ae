//! The reaching arm driven by a person's synergy controller (Aubry et al.; issue 16) instead
//! of the speed profile and the analytic IK: the scheduler moves the body as always, and each
//! frame the person's controller takes one step toward the target from where the trunk has
//! carried the shoulder ([`kinergy_solver::ArmStepper`]) — the same step a fit replays on a
//! captured torso.
//!
//! # Conventions
//! The person's parameters were fitted on [`kinergy_solver::CaptureArm`]'s chain, whose base
//! rides the clavicle with z pointing sideways out of the shoulder, y up and x = y × z (at
//! rest) — its zero swing is the arm raised sideways. The character's own arm chain (the same
//! [`kinergy_motion::Chain::arm`], same bone lengths) has its base turned so that its zero is
//! the hanging arm. Both bases ride the clavicle, so one constant rotation `K` (character
//! base → capture base) relates them: the controller runs in the capture convention, on the
//! base `R_character · K`, and its shoulder rotation is carried over as
//! `R_character_shoulder = K · R_capture_shoulder` (split again into swing and twist); elbow
//! and wrist DoFs are the same in both.
//!
//! # Limits
//! The character's limits are the character's: a configuration the controller reaches is
//! clamped into them, and the controller continues from the clamped arm. The controller's own
//! chain (`synergy_chain`) has the character's elbow and wrist limits but bounds the shoulder
//! only away from its convention's singular swing of π (the arm across the chest), its twist
//! open to ±π: the generic table's shoulder limits read in the capture convention are not the
//! character's anatomical ones (the hanging arm sits on their ±90° twist, and every raise turns
//! it further), and the character's humerothoracic limits ([`crate::character::girdle`]) clamp
//! the arm anyway. The synergy arm has arrived when the
//! hand is within half the reach's tolerance.
//!
//! # Hand-over
//! Where the synergy arm alone cannot finish — its progress stalls for [`STALL_WINDOW`]
//! seconds once the body has stopped, its step is not finite, or [`SYNERGY_TIME`] seconds
//! pass — plain inverse kinematics takes the hand the last centimeters from the posture the
//! synergy left: the same controller with damped least squares and no synergy (every gain 1,
//! no timing), so the arm keeps its posture and only closes the gap. (The analytic IK's
//! solution for the target can lie far from that posture in joint space: going there, the
//! hand of a real capture's synergy swung 0.99 m away before coming back.) Only if plain IK
//! stalls too, or drives more than a second, does the analytic IK finish (in the character's
//! own limits). The report says when, from how far and who finished ([`super::HandOver`]).

use std::ops::Range;

use kinergy_motion::{Chain, Side};

use kinergy_motion::limbs::ArmJoints;
use kinergy_motion::nalgebra::{IsometryMatrix3, Point3, Rotation3, Vector3};
use kinergy_motion::rotation::{swing_rotation, swing_twist, unwrap_near};
use kinergy_solver::{
    ArmStepper, BaseMode, CaptureArm, Controller, ControllerSettings, Optimizer, OptimizerKind,
    PersonTempo, Smoothing, StallRule, Synergy, Task, widen_to_include,
};

use super::report::ArmDriveKind;
use crate::character::{Character, GirdleTurn, Limb, Pose, angle_difference};
use crate::error::{ReachError, Result};

/// How long (seconds) the synergy arm's progress may stall, once the body has stopped,
/// before the analytic IK takes over.
pub const STALL_WINDOW: f64 = 0.25;

/// The least progress (meters) over [`STALL_WINDOW`] that is not a stall.
pub const STALL_PROGRESS: f64 = 1e-4;

/// The longest the synergy arm drives (seconds after it started) before the analytic IK
/// takes over.
pub const SYNERGY_TIME: f64 = 4.0;

/// The longest plain inverse kinematics drives after a hand-over (seconds) before the
/// analytic IK finishes.
pub const PLAIN_IK_TIME: f64 = 1.0;

/// The elbow flexion the synergy starts from at least, radians.
pub const RELAXED_ELBOW: f64 = 0.17;

/// What drives the reaching arm.
#[derive(Debug, Clone, Default, PartialEq)]
pub enum ArmDrive {
    /// The speed profile of [`super::ReachSettings::profile`] along the straight line to the
    /// target, the arm solved by analytic IK every frame (Huang et al.).
    #[default]
    Profile,
    /// A person's synergy controller: their optimizer and synergy (model and values), as a
    /// parameters file holds them ([`kinergy_solver::ParamsFile::synergy_for`] with
    /// [`arm_dof_names`]).
    Synergy {
        /// Turns the task error into a joint step.
        optimizer: Optimizer,
        /// The person's synergy.
        synergy: Synergy,
        /// The person's tempo over their fitted reaches ([`kinergy_solver::FitRecord::tempo`]):
        /// the smooth controller's bounds are those of a reach of theirs over the hand's
        /// distance. `None` (files without it): a reach peaking at 1 m/s (`SYNERGY_PEAK_SPEED`)
        /// or the profile's peak, whichever is faster.
        tempo: Option<PersonTempo>,
    },
}

impl ArmDrive {
    /// Which drive, without its values: what a report says.
    pub fn kind(&self) -> ArmDriveKind {
        match self {
            ArmDrive::Profile => ArmDriveKind::Profile,
            ArmDrive::Synergy { .. } => ArmDriveKind::Synergy,
        }
    }

    /// `profile` or `synergy`.
    pub fn name(&self) -> &'static str {
        self.kind().name()
    }
}

/// The DoF names of the character's arm chain (the same as a captured arm's), in order: what
/// a parameters file's `dof_names` must be.
pub fn arm_dof_names(character: &Character) -> Vec<String> {
    character
        .limb_chain(Limb::RightArm)
        .dof_names()
        .map(String::from)
        .collect()
}

/// `K`, the rotation from the character's base of `limb` to the capture-convention base a fit
/// of the character's own motion would use: made exactly as the fit makes it, by a
/// [`CaptureArm`] on the exported rest posture (both bases ride the clavicle, so `K` holds
/// on every frame).
fn capture_rotation(character: &Character, limb: Limb, rest: &Pose) -> Result<Rotation3<f64>> {
    let capture_base = captured_arm(character, limb, rest)?
        .base(BaseMode::Fixed)
        .at(0)
        .rotation;
    let character_base = character.limb_base_frame(limb, rest).rotation;
    Ok(character_base.inverse() * capture_base)
}

/// The [`CaptureArm`] a fit makes of `limb` in a one-frame export of `pose`.
fn captured_arm(character: &Character, limb: Limb, pose: &Pose) -> Result<CaptureArm> {
    let setting = |why: String| ReachError::Setting {
        field: "character".into(),
        why,
    };
    let clip = character.to_clip(std::slice::from_ref(pose), 1.0 / 60.0)?;
    let joints =
        ArmJoints::find(clip.skeleton(), limb.side()).map_err(|e| setting(e.to_string()))?;
    CaptureArm::new(&clip, &joints).map_err(|e| setting(e.to_string()))
}

/// The base frame of the arm on `side` at rest, as a fit of the character's motion defines
/// it ([`kinergy_solver::CaptureArm`]: at the shoulder, z out of it sideways, y up, x = y ×
/// z): the frame a parameter field's targets are given in.
pub fn fitted_base_at_rest(character: &Character, side: Side) -> Result<IsometryMatrix3<f64>> {
    let limb = Limb::arm(side);
    let rest = character.rest_pose();
    let k = capture_rotation(character, limb, &rest)?;
    let base = character.limb_base_frame(limb, &rest);
    Ok(IsometryMatrix3::from_parts(
        base.translation,
        base.rotation * k,
    ))
}

/// The arm of `limb` in `pose` as a fit of the exported motion reads it: [`CaptureArm`]'s
/// configuration of the arm's joint positions, in the capture convention.
#[cfg(test)]
fn read_as_captured(character: &Character, limb: Limb, pose: &Pose) -> Result<Vec<f64>> {
    Ok(captured_arm(character, limb, pose)?.start().to_vec())
}

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

impl SynergyArm {
    /// The synergy arm of `limb` toward `target`, starting from the arm of `pose` (the frame
    /// the arm controller starts on), at `frame_time`. `rest` is the character's rest posture
    /// (it fixes the rotation between the character's arm base and the fitted one). The elbow
    /// starts flexed at least [`RELAXED_ELBOW`]. `smoothing`: the smooth controller's bounds
    /// ([`reach_smoothing`] for a planned reach), `None` for the paper's controller. The arm
    /// starts at rest.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        character: &Character,
        limb: Limb,
        rest: &Pose,
        pose: &Pose,
        target: Point3<f64>,
        optimizer: &Optimizer,
        synergy: &Synergy,
        frame_time: f64,
        smoothing: Option<Smoothing>,
        start: Option<&super::SynergyStart>,
    ) -> Result<SynergyArm> {
        let setting = |e: kinergy_solver::SolverError| ReachError::Setting {
            field: "params".into(),
            why: e.to_string(),
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
        let setting = |e: kinergy_solver::SolverError| ReachError::Setting {
            field: "hand-over".into(),
            why: e.to_string(),
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
            .map_err(|e| ReachError::Setting {
                field: "params".into(),
                why: e.to_string(),
            })?;
        self.progress.push(seen.progress);
        if !seen.error.is_finite() || !self.stepper.advance() {
            return Ok(None);
        }
        self.history.extend_from_slice(self.stepper.configuration());
        // The distance of the arm shown (the controller's own chain clamps into its own
        // limits, which can leave its arm a little off the character's).
        let shown =
            self.stepper
                .chain()
                .end_position(base, &q)
                .map_err(|e| ReachError::Setting {
                    field: "character.arm".into(),
                    why: e.to_string(),
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

/// The shoulder elevation (radians from the hanging arm) above which the synergy arm's twist
/// does not brake before the character's twist limits: where the character's twist range
/// starts to widen ([`crate::character::OVERHEAD_TWIST_FROM`]), toward the arm straight up,
/// where the twist coordinate is singular (it moves by a lot for a small turn of the arm).
/// Braking the twist higher up held a person's overhead style back: Bandai *active*'s vector
/// fitted on takes 1–6 (`--budget 800 --seed 1`) drove `style` on all 8 takes to r 0.66 with
/// 1 hand-over braking below 90°, 0.32 with 2 braking below 150° (0.56 with 1 without the
/// brake). Braked at every elevation, the twist made high reaches chatter (`synth --params
/// tests/data/params/synthetic-p01-r09-sc.json`: 3 of 56 clips with speed jumps, 36 on
/// p02/r05); never braked, 3 of the `reach` grid's 20 person-synergy reaches kept a jump;
/// braked below 90°, 1 clip (as without the brake) and no grid reach.
pub const TWIST_BRAKE_BELOW: f64 = crate::character::OVERHEAD_TWIST_FROM;

/// Moves `q` (the arm the controller steps to, character DoFs) back toward `before` (the last
/// frame's) where a DoF heads for the character's `limits` faster than √(`a`·gap), over frames
/// of `dt` seconds: it stops in the gap at half the joint acceleration `a` (the margin the
/// analytic arm's brake keeps, `controller::arm`), a revolute DoF toward either end of its range, a
/// swing radially toward its ellipse.
fn brake_before_limits(
    limits: &[crate::character::DofLimit; 7],
    before: &[f64; 7],
    q: &mut [f64; 7],
    a: f64,
    dt: f64,
) {
    use crate::character::DofLimit;
    let mut i = 0;
    while i < 7 {
        match limits[i] {
            DofLimit::Revolute { min, max } => {
                let v = angle_difference(q[i], before[i]) / dt;
                let up = (a * (max - before[i]).max(0.0)).sqrt();
                let down = (a * (before[i] - min).max(0.0)).sqrt();
                let braked = v.clamp(-down, up);
                if braked != v {
                    q[i] = before[i] + braked * dt;
                }
            }
            DofLimit::Swing { rx, ry } if i + 1 < 7 => {
                let (sx, sy) = (before[i], before[i + 1]);
                let rho = (sx / rx).hypot(sy / ry);
                let norm = sx.hypot(sy);
                if rho > 0.0 && norm > 1e-9 {
                    let (ox, oy) = (sx / norm, sy / norm);
                    let gap = norm * (1.0 / rho - 1.0).max(0.0);
                    let (vx, vy) = ((q[i] - sx) / dt, (q[i + 1] - sy) / dt);
                    let excess = vx * ox + vy * oy - (a * gap).sqrt();
                    if excess > 0.0 {
                        q[i] -= excess * ox * dt;
                        q[i + 1] -= excess * oy * dt;
                    }
                }
                i += 1;
            }
            _ => {}
        }
        i += 1;
    }
}

/// The smooth controller's bounds ([`Smoothing::for_reach`]) for the synergy arm of `limb`
/// on a reach planned to peak at `peak_speed` m/s over `duration` seconds (the reach's speed
/// profile): the hand starts from rest and its acceleration is bounded as the profile's is,
/// so the first frames have no speed spike.
pub fn reach_smoothing(
    character: &Character,
    limb: Limb,
    peak_speed: f64,
    duration: f64,
) -> Smoothing {
    let a = character.proportions().arm(limb.side());
    Smoothing::for_reach(peak_speed, duration, a.upper_arm + a.forearm + a.hand)
}

/// The chain the synergy arm of `limb` steps, in the capture convention, from `start`
/// (module docs, "Limits"): the character's bones, elbow and wrist limits (the same DoFs in
/// both conventions); the shoulder [open](kinergy_solver::capture::open_shoulder) (its swing
/// bounded only by [`kinergy_solver::capture::OPEN_SHOULDER_SWING`], its twist open to ±π), widened to include `start`. The shoulder's anatomical limits are the
/// character's (humerothoracic, [`crate::character::girdle`]), which clamp the arm every frame.
/// The generic table's ±90° twist and 130° × 100° ellipse, read in the capture convention, put
/// the hanging arm on the twist limit (left arm −90°, right arm +90°) and held every raise
/// there: on the left arm an overhead raise stopped 0.42 m short with the character's own
/// twist at 55° of its ±90°; on the right arm (the twist was opened on the left arm's side
/// only) a high reach drove the character's twist onto its −90° limit while the synergy's sat
/// on its +90°, both clamped frame after frame (`synth --params`: 14 of 56 clips with speed
/// jumps; 1 with the twist open both ways).
///
/// A fit reads a capture on the table's chain widened to include the captured motion
/// ([`CaptureArm`]), the person's own range: a clip this arm turned past the table's twist is
/// fitted with that DoF's limit at its captured peak, unless the segments file says the
/// motion was made by this arm (its tempo given: [`CaptureArm::with_open_shoulder`]).
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

/// The character's arm convention and the fitted (capture) one (module docs,
/// "Conventions"): the capture base is the character's base turned by the girdle's turn
/// `G̃(q)` of the clavicle ([`GirdleTurn`]) and the constant `K` between the two at rest; the
/// shoulder rotations relate as `R_character = G̃(q) · K · R_capture`, the elbow and wrist DoFs
/// are the same.
#[derive(Debug, Clone, Copy)]
struct Conventions {
    /// Character base → capture base at rest.
    k: Rotation3<f64>,
    /// The girdle's turn of the base.
    girdle: GirdleTurn,
}

impl Conventions {
    /// The conventions of `limb`, `K` from the character's `rest` posture.
    fn new(character: &Character, limb: Limb, rest: &Pose) -> Result<Conventions> {
        Ok(Conventions {
            k: capture_rotation(character, limb, rest)?,
            girdle: character.girdle_turn(limb),
        })
    }

    /// Character base → capture base for the character's arm `q`: `G̃(q) · K`.
    fn base_turn(self, q: &[f64]) -> Rotation3<f64> {
        self.girdle.in_base(q) * self.k
    }

    /// The capture-convention arm `q` (shoulder swing x, y, twist; elbow, wrist) as the
    /// character's DoFs, the twist unwrapped near `twist`. The girdle's turn depends on the
    /// character's arm itself: a fixed point, contracting by the rhythm's slope (≤ 0.3 a
    /// step), to 1e-14 rad.
    fn to_character(self, q: &[f64], twist: f64) -> [f64; 7] {
        self.to_character_from(q, twist, &Rotation3::identity()).0
    }

    /// [`Conventions::to_character`] with the fixed point started from the girdle's turn
    /// `turn` (the previous frame's: a frame's arm moves little, so a few passes do); also
    /// returns the girdle's turn it ended on.
    fn to_character_from(
        self,
        q: &[f64],
        twist: f64,
        turn: &Rotation3<f64>,
    ) -> ([f64; 7], Rotation3<f64>) {
        let captured = self.k
            * swing_rotation(q[0], q[1])
            * Rotation3::from_axis_angle(&Vector3::z_axis(), q[2]);
        let mut turn = *turn;
        let mut shoulder = turn * captured;
        for _ in 0..60 {
            let (sx, sy, _) = swing_twist(&shoulder);
            let next_turn = self.girdle.in_base(&[sx, sy]);
            let moved = next_turn.angle_to(&turn);
            turn = next_turn;
            shoulder = turn * captured;
            if moved < 1e-14 {
                break;
            }
        }
        let (sx, sy, tau) = swing_twist(&shoulder);
        let mut out = [0.0; 7];
        out[0] = sx;
        out[1] = sy;
        out[2] = unwrap_near(tau, twist);
        out[3..].copy_from_slice(&q[3..7]);
        (out, turn)
    }

    /// The character's arm DoFs `q` in the capture convention.
    fn to_capture(self, q: &[f64; 7]) -> Vec<f64> {
        let shoulder = self.base_turn(q).inverse()
            * swing_rotation(q[0], q[1])
            * Rotation3::from_axis_angle(&Vector3::z_axis(), q[2]);
        let (sx, sy, tau) = swing_twist(&shoulder);
        let mut out = vec![sx, sy, tau];
        out.extend_from_slice(&q[3..]);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn character() -> Character {
        Character::from_height(1.75).expect("character")
    }

    /// The capture-convention chain on the capture base puts every arm point where the
    /// character's chain on its own base does, for arms in many postures (an independent
    /// check of K and of both conversions).
    #[test]
    fn both_conventions_place_the_arm_alike() {
        let c = character();
        let rest = c.rest_pose();
        for limb in [Limb::RightArm, Limb::LeftArm] {
            let conventions = Conventions::new(&c, limb, &rest).expect("K");
            let chain = c.limb_chain(limb);
            let mut pose = rest;
            for (i, q) in [
                [0.0; 7],
                [0.4, -0.3, 0.2, 0.9, 0.1, 0.2, -0.1],
                [-0.8, 0.5, -0.6, 1.4, -0.3, -0.4, 0.2],
                [1.2, 0.9, 1.0, 0.3, 0.5, 0.0, 0.1],
            ]
            .into_iter()
            .enumerate()
            {
                pose[3] = 0.1 * i as f64;
                pose[10] = -0.2 * i as f64;
                let base = c.limb_base_frame(limb, &pose);
                let capture_base = IsometryMatrix3::from_parts(
                    base.translation,
                    base.rotation * conventions.base_turn(&q),
                );
                let qc = conventions.to_capture(&q);
                let ours = chain.fk(&base, &q).expect("fk");
                let theirs = chain.fk(&capture_base, &qc).expect("fk");
                for (a, b) in ours.frames.iter().zip(&theirs.frames) {
                    let moved = (a.translation.vector - b.translation.vector).norm();
                    let turned = (a.rotation.matrix() - b.rotation.matrix()).norm();
                    assert!(moved < 1e-12 && turned < 1e-9, "{limb:?} {q:?}: {a} vs {b}");
                }
                assert!((ours.end - theirs.end).norm() < 1e-12);
                let back = conventions.to_character(&qc, q[2]);
                for (a, b) in back.iter().zip(&q) {
                    assert!((a - b).abs() < 1e-9, "{limb:?}: {back:?} vs {q:?}");
                }
            }
        }
    }

    /// At rest the character's hanging arm is, in the capture convention, the arm hanging
    /// down: its upper arm along −y of the capture base.
    #[test]
    fn the_hanging_arm_hangs_in_the_capture_convention_too() {
        let c = character();
        let rest = c.rest_pose();
        for limb in [Limb::RightArm, Limb::LeftArm] {
            let conventions = Conventions::new(&c, limb, &rest).expect("K");
            let k = conventions.k;
            let q = conventions.to_capture(&[0.0; 7]);
            let upper = swing_rotation(q[0], q[1])
                * Rotation3::from_axis_angle(&Vector3::z_axis(), q[2])
                * Vector3::z();
            assert!((upper - -Vector3::y()).norm() < 1e-9, "{limb:?}: {upper}");
            // A fit of the exported motion reads the same arm (the straight arm's twist aside:
            // not in its positions): every joint in the same place.
            let read = read_as_captured(&c, limb, &rest).expect("read");
            let base = c.limb_base_frame(limb, &rest);
            let capture_base = IsometryMatrix3::from_parts(base.translation, base.rotation * k);
            let chain = c.limb_chain(limb);
            let ours = chain.fk(&capture_base, &q).expect("fk");
            let theirs = chain.fk(&capture_base, &read).expect("fk");
            for (a, b) in ours.frames.iter().zip(&theirs.frames) {
                let d = (a.translation.vector - b.translation.vector).norm();
                assert!(d < 1e-9, "{limb:?}: {read:?} vs {q:?}");
            }
            assert!((ours.end - theirs.end).norm() < 1e-9);
        }
    }

    /// A fit of the exported motion reads a raised arm, whose clavicle the girdle has turned,
    /// as the controller's convention has it: the second frame of a two-frame export
    /// (rest, then the arm raised), read by [`CaptureArm`], is `to_capture` of the arm (the
    /// shoulder's three DoFs and the elbow's flexion: a fit reads joint positions, in which
    /// the forearm's twist and the wrist are not all seen).
    #[test]
    fn a_fit_reads_the_raised_arm_in_the_controllers_convention() {
        let c = character();
        let rest = c.rest_pose();
        for limb in [Limb::RightArm, Limb::LeftArm] {
            let conventions = Conventions::new(&c, limb, &rest).expect("K");
            for q in [
                [1.2, 0.9, 0.4, 0.3, 0.5, 0.0, 0.1],
                [2.4, -0.6, -0.5, 0.8, 0.0, 0.2, -0.1],
                [0.3, 2.6, 0.2, 1.1, 0.1, -0.2, 0.0],
            ] {
                let mut raised = rest;
                raised[c.limb_dofs(limb)].copy_from_slice(&q);
                assert!(c.girdle_turn(limb).in_base(&q).angle() > 0.05, "{q:?}");
                let clip = c.to_clip(&[rest, raised], 1.0 / 60.0).expect("clip");
                let joints = ArmJoints::find(clip.skeleton(), limb.side()).expect("joints");
                let arm = CaptureArm::new(&clip, &joints).expect("arm");
                let read = &arm.captured_configurations()[7..14];
                let ours = conventions.to_capture(&q);
                for (a, b) in read[..4].iter().zip(&ours) {
                    assert!(
                        (a - b).abs() < 1e-6,
                        "{limb:?} {q:?}: read {read:?}, ours {ours:?}"
                    );
                }
                let back = conventions.to_character(&ours, q[2]);
                for (a, b) in back.iter().zip(&q) {
                    assert!((a - b).abs() < 1e-6, "{limb:?}: {back:?} vs {q:?}");
                }
            }
        }
    }
}
