//! A synthesis arm made from a captured one: the 7-DoF chain with the person's bone lengths,
//! its base riding on the capture's shoulder, the start posture that puts shoulder, elbow,
//! wrist and hand exactly where the capture has them, and the way back into the capture's
//! skeleton for BVH output.
//!
//! **The base frame.** Its origin is the captured shoulder joint; its rotation is the
//! shoulder's parent (clavicle) world rotation times a constant alignment A fixed in the
//! parent's frame: A's z axis points laterally outward (the first frame's horizontal direction
//! from the other arm's shoulder to this one, on any rig; a one-armed skeleton's rest pose
//! root → shoulder direction), its x axis is up × z (forward for the right arm, backward for
//! the left), y = z × x (up, on the first frame). So a zero swing is the arm
//! raised sideways, a positive `shoulder_swing_x` lowers the arm on either side, and the
//! swing's singularity (|swing| = π) points across the body, where nobody reaches.
//!
//! **The start posture** is solved in closed form from the captured positions: the
//! shoulder swing points the upper arm at the elbow; shoulder twist and elbow flexion put
//! the forearm on the wrist; the elbow twist is chosen so the wrist swing is about its x
//! axis alone (the wider axis of its limit ellipse), and the wrist swing points the hand
//! at the hand point. When the captured start lies outside the default limits, the limits
//! it violates are widened to include it (and reported), so the first frame is the capture.
//! The same closed form on every frame gives the captured motion in the chain's DoFs
//! ([`CaptureArm::captured_configurations`]); the person's limits are widened to include
//! all of it: what the capture shows the person doing is within their limits.
//!
//! **Output.** A chain frame and the captured joint frame differ by a constant rotation
//! (measured on the first frame), so each synthesized frame gives the captured shoulder,
//! elbow and wrist world rotations, converted to each joint's own Euler channels (a leaf
//! wrist, an End Site, has none: its position follows the elbow's). Joints between them keep
//! their first-frame values, so bone lengths stay those of the chain.

use std::sync::Arc;

use kinergy_motion::nalgebra::{IsometryMatrix3, Matrix3, Point3, Rotation3, Vector3};
use kinergy_motion::rotation::{Axis, axis_rotation, euler_angles, swing_to, unwrap_near};
use kinergy_motion::{ArmJoints, Chain, Clip, Dof, Motion, Side, Trajectory};

use crate::controller::{Base, Synthesis};
use crate::error::{Result, SolverError};

/// How the chain's base moves during a synthesis.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BaseMode {
    /// The capture's own shoulder motion, replayed frame by frame (the default: only the
    /// arm is synthesized, the torso moves as captured).
    #[default]
    Replay,
    /// The shoulder stays where it is on the first frame (the paper's seated subject).
    Fixed,
}

/// A synthesis arm made from a captured arm (see the module documentation).
#[derive(Debug, Clone)]
pub struct CaptureArm {
    joints: ArmJoints,
    chain: Chain,
    bases: Vec<IsometryMatrix3<f64>>,
    start: Vec<f64>,
    captured: Vec<f64>,
    widened: Vec<String>,
    /// Chain frame → captured world rotation, for shoulder, elbow, wrist.
    align: [Rotation3<f64>; 3],
}

