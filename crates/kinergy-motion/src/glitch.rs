//! One-frame glitches: a joint that teleports for a single frame and comes back, common in
//! real captures (a marker swapped or lost for a frame).
//!
//! # Definition
//! For a point's path p_0 … p_{n−1} and an inner frame i (0 < i < n − 1), the **detour** is
//! how far p_i lies from the midpoint of its neighbours and the **chord** how far the
//! neighbours are apart:
//!
//! e_i = |p_i − (p_{i−1} + p_{i+1}) / 2|,  s_i = |p_{i+1} − p_{i−1}|.
//!
//! Frame i is a glitch when e_i ≥ [`GlitchOptions::min_size`] **and** e_i ≥
//! [`GlitchOptions::min_ratio`] · s_i: the point goes somewhere and comes back while its
//! neighbours stay close together. Smooth motion has a detour of |a| Δt² / 2 (a the
//! acceleration): at 30 fps even 30 m/s² — a fast hand turning back — gives 1.7 cm, below
//! the 5 cm default, and a point that turns a corner fast has a long chord. A one-frame jump
//! of size g has e = g and, once g is larger than the chord, is found however fast the point
//! moves otherwise. The first and last frames have one neighbour and are never glitches;
//! nor is a jump that lasts two frames or more (e = g/2 ≤ s/2 there). Frames are tested in
//! order, each against its predecessor as repaired (replaced by its neighbours' midpoint when
//! it glitched), so a glitch does not make the next frame look like one.
//!
//! The defaults leave a wide margin on the shared real captures (Bandai Namco, CMU,
//! Character Creator, Mixamo, a Z-up file): apart from one real glitch (a Character Creator
//! thumb flipping for one frame, 5.5–12.6 cm), no sample with a detour of 5 cm or more
//! reaches a ratio above 0.67 (a hand swung at 10 m/s; a clip starting from a rest pose
//! gives 0.5), and none with a ratio of 1 or more has a detour above 1.8 cm.
//!
//! In a clip ([`find_glitches`]) every joint's world path is examined; a joint whose ancestor
//! glitches in the same frame moves with it (a root or shoulder glitch drags its subtree) and
//! is counted in the ancestor's [`Glitch::joints`] rather than reported alone.

use nalgebra::Point3;

use crate::clip::Clip;
use crate::error::{MotionError, Result};
use crate::trajectory::{Trajectory, speed_series};

/// Thresholds of the glitch test (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GlitchOptions {
    /// The smallest detour that counts, meters.
    pub min_size: f64,
    /// The smallest detour-to-chord ratio that counts.
    pub min_ratio: f64,
}

impl Default for GlitchOptions {
    /// 5 cm, and a detour at least as long as the chord.
    fn default() -> Self {
        GlitchOptions {
            min_size: 0.05,
            min_ratio: 1.0,
        }
    }
}

impl GlitchOptions {
    /// Options with these thresholds, checked: both finite, the size positive, the ratio
    /// not negative.
    pub fn new(min_size: f64, min_ratio: f64) -> Result<GlitchOptions> {
        if !(min_size.is_finite() && min_size > 0.0) {
            return Err(MotionError::Invalid {
                what: "glitch size",
                why: format!("{min_size} is not a positive length"),
            });
        }
        if !(min_ratio.is_finite() && min_ratio >= 0.0) {
            return Err(MotionError::Invalid {
                what: "glitch ratio",
                why: format!("{min_ratio} is not a non-negative number"),
            });
        }
        Ok(GlitchOptions {
            min_size,
            min_ratio,
        })
    }
}

/// A one-frame glitch of a joint.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Glitch {
    /// The frame (0-based) where the joint is off its path.
    pub frame: usize,
    /// The joint (the highest one of its subtree glitching in this frame).
    pub joint: usize,
    /// The joint's detour e (meters): how far it is from the midpoint of its neighbours.
    pub size: f64,
    /// How many joints of its subtree (itself included) glitch in this frame.
    pub joints: usize,
    /// The largest detour among them (meters): a flipped thumb root moves the thumb's tip
    /// further than its first joint.
    pub largest: f64,
}

