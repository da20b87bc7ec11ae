//! The smooth controller (`ControllerSettings::smoothing`): the arm starts from rest (or from
//! the velocity it is given), the hand's acceleration and every DoF's stay within their bounds,
//! DoFs brake before their limits, a straight arm's start does not wander, and a synergy that
//! would not converge on its own (negative gains) still finishes its reach. The paper's
//! controller, for contrast, jumps and stalls on the same reaches.

use kinergy_motion::Chain;
use kinergy_motion::nalgebra::{IsometryMatrix3, Point3};
use kinergy_solver::{
    ArmTask, Base, Controller, ControllerSettings, Model, OptimizerKind, ParamSpace, Smoothing,
    StopReason, Synergy, Synthesis, Task,
};

const DT: f64 = 1.0 / 60.0;

fn arm() -> Chain {
    Chain::arm(0.30, 0.25, 0.08).expect("arm")
}

/// Bounds of a reach peaking at 1 m/s over 0.6 s on this arm: a_h = 10 m/s².
fn smoothing() -> Smoothing {
    Smoothing::for_reach(1.0, 0.6, 0.63)
}

fn reach_with(
    smoothing: Option<Smoothing>,
    synergy: Synergy,
    start: &[f64],
    velocity: Option<&[f64]>,
    target: Point3<f64>,
) -> Synthesis {
    let settings = ControllerSettings {
        smoothing,
        ..ControllerSettings::at_frame_time(DT)
    };
    let controller = Controller::new(OptimizerKind::Svd.default_optimizer(), synergy, settings)
        .expect("controller");
    controller
        .synthesize(&ArmTask {
            chain: &arm(),
            base: &Base::Fixed(IsometryMatrix3::identity()),
            start,
            task: Task::Position(target),
            start_velocity: velocity,
        })
        .expect("synthesis")
}

