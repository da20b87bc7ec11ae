//! Hands: the hand frame the planner targets, hand shapes (finger joint values) and the
//! fingers added to the character's BVH export.
//!
//! # The hand frame and its grip point
//! A hand target (Kallmann 2005: wrist location + orientation + hand shape) is given for the
//! **grip point**, the centre of the palm, [`GRIP_FRACTION`] of the way from the wrist to the
//! fingertip, in the wrist joint's orientation. Orientations are rotations *from the hand's
//! rest orientation* (hanging along the body, fingers down, palm facing the thigh): the
//! identity is the resting hand, a −90° turn about world x points the fingers forward.
//!
//! # Fingers
//! Each hand has five fingers of three flexion joints (thumb: carpometacarpal, metacarpal,
//! interphalangeal; the others: knuckle, middle and end joints). A [`HandShape`] holds the
//! 15 joint angles; its curl presets scale each finger's joints between straight (0) and
//! fully bent (1). The character's collision geometry keeps one capsule per hand: fingers are
//! drawn, not collided.

use kinergy_motion::{Axis, Clip, Dof, Joint, PositionReading, Skeleton};
use kinergy_reach::character::{Character, Pose, joint};
use nalgebra::Vector3;
use std::sync::Arc;

use crate::error::Result;

/// Where the grip point lies along the hand, from the wrist (0) to the fingertip (1).
pub const GRIP_FRACTION: f64 = 0.4;

/// Finger names in [`HandShape`] order.
pub const FINGERS: [&str; 5] = ["Thumb", "Index", "Middle", "Ring", "Pinky"];

/// Each finger's joint angles when fully curled, radians (thumb first).
const FULL_CURL_DEG: [[f64; 3]; 5] = [
    [40.0, 50.0, 70.0],
    [90.0, 100.0, 70.0],
    [90.0, 100.0, 70.0],
    [90.0, 100.0, 70.0],
    [90.0, 100.0, 70.0],
];

/// The 15 finger joint angles of one hand, radians, finger by finger (thumb, index, middle,
/// ring, little), proximal joint first. Positive angles curl toward the palm.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HandShape {
    /// The joint angles.
    pub joints: [f64; 15],
}

impl HandShape {
    /// Every finger curled by `curls[f]` of its full curl.
    pub fn from_curls(curls: [f64; 5]) -> HandShape {
        let mut joints = [0.0; 15];
        for (f, c) in curls.iter().enumerate() {
            for k in 0..3 {
                joints[3 * f + k] = c * FULL_CURL_DEG[f][k].to_radians();
            }
        }
        HandShape { joints }
    }

    /// Straight, open fingers.
    pub fn open() -> HandShape {
        HandShape::from_curls([0.0; 5])
    }

    /// The slightly curled hand of a relaxed arm.
    pub fn relaxed() -> HandShape {
        HandShape::from_curls([0.15, 0.2, 0.25, 0.3, 0.35])
    }

    /// A power grip (a handle, a thick object).
    pub fn grip() -> HandShape {
        HandShape::from_curls([0.6, 0.75, 0.8, 0.8, 0.8])
    }

    /// A pinch between the thumb and the first two fingers (a book's spine, a thin object).
    pub fn pinch() -> HandShape {
        HandShape::from_curls([0.5, 0.45, 0.45, 0.6, 0.7])
    }

    /// A preset by name: `open`, `relaxed`, `power` (or `grip`), `pinch`.
    pub fn preset(name: &str) -> Option<HandShape> {
        match name {
            "open" => Some(HandShape::open()),
            "relaxed" => Some(HandShape::relaxed()),
            "power" | "grip" => Some(HandShape::grip()),
            "pinch" => Some(HandShape::pinch()),
            _ => None,
        }
    }

    /// The shape `t` of the way from `self` to `other` (joint by joint; `t` in \[0, 1\]).
    pub fn lerp(&self, other: &HandShape, t: f64) -> HandShape {
        let mut joints = self.joints;
        for (j, o) in joints.iter_mut().zip(&other.joints) {
            *j += (o - *j) * t;
        }
        HandShape { joints }
    }
}

