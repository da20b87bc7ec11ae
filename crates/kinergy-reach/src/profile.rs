//! How far along its straight path the hand is at each moment: the arm controller's speed
//! profile (Huang, Kapadia & Terzopoulos §3.3, eqs. 1–4 and Algorithm 1; DESIGN §1.2).
//!
//! The hand moves on the segment from its start p_s to the target p_e, d_h = p_e − p_s;
//! a profile says how many meters of |d_h| it has covered t seconds after the start.
//!
//! | profile | progress s(t), h = t / T | duration T |
//! |---|---|---|
//! | [`SpeedProfile::EaseOut`] (the paper's) | v_s t, then \|d_h\| − ½ a (T − t)² | t_t = 2\|d_h\| / (v_s (r_s + 1)) (eq. 4) |
//! | [`SpeedProfile::MinimumJerk`] | \|d_h\| (10h³ − 15h⁴ + 6h⁵) | from [`BellTiming`] |
//! | [`SpeedProfile::Cubic`] (Kallmann's) | \|d_h\| (3h² − 2h³) | from [`BellTiming`] |
//!
//! Every profile starts at 0 at t = 0, ends exactly at |d_h| at t = T and stays there;
//! before t = 0 the hand has not moved. Distances ≤ 0 give a hand that never moves.
//!
//! # The ease-out, derived
//! Speed v_s for the first r_s t_t seconds, then a constant deceleration |a| that brings
//! the hand to rest at t_t (eqs. 1–2): |a| = v_s / (t_t (1 − r_s)). The distance is the
//! area under the speed, a rectangle plus a triangle:
//!
//! |d_h| = v_s r_s t_t + ½ v_s (1 − r_s) t_t = v_s t_t (1 + r_s) / 2,
//!
//! hence t_t = 2|d_h| / (v_s (r_s + 1)), the paper's eq. 4 and Algorithm 1.
//!
//! DESIGN §1.2 says eq. 3 has a typo. In our copy of the paper it reads
//! d_h = v_s t_t + ½ a (t_t (1 − r_s))², which is right: it integrates Algorithm 1's speed
//! v_s + a (t − r_s t_t) (a < 0 after r_s t_t) over [0, t_t], and with eq. 2 it gives
//! v_s t_t − ½ v_s (1 − r_s) t_t, the value above, so eqs. 1–3 do give eq. 4. (Printed
//! copies that differ should be read this way.) What does need reading with care:
//! - "2|d_h|/v_s(r_s + 1)" in eq. 4 and Algorithm 1, and "−**v**_s/t_t(1 − r_s)" in eq. 2,
//!   mean 2|d_h| / (v_s (r_s + 1)) and −**v**_s / (t_t (1 − r_s));
//! - Algorithm 1 computes a from **v**_s one line before it assigns **v**_s: compute
//!   **v**_s first;
//! - Algorithm 1's update is explicit Euler with the speed at the start of each frame, so
//!   its hand runs ahead of the closed form by up to about v_s Δt / 2 while braking, and if
//!   the ε test misses the target, v_c turns negative after t_t and the hand comes back.
//!   The closed form here stops exactly at the target at t_t.
//!
//! The ease-out starts at full speed (a step from rest to v_s). Human hand speed is
//! bell-shaped, rising from and falling to zero, which the minimum-jerk and cubic options
//! give (DESIGN §1.2, beyond the paper).
//!
//! These are the profiles' closed forms. The full-body character's arm reads them through a
//! clock of its own ([`crate::controller`], "Arm") that starts where a physical hand can: the
//! goal's speed along the line rises from the hand's own speed along it (0 from rest) to the
//! profile's over a smoothstep ramp of 0.08 s, and the clock waits while the arm lags behind
//! its goal, so the hand never catches up faster than the profile. The default ease-out's hand
//! is then within 5 % of v_s 0.075 s after the arm's onset (120 Hz) and holds v_s within 1.5 %
//! until the deceleration; the profile's time runs about 0.04 s behind the wall clock, and the
//! reach lasts that much longer. Where a step carries the hand at the arm's onset, its speed
//! comes down to within 5 % of v_s in 0.13–0.15 s. (`tests/profile_realtime.rs` measures
//! these.)
//!
//! ```
//! use kinergy_reach::profile::SpeedProfile;
//!
//! let ease = SpeedProfile::default(); // v_s = 0.20 m/s, r_s = 0.8
//! let t_t = ease.duration(0.36);
//! assert!((t_t - 2.0).abs() < 1e-12); // 2 · 0.36 / (0.2 · 1.8)
//! assert_eq!(ease.progress(0.36, t_t), 0.36);
//! assert_eq!(ease.speed(0.36, 1.0), 0.20); // still in the constant-speed phase
//! ```

