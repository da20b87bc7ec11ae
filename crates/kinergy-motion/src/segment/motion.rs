//! Motions between rests and the sub-movements inside them (module docs, steps 1 and 2).

use super::types::SegmentSettings;

/// Frames `onset..=end` between two rests (or the clip's ends).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Motion {
    pub onset: usize,
    pub peak: usize,
    /// Inclusive.
    pub end: usize,
    /// The rest threshold r of this motion, m/s.
    pub rest: f64,
    /// The hand is already moving (s ≥ r) on the clip's first frame.
    pub cut_start: bool,
    /// The hand is still moving (s ≥ r) on the clip's last frame.
    pub cut_end: bool,
}

/// One sub-movement: frames `onset..=end` of one motion, split at deep speed minima. Two
/// neighbouring sub-movements of one motion share the minimum's frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Stroke {
    pub onset: usize,
    /// Inclusive.
    pub end: usize,
    pub peak: usize,
    /// Index of its motion.
    pub motion: usize,
}

/// The motions of a speed series (module docs, step 1), in time order.
pub(super) fn motions(speed: &[f64], frame_time: f64, settings: &SegmentSettings) -> Vec<Motion> {
    let n = speed.len();
    // Candidates fastest first (earlier first among equals): each is the fastest free frame
    // when its turn comes, so one pass replaces a search per motion.
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| speed[b].total_cmp(&speed[a]).then(a.cmp(&b)));
    let mut taken = vec![false; n];
    let mut out = Vec::new();
    for peak in order {
        let peak_speed = speed[peak];
        if peak_speed < settings.min_peak_speed {
            break;
        }
        if taken[peak] {
            continue;
        }
        // A faster neighbour is taken: this frame is the tail of that motion, slowing below
        // its rest threshold, not a new peak.
        let faster = |j: Option<usize>| j.is_some_and(|j| j < n && speed[j] > peak_speed);
        if faster(peak.checked_sub(1)) || faster(Some(peak + 1)) {
            taken[peak] = true;
            continue;
        }
        let rest = (settings.rest_fraction * peak_speed).max(settings.rest_speed);
        let mut onset = peak;
        while onset > 0 && speed[onset] >= rest && !taken[onset - 1] {
            onset -= 1;
        }
        let mut end = peak;
        while end + 1 < n && speed[end] >= rest && !taken[end + 1] {
            end += 1;
        }
        // Below r the hand may still be slowing down (a long deceleration tail): follow the
        // speed down to its minimum or to the absolute floor.
        while end + 1 < n
            && !taken[end + 1]
            && speed[end + 1] < speed[end]
            && speed[end] >= settings.rest_speed
        {
            end += 1;
        }
        while onset > 0
            && !taken[onset - 1]
            && speed[onset - 1] < speed[onset]
            && speed[onset] >= settings.rest_speed
        {
            onset -= 1;
        }
        taken[onset..=end].iter_mut().for_each(|t| *t = true);
        if (end - onset) as f64 * frame_time >= settings.min_duration {
            out.push(Motion {
                onset,
                peak,
                end,
                rest,
                cut_start: onset == 0 && speed[0] >= rest,
                cut_end: end == n - 1 && speed[n - 1] >= rest,
            });
        }
    }
    out.sort_by_key(|m| m.onset);
    out
}

/// Every motion split into sub-movements (module docs, step 2), in time order.
pub(super) fn strokes(
    speed: &[f64],
    motions: &[Motion],
    settings: &SegmentSettings,
) -> Vec<Stroke> {
    let mut out = Vec::new();
    for (i, m) in motions.iter().enumerate() {
        let mut pieces = Vec::new();
        split(speed, m.onset, m.end, settings, &mut pieces);
        pieces.sort_unstable();
        out.extend(pieces.into_iter().map(|(onset, end)| Stroke {
            onset,
            end,
            peak: argmax(speed, onset, end),
            motion: i,
        }));
    }
    out
}

fn argmax(speed: &[f64], a: usize, b: usize) -> usize {
    (a..=b).fold(a, |best, i| if speed[i] > speed[best] { i } else { best })
}

