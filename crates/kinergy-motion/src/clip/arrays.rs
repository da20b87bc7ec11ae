//! A clip from arrays of local rotations: what numpy users, pose estimators and retargeting
//! hand over (joint names, parents, offsets, unit quaternions per frame and joint, the root's
//! path), made into a BVH-shaped clip with continuous Euler angles.

use std::sync::Arc;

use nalgebra::{Quaternion, Rotation3, UnitQuaternion, Vector3};

use super::Clip;
use crate::error::{MotionError, Result};
use crate::rotation::{Axis, euler_angles, nearest_euler};
use crate::skeleton::{Dof, Joint, PositionReading, Skeleton};

/// A clip as arrays, owned ([`Clip::to_rotations`]): what [`Clip::from_rotations`] takes
/// back.
#[derive(Debug, Clone, PartialEq)]
pub struct ClipArrays {
    /// The joints' names.
    pub joint_names: Vec<String>,
    /// Each joint's parent index, `-1` for the root.
    pub parents: Vec<i64>,
    /// Each joint's offset from its parent in the parent's frame, meters (the root's turned
    /// into the Y-up world).
    pub offsets: Vec<[f64; 3]>,
    /// Each frame's local rotations, joint after joint, `(w, x, y, z)`: each relative to its
    /// parent's frame, the root's to the Y-up world.
    pub rotations: Vec<[f64; 4]>,
    /// The root joint's world position on each frame, meters.
    pub root_translation: Vec<[f64; 3]>,
    /// Seconds per frame.
    pub frame_time: f64,
    /// Which joints are End Sites.
    pub end_sites: Vec<bool>,
}

impl ClipArrays {
    /// The arrays, borrowed, as [`Clip::from_rotations`] takes them.
    pub fn as_input(&self) -> RotationArrays<'_> {
        RotationArrays {
            joint_names: &self.joint_names,
            parents: &self.parents,
            offsets: &self.offsets,
            rotations: &self.rotations,
            root_translation: &self.root_translation,
            frame_time: self.frame_time,
            end_sites: Some(&self.end_sites),
        }
    }
}

/// How far a rotation's quaternion may be from unit length.
const UNIT_TOLERANCE: f64 = 1e-6;

/// A motion as arrays, Y up, meters: the input of [`Clip::from_rotations`].
#[derive(Debug, Clone, Copy)]
pub struct RotationArrays<'a> {
    /// The joints' names.
    pub joint_names: &'a [String],
    /// Each joint's parent index, `-1` for the root; parents come before their children.
    pub parents: &'a [i64],
    /// Each joint's offset from its parent, meters.
    pub offsets: &'a [[f64; 3]],
    /// Each frame's local rotations, joint after joint, as unit quaternions `(w, x, y, z)`
    /// (an End Site's is ignored).
    pub rotations: &'a [[f64; 4]],
    /// The root's world position on each frame, meters.
    pub root_translation: &'a [[f64; 3]],
    /// Seconds per frame.
    pub frame_time: f64,
    /// Which joints are End Sites (no rotation); none when not given.
    pub end_sites: Option<&'a [bool]>,
}

impl Clip {
    /// The clip as arrays of local rotations ([`Clip::from_rotations`]'s inverse up to the
    /// channels: the same world positions on every frame).
    pub fn to_rotations(&self) -> ClipArrays {
        let skeleton = self.skeleton();
        let w = skeleton.world_from_file();
        let joints = skeleton.joints();
        let mut rotations = Vec::with_capacity(self.frame_count() * joints.len());
        let mut root_translation = Vec::with_capacity(self.frame_count());
        for pose in self.frames() {
            for j in 0..joints.len() {
                let local = skeleton.local_transform(j, pose);
                if j == 0 {
                    root_translation.push(local.translation.vector.into());
                }
                let q = UnitQuaternion::from_rotation_matrix(&local.rotation);
                rotations.push([q.w, q.i, q.j, q.k]);
            }
        }
        ClipArrays {
            joint_names: joints.iter().map(|j| j.name.clone()).collect(),
            parents: joints
                .iter()
                .map(|j| j.parent.map_or(-1, |p| p as i64))
                .collect(),
            offsets: joints
                .iter()
                .map(|j| match j.parent {
                    None => (w * j.offset).into(),
                    Some(_) => j.offset.into(),
                })
                .collect(),
            rotations,
            root_translation,
            frame_time: self.frame_time(),
            end_sites: joints.iter().map(|j| j.end_site).collect(),
        }
    }

