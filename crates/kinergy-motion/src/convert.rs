//! BVH ↔ skeleton and clip: units, degrees ↔ radians, and the reading of position channels.
//!
//! # How position channels are read
//! The format does not say whether a joint's position channels *replace* its `OFFSET` or are
//! *added* to it, and real files do both: Blender's importer (and Bandai Namco's non-root
//! joints, whose channels repeat their OFFSET) replace it; Character Creator exports expect
//! OFFSET + channels on the root. [`PositionReadingChoice::Auto`] decides per joint from the
//! first frame: when the channel values are closer to the OFFSET than to zero, they hold the
//! translation itself (replace); otherwise they are a displacement (add). A zero OFFSET makes
//! both readings equal (reported as add). The choice is recorded on each joint
//! ([`crate::PositionReading`]) so export writes the channels back the same way.

use std::path::Path;
use std::sync::Arc;

use kinergy_bvh::{Bvh, Channel};
use nalgebra::Vector3;

use crate::clip::Clip;
use crate::error::{MotionError, Result};
use crate::rotation::Axis;
use crate::skeleton::{Dof, Joint, PositionReading, Skeleton};
use crate::units::{LengthUnit, UnitChoice};

/// How to read a joint's position channels relative to its `OFFSET`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum PositionReadingChoice {
    /// Decide per joint from the first frame (see the [module docs](self)).
    #[default]
    Auto,
    /// Every joint: OFFSET + channels.
    Add,
    /// Every joint: the channels replace the OFFSET on their axes.
    Replace,
}

impl std::str::FromStr for PositionReadingChoice {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "auto" => Ok(PositionReadingChoice::Auto),
            "add" => Ok(PositionReadingChoice::Add),
            "replace" => Ok(PositionReadingChoice::Replace),
            _ => Err(format!(
                "unknown position reading `{s}`: expected auto, add or replace"
            )),
        }
    }
}

/// Options for reading a BVH document into a [`Clip`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ImportOptions {
    /// The file's length unit, or a guess from the skeleton's size.
    pub unit: UnitChoice,
    /// How position channels combine with OFFSETs.
    pub position_reading: PositionReadingChoice,
}

/// What the import decided.
#[derive(Debug, Clone, PartialEq)]
pub struct ImportReport {
    /// The unit the file was read in.
    pub unit: LengthUnit,
    /// True when [`ImportReport::unit`] was guessed.
    pub unit_guessed: bool,
    /// The largest extent of the skeleton along a world axis in the first frame, in the
    /// file's units (what the guess looked at).
    pub extent_in_file_units: f64,
    /// For every joint with position channels: its name and how they were read.
    pub position_readings: Vec<(String, PositionReading)>,
}

impl ImportReport {
    /// How the root's position channels were read, if it has any.
    pub fn root_reading(&self) -> Option<PositionReading> {
        self.position_readings.first().map(|(_, r)| *r)
    }
}

fn channel_dof(c: Channel) -> Dof {
    let axis = Axis::from_index(c.axis());
    if c.is_rotation() {
        Dof::Rotation(axis)
    } else {
        Dof::Translation(axis)
    }
}

fn dof_channel(d: Dof) -> Channel {
    match d {
        Dof::Translation(Axis::X) => Channel::Xposition,
        Dof::Translation(Axis::Y) => Channel::Yposition,
        Dof::Translation(Axis::Z) => Channel::Zposition,
        Dof::Rotation(Axis::X) => Channel::Xrotation,
        Dof::Rotation(Axis::Y) => Channel::Yrotation,
        Dof::Rotation(Axis::Z) => Channel::Zrotation,
    }
}

fn auto_reading(joint: &kinergy_bvh::Joint, first_frame: &[f64]) -> PositionReading {
    let mut to_offset = 0.0;
    let mut to_zero = 0.0;
    let mut any_offset = false;
    for (k, c) in joint.channels.iter().enumerate() {
        if c.is_position() {
            let v = first_frame
                .get(joint.first_channel + k)
                .copied()
                .unwrap_or(0.0);
            let o = joint.offset[c.axis()];
            any_offset |= o != 0.0;
            to_offset += (v - o) * (v - o);
            to_zero += v * v;
        }
    }
    if any_offset && to_offset < to_zero {
        PositionReading::ReplaceOffset
    } else {
        PositionReading::AddToOffset
    }
}

