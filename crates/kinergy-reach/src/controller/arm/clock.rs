//! The profile's clock ([`ProfileClock`]): where on its world-frame straight path the reaching
//! hand's goal is on each frame. The profile ([`crate::profile`]) says how far the hand has
//! gone t seconds after the start; a physical arm cannot follow it to the letter where it asks
//! for a jump of the hand's velocity, so the clock that reads the profile
//!
//! - **ramps**: the goal's speed along the path starts at the hand's own speed along it (0
//!   from rest, the body's where a step carries the hand) and blends into the profile's over
//!   the ramp, smoothstep-weighted: `u = (1 − S) u₀ + S v(τ)`, `S = smoothstep(t / t_r)`,
//!   `t_r = max(`[`RAMP_TIME`]`, 1.5 |v(0) − u₀| / `[`RAMP_ACCELERATION`]`)` (smoothstep's peak
//!   slope is 1.5), no ramp at all where the two speeds agree (a bell from rest). The paper's
//!   ease-out's goal, from rest, is at 95 % of v_s 0.07 s after the start and at v_s from
//!   0.08 s; the profile's own time τ then runs about 0.04 s behind the wall clock (half the ramp),
//!   which is all the ease-out's reach is longer by;
//! - **waits for the hand**: where the arm shown lags behind its goal along the path by more
//!   than [`WAIT_LAG`] (joint bounds near a straight arm, a posture the analytic solution
//!   flips), τ slows, and stops at twice that lag, so the goal never runs away from the hand
//!   and the hand never has to catch up faster than the profile — the catch-up of a lagging
//!   arm was what made the ease-out's hand overshoot v_s by 75 %. A hand ahead of its goal, or
//!   off the path, does not stop the clock.
//!
//! After the ramp, with the hand following, τ advances with the wall clock and the goal is the
//! profile's own point. The goal stays on the segment from where the hand was when the clock
//! started to the target, in the world: Huang's straight line, whatever the body does.

use kinergy_motion::nalgebra::{Point3, Vector3};

use crate::profile::{SpeedProfile, smoothstep};

/// The shortest ramp from the hand's speed to the profile's, seconds.
pub(super) const RAMP_TIME: f64 = 0.08;

/// The ramp lasts long enough for the goal's acceleration along the path to stay below this,
/// m/s² (a brisk reach's hand peaks near 6 m/s²).
pub(super) const RAMP_ACCELERATION: f64 = 6.0;

/// How far, meters, the hand may lag behind its goal along the path before the profile's
/// clock slows (it stops at twice this).
pub(super) const WAIT_LAG: f64 = 0.001;

/// Where the reaching hand's goal is on its straight path, and the profile's own time.
#[derive(Debug, Clone)]
pub(super) struct ProfileClock {
    /// Where the hand was when the clock started (world).
    start: Point3<f64>,
    /// The target (world).
    end: Point3<f64>,
    /// |end − start|, meters.
    length: f64,
    /// The wall clock (seconds since the arm controller started) when the clock started.
    origin: f64,
    /// The wall clock at the last advance.
    wall: f64,
    /// The profile's own time τ, seconds.
    tau: f64,
    /// The meters of the path the goal has covered.
    covered: f64,
    /// The hand's speed along the path when the clock started, m/s.
    start_speed: f64,
    /// How long the goal's speed takes to blend into the profile's, seconds (0: no ramp).
    ramp: f64,
}

impl ProfileClock {
    /// A clock for the path from `start` to `end` on `profile`, the hand moving along it at
    /// `start_speed` m/s, started at the wall clock's `elapsed` seconds.
    pub(super) fn new(
        profile: &SpeedProfile,
        start: Point3<f64>,
        end: Point3<f64>,
        start_speed: f64,
        elapsed: f64,
    ) -> ProfileClock {
        let length = (end - start).norm();
        let start_speed = if start_speed.is_finite() {
            start_speed.max(0.0)
        } else {
            0.0
        };
        let gap = (profile.speed(length, 0.0) - start_speed).abs();
        let ramp = if gap > 0.0 {
            RAMP_TIME.max(1.5 * gap / RAMP_ACCELERATION)
        } else {
            0.0
        };
        ProfileClock {
            start,
            end,
            length,
            origin: elapsed,
            wall: elapsed,
            tau: 0.0,
            covered: 0.0,
            start_speed,
            ramp,
        }
    }

    /// The path's unit direction (zero for a path of no length).
    pub(super) fn direction(&self) -> Vector3<f64> {
        if self.length > 0.0 {
            (self.end - self.start) / self.length
        } else {
            Vector3::zeros()
        }
    }

    /// Advances the clock to the wall clock's `elapsed` seconds (since the arm controller
    /// started; no change unless later than the last advance), the hand lagging `lag` meters
    /// behind its goal along the path at the last frame's end.
    pub(super) fn advance(&mut self, profile: &SpeedProfile, elapsed: f64, lag: f64) {
        let dt = elapsed - self.wall;
        if dt <= 0.0 || !dt.is_finite() {
            return;
        }
        self.wall = elapsed;
        let total = profile.duration(self.length);
        // 1 while the hand keeps up, 0 once it lags twice WAIT_LAG behind.
        let rate = ((2.0 * WAIT_LAG - lag) / WAIT_LAG).clamp(0.0, 1.0);
        let since = elapsed - self.origin;
        if since < self.ramp {
            let s = smoothstep(since / self.ramp);
            let ahead = profile.speed(self.length, (self.tau + dt).min(total));
            let speed = (1.0 - s) * self.start_speed + s * ahead;
            self.covered = (self.covered + rate * speed * dt).min(self.length);
            self.tau = profile.time_at(self.length, self.covered).max(self.tau);
        } else {
            self.tau = (self.tau + rate * dt).min(total);
            self.covered = profile.progress(self.length, self.tau).max(self.covered);
        }
    }

