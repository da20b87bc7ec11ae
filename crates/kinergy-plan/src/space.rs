//! The arm's configuration space in a scene: forward kinematics of the points the planner
//! tracks, the collision test of a configuration and of an interpolation between two, the
//! planner's distance, and IK with collision avoidance.
//!
//! A configuration ([`ArmConfig`]) is Kallmann's arm configuration `s`: the arm's 7 DoFs (the
//! order of [`kinergy_reach::character::dof`]: shoulder swing x, swing y, twist, elbow
//! flexion, twist, wrist swing x, y) and the body's three ([`crate::posture`]: the spine's
//! swing and twist, the squat). In a space built with [`ArmSpace::new`] the body stays in the
//! pose the space was built for and its three DoFs stay zero; a space given a body motion
//! ([`ArmSpace::with_body`]) poses the spine and the legs from them, the feet planted.
//!
//! # What a configuration collides with
//! Where the body moves, every body part is tested ([`ArmSpace::with_body`]); otherwise:
//! The arm's three parts (upper arm, forearm, hand) are tested against every other body part
//! of the enabled pairs ([`BodyGeometry`]), against each other where not adjacent, and
//! against every scene object that is not ignored; a held object ([`ArmSpace::attach`])
//! against the body (except the arm holding it) and the scene. Arm capsules are inflated by
//! the *clearance* ([`ArmSpace::with_clearance`]) so that what the discrete edge checks
//! miss between samples stays within that margin. A held object is shrunk by
//! [`HELD_CONTACT`] — it may rest on the surface it is picked from or placed on — and a
//! held box grown back by half the clearance, its own margin.
//!
//! # Distance and edge resolution
//! The planner's distance between two configurations is Kallmann's: the largest Euclidean
//! distance between corresponding tracked points — elbow, wrist, fingertip, and the corners
//! of a held box, and where the body moves, the head's top, both shoulders, the other hand's
//! fingertip and both knees — posed at each ([`ArmSpace::distance`]). An interpolation
//! (linear in the DoFs) is valid when configurations spaced at most `resolution` apart in
//! that distance along it are all free ([`ArmSpace::edge_free`]); with the default 1 cm
//! resolution and 1 cm clearance no unchecked point of the motion comes closer than the
//! clearance can cover. Samples are tested midpoint first (bisection order) so colliding
//! edges fail fast.

use std::sync::Arc;

use kinergy_io::InvalidSetting;
use kinergy_motion::{Chain, ChainPose, Side};
use kinergy_reach::character::{ArmGirdle, Character, Limb, Pose};
use kinergy_solver::analytic::{AnalyticError, LimbIk, OrbitSearch, OrbitSense};
use nalgebra::{
    Isometry3, IsometryMatrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3,
};
use parry3d::math::{Pose as PPose, Vector as PVec};
use parry3d::shape::{Capsule as PCapsule, Cuboid, Shape as PShape, SharedShape};

use crate::body::{BodyGeometry, Capsule};
use crate::colliders::{
    Collider, bounds_of, collider, hit, isometry, overlaps, parry_shape, pvec, to_parry,
};
pub use crate::colliders::{PLACE_TOLERANCE, SUPPORT_GAP, check_placement};
use crate::error::{PlanError, Result};
use crate::hand::GRIP_FRACTION;
use crate::posture::{ARM_DOFS, BodyDofs, BodyMotion, CONFIG_DOFS};
use crate::scene::{Scene, Shape};

mod whole_body;
use whole_body::BodyMode;

/// An arm configuration (Kallmann's `s`): the 7 DoFs of one arm, then the body's three
/// ([`crate::posture::body_dof`]; zero where the body does not move).
pub type ArmConfig = [f64; CONFIG_DOFS];

/// The arm's 7 DoFs of a configuration.
pub fn arm_of(q: &ArmConfig) -> [f64; ARM_DOFS] {
    std::array::from_fn(|i| q[i])
}

/// The body's 3 DoFs of a configuration.
pub fn body_of(q: &ArmConfig) -> BodyDofs {
    std::array::from_fn(|i| q[ARM_DOFS + i])
}

/// The configuration of arm DoFs `arm` and body DoFs `body`.
pub fn join(arm: &[f64; ARM_DOFS], body: &BodyDofs) -> ArmConfig {
    std::array::from_fn(|i| {
        if i < ARM_DOFS {
            arm[i]
        } else {
            body[i - ARM_DOFS]
        }
    })
}

/// How much a held object is shrunk for collision tests, meters: it may touch (rest on) a
/// surface by this much without colliding.
pub const HELD_CONTACT: f64 = 0.01;

/// Most tracked points: elbow, wrist, fingertip, a held box's 8 corners and, where the body
/// moves, six of its joints ([`whole_body`]).
const MAX_POINTS: usize = 17;

