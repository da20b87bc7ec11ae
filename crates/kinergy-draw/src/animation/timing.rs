//! The instants drawn: which frame a clip shows at a time, how many GIF frames a motion
//! takes, when the strip's snapshots are.

/// The frame nearest to `t` seconds in a clip of `count` frames, clamped to the clip.
pub fn nearest_frame(t: f64, frame_time: f64, count: usize) -> usize {
    let i = (t / frame_time).round();
    if i > 0.0 {
        // `as` saturates: a time past the end clamps to the last frame.
        (i as usize).min(count.saturating_sub(1))
    } else {
        0
    }
}

/// GIF frames for `duration` seconds at `fps`: floor(duration · fps) + 1, the last instant
/// included even when rounding puts it a hair short.
pub fn gif_frame_count(duration: f64, fps: u32) -> usize {
    let ticks = duration * f64::from(fps) + 1e-9;
    if ticks.is_finite() && ticks > 0.0 {
        ticks.floor() as usize + 1
    } else {
        1
    }
}

/// `n` instants evenly spaced from 0 to `duration`, both included (0 alone when `n` is 1).
pub fn strip_times(duration: f64, n: usize) -> Vec<f64> {
    if n <= 1 {
        return vec![0.0];
    }
    (0..n)
        .map(|j| duration * j as f64 / (n - 1) as f64)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_count_includes_the_last_instant_despite_rounding() {
        // 108 frames at 60 Hz: 1.7999999999999998 s.
        assert_eq!(gif_frame_count(108.0 * (1.0 / 60.0), 10), 19);
        assert_eq!(gif_frame_count(1.27, 25), 32);
        assert_eq!(gif_frame_count(0.0, 25), 1);
    }

    #[test]
    fn poses_are_the_nearest_frame_held_after_the_end() {
        assert_eq!(nearest_frame(0.0, 0.1, 5), 0);
        assert_eq!(nearest_frame(0.26, 0.1, 5), 3);
        assert_eq!(nearest_frame(9.0, 0.1, 5), 4);
        assert_eq!(nearest_frame(f64::INFINITY, 0.1, 5), 4);
    }

    #[test]
    fn strip_times_span_the_whole_motion() {
        assert_eq!(strip_times(2.0, 5), vec![0.0, 0.5, 1.0, 1.5, 2.0]);
        assert_eq!(strip_times(2.0, 1), vec![0.0]);
    }
}
