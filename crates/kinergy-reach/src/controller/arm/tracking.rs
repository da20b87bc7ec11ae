//! The tracking law of the arm shown: the analytic solution's joint velocity fed forward, the
//! lag closed no faster than the arm can brake, and every bound scaling the whole joint
//! velocity (module docs of [`super`]).

/// The fastest an arm DoF turns, rad/s (peak elbow and shoulder speeds of fast human
/// reaches are around 10 rad/s; ours stay below).
pub(super) const ARM_MAX_SPEED: f64 = 8.0;

/// The most a reaching arm DoF's speed changes, rad/s² (the whole change of the arm's joint
/// velocity scaled alike; fast elbow movements reach several thousand degrees per second
/// squared): the person's arm, its hand-overs and the arm before its reach, as the fits
/// replayed them. The hand's own bounds ([`HAND_ACCELERATION`], [`REACH_HAND_ACCELERATION`]) are
/// what keep the hand smooth; this one keeps a flip of the analytic solution from being
/// followed at once. It has to leave room for the joints a smooth hand asks for: near the
/// relaxed, nearly straight elbow a reach starts from, the elbow flexes like the square root of
/// the hand's travel (55 rad/s² for the ease-out's ramp to v_s in 0.08 s). With 40 and 60
/// rad/s² the ease-out's hand overshot v_s by up to 7.5 % and 8.5 % on the grid of
/// `tests/profile_realtime.rs` (catching up where the arm had lagged).
pub(super) const ARM_ACCELERATION: f64 = 100.0;

/// [`ARM_ACCELERATION`] for the arm a speed profile drives (Huang's hand held to its world
/// line), rad/s² (ballistic elbow flexions peak above 10,000°/s², 175 rad/s²): while a step or a
/// squat carries the shoulder, the arm near its reach's edge turns its joints faster than the
/// hand moves. With 100 a full step of 0.425 m carried the hand 2.0–2.1 cm off its line (0.9 cm
/// with this), and toward a low target behind a step and a squat the hand, rejoining its line
/// at the reach's edge, slowed to 0.158 m/s (21 % under v_s) as the root braked. (The person's
/// arm keeps [`ARM_ACCELERATION`]: at 30 Hz its hand-over closed a 3 cm gap after the hand had
/// stopped at 0.28 m/s, a second reach.)
pub(super) const PROFILE_ARM_ACCELERATION: f64 = 250.0;

/// How long the reaching arm takes to close on the posture it lags behind, seconds (the
/// gain of [`track`] is its inverse).
pub(super) const ARM_TRACKING_TIME: f64 = 0.05;

/// The most the reaching hand's velocity relative to the shoulder changes, m/s² (a brisk
/// reach peaks near 6 m/s²; [`ARM_ACCELERATION`] alone lets all seven DoFs add up to more):
/// 0.13 m/s a frame at 60 Hz, under a quarter of what a speed jump is at 30 Hz.
pub(super) const HAND_ACCELERATION: f64 = 8.0;

/// The most the reaching hand's velocity in the world changes, m/s²: what a fast human hand
/// does (a 0.3 m minimum-jerk reach in 0.3 s peaks at 19 m/s²). Holding the hand on its
/// world-frame path while a step carries the shoulder asks the arm for the body's own
/// acceleration relative to the shoulder (the step's eased keyframes brake the shoulder at up to
/// ~13 m/s²); where the arm's onset finds the hand carried across its path, the hand comes
/// onto it within v⊥² / (2·A) (1.3 cm at 0.73 m/s).
pub(super) const REACH_HAND_ACCELERATION: f64 = 20.0;

/// The joint velocity with which an arm at `at` follows a `goal` posture moving at
/// `goal_velocity`: the goal's velocity (at most [`ARM_MAX_SPEED`]) plus the gap closed in
/// [`ARM_TRACKING_TIME`], the closing speed no more than the arm can brake from within the gap
/// at `acceleration` ([`ARM_ACCELERATION`] or [`PROFILE_ARM_ACCELERATION`]; √(A·gap), half the distance a full brake needs: the goal moves
/// meanwhile), and the whole at most [`ARM_MAX_SPEED`] in every DoF (scaled alike). The hand
/// closes on where the goal puts it, `hand_gap` meters away, no faster than it can brake at
/// [`HAND_ACCELERATION`] either (√(H·gap); the closing motion moves the hand by about the
/// gap): the hand's bound is what brakes a long arm, and closing at the joints' rate alone ran
/// a lagging arm past its goal and back (a 3 cm return after a low reach with a bend).
pub(super) fn track(
    goal: &[f64; 7],
    goal_velocity: &[f64; 7],
    at: &[f64; 7],
    hand_gap: Option<f64>,
    acceleration: f64,
    dt: f64,
) -> [f64; 7] {
    let mut feed = *goal_velocity;
    scale_to(&mut feed, ARM_MAX_SPEED);
    // The lag is behind where the goal was a frame ago: the feed carries the arm over the
    // goal's own motion in this frame. (Closing on the goal from where the arm was, on top of the
    // feed, ran the arm a frame's motion ahead of its goal.)
    let gap: [f64; 7] = std::array::from_fn(|i| goal[i] - feed[i] * dt - at[i]);
    let largest = gap.iter().fold(0.0f64, |m, g| m.max(g.abs()));
    let closing = if largest > 0.0 {
        let joints = (largest / ARM_TRACKING_TIME).min((acceleration * largest).sqrt()) / largest;
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
pub(super) fn accelerate(velocity: &[f64; 7], wanted: &[f64; 7], largest: f64) -> [f64; 7] {
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
pub(super) fn limit_speed(values: &mut [f64], previous: &[f64; 7], max_step: f64) -> bool {
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
