//! A motion moved onto another skeleton: joints matched by role ([`BodyJoints`]), each
//! role's world orientation carried over, the root's path scaled by leg length, and the hands
//! and feet put back on their paths by two-bone IK ([`Retargeter`]).
//!
//! **Rotations.** Each skeleton is first brought, in its zero pose, into one *canonical*
//! posture: facing +Z, Y up, spine, neck and head up, arms out along ±X, legs down, feet
//! forward. The pelvis and the chest are turned so their left–right axes (hips, shoulders) and
//! up axes (the chest above the pelvis, the neck above the chest) match the canonical axes;
//! every other role's bone is swung, after its parent's turn, by the shortest arc onto its
//! canonical direction. Call `K_j` a joint's world rotation in that posture. On each frame a
//! source role's change from its canonical posture, `D = R_source · K_sourceᵀ`, is given to the
//! target's joint of that role: `R_target = D · K_target`. A bone of one role then points where
//! the source's points, and its twist follows the source's, whatever the two skeletons' zero
//! poses (a T-pose, an A-pose, Bandai Namco's body lying along +X) and however their joints'
//! axes are set up.
//!
//! Spines and necks of different joint counts are matched along their length (from the first
//! spine joint to the chest, from the first neck joint to the head): each target bone takes
//! the turn of the source bone under its middle, swung to point along the source chain's chord
//! over the target bone's span, so the target's chest and head sit where the source's sit. The
//! pelvis's own bone turns with the hips, the chest's with the shoulders. Target joints of no
//! role (CMU's `LHipJoint`, twist and finger bones) take the source's rotation relative to
//! their parent where the source has a joint of their name (rigs of one family), else keep
//! their zero pose's.
//!
//! **Positions.** Everything is scaled by `s`, the ratio of the two bodies' standing pelvis
//! heights (the hip joints' drop below the pelvis, thigh, shank and ankle height, in the
//! canonical posture), about the point on the source's floor (its lowest ankle over the clip,
//! less the ankle's standing height) below the pelvis's first position: the motion starts
//! where the source's starts, with strides and heights × `s`. The pelvis goes there. Each
//! ankle's goal is the source ankle's, scaled (its height above its standing height × `s`);
//! where the source foot is planted (its ankle slower than [`PLANT_SPEED`] for at least
//! [`PLANT_MIN_S`], within [`PLANT_RADIUS`]) the goal is held at its mean over the plant, the
//! offset easing back to the moving path over [`PLANT_BLEND_S`], so the target's planted foot
//! does not slide. Each wrist's goal is the target's shoulder plus the source's
//! shoulder-to-wrist vector × the ratio of arm lengths (upper arm + forearm): the hand's path
//! relative to the body, scaled to the new arm. Where a foot's goal is beyond the straight leg
//! (legs of other proportions), the pelvis comes down as far as it needs (reported). Two-bone
//! IK (hip–knee–ankle, shoulder–elbow–wrist) reaches the goals: the knee or elbow stays in the
//! plane it was in (the source's), bends between straight and [`MAX_BEND_DEG`] (never
//! backward), and the foot and hand keep their carried world orientation.

use std::sync::Arc;

use nalgebra::{Rotation3, Unit, Vector3};

use crate::clip::Clip;
use crate::error::{MotionError, Result};
use crate::limbs::BodyJoints;
use crate::rotation::{Axis, euler_angles, nearest_euler};
use crate::skeleton::{Dof, Skeleton};

/// The height of a leaf ankle (keypoints without feet) above the sole, per unit of shank
/// length: Drillis & Contini's ankle height 0.039 H over their shank, knee height 0.285 H less
/// it (Winter, *Biomechanics and Motor Control of Human Movement*, Fig. 4.1).
pub const LEAF_ANKLE_PER_SHANK: f64 = 0.039 / (0.285 - 0.039);

/// A foot whose ankle moves slower than this (meters per second, in the source) is planted.
pub const PLANT_SPEED: f64 = 0.1;
/// A planted ankle stays within this distance of where its plant began (meters, in the
/// source).
pub const PLANT_RADIUS: f64 = 0.02;
/// A plant lasts at least this long (seconds); shorter pauses are steps.
pub const PLANT_MIN_S: f64 = 0.1;
/// The time over which a foot's goal eases between its plant and its moving path (seconds).
pub const PLANT_BLEND_S: f64 = 0.1;
/// The most a knee or elbow bends (degrees from straight).
pub const MAX_BEND_DEG: f64 = 160.0;

/// How a target joint's world rotation is made on each frame.
#[derive(Debug, Clone, Copy)]
enum Rule {
    /// The source role joint's change from its canonical posture, times this joint's canonical
    /// world rotation: `R = (R_source[source] · k_source) · k_target`, where `k_source` is
    /// `K_sourceᵀ`, stored per source joint.
    Role {
        source: usize,
        canonical: Rotation3<f64>,
        chord: Option<Chord>,
    },
    /// The parent's world rotation times the source joint's local rotation: a joint of no
    /// role that the source has too, by name (fingers, twist bones and toes of rigs of one
    /// family).
    Local(usize),
    /// The parent's world rotation (the zero-pose local rotation, the identity).
    Rest,
}

/// A spine or neck bone of the target pointed along the source chain's chord between two
/// fractions of its length.
#[derive(Debug, Clone, Copy)]
struct Chord {
    /// Which source chain ([`Retargeter::chains`]).
    chain: usize,
    /// The bone's start and end, as fractions of the chain's length.
    from: f64,
    to: f64,
    /// The bone's direction in its joint's frame.
    bone: Vector3<f64>,
}

/// A source chain (spine or neck): its bones' joints, the joint it ends at, and where each
/// bone starts as a fraction of its length.
#[derive(Debug, Clone)]
struct SourceChain {
    joints: Vec<usize>,
    end: usize,
    starts: Vec<f64>,
}

