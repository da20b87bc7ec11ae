//! Clips: a skeleton and its poses over time, and resampling to another frame rate.

use std::sync::Arc;

mod arrays;
mod positions;
mod positions_file;
mod state;
pub use arrays::{ClipArrays, RotationArrays};
pub use positions::{FromPositions, PositionArrays, Stretch};
pub use positions_file::{
    JointMap, PositionTable, TableReading, read_names, read_positions_csv, read_positions_npy,
};
pub use state::{ClipState, JointState};

use nalgebra::Point3;

use crate::error::{MotionError, Result};
use crate::rotation::{euler_angles, euler_rotation, nearest_euler, slerp, unwrap_near};
use crate::skeleton::{Dof, Skeleton};
use crate::trajectory::Trajectory;

/// A motion: a skeleton and one pose per frame at a fixed frame time.
#[derive(Debug, Clone, PartialEq)]
pub struct Clip {
    skeleton: Arc<Skeleton>,
    frame_time: f64,
    values: Vec<f64>,
}

impl Clip {
    /// A clip from flat pose values, frame after frame (`frames × dof_count` values).
    /// Checks that the frame time is finite and positive, the length fits the skeleton and
    /// every value is finite.
    pub fn new(skeleton: Arc<Skeleton>, frame_time: f64, values: Vec<f64>) -> Result<Clip> {
        if !(frame_time.is_finite() && frame_time > 0.0) {
            return Err(MotionError::Invalid {
                what: "frame time",
                why: format!(
                    "{} is not a positive number of seconds",
                    kinergy_io::Num(frame_time)
                ),
            });
        }
        let n = skeleton.dof_count();
        let ok = if n == 0 {
            values.is_empty()
        } else {
            values.len().is_multiple_of(n)
        };
        if !ok {
            return Err(MotionError::PoseLength {
                expected: n,
                found: values.len() % n.max(1),
            });
        }
        if let Some(i) = values.iter().position(|v| !v.is_finite()) {
            return Err(MotionError::NonFinite {
                what: format!(
                    "frame {} value {} ({})",
                    i / n.max(1),
                    i % n.max(1),
                    skeleton.dof_name(i % n.max(1)).unwrap_or_default()
                ),
            });
        }
        Ok(Clip {
            skeleton,
            frame_time,
            values,
        })
    }

    /// A clip from a list of poses.
    pub fn from_poses(
        skeleton: Arc<Skeleton>,
        frame_time: f64,
        poses: &[Vec<f64>],
    ) -> Result<Clip> {
        let n = skeleton.dof_count();
        if let Some(p) = poses.iter().find(|p| p.len() != n) {
            return Err(MotionError::PoseLength {
                expected: n,
                found: p.len(),
            });
        }
        Clip::new(skeleton, frame_time, poses.concat())
    }

    /// The skeleton.
    pub fn skeleton(&self) -> &Arc<Skeleton> {
        &self.skeleton
    }

    /// Seconds between frames.
    pub fn frame_time(&self) -> f64 {
        self.frame_time
    }

    /// Frames per second.
    pub fn frame_rate(&self) -> f64 {
        1.0 / self.frame_time
    }

    /// The number of frames.
    pub fn frame_count(&self) -> usize {
        let n = self.skeleton.dof_count();
        self.values.len().checked_div(n).unwrap_or(0)
    }

    /// Seconds from the first frame to the last: `(frames − 1) · frame_time`.
    pub fn duration(&self) -> f64 {
        self.frame_count().saturating_sub(1) as f64 * self.frame_time
    }

    /// The pose of frame `i`.
    pub fn frame(&self, i: usize) -> Option<&[f64]> {
        let n = self.skeleton.dof_count();
        self.values.get(i * n..(i + 1) * n)
    }

