//! The full-body reach as a viewer sees it: the hand leaves its rest smoothly and never
//! flies. (Issue 14 asks for ≤ 3 m/s on every frame of every reach; reaches with a full
//! step still reach 3.3–3.6 m/s because the root crosses between stance feet within the
//! 0.24-s weight shift: not yet asserted here, see the README's notes.)

use kinergy_motion::nalgebra::Point3;
use kinergy_reach::character::{Character, joint};
use kinergy_reach::controller::{ReachSettings, reach_full_body};

/// The reaching hand's world speed between consecutive frames, m/s.
fn hand_speeds(target: [f64; 3]) -> (Vec<f64>, f64) {
    let c = Character::from_height(1.75).expect("character");
    let m = reach_full_body(
        &c,
        Point3::new(target[0], target[1], target[2]),
        &ReachSettings::default(),
    )
    .expect("reach");
    let hand = if m.report.arm == "left_arm" {
        joint::LEFT_HAND_END
    } else {
        joint::RIGHT_HAND_END
    };
    let w: Vec<_> = m.poses.iter().map(|p| c.world_positions(p)[hand]).collect();
    let speeds = w
        .windows(2)
        .map(|p| (p[1] - p[0]).norm() / m.frame_time)
        .collect();
    (speeds, m.frame_time)
}

// From the hanging, straight arm the analytic solution flexes the elbow like the square root
// of the hand's travel; the arm's speed limit used to clamp each DoF alone, the shoulder
// swung on while the elbow was held back, and the hand jumped sideways at 2.5 m/s on the
// first frames before settling to the ease-out's 0.2 m/s (measured: 2.62, 1.06, 1.69 m/s).
// Scaling the whole step keeps the hand near its path: the first quarter second stays
// below 1 m/s (0.34 m/s without a squat) and no frame of these reaches (near, side, behind, high, low without a
// step) goes above 3 m/s.
#[test]
fn the_hand_leaves_its_rest_smoothly_and_never_flies() {
    for target in [
        [0.25, 1.1, 0.35],
        [0.3, 1.1, 0.4],
        [-0.4, 1.0, 0.5],
        [0.6, 1.0, -0.4],
        [0.0, 1.9, 0.3],
        [0.2, 0.15, 0.8],
    ] {
        let (speeds, dt) = hand_speeds(target);
        let start = (0.25 / dt).round() as usize;
        let early = speeds[..start].iter().fold(0.0_f64, |a, &b| a.max(b));
        assert!(
            early < 1.0,
            "{target:?}: the hand moves at {early:.2} m/s in the first 0.25 s"
        );
        let (at, peak) = speeds
            .iter()
            .enumerate()
            .fold((0, 0.0_f64), |a, (i, &v)| if v > a.1 { (i, v) } else { a });
        assert!(
            peak <= 3.0,
            "{target:?}: the hand moves at {peak:.2} m/s on frame {at}"
        );
    }
}
