//! The tests' own collision test ([`Verifier`]), written apart from the planner's, shared by
//! the test binaries that re-check the planner's motions.

use kinergy_plan::body::{BodyGeometry, Capsule};
use kinergy_plan::rrt::ArmPath;
use kinergy_plan::scene::Shape;
use kinergy_plan::space::{ArmConfig, ArmSpace, HELD_CONTACT, lerp};
use kinergy_plan::task::Planner;
use kinergy_reach::character::{Character, Limb};
use nalgebra::{Isometry3, Point3, Vector3};
use parry3d::math::{Pose as PPose, Rot3, Vector as PVec};
use parry3d::query::intersection_test;
use parry3d::shape::{Capsule as PCapsule, Cuboid, Shape as _, Triangle};

fn pvec(p: &Point3<f64>) -> PVec {
    PVec::new(p.x as f32, p.y as f32, p.z as f32)
}

fn ppose(iso: &Isometry3<f64>) -> PPose {
    let q = iso.rotation.coords;
    PPose::from_parts(
        pvec(&Point3::from(iso.translation.vector)),
        Rot3::from_xyzw(q.x as f32, q.y as f32, q.z as f32, q.w as f32).normalize(),
    )
}

/// A scene triangle in world: corners, bounds and the object's name.
type WorldTriangle = ([Point3<f64>; 3], Point3<f64>, Point3<f64>, String);

/// A collision test written apart from the planner's: the arm's capsules from the
/// character's full-body FK, the scene's meshes triangle by triangle (no hierarchy), boxes
/// and other primitives one by one; no clearance.
pub struct Verifier {
    character: Character,
    start: kinergy_reach::character::Pose,
    body: BodyGeometry,
    /// Scene triangles in world with their bounds, and primitive colliders.
    triangles: Vec<WorldTriangle>,
    boxes: Vec<(Isometry3<f64>, Vector3<f64>, String)>,
    other: Vec<(Isometry3<f64>, Shape, String)>,
}

impl Verifier {
    pub fn new(planner: &Planner, ignore: &[&str]) -> Verifier {
        let character = planner.character().clone();
        let body = BodyGeometry::new(&character).unwrap();
        let mut triangles = Vec::new();
        let mut boxes = Vec::new();
        let mut other = Vec::new();
        for o in &planner.scene().objects {
            if ignore.contains(&o.name.as_str()) {
                continue;
            }
            match &o.shape {
                Shape::Mesh { mesh, .. } => {
                    for t in &mesh.triangles {
                        let p = t.map(|i| o.pose * mesh.vertices[i as usize]);
                        let min = p[0].inf(&p[1]).inf(&p[2]);
                        let max = p[0].sup(&p[1]).sup(&p[2]);
                        triangles.push((p, min, max, o.name.clone()));
                    }
                }
                Shape::Box { half_extents } => boxes.push((o.pose, *half_extents, o.name.clone())),
                s => other.push((o.pose, s.clone(), o.name.clone())),
            }
        }
        Verifier {
            start: *planner.start_pose(),
            character,
            body,
            triangles,
            boxes,
            other,
        }
    }

    /// The first contact of the arm at `q` (and of the held box at `held`), if any.
    pub fn contact(
        &self,
        space: &ArmSpace,
        q: &ArmConfig,
        held: Option<(&Isometry3<f64>, Vector3<f64>)>,
    ) -> Option<String> {
        let pose = space.pose_with(&self.start, q);
        let frames = self.character.world_frames(&pose);
        let world = self.body.world_capsules(&frames);
        let arm = self.body.limb_parts(Limb::RightArm);
        let parts = self.body.parts();
        for &m in &arm {
            for j in 0..parts.len() {
                if j != m && !self.body.is_disabled(m, j) && world[m].gap(&world[j]) < 0.0 {
                    return Some(format!("{} × {}", parts[m].name, parts[j].name));
                }
            }
            if let Some(hit) = self.capsule_hits(&world[m]) {
                return Some(format!("{} × {hit}", parts[m].name));
            }
        }
        if let Some((obj, half)) = held {
            let h = half.map(|v| v - HELD_CONTACT);
            let cube = Cuboid::new(PVec::new(h.x as f32, h.y as f32, h.z as f32));
            let p = ppose(obj);
            for (j, c) in world.iter().enumerate() {
                if arm.contains(&j) {
                    continue;
                }
                let cap = PCapsule::new(pvec(&c.a), pvec(&c.b), c.radius as f32);
                if intersection_test(&PPose::IDENTITY, &cap, &p, &cube)
                    .unwrap()
                    .intersecting
                {
                    return Some(format!("book × {}", parts[j].name));
                }
            }
            let aabb = cube.compute_aabb(&p);
            for (tri, tmin, tmax, name) in &self.triangles {
                let apart = (0..3)
                    .any(|k| tmin[k] as f32 > aabb.maxs[k] || (tmax[k] as f32) < aabb.mins[k]);
                if apart {
                    continue;
                }
                let t = Triangle::new(pvec(&tri[0]), pvec(&tri[1]), pvec(&tri[2]));
                if intersection_test(&PPose::IDENTITY, &t, &p, &cube)
                    .unwrap()
                    .intersecting
                {
                    return Some(format!("book × {name}"));
                }
            }
            for (pose, he, name) in &self.boxes {
                let other = Cuboid::new(PVec::new(he.x as f32, he.y as f32, he.z as f32));
                if intersection_test(&ppose(pose), &other, &p, &cube)
                    .unwrap()
                    .intersecting
                {
                    return Some(format!("book × {name}"));
                }
            }
        }
        None
    }

