//! The full-body reaching controllers and their scheduler (Huang, Kapadia & Terzopoulos §3–4;
//! DESIGN §1.2).
//!
//! A reach is first **planned** from the rest posture — every decision made once, from the
//! seeded generator — then **animated** frame by frame:
//!
//! - **Legs** ([`crate::steps`]): the target's horizontal distance from the reaching
//!   shoulder against the CRR and MRR cylinders decides no step, a half step or a full step
//!   and its length (eq. 9) toward `d_p`; the stepping foot follows the convex foot path,
//!   the root the concave root path (a half step moves the root half the step). Planted feet
//!   stay exactly where they are: every frame both legs are solved by analytic IK for their
//!   foot frames.
//! - **Spine twist**: the total twist θ is searched (1° steps) until the target's horizontal
//!   direction from the shoulder lies within the comfortable reaching angle of the chest's
//!   forward direction (eq. 6), and split equally over sacral, lumbar and thoracic joints
//!   (eq. 5).
//! - **Spine swing**: when the vertical shoulder–target distance exceeds the start swing
//!   distance, or the arm cannot reach, the spine swings about `s = d × y` (eq. 7), the angle
//!   raised in 1° steps (split equally over the three joints, within their limits) until the
//!   arm can reach; the root moves by `r = −kφ d_p` (eq. 8, `k = r_max/φ_max`) to keep the
//!   COM over the feet. **Squat or stoop**: when the shoulder is higher above the target than
//!   the stoop range `arm length / flexibility`, the root is lowered by the excess (within
//!   what the legs allow) before the swing is searched; a low flexibility stoops instead.
//! - **Arm** ([`crate::profile`]): the hand moves on the straight line from where it is when
//!   the arm controller starts to the target with the speed profile (the paper's ease-out by
//!   default); each frame the arm is solved by analytic IK with Kallmann's orbit-angle search
//!   in the current shoulder frame. A goal out of reach is replaced by the nearest reachable
//!   point on the shoulder→goal line, so an unreachable target ends at the nearest point.
//! - **Head**: turns toward the target at a bounded angular speed, then tracks it.
//! - **Balance** (beyond the paper): after composing a frame, if the COM's ground projection
//!   is less than `balance_margin` inside the support polygon, the root is shifted
//!   horizontally to bring it back, and the limbs solved again.
//! - **Scheduler**: state 0 starts the step; state 1 (the step has progressed `r_st`, or no
//!   step) starts arm, head and twist; state 2 (the twist has progressed `r_tw`, or no
//!   twist) starts swing, COM adjustment and squat; state 3 ends when the hand is at the
//!   target and every controller has finished, or at the timeout.

use kinergy_motion::Side;
use kinergy_motion::nalgebra::{IsometryMatrix3, Point2, Point3, Rotation3, Vector3};
use kinergy_solver::analytic::{LimbIk, OrbitSearch, OrbitSense};
use rand::SeedableRng;
use rand::rngs::ChaCha8Rng;
use serde::Serialize;

use crate::character::{Character, Limb, Pose, SpineJoint, dof, joint};
use crate::error::{ReachError, Result, require};
use crate::profile::SpeedProfile;
use crate::steps::{self, StepDecision, StepSettings};

/// Everything a reach can be tuned with. Defaults follow the paper where it gives values.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ReachSettings {
    /// Frames per second of the output.
    pub frame_rate: f64,
    /// The hand's speed profile along its straight path.
    pub profile: SpeedProfile,
    /// Stepping parameters; `None`: [`StepSettings::for_arm_length`] of the reaching arm.
    pub steps: Option<StepSettings>,
    /// Leg flexibility: the stoop range is arm length / flexibility (higher squats sooner).
    pub flexibility: f64,
    /// Fraction of the step after which the arm, head and twist start (`r_st`).
    pub r_st: f64,
    /// Fraction of the twist after which the swing, COM adjustment and squat start (`r_tw`).
    pub r_tw: f64,
    /// Half-width of the comfortable reaching angle about the chest's forward direction, rad.
    pub comfortable_angle: f64,
    /// Vertical shoulder–target distance beyond which the spine swings, meters.
    pub start_swing_distance: f64,
    /// φ_max of eq. 8, rad (also the largest total swing).
    pub phi_max: f64,
    /// |r_max| of eq. 8, meters.
    pub r_max: f64,
    /// Seconds one foot takes to step.
    pub step_time: f64,
    /// Seconds the twist takes.
    pub twist_time: f64,
    /// Seconds the swing, COM adjustment and squat take.
    pub swing_time: f64,
    /// Largest head turning speed, rad/s.
    pub head_speed: f64,
    /// The hand counts as at the target within this distance, meters.
    pub tolerance: f64,
    /// The reach ends after this many seconds even if the hand is not there.
    pub timeout: f64,
    /// The COM projection is kept at least this far inside the support polygon, meters.
    pub balance_margin: f64,
    /// The reaching arm; `None`: the arm on the target's side.
    pub arm: Option<Side>,
    /// Seed of the stepping decisions.
    pub seed: u64,
}

impl Default for ReachSettings {
    fn default() -> ReachSettings {
        ReachSettings {
            frame_rate: 120.0,
            profile: SpeedProfile::default(),
            steps: None,
            flexibility: 1.0,
            r_st: 0.5,
            r_tw: 0.5,
            comfortable_angle: 40f64.to_radians(),
            start_swing_distance: 0.35,
            phi_max: 120f64.to_radians(),
            r_max: 0.1,
            step_time: 0.6,
            twist_time: 0.7,
            swing_time: 0.9,
            head_speed: 2.5,
            tolerance: 0.01,
            timeout: 8.0,
            balance_margin: 0.01,
            arm: None,
            seed: 0,
        }
    }
}