impl SourceChain {
    /// The point at `fraction` of the chain's length, on a frame with world transforms `world`.
    fn point(&self, world: &[nalgebra::IsometryMatrix3<f64>], fraction: f64) -> Vector3<f64> {
        let i = self
            .starts
            .iter()
            .rposition(|&s| s <= fraction)
            .unwrap_or(0);
        let next = self.joints.get(i + 1).copied().unwrap_or(self.end);
        let end = self.starts.get(i + 1).copied().unwrap_or(1.0);
        let t = if end > self.starts[i] {
            (fraction - self.starts[i]) / (end - self.starts[i])
        } else {
            0.0
        };
        let a = world[self.joints[i]].translation.vector;
        a + (world[next].translation.vector - a) * t
    }
}

/// The two-bone limbs of a body: hip–knee–ankle or shoulder–elbow–wrist.
#[derive(Debug, Clone, Copy)]
struct Limb {
    root: usize,
    middle: usize,
    end: usize,
}

/// A plant of one foot: its frames and where the target's ankle is held.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Plant {
    /// The plant's first frame.
    pub first: usize,
    /// Its last frame.
    pub last: usize,
    /// Where the target's ankle is held, meters (world).
    pub at: [f64; 3],
}

/// What a retargeting did, and how well the target holds its goals.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RetargetReport {
    /// The roles matched: (role, source joint, target joint).
    pub roles: Vec<(String, String, String)>,
    /// Target joints of no role, which keep their zero-pose rotation relative to their parent.
    pub unmapped: Vec<String>,
    /// The ratio of the target's standing pelvis height to the source's: how the root's path
    /// is scaled.
    pub leg_scale: f64,
    /// The ratio of each arm (right, left): how the hand's path about the shoulder is scaled.
    pub arm_scale: [f64; 2],
    /// Each foot's plants (right, left).
    pub plants: [Vec<Plant>; 2],
    /// How far a planted target ankle moves from where it is held, at most, meters.
    pub foot_slide_m: f64,
    /// The farthest each ankle (right, left) is from its goal on any frame, meters (a goal
    /// beyond the leg's reach).
    pub foot_error_m: [f64; 2],
    /// The farthest each wrist (right, left) is from its goal on any frame, meters.
    pub hand_error_m: [f64; 2],
    /// Frames on which a knee or elbow was held to straight or to [`MAX_BEND_DEG`].
    pub bend_limited_frames: usize,
    /// The most the pelvis was lowered below its scaled path so a foot could reach its goal,
    /// meters.
    pub pelvis_drop_m: f64,
}

/// A retargeted clip with its report.
#[derive(Debug, Clone)]
pub struct Retargeted {
    /// The motion on the target skeleton.
    pub clip: Clip,
    /// How it was made.
    pub report: RetargetReport,
}

/// Moves motions from one skeleton onto another (see the [module docs](self)); made once per
/// pair of skeletons, then run on any number of clips of the source skeleton.
#[derive(Debug, Clone)]
pub struct Retargeter {
    source: Arc<Skeleton>,
    target: Arc<Skeleton>,
    source_body: BodyJoints,
    target_body: BodyJoints,
    /// `K_sourceᵀ` of each source role joint (identity elsewhere).
    source_inverse: Vec<Rotation3<f64>>,
    rules: Vec<Rule>,
    /// The source's spine and neck, along which the target's spine and neck bones point.
    chains: Vec<SourceChain>,
    /// The joint whose translation places the pelvis, and the joints from it down to the
    /// pelvis (excluded).
    mover: usize,
    mover_path: Vec<usize>,
    /// Each target joint's Euler DoFs (pose indices and axes), where it has three.
    euler: Vec<Option<([usize; 3], [Axis; 3])>>,
    leg_scale: f64,
    /// The ankle's height above the floor standing, source then target, meters.
    ankle_heights: [f64; 2],
    arm_scale: [f64; 2],
    target_legs: [Limb; 2],
    target_arms: [Limb; 2],
    bend_min_cos: f64,
}

fn invalid(why: String) -> MotionError {
    MotionError::Invalid {
        what: "retarget",
        why,
    }
}

/// The shortest-arc rotation taking direction `a` to direction `b` (a half turn about a
/// normal where they are opposite; the identity where either is zero). The angle is
/// `atan2(|a × b|, a · b)`: nalgebra's `rotation_between` takes the arc cosine of a dot
/// product that rounding can put above 1, a NaN for nearly parallel bones.
fn swing(a: &Vector3<f64>, b: &Vector3<f64>) -> Rotation3<f64> {
    let (Some(a), Some(b)) = (a.try_normalize(1e-12), b.try_normalize(1e-12)) else {
        return Rotation3::identity();
    };
    let cross = a.cross(&b);
    let angle = cross.norm().atan2(a.dot(&b));
    match Unit::try_new(cross, 1e-15) {
        Some(axis) => Rotation3::from_axis_angle(&axis, angle),
        None if a.dot(&b) > 0.0 => Rotation3::identity(),
        None => {
            let other = if a.x.abs() < 0.9 {
                Vector3::x()
            } else {
                Vector3::y()
            };
            let axis = Unit::new_normalize(a.cross(&other));
            Rotation3::from_axis_angle(&axis, std::f64::consts::PI)
        }
    }
}

/// The rotation taking the frame of `left` and `up` (Gram–Schmidt, `left` first) to the
/// canonical axes X (left), Y (up), Z (forward).
fn frame_to_canonical(left: Vector3<f64>, up: Vector3<f64>) -> Option<Rotation3<f64>> {
    let x = left.try_normalize(1e-9)?;
    let y = (up - x * x.dot(&up)).try_normalize(1e-9)?;
    let z = x.cross(&y);
    let f = nalgebra::Matrix3::from_columns(&[x, y, z]);
    Some(Rotation3::from_matrix_unchecked(f.transpose()))
}

