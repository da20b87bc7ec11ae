//! Real-time fidelity of a synthesized hand-speed series against a captured one: every measure
//! here works in seconds, never on time-normalized shapes, because a reach that lasts 1.5× as
//! long with a slow tail can have the captured *shape*.
//!
//! A series is one speed per frame (m/s; in Kinergy the hand relative to the shoulder), frame
//! 0 at the motion's onset, `frame_time` seconds apart ([`Speeds`]).
//!
//! - **Real-time error** ([`realtime_error`]): e = √(mean_k (v_model,k − v_capture,k)²) ÷
//!   max v_capture, the model first resampled at the capture's frame time, the shorter series
//!   padded with zeros to the longer's length — a late start, a slow tail or an extra bump
//!   all count.
//! - **Duration, peak speed, time to peak, path length** ([`duration`], [`peak_speed`],
//!   [`time_to_peak`], [`path_length`]: the trapezoid integral of speed).
//! - **Smoothness**: SPARC, the spectral arc length of Balasubramanian, Melendez-Calderon,
//!   Roby-Brami & Burdet (2015, "On the analysis of movement smoothness", J NeuroEng Rehabil
//!   12:112), with their defaults ([`sparc`]); and the log dimensionless jerk of Hogan &
//!   Sternad (2009) / Balasubramanian et al. (2012) ([`log_dimensionless_jerk`]).
//! - **Minimum jerk** (Flash & Hogan 1985; [`minimum_jerk`]): v(t) = (L/T)·30τ²(1−τ)², τ = t/T.
//! - **A person's own repeats** ([`mean_profile`], [`leave_one_out`]): the mean of the takes'
//!   time-normalized profiles (each over its own span, divided by its own peak), played over
//!   the takes' mean duration at their mean peak speed.
//! - **Jumps in real time** ([`Fidelity::jumps`]): a frame-to-frame change of the speed larger
//!   than the capture's own largest on the same reach, at the capture's frame rate.
//!
//! ```
//! use kinergy_motion::fidelity::{Speeds, minimum_jerk, realtime_error};
//!
//! let bell = minimum_jerk(0.5, 1.0, 1.0 / 60.0);
//! let slow = minimum_jerk(0.5, 1.5, 1.0 / 60.0);
//! let s = |v| Speeds { values: v, frame_time: 1.0 / 60.0 };
//! assert_eq!(realtime_error(s(&bell), s(&bell)), 0.0);
//! assert!(realtime_error(s(&slow), s(&bell)) > 0.2);
//! ```

use serde::Serialize;

/// Whether `x` is a number above 0 (NaN is not).
fn positive(x: f64) -> bool {
    x > 0.0
}

/// Samples of a time-normalized profile in [`mean_profile`] (0, 1/100, …, 1 of the motion).
pub const NORMALIZED: usize = 101;

/// A speed series: one value per frame (m/s) and the seconds per frame.
#[derive(Debug, Clone, Copy)]
pub struct Speeds<'a> {
    /// The speeds, frame 0 at the onset.
    pub values: &'a [f64],
    /// Seconds per frame.
    pub frame_time: f64,
}

/// `values` sampled every `from_dt` seconds, resampled every `to_dt` over the same span
/// [0, (n − 1)·from_dt] by linear interpolation (the last sample at or before the span's end);
/// a copy when the two are equal, empty for no values or a frame time that is not positive.
pub fn resample(values: &[f64], from_dt: f64, to_dt: f64) -> Vec<f64> {
    if from_dt == to_dt {
        return values.to_vec();
    }
    if values.is_empty() || !(positive(from_dt) && positive(to_dt)) {
        return Vec::new();
    }
    let span = (values.len() - 1) as f64 * from_dt;
    let n = (span / to_dt + 1e-9).floor() as usize + 1;
    (0..n)
        .map(|k| at_time(values, from_dt, k as f64 * to_dt))
        .collect()
}

