//! The character's mass and balance: segment masses and centres of mass, the whole body's
//! centre of mass (COM), the foot points and the support polygon the COM's ground projection
//! must stay in.
//!
//! # Centre of mass
//! Segment masses as fractions of body mass and centres of mass along segments from the
//! proximal end, Dempster's data via Winter's Table 4.1 ([`Character::mass_segments`]):
//! hand 0.006 at 0.506 of wrist→knuckle II (the knuckle taken half-way along our
//! wrist→fingertip hand, so 0.253 of it); forearm 0.016 at 0.430; upper arm 0.028 at 0.436;
//! foot 0.0145 half-way from the ankle to the 2nd metatarsal head (taken at 0.7 of the
//! ankle→toe-tip vector, so 0.35 of it); shank 0.0465 at 0.433; thigh 0.100 at 0.433;
//! head and neck 0.081 at the ear canal (our `Head` joint); thorax 0.216 at 0.82 from C7–T1
//! (`Neck`) to T12–L1 (`Chest`); abdomen 0.139 at 0.44 from T12–L1 (`Chest`) to L4–L5
//! (`Spine`); pelvis 0.142 at 0.105 from L4–L5 (`Spine`) to the mid-point of the hip joints.
//! The fractions sum to 1.
//!
//! # Foot points and the support polygon
//! Each foot has a toe point, its tip (the `…Foot_End` End Site, `(0, toe, ankle_height)` in
//! the ankle frame), and a heel point `(0, −heel, ankle_height)` in the ankle frame: at rest
//! both lie on y = 0, the toe `toe` ahead of the ankle and the heel `heel` behind it
//! ([`Character::foot_points`]). The support polygon is the convex hull in x–z of the foot
//! points in contact: those within [`CONTACT_TOLERANCE`] of the lowest one. A foot whose toe
//! tip is in contact while its heel is raised stands on its forefoot: the support's rear edge
//! moves from the heel to the ball of the foot ([`BALL`]) as the heel rises by
//! [`HEEL_RELEASE`] (the weight leaves the heel gradually), and on tiptoe the toes bend at the
//! ball, which stays on the ground — the polygon shrinks continuously rather than collapsing
//! to the line of the toe tips.

use nalgebra::{IsometryMatrix3, Point2, Point3, Vector3};

use super::body::Character;
use super::layout::{Limb, Pose, joint};
use super::proportions::LegSegments;

/// How far above the lowest foot point (meters) a heel or toe still counts as touching the
/// ground, for the support polygon.
pub const CONTACT_TOLERANCE: f64 = 0.01;

/// Where the ball of the foot (the metatarsal heads) lies, as a fraction of the way from the
/// ankle to the toe tip (as for the foot's centre of mass).
pub const BALL: f64 = 0.7;

/// How high the heel rises (meters) before the support's rear edge has moved from the heel
/// to the ball of the foot.
pub const HEEL_RELEASE: f64 = 0.03;

/// Foot breadth as a fraction of height (Drillis & Contini: 0.055).
pub const FOOT_BREADTH: f64 = 0.055;

/// One body segment's share of the mass and its centre of mass in a pose.
#[derive(Debug, Clone, PartialEq)]
pub struct MassSegment {
    /// E.g. `thorax`, `right_thigh`.
    pub name: &'static str,
    /// Fraction of the body's mass.
    pub mass_fraction: f64,
    /// World position of its centre of mass.
    pub com: Point3<f64>,
}

/// The convex hull of the foot points touching the ground, in the x–z plane (points are
/// `(x, z)`), counter-clockwise in that plane.
#[derive(Debug, Clone, PartialEq)]
pub struct SupportPolygon {
    vertices: Vec<Point2<f64>>,
}

