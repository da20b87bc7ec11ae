//! Which way is up in a capture, and the fixed rotation that reads it into Kinergy's Y-up
//! world.
//!
//! Most BVH files are Y-up, but Z-up (3ds Max, Blender-made, some research rigs) and X-up
//! files exist, and a few are upside down. The up axis is detected from the first frame,
//! in the file's own frame:
//!
//! 1. **By joint names** ([`up_by_names`]): the head (a joint whose name has the token
//!    `head`), the feet (`foot` or `ankle`, else `toe…`) and, if there is one, the hips
//!    (`hips`, `hip` or `pelvis` without a side). The direction d = head − mean(feet) is up
//!    when the hips lie between the feet and the head along it.
//! 2. **By the body's shape** ([`up_by_shape`]), when the names say nothing: below the root,
//!    at the first joint with several children (the pelvis), the child with the most joints
//!    below it is the upper body and the others are the legs; d = centroid of the upper
//!    body − centroid of the legs.
//! 3. Otherwise +Y is assumed ([`UpDetection::Assumed`]).
//!
//! In 1 and 2 the up axis is the signed principal axis nearest d, accepted only when d
//! makes less than 45° with it (cos ≥ [`MIN_ALIGNMENT`]); a body lying down in its first
//! frame is therefore not turned upright by mistake but falls through to the next rule.
//!
//! The file's joint values are never changed: the skeleton carries the rotation
//! ([`crate::Skeleton::world_from_file`]) and applies it at the root, so writing a clip
//! back keeps the file's axis unless asked otherwise ([`crate::ExportOptions::up`]).

use std::fmt;
use std::str::FromStr;

use nalgebra::{Matrix3, Point3, Rotation3, Vector3};

use crate::limbs::name_tokens;
use crate::rotation::Axis;
use crate::skeleton::Skeleton;

/// The smallest cosine between the measured up direction and the chosen axis (45°).
pub const MIN_ALIGNMENT: f64 = std::f64::consts::FRAC_1_SQRT_2;

/// The axis of a file's frame that points up, with its sign.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum UpAxis {
    /// +Y (BVH's usual frame, Kinergy's own).
    #[default]
    Y,
    /// +Z.
    Z,
    /// +X.
    X,
    /// −Y (upside down).
    NegY,
    /// −Z.
    NegZ,
    /// −X.
    NegX,
}

impl UpAxis {
    /// Every up axis.
    pub const ALL: [UpAxis; 6] = [
        UpAxis::Y,
        UpAxis::Z,
        UpAxis::X,
        UpAxis::NegY,
        UpAxis::NegZ,
        UpAxis::NegX,
    ];

    /// The principal axis.
    pub fn axis(self) -> Axis {
        match self {
            UpAxis::X | UpAxis::NegX => Axis::X,
            UpAxis::Y | UpAxis::NegY => Axis::Y,
            UpAxis::Z | UpAxis::NegZ => Axis::Z,
        }
    }

    /// +1 or −1.
    pub fn sign(self) -> f64 {
        match self {
            UpAxis::X | UpAxis::Y | UpAxis::Z => 1.0,
            _ => -1.0,
        }
    }

    /// The unit vector pointing up, in the file's frame.
    pub fn vector(self) -> Vector3<f64> {
        self.axis().unit().into_inner() * self.sign()
    }