impl CaptureArm {
    /// The synthesis arm of `joints` in `clip`, from the clip's first frame.
    pub fn new(clip: &Clip, joints: &ArmJoints) -> Result<CaptureArm> {
        let skeleton = clip.skeleton();
        if clip.frame_count() == 0 {
            return Err(kinergy_motion::MotionError::EmptyClip.into());
        }
        let name = |j: usize| skeleton.joint(j).name.clone();
        let parent = skeleton.joint(joints.shoulder).parent;
        let align_base = alignment(clip, joints)?;

        // Per-frame bases.
        let mut world = Vec::new();
        let mut bases = Vec::with_capacity(clip.frame_count());
        let mut first_world = Vec::new();
        // Arm points of every frame: shoulder, elbow, wrist, hand.
        let mut points = Vec::with_capacity(clip.frame_count());
        for (k, pose) in clip.frames().enumerate() {
            skeleton.fk_into(pose, &mut world)?;
            let parent_rot = parent.map_or(Rotation3::identity(), |p| world[p].rotation);
            bases.push(IsometryMatrix3::from_parts(
                world[joints.shoulder].translation,
                parent_rot * align_base,
            ));
            let at = |j: usize| Point3::from(world[j].translation.vector);
            points.push((
                at(joints.shoulder),
                at(joints.elbow),
                at(joints.wrist),
                joints.hand.map(at),
            ));
            if k == 0 {
                first_world.clone_from(&world);
            }
        }
        let p = |j: usize| Point3::from(first_world[j].translation.vector);
        let (s, e, w) = (p(joints.shoulder), p(joints.elbow), p(joints.wrist));
        let h = joints.hand.map(p);
        let upper = (e - s).norm();
        let fore = (w - e).norm();
        let hand = h.map_or(0.0, |h| (h - w).norm());
        if upper < 1e-6 || fore < 1e-6 {
            return Err(SolverError::Capture(format!(
                "the arm `{}` → `{}` → `{}` has a zero-length bone on the first frame",
                name(joints.shoulder),
                name(joints.elbow),
                name(joints.wrist)
            )));
        }
        let chain = Chain::arm(upper, fore, hand)?;
        // The captured motion in the chain's DoFs, frame by frame (angles unwrapped to stay
        // continuous); the person's limits include all of it.
        let mut captured = Vec::with_capacity(points.len() * 7);
        let mut previous: Option<Vec<f64>> = None;
        for (base, &(s, e, w, h)) in bases.iter().zip(&points) {
            let mut q = start_posture(base, s, e, w, h);
            if let Some(prev) = &previous {
                for i in [2, 4] {
                    q[i] = unwrap_near(q[i], prev[i]);
                }
            }
            captured.extend_from_slice(&q);
            previous = Some(q);
        }
        let start = captured[..7].to_vec();
        let (chain, widened) = widen_to_include(&chain, &captured)?;

        let frames = chain.fk(&bases[0], &start)?.frames;
        let align = [joints.shoulder, joints.elbow, joints.wrist]
            .map(|j| first_world[j].rotation)
            .iter()
            .zip(&frames)
            .map(|(captured, f)| f.rotation.inverse() * captured)
            .collect::<Vec<_>>();
        Ok(CaptureArm {
            joints: joints.clone(),
            chain,
            bases,
            start,
            captured,
            widened,
            align: [align[0], align[1], align[2]],
        })
    }

    /// The captured arm's joints.
    pub fn joints(&self) -> &ArmJoints {
        &self.joints
    }

    /// The 7-DoF synthesis chain with the person's bone lengths.
    pub fn chain(&self) -> &Chain {
        &self.chain
    }

    /// The start configuration (the capture's first frame).
    pub fn start(&self) -> &[f64] {
        &self.start
    }

    /// The captured arm motion in the chain's DoFs: frame `k` is `[7k..7k + 7]`, with the
    /// shoulder, elbow, wrist and hand where the capture has them whenever the capture's
    /// bone lengths equal the first frame's.
    pub fn captured_configurations(&self) -> &[f64] {
        &self.captured
    }

    /// The same arm with the shoulder open as the full body's synergy arm has it
    /// ([`open_shoulder`]): for a motion that arm made, which its own chain did not stop at
    /// the captured extremes (a chain limited there brakes before them: the smooth
    /// controller's limit brake), so that a fit of it runs the controller that made it.
    pub fn with_open_shoulder(mut self) -> Result<CaptureArm> {
        self.chain = widen_to_include(&open_shoulder(&self.chain)?, &self.captured)?.0;
        Ok(self)
    }

