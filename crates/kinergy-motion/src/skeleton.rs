//! The immutable skeleton, forward kinematics and positional Jacobians.

use nalgebra::{IsometryMatrix3, Matrix3xX, Point3, Rotation3, Translation3, Vector3};

use crate::error::{MotionError, Result};
use crate::rotation::{Axis, axis_rotation};

/// One degree of freedom of a joint, as a BVH channel describes it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Dof {
    /// Translation (meters) along an axis of the parent's frame, added to the joint's offset.
    Translation(Axis),
    /// Rotation (radians) about an axis; a joint's rotations compose in listed order,
    /// the first outermost: `R = R_a0(θ0) · R_a1(θ1) · …`.
    Rotation(Axis),
}

impl Dof {
    /// The BVH channel name, e.g. `Zrotation`.
    pub fn channel_name(self) -> &'static str {
        match self {
            Dof::Translation(Axis::X) => "Xposition",
            Dof::Translation(Axis::Y) => "Yposition",
            Dof::Translation(Axis::Z) => "Zposition",
            Dof::Rotation(Axis::X) => "Xrotation",
            Dof::Rotation(Axis::Y) => "Yrotation",
            Dof::Rotation(Axis::Z) => "Zrotation",
        }
    }

    /// The DoF of a BVH channel name ([`channel_name`](Self::channel_name)'s inverse).
    pub fn from_channel_name(name: &str) -> Option<Dof> {
        [Axis::X, Axis::Y, Axis::Z]
            .into_iter()
            .flat_map(|a| [Dof::Translation(a), Dof::Rotation(a)])
            .find(|d| d.channel_name() == name)
    }
}

/// How a joint's BVH position channels relate to its `OFFSET`.
///
/// Inside a [`Skeleton`] a joint's translation is always `offset + t` with `t` the values of
/// its translation DoFs; this records how the file's channel values were mapped to `t`.
/// Export ([`crate::clip_to_bvh`]) always writes channels that replace the OFFSET (and a
/// zero OFFSET on a root with position channels), the reading every importer shares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum PositionReading {
    /// The channels are a displacement added to the OFFSET (`t = channel`); Character
    /// Creator's root reads this way.
    #[default]
    AddToOffset,
    /// The channels are the joint's translation and replace the OFFSET on their axes
    /// (`t = channel − offset`); Blender's importer reads every file this way, and Bandai
    /// Namco's non-root joints carry their OFFSET in their channels.
    ReplaceOffset,
}

impl PositionReading {
    /// `"add"` or `"replace"`.
    pub fn name(self) -> &'static str {
        match self {
            PositionReading::AddToOffset => "add",
            PositionReading::ReplaceOffset => "replace",
        }
    }
}

/// One joint of a [`Skeleton`] (an End Site is a joint without DoFs or children).
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// Unique name. End Sites are named after their parent: `"<parent>_End"`.
    pub name: String,
    /// Index of the parent joint, `None` for the root. Parents come before children.
    pub parent: Option<usize>,
    /// Offset from the parent's origin in the parent's frame, meters.
    pub offset: Vector3<f64>,
    /// The joint's DoFs in their channel order.
    pub dofs: Vec<Dof>,
    /// True for a BVH End Site.
    pub end_site: bool,
    /// How the file's position channels were read (only meaningful with translation DoFs).
    pub position_reading: PositionReading,
}

/// An immutable articulated skeleton: joints in parent-before-child order, each with an
/// offset and DoFs. A pose is a `&[f64]` of [`Skeleton::dof_count`] values (radians, meters),
/// joint after joint, each joint's DoFs in channel order.
///
/// Offsets and pose values are in the frame of the file the skeleton came from; a fixed
/// rotation [`Skeleton::world_from_file`] (the identity for a Y-up file) turns that frame
/// into Kinergy's Y-up world at the root, so a Z-up capture keeps its own joint values
/// (and writes them back unchanged) while its world positions are Y-up.
#[derive(Debug, Clone, PartialEq)]
pub struct Skeleton {
    joints: Vec<Joint>,
    first_dof: Vec<usize>,
    dof_count: usize,
    /// `None` for the identity (a Y-up file), so FK of Y-up skeletons is unchanged bit for bit.
    world_from_file: Option<Rotation3<f64>>,
}