use kinergy_io::InvalidSetting;
use nalgebra::Point3;
use serde::{Deserialize, Serialize};

use crate::error::Result;

/// The paper's start hand speed v_s, m/s (§3.3: 20 cm/s).
pub const PAPER_START_SPEED: f64 = 0.20;
/// The paper's start-phase ratio r_s (§3.3).
pub const PAPER_START_RATIO: f64 = 0.8;
/// Peak speed of the minimum-jerk profile in units of the mean speed |d|/T: s′(½) = 30/16.
pub const MINIMUM_JERK_PEAK_RATIO: f64 = 1.875;
/// Peak speed of the cubic profile in units of the mean speed |d|/T: s′(½) = 6/4.
pub const CUBIC_PEAK_RATIO: f64 = 1.5;

/// How long a bell-shaped profile (minimum jerk or cubic) takes to cover a distance D.
///
/// Serialized as e.g. `{"mean_speed": {"speed": 0.18}}`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", deny_unknown_fields)]
pub enum BellTiming {
    /// T = D / v̄: the hand covers the distance at this mean speed (m/s).
    MeanSpeed {
        /// Mean speed v̄, m/s.
        speed: f64,
    },
    /// T = c D / v_peak with c the profile's peak ratio ([`MINIMUM_JERK_PEAK_RATIO`],
    /// [`CUBIC_PEAK_RATIO`]): the hand's top speed is this (m/s) whatever the distance.
    PeakSpeed {
        /// Peak speed, m/s.
        speed: f64,
    },
    /// T fixed, whatever the distance.
    Duration {
        /// T, seconds.
        seconds: f64,
    },
    /// Fitts's law in its Shannon form (MacKenzie 1992): T = a + b log₂(1 + D / W), so far
    /// and precise reaches take longer, and a zero-distance reach still takes a.
    Fitts {
        /// Intercept a, seconds (≥ 0).
        a: f64,
        /// Slope b, seconds per bit (> 0).
        b: f64,
        /// Target width W, meters (> 0).
        width: f64,
    },
}

impl BellTiming {
    /// The mean speed of the paper's ease-out with the paper's v_s and r_s:
    /// v_s (1 + r_s) / 2 = 0.18 m/s. A bell with this timing takes as long as the
    /// ease-out (eq. 4) for every distance.
    pub const PAPER_MEAN_SPEED: f64 = PAPER_START_SPEED * (1.0 + PAPER_START_RATIO) / 2.0;

    /// The timing that makes a bell last exactly as long as the ease-out with `v_s` and
    /// `r_s` for every distance: mean speed v_s (1 + r_s) / 2 (from eq. 4).
    pub fn matching_ease_out(v_s: f64, r_s: f64) -> BellTiming {
        BellTiming::MeanSpeed {
            speed: v_s * (1.0 + r_s) / 2.0,
        }
    }

    /// The duration T for `distance` meters, for a profile whose peak speed is
    /// `peak_ratio` times its mean speed.
    fn duration(&self, distance: f64, peak_ratio: f64) -> f64 {
        let d = distance.max(0.0);
        match *self {
            BellTiming::MeanSpeed { speed } => d / speed,
            BellTiming::PeakSpeed { speed } => peak_ratio * d / speed,
            BellTiming::Duration { seconds } => seconds,
            BellTiming::Fitts { a, b, width } => a + b * (1.0 + d / width).log2(),
        }
    }