    /// DoF names whose default limits were widened to include the captured motion.
    pub fn widened_limits(&self) -> &[String] {
        &self.widened
    }

    /// The base frames for a synthesis.
    pub fn base(&self, mode: BaseMode) -> Base {
        match mode {
            BaseMode::Replay => Base::Replay(self.bases.clone()),
            BaseMode::Fixed => Base::Fixed(self.bases[0]),
        }
    }

    /// The tracked points of a synthesis in the order of [`ArmJoints::metric_joints`]
    /// (shoulder, elbow, wrist, and the hand point when the capture has one).
    pub fn synthesized_trajectory(&self, synthesis: &Synthesis) -> Result<Trajectory> {
        synthesis.trajectory(self.joints.hand.is_some())
    }

    /// The captured arm's tracked points, for the motion distance.
    pub fn captured_trajectory(&self, clip: &Clip) -> Result<Trajectory> {
        Ok(clip.trajectory(&self.joints.metric_joints())?)
    }

    /// The captured skeleton moving as the synthesis says: the arm from the synthesis, the
    /// rest of the body as captured (replayed base: frame by frame, held after the capture
    /// ends; fixed base: the first frame throughout).
    pub fn to_clip(&self, clip: &Clip, synthesis: &Synthesis, mode: BaseMode) -> Result<Clip> {
        let skeleton = clip.skeleton();
        let frames = synthesis.frame_count();
        if frames == 0 || clip.frame_count() == 0 {
            return Err(kinergy_motion::MotionError::EmptyClip.into());
        }
        let base = self.base(mode);
        let keys = [self.joints.shoulder, self.joints.elbow, self.joints.wrist];
        // A leaf wrist (an End Site: keypoints without hands) has no rotation to write.
        let mut key_axes = Vec::with_capacity(3);
        for &j in &keys {
            key_axes.push(if skeleton.joint(j).end_site {
                None
            } else {
                Some(rotation_channels(clip, j)?)
            });
        }
        // Joints on the path below the shoulder that are not keys keep their first-frame
        // values, as do the keys' translation channels.
        let end = self.joints.hand.unwrap_or(self.joints.wrist);
        let path = skeleton.path(self.joints.shoulder, end).ok_or_else(|| {
            SolverError::Capture("the hand point is not below the shoulder".into())
        })?;
        let first = clip
            .frame(0)
            .ok_or(kinergy_motion::MotionError::EmptyClip)?;
        let mut values = Vec::with_capacity(frames * skeleton.dof_count());
        let mut world = Vec::new();
        let mut previous: Option<Vec<f64>> = None;
        for k in 0..frames {
            let source = match mode {
                BaseMode::Replay => k.min(clip.frame_count() - 1),
                BaseMode::Fixed => 0,
            };
            let mut pose = clip.frame(source).unwrap_or(first).to_vec();
            for &j in &path {
                for d in skeleton.dof_range(j) {
                    let is_key_rotation = keys.contains(&j)
                        && matches!(
                            skeleton.joint(j).dofs[d - skeleton.first_dof(j)],
                            Dof::Rotation(_)
                        );
                    if !is_key_rotation {
                        pose[d] = first[d];
                    }
                }
            }
            let chain_frames = self
                .chain
                .fk(base.at(k), synthesis.configuration(k))?
                .frames;
            for (i, &j) in keys.iter().enumerate() {
                let Some((axes, idx)) = &key_axes[i] else {
                    continue;
                };
                skeleton.fk_into(&pose, &mut world)?;
                let parent_rot = skeleton
                    .joint(j)
                    .parent
                    .map_or(Rotation3::identity(), |p| world[p].rotation);
                let target = chain_frames[i].rotation * self.align[i];
                let local = parent_rot.inverse() * target;
                let angles = euler_angles(*axes, &local).ok_or_else(|| {
                    SolverError::Capture("rotation channels with repeated axes".into())
                })?;
                for (&d, angle) in idx.iter().zip(angles) {
                    pose[d] = match &previous {
                        Some(prev) => unwrap_near(angle, prev[d]),
                        None => angle,
                    };
                }
            }
            values.extend_from_slice(&pose);
            previous = Some(pose);
        }
        Ok(Clip::new(
            Arc::clone(skeleton),
            synthesis.frame_time,
            values,
        )?)
    }
}

