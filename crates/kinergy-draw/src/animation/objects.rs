//! What moves in the picture: each clip's stick figure over time, and the scene's objects,
//! fixed or moving as a plan report ([`kinergy_plan::report`]) says.

use std::path::{Path, PathBuf};

use kinergy_motion::{Clip, Skeleton};
use kinergy_plan::report::MovedObjects;
use nalgebra::{Isometry3, Point3};

use super::timing::nearest_frame;
use super::view::View;
use crate::DrawError;
use crate::bones::{BoneKind, Role, StickFigure};
use crate::shapes::Solid;

/// One clip's stick figure over time.
#[derive(Debug, Clone)]
pub struct Track {
    pub(super) label: String,
    frame_time: f64,
    joints: usize,
    /// World positions (meters), frame after frame, `joints` per frame.
    world: Vec<Point3<f64>>,
    /// What is drawn of the skeleton.
    pub(super) figure: StickFigure,
}

/// What a track draws of its skeleton on its first frame.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Drawn {
    /// Body bones drawn on the first frame.
    pub body_bones: usize,
    /// Finger bones (drawn thin) on the first frame.
    pub finger_bones: usize,
    /// Joints not drawn: a reference root and face joints.
    pub not_drawn: Vec<String>,
}

impl Track {
    /// The track of `clip`, read from `path` (errors name it), labelled `label` in the legend.
    pub fn new(clip: &Clip, path: &Path, label: String) -> Result<Track, DrawError> {
        let joints = clip.skeleton().joint_count();
        let (figure, world) = StickFigure::of_file(clip, path)?;
        Ok(Track {
            label,
            frame_time: clip.frame_time(),
            joints,
            world,
            figure,
        })
    }

    /// Its legend entry.
    pub fn label(&self) -> &str {
        &self.label
    }

    /// What is drawn of `skeleton` (the track's) on the first frame.
    pub fn drawn(&self, skeleton: &Skeleton) -> Drawn {
        let first = &self.world[..self.joints];
        let (mut body_bones, mut finger_bones) = (0, 0);
        for (_, _, kind) in self.figure.bones(first) {
            match kind {
                BoneKind::Body => body_bones += 1,
                BoneKind::Finger => finger_bones += 1,
            }
        }
        Drawn {
            body_bones,
            finger_bones,
            not_drawn: self
                .figure
                .roles()
                .iter()
                .enumerate()
                .filter(|(_, r)| matches!(r, Role::Face | Role::Reference))
                .map(|(j, _)| skeleton.joint(j).name.clone())
                .collect(),
        }
    }

    /// The pose at time `t`, seconds: the nearest frame, the last one after the end.
    pub(super) fn at(&self, t: f64) -> &[Point3<f64>] {
        let i = nearest_frame(t, self.frame_time, self.world.len() / self.joints);
        &self.world[i * self.joints..(i + 1) * self.joints]
    }

    /// The drawn joints' positions over all frames (what the view is fitted to).
    pub(super) fn drawn_points(&self) -> impl Iterator<Item = &Point3<f64>> + '_ {
        let roles = self.figure.roles();
        self.world
            .iter()
            .enumerate()
            .filter(move |(i, _)| matches!(roles[i % self.joints], Role::Body | Role::Finger))
            .map(|(_, p)| p)
    }
}

/// Where a scene object is: fixed, or on every frame of a plan.
#[derive(Debug, Clone)]
enum Placement {
    Fixed(Isometry3<f64>),
    Moving {
        frame_time: f64,
        poses: Vec<Isometry3<f64>>,
    },
}

/// One scene object ready to draw.
#[derive(Debug, Clone)]
pub struct Prop {
    name: String,
    pub(super) solid: Solid,
    placement: Placement,
}

impl Prop {
    /// The object's name in the scene.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Whether a plan moves it.
    pub fn moving(&self) -> bool {
        matches!(self.placement, Placement::Moving { .. })
    }

    /// Where it is at time `t`, seconds.
    pub(super) fn pose(&self, t: f64) -> &Isometry3<f64> {
        match &self.placement {
            Placement::Fixed(p) => p,
            Placement::Moving { frame_time, poses } => {
                &poses[nearest_frame(t, *frame_time, poses.len())]
            }
        }
    }

    /// A moving object's outline points over all its frames (the view is fitted to them).
    pub(super) fn moving_points(&self, view: View) -> Vec<(f64, f64)> {
        match &self.placement {
            Placement::Fixed(_) => Vec::new(),
            Placement::Moving { poses, .. } => poses
                .iter()
                .flat_map(|pose| {
                    let outline = self.solid.outline(pose, |p| view.project(p));
                    outline.fills.into_iter().flatten()
                })
                .collect(),
        }
    }
}

/// The scene's objects, and the mesh files the scene was read from (inputs too).
#[derive(Debug, Clone)]
pub struct Props {
    /// The objects to draw.
    pub props: Vec<Prop>,
    /// The scene's mesh files.
    pub meshes: Vec<PathBuf>,
}

/// Reads the scene `path` and, with `report` (read up to `max_input_mb` MiB), the poses of
/// the objects a plan moved.
pub fn read_props(
    path: &Path,
    report: Option<&Path>,
    max_input_mb: u64,
) -> Result<Props, DrawError> {
    let plan_scene = kinergy_plan::scene::Scene::read(path).map_err(|source| DrawError::Scene {
        path: path.to_path_buf(),
        source,
    })?;
    let meshes = plan_scene.mesh_files().map(Path::to_path_buf).collect();
    Ok(Props {
        props: scene_props(path, &plan_scene, report, max_input_mb)?,
        meshes,
    })
}

/// The objects of `plan_scene` (read from `path`) and, with `report`, the poses of those a
/// plan moved.
fn scene_props(
    path: &Path,
    plan_scene: &kinergy_plan::scene::Scene,
    report: Option<&Path>,
    max_input_mb: u64,
) -> Result<Vec<Prop>, DrawError> {
    let mut props: Vec<Prop> = plan_scene
        .objects
        .iter()
        .map(|o| Prop {
            name: o.name.clone(),
            solid: Solid::new(&o.shape),
            placement: Placement::Fixed(o.pose),
        })
        .collect();
    let Some(report_path) = report else {
        return Ok(props);
    };
    let bad = |source| DrawError::Report {
        path: report_path.to_path_buf(),
        source,
    };
    let text =
        kinergy_io::read_to_string_limited(report_path, max_input_mb.saturating_mul(1 << 20))
            .map_err(|source| DrawError::ReportRead {
                path: report_path.to_path_buf(),
                source,
            })?;
    let plan = MovedObjects::parse(&text).map_err(bad)?;
    let frame_time = plan.frame_time().map_err(bad)?;
    for object in &plan.objects {
        let Some(prop) = props.iter_mut().find(|p| p.name == object.name) else {
            return Err(DrawError::NotInScene {
                path: report_path.to_path_buf(),
                object: object.name.clone(),
                scene: path.to_path_buf(),
            });
        };
        let poses = object.track().map_err(bad)?;
        prop.placement = Placement::Moving { frame_time, poses };
    }
    Ok(props)
}
