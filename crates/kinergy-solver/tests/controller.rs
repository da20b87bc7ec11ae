//! Integration tests of the synergy controller on the 7-DoF arm: every optimizer reaches what
//! is reachable, stops at the closest point of what is not, survives singular postures, and
//! the synergy models S_A–S_D shape the motion exactly as DESIGN §1.1 says.

use kinergy_motion::nalgebra::{
    DMatrix, DVector, IsometryMatrix3, Point3, Rotation3, Translation3, UnitQuaternion, Vector3,
};
use kinergy_motion::{Chain, Linearization, Motion};
use kinergy_solver::task::TaskError;
use kinergy_solver::{
    Base, Bounds, Controller, ControllerSettings, Model, Optimizer, OptimizerKind, ParamSpace,
    PseudoInverse, Reach, StepScratch, StopReason, Synergy, Synthesis, Task,
};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

const DT: f64 = 1.0 / 120.0;

type Rng = Xoshiro256PlusPlus;

fn rng(seed: u64) -> Rng {
    Rng::seed_from_u64(seed)
}

/// 120 Hz, ε = 5 mm, a 20-second budget.
fn settings() -> ControllerSettings {
    ControllerSettings {
        max_frames: (20.0 / DT) as usize,
        ..ControllerSettings::at_frame_time(DT)
    }
}

fn controller(kind: OptimizerKind, synergy: Synergy) -> Controller {
    Controller::new(kind.default_optimizer(), synergy, settings()).expect("controller")
}

fn arm() -> Chain {
    Chain::arm(0.30, 0.26, 0.09).expect("arm")
}

/// An arm with bone lengths of a random adult.
fn random_arm(rng: &mut Rng) -> Chain {
    Chain::arm(
        rng.random_range(0.25..0.36),
        rng.random_range(0.22..0.30),
        rng.random_range(0.05..0.11),
    )
    .expect("arm")
}

fn reach_length(chain: &Chain) -> f64 {
    chain.joints()[1..]
        .iter()
        .map(|j| j.offset.norm())
        .sum::<f64>()
        + chain.end_effector().norm()
}

/// A configuration uniformly inside every limit (swings uniform inside their ellipse).
fn random_config(chain: &Chain, rng: &mut Rng) -> Vec<f64> {
    let mut q = Vec::with_capacity(chain.dof_count());
    for m in chain.joints().iter().flat_map(|j| &j.motions) {
        match *m {
            Motion::Revolute { min, max, .. } => q.push(rng.random_range(min..=max)),
            Motion::Swing { rx, ry } => loop {
                let (a, b): (f64, f64) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                if a * a + b * b <= 1.0 {
                    q.extend([a * rx, b * ry]);
                    break;
                }
            },
        }
    }
    assert!(chain.within_limits(&q), "{q:?}");
    q
}

/// A random rigid frame: any rotation, origin within a 2 m cube.
fn random_base(rng: &mut Rng) -> IsometryMatrix3<f64> {
    let axis = Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    let angle = rng.random_range(0.0..std::f64::consts::PI);
    let rotation = Rotation3::from_scaled_axis(axis.normalize() * angle);
    IsometryMatrix3::from_parts(
        Translation3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        ),
        rotation,
    )
}

fn synthesize(c: &Controller, chain: &Chain, base: &Base, start: &[f64], task: Task) -> Synthesis {
    c.synthesize(&Reach {
        chain,
        base,
        start,
        task,
    })
    .expect("synthesize")
}

fn all_finite(m: &Synthesis) -> bool {
    m.configurations.iter().all(|v| v.is_finite())
        && m.points
            .iter()
            .all(|p| p.coords.iter().all(|v| v.is_finite()))
        && m.final_error.is_finite()
}

fn last(m: &Synthesis) -> &[f64] {
    m.configuration(m.frame_count() - 1)
}

// Every optimizer reaches FK-made (so reachable) targets from random starts, bases and arms,
// staying inside the joint limits on every frame.
#[test]
fn every_optimizer_reaches_reachable_targets_from_random_starts() {
    const CASES: usize = 150;
    for (k, kind) in OptimizerKind::ALL.into_iter().enumerate() {
        let c = controller(kind, Synergy::identity(7));
        let mut rng = rng(1000 + k as u64);
        let mut failures = Vec::new();
        let mut frames = Vec::new();
        for case in 0..CASES {
            let chain = random_arm(&mut rng);
            let base = random_base(&mut rng);
            let goal = random_config(&chain, &mut rng);
            let start = random_config(&chain, &mut rng);
            let target = chain.end_position(&base, &goal).expect("fk");
            let m = synthesize(
                &c,
                &chain,
                &Base::Fixed(base),
                &start,
                Task::Position(target),
            );
            for i in 0..m.frame_count() {
                assert!(
                    chain.within_limits(m.configuration(i)),
                    "{kind} case {case} frame {i}: {:?}",
                    m.configuration(i)
                );
            }
            let end = chain.end_position(&base, last(&m)).expect("fk");
            let error = (end - target).norm();
            if m.stop == StopReason::Reached && error < settings().tolerance {
                frames.push(m.frame_count());
            } else {
                failures.push((case, m.stop, error, m.frame_count()));
            }
        }
        frames.sort_unstable();
        eprintln!(
            "{kind}: reached {}/{CASES}, frames median {} max {}; failures {failures:?}",
            frames.len(),
            frames[frames.len() / 2],
            frames.last().expect("some")
        );
    }
}