impl ReachSettings {
    /// Checks every setting, naming the field otherwise.
    pub fn validate(&self) -> Result<()> {
        let positive = |v: f64| v > 0.0 && v.is_finite();
        let fraction = |v: f64| (0.0..=1.0).contains(&v);
        require(
            positive(self.frame_rate),
            "frame_rate",
            "a positive number of frames per second",
        )?;
        self.profile.validate()?;
        if let Some(s) = &self.steps {
            s.validate()?;
        }
        require(
            positive(self.flexibility),
            "flexibility",
            "a positive number",
        )?;
        require(fraction(self.r_st), "r_st", "within [0, 1]")?;
        require(fraction(self.r_tw), "r_tw", "within [0, 1]")?;
        require(
            self.comfortable_angle > 0.0 && self.comfortable_angle < std::f64::consts::PI,
            "comfortable_angle",
            "within (0, π) radians",
        )?;
        require(
            self.start_swing_distance >= 0.0 && self.start_swing_distance.is_finite(),
            "start_swing_distance",
            "≥ 0 meters",
        )?;
        require(positive(self.phi_max), "phi_max", "a positive angle")?;
        require(
            self.r_max >= 0.0 && self.r_max.is_finite(),
            "r_max",
            "≥ 0 meters",
        )?;
        for (v, f) in [
            (self.step_time, "step_time"),
            (self.twist_time, "twist_time"),
            (self.swing_time, "swing_time"),
            (self.head_speed, "head_speed"),
            (self.tolerance, "tolerance"),
            (self.timeout, "timeout"),
        ] {
            require(positive(v), f, "a positive number")?;
        }
        require(
            self.balance_margin >= 0.0 && self.balance_margin.is_finite(),
            "balance_margin",
            "≥ 0 meters",
        )
    }
}

/// Why a reach ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ReachStop {
    /// The hand is within the tolerance of the target.
    Reached,
    /// Every controller finished with the hand at the nearest point it can reach.
    Unreachable,
    /// The timeout came first.
    Timeout,
}

/// What a reach decided and achieved.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ReachReport {
    /// The reaching arm.
    pub arm: &'static str,
    /// The step decision: `none`, `half_left`, `half_right` or `full`.
    pub step: String,
    /// The step length, meters (0 without a step).
    pub step_length: f64,
    /// Horizontal shoulder–target distance at the start, meters.
    pub horizontal_distance: f64,
    /// Total spine twist, degrees.
    pub twist_deg: f64,
    /// Total spine swing, degrees.
    pub swing_deg: f64,
    /// How far the root was lowered to squat, meters (0: none).
    pub squat_m: f64,
    /// `squat`, `stoop` or `upright`.
    pub posture: &'static str,
    /// Distance from the hand to the target on the last frame, meters.
    pub final_error: f64,
    /// Why it ended.
    pub stop: ReachStop,
    /// Frames written.
    pub frames: usize,
    /// Seconds.
    pub duration: f64,
    /// The smallest margin of the COM projection inside the support polygon over the reach,
    /// meters (negative: outside).
    pub min_balance_margin: f64,
}

/// A synthesized reach.
#[derive(Debug, Clone)]
pub struct ReachMotion {
    /// One pose per frame.
    pub poses: Vec<Pose>,
    /// Seconds per frame.
    pub frame_time: f64,
    /// What happened.
    pub report: ReachReport,
}

/// The plan: every decision, made once at the start.
#[derive(Debug, Clone)]
struct Plan {
    arm: Limb,
    target: Point3<f64>,
    step: StepDecision,
    step_length: f64,
    direction: Vector3<f64>,
    /// Total twist θ (radians, about world up) and swing φ (radians, about `axis`).
    twist: f64,
    swing: f64,
    axis: Vector3<f64>,
    squat: f64,
    com_shift: Vector3<f64>,
    horizontal_distance: f64,
}

/// Synthesizes a full-body reach of `character` toward `target` (world meters) from the
/// rest posture.
pub fn reach(
    character: &Character,
    target: Point3<f64>,
    settings: &ReachSettings,
) -> Result<ReachMotion> {
    settings.validate()?;
    require(
        target.coords.iter().all(|v| v.is_finite()),
        "target",
        "finite coordinates",
    )?;
    let rest = character.rest_pose();
    let plan = plan(character, &rest, target, settings)?;
    animate(character, &rest, &plan, settings)
}