/// Both hands' shapes in one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hands {
    /// The right hand.
    pub right: HandShape,
    /// The left hand.
    pub left: HandShape,
}

impl Default for Hands {
    fn default() -> Hands {
        Hands {
            right: HandShape::relaxed(),
            left: HandShape::relaxed(),
        }
    }
}

/// Where each new joint's values come from when fingers are added.
#[derive(Debug, Clone, Copy)]
enum Source {
    /// The character skeleton's joint.
    Body(usize),
    /// Finger joint `k` (0–14) of the right (true) or left hand.
    Finger(bool, usize),
    /// A finger tip (End Site).
    Tip,
}

/// The character's BVH skeleton with five three-joint fingers under each hand, and how to
/// fill its poses.
#[derive(Debug, Clone)]
pub struct FingeredSkeleton {
    skeleton: Arc<Skeleton>,
    sources: Vec<Source>,
}

impl FingeredSkeleton {
    /// The character's exported skeleton ([`Character::skeleton`]) with fingers: after each
    /// `…Hand_End`, joints `…Thumb1`–`…Thumb3` … `…Pinky1`–`…Pinky3` with End Sites, one
    /// rotation channel each (the curl axis at rest), offsets in the world-aligned rest
    /// frame like the rest of the export.
    pub fn new(character: &Character) -> Result<FingeredSkeleton> {
        let body = character.skeleton();
        let p = character.proportions();
        let mut joints: Vec<Joint> = Vec::new();
        let mut sources = Vec::new();
        let mut remap = vec![0usize; body.joints().len()];
        for (i, j) in body.joints().iter().enumerate() {
            remap[i] = joints.len();
            let mut copy = j.clone();
            copy.parent = j.parent.map(|q| remap[q]);
            joints.push(copy);
            sources.push(Source::Body(i));
            let (right, hand) = match i {
                joint::RIGHT_HAND_END => (true, joint::RIGHT_HAND),
                joint::LEFT_HAND_END => (false, joint::LEFT_HAND),
                _ => continue,
            };
            let side = if right { "Right" } else { "Left" };
            let length = p
                .arm(if right {
                    kinergy_motion::Side::Right
                } else {
                    kinergy_motion::Side::Left
                })
                .hand;
            add_fingers(&mut joints, &mut sources, remap[hand], side, right, length);
        }
        Ok(FingeredSkeleton {
            skeleton: Arc::new(Skeleton::new(joints)?),
            sources,
        })
    }

    /// The skeleton.
    pub fn skeleton(&self) -> &Arc<Skeleton> {
        &self.skeleton
    }

    /// A clip playing the character `poses` with the hand shapes `hands` (one per pose).
    pub fn clip(
        &self,
        character: &Character,
        poses: &[Pose],
        hands: &[Hands],
        frame_time: f64,
    ) -> Result<Clip> {
        let body = character.skeleton();
        let mut values = Vec::with_capacity(poses.len() * self.skeleton.dof_count());
        let mut previous: Option<Vec<f64>> = None;
        for (pose, h) in poses.iter().zip(hands) {
            let frame = character.skeleton_pose(pose, previous.as_deref());
            for src in &self.sources {
                match *src {
                    Source::Body(i) => {
                        let first = body.first_dof(i);
                        let n = body.joints()[i].dofs.len();
                        values.extend_from_slice(&frame[first..first + n]);
                    }
                    Source::Finger(right, k) => {
                        let shape = if right { &h.right } else { &h.left };
                        // The curl axis is world z at rest; the left hand curls the other way.
                        let sign = if right { 1.0 } else { -1.0 };
                        values.push(sign * shape.joints[k]);
                    }
                    Source::Tip => {}
                }
            }
            previous = Some(frame);
        }
        Ok(Clip::new(self.skeleton.clone(), frame_time, values)?)
    }
}