/// Scans `path` frame by frame, each frame tested against the previous one as repaired:
/// the glitches as `(frame, detour)`, and the path with each glitched sample replaced by the
/// midpoint of its neighbours.
fn scan(path: &[Point3<f64>], options: &GlitchOptions) -> (Vec<(usize, f64)>, Vec<Point3<f64>>) {
    let mut repaired = path.to_vec();
    let mut found = Vec::new();
    for i in 1..path.len().saturating_sub(1) {
        let (a, p, b) = (repaired[i - 1], path[i], path[i + 1]);
        let mid = Point3::from((a.coords + b.coords) * 0.5);
        let (e, s) = ((p - mid).norm(), (b - a).norm());
        if e >= options.min_size && e >= options.min_ratio * s {
            found.push((i, e));
            repaired[i] = mid;
        }
    }
    (found, repaired)
}

/// The one-frame glitches of a path: `(frame, detour)` for every inner frame that passes the
/// test of the [module docs](self). Frames are tested in order, each against its predecessor
/// as repaired ([`without_glitches`]), so a glitch does not make its successor look like one.
pub fn path_glitches(path: &[Point3<f64>], options: &GlitchOptions) -> Vec<(usize, f64)> {
    scan(path, options).0
}

/// The path with every glitched sample ([`path_glitches`]) replaced by the midpoint of its
/// neighbours.
pub fn without_glitches(path: &[Point3<f64>], options: &GlitchOptions) -> Vec<Point3<f64>> {
    scan(path, options).1
}

/// [`speed_series`] of the path with its one-frame glitches interpolated away
/// ([`without_glitches`]), so a teleporting sample does not make two spikes of speed.
pub fn speed_series_without_glitches(
    path: &[Point3<f64>],
    frame_time: f64,
    options: &GlitchOptions,
) -> Vec<f64> {
    speed_series(&without_glitches(path, options), frame_time)
}

// Here rather than in trajectory.rs, which the glitch finder itself builds on: the method
// belongs to the glitch filter, and keeping it here leaves no import loop between the two.
impl Trajectory {
    /// [`Trajectory::speed`] with the point's one-frame glitches interpolated away
    /// ([`speed_series_without_glitches`]).
    pub fn speed_without_glitches(&self, joint: usize, options: &GlitchOptions) -> Vec<f64> {
        speed_series_without_glitches(&self.path(joint), self.frame_time(), options)
    }
}