    fn validate(&self, field: &str) -> Result<()> {
        let positive = |v: f64| v.is_finite() && v > 0.0;
        match *self {
            BellTiming::MeanSpeed { speed } | BellTiming::PeakSpeed { speed } => {
                InvalidSetting::require(
                    positive(speed),
                    &format!("{field}.speed"),
                    "a positive speed (m/s)",
                )?
            }
            BellTiming::Duration { seconds } => InvalidSetting::require(
                positive(seconds),
                &format!("{field}.seconds"),
                "a positive duration (s)",
            )?,
            BellTiming::Fitts { a, b, width } => {
                InvalidSetting::require(
                    a.is_finite() && a >= 0.0,
                    &format!("{field}.a"),
                    "a finite intercept ≥ 0 (s)",
                )?;
                InvalidSetting::require(
                    positive(b),
                    &format!("{field}.b"),
                    "a positive slope (s/bit)",
                )?;
                InvalidSetting::require(
                    positive(width),
                    &format!("{field}.width"),
                    "a positive target width (m)",
                )?
            }
        }
        Ok(())
    }
}

impl Default for BellTiming {
    /// [`BellTiming::PAPER_MEAN_SPEED`]: as long as the paper's ease-out.
    fn default() -> BellTiming {
        BellTiming::MeanSpeed {
            speed: BellTiming::PAPER_MEAN_SPEED,
        }
    }
}

/// The hand's progress along its straight path over time. Serialized as
/// `{"kind": "ease_out", "v_s": 0.2, "r_s": 0.8}`, `{"kind": "minimum_jerk", "timing": …}`
/// or `{"kind": "cubic", "timing": …}`.
///
/// Fields are public for configuration; [`SpeedProfile::validate`] (or the constructors)
/// checks them. The methods take the distance |d_h| in meters and the time t in seconds
/// since the start of the reach.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum SpeedProfile {
    /// The paper's ease-out (§3.3, eqs. 1–4, Algorithm 1): speed v_s for the first r_s of
    /// the time, then constant deceleration to rest at t_t = 2|d_h| / (v_s (r_s + 1)).
    EaseOut {
        /// Start speed v_s, m/s (> 0; the paper's 0.20).
        v_s: f64,
        /// Start-phase ratio r_s, the constant-speed share of t_t, in (0, 1] (the paper's
        /// 0.8; 1 means constant speed and a stop at the target).
        r_s: f64,
    },
    /// Minimum jerk (Flash & Hogan 1985): s(h) = |d| (10h³ − 15h⁴ + 6h⁵), h = t / T. A
    /// symmetric bell with peak 1.875 |d|/T at T/2 and zero speed and acceleration at
    /// both ends, like measured human reaches.
    MinimumJerk {
        /// How T follows from the distance.
        timing: BellTiming,
    },
    /// Kallmann's cubic time warp t = −2h³ + 3h² (smoothstep): s(h) = |d| (3h² − 2h³). A
    /// symmetric bell with peak 1.5 |d|/T, zero speed at both ends but acceleration
    /// ±6 |d|/T² there.
    Cubic {
        /// How T follows from the distance.
        timing: BellTiming,
    },
}

impl Default for SpeedProfile {
    /// The paper's ease-out, v_s = 0.20 m/s, r_s = 0.8.
    fn default() -> SpeedProfile {
        SpeedProfile::EaseOut {
            v_s: PAPER_START_SPEED,
            r_s: PAPER_START_RATIO,
        }
    }
}

impl SpeedProfile {
    /// The paper's ease-out with start speed `v_s` (m/s) and start-phase ratio `r_s`,
    /// validated.
    pub fn ease_out(v_s: f64, r_s: f64) -> Result<SpeedProfile> {
        let profile = SpeedProfile::EaseOut { v_s, r_s };
        profile.validate()?;
        Ok(profile)
    }

    /// A minimum-jerk bell with this timing, validated.
    pub fn minimum_jerk(timing: BellTiming) -> Result<SpeedProfile> {
        let profile = SpeedProfile::MinimumJerk { timing };
        profile.validate()?;
        Ok(profile)
    }

    /// Kallmann's cubic bell with this timing, validated.
    pub fn cubic(timing: BellTiming) -> Result<SpeedProfile> {
        let profile = SpeedProfile::Cubic { timing };
        profile.validate()?;
        Ok(profile)
    }

