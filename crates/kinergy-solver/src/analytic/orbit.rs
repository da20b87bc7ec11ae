//! Kallmann's orbit-angle search settings: the angles tried ([`OrbitSearch`], [`OrbitAlphas`])
//! and which way α turns ([`OrbitSense`]). The search itself — full pose
//! ([`LimbIk::search`]) or position only ([`LimbIk::solve_position`]), taking the first α
//! whose posture is within limits (and accepted) — is a method of [`LimbIk`] in `solver.rs`.
//!
//! [`LimbIk`]: super::LimbIk
//! [`LimbIk::search`]: super::LimbIk::search
//! [`LimbIk::solve_position`]: super::LimbIk::solve_position

use kinergy_io::InvalidSetting;

use super::error::AnalyticError;

/// Which way α turns the elbow about the shoulder→wrist axis `n`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum OrbitSense {
    /// α is a right-handed rotation about `n`: `v̂ = n × û`. For a body that is Y-up and faces
    /// +z, this raises the elbow outward for the **left** arm.
    #[default]
    RightHanded,
    /// α is a left-handed rotation about `n`: `v̂ = û × n`; outward for the **right** arm of
    /// a Y-up body facing +z.
    LeftHanded,
}

/// Kallmann's orbit-angle search: the start angle, then `start ± Δ_k` (plus first, then
/// minus) with `Δ_1 = step` and `Δ_{k+1} = Δ_k + step · growth^k`, clipped to
/// `[min, max]` — each end of the range is tried once when a step overshoots it.
///
/// The default — start 20°, range [−15°, 130°], step 5°, growth 1.2 — follows the paper
/// (a growing increment, "greedy"); it tries at most 16 angles: 20, 25, 15, 31, 9, 38.2,
/// 1.8, 46.8, −6.8, 57.2, −15, 69.6, 84.6, 102.5, 124.0, 130 (degrees). Growth 1 gives a
/// uniform grid (30 angles at 5°), finer but slower when nothing fits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OrbitSearch {
    /// First α tried, radians.
    pub start: f64,
    /// Smallest α tried, radians.
    pub min: f64,
    /// Largest α tried, radians.
    pub max: f64,
    /// First increment, radians (> 0).
    pub step: f64,
    /// Factor on the increment per iteration (≥ 1).
    pub growth: f64,
}

impl Default for OrbitSearch {
    fn default() -> OrbitSearch {
        OrbitSearch {
            start: 20f64.to_radians(),
            min: (-15f64).to_radians(),
            max: 130f64.to_radians(),
            step: 5f64.to_radians(),
            growth: 1.2,
        }
    }
}

impl OrbitSearch {
    /// Checks the settings: finite, `min ≤ start ≤ max`, `step > 0`, `growth ≥ 1`.
    pub fn validate(&self) -> Result<(), AnalyticError> {
        let fail =
            |field: &str, why: &str| Err(AnalyticError::Setting(InvalidSetting::new(field, why)));
        if ![self.start, self.min, self.max, self.step, self.growth]
            .iter()
            .all(|v| v.is_finite())
        {
            return fail("OrbitSearch", "every field finite");
        }
        if !(self.min <= self.start && self.start <= self.max) {
            return fail("OrbitSearch::start", "min ≤ start ≤ max");
        }
        if self.step <= 0.0 {
            return fail("OrbitSearch::step", "a positive angle");
        }
        if self.growth < 1.0 {
            return fail("OrbitSearch::growth", "at least 1");
        }
        Ok(())
    }

    /// The orbit angles the search tries, in order.
    pub fn alphas(&self) -> Result<OrbitAlphas, AnalyticError> {
        self.validate()?;
        Ok(OrbitAlphas {
            settings: *self,
            delta: self.step,
            increment: self.step,
            up: self.start < self.max,
            down: self.start > self.min,
            next_up: true,
            started: false,
        })
    }
}

/// The sequence of orbit angles of an [`OrbitSearch`].
#[derive(Debug, Clone)]
pub struct OrbitAlphas {
    settings: OrbitSearch,
    delta: f64,
    increment: f64,
    up: bool,
    down: bool,
    next_up: bool,
    started: bool,
}

impl Iterator for OrbitAlphas {
    type Item = f64;

    fn next(&mut self) -> Option<f64> {
        let s = &self.settings;
        if !self.started {
            self.started = true;
            return Some(s.start);
        }
        while self.up || self.down {
            if self.next_up {
                self.next_up = false;
                if self.up {
                    let a = (s.start + self.delta).min(s.max);
                    self.up = a < s.max;
                    return Some(a);
                }
            } else {
                self.next_up = true;
                let out = self.down.then(|| (s.start - self.delta).max(s.min));
                if let Some(a) = out {
                    self.down = a > s.min;
                }
                self.increment *= s.growth;
                self.delta += self.increment;
                if out.is_some() {
                    return out;
                }
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_search_visits_the_documented_angles() {
        let alphas: Vec<f64> = OrbitSearch::default()
            .alphas()
            .expect("valid")
            .map(f64::to_degrees)
            .collect();
        let expected = [
            20.0,
            25.0,
            15.0,
            31.0,
            9.0,
            38.2,
            1.8,
            46.84,
            -6.84,
            57.208,
            -15.0,
            69.6496,
            84.57952,
            102.495424,
            123.9945088,
            130.0,
        ];
        assert_eq!(alphas.len(), expected.len(), "{alphas:?}");
        for (a, e) in alphas.iter().zip(expected) {
            assert!((a - e).abs() < 1e-9, "{alphas:?}");
        }
    }

    #[test]
    fn invalid_search_settings_are_named() {
        let bad = OrbitSearch {
            step: 0.0,
            ..OrbitSearch::default()
        };
        assert!(matches!(
            bad.alphas(),
            Err(AnalyticError::Setting(e)) if e.field == "OrbitSearch::step"
        ));
    }
}
