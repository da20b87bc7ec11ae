//! Smooth synergy motion that finishes its reach (a departure from the paper, whose
//! controller is Θ ← clamp(Θ + S(t)·O(ΔX)) and nothing else).
//!
//! **Why.** The paper's step can change without bound from one frame to the next, and a
//! person's hand cannot. Measured on the synthetic set (every reach fitted per clip with S_D
//! and replayed with its own parameters; `tools/speed-jumps.sh`), 41 of 56 synthesized
//! reaches had one-frame hand-speed jumps their capture does not have, and 12 of 56 stopped
//! short. The causes, each seen frame by frame:
//!
//! - *A straight arm.* A reach from a hanging arm starts at the elbow's singularity: the
//!   radial direction has no singular value, the SVD drops it, and the hand wanders sideways
//!   for tens of frames until rounding lets the elbow in, at once (0.2 rad in a frame, the
//!   hand at 7 m/s for a reach whose capture peaks at 1 m/s).
//! - *Limits.* A DoF reaching its limit stops within one frame.
//! - *Fitted gains.* The paper's bounds allow negative gains, with which J·G·J⁺ is not
//!   positive definite: the fitted synergy follows the capture over the frames it was fitted
//!   on, and afterwards can move the hand away from the target or hold it still (a stall
//!   with no limit in sight).
//! - *The first step.* The step is largest where the error is: the arm starts at its
//!   fastest, where people start from rest.
//!
//! **What [`Smoothing`] does** (each frame, after the synergy and the limits' deactivation):
//!
//! 1. *Guidance of a near-straight arm* ([`crate::reachability`]): the elbow takes the
//!    distance by the law of cosines while the arm itself is within 42° of straight, not only
//!    when the target is at the edge of the reach sphere.
//! 2. *A progress floor* p: the hand closes at least p × what the plain optimizer step
//!    would ((J·Δθ')·ΔX ≥ p (J·Δθ)·ΔX, else Δθ' += μ Δθ with the smallest μ ≥ 0 that makes
//!    it so). Continuous in the step, so it adds no jump.
//! 3. *The finish*: from `finish.after` seconds (the fitted reach's duration: what the fit
//!    saw), the step blends from the synergy's into the plain optimizer's over `finish.over`
//!    seconds (smoothstep). Beyond the fitted frames the data says nothing of the person, and
//!    the plain optimizer converges.
//! 4. *Bounded acceleration.* The step moves from the previous frame's (the start velocity
//!    before the first, rest by default) toward the new one by at most the joint bound a_j·dt²
//!    in every DoF (the whole change scaled alike), each DoF brakes before its limit so that
//!    it can stop there at a_j, and the hand's displacement relative to the chain's base —
//!    exact forward kinematics, the change scaled as 8 bisection steps would, found in about
//!    2 evaluations by a line through the bracket — changes by at most a_h·dt². So the hand's speed changes by at most a_h·dt per frame.
//!
//! 5. *Approach braking.* The hand moves no faster than it can stop from within the remaining
//!    distance e at its bound: |Δh| ≤ dt √(2 a_h e). A step proportional to the error under an
//!    acceleration bound otherwise overshoots and circles the target.
//! 6. *Onset.* Both bounds rise linearly from zero over the first 21 % of the reach (where a
//!    minimum-jerk reach's acceleration peaks): a hand at rest starts gently.
//!
//! The progress floor and the finish use the plain step without the DoFs a zero gain
//! freezes: they stay frozen.
//!
//! The stall rule then waits until the finish is over, and never fires while a DoF still
//! moves on faster than 0.05 rad/s, net over the stall window (an arm turning back under the
//! acceleration bound; an arm chattering on a limit, back and forth, is not moving on).
//!
//! **The bounds of a reach** ([`Smoothing::for_reach`]): a minimum-jerk reach of peak speed
//! V and duration T peaks at 3.08 V/T in acceleration (Flash & Hogan 1985: 5.77 D/T² with
//! V = 1.875 D/T); people's onsets are steeper than minimum jerk, so a_h = 5 V/T, about 1.6×
//! that, and at least 1 m/s² (4 V/T, tried, lagged the fast raises and correlated worse
//! with them: 0.79 against 0.87 on the shared people; 6 V/T left a one-frame change of
//! 0.55 m/s, a speed jump, on a fast held-out 30 Hz raise, Bandai *normal* take 7). The joint bound a_j = a_h / (L/2), L the arm's length: a DoF
//! turning the hand about a lever of half the arm. V and T come from the reach's capture
//! (its hand speed relative to the shoulder, or in the arm's base frame where the base turns
//! under the hand: `kinergy_train::captured`) or from the planned profile.