    /// Checks every setting, naming the field (`profile.v_s`, `profile.r_s`,
    /// `profile.timing.speed`, …) otherwise.
    pub fn validate(&self) -> Result<()> {
        match *self {
            SpeedProfile::EaseOut { v_s, r_s } => {
                InvalidSetting::require(
                    v_s.is_finite() && v_s > 0.0,
                    "profile.v_s",
                    "a positive start speed (m/s)",
                )?;
                InvalidSetting::require(
                    r_s > 0.0 && r_s <= 1.0,
                    "profile.r_s",
                    "a start-phase ratio in (0, 1]",
                )?;
                Ok(())
            }
            SpeedProfile::MinimumJerk { timing } | SpeedProfile::Cubic { timing } => {
                timing.validate("profile.timing")
            }
        }
    }

    /// The total time T (the paper's t_t) to cover `distance` meters, seconds.
    ///
    /// Ease-out: eq. 4, t_t = 2|d_h| / (v_s (r_s + 1)). Bells: from their [`BellTiming`].
    pub fn duration(&self, distance: f64) -> f64 {
        match *self {
            SpeedProfile::EaseOut { v_s, r_s } => 2.0 * distance.max(0.0) / (v_s * (r_s + 1.0)),
            SpeedProfile::MinimumJerk { timing } => {
                timing.duration(distance, MINIMUM_JERK_PEAK_RATIO)
            }
            SpeedProfile::Cubic { timing } => timing.duration(distance, CUBIC_PEAK_RATIO),
        }
    }

    /// The hand's top speed over `distance` meters, m/s: v_s for the ease-out, the bell's
    /// peak ratio times the mean speed |d|/T for the bells (1.875 minimum jerk, 1.5 cubic).
    pub fn peak_speed(&self, distance: f64) -> f64 {
        let total = self.duration(distance);
        if distance <= 0.0 || total <= 0.0 {
            return 0.0;
        }
        match *self {
            SpeedProfile::EaseOut { v_s, .. } => v_s,
            SpeedProfile::MinimumJerk { .. } => MINIMUM_JERK_PEAK_RATIO * distance / total,
            SpeedProfile::Cubic { .. } => CUBIC_PEAK_RATIO * distance / total,
        }
    }

    /// Meters travelled t seconds after the start: 0 for t ≤ 0, exactly `distance` for
    /// t ≥ T, non-decreasing and continuous in between.
    pub fn progress(&self, distance: f64, t: f64) -> f64 {
        if distance <= 0.0 || t <= 0.0 {
            return 0.0;
        }
        let total = self.duration(distance);
        if t >= total {
            return distance;
        }
        match *self {
            SpeedProfile::EaseOut { v_s, r_s } => {
                if t < r_s * total {
                    v_s * t
                } else {
                    // What is left is the braking distance ½ |a| (t_t − t)², exact at t_t.
                    let left = total - t;
                    distance - 0.5 * ease_out_deceleration(v_s, r_s, total) * left * left
                }
            }
            SpeedProfile::MinimumJerk { .. } => distance * symmetric(t / total, minimum_jerk),
            SpeedProfile::Cubic { .. } => distance * symmetric(t / total, cubic),
        }
    }