/// A body's standing heights in its canonical posture (legs straight down, zero pose), meters.
#[derive(Debug, Clone, Copy)]
struct Stance {
    /// The pelvis above the floor: the hip joints' drop below it, thigh, shank and the ankle's
    /// height (mean of both legs).
    pelvis: f64,
    /// The ankle above the floor: its height above the toe tip in the zero pose, turned upright
    /// with the pelvis (mean of both legs).
    ankle: f64,
}

/// The canonical world rotation `K_j` of each role joint of `body` on `skeleton` (zero pose),
/// `None` for joints of no role, and the body's [`Stance`].
fn canonical(
    skeleton: &Skeleton,
    body: &BodyJoints,
) -> Result<(Vec<Option<Rotation3<f64>>>, Stance)> {
    let frames = skeleton.fk(&skeleton.rest_pose())?;
    let p = |j: usize| frames[j].translation.vector;
    let w = |j: usize| frames[j].rotation;
    let name = |j: usize| skeleton.joint(j).name.as_str();
    let mut align: Vec<Option<Rotation3<f64>>> = vec![None; skeleton.joint_count()];
    let chest = body.chest();
    // The pelvis: hips left–right, the chest above.
    let pelvis = frame_to_canonical(
        p(body.legs[1].hip) - p(body.legs[0].hip),
        p(chest) - p(body.pelvis),
    )
    .ok_or_else(|| {
        invalid(format!(
            "the hips and the chest of `{}` are on one line in its zero pose",
            name(body.pelvis)
        ))
    })?;
    align[body.pelvis] = Some(pelvis);
    let mut stance = Stance {
        pelvis: 0.0,
        ankle: 0.0,
    };
    for leg in &body.legs {
        let drop = -(pelvis * (p(leg.hip) - p(body.pelvis))).y;
        let ankle = match leg.toe {
            Some(toe) => (-(pelvis * (p(toe) - p(leg.ankle))).y).max(0.0),
            // A leaf ankle (keypoints without feet): its height above the sole, from the shank.
            None => LEAF_ANKLE_PER_SHANK * (p(leg.ankle) - p(leg.knee)).norm(),
        };
        let straight = (p(leg.knee) - p(leg.hip)).norm() + (p(leg.ankle) - p(leg.knee)).norm();
        stance.pelvis += 0.5 * (drop + straight + ankle);
        stance.ankle += 0.5 * ankle;
    }
    // A bone from `j` to `to` swung onto `direction` after `parent`'s alignment.
    let swung =
        |parent: Rotation3<f64>, j: usize, to: Option<usize>, direction: Vector3<f64>| match to {
            Some(c) => swing(&(parent * (p(c) - p(j))), &direction) * parent,
            None => parent,
        };
    let up = Vector3::y();
    let mut previous = pelvis;
    for (k, &j) in body.spine.iter().enumerate() {
        if j == chest {
            break;
        }
        previous = swung(previous, j, body.spine.get(k + 1).copied(), up);
        align[j] = Some(previous);
    }
    let neck_top = body.neck.first().copied().or(body.head);
    let chest_up = match neck_top {
        Some(n) if (p(n) - p(chest)).norm() > 1e-9 => p(n) - p(chest),
        _ => p(chest) - p(body.pelvis),
    };
    let shoulders = p(body.arms[1].shoulder) - p(body.arms[0].shoulder);
    let chest_frame = frame_to_canonical(shoulders, chest_up).ok_or_else(|| {
        invalid(format!(
            "the shoulders and the neck of `{}` are on one line in its zero pose",
            name(chest)
        ))
    })?;
    align[chest] = Some(chest_frame);
    let mut previous = chest_frame;
    let neck_chain: Vec<usize> = body.neck.iter().copied().chain(body.head).collect();
    for (k, &j) in neck_chain.iter().enumerate() {
        let to = neck_chain.get(k + 1).copied().or_else(|| {
            // The head's bone: to its farthest descendant (the top of the head).
            (j + 1..skeleton.joint_count())
                .filter(|&d| skeleton.is_ancestor_or_self(j, d))
                .max_by(|&a, &b| (p(a) - p(j)).norm().total_cmp(&(p(b) - p(j)).norm()))
                .filter(|&d| (p(d) - p(j)).norm() > 1e-9)
        });
        previous = swung(previous, j, to, up);
        align[j] = Some(previous);
    }
    for (s, sign) in [(0, -1.0), (1, 1.0)] {
        let out = Vector3::x() * sign;
        let arm = &body.arms[s];
        let mut previous = chest_frame;
        if let Some(c) = arm.clavicle {
            previous = swung(previous, c, Some(arm.shoulder), out);
            align[c] = Some(previous);
        }
        for (j, to) in [
            (arm.shoulder, Some(arm.elbow)),
            (arm.elbow, Some(arm.wrist)),
            (arm.wrist, arm.hand),
        ] {
            previous = swung(previous, j, to, out);
            align[j] = Some(previous);
        }
        let leg = &body.legs[s];
        let mut previous = pelvis;
        // A leaf ankle has no foot: it turns with the shank.
        for (j, to, direction) in [
            (leg.hip, Some(leg.knee), -up),
            (leg.knee, Some(leg.ankle), -up),
            (leg.ankle, leg.toe, Vector3::z()),
        ] {
            previous = swung(previous, j, to, direction);
            align[j] = Some(previous);
        }
    }
    let k = align
        .into_iter()
        .enumerate()
        .map(|(j, a)| a.map(|a| a * w(j)))
        .collect();
    Ok((k, stance))
}

/// Where along the chain `joints` (each a bone from it to the next, the last ending at `end`)
/// each bone starts, as fractions of the chain's length in the zero pose.
fn chain_fractions(skeleton: &Skeleton, joints: &[usize], end: usize) -> Result<Vec<f64>> {
    let p = skeleton.world_positions(&skeleton.rest_pose())?;
    let mut lengths: Vec<f64> = joints
        .iter()
        .enumerate()
        .map(|(k, &j)| (p[*joints.get(k + 1).unwrap_or(&end)] - p[j]).norm())
        .collect();
    let total: f64 = lengths.iter().sum();
    if total <= 1e-12 {
        lengths.iter_mut().for_each(|l| *l = 1.0);
    }
    let total: f64 = lengths.iter().sum();
    let mut at = 0.0;
    Ok(lengths
        .iter()
        .map(|l| {
            let start = at / total;
            at += l;
            start
        })
        .collect())
}

