//! World-space trajectories of a few joints, the motion distance of Aubry et al. (2009),
//! and speed series.

use nalgebra::Point3;

use crate::error::{MotionError, Result};

/// The world positions of the same `joints` (e.g. shoulder, elbow, wrist, hand) in every
/// frame of a motion, at a fixed frame time.
#[derive(Debug, Clone, PartialEq)]
pub struct Trajectory {
    frame_time: f64,
    joints: usize,
    points: Vec<Point3<f64>>,
}

impl Trajectory {
    /// A trajectory of `joints` points per frame, frame after frame.
    pub fn new(frame_time: f64, joints: usize, points: Vec<Point3<f64>>) -> Result<Trajectory> {
        if !(frame_time.is_finite() && frame_time > 0.0) {
            return Err(MotionError::Invalid {
                what: "frame time",
                why: format!(
                    "{} is not a positive number of seconds",
                    kinergy_io::Num(frame_time)
                ),
            });
        }
        if joints == 0 || !points.len().is_multiple_of(joints) {
            return Err(MotionError::Invalid {
                what: "trajectory",
                why: format!(
                    "{} points do not make frames of {joints} joints",
                    points.len()
                ),
            });
        }
        if let Some(i) = points
            .iter()
            .position(|p| !p.coords.iter().all(|v| v.is_finite()))
        {
            return Err(MotionError::NonFinite {
                what: format!("trajectory point {} of frame {}", i % joints, i / joints),
            });
        }
        Ok(Trajectory {
            frame_time,
            joints,
            points,
        })
    }

    /// Seconds between frames.
    pub fn frame_time(&self) -> f64 {
        self.frame_time
    }

    /// Points per frame.
    pub fn joint_count(&self) -> usize {
        self.joints
    }

    /// Number of frames.
    pub fn frame_count(&self) -> usize {
        self.points.len() / self.joints
    }

    /// The points of frame `i`. Panics past the end.
    pub fn frame(&self, i: usize) -> &[Point3<f64>] {
        &self.points[i * self.joints..(i + 1) * self.joints]
    }

    /// Every frame's points.
    pub fn frames(&self) -> impl ExactSizeIterator<Item = &[Point3<f64>]> + '_ {
        self.points.chunks_exact(self.joints)
    }

    /// The path of point `joint` over the frames.
    pub fn path(&self, joint: usize) -> Vec<Point3<f64>> {
        self.frames().map(|f| f[joint]).collect()
    }

    /// The trajectory at another frame time, by linear interpolation of positions, over the
    /// same duration (the last frame is the last sample at or before the original end).
    pub fn resample(&self, frame_time: f64) -> Result<Trajectory> {
        if !(frame_time.is_finite() && frame_time > 0.0) {
            return Err(MotionError::Invalid {
                what: "frame time",
                why: format!(
                    "{} is not a positive number of seconds",
                    kinergy_io::Num(frame_time)
                ),
            });
        }
        let frames = self.frame_count();
        if frames == 0 {
            return Err(MotionError::EmptyClip);
        }
        let duration = (frames - 1) as f64 * self.frame_time;
        let count = (duration / frame_time + 1e-9).floor() as usize + 1;
        let mut points = Vec::with_capacity(count * self.joints);
        for k in 0..count {
            let x = k as f64 * frame_time / self.frame_time;
            let i0 = (x.floor() as usize).min(frames - 1);
            let i1 = (i0 + 1).min(frames - 1);
            let u = (x - i0 as f64).clamp(0.0, 1.0);
            let (a, b) = (self.frame(i0), self.frame(i1));
            points.extend(a.iter().zip(b).map(|(p, q)| p + (q - p) * u));
        }
        Trajectory::new(frame_time, self.joints, points)
    }

    /// Speed of point `joint` (m/s) in every frame: central differences inside, one-sided at
    /// the two ends. A single frame has speed 0.
    pub fn speed(&self, joint: usize) -> Vec<f64> {
        speed_series(&self.path(joint), self.frame_time)
    }
}

/// The speed (units/s) along a sampled path: |p_{i+1} − p_{i−1}| / 2Δt inside, one-sided
/// differences at the two ends.
pub fn speed_series(path: &[Point3<f64>], frame_time: f64) -> Vec<f64> {
    let n = path.len();
    if n < 2 {
        return vec![0.0; n];
    }
    (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
            (path[b] - path[a]).norm() / ((b - a) as f64 * frame_time)
        })
        .collect()
}