/// The girdle's fixed point stops when the shoulder moves less than this, meters.
const GIRDLE_TOLERANCE: f64 = 1e-13;

/// A solution whose shoulder is farther than this (meters) from where the girdle puts it
/// for the solution is none: its hand would miss by as much. (Where the girdle's fixed point
/// is not reached, it is a fraction of a millimetre but at the edge of the arm's reach, where
/// a body posture can put the shoulder: there it reached 17 mm.)
const GIRDLE_MISS: f64 = 1e-3;

/// At most this many IK searches refine the girdle's fixed point.
const GIRDLE_ITERATIONS: usize = 24;

/// The tracked points of one configuration (see the [module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Points {
    p: [Point3<f64>; MAX_POINTS],
    n: usize,
}

impl Points {
    /// The points.
    pub fn as_slice(&self) -> &[Point3<f64>] {
        &self.p[..self.n]
    }

    /// The largest distance between corresponding points.
    pub fn distance(&self, other: &Points) -> f64 {
        self.as_slice()
            .iter()
            .zip(other.as_slice())
            .map(|(a, b)| (a - b).norm_squared())
            .fold(0.0, f64::max)
            .sqrt()
    }

    /// The wrist's position.
    pub fn wrist(&self) -> Point3<f64> {
        self.p[1]
    }
}

/// A hand target (Kallmann 2005): where the grip point goes ([`crate::hand`]), optionally
/// how the hand is turned, from its rest orientation. Without an orientation the wrist stays
/// straight and the IK chooses the forearm's direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HandTarget {
    /// The grip point in world, meters.
    pub position: Point3<f64>,
    /// The hand's rotation from its rest orientation, in world.
    pub orientation: Option<UnitQuaternion<f64>>,
}

impl HandTarget {
    /// A target from its numbers: `[x, y, z]` (the grip point, world meters) or `[x, y, z,
    /// qx, qy, qz, qw]` (and the hand's rotation, normalized). Errors say why, for the caller to
    /// name where the numbers came from: a value not finite, another count, a zero quaternion.
    /// (How far the point is from the character is the caller's check.)
    pub fn from_values(values: &[f64]) -> Result<HandTarget, String> {
        if values.iter().any(|v| !v.is_finite()) {
            return Err("every value must be finite".into());
        }
        if !(values.len() == 3 || values.len() == 7) {
            return Err(format!("expected 3 or 7 numbers, found {}", values.len()));
        }
        let orientation = if values.len() == 7 {
            let q = nalgebra::Quaternion::new(values[6], values[3], values[4], values[5]);
            if q.norm() < 1e-9 {
                return Err("the quaternion must not be zero".into());
            }
            Some(UnitQuaternion::from_quaternion(q))
        } else {
            None
        };
        Ok(HandTarget {
            position: Point3::new(values[0], values[1], values[2]),
            orientation,
        })
    }
}

/// An object held in the hand.
#[derive(Clone)]
struct Held {
    /// Its index in the scene (it is ignored as an obstacle while held).
    object: usize,
    name: String,
    /// Its shape, shrunk by [`HELD_CONTACT`] (the clearance is added at test time for boxes).
    half_extents: Option<Vector3<f64>>,
    shape: SharedShape,
    /// Its frame in the wrist's frame.
    local: Isometry3<f64>,
    /// Corners tracked by the distance, in its own frame.
    corners: Vec<Point3<f64>>,
}

/// The configuration space of one arm of a character standing in a scene.
#[derive(Clone)]
pub struct ArmSpace {
    limb: Limb,
    chain: Chain,
    ik: LimbIk,
    /// The arm's base frame with the girdle at rest ([`ArmSpace::base_for`]).
    base: IsometryMatrix3<f64>,
    girdle: ArmGirdle,
    rest_hand: Rotation3<f64>,
    /// Wrist → fingertip in the wrist frame.
    hand_tip: Vector3<f64>,
    /// The arm's parts: (name, arm joint 0–2, capsule in that joint's frame).
    moving: Vec<(String, usize, Capsule)>,
    /// Static body parts in world with, per moving part, whether the pair is enabled.
    statics: Vec<(String, Capsule, [bool; 3])>,
    /// Non-adjacent moving pairs (indices into `moving`).
    moving_pairs: Vec<(usize, usize)>,
    colliders: Vec<Collider>,
    held: Option<Held>,
    clearance: f64,
    resolution: f64,
    orbit: OrbitSearch,
    /// The body's collision geometry.
    geometry: Arc<BodyGeometry>,
    /// The body's motion, where it moves ([`ArmSpace::with_body`]).
    body: Option<Arc<BodyMode>>,
}

