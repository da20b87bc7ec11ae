//! The arm's analytic solve, shared by the reaching and the idle arm: where the orbit search
//! starts, a goal out of reach moved onto the reach sphere, and the base riding the girdle as
//! a fixed-point iteration (module docs of [`super`]); and the shoulder, hand and reach error
//! the scheduler's planning asks of a pose.

use kinergy_io::InvalidSetting;
use kinergy_motion::Side;
use kinergy_motion::nalgebra::{IsometryMatrix3, Point3, Vector3};
use kinergy_solver::analytic::{LimbIk, OrbitSearch, OrbitSense};

use crate::character::{Character, Limb, Pose};
use crate::error::{ReachError, Result};

/// The most solves of the arm's fixed-point iteration with the girdle (module docs).
pub(super) const GIRDLE_PASSES: usize = 5;

/// The girdle iteration stops when the arm's base moved less than this, meters.
const GIRDLE_TOLERANCE: f64 = 1e-6;

/// Solves `limb`'s arm with its base riding the girdle. `base` is the arm's base frame while
/// the arm's DoFs are `at`; the first solve uses the base for the arm `first` (the previous
/// frame's), each later one the base for the solution before it. `solve` gives an orbit
/// angle and an arm for a base frame. The last solution found, if any.
pub(super) fn on_girdle(
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
pub(crate) fn arm_ik(character: &Character, arm: Limb) -> Result<LimbIk> {
    let sense = match arm.side() {
        Side::Right => OrbitSense::LeftHanded,
        Side::Left => OrbitSense::RightHanded,
    };
    LimbIk::new(character.limb_chain(arm))
        .map(|ik| ik.with_sense(sense))
        .map_err(|e| ReachError::Setting(InvalidSetting::new("character.arm", e.to_string())))
}

/// Where an arm's orbit search starts.
#[derive(Debug, Clone, Copy)]
pub(super) enum Near {
    /// The default start ([`OrbitSearch::start`]).
    Default,
    /// At this orbit angle (the previous frame's), with small increments.
    Alpha(f64),
    /// At the angle whose posture is closest to this one (in the shoulder and elbow DoFs).
    Posture([f64; 7]),
    /// As [`Near::Posture`], among the angles within 30° of the posture's own angle (of this
    /// one where it has none).
    PostureAround([f64; 7], f64),
    /// At the angle whose elbow is nearest this direction from the shoulder (base frame): the
    /// orbit measured from it rather than from the lowest elbow, which is undefined where the
    /// shoulder→hand axis is vertical. The angle returned is still the one from the lowest
    /// elbow.
    Elbow(Vector3<f64>),
}

/// The `arm` (its analytic IK `ik`) for the hand at `goal` (world), the body as in `pose`,
/// position mode with the orbit search and the base riding the girdle; a goal out of reach
/// is moved to the nearest reachable point on the shoulder→goal line.
pub(crate) fn solve_arm(
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
pub(super) fn solve_arm_near(
    ik: &LimbIk,
    base: &IsometryMatrix3<f64>,
    goal: &Point3<f64>,
    search: &OrbitSearch,
    near: Near,
) -> Option<(f64, [f64; 7])> {
    let down = base.rotation.inverse() * -Vector3::y();
    let lowest = ik.clone().with_down(down).ok()?;
    let ik = match near {
        Near::Elbow(elbow) => ik.clone().with_down(elbow).ok()?,
        _ => lowest.clone(),
    };
    let local = base.inverse() * goal;
    let r = local.coords.norm();
    let solve = |p: &Point3<f64>| {
        let start = match near {
            Near::Default => None,
            Near::Alpha(a) => Some(a),
            Near::Elbow(_) => Some(0.0),
            Near::Posture(q0) => closest_alpha(&ik, p, &q0),
            Near::PostureAround(q0, a) => {
                // Centred on the last frame's angle or the last posture's own angle in this
                // frame's reference, whichever names the nearer posture: near a straight,
                // hanging arm the reference (world down across the shoulder→wrist axis) turns
                // fast with the trunk, and the last frame's angle can name a posture far from
                // the last one (30° and 0.08 rad of twist in a frame, overhead); with the elbow
                // quite straight the posture has no angle of its own (a handed-over arm
                // stretched overhead was flipped through its swing's half turn, the hand thrown
                // at 2.9 m/s).
                let found = |c: f64| {
                    let (best, inside) = closest_alpha_around(&ik, p, &q0, c)?;
                    Some((best, posture_distance(&ik, p, &q0, best)?, inside))
                };
                let own = ik
                    .position_alpha_of(&q0)
                    .filter(|c| c.is_finite())
                    .and_then(found);
                let near = match (found(a), own) {
                    (Some(last), Some(own)) if own.1 < last.1 => Some(own),
                    (Some(last), _) => Some(last),
                    (None, own) => own,
                };
                // Neither window holds the last posture (the reference of a hanging arm turned
                // more than the window in a frame: its orbit angle jumped 32° on a reach's
                // first frame, and the arm twisted 0.08 rad with the hand at rest): the whole
                // circle, as for a first frame. A window holds it where its nearest posture
                // lies inside it, not on its edge, and is within a frame's motion of the last.
                match near {
                    Some((angle, d, true)) if d <= SAME_POSTURE => Some(angle),
                    _ => {
                        let whole = closest_alpha(&ik, p, &q0)
                            .and_then(|c| closest_alpha_around(&ik, p, &q0, c))
                            .and_then(|(c, _)| Some((c, posture_distance(&ik, p, &q0, c)?)));
                        match (near, whole) {
                            (Some(n), Some(w)) if w.1 < n.1 => Some(w.0),
                            (Some(n), _) => Some(n.0),
                            (None, w) => w.map(|w| w.0),
                        }
                    }
                }
            }
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
        if let Some((a, q)) = solve(&p) {
            return Some(match near {
                Near::Elbow(_) => (lowest.position_alpha_of(&q).unwrap_or(a), q),
                _ => (a, q),
            });
        }
    }
    None
}

/// The squared distance in the shoulder and elbow DoFs, radians², below which the posture
/// found inside [`Near::PostureAround`]'s window is the last one carried on (0.1 rad: a frame's
/// motion moves it 0.01–0.02 rad in a fast squat at 30 Hz, where a bound of 0.01 rad sent 186
/// of 235 frames round the whole circle); above it the whole circle is searched too.
const SAME_POSTURE: f64 = 1e-2;

/// Bisection steps of [`solve_arm_outward`] (the scale to 1/256 of its bracket).
const OUTWARD_BISECTIONS: usize = 8;

/// [`solve_arm_near`] for a goal too close to the shoulder for the arm (the elbow cannot flex
/// far enough within its limits): the nearest point on the shoulder→goal line, farther out, that
/// the arm reaches — as a goal beyond reach is moved onto the reach sphere. The hand's path runs
/// round the shoulder on the sphere the elbow's flexion leaves, where the straight line passes
/// inside it, instead of the arm holding its last posture and then jumping onto the line where
/// it comes out (a held-out overhead raise: 1.1 m/s at 4.1 s). `None` when no point on the
/// line is reached.
pub(super) fn solve_arm_outward(
    ik: &LimbIk,
    base: &IsometryMatrix3<f64>,
    goal: &Point3<f64>,
    search: &OrbitSearch,
    near: Near,
) -> Option<(f64, [f64; 7])> {
    let shoulder = Point3::from(base.translation.vector);
    let r = (goal - shoulder).norm();
    let (_, outer) = ik.position_reach().unwrap_or_else(|| ik.wrist_reach());
    if r <= 1e-9 || r >= outer {
        return None;
    }
    let most = outer / r;
    let at = |s: f64| Point3::from(shoulder.coords + (goal - shoulder) * s);
    // The first of a few growing scales that is reached brackets the nearest reached point.
    let mut low = 1.0;
    let mut found = None;
    for f in [0.01, 0.03, 0.1, 0.3, 0.6, 0.999] {
        let s = 1.0 + f * (most - 1.0);
        if let Some(q) = solve_arm_near(ik, base, &at(s), search, near) {
            found = Some((s, q));
            break;
        }
        low = s;
    }
    let (mut high, mut best) = found?;
    for _ in 0..OUTWARD_BISECTIONS {
        let mid = 0.5 * (low + high);
        match solve_arm_near(ik, base, &at(mid), search, near) {
            Some(q) => {
                high = mid;
                best = q;
            }
            None => low = mid,
        }
    }
    Some(best)
}

/// The orbit angle, on a 5° grid over the whole circle and `q0`'s own angle, whose posture
/// within the limits is closest to `q0` in the shoulder and elbow DoFs. (`q0`'s own angle
/// takes up an arm where it is: the nearest grid angle alone turned the reaching arm's twist
/// 0.02 rad in the first frame of a reach, which the tracking arm spent its acceleration on.)
fn closest_alpha(ik: &LimbIk, p: &Point3<f64>, q0: &[f64; 7]) -> Option<f64> {
    use std::f64::consts::PI;
    (0..72)
        .map(|k| -PI + (k as f64) * 5f64.to_radians())
        .chain(ik.position_alpha_of(q0))
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
/// moves little, and a flip is caught by [`ARM_JUMP`](super::follower::ARM_JUMP)'s test), then
/// refined between the grid's angles. Five to eight solves a frame where a scan of the 13
/// angles took 13. With it, whether the angle lies inside the window (not on its edge, where
/// the nearest posture may lie beyond it).
fn closest_alpha_around(
    ik: &LimbIk,
    p: &Point3<f64>,
    q0: &[f64; 7],
    center: f64,
) -> Option<(f64, bool)> {
    const STEP: f64 = 5.0 * std::f64::consts::PI / 180.0;
    const STEPS: i32 = 6;
    let distance = |k: i32| posture_distance(ik, p, q0, center + f64::from(k) * STEP);
    let Some(mut best) = distance(0) else {
        // The last angle is no longer within the limits: the whole window, scanned.
        return (-STEPS..=STEPS)
            .filter_map(|k| distance(k).map(|d| (k, d)))
            .min_by(|x, y| x.1.total_cmp(&y.1))
            .map(|(k, _)| (center + f64::from(k) * STEP, k.abs() < STEPS));
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
    // Between the grid's angles: the vertex of the parabola through the best and its two
    // neighbours, where it is nearer still. (On the grid alone the angle moved in 5° steps, and
    // near a straight arm each step turned the goal's twist by 0.02 rad within a frame.)
    let refined = match (distance(at - 1), distance(at + 1)) {
        (Some(left), Some(right)) => {
            let curve = left - 2.0 * best + right;
            if curve > 0.0 {
                let offset = (0.5 * (left - right) / curve).clamp(-0.5, 0.5);
                let k = f64::from(at) + offset;
                posture_distance(ik, p, q0, center + k * STEP)
                    .filter(|d| *d <= best)
                    .map(|_| k)
            } else {
                None
            }
        }
        _ => None,
    };
    Some((
        center + refined.unwrap_or(f64::from(at)) * STEP,
        at.abs() < STEPS,
    ))
}

/// The shoulder: the arm chain's base, in world.
pub(crate) fn shoulder_position(character: &Character, pose: &Pose, arm: Limb) -> Point3<f64> {
    let f = character.limb_base_frame(arm, pose);
    Point3::from(f.translation.vector)
}

/// The hand: the arm's fingertip joint, in world.
pub(crate) fn hand_position(character: &Character, pose: &Pose, arm: Limb) -> Point3<f64> {
    let frames = character.world_frames(pose);
    Point3::from(frames[arm.joints()[3]].translation.vector)
}

/// The arm a reach is planned for: the character's `limb`, solved by its analytic `ik` for
/// the `target` — what the plan's swing and COM-shift searches solve at every posture they
/// try.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ReachingArm<'a> {
    /// The character reaching.
    pub(crate) character: &'a Character,
    /// Its reaching arm.
    pub(crate) limb: Limb,
    /// The arm's analytic IK.
    pub(crate) ik: &'a LimbIk,
    /// The target, world meters.
    pub(crate) target: &'a Point3<f64>,
    /// Upper arm + forearm + hand, meters.
    pub(crate) length: f64,
}

impl ReachingArm<'_> {
    /// The arm solved by [`solve_arm`] for the target, the body as in `pose` (the default
    /// orbit search).
    pub(crate) fn solve(&self, pose: &Pose) -> Option<[f64; 7]> {
        solve_arm(
            self.character,
            self.limb,
            self.ik,
            pose,
            self.target,
            &OrbitSearch::default(),
        )
    }

    /// The hand's distance from the target with the arm [solved](Self::solve) at `pose`.
    pub(crate) fn error(&self, pose: &Pose) -> f64 {
        match self.solve(pose) {
            Some(q) => {
                let mut p = *pose;
                p[self.character.limb_dofs(self.limb)].copy_from_slice(&q);
                (hand_position(self.character, &p, self.limb) - self.target).norm()
            }
            None => f64::INFINITY,
        }
    }

    /// The shoulder in `pose` ([`shoulder_position`]).
    pub(crate) fn shoulder(&self, pose: &Pose) -> Point3<f64> {
        shoulder_position(self.character, pose, self.limb)
    }
}