use kinergy_io::InvalidSetting;
use kinergy_motion::nalgebra::{Point3, Vector3};
use kinergy_motion::{Chain, Motion, TrigMemo};

use crate::error::Result;

/// The plain optimizer's share of a step in the finish blend, and its length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Finish {
    /// Seconds after the start at which the blend begins (the fitted reach's duration).
    pub after: f64,
    /// Seconds over which the synergy's step gives way to the plain optimizer's.
    pub over: f64,
}

/// The smooth controller's settings (see the [module documentation](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Smoothing {
    /// The largest acceleration of the hand relative to the chain's base, m/s².
    pub hand_acceleration: f64,
    /// The largest angular acceleration of any DoF, rad/s².
    pub joint_acceleration: f64,
    /// The least share of the plain optimizer's progress toward the target, in [0, 1).
    pub progress_floor: f64,
    /// When the synergy hands the step to the plain optimizer; `None`: never.
    pub finish: Option<Finish>,
    /// Seconds over which both acceleration bounds rise linearly from zero to their values
    /// (a person's hand acceleration rises from zero too: jerk is finite); 0: at once.
    pub onset: f64,
}

/// a_h · T / V of [`Smoothing::for_reach`]: 5, about 1.6× a minimum-jerk reach's 3.08.
pub const HAND_ACCELERATION_PER_SPEED: f64 = 5.0;
/// The progress floor of [`Smoothing::for_reach`].
pub const PROGRESS_FLOOR: f64 = 0.1;
/// The finish blend's length in [`Smoothing::for_reach`], seconds (the stall window).
pub const FINISH_OVER: f64 = 0.25;
/// The share of a reach's duration over which [`Smoothing::for_reach`]'s bounds rise: where a
/// minimum-jerk reach's acceleration peaks, τ = (3 − √3)/6.
pub const ONSET_SHARE: f64 = 0.211_324_865_405_187_1;
/// The hand bound's scale is found to 1/2⁸ of the change (as 8 bisection steps would; 5,
/// tried, left 3 speed jumps on a held-out raise at 30 Hz that 8 do not).
const BISECTIONS: u32 = 8;
/// Rounds of [`largest_scale`] guided by the line through the bracket before it halves.
const MODEL_ROUNDS: usize = 4;
/// The least hand acceleration bound, m/s².
pub const MIN_HAND_ACCELERATION: f64 = 1.0;

impl Smoothing {
    /// The bounds of a reach whose hand peaks at `peak_speed` m/s (relative to the shoulder)
    /// over `duration` seconds, on an arm `arm_length` meters long, the finish after
    /// `duration` (see the module documentation).
    pub fn for_reach(peak_speed: f64, duration: f64, arm_length: f64) -> Smoothing {
        let hand = if peak_speed.is_finite() && duration.is_finite() && duration > 0.0 {
            (HAND_ACCELERATION_PER_SPEED * peak_speed / duration).max(MIN_HAND_ACCELERATION)
        } else {
            MIN_HAND_ACCELERATION
        };
        let lever = if arm_length.is_finite() && arm_length > 0.0 {
            0.5 * arm_length
        } else {
            0.35
        };
        Smoothing {
            hand_acceleration: hand,
            joint_acceleration: hand / lever,
            progress_floor: PROGRESS_FLOOR,
            finish: (duration.is_finite() && duration >= 0.0).then_some(Finish {
                after: duration,
                over: FINISH_OVER,
            }),
            onset: if duration.is_finite() && duration > 0.0 {
                ONSET_SHARE * duration
            } else {
                0.0
            },
        }
    }

    /// These bounds under S_E's tempo `factors` ([`crate::Synergy::tempo`]): both acceleration
    /// bounds × `acceleration`, the onset × `onset` (factors of 1 change nothing, bit for bit).
    pub fn scaled(&self, factors: crate::TempoFactors) -> Smoothing {
        Smoothing {
            hand_acceleration: self.hand_acceleration * factors.acceleration,
            joint_acceleration: self.joint_acceleration * factors.acceleration,
            onset: self.onset * factors.onset,
            ..*self
        }
    }