impl std::fmt::Debug for ArmSpace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ArmSpace")
            .field("limb", &self.limb)
            .field(
                "objects",
                &self.colliders.iter().map(|c| &c.name).collect::<Vec<_>>(),
            )
            .field("held", &self.held.as_ref().map(|h| &h.name))
            .field("moves_body", &self.body.is_some())
            .field("clearance", &self.clearance)
            .field("resolution", &self.resolution)
            .finish()
    }
}

impl ArmSpace {
    /// The space of `limb` (an arm) of `character` standing in `body_pose`, among the
    /// objects of `scene`, with the default clearance (1 cm), resolution (1 cm) and orbit
    /// search (Kallmann's 20°, within −15°…130°).
    pub fn new(
        character: &Character,
        body: &BodyGeometry,
        body_pose: &Pose,
        limb: Limb,
        scene: &Scene,
    ) -> Result<ArmSpace> {
        InvalidSetting::require(limb.is_arm(), "limb", "the planner moves an arm")?;
        if !body_pose.iter().all(|v| v.is_finite()) {
            return Err(PlanError::NonFinite("the body pose".into()));
        }
        let frames = character.world_frames(body_pose);
        let full = character.limb_chain(limb);
        let hand_tip = full.end_effector();
        let chain = Chain::new(full.joints().to_vec(), hand_tip * GRIP_FRACTION)?;
        let girdle = character.arm_girdle(limb);
        let mut base = character.limb_base_frame_in(limb, &frames);
        base.translation.vector -= base.rotation * girdle.shift(&body_pose[limb.dofs()]);
        // α = 0 is the lowest elbow (world down in the base frame); growing α raises the
        // elbow outward, which for the right arm is a left-handed turn about the
        // shoulder→wrist axis.
        let sense = match limb.side() {
            Side::Right => OrbitSense::LeftHanded,
            Side::Left => OrbitSense::RightHanded,
        };
        let ik = LimbIk::new(&chain)?
            .with_down(base.rotation.inverse() * -Vector3::y())?
            .with_sense(sense);
        let rest_hand = character
            .limb_base_frame(limb, &character.rest_pose())
            .rotation;
        let arm_joints = limb.joints();
        let arm_parts = body.limb_parts(limb);
        let moving: Vec<(String, usize, Capsule)> = arm_parts
            .iter()
            .map(|&i| {
                let p = &body.parts()[i];
                let k = arm_joints.iter().position(|&j| j == p.joint).unwrap_or(0);
                (p.name.clone(), k, p.capsule)
            })
            .collect();
        InvalidSetting::require(
            moving.len() == 3,
            "body",
            "an arm needs three parts (upper arm, forearm, hand)",
        )?;
        let statics = (0..body.parts().len())
            .filter(|i| !arm_parts.contains(i))
            .map(|i| {
                let p = &body.parts()[i];
                let enabled = [0, 1, 2].map(|m| !body.is_disabled(arm_parts[m], i));
                (
                    p.name.clone(),
                    p.capsule.transformed(&frames[p.joint]),
                    enabled,
                )
            })
            .collect();
        let mut moving_pairs = Vec::new();
        for a in 0..3 {
            for b in a + 1..3 {
                if !body.is_disabled(arm_parts[a], arm_parts[b]) {
                    moving_pairs.push((a, b));
                }
            }
        }
        let colliders = scene.objects.iter().map(collider).collect::<Result<_>>()?;
        Ok(ArmSpace {
            limb,
            chain,
            ik,
            base,
            girdle,
            rest_hand,
            hand_tip,
            moving,
            statics,
            moving_pairs,
            colliders,
            held: None,
            clearance: 0.01,
            resolution: 0.01,
            orbit: OrbitSearch::default(),
            geometry: Arc::new(body.clone()),
            body: None,
        })
    }

    /// The same space with the body moving by `motion` ([`crate::posture`]): a configuration's
    /// three body DoFs pose the spine and the legs (the feet planted), and every body part is
    /// tested for collisions — each arm part as before; the other parts against each other
    /// (the enabled pairs, without the clearance) and against the scene (with it), but for the
    /// feet, which stand where they stand. The motion's reference posture should be the one
    /// the space was built for.
    pub fn with_body(mut self, motion: BodyMotion) -> Result<ArmSpace> {
        self.body = Some(Arc::new(BodyMode::new(&self.geometry, self.limb, motion)?));
        Ok(self)
    }

    /// True when the body moves ([`ArmSpace::with_body`]).
    pub fn moves_body(&self) -> bool {
        self.body.is_some()
    }

    /// The body's motion, where it moves.
    pub fn body_motion(&self) -> Option<&BodyMotion> {
        self.body.as_ref().map(|b| &b.motion)
    }

    /// True when `q`'s arm is within its joint limits and its body DoFs within the stance's
    /// (zero where the body does not move).
    pub fn within_limits(&self, q: &ArmConfig) -> bool {
        let b = body_of(q);
        self.ik.within_limits(&arm_of(q))
            && match &self.body {
                Some(mode) => mode.motion.within_limits(&b),
                None => b.iter().all(|&v| v == 0.0),
            }
    }

