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
//! as far as the step needs (from [`STEP_KNEE_BEND`] to a shallow lunge, [`LUNGE_KNEE_BEND`]) and
//! never higher than both legs reach their feet from.
//!
//! The step's length is eq. 9's; whether the body can take it is the balance model's to say
//! ([`StepBalance`]): the planned step is checked through each swing — the stance foot flat,
//! the COM over it, the joints within limits — and one the body cannot hold at any knee bend
//! is shortened to the longest it can. There is no fixed cap: a 1.75 m body holds most of eq.
//! 9's steps between the cylinders as drawn and shortens the MRR's 0.633 m to 0.425 m (a full
//! step) or 0.564 m (a half step).

use kinergy_io::InvalidSetting;
use kinergy_motion::Side;
use kinergy_motion::nalgebra::{IsometryMatrix3, Point3, Rotation3, Vector3};
use kinergy_solver::analytic::{LimbIk, OrbitSearch};
use rand::SeedableRng;
use rand::rngs::ChaCha8Rng;

use super::balance::rebalance;
use super::settings::ReachSettings;
use crate::character::{Character, Limb, Pose, dof, joint};
use crate::error::{ReachError, Result};
use crate::profile::smoothstep;
use crate::steps::{self, StepDecision, StepSettings};

/// The fastest the root moves between stance feet, m/s (the weight shift before a swing
/// lasts longer when the root has further to go).
const ROOT_SPEED: f64 = 1.0;

/// The root's least drop while stepping, as a fraction of the leg length.
const STEP_KNEE_BEND: f64 = 0.12;

/// The root's deepest drop while stepping, as a fraction of the leg length: a shallow lunge's
/// (the hips a quarter of the leg lower than standing). Deeper, a step looks like kneeling.
const LUNGE_KNEE_BEND: f64 = 0.25;

/// The swinging leg's reach to its landing spot, as a fraction of the leg's length (not quite
/// straight).
const SWING_REACH: f64 = 0.97;

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
    /// The root's drop while a foot swings, as a fraction of the leg length: enough for the
    /// swinging leg to reach its landing spot while the root stays over the stance foot
    /// ([`step_knee_bend`]).
    pub knee_bend: f64,
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
/// MRR cylinders decides no step, a half step or a full step, eq. 9 its length with its random
/// p — never past the point where the target would be closer than the CRR. Whether the body
/// can take that step is the balance model's to say ([`StepBalance::fit`]), not a cap here.
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
        steps::step_length(settings, d, p).min((d - settings.d_c * 0.5).max(0.0))
    } else {
        0.0
    };
    StepPlan::new(character, step, length, direction, d)
}

impl StepPlan {
    /// The step `step` of `length` meters along `direction` toward a target `d` meters from
    /// the shoulder, the knees bent as little as lets the swinging leg reach its landing spot
    /// ([`step_knee_bend`]; the balance model may bend them more, [`StepBalance::fit`]).
    pub(super) fn new(
        character: &Character,
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
            knee_bend: step_knee_bend(character, length).unwrap_or(LUNGE_KNEE_BEND),
        }
    }
}

/// How far past the stance ankle the root stands while the other foot swings, meters: over
/// the stance foot toward its toe (the COM 30 % of the foot ahead of the ankle).
fn stance_lead(character: &Character) -> f64 {
    let leg = character.proportions().leg(Side::Right);
    0.3 * (leg.toe - leg.heel).max(0.0)
}

/// The least root drop (a fraction of the leg length, at least [`STEP_KNEE_BEND`]) that lets
/// the swinging leg reach a step of `length` meters while the root stays over the stance
/// foot; `None` beyond a lunge ([`LUNGE_KNEE_BEND`]). A first guess from the legs' lengths:
/// whether the body holds the step is [`StepBalance`]'s to say.
pub(super) fn step_knee_bend(character: &Character, length: f64) -> Option<f64> {
    let leg = character.proportions().leg(Side::Right);
    let l = leg.thigh + leg.shank;
    let ahead = (length - stance_lead(character)).max(0.0);
    let reach = SWING_REACH * l;
    if ahead > reach {
        return None;
    }
    let drop = (reach * reach - ahead * ahead).sqrt();
    let bend = (1.0 - drop / l).max(STEP_KNEE_BEND);
    (bend <= LUNGE_KNEE_BEND + 1e-12).then_some(bend)
}

/// How many knee bends between a step's least ([`step_knee_bend`]) and a lunge
/// ([`LUNGE_KNEE_BEND`]) the balance model tries.
const KNEE_BEND_TRIES: usize = 5;

/// Where in a foot's swing the balance model checks the body: about to lift (both feet flat,
/// the legs spread the most), lifted off, mid-swing, about to land, landed (fractions of the
/// swing).
const SWING_CHECKS: [f64; 6] = [0.0, 0.15, 0.4, 0.7, 0.95, 1.0];

/// How far a swinging foot's toe tip may be from its path, meters (the leg may not put the
/// foot there flat: its heel rises about the toe as it leaves the ground).
const SWING_FOOT_TOLERANCE: f64 = 0.01;

