//! What moves in the picture: each clip's stick figure over time, and the scene's objects,
//! fixed or moving as a plan report ([`kinergy_plan::report`]) says.

use std::path::Path;

use kinergy_motion::Clip;
use kinergy_plan::report::MovedObjects;
use nalgebra::{Isometry3, Point3};

use super::timing::nearest_frame;
use super::view::View;
use crate::common::Failure;
use crate::draw::bones::{Role, StickFigure};
use crate::draw::shapes::Solid;

/// One clip's stick figure over time.
pub(super) struct Track {
    pub(super) label: String,
    pub(super) frame_time: f64,
    pub(super) joints: usize,
    /// World positions (meters), frame after frame, `joints` per frame.
    pub(super) world: Vec<Point3<f64>>,
    /// What is drawn of the skeleton.
    pub(super) figure: StickFigure,
}

impl Track {
    pub(super) fn new(clip: &Clip, path: &Path, label: String) -> Result<Track, Failure> {
        let joints = clip.skeleton().joint_count();
        if clip.frame_count() == 0 || joints == 0 {
            return Err(Failure::input(path, "the clip has no frames to draw"));
        }
        let (figure, world) = StickFigure::of(clip).map_err(|e| Failure::input(path, e))?;
        Ok(Track {
            label,
            frame_time: clip.frame_time(),
            joints,
            world,
            figure,
        })
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
enum Placement {
    Fixed(Isometry3<f64>),
    Moving {
        frame_time: f64,
        poses: Vec<Isometry3<f64>>,
    },
}

/// One scene object ready to draw.
pub(super) struct Prop {
    pub(super) name: String,
    pub(super) solid: Solid,
    placement: Placement,
}

impl Prop {
    pub(super) fn pose(&self, t: f64) -> &Isometry3<f64> {
        match &self.placement {
            Placement::Fixed(p) => p,
            Placement::Moving { frame_time, poses } => {
                &poses[nearest_frame(t, *frame_time, poses.len())]
            }
        }
    }

    pub(super) fn moving(&self) -> bool {
        matches!(self.placement, Placement::Moving { .. })
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
pub(super) struct Props {
    /// The objects to draw.
    pub props: Vec<Prop>,
    /// The scene's mesh files.
    pub meshes: Vec<std::path::PathBuf>,
}

/// Reads the scene `path` and, with `report`, the poses of the objects a plan moved.
pub(super) fn read_props(
    path: &Path,
    report: Option<&Path>,
    max_input_mb: u64,
) -> Result<Props, Failure> {
    let plan_scene = kinergy_plan::scene::Scene::read(path).map_err(|e| Failure::input(path, e))?;
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
) -> Result<Vec<Prop>, Failure> {
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
    let bad = |why: String| Failure::input(report_path, why);
    let text =
        kinergy_io::read_to_string_limited(report_path, max_input_mb.saturating_mul(1 << 20))
            .map_err(|e| Failure::input(report_path, e))?;
    let plan = MovedObjects::parse(&text).map_err(|e| Failure::input(report_path, e))?;
    let frame_time = plan
        .frame_time()
        .map_err(|e| Failure::input(report_path, e))?;
    for object in &plan.objects {
        let Some(prop) = props.iter_mut().find(|p| p.name == object.name) else {
            return Err(bad(format!(
                "object `{}` is not in the scene {}",
                kinergy_io::clip_text(&object.name, 120),
                path.display()
            )));
        };
        let poses = object.track().map_err(|e| Failure::input(report_path, e))?;
        prop.placement = Placement::Moving { frame_time, poses };
    }
    Ok(props)
}
