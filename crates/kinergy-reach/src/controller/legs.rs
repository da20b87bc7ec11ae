//! The leg controller (Huang, Kapadia & Terzopoulos §3.5, State 0 of §4): the step decided
//! once ([`plan_step`], with [`crate::steps`]), then timed frame by frame ([`Stepping`]), and
//! both legs solved by analytic IK for their ankle frames every frame, so planted feet stay
//! exactly where they are.
//!
//! Each stepping foot first waits while the root moves over the other foot (a weight shift,
//! the first 40 % of `step_time` or longer, so the root moves at most [`ROOT_SPEED`]), then
//! swings on the convex foot path; in a full step the
//! second foot swings after the first has landed and the weight has shifted again. The root
//! moves on eased keyframes — over the stance foot before each swing, dipping a little while
//! a foot is in the air, and to its end (half the step for a half step) — with the knees bent
//! by [`STEP_KNEE_BEND`] for static balance.

use kinergy_io::InvalidSetting;
use kinergy_motion::Side;
use kinergy_motion::nalgebra::{IsometryMatrix3, Point3, Rotation3, Vector3};
use kinergy_solver::analytic::{LimbIk, OrbitSearch};
use rand::SeedableRng;
use rand::rngs::ChaCha8Rng;

use super::settings::ReachSettings;
use crate::character::{Character, Limb, Pose, dof, joint};
use crate::error::{ReachError, Result};
use crate::profile::smoothstep;
use crate::steps::{self, StepDecision, StepSettings};

/// The fastest the root moves between stance feet, m/s (the weight shift before a swing
/// lasts longer when the root has further to go).
const ROOT_SPEED: f64 = 1.0;

/// The root's drop while stepping, as a fraction of the leg length.
const STEP_KNEE_BEND: f64 = 0.12;

/// The step settings of a reach: the given ones, or [`StepSettings::for_arm_length`] of the
/// reaching arm.
pub(super) fn step_settings(
    character: &Character,
    arm: Limb,
    s: &ReachSettings,
) -> Result<StepSettings> {
    let settings = match s.steps {
        Some(st) => st,
        None => {
            let a = character.proportions().arm(arm.side());
            StepSettings::for_arm_length(a.upper_arm + a.forearm + a.hand)?
        }
    };
    Ok(match s.half_step_probability {
        Some((p_max, p_min)) => StepSettings {
            p_max,
            p_min,
            ..settings
        },
        None => settings,
    })
}

/// The step decided at the start.
#[derive(Debug, Clone, Copy)]
pub(super) struct StepPlan {
    /// No step, a half step (which foot) or a full step.
    pub step: StepDecision,
    /// Meters (0 without a step).
    pub length: f64,
    /// d_p: the ground direction from the shoulder to the target (+Z when straight above).
    pub direction: Vector3<f64>,
    /// d, the target's horizontal distance from the shoulder, meters.
    pub horizontal_distance: f64,
}

impl StepPlan {
    /// How far the root ends up moved along [`StepPlan::direction`]: half a half step, all of
    /// a full one.
    pub(super) fn root_move(&self) -> f64 {
        match self.step {
            StepDecision::NoStep => 0.0,
            StepDecision::HalfStep { .. } => 0.5 * self.length,
            StepDecision::FullStep => self.length,
        }
    }

    /// The ankle frames after the step, `[right, left]`, from those at rest.
    pub(super) fn feet_after(&self, rest: [IsometryMatrix3<f64>; 2]) -> [IsometryMatrix3<f64>; 2] {
        let mut feet = rest;
        let step_vec = self.direction * self.length;
        match self.step {
            StepDecision::NoStep => {}
            StepDecision::HalfStep { foot } => {
                feet[foot_index(foot)].translation.vector += step_vec;
            }
            StepDecision::FullStep => {
                for f in &mut feet {
                    f.translation.vector += step_vec;
                }
            }
        }
        feet
    }
}