    /// The orbit angle of `q`'s arm on its body (α = 0 its lowest elbow).
    pub fn alpha_of(&self, q: &ArmConfig) -> f64 {
        let (_, ik) = self.base_and_ik(&body_of(q));
        ik.alpha_of(&arm_of(q))
    }

    /// The same space with the arm capsules inflated by `clearance` meters (≥ 0).
    pub fn with_clearance(mut self, clearance: f64) -> Result<ArmSpace> {
        InvalidSetting::require(
            clearance.is_finite() && clearance >= 0.0,
            "clearance",
            "a finite number ≥ 0",
        )?;
        self.clearance = clearance;
        Ok(self)
    }

    /// The same space with interpolations checked every `resolution` meters (> 0) of the
    /// planner's distance.
    pub fn with_resolution(mut self, resolution: f64) -> Result<ArmSpace> {
        InvalidSetting::require(
            resolution.is_finite() && resolution > 0.0,
            "resolution",
            "a finite number > 0",
        )?;
        self.resolution = resolution;
        Ok(self)
    }

    /// The same space with another orbit-angle search for the IK.
    pub fn with_orbit_search(mut self, orbit: OrbitSearch) -> Result<ArmSpace> {
        orbit.validate()?;
        self.orbit = orbit;
        Ok(self)
    }

    /// The clearance, meters.
    pub fn clearance(&self) -> f64 {
        self.clearance
    }

    /// The edge resolution, meters.
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// The arm.
    pub fn limb(&self) -> Limb {
        self.limb
    }

    /// The arm's analytic IK (its end effector is the grip point).
    pub fn ik(&self) -> &LimbIk {
        &self.ik
    }

    /// Ignore (or stop ignoring) the scene object named `name` as an obstacle, e.g. the
    /// object the hand is closing on.
    pub fn set_ignored(&mut self, name: &str, ignored: bool) -> Result<()> {
        let c = self
            .colliders
            .iter_mut()
            .find(|c| c.name == name)
            .ok_or_else(|| {
                PlanError::Setting(InvalidSetting::new(
                    "object",
                    format!("the scene has no object `{name}`"),
                ))
            })?;
        c.ignored = ignored;
        Ok(())
    }

    /// Hold scene object `name` (a box, sphere or capsule) in the hand as it is posed when
    /// the arm is at `q`: from now on it moves with the wrist, is ignored as an obstacle and
    /// is tested against the body and the scene.
    pub fn attach(&mut self, scene: &Scene, name: &str, q: &ArmConfig) -> Result<()> {
        let index = scene.object_index(name).ok_or_else(|| {
            PlanError::Setting(InvalidSetting::new(
                "object",
                format!("the scene has no object `{name}`"),
            ))
        })?;
        let o = &scene.objects[index];
        let (half_extents, corners) = match &o.shape {
            Shape::Box { half_extents } => {
                let h = *half_extents;
                let corners = (0..8)
                    .map(|i| {
                        let s = |b: usize| if i & (1 << b) == 0 { -1.0 } else { 1.0 };
                        Point3::new(s(0) * h.x, s(1) * h.y, s(2) * h.z)
                    })
                    .collect();
                (Some(h), corners)
            }
            Shape::Sphere { .. } | Shape::Capsule { .. } => (None, Vec::new()),
            Shape::Mesh { .. } => {
                return Err(PlanError::Setting(InvalidSetting::new(
                    "object",
                    format!("`{name}` is a mesh; only boxes, spheres and capsules can be held"),
                )));
            }
        };
        let wrist = self.wrist_frame(q);
        let wrist = isometry(&wrist);
        self.held = Some(Held {
            object: index,
            name: name.to_string(),
            half_extents,
            shape: parry_shape(&o.shape, -HELD_CONTACT)?,
            local: wrist.inverse() * o.pose,
            corners,
        });
        self.colliders[index].ignored = true;
        Ok(())
    }

    /// Let go of the held object, leaving it where it is when the arm is at `q`; returns its
    /// new pose. It is an obstacle again from there.
    pub fn release(&mut self, q: &ArmConfig) -> Option<(String, Isometry3<f64>)> {
        let pose = self.held_pose(q)?;
        let held = self.held.take()?;
        let c = &mut self.colliders[held.object];
        c.pose = to_parry(&pose);
        (c.min, c.max) = bounds_of(c.shape.as_ref(), &c.pose);
        c.ignored = false;
        Some((held.name, pose))
    }

    /// The held object's world pose when the arm is at `q`.
    pub fn held_pose(&self, q: &ArmConfig) -> Option<Isometry3<f64>> {
        let h = self.held.as_ref()?;
        let w = self.wrist_frame(q);
        let w = isometry(&w);
        Some(w * h.local)
    }

