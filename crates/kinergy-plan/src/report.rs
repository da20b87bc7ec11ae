//! What a task's report says of the objects it moved: each object's world pose on every
//! frame of the motion, as `kinergy plan --json` writes it and `kinergy animate --report`
//! reads it back — one definition for both sides, so the two cannot drift apart.
//!
//! A pose is a position in meters and a rotation as a quaternion `[x, y, z, w]`. Reading is
//! lenient where older or hand-written reports differ (`start`, `end`, `poses` and
//! `frame_time_s` may be missing; other fields are ignored) and strict where drawing depends on
//! it: [`MovedObjects::frame_time`] and [`ObjectReport::track`] check what they return.
//!
//! ```
//! use kinergy_plan::report::MovedObjects;
//!
//! let text = r#"{"frame_time_s": 0.5, "objects": [{"name": "book",
//!     "poses": [{"position_m": [0, 1, 0], "rotation_xyzw": [0, 0, 0, 1]}]}]}"#;
//! let moved = MovedObjects::parse(text)?;
//! assert_eq!(moved.frame_time()?, 0.5);
//! let track = moved.objects[0].track()?;
//! assert_eq!(track[0].translation.vector.y, 1.0);
//! # Ok::<(), kinergy_plan::PlanError>(())
//! ```

use nalgebra::{Isometry3, Quaternion, Translation3, UnitQuaternion};
use serde::{Deserialize, Serialize};

use crate::error::{PlanError, Result};
use crate::task::ObjectTrack;

/// The most poses an object's track may hold (a plan of an hour at 1000 Hz is fewer).
pub const MAX_OBJECT_POSES: usize = 4_000_000;

/// A world pose as a report writes it.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
// The name reading errors quote ("expected struct PlanPose"), as they always have.
#[serde(rename = "PlanPose")]
pub struct PoseRecord {
    /// The position, world meters.
    pub position_m: [f64; 3],
    /// The rotation as a quaternion `[x, y, z, w]`.
    pub rotation_xyzw: [f64; 4],
}

impl From<&Isometry3<f64>> for PoseRecord {
    fn from(p: &Isometry3<f64>) -> PoseRecord {
        let q = p.rotation.coords;
        PoseRecord {
            position_m: p.translation.vector.into(),
            rotation_xyzw: [q.x, q.y, q.z, q.w],
        }
    }
}

impl PoseRecord {
    /// The pose, or `None` when a number is not finite or the quaternion is (nearly) zero.
    pub fn to_isometry(&self) -> Option<Isometry3<f64>> {
        let [x, y, z] = self.position_m;
        let [qx, qy, qz, qw] = self.rotation_xyzw;
        let q = Quaternion::new(qw, qx, qy, qz);
        let finite = self
            .position_m
            .iter()
            .chain(&self.rotation_xyzw)
            .all(|v| v.is_finite());
        if !finite || q.norm() < 1e-9 {
            return None;
        }
        Some(Isometry3::from_parts(
            Translation3::new(x, y, z),
            UnitQuaternion::from_quaternion(q),
        ))
    }
}

/// An object a task moved: where it started, where it ended, and its pose on every frame.
///
/// Written, every field is present. Read, `start` and `end` are optional (they repeat the
/// first and last pose) and `poses` is `None` in reports written before it existed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename = "PlanObject")]
pub struct ObjectReport {
    /// The scene object.
    pub name: String,
    /// Its pose on the first frame.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub start: Option<PoseRecord>,
    /// Its pose on the last frame.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub end: Option<PoseRecord>,
    /// Its world pose on every frame of the motion (`kinergy animate --report` draws it
    /// moving with the hand).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub poses: Option<Vec<PoseRecord>>,
}

impl ObjectReport {
    /// The report of a moved object's track; `None` for a track without poses.
    pub fn of(track: &ObjectTrack) -> Option<ObjectReport> {
        Some(ObjectReport {
            name: track.name.clone(),
            start: Some(track.poses.first()?.into()),
            end: Some(track.poses.last()?.into()),
            poses: Some(track.poses.iter().map(PoseRecord::from).collect()),
        })
    }