    /// Checks every setting, naming the field otherwise.
    pub fn validate(&self) -> Result<()> {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        InvalidSetting::require(
            positive(self.hand_acceleration),
            "smoothing.hand_acceleration",
            "a positive number of m/s²",
        )?;
        InvalidSetting::require(
            positive(self.joint_acceleration),
            "smoothing.joint_acceleration",
            "a positive number of rad/s²",
        )?;
        InvalidSetting::require(
            (0.0..1.0).contains(&self.progress_floor),
            "smoothing.progress_floor",
            "a number in [0, 1)",
        )?;
        InvalidSetting::require(
            self.onset.is_finite() && self.onset >= 0.0,
            "smoothing.onset",
            "a non-negative number of seconds",
        )?;
        if let Some(f) = self.finish {
            InvalidSetting::require(
                f.after.is_finite() && f.after >= 0.0,
                "smoothing.finish.after",
                "a non-negative number of seconds",
            )?;
            InvalidSetting::require(
                positive(f.over),
                "smoothing.finish.over",
                "a positive number of seconds",
            )?;
        }
        Ok(())
    }

    /// The plain optimizer's share of the step at `t` seconds (0 before the finish).
    pub fn finish_weight(&self, t: f64) -> f64 {
        self.finish
            .map_or(0.0, |f| smoothstep01((t - f.after) / f.over))
    }

    /// The share of the acceleration bounds in force on the frame that ends at `t` seconds.
    pub fn onset_share(&self, t: f64) -> f64 {
        if self.onset > 0.0 {
            (t / self.onset).clamp(0.0, 1.0)
        } else {
            1.0
        }
    }

    /// Seconds from the start until the finish is over (0 without one).
    pub fn finished_at(&self) -> f64 {
        self.finish.map_or(0.0, |f| f.after + f.over)
    }
}

fn smoothstep01(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    x * x * (3.0 - 2.0 * x)
}

/// The frame a step is bounded on.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Frame {
    /// The task error's norm, meters.
    pub(crate) error: f64,
    /// Seconds since the start, at the frame's beginning.
    pub(crate) t: f64,
    /// The frame time, seconds.
    pub(crate) dt: f64,
}

/// What the smooth controller remembers between frames.
#[derive(Debug, Clone)]
pub(crate) struct Smoother {
    /// The step the configuration made on the previous frame (after the clamp).
    pub(crate) moved: Vec<f64>,
    /// The hand in the base frame now, and how it moved on the previous frame.
    hand: Point3<f64>,
    hand_moved: Vector3<f64>,
    started: bool,
    trial: Vec<f64>,
    /// A zero step (no allocation on the frames where the hand bound binds).
    zero: Vec<f64>,
    /// The hand at the configurations forward kinematics last saw (see [`Known`]).
    known: Known,
    /// The sines and cosines of the last configuration forward kinematics walked: the
    /// frame's record places the hand at the configuration the next frame linearizes at
    /// (`ArmStepper::observe`), which takes them from here.
    pub(crate) trig: TrigMemo,
}

/// The hand at the last [`KNOWN`] configurations forward kinematics was run on. A frame asks
/// for the hand at the same configuration more than once: the hand bound's search at the step
/// it settles on, then the approach brake and the record of the frame's motion at that same
/// step. An exact match (every DoF `==`) answers without recomputing, so the answer is the one
/// forward kinematics gives.
#[derive(Debug, Clone)]
struct Known {
    configurations: [Vec<f64>; KNOWN],
    hands: [Point3<f64>; KNOWN],
    valid: [bool; KNOWN],
    /// The entry the next new configuration replaces.
    next: usize,
}

/// How many configurations [`Known`] keeps: the hand bound's search ends on its bracket's
/// lower end, evaluated up to two searches' rounds before the approach brake asks for it.
const KNOWN: usize = 4;

impl Known {
    fn new(n: usize) -> Known {
        Known {
            configurations: std::array::from_fn(|_| vec![0.0; n]),
            hands: [Point3::origin(); KNOWN],
            valid: [false; KNOWN],
            next: 0,
        }
    }

