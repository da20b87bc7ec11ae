//! What the controller's tests share: the 7-DoF arm, seeded random arms, bases and
//! configurations, the controller at 120 Hz, and checks on a synthesized motion.

use kinergy_motion::nalgebra::{IsometryMatrix3, Rotation3, Translation3, Vector3};
use kinergy_motion::{Chain, Motion};
use kinergy_solver::{
    ArmTask, Base, Controller, ControllerSettings, OptimizerKind, Synergy, Synthesis, Task,
};
use rand::rngs::Xoshiro256PlusPlus;
use rand::{RngExt, SeedableRng};

/// 120 Hz, the CMU captures' rate.
pub const DT: f64 = 1.0 / 120.0;

pub type Rng = Xoshiro256PlusPlus;

pub fn rng(seed: u64) -> Rng {
    Rng::seed_from_u64(seed)
}

/// 120 Hz, ε = 5 mm, the default stall rule and limit handling, a 20-second budget.
pub fn settings() -> ControllerSettings {
    ControllerSettings {
        max_frames: (20.0 / DT) as usize,
        ..ControllerSettings::at_frame_time(DT)
    }
}

pub fn controller(kind: OptimizerKind, synergy: Synergy) -> Controller {
    Controller::new(kind.default_optimizer(), synergy, settings()).expect("controller")
}

pub fn arm() -> Chain {
    Chain::arm(0.30, 0.26, 0.09).expect("arm")
}

/// An arm with a random adult's bone lengths and the default limits.
pub fn random_arm(rng: &mut Rng) -> Chain {
    Chain::arm(
        rng.random_range(0.25..0.36),
        rng.random_range(0.22..0.30),
        rng.random_range(0.05..0.11),
    )
    .expect("arm")
}

/// A configuration drawn uniformly from the middle `fraction` of every limit: each revolute
/// range shrunk about its center, each swing ellipse scaled about zero (1 = the whole range).
pub fn random_config(chain: &Chain, fraction: f64, rng: &mut Rng) -> Vec<f64> {
    let mut q = Vec::with_capacity(chain.dof_count());
    for m in chain.joints().iter().flat_map(|j| &j.motions) {
        match *m {
            Motion::Revolute { min, max, .. } => {
                let (c, h) = (0.5 * (min + max), 0.5 * (max - min) * fraction);
                q.push(rng.random_range(c - h..=c + h));
            }
            Motion::Swing { rx, ry } => loop {
                let (a, b): (f64, f64) = (rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                if a * a + b * b <= 1.0 {
                    q.extend([a * rx * fraction, b * ry * fraction]);
                    break;
                }
            },
        }
    }
    assert!(chain.within_limits(&q), "{q:?}");
    q
}

/// A random rigid frame: any rotation, its origin within a 2 m cube.
pub fn random_base(rng: &mut Rng) -> IsometryMatrix3<f64> {
    let axis = Vector3::new(
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
        rng.random_range(-1.0..1.0),
    );
    let rotation =
        Rotation3::from_scaled_axis(axis.normalize() * rng.random_range(0.0..std::f64::consts::PI));
    IsometryMatrix3::from_parts(
        Translation3::new(
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
            rng.random_range(-1.0..1.0),
        ),
        rotation,
    )
}

pub fn synthesize(
    c: &Controller,
    chain: &Chain,
    base: &Base,
    start: &[f64],
    task: Task,
) -> Synthesis {
    c.synthesize(&ArmTask {
        chain,
        base,
        start,
        task,
        start_velocity: None,
    })
    .expect("synthesize")
}

pub fn last(m: &Synthesis) -> &[f64] {
    m.configuration(m.frame_count() - 1)
}

pub fn assert_within_limits(chain: &Chain, m: &Synthesis, what: &str) {
    for i in 0..m.frame_count() {
        assert!(
            chain.within_limits(m.configuration(i)),
            "{what}: frame {i} {:?} is outside the limits",
            m.configuration(i)
        );
    }
}
