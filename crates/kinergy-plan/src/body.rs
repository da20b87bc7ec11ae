//! The character's collision geometry: one capsule per body part, riding a joint's frame,
//! and the pairs that are never tested (Kallmann 2005, "Collisions").
//!
//! Capsules are cheap, exact to test against each other (a segment–segment distance, see
//! [`segment_distance`]) and close to limbs' shapes. The torso is three capsules (abdomen,
//! chest and a shoulder girdle between the clavicle joints) and the pelvis one across the hip
//! joints. Radii are for a 1.75 m adult and scale with the character's height.
//!
//! # Disabled pairs
//! As in the paper, the character is put in a valid *reference posture*
//! ([`reference_pose`]: standing, arms hanging 10° away from the body, elbows bent 10°):
//! the pairs of parts that touch there and are *adjacent* — riding joints at most two links
//! apart in the skeleton, e.g. upper arm and forearm, chest and upper arm through the 0-DoF
//! clavicle — are disabled for every later query. Parts that are not adjacent never touch in
//! the reference posture (a test checks it), so no real contact is ever switched off.

use kinergy_io::InvalidSetting;
use kinergy_reach::character::{Character, Limb, Pose, joint};
use nalgebra::{IsometryMatrix3, Point3, Vector3};

use crate::error::Result;

/// A capsule: the points within `radius` of the segment `a`–`b`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Capsule {
    /// One end of the axis.
    pub a: Point3<f64>,
    /// The other end of the axis.
    pub b: Point3<f64>,
    /// The radius, meters.
    pub radius: f64,
}

impl Capsule {
    /// The capsule moved by `frame`.
    pub fn transformed(&self, frame: &IsometryMatrix3<f64>) -> Capsule {
        Capsule {
            a: frame * self.a,
            b: frame * self.b,
            radius: self.radius,
        }
    }

    /// Distance between the two capsules' surfaces; negative when they overlap.
    pub fn gap(&self, other: &Capsule) -> f64 {
        segment_distance(&self.a, &self.b, &other.a, &other.b) - self.radius - other.radius
    }

    /// Axis-aligned bounds (min, max), widened by `margin`.
    pub fn bounds(&self, margin: f64) -> (Point3<f64>, Point3<f64>) {
        let r = Vector3::repeat(self.radius + margin);
        (self.a.inf(&self.b) - r, self.a.sup(&self.b) + r)
    }
}

/// Shortest distance between segments `p0–p1` and `q0–q1` (Ericson, *Real-Time Collision
/// Detection*, §5.1.9), robust to degenerate (point) segments.
pub fn segment_distance(
    p0: &Point3<f64>,
    p1: &Point3<f64>,
    q0: &Point3<f64>,
    q1: &Point3<f64>,
) -> f64 {
    const EPS: f64 = 1e-18;
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = d1.norm_squared();
    let e = d2.norm_squared();
    let f = d2.dot(&r);
    let (s, t);
    if a <= EPS && e <= EPS {
        return r.norm();
    }
    if a <= EPS {
        s = 0.0;
        t = (f / e).clamp(0.0, 1.0);
    } else {
        let c = d1.dot(&r);
        if e <= EPS {
            t = 0.0;
            s = (-c / a).clamp(0.0, 1.0);
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s0 = if denom > EPS * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t0 = (b * s0 + f) / e;
            if t0 < 0.0 {
                t0 = 0.0;
                s0 = (-c / a).clamp(0.0, 1.0);
            } else if t0 > 1.0 {
                t0 = 1.0;
                s0 = ((b - c) / a).clamp(0.0, 1.0);
            }
            s = s0;
            t = t0;
        }
    }
    let c1 = p0 + d1 * s;
    let c2 = q0 + d2 * t;
    (c1 - c2).norm()
}

/// One body part: a capsule fixed in a joint's frame.
#[derive(Debug, Clone, PartialEq)]
pub struct BodyPart {
    /// E.g. `right_forearm`, `chest`.
    pub name: String,
    /// The character joint whose world frame carries it ([`Character::world_frames`]).
    pub joint: usize,
    /// The capsule in that joint's frame.
    pub capsule: Capsule,
}

/// The collision geometry of a [`Character`]: its parts and the disabled pairs.
#[derive(Debug, Clone)]
pub struct BodyGeometry {
    parts: Vec<BodyPart>,
    /// `disabled[i * n + j]`, symmetric.
    disabled: Vec<bool>,
}

