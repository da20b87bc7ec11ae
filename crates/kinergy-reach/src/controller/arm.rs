//! The arm controller (Huang, Kapadia & Terzopoulos §3.2, with [`crate::profile`]): the hand
//! moves on the straight line from where it is when the arm controller starts to the target
//! with the speed profile (the paper's ease-out by default); each frame the arm is solved by
//! analytic IK with Kallmann's orbit-angle search in the current shoulder frame. A goal out
//! of reach is replaced by the nearest reachable point on the shoulder→goal line, so an
//! unreachable target ends at the nearest point.
//!
//! Beyond the paper, the arm moves continuously: each frame's orbit search starts at the
//! previous frame's orbit angle ([`ArmFollower`]), and the arm shown *tracks* the analytic
//! solution rather than taking it: the solution's own joint velocity fed forward, the lag
//! closed in [`ARM_TRACKING_TIME`] no faster than the arm can brake, the joint velocity
//! changing by at most [`ARM_ACCELERATION`]·dt a frame and no DoF faster than
//! [`ARM_MAX_SPEED`] — each bound scaling the whole vector, so the arm keeps its direction of
//! motion. The hand relative to the shoulder is a function of the arm's DoFs alone (the
//! girdle follows them), so its speed cannot jump either, whatever the body does. Why: from
//! the hanging, straight arm the analytic solution flexes the elbow like the square root of
//! the hand's travel (0.12 rad for the first 1.7 mm). Clamping each DoF alone let the shoulder
//! swing on while the elbow was held back, and the hand jumped sideways at 2.5 m/s; a ramped
//! joint-speed limit instead chased those solutions for 0.28 s and then dropped to the
//! profile's speed in one frame (0.7 → 0.2 m/s on 9 of 10 grid targets); a stepping body
//! moving the shoulder away from the hand's world path threw it from 0.7 to 2.1 m/s.
//!
//! The shoulder rides the clavicle, which the girdle turns with the arm's elevation
//! ([`crate::character::girdle`]): the arm's base depends on the arm's own solution. Every
//! solve is a short fixed-point iteration ([`GIRDLE_PASSES`]): solve with the base where the
//! girdle puts it for the previous frame's arm, move the base to where the girdle puts it for
//! the solution, solve again. The base moves by the clavicle's end, at most ~5 cm per radian of
//! elevation, while the solution's elevation moves by about a radian per meter of base: each
//! pass shrinks the base's error some tenfold. Near a straight arm the elevation turns much
//! faster with the base and the plain iteration can swing from side to side of the fixed
//! point: the passes mix the last two (Anderson mixing of depth one), which settles there.

use std::ops::Range;

use kinergy_motion::Side;
use kinergy_motion::nalgebra::{IsometryMatrix3, Point3, Rotation3, Vector2, Vector3};
use kinergy_solver::analytic::{LimbIk, OrbitSearch, OrbitSense};

use crate::character::{Character, DofLimit, Limb, Pose, angle_difference};
use crate::error::{ReachError, Result};
use crate::profile::SpeedProfile;

/// The largest change of an arm DoF between frames before the orbit angle is chosen anew by
/// posture (radians; a reach moves far less per frame).
const ARM_JUMP: f64 = 0.2;

/// The fastest an arm DoF turns, rad/s (peak elbow and shoulder speeds of fast human
/// reaches are around 10 rad/s; ours stay below).
const ARM_MAX_SPEED: f64 = 8.0;

/// The fastest the reaching hand moves relative to its shoulder, m/s (human reaches peak
/// around 1–2 m/s; the body's own motion adds to it).
const HAND_MAX_SPEED: f64 = 2.0;

/// The most a reaching arm DoF's speed changes, rad/s² (the whole change of the arm's joint
/// velocity scaled alike): about the hand's 6 m/s² of a brisk 0.4 m reach in 0.6 s
/// (minimum jerk: 5.77 D/T²) on the half-arm lever, 0.4 m.
const ARM_ACCELERATION: f64 = 16.0;

/// How long the reaching arm takes to close on the posture it lags behind, seconds (the
/// gain of [`track`] is its inverse).
const ARM_TRACKING_TIME: f64 = 0.05;

/// The most the reaching hand's velocity relative to the shoulder changes, m/s² (a brisk
/// reach peaks near 6 m/s²; [`ARM_ACCELERATION`] alone lets all seven DoFs add up to more):
/// 0.13 m/s a frame at 60 Hz, under a quarter of what a speed jump is at 30 Hz.
const HAND_ACCELERATION: f64 = 8.0;

/// Below this elbow flexion, radians, the reaching arm's orbit angle is chosen by posture
/// rather than carried on ([`ArmFollower::follow`]).
const NEARLY_STRAIGHT: f64 = 0.3;

/// The elbow's flexion among the arm's seven DoFs (shoulder swing and twist before it).
const ELBOW: usize = 3;

/// Bisection steps of [`ArmFollower`]'s hand bound (the change to 1/256).
const HAND_BISECTIONS: usize = 8;