impl SupportPolygon {
    /// The convex hull of `points` (Andrew's monotone chain; collinear points dropped).
    pub fn hull(points: &[Point2<f64>]) -> SupportPolygon {
        let mut pts: Vec<Point2<f64>> = points.to_vec();
        pts.sort_by(|a, b| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y)));
        pts.dedup_by(|a, b| (*a - *b).norm() < 1e-12);
        if pts.len() < 3 {
            return SupportPolygon { vertices: pts };
        }
        let cross = |o: &Point2<f64>, a: &Point2<f64>, b: &Point2<f64>| (a - o).perp(&(b - o));
        let half = |points: &mut dyn Iterator<Item = &Point2<f64>>| {
            let mut chain: Vec<Point2<f64>> = Vec::with_capacity(pts.len());
            for p in points {
                while chain.len() >= 2
                    && cross(&chain[chain.len() - 2], &chain[chain.len() - 1], p) <= 1e-15
                {
                    chain.pop();
                }
                chain.push(*p);
            }
            chain.pop();
            chain
        };
        let mut hull = half(&mut pts.iter());
        hull.extend(half(&mut pts.iter().rev()));
        SupportPolygon { vertices: hull }
    }

    /// The vertices `(x, z)`, counter-clockwise in the x–z plane.
    pub fn vertices(&self) -> &[Point2<f64>] {
        &self.vertices
    }

    /// Distance from `(x, z)` to the polygon's boundary, positive inside, negative outside
    /// (a polygon of one or two points has no inside).
    pub fn margin(&self, p: Point2<f64>) -> f64 {
        let v = &self.vertices;
        match v.len() {
            0 => f64::NEG_INFINITY,
            1 => -(p - v[0]).norm(),
            _ => {
                let n = v.len();
                let mut nearest = f64::INFINITY;
                let mut inside = n >= 3;
                for i in 0..n {
                    let (a, b) = (v[i], v[(i + 1) % n]);
                    let ab = b - a;
                    let t = ((p - a).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0);
                    nearest = nearest.min((p - (a + ab * t)).norm());
                    if ab.perp(&(p - a)) < 0.0 {
                        inside = false;
                    }
                }
                if inside { nearest } else { -nearest }
            }
        }
    }

    /// True when `(x, z)` lies inside or on the polygon.
    pub fn contains(&self, p: Point2<f64>) -> bool {
        self.margin(p) >= -1e-12
    }
}

impl Character {
    /// The foot points `[right heel, right toe, left heel, left toe]` in world.
    pub fn foot_points(&self, pose: &Pose) -> [Point3<f64>; 4] {
        let f = self.world_frames(pose);
        let heel = |ankle: usize, leg: &LegSegments| {
            f[ankle] * Point3::new(0.0, -leg.heel, leg.ankle_height)
        };
        let p = &self.proportions;
        [
            heel(joint::RIGHT_FOOT, &p.right_leg),
            Point3::from(f[joint::RIGHT_FOOT_END].translation.vector),
            heel(joint::LEFT_FOOT, &p.left_leg),
            Point3::from(f[joint::LEFT_FOOT_END].translation.vector),
        ]
    }

    /// Every body segment's mass fraction and centre of mass (Winter's Table 4.1, see the
    /// [module docs](self)).
    pub fn mass_segments(&self, pose: &Pose) -> Vec<MassSegment> {
        self.mass_segments_in(&self.world_frames(pose))
    }