    /// The name of the held object.
    pub fn held(&self) -> Option<&str> {
        self.held.as_ref().map(|h| h.name.as_str())
    }

    /// The arm's base frame at `q`: the shoulder where the body and the girdle put it.
    pub fn base_for(&self, q: &ArmConfig) -> IsometryMatrix3<f64> {
        let (base, _) = self.base_and_ik(&body_of(q));
        shifted(&base, &self.girdle.shift(&arm_of(q)))
    }

    /// The arm's base frame with the girdle at rest, and its IK (α's lowest elbow world down),
    /// with the body at `b`.
    fn base_and_ik(&self, b: &BodyDofs) -> (IsometryMatrix3<f64>, std::borrow::Cow<'_, LimbIk>) {
        match &self.body {
            Some(mode) if b.iter().any(|&v| v != 0.0) => {
                let base = mode.base_frame(&self.girdle, self.limb, b);
                let ik = self
                    .ik
                    .clone()
                    .with_down(base.rotation.inverse() * -Vector3::y())
                    .unwrap_or_else(|_| self.ik.clone());
                (base, std::borrow::Cow::Owned(ik))
            }
            _ => (self.base, std::borrow::Cow::Borrowed(&self.ik)),
        }
    }

    /// World frames of the shoulder, elbow and wrist at `q`.
    pub fn frames(&self, q: &ArmConfig) -> [IsometryMatrix3<f64>; 3] {
        if let Some(mode) = &self.body {
            return mode.arm_frames(self.limb, q);
        }
        let mut out = ChainPose::default();
        let base = self.base_for(q);
        // The chain has 7 DoFs: fk_into cannot fail on a 7-array.
        if self.chain.fk_into(&base, &arm_of(q), &mut out).is_err() || out.frames.len() != 3 {
            return [base; 3];
        }
        [out.frames[0], out.frames[1], out.frames[2]]
    }

    fn wrist_frame(&self, q: &ArmConfig) -> IsometryMatrix3<f64> {
        self.frames(q)[2]
    }

    /// The grip point's world frame at `q` (the wrist's orientation).
    pub fn grip_frame(&self, q: &ArmConfig) -> IsometryMatrix3<f64> {
        let mut w = self.wrist_frame(q);
        w.translation.vector += w.rotation * (self.hand_tip * GRIP_FRACTION);
        w
    }

    /// The tracked points at `q` (elbow, wrist, fingertip, held box corners; where the body
    /// moves, six of its joints).
    pub fn points(&self, q: &ArmConfig) -> Points {
        let body = self.body.as_ref().map(|mode| mode.posed(self.limb, q));
        let [_, e, w] = match &body {
            Some(posed) => posed.arm_frames(self.limb),
            None => self.frames(q),
        };
        let mut p = [Point3::origin(); MAX_POINTS];
        p[0] = Point3::from(e.translation.vector);
        p[1] = Point3::from(w.translation.vector);
        p[2] = w * Point3::from(self.hand_tip);
        let mut n = 3;
        if let Some(h) = &self.held {
            let wq = isometry(&w);
            let obj = wq * h.local;
            for c in &h.corners {
                p[n] = obj * c;
                n += 1;
            }
        }
        if let (Some(mode), Some(posed)) = (&self.body, &body) {
            for point in mode.tracked(posed) {
                p[n] = point;
                n += 1;
            }
        }
        Points { p, n }
    }

    /// The planner's distance between two configurations (meters).
    pub fn distance(&self, a: &ArmConfig, b: &ArmConfig) -> f64 {
        self.points(a).distance(&self.points(b))
    }

    /// True when `q` is within the joint limits ([`ArmSpace::within_limits`]) and collides
    /// with nothing.
    pub fn free(&self, q: &ArmConfig) -> bool {
        self.within_limits(q) && self.contact(q).is_none()
    }

    /// The first collision at `q`, as `part × obstacle`, or `None` when it is free (joint
    /// limits are not looked at).
    pub fn contact(&self, q: &ArmConfig) -> Option<String> {
        self.contact_with(q, self.clearance)
    }