/// How far, radians, the arm shown may lie from the goal posture and still count as on it.
const HELD: f64 = 1e-9;

/// How far, radians, the arm may lag behind its goal posture once its profile has run its
/// course and still count as arrived (1e-4 rad moves the hand at most the arm's length ×
/// 1e-4, under 0.1 mm: a synthetic clip ends with its hand at rest where its target is).
const CAUGHT_UP: f64 = 1e-4;

/// The most solves of the arm's fixed-point iteration with the girdle (module docs).
pub(super) const GIRDLE_PASSES: usize = 5;

/// The girdle iteration stops when the arm's base moved less than this, meters.
const GIRDLE_TOLERANCE: f64 = 1e-6;

/// Solves `limb`'s arm with its base riding the girdle. `base` is the arm's base frame while
/// the arm's DoFs are `at`; the first solve uses the base for the arm `first` (the previous
/// frame's), each later one the base for the solution before it. `solve` gives an orbit
/// angle and an arm for a base frame. The last solution found, if any.
fn on_girdle(
    character: &Character,
    limb: Limb,
    base: &IsometryMatrix3<f64>,
    at: &[f64; 7],
    first: &[f64; 7],
    mut solve: impl FnMut(&IsometryMatrix3<f64>) -> Option<(f64, [f64; 7])>,
) -> Option<(f64, [f64; 7])> {
    // Only the base's origin moves (the base frame does not turn with the girdle): the
    // iteration is on that point, x ↦ g(x) = where the girdle puts the base for the arm
    // solved at x, with Anderson mixing of depth one (below).
    let mut b = character.arm_base_moved(limb, base, at, first);
    let mut found = None;
    let mut last: Option<(Vector3<f64>, Vector3<f64>)> = None;
    for _ in 0..GIRDLE_PASSES {
        let Some((a, q)) = solve(&b) else { break };
        found = Some((a, q));
        let x = b.translation.vector;
        let residual = character
            .arm_base_moved(limb, base, at, &q)
            .translation
            .vector
            - x;
        if residual.norm() < GIRDLE_TOLERANCE {
            break;
        }
        // Near a straight arm the solution's elevation turns fast with the base and the
        // plain iteration x + r can swing from side to side of the fixed point without
        // settling (the map's slope near −1); the secant along the last step, γ, takes the
        // point where the residual, linear between the two passes, is least.
        let mut step = residual;
        if let Some((x0, r0)) = last {
            let dr = residual - r0;
            let dd = dr.norm_squared();
            if dd > 0.0 {
                let gamma = dr.dot(&residual) / dd;
                step = residual - gamma * ((x - x0) + dr);
            }
        }
        last = Some((x, residual));
        b.translation.vector = x + step;
    }
    found
}

/// The arm's analytic IK: α = 0 the lowest elbow (world down) and growing α raising the
/// elbow outward — a left-handed turn about the shoulder→wrist axis for the right arm.
pub(super) fn arm_ik(character: &Character, arm: Limb) -> Result<LimbIk> {
    let sense = match arm.side() {
        Side::Right => OrbitSense::LeftHanded,
        Side::Left => OrbitSense::RightHanded,
    };
    LimbIk::new(character.limb_chain(arm))
        .map(|ik| ik.with_sense(sense))
        .map_err(|e| ReachError::Setting {
            field: "character.arm".into(),
            why: e.to_string(),
        })
}

/// The reaching arm over the frames of a reach: where the hand started, the last solution
/// and orbit angle, and the previous frame's posture.
#[derive(Debug, Clone)]
pub(super) struct ArmFollower {
    limb: Limb,
    dofs: Range<usize>,
    ik: LimbIk,
    search: OrbitSearch,
    /// Where the hand was when the arm controller started.
    hand_start: Option<Point3<f64>>,
    /// The last solution, kept when a later solve fails.
    last: Option<[f64; 7]>,
    /// The orbit angle of the previous frame's arm: each frame's search starts there, so the
    /// elbow (and the arm's twist) moves continuously; before the first solve, the search
    /// starts at the angle whose posture is closest to the resting arm.
    alpha: Option<f64>,
    /// The previous frame's arm DoFs (the rest pose's before the first frame).
    previous: [f64; 7],
    /// The arm's joint velocity over the previous frame, rad/s (rest before the first).
    velocity: [f64; 7],
    /// The previous frame's goal posture (the analytic solution the arm tracks), on the
    /// current path.
    goal: Option<[f64; 7]>,
    /// How far the arm shown lay from its goal posture at the last frame's end, radians
    /// (the largest DoF's gap).
    lag: f64,
    /// The hand relative to the shoulder (the arm's base frame) at the last frame's end, and
    /// how far it moved over that frame.
    hand: Option<(Point3<f64>, Vector3<f64>)>,
    /// Upper arm + forearm + hand, meters.
    length: f64,
}