/// Radii of the parts for a 1.75 m adult, meters (scaled by height / 1.75).
mod radius {
    pub const PELVIS: f64 = 0.08;
    pub const ABDOMEN: f64 = 0.11;
    pub const CHEST: f64 = 0.12;
    pub const GIRDLE: f64 = 0.06;
    pub const NECK: f64 = 0.05;
    pub const HEAD: f64 = 0.09;
    pub const UPPER_ARM: f64 = 0.045;
    pub const FOREARM: f64 = 0.035;
    pub const HAND: f64 = 0.03;
    pub const THIGH: f64 = 0.07;
    pub const SHANK: f64 = 0.05;
    pub const FOOT: f64 = 0.035;
}

/// The reference posture in which touching adjacent pairs are disabled: the rest pose with
/// both arms swung 10° away from the body and the elbows bent 10°, the posture the planner's
/// examples start from.
pub fn reference_pose(character: &Character) -> Pose {
    let mut pose = character.rest_pose();
    for (limb, away) in [(Limb::RightArm, 1.0), (Limb::LeftArm, -1.0)] {
        let d = character.limb_dofs(limb).start;
        // swing_y > 0 swings the arm toward −X: away from the body for the right arm.
        pose[d + 1] = away * 10f64.to_radians();
        pose[d + 3] = 10f64.to_radians();
    }
    pose
}

impl BodyGeometry {
    /// The default capsules for `character`, with the pairs touching in
    /// [`reference_pose`] disabled.
    pub fn new(character: &Character) -> Result<BodyGeometry> {
        let parts = default_parts(character);
        BodyGeometry::with_parts(character, parts, &reference_pose(character))
    }

    /// Custom parts; the adjacent pairs touching at `reference` are disabled. Non-adjacent
    /// pairs touching there are an error: the reference posture must be valid.
    pub fn with_parts(
        character: &Character,
        parts: Vec<BodyPart>,
        reference: &Pose,
    ) -> Result<BodyGeometry> {
        let joints = character.joints();
        for (i, p) in parts.iter().enumerate() {
            let c = &p.capsule;
            InvalidSetting::require(
                p.joint < joints.len(),
                &format!("parts[{i}].joint"),
                format!("joint {} does not exist", p.joint),
            )?;
            InvalidSetting::require(
                c.radius.is_finite()
                    && c.radius >= 0.0
                    && c.a.iter().chain(c.b.iter()).all(|v| v.is_finite()),
                &format!("parts[{i}].capsule"),
                "finite points and a finite radius ≥ 0",
            )?;
        }
        let n = parts.len();
        let frames = character.world_frames(reference);
        let world: Vec<Capsule> = parts
            .iter()
            .map(|p| p.capsule.transformed(&frames[p.joint]))
            .collect();
        let mut disabled = vec![false; n * n];
        for i in 0..n {
            disabled[i * n + i] = true;
            for j in i + 1..n {
                if world[i].gap(&world[j]) > 0.0 {
                    continue;
                }
                InvalidSetting::require(
                    tree_distance(character, parts[i].joint, parts[j].joint) <= 2,
                    "reference",
                    format!(
                        "{} and {} touch in the reference posture but are not adjacent",
                        parts[i].name, parts[j].name
                    ),
                )?;
                disabled[i * n + j] = true;
                disabled[j * n + i] = true;
            }
        }
        Ok(BodyGeometry { parts, disabled })
    }

    /// The parts.
    pub fn parts(&self) -> &[BodyPart] {
        &self.parts
    }

    /// The index of the part named `name`.
    pub fn part_index(&self, name: &str) -> Option<usize> {
        self.parts.iter().position(|p| p.name == name)
    }

    /// True when the pair `(i, j)` is never tested (and for `i == j`).
    pub fn is_disabled(&self, i: usize, j: usize) -> bool {
        self.disabled[i * self.parts.len() + j]
    }

    /// The disabled pairs `(i, j)`, `i < j`.
    pub fn disabled_pairs(&self) -> Vec<(usize, usize)> {
        let n = self.parts.len();
        (0..n)
            .flat_map(|i| (i + 1..n).map(move |j| (i, j)))
            .filter(|&(i, j)| self.disabled[i * n + j])
            .collect()
    }

    /// Every part's capsule in world for the joint frames of a pose
    /// ([`Character::world_frames`]).
    pub fn world_capsules(&self, frames: &[IsometryMatrix3<f64>]) -> Vec<Capsule> {
        self.parts
            .iter()
            .map(|p| p.capsule.transformed(&frames[p.joint]))
            .collect()
    }