/// How close the longest step the balance allows is found, meters.
const LENGTH_TOLERANCE: f64 = 0.005;

/// The balance model of a step (beyond the paper, which does not test balance): the body
/// standing at rest, stepping as [`Stepping`] times it, is checked at [`SWING_CHECKS`] of each
/// swing with its legs solved for the planned feet — the stance foot flat where it stands (no
/// heel rising on the one foot carrying the body), the swinging foot where its path puts it,
/// every joint within its limits, and the COM the reach's balance margin
/// ([`ReachSettings::balance_margin`]) inside the support.
/// A step passes at the least knee bend that holds; a longer one than eq. 9 asks for is never
/// taken, and one the body cannot hold at a lunge is shortened to the longest it can.
pub(super) struct StepBalance<'a> {
    character: &'a Character,
    rest: &'a Pose,
    arm: Limb,
    settings: &'a ReachSettings,
    steps: StepSettings,
    legs: [LimbIk; 2],
}

impl<'a> StepBalance<'a> {
    /// The model for `character` standing at `rest`, reaching with `arm` under `settings`.
    pub(super) fn new(
        character: &'a Character,
        rest: &'a Pose,
        arm: Limb,
        settings: &'a ReachSettings,
    ) -> Result<StepBalance<'a>> {
        Ok(StepBalance {
            character,
            rest,
            arm,
            settings,
            steps: step_settings(character, arm, settings)?,
            legs: leg_iks(character)?,
        })
    }

    /// The leg controller's parameters the steps are drawn with ([`step_settings`]).
    pub(super) fn steps(&self) -> &StepSettings {
        &self.steps
    }

    /// Whether the body holds `step` with its knees bent as the step says.
    pub(super) fn holds(&self, step: &StepPlan) -> bool {
        if !step.step.steps() || step.length <= 0.0 {
            return true;
        }
        let Ok(stepping) = Stepping::new(self.character, self.rest, step, self.arm, self.settings)
        else {
            return false;
        };
        let c = self.character;
        // Never lower than a lunge (the legs spread pull the root down).
        let leg = c.proportions().leg(Side::Right);
        let lowest = self.rest[dof::ROOT_Y]
            - LUNGE_KNEE_BEND * (leg.thigh + leg.shank)
            - self.steps.root_dip;
        stepping.windows.iter().flatten().all(|&(a, b)| {
            SWING_CHECKS.iter().all(|u| {
                let t = a + u * (b - a);
                let feet = stepping.feet(t);
                let root = stepping.root(t);
                let mut pose = *self.rest;
                pose[dof::ROOT_X] = root.x;
                pose[dof::ROOT_Y] = root.y;
                pose[dof::ROOT_Z] = root.z;
                // As every animated frame is ([`super::balance::BalanceCorrection`]): the legs
                // solved, the root shifted toward the support, up to nine times.
                let wanted = self.settings.balance_margin;
                let mut frames;
                let mut pass = 0;
                loop {
                    lower_root_for_legs(c, &mut pose, &feet);
                    solve_legs(c, &mut pose, &self.legs, &feet);
                    frames = c.world_frames(&pose);
                    match rebalance(c, &frames, wanted, 1.5).shift {
                        Some(shift) if pass < 9 => {
                            pose[dof::ROOT_X] += shift.x;
                            pose[dof::ROOT_Z] += shift.y;
                            pass += 1;
                        }
                        _ => break,
                    }
                }
                // The stance foot exactly where it stands, flat; the swinging one near its path
                // (its heel may rise about the toe as it leaves the ground).
                let placed = [joint::RIGHT_FOOT, joint::LEFT_FOOT]
                    .iter()
                    .zip(&feet)
                    .enumerate()
                    .all(|(i, (&j, want))| {
                        let got = &frames[j];
                        let leg = [Limb::RightLeg, Limb::LeftLeg][i];
                        let toe = c.limb_chain(leg).end_effector();
                        let off = (got.translation.vector - want.translation.vector).norm();
                        let toe_off = ((got.translation.vector + got.rotation * toe)
                            - (want.translation.vector + want.rotation * toe))
                            .norm();
                        // (A matrix difference: `angle()` of a near-identity rotation can be NaN.)
                        let turn = (got.rotation.matrix() - want.rotation.matrix()).norm();
                        let swinging = stepping.windows[i].is_some_and(|(a, b)| t > a && t < b);
                        if swinging {
                            toe_off < SWING_FOOT_TOLERANCE
                        } else {
                            off < 1e-3 && turn < 1e-2
                        }
                    });
                let margin = rebalance(c, &frames, wanted, 1.0).margin;
                placed
                    && pose[dof::ROOT_Y] >= lowest - 1e-9
                    && c.joint_limits_ok(&pose).is_ok()
                    && margin >= wanted
            })
        })
    }

    /// `step` with the least knee bend from its own to a lunge at which the body holds it;
    /// `None` where none does.
    pub(super) fn balanced(&self, step: &StepPlan) -> Option<StepPlan> {
        if !step.step.steps() {
            return Some(*step);
        }
        let least = step_knee_bend(self.character, step.length)?;
        (0..KNEE_BEND_TRIES)
            .map(|k| {
                let u = k as f64 / (KNEE_BEND_TRIES - 1) as f64;
                StepPlan {
                    knee_bend: least + (LUNGE_KNEE_BEND - least) * u,
                    ..*step
                }
            })
            .find(|s| self.holds(s))
    }

    /// The step the body takes for the drawn `step`: as drawn where it holds it, else the
    /// longest shorter one it holds (to [`LENGTH_TOLERANCE`]); no step where even the shortest
    /// does not hold.
    pub(super) fn fit(&self, step: &StepPlan) -> StepPlan {
        if let Some(held) = self.balanced(step) {
            return held;
        }
        self.longest(step).unwrap_or(StepPlan {
            step: StepDecision::NoStep,
            length: 0.0,
            ..*step
        })
    }

    /// The longest step of `step`'s kind and direction, no longer than it, that the body holds.
    pub(super) fn longest(&self, step: &StepPlan) -> Option<StepPlan> {
        let with = |length: f64| {
            StepPlan::new(
                self.character,
                step.step,
                length,
                step.direction,
                step.horizontal_distance,
            )
        };
        if let Some(held) = self.balanced(&with(step.length)) {
            return Some(held);
        }
        let (mut short, mut long) = (0.0, step.length);
        let mut best = None;
        while long - short > LENGTH_TOLERANCE {
            let middle = 0.5 * (short + long);
            match self.balanced(&with(middle)) {
                Some(held) => {
                    short = middle;
                    best = Some(held);
                }
                None => long = middle,
            }
        }
        best
    }
}