    /// [`Character::mass_segments`] from world frames already computed.
    pub fn mass_segments_in(&self, frames: &[IsometryMatrix3<f64>]) -> Vec<MassSegment> {
        let p: Vec<Point3<f64>> = frames
            .iter()
            .map(|f| Point3::from(f.translation.vector))
            .collect();
        let along = |a: usize, b: usize, t: f64| p[a] + (p[b] - p[a]) * t;
        let seg = |name, mass_fraction, com| MassSegment {
            name,
            mass_fraction,
            com,
        };
        let hips_mid =
            Point3::from((p[joint::RIGHT_UP_LEG].coords + p[joint::LEFT_UP_LEG].coords) * 0.5);
        let mut out = vec![
            seg("head_and_neck", 0.081, p[joint::HEAD]),
            seg("thorax", 0.216, along(joint::NECK, joint::CHEST, 0.82)),
            seg("abdomen", 0.139, along(joint::CHEST, joint::SPINE, 0.44)),
            seg(
                "pelvis",
                0.142,
                p[joint::SPINE] + (hips_mid - p[joint::SPINE]) * 0.105,
            ),
        ];
        let arms: [(&'static str, &'static str, &'static str, Limb); 2] = [
            (
                "right_upper_arm",
                "right_forearm",
                "right_hand",
                Limb::RightArm,
            ),
            ("left_upper_arm", "left_forearm", "left_hand", Limb::LeftArm),
        ];
        for (upper, fore, hand, limb) in arms {
            let [s, e, w, t] = limb.joints();
            out.push(seg(upper, 0.028, along(s, e, 0.436)));
            out.push(seg(fore, 0.016, along(e, w, 0.430)));
            out.push(seg(hand, 0.006, along(w, t, 0.253)));
        }
        let legs: [(&'static str, &'static str, &'static str, Limb); 2] = [
            ("right_thigh", "right_shank", "right_foot", Limb::RightLeg),
            ("left_thigh", "left_shank", "left_foot", Limb::LeftLeg),
        ];
        for (thigh, shank, foot, limb) in legs {
            let [h, k, a, t] = limb.joints();
            out.push(seg(thigh, 0.100, along(h, k, 0.433)));
            out.push(seg(shank, 0.0465, along(k, a, 0.433)));
            out.push(seg(foot, 0.0145, along(a, t, 0.35)));
        }
        out
    }

    /// The whole body's centre of mass: the mass-weighted mean of [`Character::mass_segments`].
    pub fn com(&self, pose: &Pose) -> Point3<f64> {
        self.com_in(&self.world_frames(pose))
    }

    /// [`Character::com`] from world frames already computed.
    pub fn com_in(&self, frames: &[IsometryMatrix3<f64>]) -> Point3<f64> {
        let segments = self.mass_segments_in(frames);
        let total: f64 = segments.iter().map(|s| s.mass_fraction).sum();
        let sum = segments.iter().fold(Vector3::zeros(), |acc, s| {
            acc + s.com.coords * s.mass_fraction
        });
        Point3::from(sum / total)
    }

    /// The support polygon: the convex hull in x–z of the feet's soles — each heel and toe
    /// point widened sideways by half the foot breadth ([`FOOT_BREADTH`] of the height) —
    /// of the points within [`CONTACT_TOLERANCE`] of the lowest; a rising heel gives way to the
    /// ball of the foot ([`BALL`], [`HEEL_RELEASE`]). One foot on the ground gives its sole's
    /// rectangle, not a line.
    pub fn support_polygon(&self, pose: &Pose) -> SupportPolygon {
        self.support_polygon_in(&self.world_frames(pose))
    }

    /// [`Character::support_polygon`] from world frames already computed.
    pub fn support_polygon_in(&self, f: &[IsometryMatrix3<f64>]) -> SupportPolygon {
        let half = 0.5 * FOOT_BREADTH * self.proportions.height();
        let p = &self.proportions;
        // Per foot: heel corners, toe-tip corners, and the ball's corners (the metatarsal
        // heads, 0.7 of the way from the ankle to the toe tip).
        let soles = [
            (joint::RIGHT_FOOT, &p.right_leg),
            (joint::LEFT_FOOT, &p.left_leg),
        ]
        .map(|(ankle, leg)| {
            [-leg.heel, leg.toe, BALL * leg.toe]
                .map(|y| [-half, half].map(|x| f[ankle] * Point3::new(x, y, leg.ankle_height)))
        });
        let lowest = soles
            .iter()
            .flat_map(|sole| sole[..2].iter().flatten())
            .map(|p| p.y)
            .fold(f64::INFINITY, f64::min);
        let touches = |p: &Point3<f64>| p.y <= lowest + CONTACT_TOLERANCE;
        let mut contact = Vec::with_capacity(12);
        for [heel, toe, ball] in &soles {
            let ground = |p: &Point3<f64>| Point2::new(p.x, p.z);
            let toe_down: Vec<_> = toe.iter().filter(|p| touches(p)).map(ground).collect();
            if toe_down.len() == toe.len() {
                // Standing on the toes: the support's rear edge moves from the heel to the
                // ball of the foot as the heel rises (the weight leaves the heel gradually),
                // and on tiptoe the toes bend at the ball, which stays on the ground.
                for (h, b) in heel.iter().zip(ball) {
                    let u = ((h.y - lowest) / HEEL_RELEASE).clamp(0.0, 1.0);
                    contact.push(ground(h) + (ground(b) - ground(h)) * u);
                }
            } else {
                contact.extend(heel.iter().filter(|p| touches(p)).map(ground));
            }
            contact.extend(toe_down);
        }
        SupportPolygon::hull(&contact)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hull_drops_interior_and_collinear_points() {
        let pts = [
            Point2::new(0.0, 0.0),
            Point2::new(1.0, 0.0),
            Point2::new(0.5, 0.0),
            Point2::new(1.0, 1.0),
            Point2::new(0.0, 1.0),
            Point2::new(0.5, 0.5),
        ];
        let hull = SupportPolygon::hull(&pts);
        assert_eq!(hull.vertices().len(), 4);
        assert!((hull.margin(Point2::new(0.5, 0.5)) - 0.5).abs() < 1e-15);
        assert!((hull.margin(Point2::new(2.0, 0.5)) + 1.0).abs() < 1e-15);
    }
}