fn projected(chain: &Chain, q: &[f64], g: &[f64]) -> Vec<f64> {
    let mut p = g.to_vec();
    let mut k = 0;
    for m in chain.joints().iter().flat_map(|j| &j.motions) {
        match *m {
            Motion::Revolute { min, max, .. } => {
                if (q[k] <= min && g[k] < 0.0) || (q[k] >= max && g[k] > 0.0) {
                    p[k] = 0.0;
                }
                k += 1;
            }
            Motion::Swing { rx, ry } => {
                let e = (q[k] / rx).powi(2) + (q[k + 1] / ry).powi(2);
                if e >= 1.0 - 1e-9 {
                    let n = Vector3::new(q[k] / (rx * rx), q[k + 1] / (ry * ry), 0.0).normalize();
                    let d = n.x * g[k] + n.y * g[k + 1];
                    if d > 0.0 {
                        p[k] -= d * n.x;
                        p[k + 1] -= d * n.y;
                    }
                }
                k += 2;
            }
        }
    }
    p
}

#[test]
fn diag() {
    for (k, kind) in OptimizerKind::ALL.into_iter().enumerate() {
        let c = controller(kind, Synergy::identity(7));
        let mut rng = rng(1000 + k as u64);
        let mut kkt = 0;
        let mut non = 0;
        for case in 0..150 {
            let chain = random_arm(&mut rng);
            let base = random_base(&mut rng);
            let goal = random_config(&chain, &mut rng);
            let start = random_config(&chain, &mut rng);
            let target = chain.end_position(&base, &goal).expect("fk");
            let m = synthesize(
                &c,
                &chain,
                &Base::Fixed(base),
                &start,
                Task::Position(target),
            );
            if m.stop == StopReason::Reached {
                continue;
            }
            let q = last(&m).to_vec();
            let mut lin = Linearization::default();
            chain.linearize_into(&base, &q, &mut lin).unwrap();
            let dx = target - lin.end;
            let g = lin.linear.transpose() * dx;
            let p = projected(&chain, &q, g.as_slice());
            let pn = p.iter().map(|v| v * v).sum::<f64>().sqrt();
            let gn = g.norm();
            if pn < 1e-3 * gn.max(1e-9) || pn < 1e-6 {
                kkt += 1
            } else {
                non += 1;
                if non <= 3 {
                    eprintln!(
                        "{kind} case {case} stop {} err {:.3} frames {} |g| {gn:.4} |proj g| {pn:.4}\n  q {:?}\n  g {:?}",
                        m.stop,
                        m.final_error,
                        m.frame_count(),
                        fmt(&q),
                        fmt(g.as_slice())
                    );
                }
            }
        }
        eprintln!("{kind}: failures at KKT points {kkt}, elsewhere {non}");
    }
}
fn fmt(v: &[f64]) -> Vec<String> {
    v.iter().map(|x| format!("{x:.4}")).collect()
}
#[test]
fn trace() {
    let kind = OptimizerKind::Njt;
    let c = controller(kind, Synergy::identity(7));
    let mut rng = rng(1001);
    for case in 0..4 {
        let chain = random_arm(&mut rng);
        let base = random_base(&mut rng);
        let goal = random_config(&chain, &mut rng);
        let start = random_config(&chain, &mut rng);
        let target = chain.end_position(&base, &goal).expect("fk");
        if case != 3 {
            continue;
        }
        let m = synthesize(
            &c,
            &chain,
            &Base::Fixed(base),
            &start,
            Task::Position(target),
        );
        for i in 125..140 {
            let q = m.configuration(i);
            let e = (chain.end_position(&base, q).unwrap() - target).norm();
            let mut lin = Linearization::default();
            chain.linearize_into(&base, q, &mut lin).unwrap();
            let mut step = vec![0.0; 7];
            kind.default_optimizer().step(
                &lin,
                &TaskError::position(target - lin.end),
                DT,
                &mut StepScratch::default(),
                &mut step,
            );
            let (sx, sy) = (q[0] + step[0], q[1] + step[1]);
            let el = (sx / 130f64.to_radians()).powi(2) + (sy / 100f64.to_radians()).powi(2);
            let mut next: Vec<f64> = q.iter().zip(&step).map(|(a, b)| a + b).collect();
            chain.clamp(&mut next);
            eprintln!(
                "  predicted next {:?} actual {:?}",
                next,
                m.configuration(i + 1)
            );
            eprintln!(
                "{i} err {e:.6} q {:?}\n   step {:?} ellipse after {el:.6}",
                fmt(q),
                step.iter().map(|x| format!("{x:.2e}")).collect::<Vec<_>>()
            );
        }
    }
}