/// The arms of `clip` (right, then left, those the finders find) whose motion leaves the
/// human limits of [`Chain::arm`], read as a capture is read ([`CaptureArm::new`]: the base on
/// the first frame): each with the DoFs it takes past them ([`CaptureArm::widened_limits`]).
/// An arm within its limits is left out. What `from-positions` reports of the rotations it
/// made: an elbow folded past 150°, a shoulder twisted past ±90° (an elbow bent backward reads
/// as a shoulder twist within range). Errors: an arm with a bone of zero length.
pub fn arms_beyond_limits(clip: &Clip) -> Result<Vec<(Side, Vec<String>)>> {
    let mut out = Vec::new();
    for side in [Side::Right, Side::Left] {
        let Ok(joints) = ArmJoints::find(clip.skeleton(), side) else {
            continue;
        };
        let arm = CaptureArm::new(clip, &joints)?;
        if !arm.widened_limits().is_empty() {
            out.push((side, arm.widened_limits().to_vec()));
        }
    }
    Ok(out)
}

/// The alignment A in the shoulder's parent's frame (module docs): z out of the shoulder
/// sideways, y up, x = y × z, as the body stands on the clip's first frame. Where the skeleton
/// has the other arm, z is the horizontal line from the other arm's shoulder to this one on
/// that frame and y the vertical, both read in the parent's frame there; a skeleton of one arm
/// has no such line, and its rest pose's horizontal root → shoulder direction (the elbow's, for
/// a shoulder above the root) is z.
///
/// One rule for every rig with two arms, whatever its zero pose: Bandai Namco's lies along +X
/// with the clavicles along the spine, Character Creator's holds its clavicles along the spine
/// too (a rule reading a standing zero pose turned that rig's base ~90° about the forward axis),
/// CMU's and Mixamo's stand. A motion and its retargeting onto another skeleton
/// ([`kinergy_motion::Retargeter`]), whose roles turn alike, then get the same base on every
/// frame up to the two rigs' shoulder lines, so a person's parameters mean the same joint
/// motion on either body. (Bases fixed in the bodies' canonical posture instead — the
/// clavicle's or the chest's — were exact across rigs but fitted the shared people's held-out
/// takes worse: 7–17 mm more on *elderly* and *normal*.)
fn alignment(clip: &Clip, joints: &ArmJoints) -> Result<Rotation3<f64>> {
    let skeleton = clip.skeleton();
    let parent = skeleton.joint(joints.shoulder).parent;
    let horizontal = |mut v: Vector3<f64>| {
        v.y = 0.0;
        v
    };
    let (parent_rot, lateral) = match other_shoulder(clip, joints) {
        Some(other) => {
            let first = clip
                .frame(0)
                .ok_or(kinergy_motion::MotionError::EmptyClip)?;
            let world = skeleton.fk(first)?;
            let parent_rot = parent.map_or(Rotation3::identity(), |p| world[p].rotation);
            let lateral = horizontal(
                world[joints.shoulder].translation.vector - world[other].translation.vector,
            );
            (parent_rot, lateral)
        }
        None => {
            let rest = skeleton.fk(&skeleton.rest_pose())?;
            let parent_rest = parent.map_or(Rotation3::identity(), |p| rest[p].rotation);
            let shoulder_rest = rest[joints.shoulder].translation.vector;
            let mut lateral = horizontal(shoulder_rest - rest[0].translation.vector);
            if lateral.norm() < 1e-3 {
                lateral = horizontal(rest[joints.elbow].translation.vector - shoulder_rest);
            }
            (parent_rest, lateral)
        }
    };
    if lateral.norm() < 1e-6 {
        return Err(SolverError::Capture(format!(
            "cannot tell which way `{}` points sideways in the rest pose or the first frame",
            skeleton.joint(joints.shoulder).name
        )));
    }
    let up = parent_rot.inverse() * Vector3::y();
    let z = parent_rot.inverse() * lateral.normalize();
    let z = (z - up * z.dot(&up)).normalize();
    let x = up.cross(&z).normalize();
    let y = z.cross(&x);
    Ok(Rotation3::from_matrix_unchecked(Matrix3::from_columns(&[
        x, y, z,
    ])))
}

