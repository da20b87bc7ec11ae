//! A clip from joint positions per frame (what pose estimators, SMPL joints and C3D joint
//! centres give): the skeleton's bones from the positions, each joint's rotation from where
//! its children are, made into a BVH-shaped clip ([`Clip::from_rotations`]).
//!
//! The rest pose is the first frame's: each bone's offset is its direction on the first frame
//! at its median length over all frames, so every rotation is the identity on the first frame.
//! On each frame a joint's world rotation is the one that carries its bones' rest directions
//! onto where its children are:
//!
//! - two or more children not on one line (a pelvis and its hips and spine, a chest and its
//!   neck and clavicles): the least-squares rotation of the rest bones onto the current ones
//!   (Kabsch), the joint fully determined;
//! - one child (an elbow and its wrist), or children on one line: the bone's swing — the
//!   smallest turn from where the last frame's rotation put the bone to where it is — with the
//!   twist about the bone kept from the last frame. The positions say nothing of that twist:
//!   the joint is reported among the undetermined.
//!
//! Every joint's world position is then where the input puts it, up to the bones' lengths:
//! the positions of a rigid skeleton come back exactly (round trip), those of one whose bones
//! vary (estimated from video) within each bone's variation from its median, reported per
//! joint and frame.

use nalgebra::{Matrix3, Point3, Rotation3, UnitQuaternion, Vector3};

use super::Clip;
use super::arrays::RotationArrays;
use crate::error::{MotionError, Result};

/// Joint positions per frame, Y up, meters: the input of [`Clip::from_positions`].
#[derive(Debug, Clone, Copy)]
pub struct PositionArrays<'a> {
    /// The joints' names.
    pub joint_names: &'a [String],
    /// Each joint's parent index, `-1` for the root; parents come before their children.
    pub parents: &'a [i64],
    /// Each frame's world positions, joint after joint.
    pub positions: &'a [[f64; 3]],
    /// Seconds per frame.
    pub frame_time: f64,
}

/// A clip made from positions, with how well it holds them.
#[derive(Debug, Clone)]
pub struct FromPositions {
    /// The clip (rotation channels Z X Y on every joint but the leaves, which are End Sites),
    /// its joints in depth-first order as BVH lists them (each joint's subtree before its next
    /// sibling; the input's order where it already is).
    pub clip: Clip,
    /// Each frame's distance of each joint from its input position, meters, joint after joint
    /// in the clip's order.
    pub error_m: Vec<f64>,
    /// The joints whose twist about their bone the positions do not determine (one child, or
    /// children on one line): kept from the previous frame.
    pub undetermined: Vec<String>,
    /// The bones whose length varies over the frames by more than 0.1 mm: (the child joint,
    /// the range of its bone's length, meters). A skeleton of rotations alone holds each at its
    /// median length, so their joints and everything below them are off by up to the range (a
    /// reference root the hips move away from, positions estimated from video).
    pub stretched: Vec<(String, f64)>,
}

impl FromPositions {
    /// The largest distance of any joint from its input position, meters.
    pub fn max_error_m(&self) -> f64 {
        self.error_m.iter().copied().fold(0.0, f64::max)
    }

    /// Each joint's largest distance from its input positions over the frames, meters, with
    /// its name, in the clip's joint order.
    pub fn joint_max_error_m(&self) -> Vec<(String, f64)> {
        let joints = self.clip.skeleton().joints();
        let n = joints.len();
        joints
            .iter()
            .enumerate()
            .map(|(j, joint)| {
                let worst = self.error_m.iter().skip(j).step_by(n).copied();
                (joint.name.clone(), worst.fold(0.0, f64::max))
            })
            .collect()
    }
}

/// A bone whose length varies by more than this over the frames (meters) is reported.
const STRETCH_M: f64 = 1e-4;

/// Children closer than this to their joint (meters) carry no direction.
const COINCIDENT_M: f64 = 1e-6;