/// A target bone's source bone (its joint) and its span along the chain (start, end fractions).
type BoneSpan = (usize, f64, f64);

/// A target chain matched to a source chain: for each target bone, the source bone its middle
/// falls on and the bone's span (start, end) as fractions of the chain's length.
fn match_chains(
    source: (&Skeleton, &[usize], usize),
    target: (&Skeleton, &[usize], usize),
) -> Result<(SourceChain, Vec<BoneSpan>)> {
    let s = chain_fractions(source.0, source.1, source.2)?;
    let t = chain_fractions(target.0, target.1, target.2)?;
    let bones = (0..t.len())
        .map(|k| {
            let end = t.get(k + 1).copied().unwrap_or(1.0);
            let middle = 0.5 * (t[k] + end);
            let i = s.iter().rposition(|&start| start <= middle).unwrap_or(0);
            (source.1[i], t[k], end)
        })
        .collect();
    let chain = SourceChain {
        joints: source.1.to_vec(),
        end: source.2,
        starts: s,
    };
    Ok((chain, bones))
}

/// Upper arm + forearm (or thigh + shank) in the pose `pose`.
fn limb_length(skeleton: &Skeleton, pose: &[f64], a: usize, b: usize, c: usize) -> Result<f64> {
    let p = skeleton.world_positions(pose)?;
    Ok((p[b] - p[a]).norm() + (p[c] - p[b]).norm())
}

/// Which arms a retargeted body has: the template's own, or the source performer's.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TargetArms {
    /// The template's bones as they are: the hands' paths about the shoulders are scaled by
    /// each arm's length ratio ([`RetargetReport::arm_scale`]).
    #[default]
    Template,
    /// The source's upper arms and forearms, scaled with the body (by the ratio of standing
    /// pelvis heights): the target keeps the performer's proportions
    /// ([`with_source_arms`]). A person's synergy, learned in joint angles on their own arm,
    /// then replays on the new body as it was fitted; on an arm of other proportions the same
    /// joint motion draws another hand path.
    Source,
}

impl std::str::FromStr for TargetArms {
    type Err = MotionError;

    /// `template` or `source` (the CLI's `--arms`, Python's `arms=`).
    fn from_str(s: &str) -> Result<TargetArms> {
        match s {
            "template" => Ok(TargetArms::Template),
            "source" => Ok(TargetArms::Source),
            other => Err(invalid(format!(
                "arms {other:?}: expected \"template\" (the template's arms) or \"source\" (the \
                 source performer's, scaled with the body)"
            ))),
        }
    }
}

impl TargetArms {
    /// The skeleton to retarget onto: `target` itself, or with the source's arms
    /// ([`with_source_arms`]).
    pub fn skeleton(
        self,
        source: &Clip,
        source_body: &BodyJoints,
        target: Arc<Skeleton>,
        target_body: &BodyJoints,
    ) -> Result<Arc<Skeleton>> {
        Ok(match self {
            TargetArms::Template => target,
            TargetArms::Source => {
                Arc::new(with_source_arms(source, source_body, &target, target_body)?)
            }
        })
    }
}

/// `target` with each arm's upper arm and forearm set to the source's on `source`'s first
/// frame, times the bodies' size ratio (standing pelvis heights, as [`Retargeter`] scales the
/// root's path): the template with the performer's arm proportions. Every joint offset from
/// the shoulder to the elbow (twist bones along the upper arm included) is scaled by one
/// factor, from the elbow to the wrist by another; the hands keep the template's. Errors: as
/// [`Retargeter::new`]'s for degenerate bodies, or an arm bone of zero length.
pub fn with_source_arms(
    source: &Clip,
    source_body: &BodyJoints,
    target: &Skeleton,
    target_body: &BodyJoints,
) -> Result<Skeleton> {
    let first = source.frame(0).ok_or(MotionError::EmptyClip)?;
    let (_, source_stance) = canonical(source.skeleton(), source_body)?;
    let (_, target_stance) = canonical(target, target_body)?;
    let size = target_stance.pelvis / source_stance.pelvis;
    let sp = source.skeleton().world_positions(first)?;
    let tp = target.world_positions(&target.rest_pose())?;
    let mut joints = target.joints().to_vec();
    for s in 0..2 {
        let (a, b) = (&source_body.arms[s], &target_body.arms[s]);
        for (from, to, source_bone) in [
            (b.shoulder, b.elbow, (sp[a.elbow] - sp[a.shoulder]).norm()),
            (b.elbow, b.wrist, (sp[a.wrist] - sp[a.elbow]).norm()),
        ] {
            let here = (tp[to] - tp[from]).norm();
            let factor = size * source_bone / here;
            if !(factor.is_finite() && factor > 0.0) {
                return Err(invalid(format!(
                    "an arm bone of zero length (`{}` → `{}`)",
                    target.joint(from).name,
                    target.joint(to).name
                )));
            }
            // Every joint hanging in this bone: below `from`, not below `to` (but `to`
            // itself).
            for (j, joint) in joints.iter_mut().enumerate() {
                let inside = j != from
                    && target.is_ancestor_or_self(from, j)
                    && (j == to || !target.is_ancestor_or_self(to, j));
                if inside {
                    joint.offset *= factor;
                }
            }
        }
    }
    Ok(Skeleton::new(joints)?.with_world_from_file(target.world_from_file()))
}