impl ArmFollower {
    /// The `limb`'s follower, starting from `rest`.
    pub(super) fn new(character: &Character, limb: Limb, rest: &Pose) -> Result<ArmFollower> {
        let ik = arm_ik(character, limb)?;
        let dofs = character.limb_dofs(limb);
        let segments = character.proportions().arm(limb.side());
        Ok(ArmFollower {
            limb,
            length: segments.upper_arm + segments.forearm + segments.hand,
            previous: std::array::from_fn(|i| rest[dofs.start + i]),
            velocity: [0.0; 7],
            goal: None,
            lag: 0.0,
            hand: None,
            dofs,
            ik,
            search: OrbitSearch::default(),
            hand_start: None,
            last: None,
            alpha: None,
        })
    }

    /// The hand (the chain's tip) in `pose` with the arm's base frame at `base`; `or` if the
    /// chain cannot say.
    pub(super) fn hand(
        &self,
        character: &Character,
        base: &IsometryMatrix3<f64>,
        pose: &Pose,
        or: Point3<f64>,
    ) -> Point3<f64> {
        character
            .limb_chain(self.limb)
            .end_position(base, &pose[self.dofs.clone()])
            .unwrap_or(or)
    }

    /// One pass of the arm controller, `elapsed` seconds after it started: the hand's goal
    /// on its path to `target` (the path starting where the hand is at the first call), the
    /// arm solved for it into `pose`. A failed solve keeps the last solution; on later passes
    /// of a frame, one that gives nothing at all leaves the pose's arm alone. Returns the
    /// orbit angle solved at, if any.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn follow(
        &mut self,
        character: &Character,
        pose: &mut Pose,
        base: &IsometryMatrix3<f64>,
        target: &Point3<f64>,
        profile: &SpeedProfile,
        elapsed: f64,
        first_pass: bool,
    ) -> Option<f64> {
        let hand_now = self.hand(character, base, pose, *target);
        let start = *self.hand_start.get_or_insert(hand_now);
        let goal = profile.position(&start, target, elapsed);
        let at: [f64; 7] = std::array::from_fn(|i| pose[self.dofs.start + i]);
        // The previous frame's goal, not the arm shown, which lags it: the reference for a
        // flip of the orbit angle and the girdle's first guess. (Against the lagging arm the
        // flip test fired on most frames of a start, each time searching 72 orbit angles.)
        let previous = self.goal.unwrap_or(self.previous);
        // Near a straight arm the orbit angle hardly shows in the posture but decides the
        // twist that follows: from the hanging arm, keeping the first angle found turned the
        // goal's twist 1.5 rad in 0.35 s (the hand spinning at 0.6 m/s with the elbow). While
        // the elbow is nearly straight the angle is the one closest to the last posture.
        let near = match self.alpha {
            Some(a) if previous[ELBOW] >= NEARLY_STRAIGHT => Near::Alpha(a),
            Some(a) => Near::PostureAround(previous, a),
            None => Near::Posture(previous),
        };
        let (ik, search) = (&self.ik, &self.search);
        let solved = on_girdle(character, self.limb, base, &at, &previous, |b| {
            let mut solved = solve_arm_near(ik, b, &goal, search, near);
            // Through a straight arm the orbit angle's reference flips: when the posture
            // jumps, take the angle closest to the previous frame's posture instead.
            if let Some((_, q)) = solved
                && (0..5).any(|i| (q[i] - previous[i]).abs() > ARM_JUMP)
            {
                let again = solve_arm_near(ik, b, &goal, search, Near::Posture(previous));
                if again.is_some() {
                    solved = again;
                }
            }
            solved
        });
        let q = solved.map(|(_, q)| q).or(self.last).unwrap_or_default();
        if first_pass || q != [0.0; 7] {
            pose[self.dofs.clone()].copy_from_slice(&q);
        }
        self.last = Some(q);
        solved.map(|(a, _)| a)
    }

    /// Ends a frame of `dt` seconds: the orbit angle solved in it (`alpha`, if any) is where
    /// the next frame's search starts, and the arm of `pose` — the frame's goal posture, the
    /// analytic solution — is replaced by the arm [tracking](track) it from the previous
    /// frames' motion. True when the arm shown is off the goal posture.
    ///
    /// The goal's own joint velocity (from the previous frame's goal) is fed forward, so a
    /// goal moving smoothly is followed without lag; what the arm lags behind it closes in
    /// [`ARM_TRACKING_TIME`], no faster than it can brake at [`ARM_ACCELERATION`]; no DoF
    /// turns faster than [`ARM_MAX_SPEED`], the hand moves at most [`HAND_MAX_SPEED`]
    /// relative to the shoulder (a goal far from the hand — one beyond reach, whose nearest
    /// point swings round — would otherwise be chased at the joints' top speed), and the
    /// joint velocity changes by at most [`ARM_ACCELERATION`]·dt a frame, the whole change
    /// scaled alike.
    pub(super) fn end_frame(
        &mut self,
        character: &Character,
        pose: &mut Pose,
        alpha: Option<f64>,
        dt: f64,
    ) -> bool {
        if alpha.is_some() {
            self.alpha = alpha;
        }
        let goal: [f64; 7] = std::array::from_fn(|i| pose[self.dofs.start + i]);
        let goal_velocity = match self.goal {
            Some(before) => std::array::from_fn(|i| (goal[i] - before[i]) / dt),
            None => [0.0; 7],
        };
        self.goal = Some(goal);
        let limits = character.limb_limits(self.limb, pose);
        let fade = self.edge_fade(&limits, &goal, &goal_velocity);
        let goal_velocity = goal_velocity.map(|v| v * fade);
        let hand_gap = self.hand.and_then(|(hand, _)| {
            let chain = character.limb_chain(self.limb);
            let to = chain
                .end_position(&IsometryMatrix3::identity(), &goal)
                .ok()?;
            Some((to - hand).norm())
        });
        let mut wanted = track(&goal, &goal_velocity, &self.previous, hand_gap);
        self.brake_before_limits(&limits, &mut wanted, ARM_ACCELERATION);
        self.cap_hand_speed(character, &mut wanted, dt);
        let mut velocity = accelerate(&self.velocity, &wanted, ARM_ACCELERATION * dt);
        self.bound_hand_acceleration(character, &mut velocity, dt);
        // The bounds above scale the whole change: a DoF braking for its limit while others
        // speed up could be held back from braking. Its own braking comes first.
        self.brake_before_limits(&limits, &mut velocity, 2.0 * ARM_ACCELERATION);
        let values = &mut pose[self.dofs.clone()];
        for (i, value) in values.iter_mut().enumerate() {
            *value = self.previous[i] + velocity[i] * dt;
        }
        self.lag = values
            .iter()
            .zip(&goal)
            .fold(0.0, |m, (v, g)| m.max((v - g).abs()));
        self.lag > HELD
    }

    /// How much of the goal's joint velocity the arm takes on (0–1): all of it, unless the
    /// goal's elbow is straightening onto its limit — the reach's edge, where the goal stops
    /// dead — sooner than the arm, moving at the goal's speed, could brake at
    /// [`ARM_ACCELERATION`]. Near full extension the elbow turns like the square root of the
    /// hand's distance from the edge: a hand closing slowly on it has the shoulder and elbow
    /// turning fast against each other (2.6 and −2.3 rad/s at 0.3 m/s on a floor reach with a
    /// stoop), the goal stops as the elbow straightens, and an arm taking on that speed to the
    /// end ran 0.2 rad (14 cm of hand) past it and back. The fade is `2·A·t / v`, `t` the
    /// time the goal's elbow needs to reach its limit at its speed and `v` the goal's fastest
    /// DoF speed: the arm brakes from `v` within the goal's remaining travel, `v·t`.
    fn edge_fade(&self, limits: &[DofLimit; 7], goal: &[f64; 7], goal_velocity: &[f64; 7]) -> f64 {
        let DofLimit::Revolute { min, .. } = limits[ELBOW] else {
            return 1.0;
        };
        let closing = -goal_velocity[ELBOW];
        let fastest = goal_velocity.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        if closing <= 0.0 || fastest <= 0.0 {
            return 1.0;
        }
        let time = (goal[ELBOW] - min).max(0.0) / closing;
        (2.0 * ARM_ACCELERATION * time / fastest).min(1.0)
    }

    /// Holds the change of the hand's motion to [`HAND_ACCELERATION`]: the hand's displacement
    /// relative to the shoulder over the frame with the joint `velocity` differs from the
    /// last frame's by at most A·dt², the change from the last frame's joint velocity scaled
    /// back (by bisection) where it would not. Every joint turning at its bound can move the
    /// hand at √7 × the lever × [`ARM_ACCELERATION`], a one-frame change of 0.3 m/s at 60 Hz.
    fn bound_hand_acceleration(&self, character: &Character, velocity: &mut [f64; 7], dt: f64) {
        let Some((hand, moved)) = self.hand else {
            return;
        };
        let chain = character.limb_chain(self.limb);
        let shoulder = IsometryMatrix3::identity();
        let largest = HAND_ACCELERATION * dt * dt;
        let change = |v: &[f64; 7]| -> Option<f64> {
            let next: [f64; 7] = std::array::from_fn(|i| self.previous[i] + v[i] * dt);
            let to = chain.end_position(&shoulder, &next).ok()?;
            Some(((to - hand) - moved).norm())
        };
        if change(velocity).is_none_or(|c| c <= largest) {
            return;
        }
        let from = self.velocity;
        let at =
            |s: f64| -> [f64; 7] { std::array::from_fn(|i| from[i] + s * (velocity[i] - from[i])) };
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..HAND_BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if change(&at(mid)).is_some_and(|c| c <= largest) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        *velocity = at(lo);
    }

    /// Whether the arm has caught up with the posture it tracks (within [`CAUGHT_UP`]): a
    /// profile that has run its course is over only then (the goal stops at once, the arm
    /// brakes onto it).
    pub(super) fn caught_up(&self) -> bool {
        self.lag <= CAUGHT_UP
    }

    /// Slows the joint `velocity` where it heads for the character's limits (at `pose`): its
    /// speed toward the limit at most √(`a`·gap) — with `a` = [`ARM_ACCELERATION`], the
    /// margin of [`track`], half the deceleration it has; with 2A, the most it can brake — for
    /// a revolute DoF toward either end of its range, a swing radially toward its ellipse. The
    /// goal can stop dead on a limit — the elbow straightens onto the reach sphere's edge and
    /// stays — and the arm tracking it would run into the limit and be clamped there within a
    /// frame.
    fn brake_before_limits(&self, limits: &[DofLimit; 7], velocity: &mut [f64; 7], a: f64) {
        let at = &self.previous;
        let mut i = 0;
        while i < 7 {
            if let DofLimit::Revolute { min, max } = limits[i] {
                let up = (a * (max - at[i]).max(0.0)).sqrt();
                let down = (a * (at[i] - min).max(0.0)).sqrt();
                velocity[i] = velocity[i].clamp(-down, up);
            } else if let DofLimit::Swing { rx, ry } = limits[i]
                && i + 1 < 7
            {
                let s = Vector2::new(at[i], at[i + 1]);
                let rho = (s.x / rx).hypot(s.y / ry);
                if let Some(out) = s.try_normalize(1e-9)
                    && rho > 0.0
                {
                    // The boundary along the swing's own direction: s / ρ.
                    let gap = s.norm() * (1.0 / rho - 1.0).max(0.0);
                    let v = Vector2::new(velocity[i], velocity[i + 1]);
                    let excess = v.dot(&out) - (a * gap).sqrt();
                    if excess > 0.0 {
                        velocity[i] -= excess * out.x;
                        velocity[i + 1] -= excess * out.y;
                    }
                }
                i += 1;
            }
            i += 1;
        }
    }

    /// Scales the joint `velocity` down so that the hand moves at most [`HAND_MAX_SPEED`]
    /// relative to the shoulder over a frame of `dt` seconds from the previous posture.
    fn cap_hand_speed(&self, character: &Character, velocity: &mut [f64; 7], dt: f64) {
        let largest = HAND_MAX_SPEED * dt;
        // No DoF moves the hand further than the arm's length times its turn: most frames
        // need no forward kinematics to know the hand is slow enough.
        let turned: f64 = velocity.iter().map(|v| (v * dt).abs()).sum();
        if self.length * turned <= largest {
            return;
        }
        let chain = character.limb_chain(self.limb);
        let shoulder = IsometryMatrix3::identity();
        let next: [f64; 7] = std::array::from_fn(|i| self.previous[i] + velocity[i] * dt);
        // The hand at the previous posture: kept by `settle`, else computed.
        let from = match self.hand {
            Some((hand, _)) => Ok(hand),
            None => chain.end_position(&shoulder, &self.previous),
        };
        let (Ok(from), Ok(to)) = (from, chain.end_position(&shoulder, &next)) else {
            return;
        };
        let moved = (to - from).norm();
        if moved > largest {
            let scale = largest / moved;
            velocity.iter_mut().for_each(|v| *v *= scale);
        }
    }

    /// The arm's posture at the last frame's end.
    pub(super) fn last_posture(&self) -> &[f64; 7] {
        &self.previous
    }

    /// Keeps the frame's final arm posture (`pose`, clamped) as the previous one, and the
    /// arm's joint velocity over the frame of `dt` seconds that led to it (whoever drove it:
    /// the analytic IK takes over from a person's arm at the speed it moved).
    pub(super) fn settle(&mut self, character: &Character, pose: &Pose, dt: f64) {
        let now: [f64; 7] = std::array::from_fn(|i| pose[self.dofs.start + i]);
        // A twist wrapped a turn by the clamp (`wrap_or_clamp`) did not move.
        self.velocity = std::array::from_fn(|i| angle_difference(now[i], self.previous[i]) / dt);
        self.previous = now;
        let chain = character.limb_chain(self.limb);
        self.hand = chain
            .end_position(&IsometryMatrix3::identity(), &now)
            .ok()
            .map(|h| {
                (
                    h,
                    self.hand.map_or(Vector3::zeros(), |(before, _)| h - before),
                )
            });
    }

    /// Takes the arm over as it is in `pose` (from another driver): the next
    /// [`ArmFollower::follow`] starts a new straight path where the hand is then.
    pub(super) fn resume_from(&mut self) {
        self.hand_start = None;
        self.goal = None;
        self.last = None;
        self.alpha = None;
    }

    /// The length of the hand's straight path: from where it started to `target` (0 before
    /// the arm controller started).
    pub(super) fn path_length(&self, target: &Point3<f64>) -> f64 {
        self.hand_start.map_or(0.0, |h| (target - h).norm())
    }
}