/// Children whose directions are closer than this to one line (the sine of their angle) do
/// not fix a twist.
const COLLINEAR_SINE: f64 = 1e-3;

impl Clip {
    /// The clip whose joints are at `arrays`' positions (module docs): bones of the median
    /// length, the first frame the rest pose, rotations from the children's directions.
    pub fn from_positions(arrays: PositionArrays<'_>) -> Result<FromPositions> {
        Clip::from_positions_with(arrays, Stretch::Hold)
    }

    /// [`Clip::from_positions`], bones that stretch over the frames held at their median
    /// length ([`Stretch::Hold`]) or given position channels that carry each frame's length
    /// ([`Stretch::Keep`]).
    pub fn from_positions_with(
        arrays: PositionArrays<'_>,
        stretch: Stretch,
    ) -> Result<FromPositions> {
        let n = arrays.joint_names.len();
        let invalid = |what: &'static str, why: String| MotionError::Invalid { what, why };
        if n == 0 {
            return Err(invalid("joint_names", "no joints".into()));
        }
        if arrays.parents.len() != n {
            let why = format!("{} parents for {n} joint names", arrays.parents.len());
            return Err(invalid("parents", why));
        }
        for (i, &p) in arrays.parents.iter().enumerate() {
            let ok = if i == 0 {
                p == -1
            } else {
                p >= 0 && (p as usize) < i
            };
            if !ok {
                let why = format!(
                    "parents[{i}] = {p} ({}): the first joint is the root (-1), every other \
                     joint's parent comes before it",
                    arrays.joint_names[i]
                );
                return Err(invalid("parents", why));
            }
        }
        if arrays.positions.is_empty() || !arrays.positions.len().is_multiple_of(n) {
            let why = format!(
                "{} positions are not a whole number of frames of {n} joints",
                arrays.positions.len()
            );
            return Err(invalid("positions", why));
        }
        let frames = arrays.positions.len() / n;
        if let Some(k) = arrays
            .positions
            .iter()
            .position(|p| !p.iter().all(|v| v.is_finite()))
        {
            let why = format!(
                "joint {} has no finite position on frame {}",
                arrays.joint_names[k % n],
                k / n
            );
            return Err(invalid("positions", why));
        }
        // BVH lists a joint's whole subtree before its next sibling: joints given in another
        // order (SMPL's lists the hips, then the spine, then the knees) are put in that order.
        let order = depth_first(arrays.parents);
        if order.iter().enumerate().any(|(k, &j)| k != j) {
            let mut new_index = vec![0usize; n];
            for (k, &j) in order.iter().enumerate() {
                new_index[j] = k;
            }
            let names: Vec<String> = order
                .iter()
                .map(|&j| arrays.joint_names[j].clone())
                .collect();
            let parents: Vec<i64> = order
                .iter()
                .map(|&j| match arrays.parents[j] {
                    -1 => -1,
                    p => new_index[p as usize] as i64,
                })
                .collect();
            let positions: Vec<[f64; 3]> = (0..frames)
                .flat_map(|f| order.iter().map(move |&j| (f, j)))
                .map(|(f, j)| arrays.positions[f * n + j])
                .collect();
            return Clip::from_positions_with(
                PositionArrays {
                    joint_names: &names,
                    parents: &parents,
                    positions: &positions,
                    frame_time: arrays.frame_time,
                },
                stretch,
            );
        }
        let at = |f: usize, j: usize| Vector3::from(arrays.positions[f * n + j]);
        let parent = |j: usize| arrays.parents[j] as usize;
        let children: Vec<Vec<usize>> = (0..n)
            .map(|j| (1..n).filter(|&c| parent(c) == j).collect())
            .collect();

        // The bones: the first frame's directions at the median length.
        let mut offsets = vec![[0.0; 3]; n];
        let mut stretched = Vec::new();
        for (c, offset) in offsets.iter_mut().enumerate().skip(1) {
            let mut lengths: Vec<f64> = (0..frames)
                .map(|f| (at(f, c) - at(f, parent(c))).norm())
                .collect();
            lengths.sort_by(f64::total_cmp);
            let median = lengths[lengths.len() / 2];
            let range = lengths[lengths.len() - 1] - lengths[0];
            if range > STRETCH_M {
                stretched.push((arrays.joint_names[c].clone(), range));
            }
            let first = at(0, c) - at(0, parent(c));
            let direction = first
                .try_normalize(COINCIDENT_M)
                .unwrap_or_else(Vector3::zeros);
            *offset = (direction * median).into();
        }

        // Which joints' twists the positions fix.
        let fixes_twist = |j: usize| -> bool {
            let dirs: Vec<Vector3<f64>> = children[j]
                .iter()
                .filter_map(|&c| Vector3::from(offsets[c]).try_normalize(COINCIDENT_M))
                .collect();
            dirs.iter().enumerate().any(|(a, u)| {
                dirs[a + 1..]
                    .iter()
                    .any(|v| u.cross(v).norm() > COLLINEAR_SINE)
            })
        };
        let determined: Vec<bool> = (0..n).map(fixes_twist).collect();
        let leaf: Vec<bool> = children.iter().map(Vec::is_empty).collect();

        // World rotations as unit quaternions, renormalized as they are composed: a rotation
        // matrix swung frame after frame drifts from orthonormal, and its quaternion near a half
        // turn was NaN (an idle hand hanging below its forearm, frame 47 of a synthetic reach).
        let mut world = vec![UnitQuaternion::identity(); n];
        let mut rotations = Vec::with_capacity(frames * n);
        let mut root_translation = Vec::with_capacity(frames);
        for f in 0..frames {
            let mut now = vec![UnitQuaternion::identity(); n];
            for j in 0..n {
                if leaf[j] {
                    // An End Site turns with its parent.
                    now[j] = if j == 0 { world[j] } else { now[parent(j)] };
                    continue;
                }
                let pairs: Vec<(Vector3<f64>, Vector3<f64>)> = children[j]
                    .iter()
                    .filter_map(|&c| {
                        let rest = Vector3::from(offsets[c]);
                        let current = at(f, c) - at(f, j);
                        (rest.norm() > COINCIDENT_M && current.norm() > COINCIDENT_M)
                            .then_some((rest, current))
                    })
                    .collect();
                now[j] = if pairs.is_empty() {
                    world[j]
                } else if determined[j] {
                    UnitQuaternion::from_rotation_matrix(&kabsch(&pairs))
                } else {
                    // The swing from where the last frame's rotation puts the bone.
                    let (rest, current) = pairs[0];
                    let was = world[j] * rest;
                    let swing = UnitQuaternion::rotation_between(&was, &current)
                        .unwrap_or_else(|| half_turn_about_normal(&was));
                    let mut q = swing * world[j];
                    q.renormalize();
                    q
                };
            }
            for j in 0..n {
                let local = if j == 0 {
                    now[0]
                } else {
                    now[parent(j)].inverse() * now[j]
                };
                let mut q = local;
                q.renormalize();
                rotations.push([q.w, q.i, q.j, q.k]);
            }
            root_translation.push(arrays.positions[f * n]);
            world = now;
        }
        let clip = Clip::from_rotations(RotationArrays {
            joint_names: arrays.joint_names,
            parents: arrays.parents,
            offsets: &offsets,
            rotations: &rotations,
            root_translation: &root_translation,
            frame_time: arrays.frame_time,
            end_sites: Some(&leaf),
        })?;
        let clip = match stretch {
            Stretch::Hold => clip,
            Stretch::Keep => {
                let moving: Vec<usize> = (1..n)
                    .filter(|&c| !leaf[c])
                    .filter(|&c| {
                        stretched
                            .iter()
                            .any(|(name, _)| *name == arrays.joint_names[c])
                    })
                    .collect();
                with_stretching_bones(&clip, &moving, &offsets, arrays.positions)?
            }
        };
        let made = clip.world_positions()?;
        let error_m = made
            .iter()
            .zip(arrays.positions)
            .map(|(m, p)| (m - Point3::from(*p)).norm())
            .collect();
        let undetermined = (0..n)
            .filter(|&j| !leaf[j] && !determined[j])
            .map(|j| arrays.joint_names[j].clone())
            .collect();
        Ok(FromPositions {
            clip,
            error_m,
            undetermined,
            stretched,
        })
    }
}