/// A hanging, nearly straight arm (elbow 0.06 rad) reaching forward and up.
fn reach(smoothing: Option<Smoothing>, target: Point3<f64>) -> Synthesis {
    let start = [0.0, 0.0, 0.0, 0.06, 0.0, 0.0, 0.0];
    reach_with(smoothing, Synergy::identity(7), &start, None, target)
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

/// The hand's displacement on each frame (the base is the world here).
fn hand_steps(m: &Synthesis) -> Vec<kinergy_motion::nalgebra::Vector3<f64>> {
    (1..m.frame_count())
        .map(|i| m.end(i) - m.end(i - 1))
        .collect()
}

/// The end effector's speed on each frame, m/s.
fn hand_speeds(m: &Synthesis) -> Vec<f64> {
    hand_steps(m).iter().map(|d| d.norm() / DT).collect()
}

#[test]
fn the_hand_starts_from_rest_and_accelerates_within_its_bound() {
    let sm = smoothing();
    let m = reach(Some(sm), Point3::new(0.25, -0.25, 0.3));
    assert_eq!(m.stop, StopReason::Reached);
    let bound = sm.hand_acceleration * DT * DT;
    let d = hand_steps(&m);
    // From rest: the first displacement is itself a change from zero.
    assert!(d[0].norm() <= bound * (1.0 + 1e-9), "first {}", d[0].norm());
    for (i, pair) in d.windows(2).enumerate() {
        let change = (pair[1] - pair[0]).norm();
        assert!(
            change <= bound * (1.0 + 1e-6) + 1e-12,
            "frame {i}: {change} > {bound}"
        );
    }
    // The joint bound too (braking before a limit shortens a step by at most what constant
    // deceleration allows, to rounding of the discrete stop: within twice the bound).
    let joint = sm.joint_acceleration * DT * DT;
    let s = steps(&m);
    let zero = vec![0.0; 7];
    let largest = std::iter::once(&zero)
        .chain(&s)
        .zip(&s)
        .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
        .fold(0.0, f64::max);
    assert!(largest <= 2.0 * joint + 1e-12, "{largest} > 2 × {joint}");
}

#[test]
fn a_spike_of_the_paper_controller_is_gone() {
    let target = Point3::new(0.25, -0.25, 0.3);
    let jumps = |m: &Synthesis| kinergy_motion::jumps::speed_jumps(&hand_speeds(m)).len();
    let free = reach(None, target);
    let smooth = reach(Some(smoothing()), target);
    assert_eq!(smooth.stop, StopReason::Reached);
    assert!(jumps(&free) > 0, "the paper's reach had no jump to remove");
    assert_eq!(jumps(&smooth), 0, "{:?}", hand_speeds(&smooth));
}

#[test]
fn no_dof_passes_its_limits_while_braking() {
    // Far up and across: the shoulder runs into its limits on the way.
    let m = reach(Some(smoothing()), Point3::new(-0.1, 0.45, 0.35));
    for i in 0..m.frame_count() {
        let mut q = m.configuration(i).to_vec();
        arm().clamp(&mut q);
        for (a, b) in q.iter().zip(m.configuration(i)) {
            approx::assert_relative_eq!(a, b, epsilon = 1e-9);
        }
    }
}

#[test]
fn a_straight_arm_moves_toward_a_near_target_from_its_first_frames() {
    // Hanging exactly straight (the radial direction has no singular value), the target
    // well inside the reach sphere: the elbow must bend.
    let start = [0.0; 7];
    let target = Point3::new(0.0, -0.2, 0.25);
    let smooth = reach_with(
        Some(smoothing()),
        Synergy::identity(7),
        &start,
        None,
        target,
    );
    assert_eq!(smooth.stop, StopReason::Reached);
    let error = |m: &Synthesis, i: usize| (m.end(i.min(m.frame_count() - 1)) - target).norm();
    // A third of a second in, the smooth arm has closed a good part of the distance.
    let at = (0.33 / DT) as usize;
    assert!(
        error(&smooth, at) < 0.8 * error(&smooth, 0),
        "{} vs {}",
        error(&smooth, at),
        error(&smooth, 0)
    );
    // And no speed jump on the way (the paper's elbow switches on at once when rounding
    // lets it).
    assert!(kinergy_motion::jumps::speed_jumps(&hand_speeds(&smooth)).is_empty());
    // The elbow bends from the first frames (the guidance of the near-straight arm).
    assert!(
        smooth.configuration(5)[3] > 1e-4,
        "{:?}",
        smooth.configuration(5)
    );
}

/// An S_B synergy with the given gains.
fn gains(g: [f64; 7]) -> Synergy {
    let names: Vec<String> = arm().dof_names().map(String::from).collect();
    let space = ParamSpace::new(Model::Sb, &names, Default::default()).expect("space");
    Synergy::new(&space, &g).expect("synergy")
}

#[test]
fn a_synergy_with_negative_gains_still_finishes_its_reach() {
    // Shoulder gains negative: on its own the synergy pushes the hand away from the target.
    let synergy = gains([-1.0, -1.0, 0.5, 1.0, 1.0, 1.0, 1.0]);
    let start = [0.0, 0.0, 0.0, 0.4, 0.0, 0.0, 0.0];
    let target = Point3::new(0.3, -0.1, 0.3);
    let paper = reach_with(None, synergy.clone(), &start, None, target);
    assert_ne!(
        paper.stop,
        StopReason::Reached,
        "the paper's synergy reached anyway"
    );
    let mut sm = smoothing();
    let smooth = reach_with(Some(sm), synergy.clone(), &start, None, target);
    assert_eq!(smooth.stop, StopReason::Reached, "{}", smooth.final_error);
    // Without the finish, the progress floor alone brings it in, slowly (it closes at least a
    // tenth of the plain optimizer's 4/s) and never stalls: in the 10 s budget, within a tenth
    // of where the paper's synergy ends (measured 0.09 with a_h = 5 V/T, 0.05 with 6 V/T: the
    // approach braking bounds its speed by √(2 a_h e)), still closing in.
    sm.finish = None;
    let floor = reach_with(Some(sm), synergy, &start, None, target);
    assert_ne!(floor.stop, StopReason::Stalled);
    assert!(
        floor.final_error < 0.1 * paper.final_error,
        "{} (paper {}), {:?} after {} frames",
        floor.final_error,
        paper.final_error,
        floor.stop,
        floor.configurations.len() / 7
    );
}

#[test]
fn a_start_velocity_is_carried_into_the_first_step() {
    let sm = smoothing();
    let start = [0.0, 0.0, 0.0, 0.6, 0.0, 0.0, 0.0];
    let v = [0.0, 0.0, 0.0, 1.5, 0.0, 0.0, 0.0];
    let target = Point3::new(0.2, -0.3, 0.25);
    let moving = reach_with(Some(sm), Synergy::identity(7), &start, Some(&v), target);
    let first = steps(&moving)[0][3] / DT;
    // The elbow goes on at about 1.5 rad/s: it may change by at most the joint bound.
    assert!(
        (first - 1.5).abs() <= sm.joint_acceleration * DT + 1e-9,
        "{first}"
    );
    // A wrong length is refused.
    let settings = ControllerSettings {
        smoothing: Some(sm),
        ..ControllerSettings::at_frame_time(DT)
    };
    let c = Controller::new(
        OptimizerKind::Svd.default_optimizer(),
        Synergy::identity(7),
        settings,
    )
    .expect("controller");
    let chain = arm();
    let mut stepper = c.stepper(&chain, &start).expect("stepper");
    assert!(stepper.set_start_velocity(&[0.0; 3]).is_err());
    assert!(stepper.set_start_velocity(&[f64::NAN; 7]).is_err());
}

#[test]
fn bad_smoothing_is_refused_by_name() {
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY] {
        let settings = ControllerSettings {
            smoothing: Some(Smoothing {
                hand_acceleration: bad,
                ..smoothing()
            }),
            ..ControllerSettings::at_frame_time(DT)
        };
        let e = settings.validate().expect_err("refused");
        assert!(e.to_string().contains("hand_acceleration"), "{e}");
    }
}