/// The series at `t` seconds by linear interpolation (its ends beyond them).
fn at_time(values: &[f64], dt: f64, t: f64) -> f64 {
    let x = (t / dt).max(0.0);
    let last = values.len() - 1;
    let i = (x.floor() as usize).min(last);
    if i >= last {
        return values[last];
    }
    let u = x - i as f64;
    values[i] * (1.0 - u) + values[i + 1] * u
}

/// The real-time error e of `model` against `capture` (module docs); NaN when the capture is
/// empty or its peak is not positive.
pub fn realtime_error(model: Speeds<'_>, capture: Speeds<'_>) -> f64 {
    let peak = peak_speed(capture);
    if capture.values.is_empty() || !positive(peak) {
        return f64::NAN;
    }
    let model = resample(model.values, model.frame_time, capture.frame_time);
    let n = model.len().max(capture.values.len());
    let sum: f64 = (0..n)
        .map(|k| {
            let a = model.get(k).copied().unwrap_or(0.0);
            let b = capture.values.get(k).copied().unwrap_or(0.0);
            (a - b) * (a - b)
        })
        .sum();
    (sum / n as f64).sqrt() / peak
}

/// Seconds from the first frame to the last ((n − 1)·dt; 0 for one frame or none).
pub fn duration(s: Speeds<'_>) -> f64 {
    s.values.len().saturating_sub(1) as f64 * s.frame_time
}

/// The share of its peak speed at which a motion counts as over ([`movement_duration`]): 10 %.
pub const END_SHARE: f64 = 0.1;

/// A motion's duration, seconds: from its first frame to the first frame past its peak at
/// which the speed has fallen to [`END_SHARE`] of the peak (the whole series when it never
/// does). The same rule for a capture and a synthesis, so a synthesis that holds the target
/// for a second after arriving is not counted long, while a slow tail above a tenth of the
/// peak is.
pub fn movement_duration(s: Speeds<'_>) -> f64 {
    let peak = peak_speed(s);
    let top = (time_to_peak(s) / s.frame_time).round() as usize;
    let end = (top..s.values.len())
        .find(|&k| s.values[k] <= END_SHARE * peak)
        .unwrap_or(s.values.len().saturating_sub(1));
    end as f64 * s.frame_time
}

/// The largest finite speed (0 for none).
pub fn peak_speed(s: Speeds<'_>) -> f64 {
    s.values
        .iter()
        .copied()
        .filter(|v| v.is_finite())
        .fold(0.0, f64::max)
}

/// Seconds from the first frame to the first maximum (0 for none).
pub fn time_to_peak(s: Speeds<'_>) -> f64 {
    let mut best = (0, f64::NEG_INFINITY);
    for (i, &v) in s.values.iter().enumerate() {
        if v.is_finite() && v > best.1 {
            best = (i, v);
        }
    }
    best.0 as f64 * s.frame_time
}

/// The path length, meters: the trapezoid integral of the speed over time.
pub fn path_length(s: Speeds<'_>) -> f64 {
    s.values
        .windows(2)
        .map(|w| 0.5 * (w[0] + w[1]) * s.frame_time)
        .filter(|v| v.is_finite())
        .sum()
}

/// The largest frame-to-frame change `|v[k+1] − v[k]|` over finite pairs (0 for fewer than 2).
pub fn largest_change(values: &[f64]) -> f64 {
    values
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| d.is_finite())
        .fold(0.0, f64::max)
}

/// SPARC's settings (Balasubramanian et al. 2015, their defaults by [`Default`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SparcSettings {
    /// The series is zero-padded to the next power of two ≥ n · 2^`pad_level` (4).
    pub pad_level: u32,
    /// The highest frequency considered, Hz (10: human movement has little above it).
    pub fc_max_hz: f64,
    /// The normalized magnitude below which the spectrum's tail is cut (0.05).
    pub amplitude_threshold: f64,
}

impl Default for SparcSettings {
    fn default() -> SparcSettings {
        SparcSettings {
            pad_level: 4,
            fc_max_hz: 10.0,
            amplitude_threshold: 0.05,
        }
    }
}

