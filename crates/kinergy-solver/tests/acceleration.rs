//! The controller's acceleration limit (`ControllerSettings::acceleration`): the arm starts
//! from rest, its step changes by a bounded amount from frame to frame, it brakes before its
//! limits instead of being stopped by them, and it still arrives. Issue 23: the paper's
//! controller's step jumps (near a singular arm the pseudo-inverse's step grows without bound,
//! and a DoF that meets its limit stops in one frame), which shows as one-frame spikes of the
//! hand speed.

use kinergy_motion::Chain;
use kinergy_motion::nalgebra::{IsometryMatrix3, Point3};
use kinergy_solver::{
    ArmTask, Base, Controller, ControllerSettings, OptimizerKind, StopReason, Synergy, Synthesis,
    Task,
};

const DT: f64 = 1.0 / 60.0;

/// A hanging, nearly straight arm (elbow 0.06 rad) reaching forward and up: the SVD step's
/// radial part switches on when the elbow's singular value crosses the threshold.
fn reach(acceleration: Option<f64>, target: Point3<f64>) -> (Chain, Synthesis) {
    let arm = Chain::arm(0.30, 0.25, 0.08).expect("arm");
    let settings = ControllerSettings {
        acceleration,
        ..ControllerSettings::at_frame_time(DT)
    };
    let controller = Controller::new(
        OptimizerKind::Svd.default_optimizer(),
        Synergy::identity(7),
        settings,
    )
    .expect("controller");
    let start = [0.0, 0.0, 0.0, 0.06, 0.0, 0.0, 0.0];
    let motion = controller
        .synthesize(&ArmTask {
            chain: &arm,
            base: &Base::Fixed(IsometryMatrix3::identity()),
            start: &start,
            task: Task::Position(target),
        })
        .expect("synthesis");
    (arm, motion)
}

/// Each frame's joint step (the configuration's change).
fn steps(m: &Synthesis) -> Vec<Vec<f64>> {
    (1..m.frame_count())
        .map(|i| {
            m.configuration(i)
                .iter()
                .zip(m.configuration(i - 1))
                .map(|(a, b)| a - b)
                .collect()
        })
        .collect()
}

/// The largest change of any DoF's step between consecutive frames, the first step against
/// rest included.
fn largest_change(m: &Synthesis) -> f64 {
    let s = steps(m);
    let zero = vec![0.0; 7];
    std::iter::once(&zero)
        .chain(&s)
        .zip(&s)
        .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
        .fold(0.0, f64::max)
}

/// The end effector's speed on each frame, m/s.
fn hand_speeds(m: &Synthesis) -> Vec<f64> {
    (1..m.frame_count())
        .map(|i| (m.end(i) - m.end(i - 1)).norm() / DT)
        .collect()
}

#[test]
fn the_arm_starts_from_rest_and_its_step_changes_by_at_most_the_bound() {
    let target = Point3::new(0.25, -0.25, 0.3);
    let a = 20.0;
    let (_, limited) = reach(Some(a), target);
    let (_, free) = reach(None, target);
    assert_eq!(limited.stop, StopReason::Reached);
    let bound = a * DT * DT;
    // Braking before a limit shortens a step by at most what constant deceleration allows,
    // to rounding of the discrete stop: within twice the bound.
    assert!(
        largest_change(&limited) <= 2.0 * bound + 1e-12,
        "{} > 2 × {bound}",
        largest_change(&limited)
    );
    let first = steps(&limited)[0]
        .iter()
        .fold(0.0_f64, |m, v| m.max(v.abs()));
    assert!(first <= bound + 1e-12, "first step {first}");
    // The paper's controller jumps by far more.
    assert!(
        largest_change(&free) > 10.0 * bound,
        "{}",
        largest_change(&free)
    );
}

#[test]
fn a_spike_of_the_unlimited_controller_is_gone_with_the_limit() {
    let target = Point3::new(0.25, -0.25, 0.3);
    let jumps = |m: &Synthesis| kinergy_motion::jumps::speed_jumps(&hand_speeds(m)).len();
    let (_, free) = reach(None, target);
    // 12 rad/s² in every DoF: the hand's speed changes by at most ≈ 0.18 m/s a frame here.
    let (_, limited) = reach(Some(12.0), target);
    assert_eq!(limited.stop, StopReason::Reached);
    assert!(
        jumps(&free) > 0,
        "the unlimited reach had no jump to remove"
    );
    assert_eq!(jumps(&limited), 0, "{:?}", hand_speeds(&limited));
}

#[test]
fn no_dof_passes_its_limits_while_braking() {
    // Far up and across: the shoulder runs into its limits on the way.
    let (arm, m) = reach(Some(20.0), Point3::new(-0.1, 0.45, 0.35));
    for i in 0..m.frame_count() {
        let mut q = m.configuration(i).to_vec();
        arm.clamp(&mut q);
        for (a, b) in q.iter().zip(m.configuration(i)) {
            approx::assert_relative_eq!(a, b, epsilon = 1e-9);
        }
    }
}

#[test]
fn a_bad_acceleration_is_refused_by_name() {
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let settings = ControllerSettings {
            acceleration: Some(bad),
            ..ControllerSettings::at_frame_time(DT)
        };
        let e = settings.validate().expect_err("refused");
        assert!(e.to_string().contains("acceleration"), "{e}");
    }
}