/// The joint velocity with which an arm at `at` follows a `goal` posture moving at
/// `goal_velocity`: the goal's velocity (at most [`ARM_MAX_SPEED`]) plus the gap closed in
/// [`ARM_TRACKING_TIME`], the closing speed no more than the arm can brake from within the gap
/// at [`ARM_ACCELERATION`] (√(A·gap), half the distance a full brake needs: the goal moves
/// meanwhile), and the whole at most [`ARM_MAX_SPEED`] in every DoF (scaled alike). The hand
/// closes on where the goal puts it, `hand_gap` meters away, no faster than it can brake at
/// [`HAND_ACCELERATION`] either (√(H·gap); the closing motion moves the hand by about the
/// gap): the hand's bound is what brakes a long arm, and closing at the joints' rate alone ran
/// a lagging arm past its goal and back (a 3 cm return after a low reach with a bend).
fn track(
    goal: &[f64; 7],
    goal_velocity: &[f64; 7],
    at: &[f64; 7],
    hand_gap: Option<f64>,
) -> [f64; 7] {
    let mut feed = *goal_velocity;
    scale_to(&mut feed, ARM_MAX_SPEED);
    let gap: [f64; 7] = std::array::from_fn(|i| goal[i] - at[i]);
    let largest = gap.iter().fold(0.0f64, |m, g| m.max(g.abs()));
    let closing = if largest > 0.0 {
        let joints =
            (largest / ARM_TRACKING_TIME).min((ARM_ACCELERATION * largest).sqrt()) / largest;
        match hand_gap {
            Some(h) if h > 0.0 => joints.min((HAND_ACCELERATION / h).sqrt()),
            _ => joints,
        }
    } else {
        0.0
    };
    let mut wanted: [f64; 7] = std::array::from_fn(|i| feed[i] + gap[i] * closing);
    scale_to(&mut wanted, ARM_MAX_SPEED);
    wanted
}