impl Retargeter {
    /// Prepares moving motions of `source` (whose first frame measures its bones, for its
    /// position channels may stretch them) onto `target`, with each body's roles. Errors: a
    /// target role joint without three rotation channels, a pelvis with no joint at or above
    /// it carrying three position channels, degenerate hips or shoulders.
    pub fn new(
        source: &Clip,
        source_body: BodyJoints,
        target: Arc<Skeleton>,
        target_body: BodyJoints,
    ) -> Result<Retargeter> {
        let first = source.frame(0).ok_or(MotionError::EmptyClip)?;
        let src = source.skeleton().clone();
        let (k_source, source_stance) = canonical(&src, &source_body)?;
        let (k_target, target_stance) = canonical(&target, &target_body)?;
        let source_inverse = k_source
            .iter()
            .map(|k| k.map_or_else(Rotation3::identity, |k| k.inverse()))
            .collect();

        // Which source joint each target role joint takes its turn from.
        let mut from: Vec<Option<usize>> = vec![None; target.joint_count()];
        let (sb, tb) = (&source_body, &target_body);
        from[tb.pelvis] = Some(sb.pelvis);
        // The spine from its first joint: the pelvis's own bone turns with the hips.
        let spine_chain = |b: &BodyJoints| -> Vec<usize> {
            if b.spine.len() > 1 {
                b.spine[..b.spine.len() - 1].to_vec()
            } else {
                vec![b.pelvis]
            }
        };
        let (s_spine, t_spine) = (spine_chain(sb), spine_chain(tb));
        // Spine and neck bones: (source chain, span) for each target joint that starts one.
        let mut chords: Vec<Option<(usize, f64, f64, usize)>> = vec![None; target.joint_count()];
        let mut chains = Vec::new();
        let (chain, bones) = match_chains(
            (&src, &s_spine, sb.chest()),
            (&target, &t_spine, tb.chest()),
        )?;
        for (k, (&t, &(s, a, b))) in t_spine.iter().zip(&bones).enumerate() {
            if t == tb.pelvis {
                continue;
            }
            from[t] = Some(s);
            let next = t_spine.get(k + 1).copied().unwrap_or(tb.chest());
            chords[t] = Some((chains.len(), a, b, next));
        }
        chains.push(chain);
        from[tb.chest()] = Some(sb.chest());
        if let (Some(sh), Some(th)) = (sb.head, tb.head) {
            // The neck from its first joint (the chest's own bone turns with the shoulders).
            let neck = |b: &BodyJoints| match b.neck.is_empty() {
                true => vec![b.chest()],
                false => b.neck.clone(),
            };
            let (s_neck, t_neck) = (neck(sb), neck(tb));
            let (chain, bones) = match_chains((&src, &s_neck, sh), (&target, &t_neck, th))?;
            for (k, (&t, &(s, a, b))) in t_neck.iter().zip(&bones).enumerate() {
                if t == tb.chest() {
                    continue;
                }
                from[t] = Some(s);
                let next = t_neck.get(k + 1).copied().unwrap_or(th);
                chords[t] = Some((chains.len(), a, b, next));
            }
            chains.push(chain);
            from[th] = Some(sh);
        }
        for s in 0..2 {
            let (sa, ta) = (&sb.arms[s], &tb.arms[s]);
            if let (Some(sc), Some(tc)) = (sa.clavicle, ta.clavicle) {
                from[tc] = Some(sc);
            }
            from[ta.shoulder] = Some(sa.shoulder);
            from[ta.elbow] = Some(sa.elbow);
            from[ta.wrist] = Some(sa.wrist);
            let (sl, tl) = (&sb.legs[s], &tb.legs[s]);
            from[tl.hip] = Some(sl.hip);
            from[tl.knee] = Some(sl.knee);
            from[tl.ankle] = Some(sl.ankle);
        }
        let zero_frames = target.fk(&target.rest_pose())?;
        let mut rules = Vec::with_capacity(target.joint_count());
        let mut euler = Vec::with_capacity(target.joint_count());
        for (j, joint) in target.joints().iter().enumerate() {
            let dofs = target.euler_dofs(j);
            let rule = match (from[j], k_target[j]) {
                (Some(source), Some(canonical)) => {
                    if dofs.is_none() {
                        return Err(invalid(format!(
                            "the target's `{}` (role joint) needs three rotation channels about \
                             three axes to take any turn; it has {}",
                            joint.name,
                            joint
                                .dofs
                                .iter()
                                .map(|d| d.channel_name())
                                .collect::<Vec<_>>()
                                .join(" ")
                        )));
                    }
                    let chord = chords[j].map(|(chain, from, to, next)| {
                        let (a, b) = (&zero_frames[j], &zero_frames[next]);
                        let bone =
                            a.rotation.inverse() * (b.translation.vector - a.translation.vector);
                        Chord {
                            chain,
                            from,
                            to,
                            bone,
                        }
                    });
                    Rule::Role {
                        source,
                        canonical,
                        chord,
                    }
                }
                // A joint of no role the source has too takes its turn, where its channels
                // can hold any turn; else it keeps its zero pose.
                _ => match src.joint_index(&joint.name) {
                    Some(s)
                        if k_source[s].is_none() && !src.joint(s).end_site && dofs.is_some() =>
                    {
                        Rule::Local(s)
                    }
                    _ => Rule::Rest,
                },
            };
            rules.push(rule);
            euler.push(dofs);
        }

        // The joint whose position channels place the pelvis.
        let has_translation = |j: usize| {
            let t = target
                .joint(j)
                .dofs
                .iter()
                .filter(|d| matches!(d, Dof::Translation(_)));
            t.count() == 3
        };
        let mut mover = tb.pelvis;
        while !has_translation(mover) {
            mover = target.joint(mover).parent.ok_or_else(|| {
                invalid(format!(
                    "no joint at or above the target's pelvis `{}` has three position channels \
                     to carry the root's path",
                    target.joint(tb.pelvis).name
                ))
            })?;
        }
        let mover_path = target
            .path(mover, tb.pelvis)
            .map(|p| p.into_iter().skip(1).collect())
            .unwrap_or_default();

        let zero = target.rest_pose();
        let leg_scale = target_stance.pelvis / source_stance.pelvis;
        let mut arm_scale = [1.0; 2];
        for (s, scale) in arm_scale.iter_mut().enumerate() {
            let (a, b) = (&sb.arms[s], &tb.arms[s]);
            *scale = limb_length(&target, &zero, b.shoulder, b.elbow, b.wrist)?
                / limb_length(&src, first, a.shoulder, a.elbow, a.wrist)?;
        }
        if !(leg_scale.is_finite()
            && leg_scale > 0.0
            && arm_scale.iter().all(|a| a.is_finite() && *a > 0.0))
        {
            return Err(invalid("a leg or an arm of zero length".into()));
        }
        let limb = |a: usize, b: usize, c: usize| Limb {
            root: a,
            middle: b,
            end: c,
        };
        let target_legs = tb.legs.map(|l| limb(l.hip, l.knee, l.ankle));
        let target_arms = [0, 1].map(|s| {
            let a = &tb.arms[s];
            limb(a.shoulder, a.elbow, a.wrist)
        });
        Ok(Retargeter {
            source: src,
            target,
            source_body,
            target_body,
            source_inverse,
            rules,
            chains,
            mover,
            mover_path,
            euler,
            leg_scale,
            ankle_heights: [source_stance.ankle, target_stance.ankle],
            arm_scale,
            target_legs,
            target_arms,
            bend_min_cos: (180.0 - MAX_BEND_DEG).to_radians().cos(),
        })
    }

