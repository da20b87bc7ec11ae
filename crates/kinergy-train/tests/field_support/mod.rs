//! What the field's tests share: a parameter space, a known linear field over a grid of
//! targets, deterministic noise, every combination of settings.

use kinergy_motion::nalgebra::Point3;
use kinergy_solver::{Bounds, Interval, Model, ParamSpace};
use kinergy_train::field::{Bandwidth, FieldSettings, Regression};

/// A target and the parameter vector fitted there.
pub type Sample = (Point3<f64>, Vec<f64>);

/// S_C on a 2-DoF chain with the paper's bounds: g_a, g_b ∈ [−5, 5], s ∈ [1, 10], o ∈ [0, 20]
/// (the default's offsets reach down to −40, a sigmoid on from the start; these tests' errors
/// are relative to the bound widths they were set with).
pub fn space() -> ParamSpace {
    ParamSpace::new(
        Model::Sc,
        &["a".to_string(), "b".to_string()],
        Bounds {
            offset: Interval::new(0.0, 20.0),
            ..Bounds::default()
        },
    )
    .expect("space")
}

/// Each parameter's bound width.
pub fn widths(space: &ParamSpace) -> Vec<f64> {
    space
        .upper()
        .iter()
        .zip(space.lower())
        .map(|(u, l)| u - l)
        .collect()
}

/// The middle of the grid.
pub const CENTER: [f64; 3] = [0.35, 0.0, 1.1];

/// A known field, linear in the target, well inside the bounds on the grid's box.
pub fn linear_truth(t: &Point3<f64>) -> Vec<f64> {
    let d = t - Point3::from(CENTER);
    vec![
        1.0 + 8.0 * d.x - 4.0 * d.y + 2.0 * d.z,
        -0.5 - 3.0 * d.x + 10.0 * d.z,
        5.0 + 12.0 * d.y - 6.0 * d.z,
        8.0 + 20.0 * d.x + 15.0 * d.y,
    ]
}

/// 4 × 3 × 3 = 36 targets, 0.1 m apart, around a seated person's reach space.
pub fn grid() -> Vec<Point3<f64>> {
    let mut out = Vec::new();
    for i in 0..4 {
        for j in 0..3 {
            for k in 0..3 {
                out.push(Point3::new(
                    0.2 + 0.1 * i as f64,
                    -0.1 + 0.1 * j as f64,
                    1.0 + 0.1 * k as f64,
                ));
            }
        }
    }
    out
}

/// Deterministic pseudo-random numbers in [0, 1) (a 64-bit LCG), independent of the crate.
pub struct Lcg(pub u64);

impl Lcg {
    pub fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Every bandwidth kind with every regression.
pub fn all_settings() -> Vec<FieldSettings> {
    let mut out = Vec::new();
    for bandwidth in [Bandwidth::Auto, Bandwidth::Fixed(0.07)] {
        for regression in [
            Regression::NadarayaWatson,
            Regression::local_linear(),
            Regression::LocalLinear { ridge: 0.0 },
        ] {
            out.push(FieldSettings {
                bandwidth,
                regression,
            });
        }
    }
    out
}

/// Noisy fits: the linear truth plus a deterministic perturbation, clamped into the bounds.
pub fn noisy_samples(seed: u64, amplitude: f64) -> Vec<Sample> {
    let space = space();
    let mut rng = Lcg(seed);
    let w = widths(&space);
    grid()
        .into_iter()
        .map(|t| {
            let mut p: Vec<f64> = linear_truth(&t)
                .iter()
                .zip(&w)
                .map(|(v, wi)| v + amplitude * wi * (rng.next() - 0.5))
                .collect();
            space.clamp(&mut p);
            (t, p)
        })
        .collect()
}