/// The stepping decision (§3.5) for the reaching arm on `side` with its shoulder at
/// `shoulder` and the root at `root`, both at rest: the target's distance from the CRR and
/// MRR cylinders decides no step, a half step or a full step, eq. 9 its length — never past
/// the point where the target would be closer than the CRR, nor longer than
/// [`static_step_limit`].
pub(super) fn plan_step(
    character: &Character,
    root: &Point3<f64>,
    shoulder: &Point3<f64>,
    target: &Point3<f64>,
    side: Side,
    settings: &StepSettings,
    seed: u64,
) -> StepPlan {
    let d = steps::horizontal_distance(shoulder, target);
    let direction = steps::step_direction(shoulder, target)
        .map(|u| u.into_inner())
        .unwrap_or_else(Vector3::z);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let facing = Vector3::z();
    let target_side = steps::target_side(root, &facing, target, side);
    let step = steps::decide(settings, d, target_side, &mut rng);
    let p = steps::draw_p(settings, &mut rng);
    let length = if step.steps() {
        // Never step past the point where the target would be closer than the CRR.
        steps::step_length(settings, d, p)
            .min((d - settings.d_c * 0.5).max(0.0))
            .min(static_step_limit(character))
    } else {
        0.0
    };
    StepPlan {
        step,
        length,
        direction,
        horizontal_distance: d,
    }
}

impl StepPlan {
    /// The step `step` of `length` meters along `direction` toward a target `d` meters from
    /// the shoulder.
    pub(super) fn new(
        step: StepDecision,
        length: f64,
        direction: Vector3<f64>,
        d: f64,
    ) -> StepPlan {
        StepPlan {
            step,
            length,
            direction,
            horizontal_distance: d,
        }
    }
}

/// The longest step the posture search takes ([`static_step_limit`]).
pub(super) fn longest_step(character: &Character) -> f64 {
    static_step_limit(character)
}

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

/// The step over time: where each foot and the root are at a time `t` of the reach.
#[derive(Debug, Clone)]
pub(super) struct Stepping {
    /// The ankle frames at rest, `[right, left]`.
    feet_rest: [IsometryMatrix3<f64>; 2],
    step_vec: Vector3<f64>,
    /// When each foot swings, `(start, end)` seconds; `None` for a foot that stays.
    windows: [Option<(f64, f64)>; 2],
    /// Eased keyframes `(time, position)` of the root; held after the last.
    root_keys: Vec<(f64, Point3<f64>)>,
    /// When the last foot has landed and the root arrived, seconds (0 without a step).
    total: f64,
    root_rest: Point3<f64>,
    settings: StepSettings,
}

impl Stepping {
    /// The timing of `step` (made by the `arm`) for a character starting at `rest`.
    pub(super) fn new(
        character: &Character,
        rest: &Pose,
        step: &StepPlan,
        arm: Limb,
        s: &ReachSettings,
    ) -> Result<Stepping> {
        let rest_frames = character.world_frames(rest);
        let feet_rest = [
            rest_frames[joint::RIGHT_FOOT],
            rest_frames[joint::LEFT_FOOT],
        ];
        let step_vec = step.direction * step.length;
        let (moves, order): ([bool; 2], [usize; 2]) = match step.step {
            StepDecision::NoStep => ([false, false], [0, 1]),
            StepDecision::HalfStep { foot } => {
                let i = foot_index(foot);
                let mut m = [false, false];
                m[i] = true;
                (m, [i, 1 - i])
            }
            StepDecision::FullStep => {
                let lead = foot_index(match arm {
                    Limb::LeftArm => Side::Left,
                    _ => Side::Right,
                });
                ([true, true], [lead, 1 - lead])
            }
        };
        // Each foot's step: a weight shift (at least the first 40 % of `step_time`, longer
        // when the root has far to go) then the swing.
        let shift_part = 0.4 * s.step_time;
        let swing_part = s.step_time - shift_part;
        let root_move = match step.step {
            StepDecision::NoStep => Vector3::zeros(),
            StepDecision::HalfStep { .. } => 0.5 * step_vec,
            StepDecision::FullStep => step_vec,
        };
        // Root keyframes (horizontal position; height stays the rest height).
        let root_rest = Point3::new(rest[dof::ROOT_X], rest[dof::ROOT_Y], rest[dof::ROOT_Z]);
        let sole = |i: usize, moved: bool| -> Point3<f64> {
            let ankle = Point3::from(feet_rest[i].translation.vector);
            let leg = character
                .proportions()
                .leg(if i == 0 { Side::Right } else { Side::Left });
            // Toward the toe, where the swinging foot is going (the COM stays 2 cm inside).
            let toward = 0.3 * (leg.toe - leg.heel).max(0.0);
            let forward = step.direction * toward;
            let c = ankle + forward + if moved { step_vec } else { Vector3::zeros() };
            // Knees bent while stepping (static balance: the swinging leg must reach its
            // landing spot while the root stays over the stance foot).
            Point3::new(
                c.x,
                root_rest.y - STEP_KNEE_BEND * (leg.thigh + leg.shank),
                c.z,
            )
        };
        // A shift of the root to `to` lasts long enough for the eased root to stay below
        // ROOT_SPEED (smoothstep peaks at 1.5 × its mean speed).
        let shift_time = |from: &Point3<f64>, to: &Point3<f64>| {
            shift_part.max(1.5 * (to - from).norm() / ROOT_SPEED)
        };
        let mut root_keys = vec![(0.0, root_rest)];
        let mut windows = [None; 2];
        if step.step.steps() {
            let mut landed = [false, false];
            for &i in order.iter().filter(|&&i| moves[i]) {
                let (t0, from) = root_keys.last().copied().unwrap_or((0.0, root_rest));
                let stance = sole(1 - i, landed[1 - i]);
                let a = t0 + shift_time(&from, &stance);
                let b = a + swing_part;
                root_keys.push((a, stance));
                root_keys.push((b, stance));
                windows[i] = Some((a, b));
                landed[i] = true;
            }
            let (t0, from) = root_keys.last().copied().unwrap_or((0.0, root_rest));
            let end = root_rest + root_move;
            root_keys.push((t0 + shift_time(&from, &end), end));
        }
        let total = root_keys.last().map_or(0.0, |k| k.0);
        Ok(Stepping {
            feet_rest,
            step_vec,
            windows,
            root_keys,
            total,
            root_rest,
            settings: step_settings(character, arm, s)?,
        })
    }