/// The motion distance of Aubry, Julliard & Gibet (2009), §3.3: the mean over frames
/// i < min(len A, len B) of
///
/// dist(P_A,i, P_B,i) = Σ_j |X_A,j − X_B,j| / (l + 1) + |X_A,e − X_B,e| / (l + 1),
///
/// over the l joints of the chain and the end effector, here every point of the
/// trajectories (the end effector being one of them), so the per-frame term is the mean
/// Euclidean distance between corresponding points. When the frame times differ, `b` is
/// resampled at `a`'s frame time first. Symmetric up to that resampling; 0 for identical
/// motions; exactly |δ| when one motion is the other shifted by a constant vector δ.
pub fn motion_distance(a: &Trajectory, b: &Trajectory) -> Result<f64> {
    if a.joint_count() != b.joint_count() {
        return Err(MotionError::JointCountMismatch {
            left: a.joint_count(),
            right: b.joint_count(),
        });
    }
    let resampled;
    let b = if (a.frame_time() - b.frame_time()).abs() > 1e-9 * a.frame_time() {
        resampled = b.resample(a.frame_time())?;
        &resampled
    } else {
        b
    };
    let frames = a.frame_count().min(b.frame_count());
    if frames == 0 {
        return Err(MotionError::EmptyClip);
    }
    let per_frame = a
        .frames()
        .zip(b.frames())
        .map(|(pa, pb)| frame_distance(pa, pb));
    Ok(per_frame.sum::<f64>() / frames as f64)
}

/// One frame's term of [`motion_distance`]: the mean Euclidean distance between
/// corresponding points of `a` and `b` (pairs up to the shorter's length, divided by `a`'s
/// length). Never negative, so a partial sum of frames' terms never exceeds the whole.
pub fn frame_distance(a: &[Point3<f64>], b: &[Point3<f64>]) -> f64 {
    a.iter().zip(b).map(|(x, y)| (x - y).norm()).sum::<f64>() / a.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use nalgebra::Vector3;
    use proptest::prelude::*;

    fn arbitrary_trajectory(frames: usize, seed: u64) -> Trajectory {
        let mut x = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
        let mut next = move || {
            x = x
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let pts = (0..frames * 4)
            .map(|_| Point3::new(next(), next(), next()))
            .collect();
        Trajectory::new(1.0 / 30.0, 4, pts).expect("valid")
    }

    #[test]
    fn identical_motions_are_at_distance_zero() {
        let a = arbitrary_trajectory(40, 1);
        assert_eq!(motion_distance(&a, &a).expect("distance"), 0.0);
    }

    #[test]
    fn mismatched_joint_counts_are_an_error() {
        let a = arbitrary_trajectory(5, 1);
        let b = Trajectory::new(1.0 / 30.0, 2, vec![Point3::origin(); 10]).expect("valid");
        assert!(matches!(
            motion_distance(&a, &b),
            Err(MotionError::JointCountMismatch { left: 4, right: 2 })
        ));
    }

    #[test]
    fn rates_are_matched_before_comparing() {
        // A straight-line motion sampled at 30 and 120 Hz is the same motion.
        let line = |dt: f64, n: usize| {
            let pts = (0..n)
                .flat_map(|i| {
                    let t = i as f64 * dt;
                    [Point3::new(t, 0.0, 0.0), Point3::new(0.0, 2.0 * t, 1.0)]
                })
                .collect();
            Trajectory::new(dt, 2, pts).expect("valid")
        };
        let d = motion_distance(&line(1.0 / 30.0, 31), &line(1.0 / 120.0, 121)).expect("d");
        assert_relative_eq!(d, 0.0, epsilon = 1e-12);
    }

    #[test]
    fn speed_of_uniform_motion_is_constant() {
        let pts: Vec<_> = (0..10)
            .map(|i| Point3::new(0.3 * i as f64, 0.0, 0.4 * i as f64))
            .collect();
        for v in speed_series(&pts, 0.5) {
            assert_relative_eq!(v, 1.0, epsilon = 1e-12);
        }
        assert_eq!(speed_series(&pts[..1], 0.5), vec![0.0]);
    }

    proptest! {
        #[test]
        fn constant_shift_gives_its_length(
            seed in any::<u64>(), frames in 1usize..50,
            dx in -2.0f64..2.0, dy in -2.0f64..2.0, dz in -2.0f64..2.0,
        ) {
            let a = arbitrary_trajectory(frames, seed);
            let delta = Vector3::new(dx, dy, dz);
            let b = Trajectory::new(
                a.frame_time(), 4, a.frames().flatten().map(|p| p + delta).collect(),
            ).expect("valid");
            assert_relative_eq!(motion_distance(&a, &b).expect("d"), delta.norm(), epsilon = 1e-12);
        }

        #[test]
        fn symmetric_and_up_to_the_shorter(seed in any::<u64>(), la in 1usize..40, lb in 1usize..40) {
            let a = arbitrary_trajectory(la, seed);
            let b = arbitrary_trajectory(lb, seed ^ 0x9e37);
            let ab = motion_distance(&a, &b).expect("d");
            let ba = motion_distance(&b, &a).expect("d");
            assert_relative_eq!(ab, ba, epsilon = 1e-12);
            // Only the first min(la, lb) frames count: appending frames to the longer
            // motion changes nothing.
            let n = la.min(lb);
            let a_short = Trajectory::new(a.frame_time(), 4, a.frames().take(n).flatten().copied().collect()).expect("valid");
            let b_short = Trajectory::new(b.frame_time(), 4, b.frames().take(n).flatten().copied().collect()).expect("valid");
            assert_relative_eq!(motion_distance(&a_short, &b_short).expect("d"), ab, epsilon = 1e-12);
        }
    }
}