    /// The roles matched and the target joints of none, for reports.
    fn roles(&self) -> (Vec<(String, String, String)>, Vec<String>) {
        let mut roles = Vec::new();
        let t_named = self.target_body.named(&self.target);
        for (role, t) in &t_named {
            if let Some(j) = self.target.joint_index(t)
                && let Rule::Role { source, .. } = self.rules[j]
            {
                let s = self.source.joint(source).name.clone();
                roles.push((role.clone(), s, t.clone()));
            }
        }
        let unmapped = self
            .target
            .joints()
            .iter()
            .zip(&self.rules)
            .filter(|(j, r)| !j.end_site && !matches!(r, Rule::Role { .. }))
            .map(|(j, _)| j.name.clone())
            .collect();
        (roles, unmapped)
    }

    /// The target skeleton.
    pub fn target(&self) -> &Arc<Skeleton> {
        &self.target
    }

    /// A source point carried to the target: × the leg scale about `fixed` (on the floor below
    /// the pelvis's first position).
    fn scaled(&self, p: &Vector3<f64>, fixed: &Vector3<f64>) -> Vector3<f64> {
        fixed + (p - fixed) * self.leg_scale
    }

    /// The point the scaling keeps fixed in `clip`: on the source's floor (the lowest ankle
    /// less its standing height) below the pelvis's first position; each foot's plants and
    /// its ankles' goals per frame (right, left).
    #[allow(clippy::type_complexity)]
    fn foot_goals(
        &self,
        clip: &Clip,
    ) -> Result<(Vector3<f64>, [Vec<Plant>; 2], [Vec<Vector3<f64>>; 2])> {
        let frames = clip.frame_count();
        let dt = clip.frame_time();
        let mut world = Vec::new();
        let mut source: [Vec<Vector3<f64>>; 2] = [Vec::new(), Vec::new()];
        let [h_source, h_target] = self.ankle_heights;
        let mut floor = f64::INFINITY;
        let mut first_pelvis = None;
        for pose in clip.frames() {
            self.source.fk_into(pose, &mut world)?;
            first_pelvis.get_or_insert(world[self.source_body.pelvis].translation.vector);
            for (s, a) in source.iter_mut().enumerate() {
                let leg = &self.source_body.legs[s];
                let ankle = world[leg.ankle].translation.vector;
                floor = floor.min(ankle.y - h_source);
                a.push(ankle);
            }
        }
        // The ankle above its standing height goes up × the scale; standing, it is at the
        // target's standing height.
        let lift = Vector3::new(0.0, h_target - h_source * self.leg_scale, 0.0);
        let pelvis = first_pelvis.ok_or(MotionError::EmptyClip)?;
        let fixed = Vector3::new(pelvis.x, floor, pelvis.z);
        let ankles = source.map(|a| {
            a.iter()
                .map(|p| self.scaled(p, &fixed) + lift)
                .collect::<Vec<_>>()
        });
        let min_frames = (PLANT_MIN_S / dt).ceil().max(2.0) as usize;
        let blend = (PLANT_BLEND_S / dt).round().max(1.0);
        let mut plants: [Vec<Plant>; 2] = [Vec::new(), Vec::new()];
        let mut goals = ankles.clone();
        for s in 0..2 {
            let a = &ankles[s];
            // Speed in the source's units: the scaled path over the scale.
            let speed = |k: usize| {
                let (i, j) = (k.saturating_sub(1), (k + 1).min(frames - 1));
                if i == j {
                    return 0.0;
                }
                (a[j] - a[i]).norm() / ((j - i) as f64 * dt) / self.leg_scale
            };
            let slow: Vec<bool> = (0..frames).map(|k| speed(k) < PLANT_SPEED).collect();
            let mut k = 0;
            while k < frames {
                if !slow[k] {
                    k += 1;
                    continue;
                }
                let start = k;
                // A slow foot that wanders off is shuffling, not planted: the plant ends there.
                while k < frames
                    && slow[k]
                    && (a[k] - a[start]).norm() < PLANT_RADIUS * self.leg_scale
                {
                    k += 1;
                }
                if k - start >= min_frames {
                    let mean = a[start..k].iter().sum::<Vector3<f64>>() / (k - start) as f64;
                    plants[s].push(Plant {
                        first: start,
                        last: k - 1,
                        at: mean.into(),
                    });
                }
            }
            for (f, goal) in goals[s].iter_mut().enumerate() {
                // The nearest plant, how far this frame is outside it, and the plant's frame
                // nearest to it.
                let nearest = plants[s]
                    .iter()
                    .map(|p| match f {
                        f if f < p.first => (p.first - f, p.first, p),
                        f if f > p.last => (f - p.last, p.last, p),
                        f => (0, f, p),
                    })
                    .min_by_key(|(d, ..)| *d);
                if let Some((d, edge, p)) = nearest
                    && (d as f64) < blend
                {
                    // Inside, the hold; outside, the moving path shifted by the hold's offset
                    // from it at the plant's edge, the shift fading over the blend.
                    let offset = Vector3::from(p.at) - ankles[s][edge];
                    *goal = ankles[s][f] + offset * (1.0 - d as f64 / blend);
                }
            }
        }
        Ok((fixed, plants, goals))
    }

