//! Measuring a capture's skeleton for the character's [`Proportions`]
//! ([`Proportions::from_skeleton`], [`Proportions::from_clip`]): limbs found by joint role
//! ([`ArmJoints::find`], [`LegJoints::find`]), the head by name, the rest from
//! [`Ratios::DRILLIS_CONTINI`].

use kinergy_io::InvalidSetting;
use kinergy_motion::limbs::{name_tokens, side_of};
use kinergy_motion::nalgebra::Point3;
use kinergy_motion::{ArmJoints, ArmLengths, Clip, LegJoints, MotionError, Side, Skeleton};

use super::proportions::{
    ArmSegments, LegSegments, Proportions, Ratios, SpineSegments, check_height,
};
use crate::error::{ReachError, Result};

fn setting(field: &str, why: impl Into<String>) -> ReachError {
    ReachError::Setting(InvalidSetting::new(field, why))
}

/// The `side` leg of a capture ([`LegJoints::find`]); a skeleton without one is a bad
/// `skeleton` input, like its other missing parts.
fn find_leg(skeleton: &Skeleton, side: Side) -> Result<LegJoints> {
    LegJoints::find(skeleton, side).map_err(|e| match e {
        MotionError::LegNotFound { .. } | MotionError::NoToe { .. } => {
            setting("skeleton", e.to_string())
        }
        e => e.into(),
    })
}

impl Proportions {
    /// Measured on a capture skeleton in its zero pose (see [`Proportions::from_clip`]).
    pub fn from_skeleton(skeleton: &Skeleton) -> Result<Proportions> {
        measure(skeleton, &skeleton.rest_pose())
    }

    /// Measured on a capture: bone lengths in the clip's first frame (position channels may
    /// stretch bones), widths and heights in the skeleton's zero pose when it is upright (the
    /// head above the hips, Y up), else in the first frame (Bandai Namco's zero pose lies
    /// along +X). A wrist without a hand point below it gets a hand
    /// [`kinergy_motion::limbs::arm::HAND_PER_FOREARM`] × its forearm long.
    ///
    /// Best effort by joint role: arms by [`ArmJoints::find`] (shoulder→elbow, elbow→wrist,
    /// wrist→hand point); legs by [`LegJoints::find`] (`UpLeg`/`UpperLeg`/`Thigh`/`Hip` →
    /// `Leg`/`LowerLeg`/`Knee`/`Shin`/`Calf` → `Foot`/`Ankle`, the toe tip being the ankle's
    /// farthest descendant); the top of the head as the highest point of the `Head` joint
    /// and its descendants. Keypoints without hands or feet (leaf wrists and ankles, End
    /// Sites) get Drillis & Contini's hand and foot, and without a `Head` joint the top of the
    /// head is the highest joint above the chest outside the arms (Human3.6M's head keypoint,
    /// COCO's eyes and ears). The standing height H is the head's top above the hips plus the
    /// mean leg (thigh + shank + ankle height 0.039 H); ankle height and heel come from
    /// [`Ratios::DRILLIS_CONTINI`], the toe keeps the measured ankle→toe-tip distance, the
    /// spine segments are Drillis & Contini's scaled to the measured hips→head-top distance,
    /// the shoulders sit at their measured height when it falls on the thoracic bone, and
    /// the widths are the measured distances between the shoulder and between the hip
    /// joints. Errors name what is missing.
    ///
    /// [`ArmJoints::find`]: kinergy_motion::ArmJoints::find
    /// [`LegJoints::find`]: kinergy_motion::LegJoints::find
    pub fn from_clip(clip: &Clip) -> Result<Proportions> {
        let pose = clip.frame(0).ok_or_else(|| {
            ReachError::Setting(InvalidSetting::new("clip", "it has no frames to measure"))
        })?;
        measure(clip.skeleton(), pose)
    }
}