    /// The clip of `arrays`: every joint but End Sites gets three rotation channels (Z, X,
    /// Y), the root also three position channels, and each joint's Euler angles stay
    /// continuous from frame to frame (the nearest of the equivalent triples).
    ///
    /// Refused, naming the array and index: lengths that disagree, a parent that is not an
    /// earlier joint, a rotation that is not a unit quaternion.
    pub fn from_rotations(arrays: RotationArrays<'_>) -> Result<Clip> {
        let n = arrays.joint_names.len();
        let invalid = |what: &'static str, why: String| MotionError::Invalid { what, why };
        if arrays.parents.len() != n {
            let why = format!("{} parents for {n} joint names", arrays.parents.len());
            return Err(invalid("parents", why));
        }
        if arrays.offsets.len() != n {
            let why = format!("{} offsets for {n} joint names", arrays.offsets.len());
            return Err(invalid("offsets", why));
        }
        let frames = arrays.root_translation.len();
        if frames == 0 {
            return Err(MotionError::EmptyClip);
        }
        if arrays.rotations.len() != frames * n {
            let why = format!(
                "{} rotations for {frames} frames of {n} joints",
                arrays.rotations.len()
            );
            return Err(invalid("rotations", why));
        }
        let no_end_sites = vec![false; n];
        let end_sites = arrays.end_sites.unwrap_or(&no_end_sites);
        if end_sites.len() != n {
            let why = format!("{} end sites for {n} joints", end_sites.len());
            return Err(invalid("end_sites", why));
        }
        let skeleton = Arc::new(Skeleton::new(joints(arrays, end_sites)?)?);
        let mut values = Vec::with_capacity(frames * skeleton.dof_count());
        let mut previous = vec![[0.0; 3]; n];
        for f in 0..frames {
            for (i, joint) in skeleton.joints().iter().enumerate() {
                if joint.parent.is_none() {
                    let root = arrays.root_translation[f];
                    values.extend((0..3).map(|a| root[a] - joint.offset[a]));
                }
                if joint.end_site {
                    continue;
                }
                let [w, x, y, z] = arrays.rotations[f * n + i];
                let norm = (w * w + x * x + y * y + z * z).sqrt();
                if !(norm.is_finite() && (norm - 1.0).abs() < UNIT_TOLERANCE) {
                    let why = format!(
                        "rotations[{f}, {i}] ({}) is not a unit quaternion (norm {norm})",
                        joint.name
                    );
                    return Err(invalid("rotations", why));
                }
                let r: Rotation3<f64> =
                    UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z))
                        .to_rotation_matrix();
                let angles = euler_angles(ZXY, &r)
                    .ok_or_else(|| invalid("rotation axes", "Z, X, Y are distinct".to_string()))?;
                let angles = if f == 0 {
                    angles
                } else {
                    nearest_euler(angles, previous[i])
                };
                previous[i] = angles;
                values.extend(angles);
            }
        }
        Clip::new(skeleton, arrays.frame_time, values)
    }
}

/// The order of every joint's rotation channels.
const ZXY: [Axis; 3] = [Axis::Z, Axis::X, Axis::Y];