    /// When the last foot has landed and the root arrived, seconds (0 without a step).
    pub(super) fn total(&self) -> f64 {
        self.total
    }

    /// When the last foot lands, seconds (0 without a step).
    pub(super) fn landed(&self) -> f64 {
        self.windows
            .iter()
            .flatten()
            .map(|w| w.1)
            .fold(0.0, f64::max)
    }

    /// The ankle frames `[right, left]` at `t`: a stepping foot waits out its weight shift,
    /// then swings on the foot path.
    pub(super) fn feet(&self, t: f64) -> [IsometryMatrix3<f64>; 2] {
        [0, 1].map(|i| {
            let mut f = self.feet_rest[i];
            if let Some((a, b)) = self.windows[i] {
                let u = ((t - a) / (b - a)).clamp(0.0, 1.0);
                let from = Point3::from(f.translation.vector);
                let to = from + self.step_vec;
                let p = steps::foot_path(from, to, self.settings.foot_lift, u);
                f.translation.vector = p.coords;
            }
            f
        })
    }

    /// The root's position at `t`.
    pub(super) fn root(&self, t: f64) -> Point3<f64> {
        if self.total > 0.0 {
            // Static balance: the root moves over the stance foot before each swing, stays
            // there while the other foot is in the air (dipping a little), and ends midway.
            let mut p = keyed(&self.root_keys, t);
            for &(a, b) in self.windows.iter().flatten() {
                if t > a && t < b {
                    let u = (t - a) / (b - a);
                    // sin², not sin: it leaves and rejoins the root's path at rest (a sine
                    // started the root down at 0.31 m/s within a frame, and the reaching hand
                    // held to its world path showed it).
                    p.y -= self.settings.root_dip * (std::f64::consts::PI * u).sin().powi(2);
                }
            }
            p
        } else {
            self.root_rest
        }
    }
}

/// The position at `t` of eased keyframes `(time, position)` (held after the last).
fn keyed(keys: &[(f64, Point3<f64>)], t: f64) -> Point3<f64> {
    for w in keys.windows(2) {
        let ((t0, p0), (t1, p1)) = (w[0], w[1]);
        if t <= t1 {
            let u = if t1 > t0 {
                smoothstep((t - t0) / (t1 - t0))
            } else {
                1.0
            };
            return p0 + (p1 - p0) * u;
        }
    }
    keys.last().map_or(Point3::origin(), |k| k.1)
}

/// 0 for the right foot, 1 for the left (the order of the feet arrays).
fn foot_index(side: Side) -> usize {
    match side {
        Side::Right => 0,
        Side::Left => 1,
    }
}

/// Both legs' analytic IK, `[right, left]`.
pub(super) fn leg_iks(character: &Character) -> Result<[LimbIk; 2]> {
    Ok([
        leg_ik(character, Limb::RightLeg)?,
        leg_ik(character, Limb::LeftLeg)?,
    ])
}

/// The leg's analytic IK, its α = 0 the knee pointing forward.
fn leg_ik(character: &Character, leg: Limb) -> Result<LimbIk> {
    let ik = LimbIk::new(character.limb_chain(leg))
        .and_then(|ik| ik.with_down(Vector3::y()))
        .map_err(|e| {
            ReachError::Setting(InvalidSetting::new(
                format!("character.{}", leg.name()),
                e.to_string(),
            ))
        })?;
    Ok(ik)
}