/// The proportions of `skeleton` at `pose` (the method of [`Proportions::from_clip`]).
fn measure(skeleton: &Skeleton, pose: &[f64]) -> Result<Proportions> {
    let zero = skeleton.world_positions(&skeleton.rest_pose())?;
    let p = skeleton.world_positions(pose)?;
    let d = |a: usize, b: usize| (p[a] - p[b]).norm();
    let ratios = Ratios::DRILLIS_CONTINI;

    let mut arms = Vec::with_capacity(2);
    let mut shoulders = Vec::with_capacity(2);
    let mut tops = Vec::with_capacity(2);
    for side in [Side::Right, Side::Left] {
        let a = ArmJoints::find(skeleton, side)?;
        let measured = ArmLengths {
            upper_arm: d(a.shoulder, a.elbow),
            forearm: d(a.elbow, a.wrist),
            hand: a.hand.map_or(0.0, |h| d(a.wrist, h)),
        };
        // A wrist with no hand point below it (Bandai's Hand_R) gets the default hand.
        arms.push(ArmSegments {
            upper_arm: measured.upper_arm,
            forearm: measured.forearm,
            hand: measured.hand_or_default(),
        });
        shoulders.push(a.shoulder);
        tops.push(a.clavicle.unwrap_or(a.shoulder));
    }
    let legs = [
        find_leg(skeleton, Side::Right)?,
        find_leg(skeleton, Side::Left)?,
    ];
    let head = (0..skeleton.joint_count()).find(|&j| {
        let joint = skeleton.joint(j);
        let tokens = name_tokens(&joint.name);
        !joint.end_site && tokens.iter().any(|t| t == "head") && side_of(&tokens).is_none()
    });
    // The head and what hangs from it; without a head joint (keypoints, whose head is a leaf:
    // Human3.6M's head, COCO's eyes and ears), whatever hangs from the chest outside the arms.
    let crown: Vec<usize> = match head {
        Some(head) => (head..skeleton.joint_count())
            .filter(|&j| skeleton.is_ancestor_or_self(head, j))
            .collect(),
        None => {
            let chest = skeleton.common_ancestor(tops[0], tops[1]);
            (chest + 1..skeleton.joint_count())
                .filter(|&j| {
                    skeleton.is_ancestor_or_self(chest, j)
                        && !tops.iter().any(|&t| skeleton.is_ancestor_or_self(t, j))
                })
                .collect()
        }
    };
    InvalidSetting::require(
        !crown.is_empty(),
        "skeleton",
        "no head joint (named like `Head`) or joint above the shoulders to measure the height to",
    )?;
    let crown_name = skeleton.joint(head.unwrap_or(crown[0])).name.clone();
    // Skeletons whose zero pose is not upright (Bandai Namco's lies along +X) are measured
    // upright in the clip's first frame instead.
    let above_hips = |q: &[Point3<f64>]| {
        let top = crown
            .iter()
            .map(|&j| q[j].y)
            .fold(f64::NEG_INFINITY, f64::max);
        top - 0.5 * (q[legs[0].hip].y + q[legs[1].hip].y)
    };
    let zero = if above_hips(&zero) > 0.0 || above_hips(&p) <= 0.0 {
        zero
    } else {
        p.clone()
    };
    let top = crown
        .iter()
        .map(|&j| zero[j].y)
        .fold(f64::NEG_INFINITY, f64::max);
    let hips_y = 0.5 * (zero[legs[0].hip].y + zero[legs[1].hip].y);
    let upper = top - hips_y;
    InvalidSetting::require(
        upper.is_finite() && upper > 0.0,
        "skeleton",
        format!("the top of the head (`{crown_name}`) is not above the hips in the zero pose"),
    )?;
    let mean_thigh_shank = 0.5
        * legs
            .iter()
            .map(|l| d(l.hip, l.knee) + d(l.knee, l.ankle))
            .sum::<f64>();
    let height = (mean_thigh_shank + upper) / (1.0 - ratios.ankle_height);
    check_height(height)?;
    let ankle_height = ratios.ankle_height * height;
    let mut leg_segments = Vec::with_capacity(2);
    for (l, side) in legs.iter().zip(["right", "left"]) {
        let toe = match l.toe {
            Some(toe) => {
                let foot = d(l.ankle, toe);
                InvalidSetting::require(
                    foot > ankle_height,
                    "skeleton",
                    format!(
                        "the {side} foot (`{}` to `{}`, {foot} m) is shorter than the ankle height {ankle_height} m",
                        skeleton.joint(l.ankle).name,
                        skeleton.joint(toe).name
                    ),
                )?;
                (foot * foot - ankle_height * ankle_height).sqrt()
            }
            // A leaf ankle (keypoints without feet): Drillis & Contini's foot.
            None => ratios.toe * height,
        };
        leg_segments.push(LegSegments {
            thigh: d(l.hip, l.knee),
            shank: d(l.knee, l.ankle),
            ankle_height,
            toe,
            heel: ratios.heel * height,
        });
    }
    let k = upper / ratios.spine_sum();
    let mut spine = SpineSegments {
        pelvis_rise: ratios.pelvis_rise * k,
        sacrum: ratios.sacrum * k,
        lumbar: ratios.lumbar * k,
        thoracic: ratios.thoracic * k,
        neck: ratios.neck * k,
        head: ratios.head * k,
        shoulder_drop: ratios.shoulder_drop * k,
    };
    let cervical = spine.pelvis_rise + spine.sacrum + spine.lumbar + spine.thoracic;
    let shoulder_y = 0.5 * (zero[shoulders[0]].y + zero[shoulders[1]].y) - hips_y;
    let drop = cervical - shoulder_y;
    if drop >= 0.0 && drop < spine.thoracic {
        spine.shoulder_drop = drop;
    }
    let proportions = Proportions {
        right_arm: arms[0],
        left_arm: arms[1],
        right_leg: leg_segments[0],
        left_leg: leg_segments[1],
        spine,
        shoulder_width: (zero[shoulders[0]] - zero[shoulders[1]]).norm(),
        hip_width: (zero[legs[0].hip] - zero[legs[1].hip]).norm(),
    };
    proportions.validate()?;
    Ok(proportions)
}