/// Reads a BVH document as a clip in SI units (meters, radians).
pub fn clip_from_bvh(bvh: &Bvh, options: &ImportOptions) -> Result<(Clip, ImportReport)> {
    let first_frame = bvh.frame(0).unwrap_or(&[]);
    let mut names = std::collections::HashMap::new();
    let mut readings = Vec::new();
    let mut joints = Vec::with_capacity(bvh.joints.len());
    for (i, bj) in bvh.joints.iter().enumerate() {
        let name = match (&bj.name, bj.parent) {
            (Some(n), _) => n.clone(),
            (None, Some(p)) => {
                let parent = bvh.joints[p].display_name();
                let mut name = format!("{parent}_End");
                let mut k = 2;
                while names.contains_key(&name) {
                    name = format!("{parent}_End{k}");
                    k += 1;
                }
                name
            }
            (None, None) => format!("joint{i}"),
        };
        names.insert(name.clone(), i);
        let has_position = bj.channels.iter().any(|c| c.is_position());
        let reading = match options.position_reading {
            PositionReadingChoice::Add => PositionReading::AddToOffset,
            PositionReadingChoice::Replace => PositionReading::ReplaceOffset,
            PositionReadingChoice::Auto => auto_reading(bj, first_frame),
        };
        if has_position {
            readings.push((name.clone(), reading));
        }
        joints.push(Joint {
            name,
            parent: bj.parent,
            offset: Vector3::from(bj.offset),
            dofs: bj.channels.iter().map(|&c| channel_dof(c)).collect(),
            end_site: bj.end_site,
            position_reading: reading,
        });
    }

    // Pose values in file units and radians; positions made relative to the OFFSET where the
    // channels replace it.
    let per_joint: Vec<(usize, &kinergy_bvh::Joint, PositionReading)> = bvh
        .joints
        .iter()
        .zip(&joints)
        .map(|(bj, j)| (bj.first_channel, bj, j.position_reading))
        .collect();
    let convert_frame = |frame: &[f64], scale: f64, out: &mut Vec<f64>| {
        for &(first, bj, reading) in &per_joint {
            for (k, c) in bj.channels.iter().enumerate() {
                let v = frame.get(first + k).copied().unwrap_or(0.0);
                out.push(if c.is_rotation() {
                    v.to_radians()
                } else if reading == PositionReading::ReplaceOffset {
                    (v - bj.offset[c.axis()]) * scale
                } else {
                    v * scale
                });
            }
        }
    };

    // The unit guess looks at the first frame's extent in file units.
    let file_skeleton = Skeleton::new(joints.clone())?;
    let mut first_pose = Vec::with_capacity(file_skeleton.dof_count());
    convert_frame(first_frame, 1.0, &mut first_pose);
    let extent = if bvh.frame_count > 0 {
        file_skeleton.extent(&first_pose)?
    } else {
        file_skeleton.extent(&file_skeleton.rest_pose())?
    };
    let (unit, guessed) = match options.unit {
        UnitChoice::Fixed(u) => (u, false),
        UnitChoice::Auto => (
            LengthUnit::guess_from_extent(extent).unwrap_or(LengthUnit::Centimeter),
            true,
        ),
    };
    let scale = unit.meters();
    for j in &mut joints {
        j.offset *= scale;
    }
    let skeleton = Arc::new(Skeleton::new(joints)?);
    let n = bvh.channel_count();
    let mut values = Vec::with_capacity(bvh.frame_count * n);
    for f in 0..bvh.frame_count {
        convert_frame(bvh.frame(f).unwrap_or(&[]), scale, &mut values);
    }
    let clip = Clip::new(skeleton, bvh.frame_time, values)?;
    Ok((
        clip,
        ImportReport {
            unit,
            unit_guessed: guessed,
            extent_in_file_units: extent,
            position_readings: readings,
        },
    ))
}

/// Reads a BVH file as a clip; errors name the file (and line, for parse errors).
pub fn read_clip(path: &Path, options: &ImportOptions) -> Result<(Clip, ImportReport)> {
    let bvh = kinergy_bvh::read_file(path, &kinergy_bvh::ReadOptions::default())?;
    clip_from_bvh(&bvh, options)
}

/// Options for writing a clip as BVH.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ExportOptions {
    /// The length unit of the written file (centimeters unless told otherwise).
    pub unit: LengthUnit,
}

impl Default for ExportOptions {
    fn default() -> Self {
        ExportOptions {
            unit: LengthUnit::Centimeter,
        }
    }
}