    /// The enabled pairs that overlap in the pose whose joint frames are `frames`.
    pub fn self_contacts(&self, frames: &[IsometryMatrix3<f64>]) -> Vec<(usize, usize)> {
        let world = self.world_capsules(frames);
        let n = self.parts.len();
        let mut out = Vec::new();
        for i in 0..n {
            for j in i + 1..n {
                if !self.is_disabled(i, j) && world[i].gap(&world[j]) < 0.0 {
                    out.push((i, j));
                }
            }
        }
        out
    }

    /// The parts carried by a limb's three moving joints (base, mid, end): for an arm, the
    /// upper arm, forearm and hand.
    pub fn limb_parts(&self, limb: Limb) -> Vec<usize> {
        let [base, mid, end, _] = limb.joints();
        (0..self.parts.len())
            .filter(|&i| [base, mid, end].contains(&self.parts[i].joint))
            .collect()
    }
}

/// Links between two joints in the skeleton tree.
fn tree_distance(character: &Character, a: usize, b: usize) -> usize {
    let joints = character.joints();
    let ancestors = |mut j: usize| {
        let mut out = vec![j];
        while let Some(p) = joints[j].parent {
            out.push(p);
            j = p;
        }
        out
    };
    let (pa, pb) = (ancestors(a), ancestors(b));
    for (i, ja) in pa.iter().enumerate() {
        if let Some(k) = pb.iter().position(|jb| jb == ja) {
            return i + k;
        }
    }
    usize::MAX
}

/// The default parts (see the [module docs](self)).
fn default_parts(character: &Character) -> Vec<BodyPart> {
    let scale = character.proportions().height() / 1.75;
    let joints = character.joints();
    let offset = |j: usize| Point3::from(joints[j].offset);
    let mut parts = Vec::new();
    let mut push = |name: &str, joint: usize, a: Point3<f64>, b: Point3<f64>, r: f64| {
        parts.push(BodyPart {
            name: name.to_string(),
            joint,
            capsule: Capsule {
                a,
                b,
                radius: r * scale,
            },
        });
    };
    // A bone from `from` to its child `to`, in `from`'s frame; `tip` pulls the far end in by
    // the radius so the rounded end stops at the child joint (fingertips, toe tips, head top).
    let bone = |from: usize, to: usize, r: f64, tip: bool| {
        let b = offset(to);
        let len = b.coords.norm();
        let pull = if tip && len > 0.0 {
            (r * scale).min(0.5 * len) / len
        } else {
            0.0
        };
        (
            from,
            Point3::origin(),
            Point3::from(b.coords * (1.0 - pull)),
            r,
        )
    };

    // Pelvis across the hip joints, pulled in so it ends level with the hip joints' outside.
    let (rh, lh) = (offset(joint::RIGHT_UP_LEG), offset(joint::LEFT_UP_LEG));
    let mid = Point3::from((rh.coords + lh.coords) * 0.5);
    let inward = |p: Point3<f64>, by: f64| {
        let d = p - mid;
        let len = d.norm();
        if len > by {
            mid + d * ((len - by) / len)
        } else {
            mid
        }
    };
    push(
        "pelvis",
        joint::HIPS,
        inward(rh, 0.02 * scale),
        inward(lh, 0.02 * scale),
        radius::PELVIS,
    );

    for (name, (j, a, b, r)) in [
        (
            "abdomen",
            bone(joint::SPINE, joint::CHEST, radius::ABDOMEN, false),
        ),
        (
            "chest",
            bone(joint::CHEST, joint::NECK, radius::CHEST, false),
        ),
        ("neck", bone(joint::NECK, joint::HEAD, radius::NECK, false)),
        (
            "head",
            bone(joint::HEAD, joint::HEAD_END, radius::HEAD, true),
        ),
    ] {
        push(name, j, a, b, r);
    }
    // The shoulder girdle: between the clavicle joints, ending 6 cm inside each shoulder.
    let (rs, ls) = (
        offset(joint::RIGHT_SHOULDER) + joints[joint::RIGHT_ARM].offset,
        offset(joint::LEFT_SHOULDER) + joints[joint::LEFT_ARM].offset,
    );
    let gmid = Point3::from((rs.coords + ls.coords) * 0.5);
    let pull = |p: Point3<f64>| {
        let d = p - gmid;
        let len = d.norm();
        let keep = (len - 0.06 * scale).max(0.0);
        gmid + d * (keep / len.max(f64::MIN_POSITIVE))
    };
    push("girdle", joint::CHEST, pull(rs), pull(ls), radius::GIRDLE);
    for (side, limb, leg) in [
        ("right", Limb::RightArm, Limb::RightLeg),
        ("left", Limb::LeftArm, Limb::LeftLeg),
    ] {
        let [s, e, w, t] = limb.joints();
        for (part, (j, a, b, r)) in [
            ("upper_arm", bone(s, e, radius::UPPER_ARM, false)),
            ("forearm", bone(e, w, radius::FOREARM, false)),
            ("hand", bone(w, t, radius::HAND, true)),
        ] {
            push(&format!("{side}_{part}"), j, a, b, r);
        }
        let [h, k, a, toe] = leg.joints();
        for (part, (j, p, q, r)) in [
            ("thigh", bone(h, k, radius::THIGH, false)),
            ("shank", bone(k, a, radius::SHANK, false)),
            ("foot", bone(a, toe, radius::FOOT, true)),
        ] {
            push(&format!("{side}_{part}"), j, p, q, r);
        }
    }
    parts
}