    /// The first contact of the whole body at `q` (every part but the feet against the
    /// scene, every enabled pair of parts against each other), if any; no clearance.
    #[allow(dead_code)] // the body test's, not every binary's
    pub fn whole_body_contact(&self, space: &ArmSpace, q: &ArmConfig) -> Option<String> {
        let pose = space.pose_with(&self.start, q);
        let frames = self.character.world_frames(&pose);
        let world = self.body.world_capsules(&frames);
        let parts = self.body.parts();
        for i in 0..parts.len() {
            for j in i + 1..parts.len() {
                if !self.body.is_disabled(i, j) && world[i].gap(&world[j]) < 0.0 {
                    return Some(format!("{} × {}", parts[i].name, parts[j].name));
                }
            }
            if parts[i].name.ends_with("_foot") {
                continue;
            }
            if let Some(hit) = self.capsule_hits(&world[i]) {
                return Some(format!("{} × {hit}", parts[i].name));
            }
        }
        None
    }

    /// Re-checks the whole body along every segment of `path`, with samples every
    /// `resolution` meters of the largest tracked-point displacement; the first contact.
    #[allow(dead_code)] // the body test's, not every binary's
    pub fn recheck_whole_body(
        &self,
        space: &ArmSpace,
        path: &ArmPath,
        resolution: f64,
    ) -> Option<String> {
        for w in path.configs.windows(2) {
            let n = (space.distance(&w[0], &w[1]) / resolution).ceil().max(1.0) as usize;
            for k in 0..=n {
                let q = lerp(&w[0], &w[1], k as f64 / n as f64);
                if !space.within_limits(&q) {
                    return Some(format!("outside the joint limits at {q:?}"));
                }
                if let Some(c) = self.whole_body_contact(space, &q) {
                    return Some(format!("{c} at {q:?}"));
                }
            }
        }
        None
    }

    fn capsule_hits(&self, c: &Capsule) -> Option<String> {
        let (min, max) = c.bounds(0.0);
        let cap = PCapsule::new(pvec(&c.a), pvec(&c.b), c.radius as f32);
        for (tri, tmin, tmax, name) in &self.triangles {
            if (0..3).any(|k| tmin[k] > max[k] || tmax[k] < min[k]) {
                continue;
            }
            let t = Triangle::new(pvec(&tri[0]), pvec(&tri[1]), pvec(&tri[2]));
            if intersection_test(&PPose::IDENTITY, &cap, &PPose::IDENTITY, &t)
                .unwrap()
                .intersecting
            {
                return Some(name.clone());
            }
        }
        for (pose, he, name) in &self.boxes {
            let cube = Cuboid::new(PVec::new(he.x as f32, he.y as f32, he.z as f32));
            if intersection_test(&PPose::IDENTITY, &cap, &ppose(pose), &cube)
                .unwrap()
                .intersecting
            {
                return Some(name.clone());
            }
        }
        for (pose, shape, name) in &self.other {
            let hit = match shape {
                Shape::Sphere { radius } => {
                    let centre = pose * Point3::origin();
                    kinergy_plan::body::segment_distance(&c.a, &c.b, &centre, &centre)
                        < c.radius + radius
                }
                Shape::Capsule {
                    half_height,
                    radius,
                } => {
                    let a = pose * Point3::new(0.0, -half_height, 0.0);
                    let b = pose * Point3::new(0.0, *half_height, 0.0);
                    kinergy_plan::body::segment_distance(&c.a, &c.b, &a, &b) < c.radius + radius
                }
                _ => false,
            };
            if hit {
                return Some(name.clone());
            }
        }
        None
    }

    /// Re-checks every segment of `path` with samples every `resolution` meters of the
    /// largest tracked-point displacement; returns the first contact found.
    pub fn recheck(
        &self,
        space: &ArmSpace,
        path: &ArmPath,
        resolution: f64,
        half: Option<Vector3<f64>>,
    ) -> Option<String> {
        for w in path.configs.windows(2) {
            let n = (space.distance(&w[0], &w[1]) / resolution).ceil().max(1.0) as usize;
            for k in 0..=n {
                let q = lerp(&w[0], &w[1], k as f64 / n as f64);
                if !space.within_limits(&q) {
                    return Some(format!("outside the joint limits at {q:?}"));
                }
                let held = half.map(|h| (space.held_pose(&q).unwrap(), h));
                if let Some(c) = self.contact(space, &q, held.as_ref().map(|(p, h)| (p, *h))) {
                    return Some(c);
                }
            }
        }
        None
    }
}