/// The clip as a BVH document: degrees, `options.unit`, and each joint's position channels
/// written the way they were read ([`crate::PositionReading`]).
pub fn clip_to_bvh(clip: &Clip, options: &ExportOptions) -> Bvh {
    let s = clip.skeleton();
    let scale = 1.0 / options.unit.meters();
    let mut first = 0;
    let joints: Vec<kinergy_bvh::Joint> = s
        .joints()
        .iter()
        .map(|j| {
            let channels: Vec<Channel> = j.dofs.iter().map(|&d| dof_channel(d)).collect();
            let bj = kinergy_bvh::Joint {
                name: (!j.end_site).then(|| j.name.clone()),
                parent: j.parent,
                offset: (j.offset * scale).into(),
                channels,
                first_channel: first,
                end_site: j.end_site,
                line: 0,
            };
            first += j.dofs.len();
            bj
        })
        .collect();
    let mut motion = Vec::with_capacity(clip.values().len());
    for pose in clip.frames() {
        for (ji, j) in s.joints().iter().enumerate() {
            for (k, d) in j.dofs.iter().enumerate() {
                let v = pose[s.first_dof(ji) + k];
                motion.push(match d {
                    Dof::Rotation(_) => v.to_degrees(),
                    Dof::Translation(a) => match j.position_reading {
                        PositionReading::AddToOffset => v * scale,
                        PositionReading::ReplaceOffset => (v + j.offset[a.index()]) * scale,
                    },
                });
            }
        }
    }
    Bvh {
        joints,
        frame_time: clip.frame_time(),
        frame_count: clip.frame_count(),
        motion,
    }
}

/// Writes a clip as a BVH file, atomically (a temporary file renamed into place).
pub fn write_clip(path: &Path, clip: &Clip, options: &ExportOptions) -> Result<()> {
    kinergy_bvh::write_file(path, &clip_to_bvh(clip, options)).map_err(MotionError::from)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    const SMALL: &str = "HIERARCHY
ROOT Hips
{
  OFFSET 0 100 0
  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
  JOINT Chest
  {
    OFFSET 0 50 0
    CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation
    JOINT Head
    {
      OFFSET 0 60 0
      CHANNELS 3 Yrotation Xrotation Zrotation
      End Site
      {
        OFFSET 0 30 0
      }
    }
  }
}
MOTION
Frames: 2
Frame Time: 0.0333333
1 2 3 10 20 30 0 50 0 5 0 0 0 0 0
0 -1 0 0 0 0 0 50 0 0 0 0 90 0 0
";

    #[test]
    fn reads_add_root_and_replace_child_automatically() {
        let bvh = kinergy_bvh::parse(SMALL).expect("parse");
        let (clip, report) = clip_from_bvh(&bvh, &ImportOptions::default()).expect("clip");
        assert_eq!(report.unit, LengthUnit::Centimeter);
        assert!(report.unit_guessed);
        assert_eq!(
            report.position_readings,
            vec![
                ("Hips".to_string(), PositionReading::AddToOffset),
                ("Chest".to_string(), PositionReading::ReplaceOffset),
            ]
        );
        let p = clip
            .skeleton()
            .world_positions(clip.frame(1).expect("frame"))
            .expect("fk");
        // Root at OFFSET + channels = (0, 99, 0) cm; chest 50 cm above; head 60 more;
        // the head's 90° yaw leaves its End Site straight above.
        assert_relative_eq!(p[0].coords, Vector3::new(0.0, 0.99, 0.0), epsilon = 1e-12);
        assert_relative_eq!(p[3].coords, Vector3::new(0.0, 2.39, 0.0), epsilon = 1e-12);
        assert_eq!(clip.skeleton().joint(3).name, "Head_End");
    }

    #[test]
    fn export_writes_channels_back_as_read() {
        let bvh = kinergy_bvh::parse(SMALL).expect("parse");
        let (clip, _) = clip_from_bvh(&bvh, &ImportOptions::default()).expect("clip");
        let out = clip_to_bvh(&clip, &ExportOptions::default());
        for (a, b) in bvh.motion.iter().zip(&out.motion) {
            assert_relative_eq!(a, b, epsilon = 1e-9);
        }
        assert_eq!(out.joints[3].name, None);
    }

    #[test]
    fn forced_readings_and_units() {
        let bvh = kinergy_bvh::parse(SMALL).expect("parse");
        let opts = ImportOptions {
            unit: UnitChoice::Fixed(LengthUnit::Meter),
            position_reading: PositionReadingChoice::Replace,
        };
        let (clip, report) = clip_from_bvh(&bvh, &opts).expect("clip");
        assert!(!report.unit_guessed);
        let p = clip
            .skeleton()
            .world_positions(clip.frame(1).expect("frame"))
            .expect("fk");
        assert_relative_eq!(p[0].coords, Vector3::new(0.0, -1.0, 0.0), epsilon = 1e-12);
    }
}
