//! The reaching arm over the frames of a reach ([`ArmFollower`]): the hand's goal on its
//! straight path, the arm solved for it on the girdle, and the arm shown tracking that
//! solution within the arm's and the hand's speed and acceleration bounds.

use std::ops::Range;

use kinergy_motion::nalgebra::{IsometryMatrix3, Point3, Vector2, Vector3};
use kinergy_solver::analytic::{LimbIk, OrbitSearch};

use super::clock::ProfileClock;
use super::solve::{Near, arm_ik, on_girdle, solve_arm_near, solve_arm_outward};
use super::tracking::{
    ARM_ACCELERATION, HAND_ACCELERATION, PROFILE_ARM_ACCELERATION, REACH_HAND_ACCELERATION,
    accelerate, track,
};
use crate::character::{Character, DofLimit, Limb, Pose, angle_difference};
use crate::error::Result;
use crate::profile::SpeedProfile;

/// The largest change of an arm DoF between frames before the orbit angle is chosen anew by
/// posture (radians; a reach moves far less per frame).
pub(super) const ARM_JUMP: f64 = 0.2;

/// The fastest the reaching hand moves relative to its shoulder, m/s (human reaches peak
/// around 1–2 m/s; the body's own motion adds to it).
const HAND_MAX_SPEED: f64 = 2.0;

/// Below this elbow flexion, radians, the reaching arm's orbit angle is the one whose posture
/// is nearest the last, rather than the one whose elbow is nearest the last
/// ([`ArmFollower::follow`]): near a straight arm the elbow hardly leaves the shoulder→hand
/// axis.
const NEARLY_STRAIGHT: f64 = 0.3;

/// How much farther than the profile's goal along its line the goal posture's hand may move in
/// a frame round the shoulder ([`ArmFollower::follow`]).
const SWEEP_SLACK: f64 = 1.01;

/// How many times the clock's advance may double in a frame where the goal posture's hand runs
/// round the shoulder slower than the profile (2^8: where the line heads for the shoulder).
const SWEEP_DOUBLINGS: usize = 8;

/// Bisection steps of the clock where the goal posture's hand runs round the shoulder.
const SWEEP_BISECTIONS: usize = 10;

/// How far beyond the elbow's full flexion a goal too close to the shoulder is put, as a
/// share of that distance.
const INNER_MARGIN: f64 = 1.002;

/// The least speed, rad/s, at which the goal's elbow closes on its straight limit for
/// [`ArmFollower::edge_fade`] to hold the arm back.
const EDGE_CLOSING: f64 = 0.01;

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
/// the target, and the seconds since the arm controller started on it (the wall clock; the
/// profile's own clock, [`ProfileClock`], ramps and waits for the hand).
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
    /// The most an arm DoF's speed changes, rad/s² ([`ARM_ACCELERATION`], or
    /// [`PROFILE_ARM_ACCELERATION`] for the arm a speed profile drives).
    acceleration: f64,
    limb: Limb,
    dofs: Range<usize>,
    ik: LimbIk,
    search: OrbitSearch,
    /// The hand's straight path and where its goal is on it, from the arm controller's first
    /// frame.
    clock: Option<ProfileClock>,
    /// The last solution, kept when a later solve fails.
    last: Option<[f64; 7]>,
    /// The orbit angle of the previous frame's arm (from the lowest elbow): a nearly straight
    /// arm's search is centred there where the posture has no angle of its own; before the
    /// first solve, the search takes the angle whose posture is closest to the resting arm.
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
    /// The hand in the world at the last frame's end, and how far it moved over that frame.
    world_hand: Option<(Point3<f64>, Vector3<f64>)>,
    /// The last frame's duration, seconds (0 before the first).
    frame_time: f64,
    /// How far the arm shown lagged behind its goal along the path at the last frame's end,
    /// meters (negative: ahead).
    path_lag: f64,
    /// Whether the arm was taken over from another driver ([`ArmFollower::resume_from`]).
    handed_over: bool,
    /// Upper arm + forearm + hand, meters.
    length: f64,
    /// The shoulder joint in the arm's base frame, and the least distance from it at which
    /// the hand is reached with the wrist straight: the elbow flexed to its limit, meters.
    inner: (Point3<f64>, f64),
}

