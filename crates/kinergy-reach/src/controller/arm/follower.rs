//! The reaching arm over the frames of a reach ([`ArmFollower`]): the hand's goal on its
//! straight path, the arm solved for it on the girdle, and the arm shown tracking that
//! solution within the arm's and the hand's speed and acceleration bounds.

use std::ops::Range;

use kinergy_motion::nalgebra::{IsometryMatrix3, Point3, Vector2, Vector3};
use kinergy_solver::analytic::{LimbIk, OrbitSearch};

use super::solve::{Near, arm_ik, on_girdle, solve_arm_near};
use super::tracking::{ARM_ACCELERATION, HAND_ACCELERATION, accelerate, track};
use crate::character::{Character, DofLimit, Limb, Pose, angle_difference};
use crate::error::Result;
use crate::profile::SpeedProfile;

/// The largest change of an arm DoF between frames before the orbit angle is chosen anew by
/// posture (radians; a reach moves far less per frame).
pub(super) const ARM_JUMP: f64 = 0.2;

/// The fastest the reaching hand moves relative to its shoulder, m/s (human reaches peak
/// around 1–2 m/s; the body's own motion adds to it).
const HAND_MAX_SPEED: f64 = 2.0;

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

/// A moment on the hand's speed profile: the profile that times the hand's straight path to
/// the target, and the seconds since the arm controller started on it.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ProfileTime<'a> {
    /// The hand's speed profile.
    pub(crate) profile: &'a SpeedProfile,
    /// Seconds since the arm controller started.
    pub(crate) elapsed: f64,
}

/// The reaching arm over the frames of a reach: where the hand started, the last solution
/// and orbit angle, and the previous frame's posture.
#[derive(Debug, Clone)]
pub(crate) struct ArmFollower {
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
    pub(crate) fn new(character: &Character, limb: Limb, rest: &Pose) -> Result<ArmFollower> {
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
    pub(crate) fn hand(
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

    /// One pass of the arm controller at `now` on its profile: the hand's goal on its path to
    /// `target` (the path starting where the hand is at the first call), the arm solved for it
    /// into `pose`. A failed solve keeps the last solution; on later passes of a frame, one
    /// that gives nothing at all leaves the pose's arm alone. Returns the orbit angle solved
    /// at, if any.
    pub(crate) fn follow(
        &mut self,
        character: &Character,
        pose: &mut Pose,
        base: &IsometryMatrix3<f64>,
        target: &Point3<f64>,
        now: ProfileTime<'_>,
        first_pass: bool,
    ) -> Option<f64> {
        let hand_now = self.hand(character, base, pose, *target);
        let start = *self.hand_start.get_or_insert(hand_now);
        let goal = now.profile.position(&start, target, now.elapsed);
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
    /// The goal's own joint velocity (from the previous frame's goal) is fed forward, so a goal
    /// moving smoothly is followed without lag; what the arm lags behind it closes in
    /// [`ARM_TRACKING_TIME`](super::tracking::ARM_TRACKING_TIME), no faster than it can brake at
    /// [`ARM_ACCELERATION`]; no DoF turns faster than
    /// [`ARM_MAX_SPEED`](super::tracking::ARM_MAX_SPEED), the hand moves at most [`HAND_MAX_SPEED`]
    /// relative to the shoulder (a goal far from the hand — one beyond reach, whose nearest point
    /// swings round — would otherwise be chased at the joints' top speed), and the joint velocity
    /// changes by at most [`ARM_ACCELERATION`]·dt a frame, the whole change scaled alike.
    pub(crate) fn end_frame(
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
    pub(crate) fn caught_up(&self) -> bool {
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
    pub(crate) fn last_posture(&self) -> &[f64; 7] {
        &self.previous
    }

    /// Keeps the frame's final arm posture (`pose`, clamped) as the previous one, and the
    /// arm's joint velocity over the frame of `dt` seconds that led to it (whoever drove it:
    /// the analytic IK takes over from a person's arm at the speed it moved).
    pub(crate) fn settle(&mut self, character: &Character, pose: &Pose, dt: f64) {
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
    pub(crate) fn resume_from(&mut self) {
        self.hand_start = None;
        self.goal = None;
        self.last = None;
        self.alpha = None;
    }

    /// The length of the hand's straight path: from where it started to `target` (0 before
    /// the arm controller started).
    pub(crate) fn path_length(&self, target: &Point3<f64>) -> f64 {
        self.hand_start.map_or(0.0, |h| (target - h).norm())
    }
}