/// Every one-frame glitch of the clip's joints, by frame then joint (see the
/// [module docs](self)).
pub fn find_glitches(clip: &Clip, options: &GlitchOptions) -> Result<Vec<Glitch>> {
    let s = clip.skeleton();
    let n = s.joint_count();
    if clip.frame_count() < 3 {
        return Ok(Vec::new());
    }
    let all: Vec<usize> = (0..n).collect();
    let trajectory = clip.trajectory(&all)?;
    // glitched[f][j]: the detour of joint j at frame f, if it glitches.
    let mut glitched = vec![vec![None; n]; clip.frame_count()];
    for &j in &all {
        for (f, e) in path_glitches(&trajectory.path(j), options) {
            glitched[f][j] = Some(e);
        }
    }
    let mut out = Vec::new();
    for (frame, row) in glitched.iter().enumerate() {
        for joint in 0..n {
            let Some(size) = row[joint] else { continue };
            let mut up = s.joint(joint).parent;
            let mut covered = false;
            while let Some(p) = up {
                if row[p].is_some() {
                    covered = true;
                    break;
                }
                up = s.joint(p).parent;
            }
            if covered {
                continue;
            }
            let below: Vec<f64> = (joint..n)
                .filter(|&k| s.is_ancestor_or_self(joint, k))
                .filter_map(|k| row[k])
                .collect();
            out.push(Glitch {
                frame,
                joint,
                size,
                joints: below.len(),
                largest: below.iter().copied().fold(size, f64::max),
            });
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::tests::test_skeleton;
    use approx::assert_relative_eq;
    use nalgebra::Vector3;
    use std::sync::Arc;

    /// A point moving on a circle at `speed` m/s, 30 fps.
    fn circle(frames: usize, speed: f64) -> Vec<Point3<f64>> {
        let (r, dt) = (0.3, 1.0 / 30.0);
        (0..frames)
            .map(|i| {
                let a = speed * i as f64 * dt / r;
                Point3::new(r * a.cos(), 1.0 + r * a.sin(), 0.0)
            })
            .collect()
    }

    #[test]
    fn finds_a_jump_on_a_fast_smooth_path_and_nothing_else() {
        // 3 m/s on a 30 cm circle: 30 m/s² of centripetal acceleration, 1.7 cm detours.
        let mut path = circle(60, 3.0);
        assert!(path_glitches(&path, &GlitchOptions::default()).is_empty());
        let clean = speed_series(&path, 1.0 / 30.0);
        path[17] += Vector3::new(0.0, 0.0, 0.22);
        let found = path_glitches(&path, &GlitchOptions::default());
        assert_eq!(found.len(), 1);
        assert_eq!(found[0].0, 17);
        assert_relative_eq!(found[0].1, 0.22, max_relative = 0.1);
        // The speed without the glitch is the circle's own (the midpoint of a chord is a
        // little inside the circle: 1.5 mm here).
        let v = speed_series_without_glitches(&path, 1.0 / 30.0, &GlitchOptions::default());
        for (a, b) in v.iter().zip(&clean) {
            assert_relative_eq!(a, b, epsilon = 0.1);
        }
        let raw = speed_series(&path, 1.0 / 30.0);
        assert!(raw[16] > 3.0, "the raw speed sees the jump");
    }

    #[test]
    fn a_two_frame_jump_or_the_ends_are_not_one_frame_glitches() {
        let mut path = circle(20, 0.5);
        path[0] += Vector3::new(0.3, 0.0, 0.0);
        path[19] += Vector3::new(0.3, 0.0, 0.0);
        path[8] += Vector3::new(0.3, 0.0, 0.0);
        path[9] += Vector3::new(0.3, 0.0, 0.0);
        assert!(path_glitches(&path, &GlitchOptions::default()).is_empty());
        assert!(GlitchOptions::new(0.0, 1.0).is_err());
        assert!(GlitchOptions::new(0.05, f64::NAN).is_err());
    }

    #[test]
    fn a_joint_glitch_is_reported_once_at_the_top_of_its_subtree() {
        let s = Arc::new(test_skeleton());
        let n = s.dof_count();
        let poses: Vec<Vec<f64>> = (0..10)
            .map(|f| (0..n).map(|d| 0.01 * f as f64 * ((d % 3) as f64)).collect())
            .collect();
        let clean = Clip::from_poses(s.clone(), 1.0 / 30.0, &poses).expect("clip");
        assert!(
            find_glitches(&clean, &GlitchOptions::default())
                .expect("glitches")
                .is_empty()
        );
        // RightForeArm has an X translation: push it 22 cm for frame 4.
        let mut bad = poses.clone();
        bad[4][s.first_dof(4) + 1] += 0.22;
        let clip = Clip::from_poses(s.clone(), 1.0 / 30.0, &bad).expect("clip");
        let g = find_glitches(&clip, &GlitchOptions::default()).expect("glitches");
        assert_eq!(g.len(), 1, "{g:?}");
        assert_eq!(
            (g[0].frame, s.joint(g[0].joint).name.as_str()),
            (4, "RightForeArm")
        );
        assert_relative_eq!(g[0].size, 0.22, max_relative = 0.05);
        // It drags the hand and the hand's End Site along.
        assert_eq!(g[0].joints, 3);
        assert!(g[0].largest >= g[0].size);
    }
}
