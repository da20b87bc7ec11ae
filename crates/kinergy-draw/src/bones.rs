//! Which of a skeleton's bones a stick figure draws, decided from the skeleton and its motion.
//!
//! Pure (no drawing, no printing), so the picture tests can count what is drawn.
//!
//! - **Body bones** are drawn with the figure's line width, their joints as dots.
//! - **Finger bones** — a joint whose name (or an ancestor's) says finger, thumb, index,
//!   middle, ring or pinky, case-insensitively, and the bone from its parent to it — are
//!   drawn as thin lines without dots, so a hand reads as a hand and not as a blob.
//! - Not drawn: **face** joints (names saying face, eye or jaw, and their descendants);
//!   bones from a **reference root** — joint 0 with a single child that has its own
//!   position channels, the root itself staying within [`STILL_ROOT_M`] of where it starts
//!   (Bandai Namco's `joint_Root` on the floor's origin while the body is elsewhere); and
//!   bones **shorter than [`MIN_BONE_M`]** on the frame drawn (zero-offset End Sites).

use kinergy_motion::{Clip, Dof, MotionError, Skeleton};
use nalgebra::Point3;

/// Bones shorter than this (meters) on a frame are not drawn on that frame.
pub const MIN_BONE_M: f64 = 1e-3;
/// A root that stays within this distance (meters) of its first position is still.
pub const STILL_ROOT_M: f64 = 0.01;

/// Name parts that make a joint a face joint (not drawn).
const FACE: [&str; 3] = ["face", "eye", "jaw"];
/// Name parts that make a joint a finger joint (drawn thin).
const FINGER: [&str; 6] = ["finger", "thumb", "index", "middle", "ring", "pinky"];

/// What a joint is to the stick figure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Role {
    /// A body joint: drawn as a dot, its bone from the parent drawn full width.
    Body,
    /// A finger joint: its bone drawn thin, no dot.
    Finger,
    /// A face joint: not drawn.
    Face,
    /// A reference root that does not move with the body: not drawn, nor its bones.
    Reference,
}

/// How a drawn bone looks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum BoneKind {
    /// The body's line width.
    Body,
    /// A thin line.
    Finger,
}

/// One bone to draw on one frame: world positions of its ends.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Segment {
    /// The parent joint's index.
    pub parent: usize,
    /// The child joint's index.
    pub child: usize,
    /// The parent's world position, meters.
    pub from: Point3<f64>,
    /// The child's world position, meters.
    pub to: Point3<f64>,
    /// How it is drawn.
    pub kind: BoneKind,
}

/// The drawable part of a skeleton: each joint's [`Role`] and the bones between them.
#[derive(Debug, Clone, PartialEq)]
pub struct StickFigure {
    roles: Vec<Role>,
    /// (parent, child, kind) of every bone that may be drawn.
    bones: Vec<(usize, usize, BoneKind)>,
    /// Joints drawn as dots.
    dots: Vec<usize>,
}

fn name_says(name: &str, parts: &[&str]) -> bool {
    let name = name.to_ascii_lowercase();
    parts.iter().any(|p| name.contains(p))
}

impl StickFigure {
    /// Decides the figure of `skeleton` moving through `world` (its joints' world positions,
    /// frame after frame, [`Skeleton::joint_count`] per frame).
    pub fn new(skeleton: &Skeleton, world: &[Point3<f64>]) -> StickFigure {
        let joints = skeleton.joints();
        let n = joints.len();
        let mut roles = Vec::with_capacity(n);
        for (j, joint) in joints.iter().enumerate() {
            let inherited = joint.parent.map(|p: usize| roles[p]);
            let role = match inherited {
                Some(Role::Face) => Role::Face,
                _ if name_says(&joint.name, &FACE) => Role::Face,
                Some(Role::Finger) => Role::Finger,
                _ if name_says(&joint.name, &FINGER) => Role::Finger,
                _ if j == 0 && is_reference_root(skeleton, world) => Role::Reference,
                _ => Role::Body,
            };
            roles.push(role);
        }
        let bones = joints
            .iter()
            .enumerate()
            .filter_map(|(j, joint)| {
                let p = joint.parent?;
                match (roles[p], roles[j]) {
                    (Role::Reference, _) | (_, Role::Reference) => None,
                    (Role::Face, _) | (_, Role::Face) => None,
                    (_, Role::Finger) => Some((p, j, BoneKind::Finger)),
                    _ => Some((p, j, BoneKind::Body)),
                }
            })
            .collect();
        let dots = joints
            .iter()
            .enumerate()
            .filter(|(j, joint)| !joint.end_site && roles[*j] == Role::Body)
            .map(|(j, _)| j)
            .collect();
        StickFigure { roles, bones, dots }
    }

    /// [`StickFigure::of`] for a clip read from `path`: a clip with no frames or joints, and
    /// one whose joints cannot be placed, are refused naming the file.
    pub fn of_file(
        clip: &Clip,
        path: &std::path::Path,
    ) -> Result<(StickFigure, Vec<Point3<f64>>), crate::DrawError> {
        if clip.frame_count() == 0 || clip.skeleton().joint_count() == 0 {
            return Err(crate::DrawError::NoFrames {
                path: path.to_path_buf(),
            });
        }
        StickFigure::of(clip).map_err(|source| crate::DrawError::Figure {
            path: path.to_path_buf(),
            source,
        })
    }

    /// Decides the figure of `clip` (runs forward kinematics on every frame); returns it with
    /// the world positions, frame after frame.
    pub fn of(clip: &Clip) -> Result<(StickFigure, Vec<Point3<f64>>), MotionError> {
        let world = clip.world_positions()?;
        Ok((StickFigure::new(clip.skeleton(), &world), world))
    }

    /// Each joint's role.
    pub fn roles(&self) -> &[Role] {
        &self.roles
    }

    /// The joints drawn as dots (body joints, not End Sites).
    pub fn dots(&self) -> &[usize] {
        &self.dots
    }

    /// The bones to draw on a frame whose joints are at `world` (one per joint, meters):
    /// (parent, child, kind) of every bone of the figure at least [`MIN_BONE_M`] long there.
    pub fn bones<'a>(
        &'a self,
        world: &'a [Point3<f64>],
    ) -> impl Iterator<Item = (usize, usize, BoneKind)> + 'a {
        self.bones
            .iter()
            .copied()
            .filter(move |&(p, j, _)| match (world.get(p), world.get(j)) {
                (Some(a), Some(b)) => nalgebra::distance(a, b) >= MIN_BONE_M,
                _ => false,
            })
    }

    /// The world segments to draw on a frame whose joints are at `world`.
    pub fn world_segments(&self, world: &[Point3<f64>]) -> Vec<Segment> {
        self.bones(world)
            .map(|(parent, child, kind)| Segment {
                parent,
                child,
                from: world[parent],
                to: world[child],
                kind,
            })
            .collect()
    }
}

/// Joint 0 is a reference root when it has a single child, that child places itself with
/// its own position channels, and the root stays still while the body moves or not.
fn is_reference_root(skeleton: &Skeleton, world: &[Point3<f64>]) -> bool {
    let mut children = skeleton.children(0);
    let (Some(child), None) = (children.next(), children.next()) else {
        return false;
    };
    let places_itself = skeleton
        .joint(child)
        .dofs
        .iter()
        .any(|d| matches!(d, Dof::Translation(_)));
    let n = skeleton.joint_count();
    let still = match world.first() {
        Some(start) => world
            .iter()
            .step_by(n.max(1))
            .all(|p| nalgebra::distance(p, start) <= STILL_ROOT_M),
        None => true,
    };
    places_itself && still
}