/// An S_D vector of the arm (gains, slopes, offsets) with some spread.
fn sd_values() -> Vec<f64> {
    let mut v = vec![1.3, 0.8, 1.1, 0.6, 1.4, 0.9, 1.2];
    v.extend([6.0, 8.0, 4.0, 9.0, 5.0, 7.0, 3.0]);
    v.extend([0.5, 1.0, 0.2, 2.0, 0.0, 1.5, 0.7]);
    v
}

fn arm_space(model: Model) -> ParamSpace {
    let names: Vec<String> = arm().dof_names().map(String::from).collect();
    ParamSpace::new(model, &names, kinergy_solver::Bounds::default()).expect("space")
}

fn bits(m: &Synthesis) -> Vec<u64> {
    m.configurations.iter().map(|v| v.to_bits()).collect()
}

// S_E carried over from S_D (no growth, tempo factors 1) is S_D's controller, bit for bit.
#[test]
fn s_d_carried_into_s_e_moves_exactly_as_s_d() {
    let (sd, se) = (arm_space(Model::Sd), arm_space(Model::Se));
    let values = sd_values();
    let carried = sd.extend_to(&values, &se).expect("extend");
    let start = [0.0, 0.0, 0.0, 0.06, 0.0, 0.0, 0.0];
    let target = Point3::new(0.25, -0.25, 0.3);
    let a = reach_with(
        Some(smoothing()),
        Synergy::new(&sd, &values).expect("S_D"),
        &start,
        None,
        target,
    );
    let b = reach_with(
        Some(smoothing()),
        Synergy::new(&se, &carried).expect("S_E"),
        &start,
        None,
        target,
    );
    assert_eq!(bits(&a), bits(&b));
}

// S_E's tempo factors are the smooth controller's bounds scaled: the same motion as S_D under
// bounds scaled by hand.
#[test]
fn s_e_tempo_factors_scale_the_smooth_controllers_bounds() {
    let (sd, se) = (arm_space(Model::Sd), arm_space(Model::Se));
    let values = sd_values();
    let mut own = sd.extend_to(&values, &se).expect("extend");
    let n = 7;
    own[4 * n] = 1.7; // acceleration
    own[4 * n + 1] = 0.4; // onset
    let sm = smoothing();
    let scaled = Smoothing {
        hand_acceleration: sm.hand_acceleration * 1.7,
        joint_acceleration: sm.joint_acceleration * 1.7,
        onset: sm.onset * 0.4,
        ..sm
    };
    let start = [0.0, 0.0, 0.0, 0.06, 0.0, 0.0, 0.0];
    let target = Point3::new(0.25, -0.25, 0.3);
    let by_hand = reach_with(
        Some(scaled),
        Synergy::new(&sd, &values).expect("S_D"),
        &start,
        None,
        target,
    );
    let s_e = reach_with(
        Some(sm),
        Synergy::new(&se, &own).expect("S_E"),
        &start,
        None,
        target,
    );
    assert_eq!(bits(&by_hand), bits(&s_e));
    // And the bound in force is the scaled one: the hand's change of displacement stays
    // within it and reaches beyond the unscaled bound.
    let d = hand_steps(&s_e);
    let largest = d
        .windows(2)
        .map(|p| (p[1] - p[0]).norm())
        .fold(0.0, f64::max);
    let bound = sm.hand_acceleration * DT * DT;
    assert!(
        largest <= 1.7 * bound * (1.0 + 1e-6),
        "{largest} > 1.7 × {bound}"
    );
    assert!(
        largest > bound,
        "{largest} ≤ {bound}: the factor did nothing"
    );
}
