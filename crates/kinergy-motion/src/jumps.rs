//! Speed jumps: frame-to-frame changes of a speed series that no smooth human motion makes.
//!
//! A **speed jump** is a frame-to-frame change of the hand speed larger than
//! [`JUMP_MIN`] (0.25 m/s) and larger than [`JUMP_RATIO`] (4) times the series' median
//! frame-to-frame change. A synthesized motion "has jumps" when it has more of them than its
//! capture over the same frames. The hand speed is the one [`crate::speed_series`] gives,
//! relative to the shoulder (`kinergy plot speed --relative`).
//!
//! ```
//! use kinergy_motion::jumps::speed_jumps;
//!
//! // A bell sampled at 60 Hz has none; a one-frame spike in it is one jump up, one down.
//! let bell: Vec<f64> = (0..60).map(|i| (std::f64::consts::PI * i as f64 / 59.0).sin()).collect();
//! assert!(speed_jumps(&bell).is_empty());
//! let mut spiked = bell.clone();
//! spiked[20] += 0.8;
//! assert_eq!(speed_jumps(&spiked).len(), 2);
//! ```

/// The smallest frame-to-frame change that can be a jump, m/s.
pub const JUMP_MIN: f64 = 0.25;

/// How many times the median frame-to-frame change a jump is at least.
pub const JUMP_RATIO: f64 = 4.0;

/// One speed jump: the speed went from `from` on frame `frame` to `to` on the next.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct SpeedJump {
    /// The frame before the jump (an index into the series).
    pub frame: usize,
    /// The speed on that frame, m/s.
    pub from: f64,
    /// The speed on the next, m/s.
    pub to: f64,
}

/// The speed jumps of `speeds` (one value per frame, m/s), in order. Non-finite values are
/// never jumps; fewer than two values have none.
pub fn speed_jumps(speeds: &[f64]) -> Vec<SpeedJump> {
    let changes: Vec<f64> = speeds
        .windows(2)
        .map(|w| (w[1] - w[0]).abs())
        .filter(|d| d.is_finite())
        .collect();
    if changes.is_empty() {
        return Vec::new();
    }
    let threshold = JUMP_MIN.max(JUMP_RATIO * median(&changes));
    speeds
        .windows(2)
        .enumerate()
        .filter(|(_, w)| (w[1] - w[0]).abs() > threshold)
        .map(|(frame, w)| SpeedJump {
            frame,
            from: w[0],
            to: w[1],
        })
        .collect()
}

/// The median of a non-empty slice of finite values (the mean of the middle two for an even
/// count).
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_step_is_one_jump_at_its_frame() {
        let mut v = vec![0.1; 30];
        v[15..].fill(0.9);
        let j = speed_jumps(&v);
        assert_eq!(j.len(), 1);
        assert_eq!(j[0].frame, 14);
        assert_eq!((j[0].from, j[0].to), (0.1, 0.9));
    }

    #[test]
    fn a_jittery_series_sets_its_own_bar() {
        // Changes of 0.3 every frame: the median is 0.3, so 0.3 is no jump, 1.5 is.
        let mut v: Vec<f64> = (0..40)
            .map(|i| if i % 2 == 0 { 1.0 } else { 1.3 })
            .collect();
        assert!(speed_jumps(&v).is_empty());
        v[20] = 2.8;
        assert_eq!(speed_jumps(&v).len(), 2);
    }

    #[test]
    fn small_changes_are_never_jumps() {
        let v = [0.0, 0.0, 0.0, 0.2, 0.0, 0.0];
        assert!(speed_jumps(&v).is_empty());
        assert!(speed_jumps(&[1.0]).is_empty());
        assert!(speed_jumps(&[]).is_empty());
    }
}