#[cfg(test)]
mod tests {
    use super::*;

    fn brute_distance(
        p0: &Point3<f64>,
        p1: &Point3<f64>,
        q0: &Point3<f64>,
        q1: &Point3<f64>,
    ) -> f64 {
        let n = 400;
        let mut best = f64::INFINITY;
        for i in 0..=n {
            let p = p0 + (p1 - p0) * (i as f64 / n as f64);
            // Closest point on q0–q1 to p, exactly.
            let d = q1 - q0;
            let t = if d.norm_squared() > 0.0 {
                ((p - q0).dot(&d) / d.norm_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            best = best.min((p - (q0 + d * t)).norm());
        }
        best
    }

    #[test]
    fn segment_distance_matches_dense_sampling() {
        let pts = [
            [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.5, 1.0, 0.0, 0.5, 2.0, 0.0],
            [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 2.0, 0.0, 0.0, 3.0, 0.0, 0.0],
            [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 1.0, 0.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.3, -1.0, 0.2, 0.3, 1.0, 0.2],
            [
                0.1, 0.2, 0.3, -0.4, 0.5, 0.9, 0.7, -0.2, 0.1, -0.3, 0.8, -0.6,
            ],
        ];
        for v in pts {
            let p = |i: usize| Point3::new(v[i], v[i + 1], v[i + 2]);
            let exact = segment_distance(&p(0), &p(3), &p(6), &p(9));
            let brute = brute_distance(&p(0), &p(3), &p(6), &p(9));
            assert!(
                exact <= brute + 1e-12 && brute - exact < 2e-3,
                "{exact} vs {brute}"
            );
        }
    }

    #[test]
    fn only_adjacent_pairs_are_disabled_and_the_reference_is_valid() {
        let body = Character::from_height(1.75).unwrap();
        let geo = BodyGeometry::new(&body).unwrap();
        assert_eq!(geo.parts().len(), 18);
        let frames = body.world_frames(&reference_pose(&body));
        assert!(geo.self_contacts(&frames).is_empty());
        let pairs = geo.disabled_pairs();
        let name = |i: usize| geo.parts()[i].name.as_str();
        let has = |a: &str, b: &str| {
            pairs
                .iter()
                .any(|&(i, j)| (name(i), name(j)) == (a, b) || (name(j), name(i)) == (a, b))
        };
        assert!(has("right_upper_arm", "right_forearm"));
        assert!(has("right_forearm", "right_hand"));
        assert!(has("right_thigh", "right_shank"));
        // The arm and the chest do not touch at rest: the arm cannot pass through the chest.
        assert!(!has("chest", "right_upper_arm"));
        assert!(!has("right_hand", "right_thigh"));
        for (i, j) in pairs {
            let d = tree_distance(&body, geo.parts()[i].joint, geo.parts()[j].joint);
            assert!(d <= 2, "{} × {}", name(i), name(j));
        }
    }

    #[test]
    fn an_arm_swung_through_the_torso_is_a_self_contact() {
        let body = Character::from_height(1.75).unwrap();
        let geo = BodyGeometry::new(&body).unwrap();
        let mut pose = reference_pose(&body);
        let d = body.limb_dofs(Limb::RightArm).start;
        pose[d + 1] = -1.2; // the right arm swung across the body
        let contacts = geo.self_contacts(&body.world_frames(&pose));
        let names: Vec<_> = contacts
            .iter()
            .map(|&(i, j)| (geo.parts()[i].name.clone(), geo.parts()[j].name.clone()))
            .collect();
        assert!(
            names
                .iter()
                .any(|(a, b)| a.starts_with("right_") && b == "chest"
                    || b.starts_with("right_") && a == "chest"
                    || a == "chest" && b.starts_with("right_")),
            "{names:?}"
        );
    }
}