impl Skeleton {
    /// Builds a skeleton, checking that joint 0 is the only root, parents come before their
    /// children, names are unique and non-empty, offsets are finite and End Sites have no DoFs.
    pub fn new(joints: Vec<Joint>) -> Result<Skeleton> {
        if joints.is_empty() {
            return Err(MotionError::Invalid {
                what: "skeleton",
                why: "it has no joints".into(),
            });
        }
        let mut names = std::collections::HashSet::new();
        let mut first_dof = Vec::with_capacity(joints.len());
        let mut n = 0;
        for (i, j) in joints.iter().enumerate() {
            let bad = |why: String| MotionError::Invalid {
                what: "skeleton",
                why,
            };
            match j.parent {
                None if i != 0 => return Err(bad(format!("`{}` is a second root", j.name))),
                Some(_) if i == 0 => {
                    return Err(bad(format!("the root `{}` has a parent", j.name)));
                }
                Some(p) if p >= i => {
                    return Err(bad(format!("`{}` comes before its parent", j.name)));
                }
                _ => {}
            }
            if j.name.is_empty() || !names.insert(j.name.as_str()) {
                return Err(bad(format!("joint name `{}` is empty or repeated", j.name)));
            }
            if !j.offset.iter().all(|v| v.is_finite()) {
                return Err(MotionError::NonFinite {
                    what: format!("the offset of `{}`", j.name),
                });
            }
            if j.end_site && !j.dofs.is_empty() {
                return Err(bad(format!("End Site `{}` has DoFs", j.name)));
            }
            first_dof.push(n);
            n += j.dofs.len();
        }
        Ok(Skeleton {
            joints,
            first_dof,
            dof_count: n,
            world_from_file: None,
        })
    }

    /// The same skeleton whose file frame is turned into the world by `world_from_file`
    /// (applied at the root, before the root's own offset, translation and rotation).
    pub fn with_world_from_file(mut self, world_from_file: Rotation3<f64>) -> Skeleton {
        self.world_from_file =
            (world_from_file != Rotation3::identity()).then_some(world_from_file);
        self
    }

    /// The fixed rotation from the file's frame to Kinergy's Y-up world (the identity unless
    /// the file was read with another up axis, see [`crate::up`]).
    pub fn world_from_file(&self) -> Rotation3<f64> {
        self.world_from_file.unwrap_or_else(Rotation3::identity)
    }

    /// The joints, parents before children.
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// Joint `i`. Panics if out of range (indices come from this skeleton).
    pub fn joint(&self, i: usize) -> &Joint {
        &self.joints[i]
    }

    /// The number of joints (End Sites included).
    pub fn joint_count(&self) -> usize {
        self.joints.len()
    }

    /// The number of DoFs, the length of a pose.
    pub fn dof_count(&self) -> usize {
        self.dof_count
    }

    /// The index in a pose of joint `joint`'s first DoF.
    pub fn first_dof(&self, joint: usize) -> usize {
        self.first_dof[joint]
    }

    /// The pose indices of joint `joint`'s DoFs.
    pub fn dof_range(&self, joint: usize) -> std::ops::Range<usize> {
        let s = self.first_dof[joint];
        s..s + self.joints[joint].dofs.len()
    }

    /// The pose indices and axes of joint `joint`'s rotation DoFs, in channel order.
    pub fn rotation_dofs(&self, joint: usize) -> Vec<(usize, Axis)> {
        let start = self.first_dof[joint];
        self.joints[joint]
            .dofs
            .iter()
            .enumerate()
            .filter_map(|(k, d)| match d {
                Dof::Rotation(a) => Some((start + k, *a)),
                Dof::Translation(_) => None,
            })
            .collect()
    }