/// SPARC, the spectral arc length of the speed profile (Balasubramanian et al. 2015): the
/// magnitude spectrum |V(f)| of the zero-padded series, normalized by |V(0)|, is cut at the
/// last frequency f_c ≤ `fc_max_hz` where it is still at least `amplitude_threshold`, and
/// SPARC = −∫₀^{f_c} √((1/f_c)² + (d|V̂|/df)²) df, summed over the spectral bins. It is
/// dimensionless, independent of the profile's amplitude and duration: a minimum-jerk bell
/// scores about −1.42, a profile of several submovements or with tremor lower (more
/// negative). The spectrum is a direct DFT of the bins up to `fc_max_hz`. NaN for fewer than
/// 2 samples, a frame time that is not positive, or a profile of zero mean.
pub fn sparc(s: Speeds<'_>, settings: &SparcSettings) -> f64 {
    let n = s.values.len();
    if n < 2 || !positive(s.frame_time) || s.values.iter().any(|v| !v.is_finite()) {
        return f64::NAN;
    }
    let padded = (n as f64 * 2f64.powi(settings.pad_level as i32))
        .log2()
        .ceil();
    let total = 2f64.powf(padded);
    let df = 1.0 / (total * s.frame_time);
    let bins = ((settings.fc_max_hz / df).floor() as usize).max(1);
    let magnitude = |k: usize| -> f64 {
        let w = -2.0 * std::f64::consts::PI * k as f64 / total;
        let (mut re, mut im) = (0.0, 0.0);
        for (i, &v) in s.values.iter().enumerate() {
            let (sin, cos) = (w * i as f64).sin_cos();
            re += v * cos;
            im += v * sin;
        }
        re.hypot(im)
    };
    let zero = magnitude(0);
    if !positive(zero) {
        return f64::NAN;
    }
    let spectrum: Vec<f64> = (0..=bins).map(|k| magnitude(k) / zero).collect();
    let cut = spectrum
        .iter()
        .rposition(|&m| m >= settings.amplitude_threshold)
        .unwrap_or(0)
        .max(1);
    let fc = cut as f64 * df;
    let step = df / fc;
    -spectrum[..=cut]
        .windows(2)
        .map(|w| step.hypot(w[1] - w[0]))
        .sum::<f64>()
}

/// The log dimensionless jerk of a speed profile: −ln((T³ / v_peak²) ∫₀^T (d²v/dt²)² dt), the
/// second derivative by central differences and the integral by the rectangle rule. For a
/// straight path the speed's second derivative is the jerk along it (what a hand-speed profile
/// can tell). Minimum jerk scores −ln(720 / 1.875²) = −5.322; less smooth motions lower. NaN
/// for fewer than 5 samples or a zero peak.
pub fn log_dimensionless_jerk(s: Speeds<'_>) -> f64 {
    let v = s.values;
    let dt = s.frame_time;
    let peak = peak_speed(s);
    if v.len() < 5 || !positive(peak) || !positive(dt) {
        return f64::NAN;
    }
    let integral: f64 = v
        .windows(3)
        .map(|w| {
            let a = (w[2] - 2.0 * w[1] + w[0]) / (dt * dt);
            a * a * dt
        })
        .sum();
    let t = duration(s);
    -(t.powi(3) / (peak * peak) * integral).ln()
}

/// The minimum-jerk speed over a path of `length` meters lasting `duration` seconds, sampled
/// every `frame_time` from 0 to the frame nearest `duration`: v(t) = (L/T)·30τ²(1−τ)², τ = t/T
/// (0 past T). Empty for a duration or frame time that is not positive.
pub fn minimum_jerk(length: f64, duration: f64, frame_time: f64) -> Vec<f64> {
    if !(positive(duration) && positive(frame_time) && length.is_finite()) {
        return Vec::new();
    }
    let n = (duration / frame_time).round() as usize + 1;
    (0..n)
        .map(|k| {
            let tau = (k as f64 * frame_time / duration).clamp(0.0, 1.0);
            length / duration * 30.0 * tau * tau * (1.0 - tau) * (1.0 - tau)
        })
        .collect()
}