    /// The path's length, meters.
    pub(super) fn length(&self) -> f64 {
        self.length
    }

    /// The meters of the path the goal has covered.
    pub(super) fn covered(&self) -> f64 {
        self.covered
    }

    /// Puts the goal `covered` meters along the path (the caller keeps it from going back before
    /// the last frame's), the profile's time with it: where the goal is moved round the
    /// shoulder, the follower decides how far along the line it goes.
    pub(super) fn hold_at(&mut self, profile: &SpeedProfile, covered: f64) {
        self.covered = covered.clamp(0.0, self.length);
        self.tau = profile.time_at(self.length, self.covered);
    }

    /// The point `covered` meters along the path.
    pub(super) fn point_at(&self, covered: f64) -> Point3<f64> {
        if self.length <= 0.0 || covered >= self.length {
            return self.end;
        }
        let f = (covered / self.length).max(0.0);
        Point3::from(self.start.coords * (1.0 - f) + self.end.coords * f)
    }

    /// The goal: the point of the path the profile has reached (exactly the target at its
    /// end).
    pub(super) fn goal(&self) -> Point3<f64> {
        self.point_at(self.covered)
    }

    /// Whether the profile has run its course.
    pub(super) fn finished(&self, profile: &SpeedProfile) -> bool {
        self.covered >= self.length || self.tau >= profile.duration(self.length)
    }
}

#[cfg(test)]
mod tests {
    use approx::assert_relative_eq;

    use super::*;

    const DT: f64 = 1.0 / 120.0;

    fn clock(speed: f64) -> ProfileClock {
        ProfileClock::new(
            &SpeedProfile::default(),
            Point3::origin(),
            Point3::new(0.0, 0.0, 1.0),
            speed,
            0.0,
        )
    }

    /// The goal's speed over frames `1..=n` of a clock the hand keeps up with.
    fn speeds(clock: &mut ProfileClock, n: usize, lag: f64) -> Vec<f64> {
        let profile = SpeedProfile::default();
        (0..n)
            .map(|_| {
                let before = clock.covered();
                clock.advance(&profile, clock.wall + DT, lag);
                (clock.covered() - before) / DT
            })
            .collect()
    }

    #[test]
    fn from_rest_the_goal_ramps_to_v_s_and_then_runs_with_the_profile() {
        let mut c = clock(0.0);
        let v = speeds(&mut c, 60, 0.0);
        assert!(v[0] < 0.01, "{v:?}");
        assert!(v.windows(2).all(|w| w[1] >= w[0] - 1e-12), "{v:?}");
        let ramp = (RAMP_TIME / DT).ceil() as usize;
        for s in &v[ramp..] {
            assert_relative_eq!(*s, 0.2, epsilon = 1e-9);
        }
        // The profile's time runs about half the ramp behind the wall clock.
        assert_relative_eq!(c.tau, 60.0 * DT - 0.5 * RAMP_TIME, epsilon = 5e-3);
    }

    #[test]
    fn a_carried_hand_s_speed_blends_down_into_the_profile_s() {
        let mut c = clock(0.8);
        assert_relative_eq!(c.ramp, 1.5 * 0.6 / RAMP_ACCELERATION, epsilon = 1e-12);
        let v = speeds(&mut c, 40, 0.0);
        assert!(v[0] > 0.79, "{v:?}");
        assert!(v.windows(2).all(|w| w[1] <= w[0] + 1e-12), "{v:?}");
        assert_relative_eq!(v[39], 0.2, epsilon = 1e-9);
    }

    #[test]
    fn the_clock_waits_for_a_hand_that_lags() {
        let mut c = clock(0.0);
        speeds(&mut c, 20, 0.0);
        let at = c.covered();
        let v = speeds(&mut c, 5, 2.0 * WAIT_LAG);
        assert_eq!(c.covered(), at, "{v:?}");
        let half = speeds(&mut c, 1, 1.5 * WAIT_LAG)[0];
        assert_relative_eq!(half, 0.1, epsilon = 1e-9);
    }

    #[test]
    fn the_goal_ends_exactly_on_the_target() {
        let profile = SpeedProfile::default();
        let mut c = clock(0.0);
        let mut k = 0;
        while !c.finished(&profile) {
            k += 1;
            c.advance(&profile, k as f64 * DT, 0.0);
            assert!(k < 10_000);
        }
        assert_eq!(c.goal(), Point3::new(0.0, 0.0, 1.0));
        // 1 m at the paper's defaults takes eq. 4's 5.56 s, and half the ramp more.
        assert_relative_eq!(k as f64 * DT, 1.0 / 0.18 + 0.5 * RAMP_TIME, epsilon = 0.02);
    }
}