    /// `"y"`, `"z"`, `"x"`, `"-y"`, `"-z"` or `"-x"`.
    pub fn name(self) -> &'static str {
        match self {
            UpAxis::Y => "y",
            UpAxis::Z => "z",
            UpAxis::X => "x",
            UpAxis::NegY => "-y",
            UpAxis::NegZ => "-z",
            UpAxis::NegX => "-x",
        }
    }

    /// The rotation from the file's frame to Kinergy's Y-up world, a signed permutation
    /// (exact, no rounding) taking [`UpAxis::vector`] to +Y by a quarter or half turn:
    ///
    /// | up | (x, y, z) becomes |
    /// |---|---|
    /// | +Y | (x, y, z) |
    /// | +Z | (x, z, −y): −90° about X, so Z-up's −Y forward becomes +Z |
    /// | −Z | (x, −z, y) |
    /// | +X | (−y, x, z): +90° about Z |
    /// | −X | (y, −x, z) |
    /// | −Y | (x, −y, −z): 180° about X |
    pub fn world_from_file(self) -> Rotation3<f64> {
        #[rustfmt::skip]
        let m = match self {
            UpAxis::Y => Matrix3::identity(),
            UpAxis::Z => Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, -1.0, 0.0),
            UpAxis::NegZ => Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0),
            UpAxis::X => Matrix3::new(0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0),
            UpAxis::NegX => Matrix3::new(0.0, 1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 1.0),
            UpAxis::NegY => Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0),
        };
        Rotation3::from_matrix_unchecked(m)
    }

    /// The signed principal axis nearest the direction `d`, if `d` makes less than 45° with
    /// it ([`MIN_ALIGNMENT`]); `None` for a zero or non-finite `d` or an oblique one.
    pub fn nearest(d: &Vector3<f64>) -> Option<UpAxis> {
        let n = d.norm();
        if !(n.is_finite() && n > 0.0) {
            return None;
        }
        let k = d.iamax();
        if d[k].abs() / n < MIN_ALIGNMENT {
            return None;
        }
        let positive = d[k] > 0.0;
        Some(match (k, positive) {
            (0, true) => UpAxis::X,
            (0, false) => UpAxis::NegX,
            (1, true) => UpAxis::Y,
            (1, false) => UpAxis::NegY,
            (_, true) => UpAxis::Z,
            (_, false) => UpAxis::NegZ,
        })
    }
}

impl fmt::Display for UpAxis {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The up axis named on the command line was not one we know.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown up axis `{0}`: expected y, z, x, -y, -z, -x or auto")]
pub struct UnknownUpAxis(pub String);

impl FromStr for UpAxis {
    type Err = UnknownUpAxis;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let t = s.trim();
        let t = t.strip_prefix('+').unwrap_or(t);
        UpAxis::ALL
            .into_iter()
            .find(|u| u.name().eq_ignore_ascii_case(t))
            .ok_or_else(|| UnknownUpAxis(s.to_string()))
    }
}

/// Which up axis to read a file with: a given one, or detected from its first frame.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum UpChoice {
    /// Detect it (see the [module docs](self)).
    #[default]
    Auto,
    /// Use this one.
    Fixed(UpAxis),
}

impl UpChoice {
    /// As `--up` spells it: `auto`, `y`, `z`, `x`, `-y`, `-z` or `-x`.
    pub fn name(self) -> &'static str {
        match self {
            UpChoice::Auto => "auto",
            UpChoice::Fixed(axis) => axis.name(),
        }
    }
}

impl FromStr for UpChoice {
    type Err = UnknownUpAxis;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s.trim().eq_ignore_ascii_case("auto") {
            Ok(UpChoice::Auto)
        } else {
            s.parse().map(UpChoice::Fixed)
        }
    }
}

/// How the up axis of an import was decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum UpDetection {
    /// Given by the caller ([`UpChoice::Fixed`]).
    Given,
    /// Detected from the head, hips and feet found by name ([`up_by_names`]).
    JointNames,
    /// Detected from the body's shape ([`up_by_shape`]).
    BodyShape,
    /// Neither rule could tell; +Y assumed.
    Assumed,
}

impl UpDetection {
    /// True when the axis was detected from the data.
    pub fn detected(self) -> bool {
        matches!(self, UpDetection::JointNames | UpDetection::BodyShape)
    }

    /// `"given"`, `"joint names"`, `"body shape"` or `"assumed"`.
    pub fn name(self) -> &'static str {
        match self {
            UpDetection::Given => "given",
            UpDetection::JointNames => "joint names",
            UpDetection::BodyShape => "body shape",
            UpDetection::Assumed => "assumed",
        }
    }
}

/// The up axis of a skeleton whose joints are at `points` (its world positions in the file's
/// frame, one per joint), by the rules of the [module docs](self) in order.
pub fn detect_up(skeleton: &Skeleton, points: &[Point3<f64>]) -> (UpAxis, UpDetection) {
    if let Some(up) = up_by_names(skeleton, points) {
        (up, UpDetection::JointNames)
    } else if let Some(up) = up_by_shape(skeleton, points) {
        (up, UpDetection::BodyShape)
    } else {
        (UpAxis::Y, UpDetection::Assumed)
    }
}