    /// Joint `joint`'s rotation as Euler angles: the pose indices and axes of its rotation
    /// DoFs where it has exactly three, about three different axes (so any turn has angles);
    /// `None` otherwise.
    pub fn euler_dofs(&self, joint: usize) -> Option<([usize; 3], [Axis; 3])> {
        match self.rotation_dofs(joint)[..] {
            [(i0, a0), (i1, a1), (i2, a2)] if a0 != a1 && a1 != a2 && a0 != a2 => {
                Some(([i0, i1, i2], [a0, a1, a2]))
            }
            _ => None,
        }
    }

    /// The joint named `name`.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The joint named `name`, or an error listing the skeleton's joints.
    pub fn require_joint(&self, name: &str) -> Result<usize> {
        self.joint_index(name)
            .ok_or_else(|| MotionError::UnknownJoint {
                name: name.to_string(),
                available: self
                    .joints
                    .iter()
                    .filter(|j| !j.end_site)
                    .map(|j| j.name.clone())
                    .collect(),
            })
    }

    /// `"<joint>.<channel>"` for pose index `dof`, e.g. `"RightArm.Zrotation"`.
    pub fn dof_name(&self, dof: usize) -> Option<String> {
        let j = self
            .first_dof
            .partition_point(|&f| f <= dof)
            .checked_sub(1)?;
        let joint = &self.joints[j];
        let d = joint.dofs.get(dof - self.first_dof[j])?;
        Some(format!("{}.{}", joint.name, d.channel_name()))
    }