    fn get(&self, q: &[f64]) -> Option<Point3<f64>> {
        (0..KNOWN)
            .find(|&i| self.valid[i] && self.configurations[i].as_slice() == q)
            .map(|i| self.hands[i])
    }

    fn put(&mut self, q: &[f64], hand: Point3<f64>) {
        let i = self.next;
        self.configurations[i].copy_from_slice(q);
        self.hands[i] = hand;
        self.valid[i] = true;
        self.next = (i + 1) % KNOWN;
    }
}

/// The step `a + k (b − a)` between two steps, `a` itself at k = 0 and `b` itself at k = 1: the
/// step a scale of the hand bound's search stands for, computed alike where the search tries it
/// and where the frame takes it, so the configuration the frame moves to is the one the search
/// measured, to the bit.
#[inline]
fn between(a: f64, b: f64, k: f64) -> f64 {
    if k == 1.0 { b } else { a + k * (b - a) }
}

impl Smoother {
    pub(crate) fn new(n: usize) -> Smoother {
        Smoother {
            moved: vec![0.0; n],
            hand: Point3::origin(),
            hand_moved: Vector3::zeros(),
            started: false,
            trial: vec![0.0; n],
            zero: vec![0.0; n],
            known: Known::new(n),
            trig: TrigMemo::default(),
        }
    }

    /// The arm moves at `step` per frame before the first (its start velocity × dt).
    pub(crate) fn set_start_step(&mut self, chain: &Chain, q: &[f64], step: &[f64]) {
        self.moved.copy_from_slice(step);
        let before: Vec<f64> = q.iter().zip(step).map(|(a, s)| a - s).collect();
        let from = self.hand_at(chain, &before);
        self.hand = self.hand_at(chain, q);
        self.hand_moved = self.hand - from;
        self.started = true;
    }

    /// Bounds `step` (this frame's, from configuration `q`) by the accelerations.
    pub(crate) fn limit(
        &mut self,
        chain: &Chain,
        q: &[f64],
        step: &mut [f64],
        smoothing: &Smoothing,
        frame: Frame,
    ) {
        let Frame { error, t, dt } = frame;
        if !self.started {
            self.hand = self.hand_at(chain, q);
            self.started = true;
        }
        // Bounds of the frame from t to t + dt, ramped up over the onset.
        let share = smoothing.onset_share(t + dt);
        limit_change(
            step,
            &self.moved,
            share * smoothing.joint_acceleration * dt * dt,
        );
        self.limit_hand(
            chain,
            q,
            step,
            share * smoothing.hand_acceleration * dt * dt,
        );
        // Then the two brakes, which hold whatever the bounds left. Approach braking: no faster
        // toward the target than the hand can stop from at its bound within the remaining
        // distance, |Δh| ≤ dt √(2 a_h e) (a step proportional to the error under an
        // acceleration bound overshoots and circles).
        let most = dt * (2.0 * smoothing.hand_acceleration * error.max(0.0)).sqrt();
        let here = self.hand;
        let mut trial = std::mem::take(&mut self.trial);
        for ((t, a), b) in trial.iter_mut().zip(q).zip(step.iter()) {
            *t = a + b;
        }
        let moved = (self.hand_at(chain, &trial) - here).norm();
        self.trial = trial;
        if moved > most && moved > 0.0 {
            let k = most / moved;
            for v in step.iter_mut() {
                *v *= k;
            }
        }
        // Each DoF brakes before its limit at the full joint bound.
        brake_at_limits(chain, q, step, smoothing.joint_acceleration * dt * dt);
    }

    /// Remembers the configuration `q` before this frame's step.
    pub(crate) fn begin(&mut self, q: &[f64]) {
        self.moved.copy_from_slice(q);
    }

    /// Records the frame's actual motion to `after` (after the clamp) from the configuration
    /// given to [`Smoother::begin`].
    pub(crate) fn record(&mut self, chain: &Chain, after: &[f64]) {
        for (m, a) in self.moved.iter_mut().zip(after) {
            *m = a - *m;
        }
        let now = self.hand_at(chain, after);
        self.hand_moved = now - self.hand;
        self.hand = now;
    }