fn is_side(t: &str) -> bool {
    matches!(t, "right" | "r" | "left" | "l")
}

/// The shallowest joint whose name tokens satisfy `pred`.
fn shallowest(skeleton: &Skeleton, pred: impl Fn(&[String]) -> bool) -> Option<usize> {
    (0..skeleton.joint_count())
        .filter(|&j| !skeleton.joint(j).end_site && pred(&name_tokens(&skeleton.joint(j).name)))
        .min_by_key(|&j| skeleton.path(0, j).map_or(usize::MAX, |p| p.len()))
}

fn mean(points: &[Point3<f64>], joints: impl Iterator<Item = usize>) -> Option<Vector3<f64>> {
    let (sum, n) = joints
        .filter_map(|j| points.get(j))
        .fold((Vector3::zeros(), 0usize), |(s, n), p| {
            (s + p.coords, n + 1)
        });
    (n > 0).then(|| sum / n as f64)
}

/// Up from the head, feet and hips found by name (rule 1 of the [module docs](self));
/// `None` without a head and a foot, when the hips are not between them, or when the
/// head–feet direction is oblique.
pub fn up_by_names(skeleton: &Skeleton, points: &[Point3<f64>]) -> Option<UpAxis> {
    let has = |t: &[String], words: &[&str]| t.iter().any(|x| words.contains(&x.as_str()));
    let helper = |t: &[String]| {
        t.iter().any(|x| {
            ["twist", "share", "roll", "helper"]
                .iter()
                .any(|k| x.contains(k))
        })
    };
    let head = shallowest(skeleton, |t| has(t, &["head"]))?;
    let joints = 0..skeleton.joint_count();
    let feet_by = |words: &dyn Fn(&str) -> bool| -> Vec<usize> {
        joints
            .clone()
            .filter(|&j| {
                let t = name_tokens(&skeleton.joint(j).name);
                !skeleton.joint(j).end_site && !helper(&t) && t.iter().any(|x| words(x))
            })
            .collect()
    };
    let mut feet = feet_by(&|x| matches!(x, "foot" | "ankle"));
    if feet.is_empty() {
        feet = feet_by(&|x| x.starts_with("toe"));
    }
    let feet = mean(points, feet.into_iter())?;
    let d = points.get(head)?.coords - feet;
    let up = UpAxis::nearest(&d)?;
    let hips = shallowest(skeleton, |t| {
        has(t, &["hips", "hip", "pelvis"]) && !t.iter().any(|x| is_side(x))
    });
    if let Some(h) = hips.and_then(|h| points.get(h)) {
        let along = (h.coords - feet).dot(&d) / d.norm_squared();
        if !(0.0 < along && along < 1.0) {
            return None;
        }
    }
    Some(up)
}