/// The joint velocity after a frame whose change from `velocity` toward `wanted` is at most
/// `largest` in every DoF, the whole change scaled alike (the arm keeps the direction of its
/// change in joint space).
fn accelerate(velocity: &[f64; 7], wanted: &[f64; 7], largest: f64) -> [f64; 7] {
    let mut change: [f64; 7] = std::array::from_fn(|i| wanted[i] - velocity[i]);
    scale_to(&mut change, largest);
    std::array::from_fn(|i| velocity[i] + change[i])
}

/// Scales `values` so that none is larger than `largest` in magnitude (unchanged when none
/// is; non-finite values become 0).
fn scale_to(values: &mut [f64; 7], largest: f64) {
    if values.iter().any(|v| !v.is_finite()) {
        *values = [0.0; 7];
        return;
    }
    let top = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    if top > largest {
        let scale = largest / top;
        values.iter_mut().for_each(|v| *v *= scale);
    }
}

/// Holds the arm DoFs `values` to at most `max_step` radians from `previous`; true when they
/// were held back.
fn limit_speed(values: &mut [f64], previous: &[f64; 7], max_step: f64) -> bool {
    // A human joint turns at most so fast: near full extension a millimetre of shoulder
    // motion (a balance correction) swings the elbow by tens of degrees, which the arm then
    // catches up with over a few frames instead of in one.
    let largest = values
        .iter()
        .zip(previous)
        .map(|(v, b)| (v - b).abs())
        .fold(0.0, f64::max);
    if largest <= max_step {
        return false;
    }
    // The whole step is scaled, not each DoF clamped: the arm keeps the direction of its
    // motion in joint space (clamping the elbow alone while the shoulder swings on would throw
    // the hand sideways).
    let scale = max_step / largest;
    for (value, before) in values.iter_mut().zip(previous) {
        *value = before + (*value - before) * scale;
    }
    true
}