/// What [`Clip::from_positions_with`] does with a bone whose length varies over the frames.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Stretch {
    /// Held at its median length (a skeleton of rotations alone; the joint is off by up to
    /// the bone's range, reported).
    #[default]
    Hold,
    /// Kept: the bone's child joint gets position channels carrying its offset on each frame,
    /// so every joint but a stretching leaf (an End Site has no channels) is where the input
    /// puts it — a reference root the hips move away from, positions estimated from video.
    Keep,
}

impl std::str::FromStr for Stretch {
    type Err = String;

    fn from_str(s: &str) -> std::result::Result<Stretch, String> {
        match s {
            "hold" => Ok(Stretch::Hold),
            "keep" => Ok(Stretch::Keep),
            other => Err(format!("`{other}`: hold or keep")),
        }
    }
}

/// `clip` with position channels on the joints `moving` (before their rotation channels),
/// each frame's value putting the joint where `positions` (frames of the clip's joints) has it
/// relative to its parent, in the parent's frame: offset + channel.
fn with_stretching_bones(
    clip: &Clip,
    moving: &[usize],
    offsets: &[[f64; 3]],
    positions: &[[f64; 3]],
) -> Result<Clip> {
    use crate::rotation::Axis;
    use crate::skeleton::{Dof, PositionReading, Skeleton};
    if moving.is_empty() {
        return Ok(clip.clone());
    }
    let old = clip.skeleton();
    let n = old.joint_count();
    let mut joints = old.joints().to_vec();
    for &c in moving {
        let mut dofs = vec![
            Dof::Translation(Axis::X),
            Dof::Translation(Axis::Y),
            Dof::Translation(Axis::Z),
        ];
        dofs.extend(joints[c].dofs.iter().copied());
        joints[c].dofs = dofs;
        joints[c].position_reading = PositionReading::ReplaceOffset;
    }
    let skeleton =
        std::sync::Arc::new(Skeleton::new(joints)?.with_world_from_file(old.world_from_file()));
    let mut values = Vec::with_capacity(clip.frame_count() * skeleton.dof_count());
    let mut world = Vec::new();
    for (f, pose) in clip.frames().enumerate() {
        old.fk_into(pose, &mut world)?;
        for j in 0..n {
            if moving.contains(&j) {
                let p = old.joint(j).parent.unwrap_or(0);
                let (a, b) = (
                    Vector3::from(positions[f * n + p]),
                    Vector3::from(positions[f * n + j]),
                );
                let local = world[p].rotation.inverse() * (b - a) - Vector3::from(offsets[j]);
                values.extend(local.iter());
            }
            values.extend_from_slice(&pose[old.dof_range(j)]);
        }
    }
    Clip::new(skeleton, clip.frame_time(), values)
}