    /// The inverse of [`progress`](Self::progress): the first time, seconds, at which the hand
    /// has covered `covered` meters of `distance` — 0 for `covered` ≤ 0, T for `covered` ≥
    /// `distance`. Closed form for the ease-out (t = s / v_s, then t_t − √(2 (|d_h| − s) / |a|)),
    /// bisection to machine precision for the bells (their progress rises strictly).
    pub fn time_at(&self, distance: f64, covered: f64) -> f64 {
        let total = self.duration(distance);
        if distance <= 0.0 || covered <= 0.0 || !covered.is_finite() {
            return 0.0;
        }
        if covered >= distance {
            return total;
        }
        if let SpeedProfile::EaseOut { v_s, r_s } = *self {
            let cruise = v_s * r_s * total;
            return if covered <= cruise {
                (covered / v_s).min(total)
            } else {
                let left = 2.0 * (distance - covered) / ease_out_deceleration(v_s, r_s, total);
                (total - left.max(0.0).sqrt()).clamp(0.0, total)
            };
        }
        let (mut lo, mut hi) = (0.0, total);
        for _ in 0..64 {
            let mid = 0.5 * (lo + hi);
            if self.progress(distance, mid) < covered {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        hi
    }

    /// Hand speed t seconds after the start, m/s: the derivative of
    /// [`progress`](Self::progress) (one-sided at the ease-out's start and, for r_s = 1,
    /// its end, where the speed jumps). Zero before the start and after T.
    pub fn speed(&self, distance: f64, t: f64) -> f64 {
        let total = self.duration(distance);
        if distance <= 0.0 || t < 0.0 || t >= total {
            return 0.0;
        }
        match *self {
            SpeedProfile::EaseOut { v_s, r_s } => {
                if t < r_s * total {
                    v_s
                } else {
                    ease_out_deceleration(v_s, r_s, total) * (total - t)
                }
            }
            SpeedProfile::MinimumJerk { .. } => {
                let (h, g) = (t / total, 1.0 - t / total);
                distance / total * 30.0 * h * h * g * g
            }
            SpeedProfile::Cubic { .. } => {
                let (h, g) = (t / total, 1.0 - t / total);
                distance / total * 6.0 * h * g
            }
        }
    }

    /// Hand acceleration along the path t seconds after the start, m/s² (negative while
    /// braking): the derivative of [`speed`](Self::speed). Zero before the start and after
    /// T. The ease-out's is −a of eq. 2 during deceleration (−v_s / (t_t (1 − r_s))).
    pub fn acceleration(&self, distance: f64, t: f64) -> f64 {
        let total = self.duration(distance);
        if distance <= 0.0 || t < 0.0 || t >= total {
            return 0.0;
        }
        match *self {
            SpeedProfile::EaseOut { v_s, r_s } => {
                if t < r_s * total {
                    0.0
                } else {
                    -ease_out_deceleration(v_s, r_s, total)
                }
            }
            SpeedProfile::MinimumJerk { .. } => {
                let (h, g) = (t / total, 1.0 - t / total);
                distance / (total * total) * 60.0 * h * g * (g - h)
            }
            SpeedProfile::Cubic { .. } => {
                let (h, g) = (t / total, 1.0 - t / total);
                distance / (total * total) * 6.0 * (g - h)
            }
        }
    }

    /// The hand on the segment from `start` (p_s) to `end` (p_e) t seconds after the
    /// start: Algorithm 1's p_c in closed form. Exactly `start` for t ≤ 0 and exactly
    /// `end` for t ≥ T.
    pub fn position(&self, start: &Point3<f64>, end: &Point3<f64>, t: f64) -> Point3<f64> {
        let distance = (end - start).norm();
        if distance == 0.0 {
            return *start;
        }
        let f = self.progress(distance, t) / distance;
        // (1 − f) p_s + f p_e is exact at f = 0 and f = 1.
        Point3::from(start.coords * (1.0 - f) + end.coords * f)
    }
}

/// |a| of eq. 2: v_s / (t_t (1 − r_s)).
fn ease_out_deceleration(v_s: f64, r_s: f64, total: f64) -> f64 {
    v_s / (total * (1.0 - r_s))
}

/// Minimum-jerk progress on [0, 1], Horner form of 10h³ − 15h⁴ + 6h⁵.
fn minimum_jerk(h: f64) -> f64 {
    h * h * h * (10.0 + h * (-15.0 + 6.0 * h))
}

/// Cubic progress on [0, 1], 3h² − 2h³.
fn cubic(h: f64) -> f64 {
    h * h * (3.0 - 2.0 * h)
}

/// Smoothstep: the cubic bell's progress of `x` clamped to [0, 1]. The body's controllers
/// (the step's keyframes, the twist, the swing, the squat) ease in and out on it.
pub(crate) fn smoothstep(x: f64) -> f64 {
    cubic(x.clamp(0.0, 1.0))
}

/// `shape(h)` for h ≤ ½ and 1 − shape(1 − h) beyond: both bells are point-symmetric about
/// (½, ½), and evaluating the second half from the end keeps it accurate near h = 1.
fn symmetric(h: f64, shape: fn(f64) -> f64) -> f64 {
    if h <= 0.5 {
        shape(h)
    } else {
        1.0 - shape(1.0 - h)
    }
}