    /// The hand in the chain's base frame at configuration `q` (forward kinematics, or the
    /// [`Known`] answer for the same configuration).
    fn hand_at(&mut self, chain: &Chain, q: &[f64]) -> Point3<f64> {
        if let Some(hand) = self.known.get(q) {
            return hand;
        }
        // The end alone, from the hand inward (the joints' frames are not needed).
        match chain.end_in_base_memo(q, &mut self.trig) {
            Ok(end) => {
                self.known.put(q, end);
                end
            }
            Err(_) => self.hand,
        }
    }

    /// How the hand's displacement in the base frame changes from the previous frame's when
    /// the configuration moves from `q` by the step `a + k (b − a)` ([`between`]).
    fn change(&mut self, chain: &Chain, q: &[f64], a: &[f64], b: &[f64], k: f64) -> Vector3<f64> {
        let mut trial = std::mem::take(&mut self.trial);
        for (i, t) in trial.iter_mut().enumerate() {
            *t = q[i] + between(a[i], b[i], k);
        }
        let h = self.hand_at(chain, &trial);
        self.trial = trial;
        h - self.hand - self.hand_moved
    }

    /// Scales the change of `step` from the previous frame's so that the hand's displacement
    /// in the base frame changes by at most `bound` meters (exact forward kinematics; the
    /// scale found as in [`largest_scale`]).
    fn limit_hand(&mut self, chain: &Chain, q: &[f64], step: &mut [f64], bound: f64) {
        let previous = std::mem::take(&mut self.moved);
        let full = self.change(chain, q, &previous, step, 1.0);
        if full.norm() > bound {
            let none = self.change(chain, q, &previous, step, 0.0);
            if none.norm() > bound {
                let zero = std::mem::take(&mut self.zero);
                // Going on as on the previous frame already changes the hand's motion too
                // much (the same joint velocity moves the hand differently as the arm bends):
                // the previous step scales, to the share whose hand displacement changes
                // least.
                let mut best = (f64::INFINITY, 1.0);
                for k in [1.0, 0.75, 0.5, 0.25, 0.0] {
                    let c = self.change(chain, q, &zero, &previous, k).norm();
                    if c < best.0 {
                        best = (c, k);
                    }
                }
                for (s, p) in step.iter_mut().zip(&previous) {
                    *s = between(0.0, *p, best.1);
                }
                self.zero = zero;
            } else {
                let lo = largest_scale(none, full, bound, |k| {
                    self.change(chain, q, &previous, step, k)
                });
                for (s, p) in step.iter_mut().zip(&previous) {
                    *s = between(*p, *s, lo);
                }
            }
        }
        self.moved = previous;
    }
}

/// The largest scale k = j / 256 (j = 0…256) at which the change `c(k)` (a vector, nearly
/// affine in k) stays within `bound`, given `c(0)` = `at_zero` within it and `c(1)` =
/// `at_one` beyond: the answer eight bisection steps give, in fewer evaluations.
///
/// Each round puts a line through the bracket's two changes, takes the grid point just below
/// where its norm meets the bound (a quadratic; exact when `c` is affine), strictly inside the
/// bracket, and keeps the side the exact change falls on. When the line is right, two rounds
/// end it: the grid point below the crossing, then the one above. After [`MODEL_ROUNDS`]
/// rounds the search halves the bracket, as bisection does. Where |c| grows with k (a change
/// nearly affine in k, as here) the answer is bisection's to the bit.
fn largest_scale(
    at_zero: Vector3<f64>,
    at_one: Vector3<f64>,
    bound: f64,
    mut change: impl FnMut(f64) -> Vector3<f64>,
) -> f64 {
    const GRID: u32 = 1 << BISECTIONS;
    let (mut lo, mut c_lo) = (0_u32, at_zero);
    let (mut hi, mut c_hi) = (GRID, at_one);
    let mut rounds = 0;
    while hi - lo > 1 {
        let j = if rounds < MODEL_ROUNDS {
            let t = line_meets_bound(&c_lo, &(c_hi - c_lo), bound);
            let crossing = lo as f64 + t * (hi - lo) as f64;
            (crossing.floor() as u32).clamp(lo + 1, hi - 1)
        } else {
            lo + (hi - lo) / 2
        };
        rounds += 1;
        let c = change(j as f64 / GRID as f64);
        if c.norm() <= bound {
            (lo, c_lo) = (j, c);
        } else {
            (hi, c_hi) = (j, c);
        }
    }
    lo as f64 / GRID as f64
}