/// Up from the body's shape (rule 2 of the [module docs](self)): at the first joint below
/// the root with several children, the biggest child subtree (the upper body) lies above
/// the others (the legs). `None` when the skeleton never branches or the direction is
/// oblique.
pub fn up_by_shape(skeleton: &Skeleton, points: &[Point3<f64>]) -> Option<UpAxis> {
    let n = skeleton.joint_count();
    if points.len() != n {
        return None;
    }
    // Subtree sizes, children after parents so a reverse pass accumulates them.
    let mut size = vec![1usize; n];
    for j in (1..n).rev() {
        if let Some(p) = skeleton.joint(j).parent {
            size[p] += size[j];
        }
    }
    let mut branch = 0;
    let children = loop {
        let c: Vec<usize> = skeleton.children(branch).collect();
        match c.len() {
            0 => return None,
            1 => branch = c[0],
            _ => break c,
        }
    };
    let upper = *children.iter().max_by_key(|&&c| size[c])?;
    if children.iter().filter(|&&c| size[c] == size[upper]).count() > 1 {
        return None;
    }
    let subtree = |root: usize| (root..n).filter(move |&j| skeleton.is_ancestor_or_self(root, j));
    let top = mean(points, subtree(upper))?;
    let legs = mean(
        points,
        children
            .iter()
            .filter(|&&c| c != upper)
            .flat_map(|&c| subtree(c)),
    )?;
    UpAxis::nearest(&(top - legs))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::skeleton::{Joint, PositionReading};
    use approx::assert_relative_eq;

    /// A standing figure, Y-up, in meters: hips, spine to head, two legs, two arms.
    pub(crate) fn figure(names: bool) -> Skeleton {
        let j = |name: &str, parent: Option<usize>, off: [f64; 3]| Joint {
            name: name.into(),
            parent,
            offset: Vector3::from(off),
            dofs: vec![],
            end_site: false,
            position_reading: PositionReading::AddToOffset,
        };
        let n = |named: &str, k: usize| {
            if names {
                named.to_string()
            } else {
                format!("j{k}")
            }
        };
        Skeleton::new(vec![
            j(&n("Hips", 0), None, [0.0, 0.9, 0.0]),
            j(&n("Spine", 1), Some(0), [0.0, 0.3, 0.0]),
            j(&n("Head", 2), Some(1), [0.0, 0.4, 0.0]),
            j(&n("LeftArm", 3), Some(1), [0.2, 0.25, 0.0]),
            j(&n("LeftHand", 4), Some(3), [0.5, 0.0, 0.0]),
            j(&n("RightArm", 5), Some(1), [-0.2, 0.25, 0.0]),
            j(&n("RightHand", 6), Some(5), [-0.5, 0.0, 0.0]),
            j(&n("LeftUpLeg", 7), Some(0), [0.1, -0.05, 0.0]),
            j(&n("LeftFoot", 8), Some(7), [0.0, -0.85, 0.0]),
            j(&n("RightUpLeg", 9), Some(0), [-0.1, -0.05, 0.0]),
            j(&n("RightFoot", 10), Some(9), [0.0, -0.85, 0.0]),
        ])
        .expect("valid")
    }

    #[test]
    fn rotations_take_up_to_y_exactly() {
        for up in UpAxis::ALL {
            let r = up.world_from_file();
            assert_eq!(r * up.vector(), Vector3::y(), "{up}");
            assert_relative_eq!(r.matrix().determinant(), 1.0);
            assert_eq!(up.name().parse::<UpAxis>(), Ok(up));
        }
        assert_eq!("+Z".parse::<UpChoice>(), Ok(UpChoice::Fixed(UpAxis::Z)));
        assert_eq!("auto".parse::<UpChoice>(), Ok(UpChoice::Auto));
        assert!("w".parse::<UpChoice>().is_err());
    }

    #[test]
    fn detects_every_axis_by_names_and_by_shape() {
        for up in UpAxis::ALL {
            // The figure as a file with this up axis would hold it.
            let file_from_world = up.world_from_file().inverse();
            for names in [true, false] {
                let s = figure(names);
                let pts: Vec<_> = s
                    .world_positions(&s.rest_pose())
                    .expect("fk")
                    .iter()
                    .map(|p| file_from_world * p)
                    .collect();
                let expected = if names {
                    UpDetection::JointNames
                } else {
                    UpDetection::BodyShape
                };
                assert_eq!(detect_up(&s, &pts), (up, expected), "{up}, names {names}");
                assert_eq!(up_by_shape(&s, &pts), Some(up), "{up}");
            }
        }
    }

    #[test]
    fn oblique_or_shapeless_bodies_fall_back_to_y() {
        let s = figure(true);
        // Leaning along the cube's diagonal, 55° from every axis: neither rule is sure.
        let tilt = Rotation3::rotation_between(&Vector3::y(), &Vector3::new(1.0, 1.0, 1.0))
            .expect("rotation");
        let pts: Vec<_> = s
            .world_positions(&s.rest_pose())
            .expect("fk")
            .iter()
            .map(|p| tilt * p)
            .collect();
        assert_eq!(detect_up(&s, &pts), (UpAxis::Y, UpDetection::Assumed));
        assert_eq!(UpAxis::nearest(&Vector3::zeros()), None);
        let one = Skeleton::new(vec![s.joint(0).clone()]).expect("valid");
        assert_eq!(
            detect_up(&one, &[Point3::origin()]),
            (UpAxis::Y, UpDetection::Assumed)
        );
    }
}