    /// Every joint's world position on every frame, frame after frame, meters, Y up.
    pub fn world_positions(&self) -> Result<Vec<Point3<f64>>> {
        let skeleton = self.skeleton();
        let mut out = Vec::with_capacity(self.frame_count() * skeleton.joint_count());
        for pose in self.frames() {
            out.extend(skeleton.world_positions(pose)?);
        }
        Ok(out)
    }

    /// Every frame's pose, in order.
    pub fn frames(&self) -> impl ExactSizeIterator<Item = &[f64]> + '_ {
        let n = self.skeleton.dof_count().max(1);
        self.values.chunks_exact(n)
    }

    /// All values, frame after frame.
    pub fn values(&self) -> &[f64] {
        &self.values
    }

    /// Frames `range` as a new clip.
    pub fn slice(&self, range: std::ops::Range<usize>) -> Result<Clip> {
        if range.start >= range.end || range.end > self.frame_count() {
            return Err(MotionError::Invalid {
                what: "frame range",
                why: format!(
                    "{}..{} is empty or past the clip's {} frames",
                    range.start,
                    range.end,
                    self.frame_count()
                ),
            });
        }
        let n = self.skeleton.dof_count();
        Ok(Clip {
            skeleton: self.skeleton.clone(),
            frame_time: self.frame_time,
            values: self.values[range.start * n..range.end * n].to_vec(),
        })
    }

    /// The world positions of `joints` in every frame.
    pub fn trajectory(&self, joints: &[usize]) -> Result<Trajectory> {
        if self.frame_count() == 0 {
            return Err(MotionError::EmptyClip);
        }
        if let Some(&j) = joints.iter().find(|&&j| j >= self.skeleton.joint_count()) {
            return Err(MotionError::Invalid {
                what: "joint index",
                why: format!("{j} is out of range"),
            });
        }
        let mut world = Vec::with_capacity(self.skeleton.joint_count());
        let mut points = Vec::with_capacity(self.frame_count() * joints.len());
        for pose in self.frames() {
            self.skeleton.fk_into(pose, &mut world)?;
            points.extend(
                joints
                    .iter()
                    .map(|&j| Point3::from(world[j].translation.vector)),
            );
        }
        Trajectory::new(self.frame_time, joints.len(), points)
    }

    /// The clip resampled at `frame_time`, over the same duration (the last new frame is the
    /// last one at or before the original end).
    ///
    /// Translations are interpolated linearly. A joint's three rotation channels about three
    /// distinct axes are turned into one rotation and interpolated by slerp, then decomposed
    /// back in the joint's own channel order, taking the angles nearest the linear
    /// interpolation (so no ±2π jumps appear). Joints with fewer rotation channels, or
    /// repeated axes, interpolate each angle linearly along the shorter arc.
    pub fn resample(&self, frame_time: f64) -> Result<Clip> {
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
        let count = (self.duration() / frame_time + 1e-9).floor() as usize + 1;
        let n = self.skeleton.dof_count();
        let mut values = Vec::with_capacity(count * n);
        let mut pose = vec![0.0; n];
        for k in 0..count {
            let x = k as f64 * frame_time / self.frame_time;
            let i0 = (x.floor() as usize).min(frames - 1);
            let i1 = (i0 + 1).min(frames - 1);
            let u = (x - i0 as f64).clamp(0.0, 1.0);
            let (a, b) = (
                self.frame(i0).unwrap_or_default(),
                self.frame(i1).unwrap_or_default(),
            );
            self.interpolate(a, b, u, &mut pose);
            values.extend_from_slice(&pose);
        }
        Clip::new(self.skeleton.clone(), frame_time, values)
    }

    fn interpolate(&self, a: &[f64], b: &[f64], u: f64, out: &mut [f64]) {
        for (j, joint) in self.skeleton.joints().iter().enumerate() {
            let range = self.skeleton.dof_range(j);
            for (k, d) in joint.dofs.iter().enumerate() {
                let i = range.start + k;
                out[i] = match d {
                    Dof::Translation(_) => a[i] + (b[i] - a[i]) * u,
                    Dof::Rotation(_) => a[i] + (unwrap_near(b[i], a[i]) - a[i]) * u,
                };
            }
            if let Some(([i0, i1, i2], order)) = self.skeleton.euler_dofs(j) {
                let ra = euler_rotation(&order, &[a[i0], a[i1], a[i2]]);
                let rb = euler_rotation(&order, &[b[i0], b[i1], b[i2]]);
                let r = slerp(&ra, &rb, u);
                let near = [out[i0], out[i1], out[i2]];
                if let Some(angles) = euler_angles(order, &r) {
                    let chosen = nearest_euler(angles, near);
                    out[i0] = chosen[0];
                    out[i1] = chosen[1];
                    out[i2] = chosen[2];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::tests::test_skeleton;
    use approx::assert_relative_eq;

    fn ramp_clip(frames: usize, frame_time: f64) -> Clip {
        let s = Arc::new(test_skeleton());
        let n = s.dof_count();
        let poses: Vec<Vec<f64>> = (0..frames)
            .map(|f| {
                (0..n)
                    .map(|d| 0.01 * f as f64 * ((d % 5) as f64 - 2.0))
                    .collect()
            })
            .collect();
        Clip::from_poses(s, frame_time, &poses).expect("clip")
    }

    #[test]
    fn resampling_at_the_same_rate_is_the_identity() {
        let c = ramp_clip(20, 1.0 / 30.0);
        let r = c.resample(1.0 / 30.0).expect("resample");
        assert_eq!(r.frame_count(), 20);
        for (x, y) in c.values().iter().zip(r.values()) {
            assert_relative_eq!(x, y, epsilon = 1e-12);
        }
    }

    #[test]
    fn upsampling_passes_through_original_frames_and_keeps_duration() {
        let c = ramp_clip(31, 1.0 / 30.0);
        let r = c.resample(1.0 / 120.0).expect("resample");
        assert_eq!(r.frame_count(), 121);
        assert_relative_eq!(r.duration(), c.duration(), epsilon = 1e-12);
        let pc = c.trajectory(&[7]).expect("traj");
        let pr = r.trajectory(&[7]).expect("traj");
        for f in 0..31 {
            assert_relative_eq!(pc.frame(f)[0], pr.frame(4 * f)[0], epsilon = 1e-9);
        }
    }

    #[test]
    fn slerp_midpoint_is_the_halfway_rotation() {
        // One joint swings from 0 to 60° about X while the Euler order is Z X Y:
        // the midpoint must be exactly 30° about X whatever the order.
        let c = ramp_clip(2, 1.0);
        let s = c.skeleton().clone();
        let n = s.dof_count();
        let mut a = vec![0.0; n];
        let mut b = vec![0.0; n];
        let hand = s.dof_range(5);
        a[hand.start + 1] = 0.0;
        b[hand.start + 1] = 60f64.to_radians();
        let c = Clip::from_poses(s.clone(), 1.0, &[a, b]).expect("clip");
        let r = c.resample(0.5).expect("resample");
        let mid = r.frame(1).expect("frame");
        assert_relative_eq!(mid[hand.start], 0.0, epsilon = 1e-12);
        assert_relative_eq!(mid[hand.start + 1], 30f64.to_radians(), epsilon = 1e-12);
        assert_relative_eq!(mid[hand.start + 2], 0.0, epsilon = 1e-12);
    }

    #[test]
    fn resampling_rejects_bad_frame_times() {
        let c = ramp_clip(5, 0.1);
        assert!(c.resample(0.0).is_err());
        assert!(c.resample(f64::NAN).is_err());
    }

    #[test]
    fn clips_reject_non_finite_values() {
        let s = Arc::new(test_skeleton());
        let mut v = vec![0.0; s.dof_count() * 2];
        v[30] = f64::NAN;
        let e = Clip::new(s, 0.1, v).expect_err("NaN");
        assert!(e.to_string().contains("frame 1"), "{e}");
    }
}
