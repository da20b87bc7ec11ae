//! The paths and the speed segmentation reads (see the module docs, "The speed signal").

use crate::{ArmJoints, Clip, speed_series};
use nalgebra::{Point3, Vector3};

use super::types::SegmentSettings;
use crate::error::Result;

/// Everything segmentation reads from a clip, computed once.
#[derive(Debug, Clone)]
pub(super) struct Signal {
    /// The path the speed is measured on, despiked: hand − shoulder, or the world hand.
    pub path: Vec<Point3<f64>>,
    /// The hand in the world, despiked.
    pub world: Vec<Point3<f64>>,
    /// The shoulder in the world, despiked.
    pub shoulder: Vec<Point3<f64>>,
    /// The smoothed speed along `path`, m/s.
    pub speed: Vec<f64>,
    /// Shoulder → elbow → wrist → hand point, meters: the median over frames.
    pub arm_length: f64,
    /// Seconds per frame.
    pub frame_time: f64,
    /// Whether `path` is relative to the shoulder.
    pub relative: bool,
}

impl Signal {
    pub fn new(clip: &Clip, arm: &ArmJoints, settings: &SegmentSettings) -> Result<Signal> {
        let frame_time = clip.frame_time();
        let relative = settings.relative_to_shoulder;
        if clip.frame_count() == 0 {
            return Ok(Signal {
                path: Vec::new(),
                world: Vec::new(),
                shoulder: Vec::new(),
                speed: Vec::new(),
                arm_length: 0.0,
                frame_time,
                relative,
            });
        }
        let hand = arm.end_effector();
        let t = clip.trajectory(&[hand, arm.shoulder, arm.elbow, arm.wrist])?;
        let lengths: Vec<f64> = t
            .frames()
            .map(|f| (f[1] - f[2]).norm() + (f[2] - f[3]).norm() + (f[3] - f[0]).norm())
            .collect();
        let world = despike(&t.path(0));
        let shoulder = despike(&t.path(1));
        let path = if relative {
            despike(
                &t.frames()
                    .map(|f| Point3::from(f[0] - f[1]))
                    .collect::<Vec<_>>(),
            )
        } else {
            world.clone()
        };
        let speed = smoothed_speed(&path, frame_time, settings.smoothing);
        Ok(Signal {
            path,
            world,
            shoulder,
            speed,
            arm_length: median(lengths),
            frame_time,
            relative,
        })
    }

    /// The same clip read in the world: the path is the world hand's, and the speed along it.
    pub fn in_world(&self, settings: &SegmentSettings) -> Signal {
        Signal {
            path: self.world.clone(),
            speed: smoothed_speed(&self.world, self.frame_time, settings.smoothing),
            relative: false,
            ..self.clone()
        }
    }

    /// Frames in the clip.
    pub fn len(&self) -> usize {
        self.speed.len()
    }

    /// How high the hand hangs at rest from the standing body, in the world: the highest the
    /// shoulder gets in the clip, less the arm's length (module docs, step 5). A hand that
    /// ends a reach's length below it has been carried down to something — the floor, a
    /// low shelf — not back to rest.
    pub fn rest_height(&self) -> f64 {
        self.shoulder
            .iter()
            .map(|p| p.y)
            .fold(f64::NEG_INFINITY, f64::max)
            - self.arm_length
    }

    /// Where the hand hangs at rest on frame `i` (the arm straight down from the shoulder),
    /// in the frame of [`Signal::path`].
    pub fn hanging(&self, i: usize) -> Point3<f64> {
        let down = Vector3::new(0.0, -self.arm_length, 0.0);
        if self.relative {
            Point3::from(down)
        } else {
            self.shoulder[i] + down
        }
    }
}

/// How far a frame may stand off the median of itself and its neighbours before it may be a
/// spike, meters.
const SPIKE: f64 = 0.01;