/// Appends one hand's fingers under joint `hand` (new index).
fn add_fingers(
    joints: &mut Vec<Joint>,
    sources: &mut Vec<Source>,
    hand: usize,
    side: &str,
    right: bool,
    length: f64,
) {
    // At rest the hand hangs (fingers along −Y), palm facing the body's midline; the
    // knuckle row runs front (+Z, index) to back (−Z, little).
    let inward = if right { 1.0 } else { -1.0 };
    let palm = 0.45 * length;
    let phalanges = [0.45, 0.3, 0.25].map(|f| f * (length - palm));
    let spread = [0.03, 0.012, -0.006, -0.024];
    for (f, name) in FINGERS.iter().enumerate() {
        let (base, lengths) = if f == 0 {
            (
                Vector3::new(inward * 0.015, -0.2 * length, 0.03),
                [0.25 * length, 0.2 * length, 0.15 * length],
            )
        } else {
            (
                Vector3::new(0.0, -palm, spread[f - 1] * length / 0.19),
                phalanges,
            )
        };
        let mut parent = hand;
        for k in 0..3 {
            let offset = if k == 0 {
                base
            } else {
                Vector3::new(0.0, -lengths[k - 1], 0.0)
            };
            joints.push(Joint {
                name: format!("{side}{name}{}", k + 1),
                parent: Some(parent),
                offset,
                dofs: vec![Dof::Rotation(if f == 0 { Axis::Y } else { Axis::Z })],
                end_site: false,
                position_reading: PositionReading::default(),
            });
            sources.push(Source::Finger(right, 3 * f + k));
            parent = joints.len() - 1;
        }
        joints.push(Joint {
            name: format!("{side}{name}3_End"),
            parent: Some(parent),
            offset: Vector3::new(0.0, -lengths[2], 0.0),
            dofs: Vec::new(),
            end_site: true,
            position_reading: PositionReading::default(),
        });
        sources.push(Source::Tip);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curls_and_lerp() {
        let a = HandShape::open();
        let b = HandShape::from_curls([1.0; 5]);
        assert_eq!(a.lerp(&b, 0.0), a);
        assert_eq!(a.lerp(&b, 1.0), b);
        assert!((b.joints[4] - 100f64.to_radians()).abs() < 1e-15);
        assert!((a.lerp(&b, 0.5).joints[4] - 50f64.to_radians()).abs() < 1e-15);
        assert!(HandShape::preset("nope").is_none());
    }

    #[test]
    fn fingered_clip_keeps_the_body_and_moves_the_fingers() {
        let body = Character::from_height(1.75).unwrap();
        let fingered = FingeredSkeleton::new(&body).unwrap();
        let s = fingered.skeleton();
        assert_eq!(s.joints().len(), body.skeleton().joints().len() + 2 * 5 * 4);
        assert_eq!(s.dof_count(), body.skeleton().dof_count() + 30);
        let pose = body.rest_pose();
        let open = Hands {
            right: HandShape::open(),
            left: HandShape::open(),
        };
        let fist = Hands {
            right: HandShape::from_curls([1.0; 5]),
            left: HandShape::open(),
        };
        let clip = fingered
            .clip(&body, &[pose, pose], &[open, fist], 1.0 / 30.0)
            .unwrap();
        let plain = body.to_clip(&[pose], 1.0 / 30.0).unwrap();
        let tip = |c: &Clip, f: usize, name: &str| {
            let i = c
                .skeleton()
                .joints()
                .iter()
                .position(|j| j.name == name)
                .unwrap();
            c.skeleton().world_positions(c.frame(f).unwrap()).unwrap()[i]
        };
        // The body joints are where the plain export has them.
        for name in ["RightHand", "LeftHand_End", "Head"] {
            assert!((tip(&clip, 0, name) - tip(&plain, 0, name)).norm() < 1e-12);
        }
        // An open hand's fingertips lie below the wrist; a fist pulls them up and inward.
        let wrist = tip(&clip, 0, "RightHand");
        let open_tip = tip(&clip, 0, "RightMiddle3_End");
        let fist_tip = tip(&clip, 1, "RightMiddle3_End");
        assert!(open_tip.y < wrist.y - 0.15);
        assert!(fist_tip.y > open_tip.y + 0.05);
        assert!(
            fist_tip.x > open_tip.x + 0.005,
            "curls toward the palm (+x for the right hand): {open_tip} {fist_tip} {wrist}"
        );
        assert_eq!(
            tip(&clip, 1, "LeftMiddle3_End"),
            tip(&clip, 0, "LeftMiddle3_End")
        );
    }
}