    /// [`ArmSpace::contact`] with another clearance (0 tests the true geometry). Where the
    /// body moves, feet its legs cannot keep planted are a contact too (`the feet …`).
    pub fn contact_with(&self, q: &ArmConfig, clearance: f64) -> Option<String> {
        if let Some(mode) = &self.body {
            let posed = mode.posed(self.limb, q);
            return self.whole_body_contact(mode, &posed, clearance);
        }
        let frames = self.frames(q);
        let mut world = [Capsule {
            a: Point3::origin(),
            b: Point3::origin(),
            radius: 0.0,
        }; 3];
        for (m, (_, k, c)) in self.moving.iter().enumerate() {
            world[m] = c.transformed(&frames[*k]);
            world[m].radius += clearance;
        }
        for (name, c, enabled) in &self.statics {
            for m in 0..3 {
                if enabled[m] && world[m].gap(c) < 0.0 {
                    return Some(format!("{} × {name}", self.moving[m].0));
                }
            }
        }
        for &(a, b) in &self.moving_pairs {
            if world[a].gap(&world[b]) + clearance < 0.0 {
                return Some(format!("{} × {}", self.moving[a].0, self.moving[b].0));
            }
        }
        for (w, (name, _, _)) in world.iter().zip(&self.moving) {
            let bounds = w.bounds(0.0);
            let cap = PCapsule::new(pvec(&w.a), pvec(&w.b), w.radius as f32);
            for c in &self.colliders {
                if c.ignored || !overlaps(&bounds, &c.min, &c.max) {
                    continue;
                }
                if hit(&PPose::IDENTITY, &cap, &c.pose, c.shape.as_ref()) {
                    return Some(format!("{name} × {}", c.name));
                }
            }
        }
        if let Some(h) = &self.held {
            let statics = self.statics.iter().map(|(n, c, _)| (n.as_str(), c));
            return self.held_contact(h, &frames[2], clearance, statics);
        }
        None
    }