/// The arm that does not reach: it hangs from its shoulder under its own weight while the
/// body steps, twists, bends and squats. Its hand is held where it hangs at rest relative to
/// the shoulder, turned with the trunk about the vertical, a little closer so the elbow
/// relaxes, and never lower than [`IDLE_HAND_CLEARANCE`] above the floor; the arm is solved
/// for it by the same analytic IK as the reaching arm, continuous from frame to frame and no
/// faster than [`ARM_MAX_SPEED`]. (Left at its rest angles the arm would stick out straight
/// behind a bending trunk.)
#[derive(Debug, Clone)]
pub(super) struct IdleArm {
    limb: Limb,
    dofs: Range<usize>,
    ik: LimbIk,
    search: OrbitSearch,
    /// The hand's offset from the shoulder at rest, world, shortened by [`IDLE_RELAX`].
    hang: Vector3<f64>,
    /// The trunk's heading at rest: the shoulder frame's x axis on the ground.
    heading: Vector3<f64>,
    /// The previous frame's arm DoFs (the rest pose's before the first frame).
    previous: [f64; 7],
    /// The previous frame's orbit angle.
    alpha: Option<f64>,
    /// The last goal in the arm's base frame and the arm solved for it.
    solved: Option<(Point3<f64>, [f64; 7])>,
}