/// The other arm's shoulder joint, when the skeleton has another arm found by name on the
/// other side (`joints.side`, or whichever side gives a different shoulder).
fn other_shoulder(clip: &Clip, joints: &ArmJoints) -> Option<usize> {
    let skeleton = clip.skeleton();
    let sides = match joints.side {
        Some(side) => vec![side.opposite()],
        None => vec![Side::Left, Side::Right],
    };
    sides
        .into_iter()
        .filter_map(|side| ArmJoints::find(skeleton, side).ok())
        .map(|other| other.shoulder)
        .find(|&other| {
            other != joints.shoulder
                && !skeleton.is_ancestor_or_self(other, joints.shoulder)
                && !skeleton.is_ancestor_or_self(joints.shoulder, other)
        })
}

/// The rotation axes of joint `j` (exactly three, distinct) and their pose indices.
fn rotation_channels(clip: &Clip, j: usize) -> Result<([Axis; 3], [usize; 3])> {
    let skeleton = clip.skeleton();
    let joint = skeleton.joint(j);
    let rot: Vec<(Axis, usize)> = joint
        .dofs
        .iter()
        .enumerate()
        .filter_map(|(k, d)| match d {
            Dof::Rotation(a) => Some((*a, skeleton.first_dof(j) + k)),
            Dof::Translation(_) => None,
        })
        .collect();
    let distinct =
        rot.len() == 3 && rot[0].0 != rot[1].0 && rot[1].0 != rot[2].0 && rot[0].0 != rot[2].0;
    if !distinct {
        return Err(SolverError::Capture(format!(
            "joint `{}` has {} rotation channels; writing an arbitrary rotation needs three about distinct axes",
            joint.name,
            rot.len()
        )));
    }
    Ok((
        [rot[0].0, rot[1].0, rot[2].0],
        [rot[0].1, rot[1].1, rot[2].1],
    ))
}

/// The 7-DoF configuration whose shoulder, elbow, wrist and hand are at `s, e, w, h`, with
/// the base frame `base` at `s` (see the module documentation).
fn start_posture(
    base: &IsometryMatrix3<f64>,
    s: Point3<f64>,
    e: Point3<f64>,
    w: Point3<f64>,
    h: Option<Point3<f64>>,
) -> Vec<f64> {
    let to_base = base.rotation.inverse();
    let (sx, sy) = swing_to(&(to_base * (e - s)));
    let swing = kinergy_motion::rotation::swing_rotation(sx, sy);
    let f = (swing.inverse() * to_base * (w - e)).normalize();
    let flex = f.z.clamp(-1.0, 1.0).acos();
    let twist = if flex.sin() > 1e-9 {
        f.x.atan2(-f.y)
    } else {
        0.0
    };
    let forearm =
        base.rotation * swing * axis_rotation(Axis::Z, twist) * axis_rotation(Axis::X, flex);
    let (mut pronation, mut wx, mut wy) = (0.0, 0.0, 0.0);
    if let Some(h) = h {
        let d = forearm.inverse() * (h - w);
        if d.norm() > 1e-12 {
            let d = d.normalize();
            if d.x.hypot(d.y) > 1e-9 {
                // Rz(−ψ) d has no x component: ψ = atan2(−d.x, d.y) (or that + π).
                let a = (-d.x).atan2(d.y);
                let b = unwrap_near(a + std::f64::consts::PI, 0.0);
                pronation = if a.abs() <= b.abs() { a } else { b };
            }
            let local = axis_rotation(Axis::Z, pronation).inverse() * d;
            (wx, wy) = swing_to(&local);
        }
    }
    vec![sx, sy, twist, flex, pronation, wx, wy]
}