impl ArmFollower {
    /// The `limb`'s follower, starting from `rest`.
    pub(crate) fn new(character: &Character, limb: Limb, rest: &Pose) -> Result<ArmFollower> {
        let ik = arm_ik(character, limb)?;
        let dofs = character.limb_dofs(limb);
        let segments = character.proportions().arm(limb.side());
        let flexed = match character.limb_limits(limb, rest)[ELBOW] {
            DofLimit::Revolute { max, .. } => max,
            _ => std::f64::consts::PI,
        };
        let folded = character.limb_chain(limb).fk(
            &IsometryMatrix3::identity(),
            &[0.0, 0.0, 0.0, flexed, 0.0, 0.0, 0.0],
        );
        let inner = match folded {
            Ok(pose) => {
                let shoulder = pose.joint_position(0);
                (shoulder, (pose.end - shoulder).norm())
            }
            Err(_) => (Point3::origin(), 0.0),
        };
        Ok(ArmFollower {
            acceleration: ARM_ACCELERATION,
            inner,
            limb,
            length: segments.upper_arm + segments.forearm + segments.hand,
            previous: std::array::from_fn(|i| rest[dofs.start + i]),
            velocity: [0.0; 7],
            goal: None,
            lag: 0.0,
            hand: None,
            world_hand: None,
            frame_time: 0.0,
            path_lag: 0.0,
            handed_over: false,
            dofs,
            ik,
            search: OrbitSearch::default(),
            clock: None,
            last: None,
            alpha: None,
        })
    }

    /// The most an arm DoF's speed changes on this frame, rad/s²: the follower's own while the
    /// profile's goal runs along its line, [`ARM_ACCELERATION`] once it has arrived — the arm
    /// then holds the hand as the person's arm does (at 30 Hz the faster arm threw a hand that
    /// had stopped 1.6 cm off its target and back as the trunk settled).
    fn acceleration(&self) -> f64 {
        match &self.clock {
            Some(c) if c.covered() < c.length() => self.acceleration,
            _ => ARM_ACCELERATION,
        }
    }