    /// The target's world rotations of the joints of no role, from their parents (and the
    /// source's local rotation where it has the joint: `source_world` is the frame's FK).
    fn fill_rest(
        &self,
        rotations: &mut [Rotation3<f64>],
        source_world: &[nalgebra::IsometryMatrix3<f64>],
    ) {
        let w = self.target.world_from_file();
        for (j, rule) in self.rules.iter().enumerate() {
            let parent = || match self.target.joint(j).parent {
                Some(p) => rotations[p],
                None => w,
            };
            match rule {
                Rule::Rest => rotations[j] = parent(),
                Rule::Local(s) => {
                    // The source joint's turn relative to its parent (a root's, to the world).
                    let local = match self.source.joint(*s).parent {
                        Some(q) => source_world[q].rotation.inverse() * source_world[*s].rotation,
                        None => source_world[*s].rotation,
                    };
                    rotations[j] = match self.target.joint(j).parent {
                        Some(p) => rotations[p] * local,
                        None => local,
                    };
                }
                Rule::Role { .. } => {}
            }
        }
    }

    /// The target's world positions from its world rotations, the pelvis at `pelvis`.
    fn positions(
        &self,
        rotations: &[Rotation3<f64>],
        pelvis: &Vector3<f64>,
        out: &mut Vec<Vector3<f64>>,
    ) {
        let t = &self.target;
        let mut mover = *pelvis;
        for &k in self.mover_path.iter().rev() {
            let parent = t.joint(k).parent.unwrap_or(0);
            mover -= rotations[parent] * t.joint(k).offset;
        }
        out.clear();
        for (j, joint) in t.joints().iter().enumerate() {
            let p = if j == self.mover {
                mover
            } else {
                match joint.parent {
                    Some(p) => out[p] + rotations[p] * joint.offset,
                    None => t.world_from_file() * joint.offset,
                }
            };
            out.push(p);
        }
    }

    /// How far the pelvis must come down for `leg` to reach `goal` (0 where it does): the
    /// least `δ` with |goal − (hip − δ·y)| within the straight leg.
    fn drop_to_reach(&self, leg: Limb, goal: &Vector3<f64>, p: &[Vector3<f64>]) -> f64 {
        let reach = ((p[leg.middle] - p[leg.root]).norm() + (p[leg.end] - p[leg.middle]).norm())
            * (1.0 - 1e-9);
        let v = goal - p[leg.root];
        if v.norm() <= reach {
            return 0.0;
        }
        let discriminant = v.y * v.y - (v.norm_squared() - reach * reach);
        let drop = if discriminant >= 0.0 {
            -v.y - discriminant.sqrt()
        } else {
            -v.y
        };
        drop.max(0.0)
    }

    /// Two-bone IK of `limb` toward `goal`: turns the root and middle joints' world rotations
    /// (and those of their subtrees of no role), keeps the end's. Returns whether the bend was
    /// held to a limit.
    fn reach(
        &self,
        limb: Limb,
        goal: &Vector3<f64>,
        rotations: &mut [Rotation3<f64>],
        p: &[Vector3<f64>],
        pole_fallback: &mut Vector3<f64>,
    ) -> bool {
        let (a, b, c) = (p[limb.root], p[limb.middle], p[limb.end]);
        let (l1, l2) = ((b - a).norm(), (c - b).norm());
        let to_goal = goal - a;
        let d_max = l1 + l2;
        let d_min = (l1 * l1 + l2 * l2 - 2.0 * l1 * l2 * self.bend_min_cos)
            .max(0.0)
            .sqrt();
        let d_goal = to_goal.norm();
        let d = d_goal.clamp(d_min, d_max * (1.0 - 1e-12));
        let limited = d != d_goal;
        let Some(e) = to_goal.try_normalize(1e-12) else {
            return limited;
        };
        // The bend's side: where the middle joint is now, off the line to the goal.
        let off = (b - a) - e * e.dot(&(b - a));
        let pole = match off.try_normalize(1e-4 * l1.max(1e-9)) {
            Some(n) => {
                *pole_fallback = n;
                n
            }
            None => {
                let n = *pole_fallback - e * e.dot(pole_fallback);
                n.try_normalize(1e-9).unwrap_or_else(|| {
                    let other = if e.x.abs() < 0.9 {
                        Vector3::x()
                    } else {
                        Vector3::y()
                    };
                    e.cross(&other).normalize()
                })
            }
        };
        let cos_a = ((l1 * l1 + d * d - l2 * l2) / (2.0 * l1 * d)).clamp(-1.0, 1.0);
        let sin_a = (1.0 - cos_a * cos_a).sqrt();
        let middle = a + (e * cos_a + pole * sin_a) * l1;
        let end = a + e * d;
        let turn_root = swing(&(b - a), &(middle - a));
        let turn_middle = swing(&(turn_root * (c - b)), &(end - middle));
        let t = &self.target;
        // The subtree of the root turns by turn_root; below the middle, by turn_middle too;
        // role joints below the end keep their world rotation (the hand, the foot).
        for (j, r) in rotations.iter_mut().enumerate().skip(limb.root) {
            if !t.is_ancestor_or_self(limb.root, j) || t.is_ancestor_or_self(limb.end, j) {
                continue;
            }
            *r = if t.is_ancestor_or_self(limb.middle, j) {
                turn_middle * turn_root * *r
            } else {
                turn_root * *r
            };
        }
        limited
    }