/// Chooses the arm, the step, the twist, the squat and the swing.
fn plan(
    character: &Character,
    rest: &Pose,
    target: Point3<f64>,
    s: &ReachSettings,
) -> Result<Plan> {
    let frames = character.world_frames(rest);
    let root = Point3::from(frames[joint::HIPS].translation.vector);
    let side = s.arm.unwrap_or(if target.x >= root.x {
        Side::Left
    } else {
        Side::Right
    });
    let arm = match side {
        Side::Left => Limb::LeftArm,
        Side::Right => Limb::RightArm,
    };
    let segments = character.proportions().arm(side);
    let arm_length = segments.upper_arm + segments.forearm + segments.hand;
    let step_settings = match s.steps {
        Some(st) => st,
        None => StepSettings::for_arm_length(arm_length)?,
    };
    let shoulder = shoulder_position(character, rest, arm);
    let d = steps::horizontal_distance(&shoulder, &target);
    let direction = steps::step_direction(&shoulder, &target)
        .map(|u| u.into_inner())
        .unwrap_or_else(Vector3::z);
    let mut rng = ChaCha8Rng::seed_from_u64(s.seed);
    let facing = Vector3::z();
    let target_side = steps::target_side(&root, &facing, &target, side);
    let step = steps::decide(&step_settings, d, target_side, &mut rng);
    let p = steps::draw_p(&step_settings, &mut rng);
    let step_length = if step.steps() {
        // Never step past the point where the target would be closer than the CRR.
        steps::step_length(&step_settings, d, p)
            .min((d - step_settings.d_c * 0.5).max(0.0))
            .min(static_step_limit(character))
    } else {
        0.0
    };
    let root_move = match step {
        StepDecision::NoStep => 0.0,
        StepDecision::HalfStep { .. } => 0.5 * step_length,
        StepDecision::FullStep => step_length,
    };
    let mut pose = *rest;
    pose[dof::ROOT_X] += direction.x * root_move;
    pose[dof::ROOT_Z] += direction.z * root_move;

    // Twist: the smallest |θ| putting the target within the comfortable angle.
    // The smallest |θ| (1° steps, + before −) putting the target within the comfortable
    // angle; when none within the limits does, the θ turning closest to it.
    let max_twist = max_equal_split(character, |j| j.rotation_dofs().start + dof::TWIST);
    let forward_local = chest_forward_local(character);
    let mut found = None;
    let mut closest = (f64::INFINITY, 0.0);
    'search: for k in 0..=180 {
        for sign in [1.0, -1.0] {
            let theta = sign * (k as f64).to_radians();
            if theta.abs() > max_twist {
                continue;
            }
            let mut p = pose;
            set_twist(&mut p, theta);
            let a = comfort_angle(character, &p, arm, &target, &forward_local);
            if a <= s.comfortable_angle {
                found = Some(theta);
                break 'search;
            }
            if a < closest.0 - 1e-12 {
                closest = (a, theta);
            }
        }
    }
    let twist = found.unwrap_or(closest.1);
    set_twist(&mut pose, twist);

    // Squat: lower the root by what the shoulder's height above the target exceeds the
    // stoop range, as far as the legs allow.
    let shoulder = shoulder_position(character, &pose, arm);
    let drop = shoulder.y - target.y;
    let stoop_range = arm_length / s.flexibility;
    let leg = character.proportions().leg(Side::Right);
    let max_squat = 0.45 * (leg.thigh + leg.shank);
    let squat = if drop > stoop_range {
        (drop - stoop_range).min(max_squat)
    } else {
        0.0
    };
    pose[dof::ROOT_Y] -= squat;

    // Swing about s = d × y, raised until the arm reaches (or the limits / φ_max stop it).
    let shoulder = shoulder_position(character, &pose, arm);
    let dv = target - shoulder;
    let vertical = dv.y.abs();
    let arm_ik = arm_ik_of(character, arm).map_err(|e| ReachError::Setting {
        field: "character.arm".into(),
        why: e.to_string(),
    })?;
    // How far the body is from letting the hand reach comfortably: the hand's distance from
    // the target with the arm solved at this posture, or the shoulder's distance beyond 90 %
    // of the arm's length, whichever is larger.
    let reach_of = |p: &Pose| {
        let beyond = (shoulder_position(character, p, arm) - target).norm() - 0.9 * arm_length;
        arm_error(character, p, arm, &arm_ik, &target)
            .max(beyond)
            .max(0.0)
    };
    let reachable = 0.5 * s.tolerance;
    let horizontal = Vector3::new(dv.x, 0.0, dv.z);
    let axis = {
        let a = dv.cross(&Vector3::y());
        if a.norm() > 1e-9 {
            a.normalize()
        } else {
            Vector3::x()
        }
    };
    let dp = if horizontal.norm() > 1e-9 {
        horizontal.normalize()
    } else {
        direction
    };
    let k_com = s.r_max / s.phi_max;
    let mut swing = 0.0;
    if vertical > s.start_swing_distance || reach_of(&pose) > reachable {
        let max_swing = s.phi_max.min(max_swing_split(character));
        let at = |phi: f64| {
            let mut p = pose;
            apply_swing(character, &mut p, &axis, phi);
            let shift = -k_com * phi.abs() * dp;
            p[dof::ROOT_X] += shift.x;
            p[dof::ROOT_Z] += shift.z;
            p
        };
        // The direction (clockwise or not) that brings the shoulder closer.
        let step = 1f64.to_radians();
        let sign = if reach_of(&at(step)) <= reach_of(&at(-step)) {
            1.0
        } else {
            -1.0
        };
        let mut best = (reach_of(&pose), 0.0);
        let mut phi: f64 = 0.0;
        while phi + step <= max_swing + 1e-12 {
            phi += step;
            let r = reach_of(&at(sign * phi));
            if r < best.0 - 1e-9 {
                best = (r, sign * phi);
            }
            if r <= reachable {
                break;
            }
        }
        swing = best.1;
    }
    // COM adjustment: eq. 8's r = −kφ d_p, then — beyond the paper — as much more along the
    // support polygon's centre as the final posture needs to keep the COM's projection
    // inside the final support polygon (feet where the step leaves them).
    let mut com_shift = -k_com * swing.abs() * dp;
    {
        let mut p = pose;
        if swing != 0.0 {
            apply_swing(character, &mut p, &axis, swing);
        }
        let rest_frames = character.world_frames(rest);
        let mut feet = [
            rest_frames[joint::RIGHT_FOOT],
            rest_frames[joint::LEFT_FOOT],
        ];
        let step_vec = direction * step_length;
        match step {
            StepDecision::NoStep => {}
            StepDecision::HalfStep { foot } => {
                let i = if foot == Side::Right { 0 } else { 1 };
                feet[i].translation.vector += step_vec;
            }
            StepDecision::FullStep => {
                for f in &mut feet {
                    f.translation.vector += step_vec;
                }
            }
        }
        let legs = [
            leg_ik(character, Limb::RightLeg)?,
            leg_ik(character, Limb::LeftLeg)?,
        ];
        for _ in 0..40 {
            let mut q = p;
            q[dof::ROOT_X] += com_shift.x;
            q[dof::ROOT_Z] += com_shift.z;
            lower_root_for_legs(character, &mut q, &feet);
            solve_legs(character, &mut q, &legs, &feet)?;
            let base = character.limb_base_frame(arm, &q);
            if let Some(a) = solve_arm(&arm_ik, &base, &target, &OrbitSearch::default()) {
                q[character.limb_dofs(arm)].copy_from_slice(&a);
            }
            let com = character.com(&q);
            let polygon = character.support_polygon(&q);
            let c = Point2::new(com.x, com.z);
            let margin = polygon.margin(c);
            if margin >= s.balance_margin + 0.02 {
                break;
            }
            let v = polygon.vertices();
            let centroid = v
                .iter()
                .fold(Point2::origin(), |a, p| a + p.coords / v.len() as f64);
            let dir = (centroid - c)
                .try_normalize(1e-12)
                .unwrap_or_else(kinergy_motion::nalgebra::Vector2::zeros);
            let d = s.balance_margin + 0.02 - margin;
            com_shift += Vector3::new(dir.x, 0.0, dir.y) * (0.5 * d + 0.002);
        }
    }
    Ok(Plan {
        arm,
        target,
        step,
        step_length,
        direction,
        twist,
        swing,
        axis,
        squat,
        com_shift,
        horizontal_distance: d,
    })
}