/// How much closer to the shoulder the idle hand hangs than the straight arm at rest (a
/// relaxed elbow bends a little, and a straight arm is the IK's singular posture).
const IDLE_RELAX: f64 = 0.995;

/// The lowest the idle hand goes, meters above the floor (y = 0).
pub(super) const IDLE_HAND_CLEARANCE: f64 = 0.1;

impl IdleArm {
    /// The `limb`'s idle arm, hanging as in `rest`.
    pub(super) fn new(character: &Character, limb: Limb, rest: &Pose) -> Result<IdleArm> {
        let ik = arm_ik(character, limb)?;
        let dofs = character.limb_dofs(limb);
        let base = character.limb_base_frame(limb, rest);
        let hand = character
            .limb_chain(limb)
            .end_position(&base, &rest[dofs.clone()])
            .unwrap_or_else(|_| Point3::from(base.translation.vector));
        Ok(IdleArm {
            limb,
            previous: std::array::from_fn(|i| rest[dofs.start + i]),
            dofs,
            ik,
            search: OrbitSearch::default(),
            hang: (hand.coords - base.translation.vector) * IDLE_RELAX,
            heading: ground_heading(&base),
            alpha: None,
            solved: None,
        })
    }

    /// Solves the idle arm into `pose`, the arm's base frame at `base`; keeps the pose's arm
    /// when nothing is found. Returns the orbit angle solved at, if any. The goal depends on
    /// the base's rotation only (and on its height near the floor): while the trunk keeps
    /// its orientation — the root shifted for balance, the body stepping upright — the last
    /// solution is reused.
    pub(super) fn hang(
        &mut self,
        character: &Character,
        pose: &mut Pose,
        base: &IsometryMatrix3<f64>,
    ) -> Option<f64> {
        // The hand hangs below where the shoulder is with the clavicle at rest.
        let at: [f64; 7] = std::array::from_fn(|i| pose[self.dofs.start + i]);
        let rest = character.arm_base_moved(self.limb, base, &at, &[0.0; 7]);
        let now = ground_heading(&rest);
        let yaw = self.heading.cross(&now).y.atan2(self.heading.dot(&now));
        let turned = Rotation3::from_axis_angle(&Vector3::y_axis(), yaw) * self.hang;
        let mut goal = Point3::from(rest.translation.vector + turned);
        goal.y = goal.y.max(IDLE_HAND_CLEARANCE);
        let local = rest.inverse() * goal;
        if let Some((last, q)) = self.solved
            && (last - local).norm() < 1e-9
        {
            pose[self.dofs.clone()].copy_from_slice(&q);
            return self.alpha;
        }
        let near = match self.alpha {
            Some(a) => Near::Alpha(a),
            None => Near::Posture(self.previous),
        };
        let (ik, search) = (&self.ik, &self.search);
        let (alpha, q) = on_girdle(character, self.limb, base, &at, &self.previous, |b| {
            solve_arm_near(ik, b, &goal, search, near)
        })?;
        pose[self.dofs.clone()].copy_from_slice(&q);
        self.solved = Some((local, q));
        Some(alpha)
    }

    /// Ends a frame of `dt` seconds as [`ArmFollower::end_frame`] does, and keeps the frame's
    /// posture as the previous one.
    pub(super) fn end_frame(&mut self, pose: &mut Pose, alpha: Option<f64>, dt: f64) {
        if alpha.is_some() {
            self.alpha = alpha;
        }
        limit_speed(
            &mut pose[self.dofs.clone()],
            &self.previous,
            ARM_MAX_SPEED * dt,
        );
    }

    /// Keeps the frame's final arm posture (`pose`, clamped) as the previous one.
    pub(super) fn settle(&mut self, pose: &Pose) {
        self.previous = std::array::from_fn(|i| pose[self.dofs.start + i]);
    }

    /// Keeps the orbit angle solved in a frame (`alpha`, if any) for the next frame's search,
    /// when another controller holds the arm to its speed ([`ArmFollower::end_frame`]: the
    /// reaching arm hanging before it reaches).
    pub(super) fn solved_at(&mut self, alpha: Option<f64>) {
        if alpha.is_some() {
            self.alpha = alpha;
        }
    }
}

/// The direction of a frame's x axis on the ground (x if it points straight up or down).
fn ground_heading(frame: &IsometryMatrix3<f64>) -> Vector3<f64> {
    let x = frame.rotation * Vector3::x();
    Vector3::new(x.x, 0.0, x.z)
        .try_normalize(1e-9)
        .unwrap_or_else(Vector3::x)
}

/// Where an arm's orbit search starts.
#[derive(Debug, Clone, Copy)]
enum Near {
    /// The default start ([`OrbitSearch::start`]).
    Default,
    /// At this orbit angle (the previous frame's), with small increments.
    Alpha(f64),
    /// At the angle whose posture is closest to this one (in the shoulder and elbow DoFs).
    Posture([f64; 7]),
    /// As [`Near::Posture`], among the angles within 30° of this one.
    PostureAround([f64; 7], f64),
}