/// One-frame spikes removed (module docs, "The speed signal", step 2).
pub(super) fn despike(path: &[Point3<f64>]) -> Vec<Point3<f64>> {
    let n = path.len();
    if n < 3 {
        return path.to_vec();
    }
    let p = path;
    let median3 = |a: f64, b: f64, c: f64| a.min(b).max(a.max(b).min(c));
    // How far frame i stands off the per-coordinate median of itself and its neighbours (at
    // an end, the missing neighbour is the linear extrapolation of the next two).
    let off_median = |i: usize| {
        let (a, c) = if i == 0 {
            (p[1] + (p[1] - p[2]), p[1])
        } else if i == n - 1 {
            (p[n - 2], p[n - 2] + (p[n - 2] - p[n - 3]))
        } else {
            (p[i - 1], p[i + 1])
        };
        let b = p[i];
        let m = Point3::new(
            median3(a.x, b.x, c.x),
            median3(a.y, b.y, c.y),
            median3(a.z, b.z, c.z),
        );
        (b - m).norm()
    };
    // How far an inner frame stands off the midpoint of its neighbours.
    let off_line = |i: usize| (p[i] - (p[i - 1] + (p[i + 1] - p[i - 1]) / 2.0)).norm();
    let spike = |i: usize| {
        if off_median(i) <= SPIKE {
            return false;
        }
        if i == 0 || i == n - 1 {
            // One-sided: a first step more than twice the next one, plus the tolerance.
            let (q, r, s) = if i == 0 {
                (p[0], p[1], p[2])
            } else {
                (p[n - 1], p[n - 2], p[n - 3])
            };
            return (q - r).norm() > 2.0 * (r - s).norm() + SPIKE;
        }
        // The frame turns back sharply (it leaves the chord of its neighbours by more than
        // half its length), and farther than either neighbour does (a jump moves their
        // midpoints half as far).
        let off = off_line(i);
        off > 0.5 * (p[i + 1] - p[i - 1]).norm()
            && (i < 2 || off >= off_line(i - 1))
            && (i + 2 > n - 1 || off >= off_line(i + 1))
    };
    (0..n)
        .map(|i| {
            if !spike(i) {
                p[i]
            } else if i == 0 {
                p[1] + (p[1] - p[2])
            } else if i == n - 1 {
                p[n - 2] + (p[n - 2] - p[n - 3])
            } else if i >= 2 && i + 2 < n {
                // The cubic through frames i ± 1 and i ± 2.
                Point3::from(
                    (4.0 * (p[i - 1].coords + p[i + 1].coords) - p[i - 2].coords - p[i + 2].coords)
                        / 6.0,
                )
            } else {
                p[i - 1] + (p[i + 1] - p[i - 1]) / 2.0
            }
        })
        .collect()
}

fn median(mut values: Vec<f64>) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    values.sort_by(f64::total_cmp);
    values[values.len() / 2]
}

/// A centred moving average over `width` frames (odd), cut at the ends.
pub(super) fn moving_average(values: &[f64], width: usize) -> Vec<f64> {
    let half = width / 2;
    let n = values.len();
    let mut prefix = Vec::with_capacity(n + 1);
    prefix.push(0.0);
    for v in values {
        prefix.push(prefix.last().copied().unwrap_or(0.0) + v);
    }
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(half), (i + half + 1).min(n));
            // Clamped at 0 so rounding in the prefix sums never gives a negative speed.
            ((prefix[b] - prefix[a]) / (b - a) as f64).max(0.0)
        })
        .collect()
}

/// Central-difference speed of `path`, then the moving average of about `smoothing` seconds.
pub(super) fn smoothed_speed(path: &[Point3<f64>], frame_time: f64, smoothing: f64) -> Vec<f64> {
    let raw = speed_series(path, frame_time);
    let frames = (smoothing / frame_time).round();
    // Odd width of about `smoothing` seconds; capped by the clip length (the cast saturates).
    let width = (frames as usize).min(raw.len()) | 1;
    if width <= 1 {
        raw
    } else {
        moving_average(&raw, width)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn moving_average_keeps_constants_and_cuts_the_ends() {
        assert_eq!(moving_average(&[2.0; 7], 5), vec![2.0; 7]);
        let m = moving_average(&[0.0, 3.0, 0.0, 0.0], 3);
        assert_eq!(m, vec![1.5, 1.0, 1.0, 0.0]);
    }

    fn line(n: usize) -> Vec<Point3<f64>> {
        (0..n)
            .map(|i| Point3::new(0.01 * i as f64, -0.02 * i as f64, 0.5))
            .collect()
    }

    fn assert_same(a: &[Point3<f64>], b: &[Point3<f64>]) {
        assert_eq!(a.len(), b.len());
        for (p, q) in a.iter().zip(b) {
            assert_relative_eq!(p, q, epsilon = 1e-12);
        }
    }

    #[test]
    fn despike_keeps_a_steady_motion_and_drops_one_frame_jumps() {
        let clean = line(10);
        assert_same(&despike(&clean), &clean);
        for at in [0, 4, 9] {
            let mut glitched = clean.clone();
            glitched[at] += Vector3::new(0.22, 0.0, -0.1);
            assert_same(&despike(&glitched), &clean);
        }
        // Too short to tell a jump from motion: unchanged.
        assert_eq!(despike(&clean[..2]), clean[..2].to_vec());
    }

    #[test]
    fn median_of_an_empty_series_is_zero() {
        assert_eq!(median(vec![]), 0.0);
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
    }
}
