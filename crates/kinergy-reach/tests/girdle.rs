//! The shoulder girdle on the full body: an overhead reach, ~0.3 m above the head and in front,
//! is reached by the arm — with the default profile (the analytic IK on a shoulder that rides
//! the clavicle) and with a person's synergy arm, without a hand-over — and along the motion
//! the clavicle's measured angles follow the scapulohumeral rhythm at the arm's measured
//! elevation.

use kinergy_motion::nalgebra::{Point3, Vector3};
use kinergy_reach::character::{Character, Girdle, Limb, joint};
use kinergy_reach::controller::{
    ArmDrive, ReachMotion, ReachSettings, ReachStop, arm_dof_names, reach_full_body_driven,
};
use kinergy_solver::{OptimizerKind, Synergy};

/// The synergy arm with S_A at gain 1 and damped least squares: the synergy controller's
/// stepping on the shoulder frame that rides the clavicle, without a person's quirks. (On the
/// shoulder twist limit of the generic table read in the capture convention, −90° at the
/// hanging arm, it stalls 0.42 m short while the character's own twist is at 55° of its ±90°:
/// the synergy chain's shoulder has only the character's limits.)
fn synergy(c: &Character) -> ArmDrive {
    ArmDrive::Synergy {
        optimizer: OptimizerKind::Dls.default_optimizer(),
        synergy: Synergy::identity(arm_dof_names(c).len()),
        tempo: None,
        controller: None,
    }
}

/// 0.3 m above the top of the head, 0.25 m in front, over the left shoulder.
fn overhead(c: &Character) -> Point3<f64> {
    let top = c.world_positions(&c.rest_pose())[joint::HEAD_END];
    Point3::new(0.12, top.y + 0.3, 0.25)
}

/// Per frame: the arm's humerothoracic elevation measured from joint positions (upper arm
/// against the thorax's downward axis) and the clavicle's elevation and retraction measured
/// from its world frame against the thorax's (the lateral axis's rise and its turn back).
fn measured(c: &Character, m: &ReachMotion) -> Vec<(f64, f64, f64)> {
    let [shoulder, elbow, _, _] = m.report.arm.joints();
    m.poses
        .iter()
        .map(|pose| {
            let f = c.world_frames(pose);
            let chest = f[joint::CHEST].rotation;
            let down = chest * -Vector3::z();
            let upper = f[elbow].translation.vector - f[shoulder].translation.vector;
            let elevation = upper.angle(&down);
            // The clavicle's lateral axis (thorax +x for the left) in thorax coordinates.
            let lateral = chest.inverse() * (f[joint::LEFT_SHOULDER].rotation * Vector3::x());
            let rise = lateral.z.asin();
            let back = lateral.y.atan2(lateral.x); // thorax y is back
            (elevation, rise, back)
        })
        .collect()
}

fn check_overhead(c: &Character, m: &ReachMotion, what: &str) {
    let target = overhead(c);
    assert_eq!(m.report.arm, Limb::LeftArm, "{what}");
    assert_eq!(m.report.stop, ReachStop::Reached, "{what}: {:?}", m.report);
    let rows = measured(c, m);
    let top = rows.iter().map(|r| r.0).fold(0.0, f64::max);
    let d = m.report.arm.dofs();
    let at = m.report.hand_over.map_or(0.0, |h| h.at_s);
    assert!(
        m.report.hand_over.is_none(),
        "{what}: {:?}, top {:.1}°, arm {:?}",
        m.report.hand_over,
        top.to_degrees(),
        &m.poses[(at / m.frame_time) as usize][d]
    );
    let hand = c.world_positions(m.poses.last().expect("frames"))[joint::LEFT_HAND_END];
    assert!((hand - target).norm() < 0.01, "{what}: {hand} vs {target}");
    for (i, pose) in m.poses.iter().enumerate() {
        c.joint_limits_ok(pose)
            .unwrap_or_else(|e| panic!("{what}: frame {i}: {e}"));
    }
    // Overhead: the arm well above the horizontal, and the clavicle rose and retracted.
    assert!(
        top.to_degrees() > 110.0,
        "{what}: top elevation {}°",
        top.to_degrees()
    );
    for (i, &(elevation, rise, back)) in rows.iter().enumerate() {
        let g = Girdle::angles(elevation);
        // Retraction then elevation: the lateral axis rises by the elevation exactly and turns
        // back by the retraction exactly.
        assert!(
            (rise - g.elevation).abs() < 0.1f64.to_radians()
                && (back - g.retraction).abs() < 0.1f64.to_radians(),
            "{what}: frame {i} at {:.1}°: clavicle ({:.2}°, {:.2}°), rhythm ({:.2}°, {:.2}°)",
            elevation.to_degrees(),
            rise.to_degrees(),
            back.to_degrees(),
            g.elevation.to_degrees(),
            g.retraction.to_degrees()
        );
    }
    let last = rows.last().expect("frames");
    assert!(
        last.1.to_degrees() > 6.0 && last.2.to_degrees() > 12.0,
        "{what}: {last:?}"
    );
}

#[test]
fn an_overhead_reach_with_the_default_profile() {
    let c = Character::from_height(1.75).expect("character");
    let m = reach_full_body_driven(
        &c,
        overhead(&c),
        &ReachSettings::default(),
        &ArmDrive::Profile,
    )
    .expect("reach");
    check_overhead(&c, &m, "profile");
}

#[test]
fn an_overhead_reach_with_a_synergy_arm_needs_no_hand_over() {
    let c = Character::from_height(1.75).expect("character");
    let drive = synergy(&c);
    let m =
        reach_full_body_driven(&c, overhead(&c), &ReachSettings::default(), &drive).expect("reach");
    check_overhead(&c, &m, "synergy");
}

/// The exported BVH puts every joint where the character's forward kinematics does, the
/// rotating clavicles included (read back through the motion crate's own FK).
#[test]
fn the_export_carries_the_girdle() {
    let c = Character::from_height(1.75).expect("character");
    let m = reach_full_body_driven(
        &c,
        overhead(&c),
        &ReachSettings::default(),
        &ArmDrive::Profile,
    )
    .expect("reach");
    let clip = c.to_clip(&m.poses, m.frame_time).expect("clip");
    let last = m.poses.len() - 1;
    let ours = c.world_positions(&m.poses[last]);
    let theirs = clip
        .skeleton()
        .world_positions(clip.frame(last).expect("frame"))
        .expect("fk");
    for (j, (a, b)) in ours.iter().zip(&theirs).enumerate() {
        assert!((a - b).norm() < 1e-9, "joint {j}: {a} vs {b}");
    }
    let shoulder = clip
        .skeleton()
        .joint_index("LeftShoulder")
        .expect("clavicle");
    assert!(!clip.skeleton().joints()[shoulder].dofs.is_empty());
}