    /// The follower for an arm a speed profile drives: its joints take up the body's motion
    /// at [`PROFILE_ARM_ACCELERATION`].
    pub(crate) fn driven_by_profile(mut self) -> ArmFollower {
        self.acceleration = PROFILE_ARM_ACCELERATION;
        self
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
    /// `target` (the path starting where the hand is at the first call, the profile's clock
    /// advanced on each frame's first pass), the arm solved for it into `pose` with the elbow
    /// nearest where it was. A goal too close to the shoulder for the elbow's flexion is moved
    /// out to the nearest reachable point on the shoulder→goal line, as one out of reach is
    /// moved in, and the clock then goes as far along the line as moves that point by the
    /// profile's own step, so the hand runs round the shoulder at the profile's speed. A failed
    /// solve keeps the last solution; on later passes of a frame, one that gives nothing at all
    /// leaves the pose's arm alone. Returns the orbit angle solved at, if any.
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
        let mut before = None;
        match self.clock.as_mut() {
            Some(clock) if first_pass => {
                before = Some(clock.covered());
                clock.advance(now.profile, now.elapsed, self.path_lag);
            }
            Some(_) => {}
            None => {
                // The hand's speed along its path as it starts: a step carries it. (Not after a
                // hand-over, where the approach starts from rest as the person's arm left it:
                // a goal moving at once, from a stretched arm overhead, was solved through the
                // swing's half turn.)
                let along = (target - hand_now).try_normalize(1e-12);
                let speed = match (self.world_hand, along) {
                    (Some((before, _)), Some(along))
                        if self.frame_time > 0.0 && !self.handed_over =>
                    {
                        (hand_now - before).dot(&along) / self.frame_time
                    }
                    _ => 0.0,
                };
                self.clock = Some(ProfileClock::new(
                    now.profile,
                    hand_now,
                    *target,
                    speed.min(HAND_MAX_SPEED),
                    now.elapsed,
                ));
            }
        }
        let at: [f64; 7] = std::array::from_fn(|i| pose[self.dofs.start + i]);
        // The previous frame's goal, not the arm shown, which lags it: the reference for a
        // flip of the orbit angle and the girdle's first guess. (Against the lagging arm the
        // flip test fired on most frames of a start, each time searching 72 orbit angles.)
        let previous = self.goal.unwrap_or(self.previous);
        // The orbit angle is the one whose elbow is nearest the last: the angle measured from
        // the lowest elbow, carried from frame to frame, swung the goal's shoulder at 20 rad/s
        // where the hand passes below or above the shoulder (the lowest elbow turns half a turn
        // about the shoulder→hand axis as the axis passes the vertical: a step's hand, passing
        // below the shoulder, thrown to 0.64 m/s), and the posture nearest the last, sought on a
        // grid of angles, jumped between two near minima (0.1 rad of shoulder swing in a frame).
        // Near a straight arm, where the elbow hardly leaves the axis, the orbit angle hardly
        // shows in the posture but decides the twist that follows: from the hanging arm,
        // keeping the first angle found turned the goal's twist 1.5 rad in 0.35 s (the hand
        // spinning at 0.6 m/s with the elbow). While the elbow is nearly straight the angle is
        // the one closest to the last posture.
        let near = match (self.alpha, self.elbow_direction(character, &previous)) {
            (Some(_), Some(elbow)) if previous[ELBOW] >= NEARLY_STRAIGHT => Near::Elbow(elbow),
            (Some(a), _) => Near::PostureAround(previous, a),
            (None, _) => Near::Posture(previous),
        };
        let (ik, search) = (&self.ik, &self.search);
        let (center, inner) = self.inner;
        let solve = |goal: &Point3<f64>| {
            let mut outward = false;
            let solved = on_girdle(character, self.limb, base, &at, &previous, |b| {
                // Too close to the shoulder for the elbow's flexion: out on the shoulder→goal
                // line to where it flexes to its limit (a hair beyond).
                let local = b.inverse() * goal - center;
                let r = local.norm();
                outward = r < INNER_MARGIN * inner && r > 1e-9;
                let point = if outward {
                    b * (center + local * (INNER_MARGIN * inner / r))
                } else {
                    *goal
                };
                let mut solved = solve_arm_near(ik, b, &point, search, near);
                if solved.is_none() {
                    outward = true;
                    solved = solve_arm_outward(ik, b, goal, search, near);
                }
                // Through a straight arm the orbit angle's reference flips: when the posture
                // jumps, take the angle closest to the previous frame's posture instead.
                if let Some((_, q)) = solved
                    && (0..5).any(|i| (q[i] - previous[i]).abs() > ARM_JUMP)
                {
                    let again = solve_arm_near(ik, b, goal, search, Near::Posture(previous));
                    if again.is_some() {
                        solved = again;
                    }
                }
                solved
            });
            (solved, outward)
        };
        let goal = self.clock.as_ref().map_or(*target, ProfileClock::goal);
        let (mut solved, outward) = solve(&goal);
        if let (Some(from), Some(clock), true) = (before, self.clock.as_mut(), outward)
            && let (Some((_, was)), _) = solve(&clock.point_at(from))
        {
            // Round the shoulder the goal posture's hand moves as far as the profile's goal
            // along its line would (both solved with the body as it is now: its own motion is
            // not the arm's): the clock goes as far along the line as keeps it so. (Put out
            // along the shoulder→goal line, the hand crawled where the line heads for the
            // shoulder and swept round it where the line passes close: from 0.2 to 0.03 m/s and
            // up to 1.8 m/s on held-out raises.)
            let hand_at = |q: &[f64; 7]| {
                let moved = character.arm_base_moved(self.limb, base, &at, q);
                character.limb_chain(self.limb).end_position(&moved, q).ok()
            };
            let length = clock.length();
            let to = clock.covered();
            let step = to - from;
            let start = hand_at(&was);
            let moved = |covered: f64| -> Option<(f64, (f64, [f64; 7]))> {
                let found = solve(&clock.point_at(covered)).0?;
                let d = (hand_at(&found.1)? - start?).norm();
                Some((d, found))
            };
            if step > 0.0 && start.is_some() {
                // Bracket the advance whose hand moves `step`, then bisect.
                let (mut lo, mut hi, mut kept) = (from, to, None);
                let mut reach = to;
                for _ in 0..SWEEP_DOUBLINGS {
                    match moved(reach) {
                        Some((d, found)) if d < step && reach < length => {
                            lo = reach;
                            kept = Some(found);
                            reach = (from + 2.0 * (reach - from)).min(length);
                            hi = reach;
                        }
                        Some((d, found)) if d < step => {
                            lo = reach;
                            hi = reach;
                            kept = Some(found);
                            break;
                        }
                        _ => {
                            hi = reach;
                            break;
                        }
                    }
                }
                for _ in 0..SWEEP_BISECTIONS {
                    if hi - lo <= 0.0 {
                        break;
                    }
                    let mid = 0.5 * (lo + hi);
                    match moved(mid) {
                        Some((d, found)) if d <= step * SWEEP_SLACK => {
                            lo = mid;
                            kept = Some(found);
                        }
                        _ => hi = mid,
                    }
                }
                if kept.is_some() {
                    clock.hold_at(now.profile, lo);
                    solved = kept;
                }
            }
        }
        let q = solved.map(|(_, q)| q).or(self.last).unwrap_or_default();
        if first_pass || q != [0.0; 7] {
            pose[self.dofs.clone()].copy_from_slice(&q);
        }
        self.last = Some(q);
        solved.map(|(a, _)| a)
    }