/// The largest shoulder swing of an [open shoulder](open_shoulder), radians: this capture
/// convention measures the swing from the arm raised sideways, so a swing of π (the upper arm
/// across the chest) is singular; 160° keeps 20° from it, beyond anything a body's limits let
/// a reach use.
pub const OPEN_SHOULDER_SWING: f64 = 160.0 * std::f64::consts::PI / 180.0;

/// `chain` (an arm: shoulder swing and twist first) with the shoulder's swing bounded only by
/// [`OPEN_SHOULDER_SWING`] and its twist open to ±π: the chain of a synergy arm whose
/// anatomical shoulder limits are applied by someone else (the full body's character clamps
/// its arm every frame, `kinergy_reach`'s synergy arm).
pub fn open_shoulder(chain: &Chain) -> Result<Chain> {
    let mut joints = chain.joints().to_vec();
    if let Some(shoulder) = joints.first_mut() {
        for m in &mut shoulder.motions {
            match m {
                Motion::Swing { rx, ry } => (*rx, *ry) = (OPEN_SHOULDER_SWING, OPEN_SHOULDER_SWING),
                Motion::Revolute { min, max, .. } => {
                    (*min, *max) = (-std::f64::consts::PI, std::f64::consts::PI);
                }
            }
        }
    }
    Ok(Chain::new(joints, chain.end_effector())?)
}

/// `chain` with every limit widened to include the configurations `qs` (one after the
/// other, `dof_count` values each); the widened DoF names. (A captured arm's start, or a
/// full-body character's hanging arm seen in the capture convention, can lie outside the
/// default limits: a controller clamping it would jump the arm on its first frame.)
pub fn widen_to_include(chain: &Chain, qs: &[f64]) -> Result<(Chain, Vec<String>)> {
    let n = chain.dof_count();
    let mut widened: Vec<usize> = Vec::new();
    let mut chain = chain.clone();
    for q in qs.chunks(n) {
        if !chain.within_limits(q) {
            let (wider, more) = widen_one(&chain, q)?;
            chain = wider;
            widened.extend(more);
        }
    }
    widened.sort_unstable();
    widened.dedup();
    let names: Vec<String> = chain.dof_names().map(String::from).collect();
    Ok((
        chain,
        widened.into_iter().map(|i| names[i].clone()).collect(),
    ))
}

/// `chain` with any limit that `q` violates widened to include it; the widened DoFs.
fn widen_one(chain: &Chain, q: &[f64]) -> Result<(Chain, Vec<usize>)> {
    let margin = 1e-9;
    let mut widened = Vec::new();
    let mut joints = chain.joints().to_vec();
    let mut k = 0;
    for joint in &mut joints {
        for m in &mut joint.motions {
            match m {
                Motion::Revolute { min, max, .. } => {
                    if q[k] < *min || q[k] > *max {
                        *min = min.min(q[k] - margin);
                        *max = max.max(q[k] + margin);
                        widened.push(k);
                    }
                    k += 1;
                }
                Motion::Swing { rx, ry } => {
                    let e = (q[k] / *rx).powi(2) + (q[k + 1] / *ry).powi(2);
                    if e > 1.0 {
                        let grow = e.sqrt() * (1.0 + 1e-9);
                        *rx *= grow;
                        *ry *= grow;
                        widened.extend([k, k + 1]);
                    }
                    k += 2;
                }
            }
        }
    }
    Ok((Chain::new(joints, chain.end_effector())?, widened))
}