/// Splits `a..=b` at its deepest speed minimum while one is at most `split_ratio` of the
/// slower of the two peaks beside it (each at least `min_peak_speed`).
fn split(
    speed: &[f64],
    a: usize,
    b: usize,
    settings: &SegmentSettings,
    out: &mut Vec<(usize, usize)>,
) {
    let mut stack = vec![(a, b)];
    while let Some((a, b)) = stack.pop() {
        if b < a + 2 {
            out.push((a, b));
            continue;
        }
        // Highest speed in a..=m and in m..=b, for every m.
        let mut left = vec![0.0; b - a + 1];
        let mut right = vec![0.0; b - a + 1];
        let mut running = 0.0_f64;
        for i in a..=b {
            running = running.max(speed[i]);
            left[i - a] = running;
        }
        running = 0.0;
        for i in (a..=b).rev() {
            running = running.max(speed[i]);
            right[i - a] = running;
        }
        let mut best: Option<(f64, usize)> = None;
        for m in a + 1..b {
            if speed[m] > speed[m - 1] || speed[m] > speed[m + 1] {
                continue;
            }
            let flank = left[m - a].min(right[m - a]);
            if flank < settings.min_peak_speed {
                continue;
            }
            let ratio = speed[m] / flank;
            if best.is_none_or(|(r, _)| ratio < r) {
                best = Some((ratio, m));
            }
        }
        match best {
            Some((ratio, m)) if ratio <= settings.split_ratio => {
                stack.push((a, m));
                stack.push((m, b));
            }
            _ => out.push((a, b)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn settings() -> SegmentSettings {
        SegmentSettings::default()
    }

    fn hump(peak: f64, frames: usize) -> impl Iterator<Item = f64> {
        (1..frames).map(move |i| peak * (std::f64::consts::PI * i as f64 / frames as f64).sin())
    }

    #[test]
    fn degenerate_series_give_no_motion() {
        for speed in [vec![], vec![5.0], vec![0.0; 10], vec![1.0; 3]] {
            // A constant fast series is one motion only when it lasts min_duration.
            let m = motions(&speed, 0.01, &settings());
            assert!(m.len() <= 1, "{speed:?}: {m:?}");
        }
        let long = motions(&[1.0; 100], 0.01, &settings());
        assert_eq!(
            long,
            [Motion {
                onset: 0,
                peak: 0,
                end: 99,
                rest: 0.1,
                cut_start: true,
                cut_end: true,
            }]
        );
    }

    #[test]
    fn neighbouring_motions_do_not_share_a_frame() {
        // Two humps separated by a single rest frame, which only the bigger one (taken
        // first) may hold; the smaller one's tail stays above its own rest threshold.
        let speed: Vec<f64> = hump(1.0, 29).chain([0.0]).chain(hump(2.0, 29)).collect();
        let m = motions(&speed, 0.01, &settings());
        assert_eq!(m.len(), 2, "{m:?}");
        assert_eq!((m[0].end, m[1].onset), (27, 28), "{m:?}");
        assert_relative_eq!(speed[m[1].peak], speed.iter().copied().fold(0.0, f64::max));
    }

    #[test]
    fn a_slow_drift_after_a_fast_reach_is_its_tail() {
        // A hump peaking at 3 m/s (rest below 0.3 m/s), then 0.3 s of drift slowing from
        // 0.29 to 0.2 m/s: above min_peak_speed but only ever slowing, so no new motion; the
        // hand is still slowing down, so the motion ends where the drift does.
        let hump = (0..=30).map(|i| 3.0 * (std::f64::consts::PI * i as f64 / 30.0).sin());
        let drift = (0..30).map(|i| 0.29 - 0.003 * i as f64);
        let speed: Vec<f64> = hump.take(29).chain(drift).chain([0.0; 10]).collect();
        let m = motions(&speed, 0.01, &settings());
        assert_eq!(m.len(), 1, "{m:?}");
        assert_eq!((m[0].peak, m[0].end), (15, 59), "{m:?}");
    }

    #[test]
    fn a_deep_minimum_splits_a_shallow_one_does_not() {
        // Two humps peaking at 1 m/s (frames 10 and 30) over a minimum of `dip` at frame 20.
        let split_at = |dip: f64| {
            let humps = (1..40)
                .map(|i| dip + (1.0 - dip) * (std::f64::consts::PI * i as f64 / 20.0).sin().abs());
            let speed: Vec<f64> = [0.0].into_iter().chain(humps).chain([0.0]).collect();
            let m = motions(&speed, 0.01, &settings());
            assert_eq!(m.len(), 1, "{m:?}");
            strokes(&speed, &m, &settings())
        };
        let deep = split_at(0.3);
        assert_eq!(deep.len(), 2, "{deep:?}");
        assert_eq!((deep[0].end, deep[1].onset), (20, 20));
        let shallow = split_at(0.8);
        assert_eq!(shallow.len(), 1, "{shallow:?}");
    }
}
