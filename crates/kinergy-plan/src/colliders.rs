//! The collision tests' view of a scene: parry shapes of scene objects (grown or shrunk),
//! their world bounds, nalgebra ↔ parry poses, the intersection test, and whether an object
//! placed somewhere would stand there ([`check_placement`]). [`crate::space`] builds on it.

use kinergy_io::InvalidSetting;
use nalgebra::{Isometry3, IsometryMatrix3, Point3, Translation3, UnitQuaternion};
use parry3d::math::{Pose as PPose, Rot3, Vector as PVec};
use parry3d::query::intersection_test;
use parry3d::shape::{Ball, Capsule as PCapsule, Cuboid, Shape as PShape, SharedShape, TriMesh};

use crate::error::{PlanError, Result};
use crate::scene::{Scene, SceneObject, Shape};

/// A scene object as the collision tests see it.
#[derive(Clone)]
pub(crate) struct Collider {
    pub(crate) name: String,
    pub(crate) shape: SharedShape,
    pub(crate) pose: PPose,
    pub(crate) min: Point3<f64>,
    pub(crate) max: Point3<f64>,
    pub(crate) ignored: bool,
}

/// nalgebra → parry's glam pose (f32).
pub(crate) fn to_parry(iso: &Isometry3<f64>) -> PPose {
    let t = iso.translation.vector;
    let q = iso.rotation.coords;
    PPose::from_parts(
        PVec::new(t.x as f32, t.y as f32, t.z as f32),
        Rot3::from_xyzw(q.x as f32, q.y as f32, q.z as f32, q.w as f32).normalize(),
    )
}

/// A rotation-matrix isometry as a quaternion one.
pub(crate) fn isometry(m: &IsometryMatrix3<f64>) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::from(m.translation.vector),
        UnitQuaternion::from_rotation_matrix(&m.rotation),
    )
}

/// World bounds of a parry shape at a pose.
pub(crate) fn bounds_of(shape: &dyn PShape, pose: &PPose) -> (Point3<f64>, Point3<f64>) {
    let aabb = shape.compute_aabb(pose);
    let p = |v: PVec| Point3::new(v.x as f64, v.y as f64, v.z as f64);
    (p(aabb.mins), p(aabb.maxs))
}

pub(crate) fn pvec(p: &Point3<f64>) -> PVec {
    PVec::new(p.x as f32, p.y as f32, p.z as f32)
}

/// The parry shape of a scene shape, grown (or shrunk, negative) by `grow` for primitives.
pub(crate) fn parry_shape(shape: &Shape, grow: f64) -> Result<SharedShape> {
    Ok(match shape {
        Shape::Box { half_extents } => {
            let h = half_extents.map(|v| (v + grow).max(1e-4));
            SharedShape::new(Cuboid::new(PVec::new(h.x as f32, h.y as f32, h.z as f32)))
        }
        Shape::Sphere { radius } => SharedShape::new(Ball::new((radius + grow).max(1e-4) as f32)),
        Shape::Capsule {
            half_height,
            radius,
        } => SharedShape::new(PCapsule::new_y(
            *half_height as f32,
            (radius + grow).max(1e-4) as f32,
        )),
        Shape::Mesh { file, mesh } => {
            let vertices = mesh.vertices.iter().map(pvec).collect();
            let mesh =
                TriMesh::new(vertices, mesh.triangles.clone()).map_err(|e| PlanError::Obj {
                    path: file.clone(),
                    line: 0,
                    why: format!("not a usable triangle mesh: {e}"),
                })?;
            SharedShape::new(mesh)
        }
    })
}

pub(crate) fn collider(o: &SceneObject) -> Result<Collider> {
    let shape = parry_shape(&o.shape, 0.0)?;
    let pose = to_parry(&o.pose);
    let (min, max) = bounds_of(shape.as_ref(), &pose);
    Ok(Collider {
        name: o.name.clone(),
        shape,
        pose,
        min,
        max,
        ignored: false,
    })
}

/// How far below a placed object its support may be, meters: it settles that far.
pub const SUPPORT_GAP: f64 = 0.005;

/// How deep a placed object may sink into another before it counts as intersecting it,
/// meters (resting contact is not an intersection).
pub const PLACE_TOLERANCE: f64 = 0.002;

/// Checks that object `name` of `scene`, placed at `pose`, would stand there: it intersects
/// no other object by more than [`PLACE_TOLERANCE`], and another object lies within
/// [`SUPPORT_GAP`] below it (the object lowered that far touches it). A mesh object is
/// tested unshrunk.
pub fn check_placement(scene: &Scene, name: &str, pose: &Isometry3<f64>) -> Result<()> {
    let index = scene.object_index(name).ok_or_else(|| {
        PlanError::Setting(InvalidSetting::new(
            "object",
            format!("the scene has no object `{name}`"),
        ))
    })?;
    let inner = parry_shape(&scene.objects[index].shape, -PLACE_TOLERANCE)?;
    let at = to_parry(pose);
    let lowered = to_parry(&(Translation3::new(0.0, -(SUPPORT_GAP + PLACE_TOLERANCE), 0.0) * pose));
    let fail = |why: String| PlanError::Placement {
        object: name.to_string(),
        why,
    };
    let mut supported = false;
    for (k, other) in scene.objects.iter().enumerate() {
        if k == index {
            continue;
        }
        let c = collider(other)?;
        if hit(&at, inner.as_ref(), &c.pose, c.shape.as_ref()) {
            return Err(fail(format!("it would intersect `{}`", other.name)));
        }
        supported |= hit(&lowered, inner.as_ref(), &c.pose, c.shape.as_ref());
    }
    if supported {
        Ok(())
    } else {
        Err(fail(format!(
            "nothing would hold it up: no surface lies within {:.0} mm below it (give --to a \
             height where it rests on a support)",
            SUPPORT_GAP * 1e3
        )))
    }
}

pub(crate) fn overlaps(
    a: &(Point3<f64>, Point3<f64>),
    min: &Point3<f64>,
    max: &Point3<f64>,
) -> bool {
    (0..3).all(|k| a.0[k] <= max[k] && a.1[k] >= min[k])
}

/// parry's intersection test; pairs it cannot test count as colliding (never silently
/// free).
pub(crate) fn hit(p1: &PPose, s1: &dyn PShape, p2: &PPose, s2: &dyn PShape) -> bool {
    intersection_test(p1, s1, p2, s2).map_or(true, |r| r.intersecting)
}