    /// The object's pose on every frame, checked: present (else
    /// [`PlanError::ReportNoPoses`]), 1 to [`MAX_OBJECT_POSES`] of them
    /// ([`PlanError::ReportPoseCount`]), each finite with a non-zero rotation
    /// ([`PlanError::ReportPose`]).
    pub fn track(&self) -> Result<Vec<Isometry3<f64>>> {
        let poses = self
            .poses
            .as_ref()
            .ok_or_else(|| PlanError::ReportNoPoses {
                object: self.name.clone(),
            })?;
        if poses.is_empty() || poses.len() > MAX_OBJECT_POSES {
            return Err(PlanError::ReportPoseCount {
                object: self.name.clone(),
                count: poses.len(),
                max: MAX_OBJECT_POSES,
            });
        }
        poses
            .iter()
            .enumerate()
            .map(|(index, p)| {
                p.to_isometry().ok_or_else(|| PlanError::ReportPose {
                    object: self.name.clone(),
                    index,
                })
            })
            .collect()
    }
}

/// The part of a task's report that says how its objects moved: the frame time and the
/// moved objects (what `kinergy animate --report` reads of a `kinergy plan --json` report).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(rename = "PlanReport")]
pub struct MovedObjects {
    /// Seconds per frame; `None` in reports written before it was recorded.
    pub frame_time_s: Option<f64>,
    /// The objects that moved.
    #[serde(default)]
    pub objects: Vec<ObjectReport>,
}

impl MovedObjects {
    /// Reads the moved objects of a report's JSON `text` ([`PlanError::ReportJson`] when it
    /// is not one).
    pub fn parse(text: &str) -> Result<MovedObjects> {
        serde_json::from_str(text).map_err(|e| PlanError::ReportJson {
            why: kinergy_io::clip_text(&e.to_string(), 120).into_owned(),
        })
    }

    /// The frame time, checked: present ([`PlanError::ReportNoFrameTime`]), finite and > 0
    /// ([`PlanError::ReportFrameTime`]).
    pub fn frame_time(&self) -> Result<f64> {
        let frame_time = self.frame_time_s.ok_or(PlanError::ReportNoFrameTime)?;
        if frame_time.is_finite() && frame_time > 0.0 {
            Ok(frame_time)
        } else {
            Err(PlanError::ReportFrameTime(frame_time))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_track_round_trips_through_its_report() {
        let poses = vec![
            Isometry3::translation(0.1, 1.2, 0.3),
            Isometry3::new(
                nalgebra::Vector3::new(-0.2, 1.5, 0.5),
                nalgebra::Vector3::new(0.0, 0.7, 0.0),
            ),
        ];
        let track = ObjectTrack {
            name: "book".into(),
            poses: poses.clone(),
        };
        let report = ObjectReport::of(&track).expect("poses");
        assert_eq!(report.start, Some(PoseRecord::from(&poses[0])));
        assert_eq!(report.end, Some(PoseRecord::from(&poses[1])));
        let text = format!(
            r#"{{"frame_time_s": 0.25, "objects": [{}]}}"#,
            serde_json::to_string(&report).expect("json")
        );
        let read = MovedObjects::parse(&text).expect("parses");
        assert_eq!(read.objects, [report]);
        let back = read.objects[0].track().expect("track");
        for (a, b) in back.iter().zip(&poses) {
            assert!((a.to_homogeneous() - b.to_homogeneous()).norm() < 1e-12);
        }
    }

    #[test]
    fn bad_reports_say_what_is_wrong() {
        assert!(matches!(
            MovedObjects::parse("{\"objects\": 5}"),
            Err(PlanError::ReportJson { .. })
        ));
        let old = MovedObjects::parse(r#"{"objects": [{"name": "a"}]}"#).expect("parses");
        assert!(matches!(
            old.frame_time(),
            Err(PlanError::ReportNoFrameTime)
        ));
        assert!(matches!(
            old.objects[0].track(),
            Err(PlanError::ReportNoPoses { .. })
        ));
        let zero = MovedObjects::parse(
            r#"{"frame_time_s": 0, "objects": [{"name": "a", "poses": [
                {"position_m": [0, 0, 0], "rotation_xyzw": [0, 0, 0, 0]}]}]}"#,
        )
        .expect("parses");
        assert!(matches!(
            zero.frame_time(),
            Err(PlanError::ReportFrameTime(_))
        ));
        assert!(matches!(
            zero.objects[0].track(),
            Err(PlanError::ReportPose { index: 0, .. })
        ));
    }
}