/// The longest step the posture search tries, meters: one the swinging leg reaches with the
/// root over the stance foot at a lunge ([`LUNGE_KNEE_BEND`]); whether the body holds it is
/// [`StepBalance::longest`]'s to say.
pub(super) fn longest_step(character: &Character) -> f64 {
    let leg = character.proportions().leg(Side::Right);
    let l = leg.thigh + leg.shank;
    let reach = SWING_REACH * l;
    let drop = (1.0 - LUNGE_KNEE_BEND) * l;
    (reach * reach - drop * drop).max(0.0).sqrt() + stance_lead(character)
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
            // Along the stance foot toward its toe as far as the step goes that way (a foot is
            // long but narrow: a root moved sideways along a lateral step's direction would
            // leave the COM beside the foot).
            let toe_ward = feet_rest[i].rotation * Vector3::y();
            let toe_ward = Vector3::new(toe_ward.x, 0.0, toe_ward.z)
                .try_normalize(1e-9)
                .unwrap_or_else(Vector3::z);
            let forward =
                toe_ward * (stance_lead(character) * step.direction.dot(&toe_ward).max(0.0));
            let c = ankle + forward + if moved { step_vec } else { Vector3::zeros() };
            // Knees bent while stepping (static balance: the swinging leg must reach its
            // landing spot while the root stays over the stance foot).
            Point3::new(
                c.x,
                root_rest.y - step.knee_bend * (leg.thigh + leg.shank),
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
        let mut stepping = Stepping {
            feet_rest,
            step_vec,
            windows,
            root_keys,
            total,
            root_rest,
            settings: step_settings(character, arm, s)?,
        };
        // Each key no higher than both legs reach their feet from: a root the legs pulled down
        // between keys would spring up when a foot left the ground.
        for k in 1..stepping.root_keys.len() {
            let (t, key) = stepping.root_keys[k];
            let mut pose = *rest;
            pose[dof::ROOT_X] = key.x;
            pose[dof::ROOT_Y] = key.y;
            pose[dof::ROOT_Z] = key.z;
            lower_root_for_legs(character, &mut pose, &stepping.feet(t));
            stepping.root_keys[k].1.y = pose[dof::ROOT_Y];
        }
        Ok(stepping)
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

/// The most a leg's orbit search turns the knee out, radians: the default search's angles
/// beyond it (57° to 130°) are not a person's knee, and no leg solved in the synthetic set
/// (26,000 solves) or the bench's reaches found one there — each leg whose foot cannot lie flat
/// tried all sixteen before its heel rose, ten now, the same postures found.
pub(super) const KNEE_ORBIT_MAX: f64 = 47.0 * std::f64::consts::PI / 180.0;

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
        // The knee's natural orbit (α = 0) first, then the default search's angles up to
        // [`KNEE_ORBIT_MAX`].
        let alphas = OrbitSearch::default().alphas().ok();
        let solve = |goal_world: &IsometryMatrix3<f64>| -> Option<[f64; 7]> {
            let goal = base.inverse() * goal_world;
            let search = alphas
                .clone()
                .into_iter()
                .flatten()
                .filter(|a| *a <= KNEE_ORBIT_MAX);
            iks[i]
                .first_within_limits(&goal, std::iter::once(0.0).chain(search))
                .map(|(_, q)| q)
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