    /// The direction from the shoulder to the elbow of the arm at `q`, in the arm's base frame
    /// (`None` where they meet).
    fn elbow_direction(&self, character: &Character, q: &[f64; 7]) -> Option<Vector3<f64>> {
        let pose = character
            .limb_chain(self.limb)
            .fk(&IsometryMatrix3::identity(), q)
            .ok()?;
        (pose.joint_position(1) - pose.joint_position(0)).try_normalize(1e-9)
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
    ///
    /// The hand's velocity changes by at most [`REACH_HAND_ACCELERATION`]·dt a frame in the
    /// world while the arm reaches (`world`: the arm's base frame for the goal posture, the body
    /// as in `pose`) — the arm takes up the body's motion, which a hand on Huang's world-frame
    /// line must not show — and by [`HAND_ACCELERATION`]·dt relative to the shoulder while it
    /// hangs before its reach (`None`: the body carries it).
    pub(crate) fn end_frame(
        &mut self,
        character: &Character,
        pose: &mut Pose,
        alpha: Option<f64>,
        dt: f64,
        world: Option<&IsometryMatrix3<f64>>,
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
        // The goal's hand in the arm's base frame (the shoulder's), once.
        let chain = character.limb_chain(self.limb);
        let goal_hand = chain.end_position(&IsometryMatrix3::identity(), &goal).ok();
        let hand_gap = self
            .hand
            .and_then(|(hand, _)| Some((goal_hand? - hand).norm()));
        let a = self.acceleration();
        let mut wanted = track(&goal, &goal_velocity, &self.previous, hand_gap, a, dt);
        self.brake_before_limits(&limits, &mut wanted, a);
        self.cap_hand_speed(character, &mut wanted, dt);
        let mut velocity = accelerate(&self.velocity, &wanted, a * dt);
        match world {
            Some(base) => self.bound_world_acceleration(character, base, &goal, &mut velocity, dt),
            None => self.bound_hand_acceleration(character, &mut velocity, dt),
        }
        // The bounds above scale the whole change: a DoF braking for its limit while others
        // speed up could be held back from braking. Its own braking comes first.
        self.brake_before_limits(&limits, &mut velocity, 2.0 * a);
        let values = &mut pose[self.dofs.clone()];
        for (i, value) in values.iter_mut().enumerate() {
            *value = self.previous[i] + velocity[i] * dt;
        }
        self.lag = values
            .iter()
            .zip(&goal)
            .fold(0.0, |m, (v, g)| m.max((v - g).abs()));
        let shown: [f64; 7] = std::array::from_fn(|i| values[i]);
        self.path_lag = match (world, &self.clock) {
            (Some(base), Some(clock)) => {
                let at = |q: &[f64; 7]| self.world_position(character, base, &goal, q);
                // At the goal the girdle leaves the base where it is.
                match (goal_hand.map(|h| base * h), at(&shown)) {
                    (Some(to), Some(hand)) => (to - hand).dot(&clock.direction()),
                    _ => 0.0,
                }
            }
            _ => 0.0,
        };
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
        // An elbow that rests on its limit (a goal out of reach, the arm straight) does not
        // close on it: its rounding of a micro-radian a second once zeroed the whole feed for a
        // frame, and the hand's speed jumped 0.28 → 0.12 m/s under a twisting trunk.
        if closing <= EDGE_CLOSING || fastest <= 0.0 {
            return 1.0;
        }
        let time = (goal[ELBOW] - min).max(0.0) / closing;
        (2.0 * self.acceleration() * time / fastest).min(1.0)
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
        *velocity = scaled_back(&from, velocity, |v| change(v).is_some_and(|c| c <= largest));
    }

    /// The hand in the world with the arm at `q`, the arm's base frame `base` with the arm at
    /// `at` (the girdle moves the base with the arm).
    fn world_position(
        &self,
        character: &Character,
        base: &IsometryMatrix3<f64>,
        at: &[f64; 7],
        q: &[f64; 7],
    ) -> Option<Point3<f64>> {
        let moved = character.arm_base_moved(self.limb, base, at, q);
        character.limb_chain(self.limb).end_position(&moved, q).ok()
    }

    /// Holds the change of the hand's motion in the world to [`REACH_HAND_ACCELERATION`]: the
    /// hand's displacement over the frame with the joint `velocity` (the arm's base frame `base`
    /// with the arm at `goal`) differs from the last frame's by at most A·dt², the change from
    /// the last frame's joint velocity scaled back (by bisection) where it would not. Where the
    /// body alone breaks the bound (the last frame's joint velocity does), the arm's change is
    /// kept if it brings the hand's motion nearer the last frame's.
    fn bound_world_acceleration(
        &self,
        character: &Character,
        base: &IsometryMatrix3<f64>,
        goal: &[f64; 7],
        velocity: &mut [f64; 7],
        dt: f64,
    ) {
        let Some((hand, moved)) = self.world_hand else {
            return;
        };
        let largest = REACH_HAND_ACCELERATION * dt * dt;
        let change = |v: &[f64; 7]| -> Option<f64> {
            let next: [f64; 7] = std::array::from_fn(|i| self.previous[i] + v[i] * dt);
            let to = self.world_position(character, base, goal, &next)?;
            Some(((to - hand) - moved).norm())
        };
        let Some(wanted) = change(velocity) else {
            return;
        };
        if wanted <= largest {
            return;
        }
        let from = self.velocity;
        match change(&from) {
            Some(kept) if kept > largest => {
                if kept < wanted {
                    *velocity = from;
                }
                return;
            }
            None => return,
            Some(_) => {}
        }
        *velocity = scaled_back(&from, velocity, |v| change(v).is_some_and(|c| c <= largest));
    }

    /// Whether the profile's clock has run its course on `profile` (false before the arm
    /// controller started).
    pub(crate) fn profile_finished(&self, profile: &SpeedProfile) -> bool {
        self.clock.as_ref().is_some_and(|c| c.finished(profile))
    }

    /// Whether the arm has caught up with the posture it tracks (within [`CAUGHT_UP`]): a
    /// profile that has run its course is over only then (the goal stops at once, the arm
    /// brakes onto it).
    pub(crate) fn caught_up(&self) -> bool {
        self.lag <= CAUGHT_UP
    }

    /// Slows the joint `velocity` where it heads for the character's limits (at `pose`): its
    /// speed toward the limit at most √(`a`·gap) — with `a` = the follower's acceleration ([`ARM_ACCELERATION`]), the
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
    /// the analytic IK takes over from a person's arm at the speed it moved). `base` is the
    /// arm's base frame in `pose` ([`Character::limb_base_frame`]).
    pub(crate) fn settle(
        &mut self,
        character: &Character,
        pose: &Pose,
        base: &IsometryMatrix3<f64>,
        dt: f64,
    ) {
        let now: [f64; 7] = std::array::from_fn(|i| pose[self.dofs.start + i]);
        // A twist wrapped a turn by the clamp (`wrap_or_clamp`) did not move.
        self.velocity = std::array::from_fn(|i| angle_difference(now[i], self.previous[i]) / dt);
        self.previous = now;
        let chain = character.limb_chain(self.limb);
        // The hand in the base frame, and in the world through the base.
        let local = chain.end_position(&IsometryMatrix3::identity(), &now).ok();
        self.world_hand = local.map(|h| base * h).map(|h| {
            (
                h,
                self.world_hand
                    .map_or(Vector3::zeros(), |(before, _)| h - before),
            )
        });
        self.frame_time = dt;
        self.hand = local.map(|h| {
            (
                h,
                self.hand.map_or(Vector3::zeros(), |(before, _)| h - before),
            )
        });
    }

    /// Takes the arm over as it is in `pose` (from another driver): the next
    /// [`ArmFollower::follow`] starts a new straight path where the hand is then.
    pub(crate) fn resume_from(&mut self) {
        self.clock = None;
        self.handed_over = true;
        self.goal = None;
        self.last = None;
        self.alpha = None;
    }
}

/// The joint velocity on the way from `from` to `to` (`from + s·(to − from)`) with the largest
/// `s` in [0, 1] that `holds` — found by bisection to 1/2^[`HAND_BISECTIONS`], `from` itself
/// when no step holds: the change of the arm's joint velocity scaled back where a bound on the
/// hand's motion would break.
fn scaled_back(from: &[f64; 7], to: &[f64; 7], holds: impl Fn(&[f64; 7]) -> bool) -> [f64; 7] {
    let at = |s: f64| -> [f64; 7] { std::array::from_fn(|i| from[i] + s * (to[i] - from[i])) };
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..HAND_BISECTIONS {
        let mid = 0.5 * (lo + hi);
        if holds(&at(mid)) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    at(lo)
}