/// The t ≥ 0 at which |c + t d| = bound, for |c| ≤ bound (the larger root of
/// |d|² t² + 2 (c·d) t + |c|² − bound² = 0, in its cancellation-free form); 0 when `d` is
/// zero.
fn line_meets_bound(c: &Vector3<f64>, d: &Vector3<f64>, bound: f64) -> f64 {
    let a = d.norm_squared();
    let b = 2.0 * c.dot(d);
    let k = (c.norm_squared() - bound * bound).min(0.0);
    if a <= 0.0 {
        return 0.0;
    }
    let root = (b * b - 4.0 * a * k).max(0.0).sqrt();
    let t = if b >= 0.0 {
        if b + root > 0.0 {
            -2.0 * k / (b + root)
        } else {
            0.0
        }
    } else {
        (root - b) / (2.0 * a)
    };
    if t.is_finite() { t.max(0.0) } else { 0.0 }
}

/// Moves `step` from `previous` toward itself by at most `bound` in every DoF, the change
/// scaled alike in all of them (its direction kept).
fn limit_change(step: &mut [f64], previous: &[f64], bound: f64) {
    let largest = step
        .iter()
        .zip(previous)
        .fold(0.0_f64, |m, (s, p)| m.max((s - p).abs()));
    if largest > bound {
        let k = bound / largest;
        for (s, p) in step.iter_mut().zip(previous) {
            *s = p + k * (*s - p);
        }
    }
}