/// The largest total angle that splits equally over sacral, lumbar and thoracic within each
/// one's limit of the DoF `index(joint)`.
fn max_equal_split(character: &Character, index: impl Fn(SpineJoint) -> usize) -> f64 {
    [SpineJoint::Sacral, SpineJoint::Lumbar, SpineJoint::Thoracic]
        .iter()
        .map(|&j| 3.0 * dof_limit(character, index(j)))
        .fold(f64::INFINITY, f64::min)
}

/// The largest total swing splitting equally over the three lower spine joints (the
/// smaller ellipse radius of each, so every direction fits).
fn max_swing_split(character: &Character) -> f64 {
    [SpineJoint::Sacral, SpineJoint::Lumbar, SpineJoint::Thoracic]
        .iter()
        .map(|&j| {
            let joint = &character.joints()[j.joint()];
            joint
                .motions
                .iter()
                .find_map(|m| match *m {
                    kinergy_motion::Motion::Swing { rx, ry } => Some(3.0 * rx.min(ry)),
                    _ => None,
                })
                .unwrap_or(0.0)
        })
        .fold(f64::INFINITY, f64::min)
}

/// The symmetric limit of a revolute DoF (the smaller of |min| and |max|).
fn dof_limit(character: &Character, index: usize) -> f64 {
    for j in character.joints() {
        let range = j.dof_range();
        if !range.contains(&index) {
            continue;
        }
        let mut k = j.first_dof + if j.translates { 3 } else { 0 };
        for m in &j.motions {
            if (k..k + m.dof_count()).contains(&index) {
                return match *m {
                    kinergy_motion::Motion::Revolute { min, max, .. } => min.abs().min(max.abs()),
                    kinergy_motion::Motion::Swing { rx, ry } => rx.min(ry),
                };
            }
            k += m.dof_count();
        }
    }
    0.0
}

fn set_twist(pose: &mut Pose, theta: f64) {
    for j in [SpineJoint::Sacral, SpineJoint::Lumbar, SpineJoint::Thoracic] {
        pose[j.rotation_dofs().start + dof::TWIST] = theta / 3.0;
    }
}

/// Sets the three lower spine joints' swings so the spine turns by `phi` about the world
/// axis `axis`, each joint a third, each expressed in its own frame before its motions.
fn apply_swing(character: &Character, pose: &mut Pose, axis: &Vector3<f64>, phi: f64) {
    for j in [SpineJoint::Sacral, SpineJoint::Lumbar, SpineJoint::Thoracic] {
        let frames = character.world_frames(pose);
        let cj = &character.joints()[j.joint()];
        let parent = cj
            .parent
            .map_or(Rotation3::identity(), |p| frames[p].rotation);
        let local = (parent * cj.rest).inverse() * axis;
        let planar = Vector3::new(local.x, local.y, 0.0);
        let v = if planar.norm() > 1e-9 {
            planar.normalize() * (phi / 3.0)
        } else {
            Vector3::zeros()
        };
        let r = j.rotation_dofs();
        pose[r.start + dof::SWING_X] = v.x;
        pose[r.start + dof::SWING_Y] = v.y;
    }
}

fn shoulder_position(character: &Character, pose: &Pose, arm: Limb) -> Point3<f64> {
    let f = character.limb_base_frame(arm, pose);
    Point3::from(f.translation.vector)
}

/// The hand's distance from `target` with the arm solved by [`solve_arm`] at `pose`.
fn arm_error(
    character: &Character,
    pose: &Pose,
    arm: Limb,
    ik: &LimbIk,
    target: &Point3<f64>,
) -> f64 {
    let base = character.limb_base_frame(arm, pose);
    match solve_arm(ik, &base, target, &OrbitSearch::default()) {
        Some(q) => {
            let mut p = *pose;
            p[character.limb_dofs(arm)].copy_from_slice(&q);
            (hand_position(character, &p, arm) - target).norm()
        }
        None => f64::INFINITY,
    }
}

/// The angle between the target's horizontal direction from the shoulder and the chest's
/// horizontal forward direction (eq. 6).
fn comfort_angle(
    character: &Character,
    pose: &Pose,
    arm: Limb,
    target: &Point3<f64>,
    forward_local: &Vector3<f64>,
) -> f64 {
    let frames = character.world_frames(pose);
    let forward = frames[joint::CHEST].rotation * forward_local;
    let shoulder = shoulder_position(character, pose, arm);
    let d = target - shoulder;
    let (f, d) = (
        Vector3::new(forward.x, 0.0, forward.z),
        Vector3::new(d.x, 0.0, d.z),
    );
    if d.norm() < 1e-6 || f.norm() < 1e-9 {
        return 0.0;
    }
    f.normalize().dot(&d.normalize()).clamp(-1.0, 1.0).acos()
}

/// The chest's forward direction in its own frame (world +Z at rest).
fn chest_forward_local(character: &Character) -> Vector3<f64> {
    let rest = character.rest_pose();
    let frames = character.world_frames(&rest);
    frames[joint::CHEST].rotation.inverse() * Vector3::z()
}