/// The joints in depth-first order (each joint's subtree before its next sibling, siblings in
/// their given order): indices into `parents` (valid: the root first, parents before children).
fn depth_first(parents: &[i64]) -> Vec<usize> {
    let n = parents.len();
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (j, &p) in parents.iter().enumerate().skip(1) {
        children[p as usize].push(j);
    }
    let mut order = Vec::with_capacity(n);
    let mut stack = vec![0];
    while let Some(j) = stack.pop() {
        order.push(j);
        stack.extend(children[j].iter().rev());
    }
    order
}

/// The rotation `R` minimizing Σ |R·rest − current|² over the pairs (Kabsch, by SVD of the
/// cross-covariance; a reflection is turned into the nearest rotation).
fn kabsch(pairs: &[(Vector3<f64>, Vector3<f64>)]) -> Rotation3<f64> {
    let h: Matrix3<f64> = pairs.iter().fold(Matrix3::zeros(), |h, (rest, current)| {
        h + current * rest.transpose()
    });
    let svd = h.svd(true, true);
    let (Some(u), Some(v_t)) = (svd.u, svd.v_t) else {
        return Rotation3::identity();
    };
    let d = (u * v_t).determinant().signum();
    let fix = Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d));
    Rotation3::from_matrix_unchecked(u * fix * v_t)
}

