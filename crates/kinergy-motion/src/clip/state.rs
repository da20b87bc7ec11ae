//! A clip's exact state as plain data ([`ClipState`]): what pickling, caches and messages
//! between processes carry. Every value round-trips bit for bit (serde_json's
//! `float_roundtrip`), unlike BVH text, whose unit and up axis are a reading's choice.

use std::sync::Arc;

use nalgebra::{Matrix3, Rotation3, Vector3};
use serde::{Deserialize, Serialize};

use super::Clip;
use crate::error::{MotionError, Result};
use crate::skeleton::{Dof, Joint, PositionReading, Skeleton};

/// One joint of a [`ClipState`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointState {
    /// The joint's name.
    pub name: String,
    /// Its parent's index (none for the root).
    pub parent: Option<usize>,
    /// Its offset from the parent, meters in the file's frame.
    pub offset: [f64; 3],
    /// Its BVH channels, in order (`Zrotation`, …).
    pub channels: Vec<String>,
    /// An End Site.
    pub end_site: bool,
    /// How its position channels read: `add` or `replace`.
    pub reading: String,
}

/// A clip as plain data: its skeleton, the rotation from the file's frame into the Y-up
/// world (column-major), the frame time and the pose values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClipState {
    /// The joints, parents first.
    pub joints: Vec<JointState>,
    /// The world-from-file rotation, column-major.
    pub world_from_file: [f64; 9],
    /// Seconds per frame.
    pub frame_time: f64,
    /// The pose values, frame after frame.
    pub values: Vec<f64>,
}

impl Clip {
    /// The clip's state ([`Clip::from_state`] gives it back exactly).
    pub fn state(&self) -> ClipState {
        let skeleton = self.skeleton();
        let mut world_from_file = [0.0; 9];
        world_from_file.copy_from_slice(skeleton.world_from_file().matrix().as_slice());
        ClipState {
            joints: skeleton
                .joints()
                .iter()
                .map(|j| JointState {
                    name: j.name.clone(),
                    parent: j.parent,
                    offset: j.offset.into(),
                    channels: j.dofs.iter().map(|d| d.channel_name().into()).collect(),
                    end_site: j.end_site,
                    reading: j.position_reading.name().into(),
                })
                .collect(),
            world_from_file,
            frame_time: self.frame_time(),
            values: self.values().to_vec(),
        }
    }

    /// The clip of `state`, checked as any clip is (an unknown channel or reading, a
    /// skeleton or values that do not make one are refused).
    pub fn from_state(state: ClipState) -> Result<Clip> {
        let invalid = |why: String| MotionError::Invalid {
            what: "clip state",
            why,
        };
        let mut joints = Vec::with_capacity(state.joints.len());
        for j in state.joints {
            let dofs = j
                .channels
                .iter()
                .map(|c| Dof::from_channel_name(c).ok_or_else(|| invalid(format!("channel {c:?}"))))
                .collect::<Result<Vec<_>>>()?;
            let position_reading = match j.reading.as_str() {
                "add" => PositionReading::AddToOffset,
                "replace" => PositionReading::ReplaceOffset,
                other => return Err(invalid(format!("position reading {other:?}"))),
            };
            joints.push(Joint {
                name: j.name,
                parent: j.parent,
                offset: Vector3::from(j.offset),
                dofs,
                end_site: j.end_site,
                position_reading,
            });
        }
        let rotation =
            Rotation3::from_matrix_unchecked(Matrix3::from_column_slice(&state.world_from_file));
        let skeleton = Skeleton::new(joints)?.with_world_from_file(rotation);
        Clip::new(Arc::new(skeleton), state.frame_time, state.values)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_z_up_capture_round_trips_bit_for_bit_through_its_state_as_json() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/006_14.bvh");
        let options = crate::ImportOptions {
            up: "z".parse().unwrap(),
            ..Default::default()
        };
        let (clip, _) = crate::read_clip(std::path::Path::new(path), &options).unwrap();
        let text = serde_json::to_string(&clip.state()).unwrap();
        let back = Clip::from_state(serde_json::from_str(&text).unwrap()).unwrap();
        assert_eq!(back.skeleton(), clip.skeleton());
        assert_eq!(back.frame_time().to_bits(), clip.frame_time().to_bits());
        assert!(
            back.values()
                .iter()
                .zip(clip.values())
                .all(|(a, b)| a.to_bits() == b.to_bits())
        );
    }

    #[test]
    fn a_damaged_state_is_refused_by_name() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/../../tests/data/006_14.bvh");
        let (clip, _) = crate::read_clip(std::path::Path::new(path), &Default::default()).unwrap();
        let mut state = clip.state();
        state.joints[1].channels[0] = "Wrotation".into();
        let e = Clip::from_state(state).unwrap_err().to_string();
        assert!(e.contains("clip state") && e.contains("Wrotation"), "{e}");
        let mut state = clip.state();
        state.values.pop();
        assert!(Clip::from_state(state).is_err());
    }
}