/// `values` resampled at [`NORMALIZED`] evenly spaced fractions of their span.
fn normalized(values: &[f64]) -> Vec<f64> {
    if values.len() < 2 {
        return vec![values.first().copied().unwrap_or(0.0); NORMALIZED];
    }
    let last = (values.len() - 1) as f64;
    (0..NORMALIZED)
        .map(|k| at_time(values, 1.0, k as f64 / (NORMALIZED - 1) as f64 * last))
        .collect()
}

/// The person's own repeats as a predictor (module docs): the mean of the `takes`'
/// time-normalized profiles, each divided by its own peak, scaled to peak at the takes' mean
/// peak speed and played over their mean duration, sampled every `frame_time`. Empty for no
/// takes (or none with a positive peak and duration).
pub fn mean_profile(takes: &[Speeds<'_>], frame_time: f64) -> Vec<f64> {
    let usable: Vec<&Speeds<'_>> = takes
        .iter()
        .filter(|s| peak_speed(**s) > 0.0 && duration(**s) > 0.0)
        .collect();
    if usable.is_empty() || !positive(frame_time) {
        return Vec::new();
    }
    let k = usable.len() as f64;
    let mut shape = vec![0.0; NORMALIZED];
    for s in &usable {
        let peak = peak_speed(**s);
        for (m, v) in shape.iter_mut().zip(normalized(s.values)) {
            *m += v / peak / k;
        }
    }
    let top = shape.iter().copied().fold(0.0, f64::max);
    let peak = usable.iter().map(|s| peak_speed(**s)).sum::<f64>() / k;
    let length = usable.iter().map(|s| duration(**s)).sum::<f64>() / k;
    let n = (length / frame_time).round() as usize + 1;
    (0..n)
        .map(|i| {
            let u = (i as f64 * frame_time / length).min(1.0) * (NORMALIZED - 1) as f64;
            at_time(&shape, 1.0, u) / top * peak
        })
        .collect()
}

/// The noise ceiling by leave-one-out: for each take, the real-time error of the others'
/// [`mean_profile`] (at its frame time) against it. NaN for every take when there are fewer
/// than two.
pub fn leave_one_out(takes: &[Speeds<'_>]) -> Vec<f64> {
    (0..takes.len())
        .map(|i| {
            if takes.len() < 2 {
                return f64::NAN;
            }
            let others: Vec<Speeds<'_>> = takes
                .iter()
                .enumerate()
                .filter(|&(k, _)| k != i)
                .map(|(_, s)| *s)
                .collect();
            let predicted = mean_profile(&others, takes[i].frame_time);
            realtime_error(
                Speeds {
                    values: &predicted,
                    frame_time: takes[i].frame_time,
                },
                takes[i],
            )
        })
        .collect()
}

/// How much larger than the capture's own largest frame-to-frame change a motion's may be
/// before it is a jump: 0 (a tie is not a jump).
pub const JUMP_SLACK: f64 = 0.0;

/// One motion's real-time figures against a capture ([`Fidelity::of`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Fidelity {
    /// The real-time error e ([`realtime_error`]).
    pub error: f64,
    /// The motion's duration over the capture's, both by [`movement_duration`].
    pub duration_ratio: f64,
    /// The motion's peak speed over the capture's.
    pub peak_ratio: f64,
    /// The motion's time to peak, seconds.
    pub time_to_peak_s: f64,
    /// The capture's time to peak, seconds.
    pub capture_time_to_peak_s: f64,
    /// The motion's SPARC ([`sparc`], default settings).
    pub sparc: f64,
    /// The capture's SPARC.
    pub capture_sparc: f64,
    /// The motion's largest frame-to-frame speed change at the capture's frame time, m/s.
    pub largest_change: f64,
    /// The capture's largest frame-to-frame speed change, m/s.
    pub capture_largest_change: f64,
    /// Whether the motion has a jump: a change larger than the capture's largest by more than
    /// [`JUMP_SLACK`] of it.
    pub jumps: bool,
}

impl Fidelity {
    /// `model`'s figures against `capture`.
    pub fn of(model: Speeds<'_>, capture: Speeds<'_>) -> Fidelity {
        let settings = SparcSettings::default();
        let at_capture = resample(model.values, model.frame_time, capture.frame_time);
        let change = largest_change(&at_capture);
        let capture_change = largest_change(capture.values);
        Fidelity {
            error: realtime_error(model, capture),
            duration_ratio: movement_duration(model) / movement_duration(capture),
            peak_ratio: peak_speed(model) / peak_speed(capture),
            time_to_peak_s: time_to_peak(model),
            capture_time_to_peak_s: time_to_peak(capture),
            sparc: sparc(model, &settings),
            capture_sparc: sparc(capture, &settings),
            largest_change: change,
            capture_largest_change: capture_change,
            jumps: change > capture_change * (1.0 + JUMP_SLACK),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn s(values: &[f64], frame_time: f64) -> Speeds<'_> {
        Speeds { values, frame_time }
    }

    #[test]
    fn the_error_of_a_series_with_itself_is_zero_and_of_nothing_its_rms_over_its_peak() {
        let dt = 0.01;
        let bell: Vec<f64> = (0..=100)
            .map(|i| (std::f64::consts::PI * i as f64 / 100.0).sin())
            .collect();
        assert_eq!(realtime_error(s(&bell, dt), s(&bell, dt)), 0.0);
        let rms = (bell.iter().map(|v| v * v).sum::<f64>() / bell.len() as f64).sqrt();
        assert_relative_eq!(
            realtime_error(s(&[], dt), s(&bell, dt)),
            rms,
            epsilon = 1e-12
        );
        let double: Vec<f64> = bell.iter().map(|v| 2.0 * v).collect();
        assert_relative_eq!(
            realtime_error(s(&double, dt), s(&bell, dt)),
            rms,
            epsilon = 1e-12
        );
        // Half of it: the capture's tail counts against zeros.
        let half = &bell[..51];
        let tail = (bell[51..].iter().map(|v| v * v).sum::<f64>() / bell.len() as f64).sqrt();
        assert_relative_eq!(
            realtime_error(s(half, dt), s(&bell, dt)),
            tail,
            epsilon = 1e-12
        );
        assert!(realtime_error(s(&bell, dt), s(&[0.0; 5], dt)).is_nan());
    }

    #[test]
    fn minimum_jerk_covers_its_length_and_peaks_at_one_point_875_times_the_mean_speed() {
        let v = minimum_jerk(0.6, 0.8, 0.001);
        assert_relative_eq!(path_length(s(&v, 0.001)), 0.6, max_relative = 1e-4);
        assert_relative_eq!(
            peak_speed(s(&v, 0.001)),
            1.875 * 0.6 / 0.8,
            max_relative = 1e-9
        );
        assert_relative_eq!(time_to_peak(s(&v, 0.001)), 0.4, epsilon = 1e-9);
        assert_eq!(realtime_error(s(&v, 0.001), s(&v, 0.001)), 0.0);
        assert!(minimum_jerk(1.0, 0.0, 0.01).is_empty());
    }

    #[test]
    fn resampling_a_ramp_is_exact_and_an_integer_ratio_round_trips() {
        let ramp: Vec<f64> = (0..=40).map(|i| 0.5 * i as f64).collect();
        let fine = resample(&ramp, 0.1, 0.025);
        assert_eq!(fine.len(), 161);
        for (k, v) in fine.iter().enumerate() {
            assert_relative_eq!(*v, 0.125 * k as f64, epsilon = 1e-9);
        }
        let back = resample(&fine, 0.025, 0.1);
        assert_eq!(back.len(), ramp.len());
        for (a, b) in back.iter().zip(&ramp) {
            assert_relative_eq!(a, b, epsilon = 1e-9);
        }
    }

    #[test]
    fn sparc_is_dimensionless_and_lower_for_two_bells_and_for_noise() {
        let st = SparcSettings::default();
        let one = |t: f64, dt: f64| sparc(s(&minimum_jerk(0.5, t, dt), dt), &st);
        let reference = one(1.0, 1.0 / 60.0);
        // A single minimum-jerk bell: −1.42 (Balasubramanian et al. 2015 report about −1.4
        // for a single submovement).
        assert!((reference + 1.42).abs() < 0.03, "{reference}");
        assert_relative_eq!(one(1.0, 1.0 / 120.0), reference, max_relative = 0.02);
        assert_relative_eq!(one(0.5, 1.0 / 120.0), reference, max_relative = 0.02);
        assert_relative_eq!(one(1.5, 1.0 / 60.0), reference, max_relative = 0.02);
        let bell = minimum_jerk(0.5, 1.0, 1.0 / 60.0);
        let scaled: Vec<f64> = bell.iter().map(|v| 3.0 * v).collect();
        assert_relative_eq!(
            sparc(s(&scaled, 1.0 / 60.0), &st),
            reference,
            epsilon = 1e-9
        );
        let mut two = bell.clone();
        two.extend(&bell);
        assert!(sparc(s(&two, 1.0 / 60.0), &st) < reference - 0.3);
        // 5 Hz tremor (within SPARC's 10 Hz) of 5 % of the peak.
        let noisy: Vec<f64> = bell
            .iter()
            .enumerate()
            .map(|(i, v)| v + 0.05 * (i as f64 * 2.0 * std::f64::consts::PI * 5.0 / 60.0).sin())
            .collect();
        assert!(sparc(s(&noisy, 1.0 / 60.0), &st) < reference - 0.3);
    }

    #[test]
    fn the_log_dimensionless_jerk_of_minimum_jerk_is_its_closed_form() {
        // ∫₀¹ v''² dτ = 900 ∫₀¹ (2 − 12τ + 12τ²)² dτ = 900 · 0.8 = 720, v_peak = 1.875.
        let closed = -(720.0f64 / (1.875 * 1.875)).ln();
        let v = minimum_jerk(1.0, 1.0, 0.001);
        assert_relative_eq!(
            log_dimensionless_jerk(s(&v, 0.001)),
            closed,
            max_relative = 0.01
        );
        let mut two = v.clone();
        two.extend(&v);
        assert!(log_dimensionless_jerk(s(&two, 0.001)) < closed - 1.0);
    }

    #[test]
    fn the_mean_profile_of_repeats_is_the_repeat_and_lasts_their_mean_duration() {
        let dt = 0.01;
        let a = minimum_jerk(0.5, 1.0, dt);
        let same = mean_profile(&[s(&a, dt), s(&a, dt)], dt);
        assert_eq!(same.len(), a.len());
        for (x, y) in same.iter().zip(&a) {
            assert_relative_eq!(x, y, epsilon = 1e-9);
        }
        let b = minimum_jerk(1.0, 2.0, dt);
        let mixed = mean_profile(&[s(&a, dt), s(&b, dt)], dt);
        assert_relative_eq!(duration(s(&mixed, dt)), 1.5, epsilon = 1e-9);
        assert_relative_eq!(peak_speed(s(&mixed, dt)), 0.9375, max_relative = 1e-3);
        for e in leave_one_out(&[s(&a, dt), s(&a, dt), s(&a, dt)]) {
            assert_relative_eq!(e, 0.0, epsilon = 1e-9);
        }
        assert!(leave_one_out(&[s(&a, dt)])[0].is_nan());
    }

    #[test]
    fn a_copy_has_no_jump_and_a_one_frame_spike_is_one() {
        let dt = 1.0 / 30.0;
        let v = minimum_jerk(0.5, 1.0, dt);
        let f = Fidelity::of(s(&v, dt), s(&v, dt));
        assert_eq!(f.error, 0.0);
        assert_eq!((f.duration_ratio, f.peak_ratio), (1.0, 1.0));
        assert!(!f.jumps);
        // Held at the end for as long again: no longer a motion.
        let mut held = v.clone();
        held.extend([0.0; 30]);
        assert_eq!(Fidelity::of(s(&held, dt), s(&v, dt)).duration_ratio, 1.0);
        let mut spiked = v.clone();
        spiked[10] += 0.3;
        assert!(Fidelity::of(s(&spiked, dt), s(&v, dt)).jumps);
    }
}