/// Lowers the root until both ankles are within 98.5 % of the legs' length from the hips
/// (a planted foot must stay reachable whatever the root does).
pub(super) fn lower_root_for_legs(
    character: &Character,
    pose: &mut Pose,
    feet: &[IsometryMatrix3<f64>; 2],
) {
    let mut frames = character.world_frames(pose);
    lower_root_for_legs_in(character, pose, &mut frames, feet, 0.0);
}

/// [`lower_root_for_legs`] with the pose's world `frames` already computed; they are moved
/// down with the root (lowering the root translates every joint); the legs' need blended over
/// `blend` meters ([`soft_excess`]).
pub(super) fn lower_root_for_legs_in(
    character: &Character,
    pose: &mut Pose,
    frames: &mut [IsometryMatrix3<f64>],
    feet: &[IsometryMatrix3<f64>; 2],
    blend: f64,
) {
    let mut lowered = 0.0;
    for (i, leg) in [Limb::RightLeg, Limb::LeftLeg].into_iter().enumerate() {
        let segments = character.proportions().leg(leg.side());
        let reach = 0.985 * (segments.thigh + segments.shank);
        let hip = character.limb_base_frame_in(leg, frames).translation.vector;
        let hip_y = hip.y - lowered;
        let ankle = feet[i].translation.vector;
        let h = ((hip.x - ankle.x).powi(2) + (hip.z - ankle.z).powi(2)).sqrt();
        if h >= reach {
            continue;
        }
        let allowed = (reach * reach - h * h).sqrt();
        let vertical = hip_y - ankle.y;
        lowered += soft_excess(vertical - allowed, blend);
    }
    if lowered > 0.0 {
        pose[dof::ROOT_Y] -= lowered;
        for f in frames.iter_mut() {
            f.translation.vector.y -= lowered;
        }
    }
}

/// The root starts down this far, meters, before a leg would be stretched to its reach, where the
/// scheduler lowers it smoothly ([`soft_excess`]).
pub(super) const LOWER_BLEND: f64 = 0.02;

/// How far a leg needs the root lowered when its hip is `x` meters higher than it can reach,
/// blended over `b` meters: `x` beyond `b`, nothing below −`b`, and between them the parabola
/// that joins the two with its slope, (x + b)² / 4b — so the root starts down at rest rather
/// than at the speed the stretching leg's hip then has (0.31 m/s within a frame, behind a
/// stepping body, which the reaching hand held to its world path showed). `b` = 0: the hard
/// `max(x, 0)` (the plan's searches, and where the scheduler does not smooth the root).
fn soft_excess(x: f64, b: f64) -> f64 {
    if x <= -b {
        0.0
    } else if x >= b {
        x
    } else {
        (x + b).powi(2) / (4.0 * b)
    }
}

/// Both legs for their ankle frames (`feet[0]` right, `feet[1]` left), knees forward.
pub(super) fn solve_legs(
    character: &Character,
    pose: &mut Pose,
    iks: &[LimbIk; 2],
    feet: &[IsometryMatrix3<f64>; 2],
) {
    let above = character.world_frames(pose);
    solve_legs_in(character, pose, &above, iks, feet);
}

/// [`solve_legs`] with the world frames of the body above the legs already computed.
pub(super) fn solve_legs_in(
    character: &Character,
    pose: &mut Pose,
    above: &[IsometryMatrix3<f64>],
    iks: &[LimbIk; 2],
    feet: &[IsometryMatrix3<f64>; 2],
) {
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
        // (toe-off): the first of 5° steps up to 60° that works, then halved five times
        // toward the last that did not (to 0.16°), so the heel rises smoothly over frames.
        let tilted = |pitch: f64| {
            IsometryMatrix3::from_parts(
                goal_world.translation,
                goal_world.rotation * Rotation3::from_axis_angle(&Vector3::x_axis(), pitch),
            )
        };
        let mut q = solve(&goal_world);
        let mut pitch = 0.0f64;
        while q.is_none() && pitch < 60f64.to_radians() {
            pitch += 5f64.to_radians();
            q = solve(&tilted(pitch));
        }
        if q.is_some() && pitch > 0.0 {
            let (mut failing, mut working) = (pitch - 5f64.to_radians(), pitch);
            for _ in 0..5 {
                let middle = 0.5 * (failing + working);
                match solve(&tilted(middle)) {
                    Some(found) => {
                        working = middle;
                        q = Some(found);
                    }
                    None => failing = middle,
                }
            }
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
}