    /// The children of joint `joint`.
    pub fn children(&self, joint: usize) -> impl Iterator<Item = usize> + '_ {
        (joint + 1..self.joints.len()).filter(move |&c| self.joints[c].parent == Some(joint))
    }

    /// True when `ancestor` is `joint` or above it.
    pub fn is_ancestor_or_self(&self, ancestor: usize, joint: usize) -> bool {
        let mut j = Some(joint);
        while let Some(i) = j {
            if i == ancestor {
                return true;
            }
            j = self.joints[i].parent;
        }
        false
    }

    /// The lowest common ancestor of joints `a` and `b` (one of them when it is above the
    /// other; parents come before children, and the root is every joint's ancestor).
    pub fn common_ancestor(&self, mut a: usize, mut b: usize) -> usize {
        while a != b {
            if a > b {
                a = self.joints[a].parent.unwrap_or(0);
            } else {
                b = self.joints[b].parent.unwrap_or(0);
            }
        }
        a
    }

    /// The joints from `from` down to `to`, both included; `None` if `from` is not an
    /// ancestor of (or equal to) `to`.
    pub fn path(&self, from: usize, to: usize) -> Option<Vec<usize>> {
        let mut path = vec![to];
        let mut j = to;
        while j != from {
            j = self.joints.get(j)?.parent?;
            path.push(j);
        }
        path.reverse();
        Some(path)
    }

    /// The pose indices of every DoF of the joints on [`Skeleton::path`]`(from, to)`.
    pub fn path_dofs(&self, from: usize, to: usize) -> Option<Vec<usize>> {
        Some(
            self.path(from, to)?
                .into_iter()
                .flat_map(|j| self.dof_range(j))
                .collect(),
        )
    }

    /// A pose of zeros (every joint at its offset, unrotated).
    pub fn rest_pose(&self) -> Vec<f64> {
        vec![0.0; self.dof_count]
    }

    fn check_pose(&self, pose: &[f64]) -> Result<()> {
        if pose.len() == self.dof_count {
            Ok(())
        } else {
            Err(MotionError::PoseLength {
                expected: self.dof_count,
                found: pose.len(),
            })
        }
    }

    /// The transform of joint `j` relative to its parent: `T(offset + t) · R`; for the root,
    /// relative to the world: `W · T(offset + t) · R` with `W` = [`Skeleton::world_from_file`].
    pub fn local_transform(&self, j: usize, pose: &[f64]) -> IsometryMatrix3<f64> {
        let joint = &self.joints[j];
        let mut t = joint.offset;
        let mut r = Rotation3::identity();
        let start = self.first_dof[j];
        for (k, d) in joint.dofs.iter().enumerate() {
            let v = pose[start + k];
            match *d {
                Dof::Translation(a) => t[a.index()] += v,
                Dof::Rotation(a) => r *= axis_rotation(a, v),
            }
        }
        if let (None, Some(w)) = (joint.parent, self.world_from_file) {
            return IsometryMatrix3::from_parts(Translation3::from(w * t), w * r);
        }
        IsometryMatrix3::from_parts(Translation3::from(t), r)
    }

    /// Forward kinematics: the world transform of every joint, into `out` (reused, so a
    /// loop over frames allocates once).
    pub fn fk_into(&self, pose: &[f64], out: &mut Vec<IsometryMatrix3<f64>>) -> Result<()> {
        self.check_pose(pose)?;
        out.clear();
        for j in 0..self.joints.len() {
            let local = self.local_transform(j, pose);
            let world = match self.joints[j].parent {
                Some(p) => out[p] * local,
                None => local,
            };
            out.push(world);
        }
        Ok(())
    }

    /// Forward kinematics: the world transform of every joint.
    pub fn fk(&self, pose: &[f64]) -> Result<Vec<IsometryMatrix3<f64>>> {
        let mut out = Vec::with_capacity(self.joints.len());
        self.fk_into(pose, &mut out)?;
        Ok(out)
    }

    /// World positions of every joint.
    pub fn world_positions(&self, pose: &[f64]) -> Result<Vec<Point3<f64>>> {
        Ok(self
            .fk(pose)?
            .iter()
            .map(|t| Point3::from(t.translation.vector))
            .collect())
    }

    /// The positional Jacobian `∂p_target/∂q_d` (3 × `dofs.len()`) of joint or End Site
    /// `target` with respect to the pose DoFs `dofs`, at `pose`.
    ///
    /// A rotation DoF about unit axis ω (in world space, after the rotations listed before
    /// it on the same joint) through the joint's origin p_j gives the column ω × (p_target −
    /// p_j); a translation DoF gives its world axis; a DoF that does not move the target
    /// (not on the root path) gives a zero column.
    pub fn jacobian(&self, pose: &[f64], target: usize, dofs: &[usize]) -> Result<Matrix3xX<f64>> {
        if target >= self.joints.len() {
            return Err(MotionError::Invalid {
                what: "Jacobian target",
                why: format!("joint index {target} is out of range"),
            });
        }
        if let Some(&d) = dofs.iter().find(|&&d| d >= self.dof_count) {
            return Err(MotionError::Invalid {
                what: "Jacobian DoF",
                why: format!(
                    "DoF index {d} is out of range (the skeleton has {})",
                    self.dof_count
                ),
            });
        }
        let world = self.fk(pose)?;
        let p = world[target].translation.vector;
        let mut jac = Matrix3xX::zeros(dofs.len());
        for (col, &d) in dofs.iter().enumerate() {
            let j = self.first_dof.partition_point(|&f| f <= d) - 1;
            if !self.is_ancestor_or_self(j, target) {
                continue;
            }
            let joint = &self.joints[j];
            let parent_rot = match joint.parent {
                Some(pa) => *world[pa].rotation.matrix(),
                None => *self.world_from_file().matrix(),
            };
            let origin = world[j].translation.vector;
            let k = d - self.first_dof[j];
            match joint.dofs[k] {
                Dof::Translation(a) => jac.set_column(col, &(parent_rot * a.unit().into_inner())),
                Dof::Rotation(a) => {
                    let mut r = parent_rot;
                    for (m, dm) in joint.dofs[..k].iter().enumerate() {
                        if let Dof::Rotation(b) = dm {
                            r *= axis_rotation(*b, pose[self.first_dof[j] + m]).matrix();
                        }
                    }
                    let omega = r * a.unit().into_inner();
                    jac.set_column(col, &omega.cross(&(p - origin)));
                }
            }
        }
        Ok(jac)
    }

    /// The skeleton's largest extent along any world axis at `pose`: the body's size, without
    /// the reference joints above it (see [`Skeleton::reference_joints`]) — a performer who
    /// walked 5 m away from a `joint_Root` left at the origin is still a 1.7 m body, not a
    /// 5.4 m one.
    pub fn extent(&self, pose: &[f64]) -> Result<f64> {
        let pts = self.world_positions(pose)?;
        let skip = self.reference_joints();
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for p in &pts[skip..] {
            lo = lo.inf(&p.coords);
            hi = hi.sup(&p.coords);
        }
        Ok((hi - lo).max())
    }

    /// How many joints, from the root down, are reference joints rather than the body: the
    /// root and its descendants while each has exactly one child (a `joint_Root` or
    /// `Reference` above the hips, which exporters leave at the origin while the body moves
    /// away). The hips, where the legs and the spine branch, are body. Leaving such a joint
    /// out of a size costs nothing when it sits in the body (its one child is near it).
    /// Joints are in parent-first order, so the reference joints are the first ones. A
    /// skeleton that never branches (one chain, an arm alone) has none.
    pub fn reference_joints(&self) -> usize {
        let mut joint = 0;
        while joint < self.joints.len() {
            let mut children = self.children(joint);
            match (children.next(), children.next()) {
                (Some(only), None) if only == joint + 1 => joint = only,
                (Some(_), Some(_)) => return joint,
                _ => return 0,
            }
        }
        0
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    /// A small branching skeleton with every kind of DoF, in meters.
    pub(crate) fn test_skeleton() -> Skeleton {
        use Axis::*;
        let j = |name: &str, parent: Option<usize>, off: [f64; 3], dofs: Vec<Dof>| Joint {
            name: name.into(),
            parent,
            offset: Vector3::from(off),
            dofs,
            end_site: false,
            position_reading: PositionReading::AddToOffset,
        };
        let all = |order: [Axis; 3]| order.map(Dof::Rotation).to_vec();
        let mut joints = vec![
            j(
                "Hips",
                None,
                [0.0, 0.9, 0.0],
                vec![
                    Dof::Translation(X),
                    Dof::Translation(Y),
                    Dof::Translation(Z),
                    Dof::Rotation(Z),
                    Dof::Rotation(X),
                    Dof::Rotation(Y),
                ],
            ),
            j("Spine", Some(0), [0.0, 0.2, 0.01], all([Y, X, Z])),
            j("RightShoulder", Some(1), [-0.05, 0.3, 0.0], all([Z, Y, X])),
            j("RightArm", Some(2), [-0.15, 0.0, 0.0], all([X, Z, Y])),
            j(
                "RightForeArm",
                Some(3),
                [-0.28, 0.0, 0.0],
                vec![Dof::Rotation(Y), Dof::Translation(X), Dof::Rotation(X)],
            ),
            j("RightHand", Some(4), [-0.26, 0.0, 0.0], all([Z, X, Y])),
            j("Head", Some(1), [0.0, 0.35, 0.0], all([Z, X, Y])),
        ];
        joints.push(Joint {
            end_site: true,
            ..j("RightHand_End", Some(5), [-0.09, 0.0, 0.01], vec![])
        });
        Skeleton::new(joints).expect("valid")
    }

    #[test]
    fn reference_joints_are_the_single_child_joints_above_the_first_branch() {
        let skeleton = test_skeleton();
        // Hips has one child (Spine), where the arm and the head branch.
        assert_eq!(skeleton.reference_joints(), 1);
        // A chain never branches: nothing is a reference joint.
        let chain: Vec<Joint> = skeleton.joints()[2..6]
            .iter()
            .enumerate()
            .map(|(k, j)| Joint {
                parent: k.checked_sub(1),
                ..j.clone()
            })
            .collect();
        let chain = Skeleton::new(chain).expect("chain");
        assert_eq!(chain.reference_joints(), 0);
        // A reference far away does not count in the extent; the body does.
        let mut joints = skeleton.joints().to_vec();
        joints[0].offset = Vector3::new(0.0, 0.9, -5.4);
        let far = Skeleton::new(joints).expect("far");
        let pose = vec![0.0; far.dof_count()];
        let near = skeleton.extent(&pose).expect("extent");
        assert_relative_eq!(far.extent(&pose).expect("extent"), near, epsilon = 1e-12);
    }

    #[test]
    fn rest_pose_sums_offsets() {
        let s = test_skeleton();
        let p = s.world_positions(&s.rest_pose()).expect("pose");
        assert_relative_eq!(p[7].coords, Vector3::new(-0.83, 1.4, 0.02), epsilon = 1e-12);
    }

    #[test]
    fn rejects_bad_skeletons_and_poses() {
        let s = test_skeleton();
        assert!(matches!(
            s.fk(&[0.0; 3]),
            Err(MotionError::PoseLength { .. })
        ));
        let mut joints = s.joints().to_vec();
        joints[3].parent = Some(5);
        assert!(Skeleton::new(joints).is_err());
        let mut joints = s.joints().to_vec();
        joints[4].name = "RightArm".into();
        assert!(Skeleton::new(joints).is_err());
        assert!(matches!(
            s.require_joint("Tail"),
            Err(MotionError::UnknownJoint { .. })
        ));
    }

    #[test]
    fn dof_names() {
        let s = test_skeleton();
        assert_eq!(s.dof_name(0).as_deref(), Some("Hips.Xposition"));
        assert_eq!(s.dof_name(6).as_deref(), Some("Spine.Yrotation"));
        assert_eq!(s.dof_name(s.dof_count()), None);
    }

    #[test]
    fn world_from_file_turns_the_whole_body_and_its_jacobian() {
        let s = test_skeleton();
        let w = crate::up::UpAxis::Z.world_from_file();
        let turned = s.clone().with_world_from_file(w);
        let pose: Vec<f64> = (0..s.dof_count()).map(|d| 0.1 * d as f64 - 0.7).collect();
        let a = s.world_positions(&pose).expect("fk");
        let b = turned.world_positions(&pose).expect("fk");
        for (a, b) in a.iter().zip(&b) {
            assert_relative_eq!(w * a, *b, epsilon = 1e-12);
        }
        let dofs: Vec<usize> = (0..s.dof_count()).collect();
        let jac = turned.jacobian(&pose, 7, &dofs).expect("jacobian");
        let h = 1e-6;
        for d in dofs {
            let (mut plus, mut minus) = (pose.clone(), pose.clone());
            plus[d] += h;
            minus[d] -= h;
            let fd = (turned.world_positions(&plus).expect("fk")[7]
                - turned.world_positions(&minus).expect("fk")[7])
                / (2.0 * h);
            assert_relative_eq!(jac.column(d).into_owned(), fd, epsilon = 1e-7);
        }
        assert_eq!(
            s.with_world_from_file(Rotation3::identity())
                .world_from_file(),
            Rotation3::identity()
        );
    }

    proptest! {
        #[test]
        fn jacobian_matches_finite_differences(
            pose in proptest::collection::vec(-2.0f64..2.0, 24),
            target in 0usize..8,
        ) {
            let s = test_skeleton();
            prop_assume!(pose.len() == s.dof_count());
            let dofs: Vec<usize> = (0..s.dof_count()).collect();
            let jac = s.jacobian(&pose, target, &dofs).expect("jacobian");
            let h = 1e-6;
            for d in dofs {
                let mut plus = pose.clone();
                let mut minus = pose.clone();
                plus[d] += h;
                minus[d] -= h;
                let fd = (s.world_positions(&plus).expect("fk")[target]
                    - s.world_positions(&minus).expect("fk")[target])
                    / (2.0 * h);
                assert_relative_eq!(jac.column(d).into_owned(), fd, epsilon = 1e-7);
            }
        }
    }
}