    /// Retargets `clip` (of the source skeleton) onto the target skeleton.
    pub fn run(&self, clip: &Clip) -> Result<Retargeted> {
        if clip.skeleton().as_ref() != self.source.as_ref() {
            return Err(invalid(
                "the clip is not of the skeleton the retargeting was made for".into(),
            ));
        }
        let frames = clip.frame_count();
        if frames == 0 {
            return Err(MotionError::EmptyClip);
        }
        let (fixed, plants, foot_goals) = self.foot_goals(clip)?;
        let t = &self.target;
        let n = t.joint_count();
        let dofs = t.dof_count();
        let mut values = Vec::with_capacity(frames * dofs);
        let mut previous = t.rest_pose();
        let mut source_world = Vec::new();
        let mut rotations = vec![Rotation3::identity(); n];
        let mut p = Vec::with_capacity(n);
        let mut foot_error = [0.0f64; 2];
        let mut hand_error = [0.0f64; 2];
        let mut slide = 0.0f64;
        let mut bend_limited = 0;
        let mut pelvis_drop = 0.0f64;
        let mut poles = [Vector3::zeros(); 4];
        let w_inverse = t.world_from_file().inverse();
        for (f, pose) in clip.frames().enumerate() {
            self.source.fk_into(pose, &mut source_world)?;
            for (j, rule) in self.rules.iter().enumerate() {
                if let Rule::Role {
                    source,
                    canonical,
                    chord,
                } = rule
                {
                    let mut r =
                        source_world[*source].rotation * self.source_inverse[*source] * canonical;
                    if let Some(c) = chord {
                        let chain = &self.chains[c.chain];
                        let along =
                            chain.point(&source_world, c.to) - chain.point(&source_world, c.from);
                        r = swing(&(r * c.bone), &along) * r;
                    }
                    rotations[j] = r;
                }
            }
            self.fill_rest(&mut rotations, &source_world);
            let mut pelvis = self.scaled(
                &source_world[self.source_body.pelvis].translation.vector,
                &fixed,
            );
            self.positions(&rotations, &pelvis, &mut p);
            // A foot beyond its leg's reach (legs of other proportions, nearly straight) lowers
            // the pelvis as far as it needs.
            let drop = (0..2)
                .map(|s| self.drop_to_reach(self.target_legs[s], &foot_goals[s][f], &p))
                .fold(0.0, f64::max);
            if drop > 0.0 {
                pelvis.y -= drop;
                pelvis_drop = pelvis_drop.max(drop);
                self.positions(&rotations, &pelvis, &mut p);
            }
            let mut limited = false;
            for s in 0..2 {
                let (limb, goal) = (self.target_legs[s], &foot_goals[s][f]);
                limited |= self.reach(limb, goal, &mut rotations, &p, &mut poles[s]);
            }
            // The shoulders do not move with the legs: the hands' goals from the same positions.
            let sw = |j: usize| source_world[j].translation.vector;
            let hand_goals = [0, 1].map(|s| {
                let a = &self.source_body.arms[s];
                p[self.target_arms[s].root] + (sw(a.wrist) - sw(a.shoulder)) * self.arm_scale[s]
            });
            for s in 0..2 {
                let (limb, goal) = (self.target_arms[s], &hand_goals[s]);
                limited |= self.reach(limb, goal, &mut rotations, &p, &mut poles[2 + s]);
            }
            bend_limited += usize::from(limited);
            self.positions(&rotations, &pelvis, &mut p);
            for s in 0..2 {
                let ankle = p[self.target_legs[s].end];
                foot_error[s] = foot_error[s].max((ankle - foot_goals[s][f]).norm());
                if let Some(plant) = plants[s]
                    .iter()
                    .find(|pl| (pl.first..=pl.last).contains(&f))
                {
                    slide = slide.max((ankle - Vector3::from(plant.at)).norm());
                }
                let wrist = p[self.target_arms[s].end];
                hand_error[s] = hand_error[s].max((wrist - hand_goals[s]).norm());
            }

            // The pose: local rotations in each joint's channel order, the mover's translation.
            let mut out = vec![0.0; dofs];
            for (j, joint) in t.joints().iter().enumerate() {
                // Roles and turns taken from the source (checked to have Euler channels); a
                // joint of no role keeps its zero pose's.
                if let (false, Some((idx, axes))) =
                    (matches!(self.rules[j], Rule::Rest), self.euler[j])
                {
                    let parent = match joint.parent {
                        Some(q) => rotations[q].inverse(),
                        None => w_inverse,
                    };
                    let local = parent * rotations[j];
                    let near = idx.map(|i| previous[i]);
                    if let Some(angles) = euler_angles(axes, &local) {
                        let chosen = nearest_euler(angles, near);
                        for (i, v) in idx.into_iter().zip(chosen) {
                            out[i] = v;
                        }
                    }
                }
                if j == self.mover {
                    let local = match joint.parent {
                        Some(q) => rotations[q].inverse() * (p[j] - p[q]),
                        None => w_inverse * p[j],
                    } - joint.offset;
                    let start = t.first_dof(j);
                    for (k, d) in joint.dofs.iter().enumerate() {
                        if let Dof::Translation(a) = d {
                            out[start + k] = local[a.index()];
                        }
                    }
                }
            }
            values.extend_from_slice(&out);
            previous = out;
        }
        let clip = Clip::new(t.clone(), clip.frame_time(), values)?;
        let (roles, unmapped) = self.roles();
        Ok(Retargeted {
            clip,
            report: RetargetReport {
                roles,
                unmapped,
                leg_scale: self.leg_scale,
                arm_scale: self.arm_scale,
                plants,
                foot_slide_m: slide,
                foot_error_m: foot_error,
                hand_error_m: hand_error,
                bend_limited_frames: bend_limited,
                pelvis_drop_m: pelvis_drop,
            },
        })
    }
}