/// Smoothstep on [0, 1].
fn ease(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Runs the scheduler frame by frame.
fn animate(
    character: &Character,
    rest: &Pose,
    plan: &Plan,
    s: &ReachSettings,
) -> Result<ReachMotion> {
    let dt = 1.0 / s.frame_rate;
    let max_frames = (s.timeout / dt).ceil() as usize + 1;
    let rest_frames = character.world_frames(rest);
    // Feet: the ankle frames at rest and after the step.
    let feet_rest = [
        rest_frames[joint::RIGHT_FOOT],
        rest_frames[joint::LEFT_FOOT],
    ];
    let step_vec = plan.direction * plan.step_length;
    let (moves, order): ([bool; 2], [usize; 2]) = match plan.step {
        StepDecision::NoStep => ([false, false], [0, 1]),
        StepDecision::HalfStep { foot } => {
            let i = foot_index(foot);
            let mut m = [false, false];
            m[i] = true;
            (m, [i, 1 - i])
        }
        StepDecision::FullStep => {
            let lead = foot_index(match plan.arm {
                Limb::LeftArm => Side::Left,
                _ => Side::Right,
            });
            ([true, true], [lead, 1 - lead])
        }
    };
    // Each foot's step: a weight shift (the first 40 % of `step_time`) then the swing.
    let shift_part = 0.4 * s.step_time;
    let swing_part = s.step_time - shift_part;
    let step_total = match plan.step {
        StepDecision::NoStep => 0.0,
        StepDecision::HalfStep { .. } => s.step_time + shift_part,
        StepDecision::FullStep => 2.0 * s.step_time + shift_part,
    };
    let root_move = match plan.step {
        StepDecision::NoStep => Vector3::zeros(),
        StepDecision::HalfStep { .. } => 0.5 * step_vec,
        StepDecision::FullStep => step_vec,
    };
    // Root keyframes (horizontal position; height stays the rest height).
    let root_rest_point = Point3::new(rest[dof::ROOT_X], rest[dof::ROOT_Y], rest[dof::ROOT_Z]);
    let sole = |i: usize, moved: bool| -> Point3<f64> {
        let ankle = Point3::from(feet_rest[i].translation.vector);
        let leg = character
            .proportions()
            .leg(if i == 0 { Side::Right } else { Side::Left });
        // Toward the toe, where the swinging foot is going (the COM stays 2 cm inside).
        let toward = 0.3 * (leg.toe - leg.heel).max(0.0);
        let forward = plan.direction * toward;
        let c = ankle + forward + if moved { step_vec } else { Vector3::zeros() };
        // Knees bent while stepping (static balance: the swinging leg must reach its landing
        // spot while the root stays over the stance foot).
        Point3::new(
            c.x,
            root_rest_point.y - STEP_KNEE_BEND * (leg.thigh + leg.shank),
            c.z,
        )
    };
    let mut root_keys = vec![(0.0, root_rest_point)];
    if step_total > 0.0 {
        let mut landed = [false, false];
        for &i in order.iter().filter(|&&i| moves[i]) {
            let (a, b) = swing_window(order, i, s.step_time);
            let stance = sole(1 - i, landed[1 - i]);
            root_keys.push((a, stance));
            root_keys.push((b, stance));
            landed[i] = true;
        }
        let end = root_keys.last().map_or(0.0, |k| k.0) + shift_part;
        root_keys.push((end, root_rest_point + root_move));
    }
    let step_total = root_keys.last().map_or(0.0, |k| k.0);
    let step_settings = match s.steps {
        Some(st) => st,
        None => {
            let a = character.proportions().arm(plan.arm.side());
            StepSettings::for_arm_length(a.upper_arm + a.forearm + a.hand)?
        }
    };
    let leg_iks = [
        leg_ik(character, Limb::RightLeg)?,
        leg_ik(character, Limb::LeftLeg)?,
    ];
    let arm_ik = arm_ik_of(character, plan.arm).map_err(|e| ReachError::Setting {
        field: "character.arm".into(),
        why: e.to_string(),
    })?;
    let search = OrbitSearch::default();

    // Scheduler times.
    let t_arm = if plan.step.steps() {
        s.r_st * step_total
    } else {
        0.0
    };
    let twist_time = if plan.twist != 0.0 { s.twist_time } else { 0.0 };
    let t_swing = t_arm + s.r_tw * twist_time;
    let swing_time = if plan.swing != 0.0 || plan.squat != 0.0 {
        s.swing_time
    } else {
        0.0
    };
    let mut hand_start: Option<Point3<f64>> = None;
    let mut head = (0.0f64, 0.0f64); // cervical twist, swing_x
    let mut poses = Vec::new();
    let mut min_margin = f64::INFINITY;
    let mut stop = ReachStop::Timeout;
    let mut final_error = f64::INFINITY;
    let arm_dofs = character.limb_dofs(plan.arm);
    let mut last_arm: Option<[f64; 7]> = None;
    // The orbit angle of the previous frame's arm: each frame's search starts there, so the
    // elbow (and the arm's twist) moves continuously; before the first solve, the search
    // starts at the angle whose posture is closest to the resting arm.
    let mut arm_alpha: Option<f64> = None;
    let mut previous_arm: [f64; 7] = std::array::from_fn(|i| rest[arm_dofs.start + i]);
    for frame in 0..max_frames {
        let t = frame as f64 * dt;
        let mut pose = *rest;
        // Legs: each stepping foot first waits while the root moves over the other foot
        // (weight shift), then swings; the root travels during the swing.
        let foot_goal = |i: usize| -> IsometryMatrix3<f64> {
            let mut f = feet_rest[i];
            if moves[i] && step_total > 0.0 {
                let (a, _) = swing_window(order, i, s.step_time);
                let u = ((t - a) / swing_part).clamp(0.0, 1.0);
                let from = Point3::from(f.translation.vector);
                let to = from + step_vec;
                let p = steps::foot_path(from, to, step_settings.foot_lift, u);
                f.translation.vector = p.coords;
            }
            f
        };
        let root_rest = Point3::new(rest[dof::ROOT_X], rest[dof::ROOT_Y], rest[dof::ROOT_Z]);
        let root_path = if step_total > 0.0 {
            // Static balance: the root moves over the stance foot before each swing, stays
            // there while the other foot is in the air (dipping a little), and ends midway.
            let mut p = keyed(&root_keys, t);
            for (i, _) in moves.iter().enumerate().filter(|(_, m)| **m) {
                let (a, b) = swing_window(order, i, s.step_time);
                if t > a && t < b {
                    let u = (t - a) / (b - a);
                    p.y -= step_settings.root_dip * (std::f64::consts::PI * u).sin();
                }
            }
            p
        } else {
            root_rest
        };
        // Spine.
        let tw = if twist_time > 0.0 {
            ease((t - t_arm) / twist_time)
        } else {
            1.0
        };
        let sw = if swing_time > 0.0 {
            ease((t - t_swing) / swing_time)
        } else {
            1.0
        };
        let started_swing = t >= t_swing;
        pose[dof::ROOT_X] = root_path.x + plan.com_shift.x * sw;
        pose[dof::ROOT_Y] = root_path.y - plan.squat * sw;
        pose[dof::ROOT_Z] = root_path.z + plan.com_shift.z * sw;
        set_twist(&mut pose, plan.twist * tw);
        if started_swing && plan.swing != 0.0 {
            apply_swing(character, &mut pose, &plan.axis, plan.swing * sw);
        }
        // Head: toward the target at a bounded speed.
        if t >= t_arm {
            let want = head_angles(character, &pose, &plan.target);
            let max = s.head_speed * dt;
            head.0 += (want.0 - head.0).clamp(-max, max);
            head.1 += (want.1 - head.1).clamp(-max, max);
        }
        pose[dof::CERVICAL.start + dof::TWIST] = head.0;
        pose[dof::CERVICAL.start + dof::SWING_X] = head.1;

        // Limbs, then balance (at most two corrections).
        let mut error = f64::INFINITY;
        let mut frame_alpha = None;
        for pass in 0..10 {
            let feet = [foot_goal(0), foot_goal(1)];
            lower_root_for_legs(character, &mut pose, &feet);
            // The limbs' bases do not depend on the limbs: one FK serves all three.
            let above = character.world_frames(&pose);
            solve_legs_in(character, &mut pose, &above, &leg_iks, &feet)?;
            // Arm.
            let base = character.limb_base_frame_in(plan.arm, &above);
            let arm_chain = character.limb_chain(plan.arm);
            let end = |pose: &Pose| {
                arm_chain
                    .end_position(&base, &pose[arm_dofs.clone()])
                    .unwrap_or(plan.target)
            };
            let hand_now = end(&pose);
            if t >= t_arm {
                let start = *hand_start.get_or_insert(hand_now);
                let goal = s.profile.position(&start, &plan.target, t - t_arm);
                let near = match arm_alpha {
                    Some(a) => Near::Alpha(a),
                    None => Near::Posture(previous_arm),
                };
                let mut solved = solve_arm_near(&arm_ik, &base, &goal, &search, near);
                // Through a straight arm the orbit angle's reference flips: when the posture
                // jumps, take the angle closest to the previous frame's posture instead.
                if let Some((_, q)) = solved
                    && (0..5).any(|i| (q[i] - previous_arm[i]).abs() > ARM_JUMP)
                {
                    let again =
                        solve_arm_near(&arm_ik, &base, &goal, &search, Near::Posture(previous_arm));
                    if again.is_some() {
                        solved = again;
                    }
                }
                if let Some((a, _)) = solved {
                    frame_alpha = Some(a);
                }
                let q = solved.map(|(_, q)| q).or(last_arm).unwrap_or_default();
                if pass == 0 || q != [0.0; 7] {
                    pose[arm_dofs.clone()].copy_from_slice(&q);
                }
                last_arm = Some(q);
            }
            error = (end(&pose) - plan.target).norm();
            // Balance.
            let frames = character.world_frames(&pose);
            let com = character.com_in(&frames);
            let polygon = character.support_polygon_in(&frames);
            let c = Point2::new(com.x, com.z);
            let margin = polygon.margin(c);
            if margin >= s.balance_margin || pass == 9 {
                min_margin = min_margin.min(margin);
                break;
            }
            // Move the root toward the polygon's centroid by the shortfall.
            let v = polygon.vertices();
            let centroid = v
                .iter()
                .fold(Point2::origin(), |a, p| a + p.coords / v.len() as f64);
            let dir = (centroid - c)
                .try_normalize(1e-12)
                .unwrap_or_else(kinergy_motion::nalgebra::Vector2::zeros);
            let shift = dir * (1.5 * (s.balance_margin - margin) + 0.002);
            pose[dof::ROOT_X] += shift.x;
            pose[dof::ROOT_Z] += shift.y;
        }
        if frame_alpha.is_some() {
            arm_alpha = frame_alpha;
        }
        // A human joint turns at most so fast: near full extension a millimetre of shoulder
        // motion (a balance correction) swings the elbow by tens of degrees, which the arm
        // then catches up with over a few frames instead of in one.
        let max_step = ARM_MAX_SPEED * dt;
        let mut limited = false;
        for (value, before) in pose[arm_dofs.clone()].iter_mut().zip(&previous_arm) {
            let change = *value - before;
            if change.abs() > max_step {
                *value = before + max_step.copysign(change);
                limited = true;
            }
        }
        if limited {
            error = (character.world_positions(&pose)[plan.arm.joints()[3]] - plan.target).norm();
        }
        final_error = error;
        character.clamp_pose(&mut pose);
        previous_arm = std::array::from_fn(|i| pose[arm_dofs.start + i]);
        poses.push(pose);
        let done_body = t >= t_swing + swing_time && t >= step_total && t >= t_arm + twist_time;
        let hand_done = t
            >= t_arm
                + s.profile
                    .duration(hand_start.map_or(0.0, |h| (plan.target - h).norm()));
        if done_body && hand_done {
            if error <= s.tolerance {
                stop = ReachStop::Reached;
                break;
            }
            // Hold a few frames to let the nearest point settle, then give up.
            if t >= t_swing + swing_time + 0.25 && t >= t_arm + 0.25 {
                stop = ReachStop::Unreachable;
                break;
            }
        }
    }
    let frames = poses.len();
    let report = ReachReport {
        arm: plan.arm.name(),
        step: match plan.step {
            StepDecision::NoStep => "none".into(),
            StepDecision::HalfStep { foot: Side::Left } => "half_left".into(),
            StepDecision::HalfStep { foot: Side::Right } => "half_right".into(),
            StepDecision::FullStep => "full".into(),
        },
        step_length: plan.step_length,
        horizontal_distance: plan.horizontal_distance,
        twist_deg: plan.twist.to_degrees(),
        swing_deg: plan.swing.to_degrees(),
        squat_m: plan.squat,
        posture: if plan.squat > 0.0 {
            "squat"
        } else if plan.swing != 0.0 && plan.target.y < hand_rest_height(character, rest, plan.arm) {
            "stoop"
        } else {
            "upright"
        },
        final_error,
        stop,
        frames,
        duration: frames as f64 * dt,
        min_balance_margin: min_margin,
    };
    Ok(ReachMotion {
        poses,
        frame_time: dt,
        report,
    })
}

/// The root's drop while stepping, as a fraction of the leg length.
const STEP_KNEE_BEND: f64 = 0.12;

/// The longest step a foot can take while the root stays over the other foot's toe (static
/// balance), from the leg's geometry with the knees bent by [`STEP_KNEE_BEND`].
fn static_step_limit(character: &Character) -> f64 {
    let leg = character.proportions().leg(Side::Right);
    let l = leg.thigh + leg.shank;
    let drop = l - STEP_KNEE_BEND * l;
    let reach = 0.97 * l;
    let horizontal = (reach * reach - drop * drop).max(0.0).sqrt();
    horizontal + 0.3 * (leg.toe - leg.heel).max(0.0)
}

/// The position at `t` of eased keyframes `(time, position)` (held after the last).
fn keyed(keys: &[(f64, Point3<f64>)], t: f64) -> Point3<f64> {
    for w in keys.windows(2) {
        let ((t0, p0), (t1, p1)) = (w[0], w[1]);
        if t <= t1 {
            let u = if t1 > t0 {
                ease((t - t0) / (t1 - t0))
            } else {
                1.0
            };
            return p0 + (p1 - p0) * u;
        }
    }
    keys.last().map_or(Point3::origin(), |k| k.1)
}

/// When foot `i` swings: `(start, end)` seconds. The first foot of `order` swings after one
/// weight shift, the second after the first has landed and the weight has shifted again.
fn swing_window(order: [usize; 2], i: usize, step_time: f64) -> (f64, f64) {
    let shift = 0.4 * step_time;
    let swing = step_time - shift;
    let k = if order[0] == i { 0.0 } else { 1.0 };
    let a = shift + k * step_time;
    (a, a + swing)
}

fn foot_index(side: Side) -> usize {
    match side {
        Side::Right => 0,
        Side::Left => 1,
    }
}

fn hand_rest_height(character: &Character, rest: &Pose, arm: Limb) -> f64 {
    hand_position(character, rest, arm).y
}

fn hand_position(character: &Character, pose: &Pose, arm: Limb) -> Point3<f64> {
    let frames = character.world_frames(pose);
    Point3::from(frames[arm.joints()[3]].translation.vector)
}

/// The leg's analytic IK, its α = 0 the knee pointing forward.
fn leg_ik(character: &Character, leg: Limb) -> Result<LimbIk> {
    let ik = LimbIk::new(character.limb_chain(leg))
        .and_then(|ik| ik.with_down(Vector3::y()))
        .map_err(|e| ReachError::Setting {
            field: format!("character.{}", leg.name()),
            why: e.to_string(),
        })?;
    Ok(ik)
}

/// Lowers the root until both ankles are within 98.5 % of the legs' length from the hips
/// (a planted foot must stay reachable whatever the root does).
fn lower_root_for_legs(character: &Character, pose: &mut Pose, feet: &[IsometryMatrix3<f64>; 2]) {
    for (i, leg) in [Limb::RightLeg, Limb::LeftLeg].into_iter().enumerate() {
        let segments = character.proportions().leg(leg.side());
        let reach = 0.985 * (segments.thigh + segments.shank);
        let hip = character.limb_base_frame(leg, pose).translation.vector;
        let ankle = feet[i].translation.vector;
        let h = ((hip.x - ankle.x).powi(2) + (hip.z - ankle.z).powi(2)).sqrt();
        if h >= reach {
            continue;
        }
        let allowed = (reach * reach - h * h).sqrt();
        let vertical = hip.y - ankle.y;
        if vertical > allowed {
            pose[dof::ROOT_Y] -= vertical - allowed;
        }
    }
}

/// Both legs for their ankle frames (`feet[0]` right, `feet[1]` left), knees forward.
fn solve_legs(
    character: &Character,
    pose: &mut Pose,
    iks: &[LimbIk; 2],
    feet: &[IsometryMatrix3<f64>; 2],
) -> Result<()> {
    let above = character.world_frames(pose);
    solve_legs_in(character, pose, &above, iks, feet)
}

/// [`solve_legs`] with the world frames of the body above the legs already computed.
fn solve_legs_in(
    character: &Character,
    pose: &mut Pose,
    above: &[IsometryMatrix3<f64>],
    iks: &[LimbIk; 2],
    feet: &[IsometryMatrix3<f64>; 2],
) -> Result<()> {
    for (i, leg) in [Limb::RightLeg, Limb::LeftLeg].into_iter().enumerate() {
        let base = character.limb_base_frame_in(leg, above);
        // The chain's end effector is the toe tip in the ankle frame.
        let toe = character.limb_chain(leg).end_effector();
        let goal_world = IsometryMatrix3::from_parts(
            (feet[i].translation.vector + feet[i].rotation * toe).into(),
            feet[i].rotation,
        );
        let solve = |goal_world: &IsometryMatrix3<f64>| -> Option<[f64; 7]> {
            let goal = base.inverse() * goal_world;
            match iks[i].solve(&goal, 0.0) {
                Ok(q) if iks[i].within_limits(&q) => Some(q),
                _ => iks[i]
                    .search(&goal, &OrbitSearch::default())
                    .ok()
                    .map(|(_, q)| q),
            }
        };
        // Flat foot first; if the ankle cannot take it, the heel rises about the planted toe
        // (toe-off), in 5° steps up to 60°.
        let mut q = solve(&goal_world);
        let mut pitch = 0.0f64;
        while q.is_none() && pitch < 60f64.to_radians() {
            pitch += 5f64.to_radians();
            let tilted = IsometryMatrix3::from_parts(
                goal_world.translation,
                goal_world.rotation * Rotation3::from_axis_angle(&Vector3::x_axis(), pitch),
            );
            q = solve(&tilted);
        }
        let q = match q {
            Some(q) => q,
            None => {
                let mut q = iks[i]
                    .solve(&(base.inverse() * goal_world), 0.0)
                    .unwrap_or_default();
                character.limb_chain(leg).clamp(&mut q);
                q
            }
        };
        pose[character.limb_dofs(leg)].copy_from_slice(&q);
    }
    Ok(())
}

/// The arm's analytic IK: α = 0 the lowest elbow (world down) and growing α raising the
/// elbow outward — a left-handed turn about the shoulder→wrist axis for the right arm.
fn arm_ik_of(
    character: &Character,
    arm: Limb,
) -> std::result::Result<LimbIk, kinergy_solver::analytic::AnalyticError> {
    let sense = match arm.side() {
        Side::Right => OrbitSense::LeftHanded,
        Side::Left => OrbitSense::RightHanded,
    };
    Ok(LimbIk::new(character.limb_chain(arm))?.with_sense(sense))
}

/// The largest change of an arm DoF between frames before the orbit angle is chosen anew by
/// posture (radians; a reach moves far less per frame).
const ARM_JUMP: f64 = 0.2;

/// The fastest an arm DoF turns, rad/s (peak elbow and shoulder speeds of fast human
/// reaches are around 10 rad/s; ours stay below).
const ARM_MAX_SPEED: f64 = 8.0;

/// Where an arm's orbit search starts.
#[derive(Debug, Clone, Copy)]
enum Near {
    /// The default start ([`OrbitSearch::start`]).
    Default,
    /// At this orbit angle (the previous frame's), with small increments.
    Alpha(f64),
    /// At the angle whose posture is closest to this one (in the shoulder and elbow DoFs).
    Posture([f64; 7]),
}

/// The arm for the hand at `goal` (world), position mode with the orbit search; a goal out
/// of reach is moved to the nearest reachable point on the shoulder→goal line.
fn solve_arm(
    ik: &LimbIk,
    base: &IsometryMatrix3<f64>,
    goal: &Point3<f64>,
    search: &OrbitSearch,
) -> Option<[f64; 7]> {
    solve_arm_near(ik, base, goal, search, Near::Default).map(|(_, q)| q)
}

/// [`solve_arm`] with the search starting [`Near`] a previous solution; returns the orbit
/// angle too.
fn solve_arm_near(
    ik: &LimbIk,
    base: &IsometryMatrix3<f64>,
    goal: &Point3<f64>,
    search: &OrbitSearch,
    near: Near,
) -> Option<(f64, [f64; 7])> {
    let down = base.rotation.inverse() * -Vector3::y();
    let ik = ik.clone().with_down(down).ok()?;
    let local = base.inverse() * goal;
    let r = local.coords.norm();
    let solve = |p: &Point3<f64>| {
        let start = match near {
            Near::Default => None,
            Near::Alpha(a) => Some(a),
            Near::Posture(q0) => closest_alpha(&ik, p, &q0),
        };
        match start {
            None => ik.solve_position(p, search).ok(),
            Some(a) => {
                // The range widens to include the start: continuity comes first.
                let s = OrbitSearch {
                    start: a,
                    min: search.min.min(a),
                    max: search.max.max(a),
                    step: search.step.min(2f64.to_radians()),
                    ..*search
                };
                ik.solve_position(p, &s)
                    .or_else(|_| ik.solve_position(p, search))
                    .ok()
            }
        }
    };
    const SCALES: [f64; 8] = [1.0, 0.999, 0.995, 0.99, 0.98, 0.96, 0.93, 0.9];
    // The goal itself, or a point a little closer on the same line (a goal exactly at full
    // extension can fail by rounding) ...
    for scale in SCALES {
        let p = if r > 1e-9 {
            Point3::from(local.coords * scale)
        } else {
            local
        };
        if let Some(found) = solve(&p) {
            return Some(found);
        }
    }
    // ... and only then, out of reach, the point at the reach radius on that line.
    let (_, outer) = ik.position_reach().unwrap_or_else(|| ik.wrist_reach());
    if r > outer {
        for scale in SCALES {
            if let Some(found) = solve(&Point3::from(local.coords * (outer / r) * scale)) {
                return Some(found);
            }
        }
    }
    None
}

/// The orbit angle, on a 5° grid over the whole circle, whose posture within the limits is
/// closest to `q0` in the shoulder and elbow DoFs.
fn closest_alpha(ik: &LimbIk, p: &Point3<f64>, q0: &[f64; 7]) -> Option<f64> {
    use std::f64::consts::PI;
    (0..72)
        .map(|k| -PI + (k as f64) * 5f64.to_radians())
        .filter_map(|a| {
            let q = ik.solve_position_at(p, a).ok()?;
            ik.within_limits(&q).then(|| {
                let d: f64 = (0..5).map(|i| (q[i] - q0[i]).powi(2)).sum();
                (a, d)
            })
        })
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .map(|(a, _)| a)
}

/// The cervical twist and forward swing that face the head toward the target.
fn head_angles(character: &Character, pose: &Pose, target: &Point3<f64>) -> (f64, f64) {
    let frames = character.world_frames(pose);
    let neck = &character.joints()[joint::NECK];
    let parent = neck
        .parent
        .map_or(IsometryMatrix3::identity(), |p| frames[p]);
    let frame_rot = parent.rotation * neck.rest;
    let origin = parent * Point3::from(neck.offset);
    let d = frame_rot.inverse() * (target - origin);
    // In the spine frames forward is −y, up is +z, left is +x.
    let yaw = (d.x).atan2(-d.y);
    let horizontal = (d.x * d.x + d.y * d.y).sqrt();
    let pitch = (-d.z).atan2(horizontal);
    let lim = |v: f64, l: f64| v.clamp(-l, l);
    (lim(yaw, 70f64.to_radians()), lim(pitch, 50f64.to_radians()))
}