    /// The held object's first contact with the body parts `statics` (name, world capsule)
    /// and the scene.
    fn held_contact<'n>(
        &self,
        h: &Held,
        wrist: &IsometryMatrix3<f64>,
        clearance: f64,
        statics: impl Iterator<Item = (&'n str, &'n Capsule)>,
    ) -> Option<String> {
        let wq = isometry(wrist);
        let pose = to_parry(&(wq * h.local));
        let grown;
        let shape: &dyn PShape = match (h.half_extents, clearance > 0.0) {
            (Some(he), true) => {
                let g = he.map(|v| (v - HELD_CONTACT + 0.5 * clearance).max(1e-4));
                grown = Cuboid::new(PVec::new(g.x as f32, g.y as f32, g.z as f32));
                &grown
            }
            _ => h.shape.as_ref(),
        };
        let bounds = bounds_of(shape, &pose);
        for (name, c) in statics {
            let cap = PCapsule::new(pvec(&c.a), pvec(&c.b), c.radius as f32);
            if hit(&PPose::IDENTITY, &cap, &pose, shape) {
                return Some(format!("{} × {name}", h.name));
            }
        }
        for c in &self.colliders {
            if c.ignored || !overlaps(&bounds, &c.min, &c.max) {
                continue;
            }
            if hit(&pose, shape, &c.pose, c.shape.as_ref()) {
                return Some(format!("{} × {}", h.name, c.name));
            }
        }
        None
    }

    /// True when the interpolation from `a` to `b` is free at the space's resolution (the
    /// end configurations themselves are not tested: callers have).
    pub fn edge_free(&self, a: &ArmConfig, b: &ArmConfig) -> bool {
        self.edge_free_at(a, b, self.resolution, self.clearance)
    }

    /// [`ArmSpace::edge_free`] at another resolution and clearance.
    pub fn edge_free_at(
        &self,
        a: &ArmConfig,
        b: &ArmConfig,
        resolution: f64,
        clearance: f64,
    ) -> bool {
        self.edge_contact_at(a, b, resolution, clearance).is_none()
    }

    /// What the interpolation from `a` to `b` first runs into at the space's resolution and
    /// clearance — `part × obstacle`, or the joint limits — or `None` when it is free (as
    /// [`ArmSpace::edge_free`], the ends are not tested).
    pub fn edge_contact(&self, a: &ArmConfig, b: &ArmConfig) -> Option<String> {
        self.edge_contact_at(a, b, self.resolution, self.clearance)
    }

    fn edge_contact_at(
        &self,
        a: &ArmConfig,
        b: &ArmConfig,
        resolution: f64,
        clearance: f64,
    ) -> Option<String> {
        let d = self.distance(a, b);
        let n = (d / resolution).ceil() as usize;
        if n <= 1 {
            return None;
        }
        // Bisection order: every interior sample k/n, coarse levels first.
        let mut stride = n.next_power_of_two();
        let mut seen = vec![false; n + 1];
        seen[0] = true;
        seen[n] = true;
        while stride >= 1 {
            let mut k = stride;
            while k < n {
                if !seen[k] {
                    seen[k] = true;
                    let q = lerp(a, b, k as f64 / n as f64);
                    if !self.within_limits(&q) {
                        return Some("the joint limits".into());
                    }
                    if let Some(contact) = self.contact_with(&q, clearance) {
                        return Some(contact);
                    }
                }
                k += stride;
            }
            stride /= 2;
        }
        None
    }

    /// The goal in the chain's base frame for a world hand target.
    fn goal(
        &self,
        base: &IsometryMatrix3<f64>,
        target: &HandTarget,
        orientation: &UnitQuaternion<f64>,
    ) -> IsometryMatrix3<f64> {
        let world = IsometryMatrix3::from_parts(
            Translation3::from(target.position.coords),
            orientation.to_rotation_matrix() * self.rest_hand,
        );
        base.inverse() * world
    }

    /// IK with collision avoidance (Kallmann's unified search): the orbit-angle search
    /// accepts the first posture within the joint limits that collides with nothing.
    /// Returns the orbit angle and the configuration (the body at the reference posture).
    pub fn solve(&self, target: &HandTarget) -> Result<(f64, ArmConfig)> {
        self.solve_with(target, &|_| true)
    }

    /// [`ArmSpace::solve`] with an extra acceptance test.
    pub fn solve_with(
        &self,
        target: &HandTarget,
        accept: &dyn Fn(&ArmConfig) -> bool,
    ) -> Result<(f64, ArmConfig)> {
        self.solve_searching(target, &[0.0; 3], &self.orbit, accept, true)
    }

    /// [`ArmSpace::solve`] with another orbit-angle search (e.g. one starting at the previous
    /// frame's angle when a target is followed).
    pub fn solve_from(&self, target: &HandTarget, orbit: &OrbitSearch) -> Result<(f64, ArmConfig)> {
        orbit.validate()?;
        self.solve_searching(target, &[0.0; 3], orbit, &|_| true, true)
    }

    /// The IK without collision avoidance: the orbit-angle search `orbit` accepts the first
    /// posture within the joint limits, whatever it touches (the `ik` level's frames,
    /// [`crate::level`]).
    pub fn solve_within_limits(
        &self,
        target: &HandTarget,
        orbit: &OrbitSearch,
    ) -> Result<(f64, ArmConfig)> {
        orbit.validate()?;
        self.solve_searching(target, &[0.0; 3], orbit, &|_| true, false)
    }

    /// The arm's IK with the body at `body` (its DoFs within the stance's limits, the feet
    /// planted; zeros where the body does not move): the orbit-angle search `orbit` accepts
    /// the first posture within the joint limits that — when `collisions` — collides with
    /// nothing, the whole body tested. The configuration carries `body`.
    pub fn solve_at(
        &self,
        target: &HandTarget,
        body: &BodyDofs,
        orbit: &OrbitSearch,
        collisions: bool,
    ) -> Result<(f64, ArmConfig)> {
        orbit.validate()?;
        self.solve_searching(target, body, orbit, &|_| true, collisions)
    }

    fn solve_searching(
        &self,
        target: &HandTarget,
        body: &BodyDofs,
        orbit: &OrbitSearch,
        accept: &dyn Fn(&ArmConfig) -> bool,
        collisions: bool,
    ) -> Result<(f64, ArmConfig)> {
        if !target.position.iter().all(|v| v.is_finite()) {
            return Err(PlanError::NonFinite("the hand target".into()));
        }
        if !body.iter().all(|v| v.is_finite()) {
            return Err(PlanError::NonFinite("the body's DoFs".into()));
        }
        let within = match &self.body {
            Some(mode) => mode.motion.within_limits(body),
            None => body.iter().all(|&v| v == 0.0),
        };
        if !within {
            return Err(PlanError::GoalUnreachable {
                why: format!(
                    "the body's DoFs {body:?} lie outside the stance's limits (or the body does \
                     not move in this space)"
                ),
            });
        }
        // The body's pose, and what it touches but for the acting arm, are solved once for
        // the whole search: the arm's DoFs do not move them.
        let posed = self.body.as_ref().map(|mode| mode.posed_body(body));
        let body_touches = match (&self.body, &posed) {
            (Some(mode), Some(p)) => {
                if !mode.planted(p) {
                    return Err(PlanError::GoalUnreachable {
                        why: "the legs cannot keep the feet planted in that body posture".into(),
                    });
                }
                self.body_contact(mode, p, &mode.world(p), self.clearance)
            }
            _ => None,
        };
        let contact = |q7: &[f64; ARM_DOFS]| match (&self.body, &posed) {
            (Some(mode), Some(p)) => body_touches.clone().or_else(|| {
                let posed = mode.with_arm(p, self.limb, q7);
                self.arm_contact(mode, &posed, &mode.world(&posed), self.clearance)
            }),
            _ => self.contact(&join(q7, body)),
        };
        let ok = |q7: &[f64; ARM_DOFS]| {
            (!collisions || contact(q7).is_none()) && accept(&join(q7, body))
        };
        let (base, ik) = self.base_and_ik(body);
        let solve_on = |base: &IsometryMatrix3<f64>| match &target.orientation {
            Some(o) => ik.search_with(&self.goal(base, target, o), orbit, &ok),
            None => {
                let p = base.inverse() * target.position;
                ik.solve_position_with(&p, orbit, &ok)
            }
        };
        // The shoulder rides the girdle, which depends on the solution: the fixed point
        // s = shift(solve(base + s)) of the girdle's shift s.
        let mut s = Vector3::zeros();
        let mut result = solve_on(&shifted(&base, &s));
        let mut previous: Option<(Vector3<f64>, Vector3<f64>)> = None;
        for _ in 0..GIRDLE_ITERATIONS {
            let Ok((_, q)) = &result else { break };
            let image = self.girdle.shift(q);
            if (image - s).norm() < GIRDLE_TOLERANCE {
                break;
            }
            // Plain iteration contracts only by ~0.2 a step near a raised arm (12 steps left
            // 1e-10 m); Anderson's depth-1 mixing (the secant along the last two residuals)
            // converges in a few.
            let mixed = previous.and_then(|(s0, g0)| {
                let dr = (image - s) - (g0 - s0);
                let d = dr.norm_squared();
                (d > 0.0).then(|| image - (image - g0) * ((image - s).dot(&dr) / d))
            });
            previous = Some((s, image));
            // An extrapolated shoulder whose search fails falls back to the plain step.
            let next = mixed.into_iter().chain([image]).find_map(|candidate| {
                let solved = solve_on(&shifted(&base, &candidate)).ok()?;
                Some((candidate, solved))
            });
            let Some((candidate, solved)) = next else {
                break;
            };
            s = candidate;
            result = Ok(solved);
        }
        // A posture solved for a shoulder the girdle does not put there misses the target:
        // not a solution.
        if let Ok((_, q)) = &result {
            let off = (self.girdle.shift(q) - s).norm();
            if off > GIRDLE_MISS {
                return Err(PlanError::GoalUnreachable {
                    why: format!(
                        "the girdle moves the shoulder {:.1} mm from where the arm was solved \
                         for, at the edge of its reach",
                        off * 1e3
                    ),
                });
            }
        }
        result
            .map(|(alpha, q7)| (alpha, join(&q7, body)))
            .map_err(|e| match e {
                AnalyticError::Rejected { within_limits, .. } => PlanError::GoalInCollision {
                    tried: within_limits,
                    contact: self
                        .first_contact_of(target, &base, &ik, orbit, &contact)
                        .unwrap_or_else(|| "a rejected posture".into()),
                },
                other => other.into(),
            })
    }

    /// The first contact of the first within-limits posture the search tries on `base`.
    fn first_contact_of(
        &self,
        target: &HandTarget,
        base: &IsometryMatrix3<f64>,
        ik: &LimbIk,
        orbit: &OrbitSearch,
        contact: &dyn Fn(&[f64; ARM_DOFS]) -> Option<String>,
    ) -> Option<String> {
        let found = std::cell::RefCell::new(None);
        let record = |q: &[f64; ARM_DOFS]| {
            if found.borrow().is_none() {
                *found.borrow_mut() = contact(q);
            }
            false
        };
        let _ = match &target.orientation {
            Some(o) => ik.search_with(&self.goal(base, target, o), orbit, &record),
            None => {
                let p = base.inverse() * target.position;
                ik.solve_position_with(&p, orbit, &record)
            }
        };
        found.into_inner()
    }

    /// The configuration of a full-body pose: the arm's DoFs and, where the body moves, the
    /// body's read back from the spine and the root ([`BodyMotion::dofs_of`]: for poses the
    /// space made, [`ArmSpace::pose_with`]); zeros otherwise.
    pub fn config_of(&self, pose: &Pose) -> ArmConfig {
        let d = self.limb.dofs().start;
        let arm = std::array::from_fn(|i| pose[d + i]);
        let body = match &self.body {
            Some(mode) => mode.motion.dofs_of(pose),
            None => [0.0; 3],
        };
        join(&arm, &body)
    }

    /// A full-body pose with the arm at `q` — and where the body moves, the spine, root and
    /// legs at `q`'s body DoFs; `pose` gives every other DoF.
    pub fn pose_with(&self, pose: &Pose, q: &ArmConfig) -> Pose {
        let mut out = *pose;
        if let Some(mode) = &self.body {
            mode.set_body(&mut out, &body_of(q));
        }
        out[self.limb.dofs()].copy_from_slice(&arm_of(q));
        out
    }
}

/// `base` with its shoulder moved by `shift` (in the base's own frame).
fn shifted(base: &IsometryMatrix3<f64>, shift: &Vector3<f64>) -> IsometryMatrix3<f64> {
    IsometryMatrix3::from_parts(
        (base.translation.vector + base.rotation * shift).into(),
        base.rotation,
    )
}

/// Linear interpolation of two configurations.
pub fn lerp(a: &ArmConfig, b: &ArmConfig, t: f64) -> ArmConfig {
    std::array::from_fn(|i| a[i] + (b[i] - a[i]) * t)
}