/// Slows each DoF that moves toward its limit so that it can stop there at the acceleration
/// whose per-frame change of step is `bound`: a step toward a limit `d` away is at most
/// √(2·bound·d) (the speed from which constant deceleration stops in `d`). A swing brakes the
/// part of its step along the ellipse's outward normal, `d` measured along it. The other DoFs
/// keep their steps, so the hand slows only by what the braking DoF contributed.
fn brake_at_limits(chain: &Chain, q: &[f64], step: &mut [f64], bound: f64) {
    let cap = |d: f64| (2.0 * bound * d.max(0.0)).sqrt();
    let mut k = 0;
    for m in chain.joints().iter().flat_map(|j| &j.motions) {
        match *m {
            Motion::Revolute { min, max, .. } => {
                if step[k] > 0.0 {
                    step[k] = step[k].min(cap(max - q[k]));
                } else if step[k] < 0.0 {
                    step[k] = step[k].max(-cap(q[k] - min));
                }
            }
            Motion::Swing { rx, ry } => {
                let (a, b) = (q[k] / rx, q[k + 1] / ry);
                let e = (a * a + b * b).sqrt();
                // The outward unit normal (the gradient of the ellipse's level set).
                let (n0, n1) = (a / rx, b / ry);
                let norm = n0.hypot(n1);
                if e > 0.0 && norm > 0.0 {
                    let (n0, n1) = (n0 / norm, n1 / norm);
                    let outward = n0 * step[k] + n1 * step[k + 1];
                    // Distance to the ellipse along the normal, to first order in (1 − e):
                    // (1 − e) / |∇e|, with ∇e = (a/rx, b/ry) / e.
                    let d = (1.0 - e) * e / norm;
                    let allowed = cap(d);
                    if outward > allowed {
                        let cut = outward - allowed;
                        step[k] -= cut * n0;
                        step[k + 1] -= cut * n1;
                    }
                }
            }
        }
        k += m.dof_count();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bounds_of_a_reach_follow_its_speed_and_duration() {
        // 1 m/s over 0.5 s: 10 m/s², on a 0.6 m arm 10 / 0.3 rad/s².
        let s = Smoothing::for_reach(1.0, 0.5, 0.6);
        assert!((s.hand_acceleration - 10.0).abs() < 1e-12);
        assert!((s.joint_acceleration - 10.0 / 0.3).abs() < 1e-12);
        assert_eq!(
            s.finish,
            Some(Finish {
                after: 0.5,
                over: FINISH_OVER
            })
        );
        // A hand at rest still gets the least bound.
        let slow = Smoothing::for_reach(0.0, 1.0, 0.6);
        assert_eq!(slow.hand_acceleration, MIN_HAND_ACCELERATION);
        s.validate().unwrap();
        slow.validate().unwrap();
    }

    #[test]
    fn the_finish_weight_rises_smoothly_from_zero_to_one() {
        let s = Smoothing::for_reach(1.0, 0.5, 0.6);
        assert_eq!(s.finish_weight(0.5), 0.0);
        assert_eq!(s.finish_weight(0.75), 1.0);
        assert!((s.finish_weight(0.625) - 0.5).abs() < 1e-12);
        // Its slope vanishes at both ends (no kink in the blend).
        let h = 1e-6;
        assert!((s.finish_weight(0.5 + h) - s.finish_weight(0.5)) / h < 1e-4);
        assert!((s.finish_weight(0.75) - s.finish_weight(0.75 - h)) / h < 1e-4);
    }

    /// Eight bisection steps, as the hand bound searched before (the independent truth).
    fn bisected(c: impl Fn(f64) -> Vector3<f64>, bound: f64) -> f64 {
        let (mut lo, mut hi) = (0.0, 1.0);
        for _ in 0..BISECTIONS {
            let mid = 0.5 * (lo + hi);
            if c(mid).norm() <= bound {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        lo
    }

    #[test]
    fn the_scale_of_an_affine_change_is_bisections_in_two_rounds() {
        let (c0, d) = (
            Vector3::new(0.01, -0.02, 0.005),
            Vector3::new(0.3, 0.1, -0.2),
        );
        let c = |k: f64| c0 + d * k;
        for bound in [0.03, 0.1, 0.2, 0.37] {
            let mut rounds = 0;
            let k = largest_scale(c(0.0), c(1.0), bound, |k| {
                rounds += 1;
                c(k)
            });
            assert_eq!(k.to_bits(), bisected(c, bound).to_bits(), "bound {bound}");
            assert!(rounds <= 2, "bound {bound}: {rounds} rounds");
        }
    }

    #[test]
    fn the_scale_of_a_curved_change_is_bisections_and_keeps_the_bound() {
        // The hand swinging on an arc as the scale grows, a change that grows slowly then
        // fast, and one that turns back inside the bound.
        let arc = |k: f64| Vector3::new(0.2 * (2.5 * k).sin(), 0.2 * (1.0 - (2.5 * k).cos()), 0.0);
        let cubic = |k: f64| Vector3::new(k * k * k * 0.9, 0.05 * k, -0.01);
        let back = |k: f64| Vector3::new(0.05 - 0.2 * k + 0.5 * k * k, 0.0, 0.0);
        for (name, c, bound) in [
            ("arc", &arc as &dyn Fn(f64) -> Vector3<f64>, 0.17),
            ("cubic", &cubic, 0.3),
            ("cubic, tight", &cubic, 0.0101),
            ("back", &back, 0.1),
        ] {
            let mut rounds = 0;
            let k = largest_scale(c(0.0), c(1.0), bound, |k| {
                rounds += 1;
                c(k)
            });
            assert!(c(k).norm() <= bound, "{name}: the bound holds");
            assert_eq!(k.to_bits(), bisected(c, bound).to_bits(), "{name}");
            assert!(
                rounds <= MODEL_ROUNDS + BISECTIONS as usize,
                "{name}: {rounds} rounds"
            );
        }
    }

    #[test]
    fn the_line_meets_the_bound_where_the_quadratic_says() {
        let c = Vector3::new(0.0, 0.0, 0.0);
        let d = Vector3::new(2.0, 0.0, 0.0);
        assert!((line_meets_bound(&c, &d, 1.0) - 0.5).abs() < 1e-15);
        // Starting on the bound, moving inward first: the far crossing.
        let c = Vector3::new(-1.0, 0.0, 0.0);
        assert!((line_meets_bound(&c, &d, 1.0) - 1.0).abs() < 1e-15);
        // No motion: no scale.
        assert_eq!(line_meets_bound(&c, &Vector3::zeros(), 1.0), 0.0);
    }

    #[test]
    fn bad_settings_are_named() {
        let mut s = Smoothing::for_reach(1.0, 0.5, 0.6);
        s.progress_floor = 1.0;
        assert!(
            s.validate()
                .unwrap_err()
                .to_string()
                .contains("progress_floor")
        );
        let mut s = Smoothing::for_reach(1.0, 0.5, 0.6);
        s.hand_acceleration = f64::NAN;
        assert!(
            s.validate()
                .unwrap_err()
                .to_string()
                .contains("hand_acceleration")
        );
    }
}
