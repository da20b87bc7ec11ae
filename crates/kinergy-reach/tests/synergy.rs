//! The full-body reach with the arm driven by a person's synergy controller: the hand ends
//! within 1 cm of every reachable target of a grid around the body (near, far enough to step,
//! low enough to squat), joint limits, planted feet and balance hold on every frame as for the
//! profile-driven reach, and where the synergy arm cannot finish the analytic IK's hand-over is
//! reported.
//!
//! Parameters: `tests/data/params/` (see its README): one fitted on a real capture (CMU subject
//! 6 on the Character Creator rig, whose fitted vector does not even reach its own target:
//! hand-overs are expected) and one on the synthetic character's own reach.

use std::path::{Path, PathBuf};

use kinergy_motion::nalgebra::{Point2, Point3};
use kinergy_reach::character::{Character, Limb, joint};
use kinergy_reach::controller::{
    ArmDrive, ArmDriveKind, HandOverWhy, ReachMotion, ReachSettings, ReachStop, arm_dof_names,
    reach_full_body, reach_full_body_driven,
};
use kinergy_solver::{ParamsFile, Synergy};

fn params_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/params")
        .join(name)
}

fn drive(c: &Character, name: &str) -> ArmDrive {
    let path = params_path(name);
    let file = ParamsFile::read(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    ArmDrive::Synergy {
        optimizer: file.optimizer,
        synergy: file.synergy_for(&arm_dof_names(c)).expect("the arm's DoFs"),
        tempo: None,
        controller: None,
    }
}

fn hand(c: &Character, m: &ReachMotion) -> Point3<f64> {
    let p = c.world_positions(m.poses.last().expect("frames"));
    if m.report.arm == Limb::LeftArm {
        p[joint::LEFT_HAND_END]
    } else {
        p[joint::RIGHT_HAND_END]
    }
}

/// Every frame within the limits, planted feet still (≤ 1 mm), the COM over the support
/// polygon.
fn check_frames(c: &Character, m: &ReachMotion, what: &str) {
    let mut prev = c.foot_points(&m.poses[0]);
    for (i, pose) in m.poses.iter().enumerate() {
        c.joint_limits_ok(pose)
            .unwrap_or_else(|e| panic!("{what}: frame {i}: {e}"));
        let feet = c.foot_points(pose);
        for k in 0..4 {
            if feet[k].y.abs() < 1e-6 && prev[k].y.abs() < 1e-6 {
                let slide = (feet[k] - prev[k]).norm();
                assert!(
                    slide <= 1e-3,
                    "{what}: frame {i}: a planted foot slid {slide} m"
                );
            }
        }
        prev = feet;
        let com = c.com(pose);
        let margin = c.support_polygon(pose).margin(Point2::new(com.x, com.z));
        assert!(
            margin > -1e-9,
            "{what}: frame {i}: COM {margin} m outside the support polygon"
        );
    }
}

/// Near, far (a step), low (a squat), high, to the side, across, behind.
const GRID: [[f64; 3]; 10] = [
    [0.25, 1.1, 0.35],
    [-0.3, 1.3, 0.3],
    [0.1, 0.9, 0.5],
    [0.2, 1.0, 1.15],
    [-0.2, 1.0, 1.15],
    [0.2, 0.3, 0.8],
    [0.0, 1.5, 0.45],
    [-0.5, 1.0, -0.3],
    [0.5, 1.4, 0.1],
    [-0.6, 0.6, 0.5],
];

fn grid_reaches(name: &str) -> Vec<([f64; 3], ReachMotion)> {
    let c = Character::from_height(1.75).expect("character");
    let drive = drive(&c, name);
    let settings = ReachSettings::default();
    GRID.iter()
        .map(|&t| {
            let target = Point3::new(t[0], t[1], t[2]);
            let m = reach_full_body_driven(&c, target, &settings, &drive).expect("reach");
            let what = format!("{name} {t:?}");
            check_frames(&c, &m, &what);
            let error = (hand(&c, &m) - target).norm();
            assert_eq!(m.report.stop, ReachStop::Reached, "{what}: {:?}", m.report);
            assert!(error < 0.01, "{what}: {error} m");
            assert!((error - m.report.final_error).abs() < 1e-9, "{what}");
            assert_eq!(m.report.arm_drive, ArmDriveKind::Synergy);
            if let Some(h) = m.report.hand_over {
                assert!(h.distance_m > 0.5 * settings.tolerance, "{what}: {h:?}");
                // A hand-over may fall on the motion's last frame (the plain IK's first step
                // reaching): within a frame of the end.
                assert!(
                    h.at_s > 0.0 && h.at_s <= m.report.duration + 0.02,
                    "{what}: {h:?}, duration {}",
                    m.report.duration
                );
            }
            (t, m)
        })
        .collect()
}

#[test]
fn a_real_captures_synergy_reaches_every_grid_target_within_a_centimeter() {
    let reaches = grid_reaches("006_14-sc.json");
    let handed: Vec<_> = reaches
        .iter()
        .filter_map(|(t, m)| m.report.hand_over.map(|h| (t, h)))
        .collect();
    eprintln!(
        "006_14: {} of {} reaches handed over: {handed:?}",
        handed.len(),
        reaches.len()
    );
}

/// The synthetic character's own synergy carries the hand all the way on most of the grid
/// (the hand-over is the exception, not the rule), and its motion is not the profile's.
#[test]
fn the_characters_own_synergy_drives_the_hand_to_the_target() {
    let reaches = grid_reaches("synthetic-p01-r09-sc.json");
    let by_synergy = reaches
        .iter()
        .filter(|(_, m)| m.report.hand_over.is_none())
        .count();
    let handed: Vec<_> = reaches
        .iter()
        .filter_map(|(t, m)| m.report.hand_over.map(|h| (t, h)))
        .collect();
    eprintln!(
        "synthetic p01/r09: {by_synergy} of {} reaches without a hand-over; {handed:?}",
        reaches.len()
    );
    assert!(by_synergy >= 7, "{by_synergy} of {}", reaches.len());
    let c = Character::from_height(1.75).expect("character");
    let (t, with) = &reaches[0];
    let without = reach_full_body(&c, Point3::new(t[0], t[1], t[2]), &ReachSettings::default())
        .expect("reach");
    assert_eq!(without.report.arm_drive, ArmDriveKind::Profile);
    assert!(without.report.hand_over.is_none());
    // Halfway through, the two hands are centimeters apart.
    let half = with.poses.len().min(without.poses.len()) / 2;
    let at = |m: &ReachMotion| c.world_positions(&m.poses[half])[joint::LEFT_HAND_END];
    assert!((at(with) - at(&without)).norm() > 0.02);
}

/// A synergy whose gains are all zero never moves the arm: its progress stalls, the analytic
/// IK takes the hand over (reported, with the distance it started from) and finishes.
#[test]
fn a_synergy_that_cannot_move_hands_over_and_says_so() {
    let c = Character::from_height(1.75).expect("character");
    let path = params_path("synthetic-p01-r09-sc.json");
    let file = ParamsFile::read(&path).expect("params");
    let space = file.space().expect("space");
    let mut values = file.values().expect("values");
    for (v, name) in values.iter_mut().zip(space.names()) {
        if name.starts_with("g_") {
            *v = 0.0;
        }
    }
    let synergy = Synergy::new(&space, &values).expect("synergy");
    let drive = ArmDrive::Synergy {
        optimizer: file.optimizer,
        synergy,
        tempo: None,
        controller: None,
    };
    let target = Point3::new(0.25, 1.1, 0.35);
    let m = reach_full_body_driven(&c, target, &ReachSettings::default(), &drive).expect("reach");
    check_frames(&c, &m, "zero gains");
    let h = m.report.hand_over.expect("a hand-over");
    assert_eq!(h.why, HandOverWhy::Stalled);
    // The hand had not moved since the controller's first posture (its relaxed elbow,
    // `RELAXED_ELBOW`): the frame before the hand-over.
    let before = ((h.at_s / m.frame_time).round() as usize).saturating_sub(1);
    let still = c.world_positions(&m.poses[before])[joint::LEFT_HAND_END];
    assert!(
        (h.distance_m - (still - target).norm()).abs() < 1e-6,
        "the hand had not moved: {h:?}"
    );
    assert_eq!(m.report.stop, ReachStop::Reached);
    assert!((hand(&c, &m) - target).norm() < 0.01);
}

/// A parameters file made for another chain is refused, naming what differs.
#[test]
fn params_for_another_chain_are_refused() {
    let c = Character::from_height(1.75).expect("character");
    let path = params_path("006_14-sc.json");
    let file = ParamsFile::read(&path).expect("params");
    let mut names = arm_dof_names(&c);
    names.pop();
    assert!(file.synergy_for(&names).is_err());
}

/// On a grid of targets, the hand's speed relative to the shoulder has no jump
/// (`kinergy_motion::jumps::speed_jumps`: a frame-to-frame change above 0.25 m/s and 4× the
/// reach's median change) from the arm's onset to the reach's end, with a person's synergy (a
/// real capture's, which hands over on half the grid, and the synthetic character's own) and
/// with the default profile, and every reach ends reached.
///
/// Without the analytic arm tracking its goal (`controller::arm`), measured on the same 30
/// reaches, the default profile jumps on 9 of 10 (0.7 → 0.2 m/s at 0.28 s, the catch-up of a
/// ramped speed limit), and the hand-overs to plain IK on 5 (0.25 → 2.5 m/s).
///
/// Without the synergy arm's brake before the character's limits
/// (`kinergy_reach::controller::SynergyArm::pose_arm`), the person synergies jump on 4 of 20:
/// the real capture's toward [-0.3, 1.3, 0.3] and [0.5, 1.4, 0.1] once each (the character's
/// twist limit, ±90° below 90° of elevation, stops the twist within a frame), toward
/// [0.2, 0.3, 0.8] twice near 3.6 s (the character's swing ellipse clamps the circling arm),
/// and the synthetic person's toward [-0.6, 0.6, 0.5] once (its twist held at once by the
/// capture convention's and the character's limits). Two alternatives do not serve: braking
/// the swing radially alone moves the jumps to the hand-over, and easing the character's elbow
/// into the controller's relaxed start (`RELAXED_ELBOW`) after the onset (at 0.25–0.5 s) makes
/// a 30 Hz held-out raise jump or moves its peak 0.13 late; the reaching arm instead hangs
/// relaxed before its reach, as the idle arm does, so its elbow does not snap on the first
/// frame. Braking the twist while its range does not widen overhead costs the held-out
/// *active* raises r 0.73 → 0.53; with the widening it raises them 0.81 → 0.85.
#[test]
fn reaches_on_the_grid_have_no_speed_jumps() {
    use kinergy_motion::jumps::speed_jumps;
    let c = Character::from_height(1.75).expect("character");
    let settings = ReachSettings::default();
    let mut report = Vec::new();
    let mut failed = Vec::new();
    for (name, drive) in [
        ("006_14-sc", drive(&c, "006_14-sc.json")),
        (
            "synthetic-p01-r09-sc",
            drive(&c, "synthetic-p01-r09-sc.json"),
        ),
        ("profile", ArmDrive::Profile),
    ] {
        for t in GRID {
            let target = Point3::new(t[0], t[1], t[2]);
            let m = reach_full_body_driven(&c, target, &settings, &drive).expect("reach");
            let speeds = m.arm_speeds(&c, false);
            let jumps = speed_jumps(&speeds);
            let line = format!(
                "{name} {t:?}: {} jumps {:?} ({:?}, hand-over {:?}, limited at {:?} s)",
                jumps.len(),
                jumps.first(),
                m.report.stop,
                m.report.hand_over,
                m.report.synergy_limited_at_s,
            );
            if !jumps.is_empty() || m.report.stop != ReachStop::Reached {
                failed.push(line.clone());
            }
            report.push(line);
        }
    }
    for r in &report {
        eprintln!("{r}");
    }
    assert!(failed.is_empty(), "{failed:#?}");
}

/// The arm runs the controller the person's parameters were fitted under (the drive's
/// `controller`, their record's) unless the settings choose one: a drive recorded under the
/// paper's controller moves as the settings' `paper` does, and not as the smooth one.
#[test]
fn the_synergy_arm_runs_the_controller_the_person_was_fitted_under() {
    let c = Character::from_height(1.75).expect("character");
    let target = Point3::new(0.25, 1.1, 0.35);
    let with = |recorded, chosen| {
        let mut d = drive(&c, "synthetic-p01-r09-sc.json");
        if let ArmDrive::Synergy { controller, .. } = &mut d {
            *controller = recorded;
        }
        let settings = ReachSettings {
            synergy_controller: chosen,
            ..ReachSettings::default()
        };
        let m = reach_full_body_driven(&c, target, &settings, &d).expect("reach");
        let end = match m.report.arm {
            Limb::LeftArm => joint::LEFT_HAND_END,
            _ => joint::RIGHT_HAND_END,
        };
        m.poses
            .iter()
            .map(|p| c.world_positions(p)[end])
            .collect::<Vec<_>>()
    };
    use kinergy_solver::ControllerKind::{Paper, Smooth};
    let recorded_paper = with(Some(Paper), None);
    assert_eq!(recorded_paper, with(None, Some(Paper)));
    assert_eq!(recorded_paper, with(Some(Smooth), Some(Paper)));
    let smooth = with(None, None);
    assert_eq!(smooth, with(Some(Smooth), None));
    assert_eq!(smooth, with(Some(Paper), Some(Smooth)));
    let apart = recorded_paper
        .iter()
        .zip(&smooth)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    assert!(
        apart > 1e-3,
        "the controllers move the hand alike ({apart} m apart)"
    );
}