/// A half turn about an axis normal to `v` (the turn that reverses a bone).
fn half_turn_about_normal(v: &Vector3<f64>) -> UnitQuaternion<f64> {
    let other = if v.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let axis = nalgebra::Unit::new_normalize(v.cross(&other));
    UnitQuaternion::from_axis_angle(&axis, std::f64::consts::PI)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A three-joint arm and a hip with two legs, moved rigidly: positions come back exactly.
    #[test]
    fn positions_of_a_rigid_skeleton_come_back_and_single_child_twists_are_reported() {
        let names: Vec<String> = [
            "Hips",
            "LeftLeg",
            "LeftFoot",
            "RightLeg",
            "RightFoot",
            "Spine",
            "Head",
        ]
        .map(String::from)
        .to_vec();
        let parents = [-1, 0, 1, 0, 3, 0, 5];
        let rest = [
            [0.0, 1.0, 0.0],
            [0.1, 0.9, 0.0],
            [0.1, 0.5, 0.05],
            [-0.1, 0.9, 0.0],
            [-0.1, 0.5, -0.05],
            [0.0, 1.3, 0.0],
            [0.0, 1.6, 0.02],
        ];
        let mut positions = Vec::new();
        for f in 0..20 {
            let t = f as f64 * 0.1;
            let turn = Rotation3::from_euler_angles(0.3 * t, 0.7 * t, -0.2 * t);
            let knee = Rotation3::from_euler_angles(0.5 * t.sin(), 0.0, 0.0);
            let shift = Vector3::new(0.2 * t, 0.0, -0.1 * t);
            let hips = Vector3::from(rest[0]);
            for (j, p) in rest.iter().enumerate() {
                let mut v = Vector3::from(*p) - hips;
                // The feet swing about their knees (a one-child joint moving).
                if j == 2 || j == 4 {
                    let k = Vector3::from(rest[j - 1]) - hips;
                    v = k + knee * (v - k);
                }
                positions.push((hips + shift + turn * v).into());
            }
        }
        let made = Clip::from_positions(PositionArrays {
            joint_names: &names,
            parents: &parents,
            positions: &positions,
            frame_time: 1.0 / 30.0,
        })
        .expect("clip");
        assert!(made.max_error_m() < 1e-9, "{}", made.max_error_m());
        assert_eq!(made.undetermined, ["LeftLeg", "RightLeg", "Spine"]);
        assert!(made.stretched.is_empty());
        assert_eq!(made.clip.frame_count(), 20);
    }

    #[test]
    fn bad_arrays_are_refused_naming_the_field() {
        let names = vec!["a".to_string(), "b".to_string()];
        let good = [[0.0; 3], [0.0, 1.0, 0.0]];
        let e = Clip::from_positions(PositionArrays {
            joint_names: &names,
            parents: &[-1, 1],
            positions: &good,
            frame_time: 0.1,
        })
        .expect_err("parent after");
        assert!(e.to_string().contains("parents[1]"), "{e}");
        let nan = [[0.0; 3], [0.0, f64::NAN, 0.0]];
        let e = Clip::from_positions(PositionArrays {
            joint_names: &names,
            parents: &[-1, 0],
            positions: &nan,
            frame_time: 0.1,
        })
        .expect_err("nan");
        assert!(e.to_string().contains("joint b"), "{e}");
    }
}