/// The `arm` (its analytic IK `ik`) for the hand at `goal` (world), the body as in `pose`,
/// position mode with the orbit search and the base riding the girdle; a goal out of reach
/// is moved to the nearest reachable point on the shoulder→goal line.
pub(super) fn solve_arm(
    character: &Character,
    arm: Limb,
    ik: &LimbIk,
    pose: &Pose,
    goal: &Point3<f64>,
    search: &OrbitSearch,
) -> Option<[f64; 7]> {
    let base = character.limb_base_frame(arm, pose);
    let at: [f64; 7] = std::array::from_fn(|i| pose[arm.dofs().start + i]);
    on_girdle(character, arm, &base, &at, &at, |b| {
        solve_arm_near(ik, b, goal, search, Near::Default)
    })
    .map(|(_, q)| q)
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
            Near::PostureAround(q0, a) => closest_alpha_around(&ik, p, &q0, a),
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
    // Out of reach, the point at the reach radius on the goal's line; else the goal itself.
    // Then, where the limits refuse it (or rounding at full extension does), a point a little
    // closer on the same line. The order matters near full extension, where the elbow turns
    // like the square root of the distance: 0.1 % of the distance is 0.09 rad of elbow, and a
    // goal just beyond reach solved 0.1 % short threw the elbow from straight to bent within a
    // frame while one just within reach kept it straight.
    let (_, outer) = ik.position_reach().unwrap_or_else(|| ik.wrist_reach());
    let aim = if r > outer && r > 1e-9 {
        outer / r
    } else {
        1.0
    };
    for scale in SCALES {
        let p = if r > 1e-9 {
            Point3::from(local.coords * (aim * scale))
        } else {
            local
        };
        if let Some(found) = solve(&p) {
            return Some(found);
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
        .filter_map(|a| posture_distance(ik, p, q0, a).map(|d| (a, d)))
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .map(|(a, _)| a)
}

/// The squared distance, in the shoulder and elbow DoFs, from `q0` of the posture reaching
/// `p` at orbit angle `a`; `None` when there is none within the limits.
fn posture_distance(ik: &LimbIk, p: &Point3<f64>, q0: &[f64; 7], a: f64) -> Option<f64> {
    let q = ik.solve_position_at(p, a).ok()?;
    ik.within_limits(&q)
        .then(|| (0..5).map(|i| (q[i] - q0[i]).powi(2)).sum())
}

/// The orbit angle within 30° of `center`, on a 5° grid, whose posture within the limits is
/// closest to `q0` in the shoulder and elbow DoFs, found by walking downhill from `center`
/// ([`closest_alpha`] searches all 72 angles; from one frame to the next the closest angle
/// moves little, and a flip is caught by [`ARM_JUMP`]'s test). Three to five solves a frame
/// where a scan of the 13 angles took 13.
fn closest_alpha_around(ik: &LimbIk, p: &Point3<f64>, q0: &[f64; 7], center: f64) -> Option<f64> {
    const STEP: f64 = 5.0 * std::f64::consts::PI / 180.0;
    const STEPS: i32 = 6;
    let distance = |k: i32| posture_distance(ik, p, q0, center + f64::from(k) * STEP);
    let Some(mut best) = distance(0) else {
        // The last angle is no longer within the limits: the whole window, scanned.
        return (-STEPS..=STEPS)
            .filter_map(|k| distance(k).map(|d| (k, d)))
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .map(|(k, _)| center + f64::from(k) * STEP);
    };
    let mut at: i32 = 0;
    for direction in [1, -1] {
        let mut k = at + direction;
        let mut moved = false;
        while k.abs() <= STEPS {
            match distance(k) {
                Some(d) if d < best => {
                    best = d;
                    at = k;
                    moved = true;
                    k += direction;
                }
                _ => break,
            }
        }
        if moved {
            break;
        }
    }
    Some(center + f64::from(at) * STEP)
}

/// The shoulder: the arm chain's base, in world.
pub(super) fn shoulder_position(character: &Character, pose: &Pose, arm: Limb) -> Point3<f64> {
    let f = character.limb_base_frame(arm, pose);
    Point3::from(f.translation.vector)
}

/// The hand: the arm's fingertip joint, in world.
pub(super) fn hand_position(character: &Character, pose: &Pose, arm: Limb) -> Point3<f64> {
    let frames = character.world_frames(pose);
    Point3::from(frames[arm.joints()[3]].translation.vector)
}

/// The hand's distance from `target` with the arm solved by [`solve_arm`] at `pose`.
pub(super) fn arm_error(
    character: &Character,
    pose: &Pose,
    arm: Limb,
    ik: &LimbIk,
    target: &Point3<f64>,
) -> f64 {
    match solve_arm(character, arm, ik, pose, target, &OrbitSearch::default()) {
        Some(q) => {
            let mut p = *pose;
            p[character.limb_dofs(arm)].copy_from_slice(&q);
            (hand_position(character, &p, arm) - target).norm()
        }
        None => f64::INFINITY,
    }
}