/// The joints of `arrays`, their parents checked.
fn joints(arrays: RotationArrays<'_>, end_sites: &[bool]) -> Result<Vec<Joint>> {
    let mut joints = Vec::with_capacity(arrays.joint_names.len());
    for (i, name) in arrays.joint_names.iter().enumerate() {
        let parent = match arrays.parents[i] {
            -1 => None,
            p if p >= 0 && (p as usize) < i => Some(p as usize),
            p => {
                return Err(MotionError::Invalid {
                    what: "parents",
                    why: format!(
                        "parents[{i}] = {p}: expected -1 (the root) or the index of an earlier joint"
                    ),
                });
            }
        };
        let mut dofs = Vec::new();
        if parent.is_none() {
            dofs.extend([Axis::X, Axis::Y, Axis::Z].map(Dof::Translation));
        }
        if !end_sites[i] {
            dofs.extend(ZXY.map(Dof::Rotation));
        }
        joints.push(Joint {
            name: name.clone(),
            parent,
            offset: Vector3::from(arrays.offsets[i]),
            dofs,
            end_site: end_sites[i],
            position_reading: PositionReading::AddToOffset,
        });
    }
    Ok(joints)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    /// A two-joint arm turned about Y by θ(t): its clip's FK puts the child where the
    /// rotation of its offset says (a closed form), and the angles stay continuous through
    /// ±180°.
    #[test]
    fn a_turning_bone_lands_where_its_rotation_puts_it_and_stays_continuous() {
        let names = ["root".to_string(), "tip".to_string()];
        let frames = 40;
        let angles: Vec<f64> = (0..frames).map(|f| 0.2 * f as f64).collect();
        let rotations: Vec<[f64; 4]> = angles
            .iter()
            .flat_map(|&a| {
                let q = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), a);
                [[q.w, q.i, q.j, q.k], [1.0, 0.0, 0.0, 0.0]]
            })
            .collect();
        let root: Vec<[f64; 3]> = (0..frames).map(|f| [0.0, 1.0, 0.01 * f as f64]).collect();
        let clip = Clip::from_rotations(RotationArrays {
            joint_names: &names,
            parents: &[-1, 0],
            offsets: &[[0.0, 0.0, 0.0], [0.5, 0.0, 0.0]],
            rotations: &rotations,
            root_translation: &root,
            frame_time: 1.0 / 30.0,
            end_sites: Some(&[false, true]),
        })
        .unwrap();
        let mut world = Vec::new();
        let mut last_y = 0.0;
        for (f, &a) in angles.iter().enumerate() {
            clip.skeleton()
                .fk_into(clip.frame(f).unwrap(), &mut world)
                .unwrap();
            let tip = world[1].translation.vector;
            assert_relative_eq!(tip.x, 0.5 * a.cos(), epsilon = 1e-12);
            assert_relative_eq!(tip.z, root[f][2] - 0.5 * a.sin(), epsilon = 1e-12);
            // The root's Y rotation (its third rotation channel) unwraps past π.
            let y = clip.frame(f).unwrap()[5];
            assert!(
                f == 0 || (y - last_y).abs() < 0.5,
                "frame {f}: {last_y} → {y}"
            );
            last_y = y;
        }
        assert!(last_y > std::f64::consts::PI);
    }

    /// A real capture (Z-up, centimeters, End Sites) to arrays and back: every joint's world
    /// position on every frame is where it was.
    #[test]
    fn a_capture_round_trips_through_its_arrays() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/006_14.bvh");
        let (clip, _) = crate::read_clip(std::path::Path::new(path), &Default::default()).unwrap();
        let arrays = clip.to_rotations();
        let back = Clip::from_rotations(arrays.as_input()).unwrap();
        assert_eq!(back.frame_count(), clip.frame_count());
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for f in 0..clip.frame_count() {
            clip.skeleton()
                .fk_into(clip.frame(f).unwrap(), &mut a)
                .unwrap();
            back.skeleton()
                .fk_into(back.frame(f).unwrap(), &mut b)
                .unwrap();
            for (x, y) in a.iter().zip(&b) {
                let gap = (x.translation.vector - y.translation.vector).norm();
                assert!(gap < 1e-9, "frame {f}: {gap} m");
            }
        }
        assert_eq!(back.to_rotations().parents, arrays.parents);
    }

    #[test]
    fn arrays_that_disagree_are_refused_naming_the_array() {
        let names = ["a".to_string(), "b".to_string()];
        let one = [[1.0, 0.0, 0.0, 0.0]; 2];
        let base = RotationArrays {
            joint_names: &names,
            parents: &[-1, 0],
            offsets: &[[0.0; 3]; 2],
            rotations: &one,
            root_translation: &[[0.0; 3]],
            frame_time: 0.1,
            end_sites: None,
        };
        let message = |a: RotationArrays<'_>| Clip::from_rotations(a).unwrap_err().to_string();
        assert!(
            message(RotationArrays {
                parents: &[-1, 1],
                ..base
            })
            .contains("parents[1] = 1")
        );
        assert!(
            message(RotationArrays {
                parents: &[-1],
                ..base
            })
            .contains("1 parents")
        );
        let skewed = [[1.0, 0.0, 0.0, 0.0], [2.0, 0.0, 0.0, 0.0]];
        assert!(
            message(RotationArrays {
                rotations: &skewed,
                ..base
            })
            .contains("rotations[0, 1] (b) is not a unit quaternion")
        );
        assert!(
            message(RotationArrays {
                rotations: &one[..1],
                ..base
            })
            .contains("1 rotations")
        );
    }
}
