//! The kernel regression itself: the weights, Nadaraya–Watson and local-linear predictions,
//! the leave-one-out error and the choice of bandwidth.

use kinergy_motion::nalgebra::{Matrix3, Point3, Vector3};
use rayon::prelude::*;

use super::param_field::BandwidthChoice;
use super::settings::{AUTO_FACTORS, BandwidthScore, FALLBACK_BANDWIDTH, Regression};

/// Eigenvalues of the local-linear slope matrix below this fraction of the largest count as
/// zero (no slope along their direction).
const MIN_EIGENVALUE_RATIO: f64 = 1e-12;

/// The samples and bounds the regression works on.
pub(super) struct Data<'a> {
    pub(super) targets: &'a [Point3<f64>],
    pub(super) values: &'a [Vec<f64>],
    pub(super) lower: &'a [f64],
    pub(super) upper: &'a [f64],
}

impl Data<'_> {
    /// The value at `at` from every sample but `skip`.
    pub(super) fn predict(
        &self,
        h: f64,
        regression: Regression,
        at: &Point3<f64>,
        skip: Option<usize>,
    ) -> Vec<f64> {
        let used: Vec<usize> = (0..self.targets.len())
            .filter(|&k| Some(k) != skip)
            .collect();
        if used.len() == 1 {
            return self.values[used[0]].clone();
        }
        if !at.iter().all(|c| c.is_finite()) {
            let w = vec![1.0; used.len()];
            return self.weighted_mean(&used, &w);
        }
        let w = self.weights(h, at, &used);
        let nw = self.weighted_mean(&used, &w);
        match regression {
            Regression::NadarayaWatson => nw,
            Regression::LocalLinear { ridge } => self.local_linear(h, ridge, at, &used, &w, nw),
        }
    }

    /// Kernel weights of the `used` samples, the largest exactly 1.
    fn weights(&self, h: f64, at: &Point3<f64>, used: &[usize]) -> Vec<f64> {
        let logs: Vec<f64> = used
            .iter()
            .map(|&k| {
                let r = (at - self.targets[k]).norm() / h;
                -0.5 * r * r
            })
            .collect();
        let max = logs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        if max.is_finite() {
            return logs.iter().map(|l| (l - max).exp()).collect();
        }
        // Every distance overflowed: the nearest sample, compared at a scale that cannot.
        let scale = used
            .iter()
            .map(|&k| (at - self.targets[k]).amax())
            .fold(0.0, f64::max);
        let scaled: Vec<f64> = used
            .iter()
            .map(|&k| ((at - self.targets[k]) / scale).norm_squared())
            .collect();
        let nearest = (0..used.len())
            .min_by(|&a, &b| scaled[a].total_cmp(&scaled[b]))
            .unwrap_or(0);
        (0..used.len())
            .map(|i| if i == nearest { 1.0 } else { 0.0 })
            .collect()
    }

    /// Σ w_k p_k / Σ w_k, clamped to the range of the `used` samples' values.
    fn weighted_mean(&self, used: &[usize], w: &[f64]) -> Vec<f64> {
        let dim = self.lower.len();
        let total: f64 = w.iter().sum();
        (0..dim)
            .map(|i| {
                let mut sum = 0.0;
                let mut lo = f64::INFINITY;
                let mut hi = f64::NEG_INFINITY;
                for (&k, &wk) in used.iter().zip(w) {
                    let v = self.values[k][i];
                    sum += wk * v;
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
                (sum / total).clamp(lo, hi)
            })
            .collect()
    }

    /// The local-linear value: `nw` (the weighted mean, also the weighted mean of the plane
    /// fitted around the weighted mean target t̄) carried along the ridge-regularized slopes
    /// from t̄ to `at`, clamped into the bounds.
    fn local_linear(
        &self,
        h: f64,
        ridge: f64,
        at: &Point3<f64>,
        used: &[usize],
        w: &[f64],
        nw: Vec<f64>,
    ) -> Vec<f64> {
        let total: f64 = w.iter().sum();
        // Only the samples that carry weight (far ones may have underflowed to exactly 0).
        let kept: Vec<(usize, f64)> = used
            .iter()
            .zip(w)
            .filter(|&(_, &wk)| wk > 0.0)
            .map(|(&k, &wk)| (k, wk / total))
            .collect();
        let mean = kept.iter().fold(Vector3::zeros(), |acc, &(k, wk)| {
            acc + wk * self.targets[k].coords
        });
        let v = |k: usize| (self.targets[k].coords - mean) / h;
        // S = Σ ŵ v vᵀ + λI, inverted on its numerically nonzero eigenvalues: with λ = 0 and
        // targets on a plane or a line, no slope across them (the λ → 0 limit).
        let mut s = Matrix3::<f64>::identity() * ridge;
        for &(k, wk) in &kept {
            let vk = v(k);
            s += wk * vk * vk.transpose();
        }
        let eigen = s.symmetric_eigen();
        let largest = eigen.eigenvalues.amax();
        let inverse_values = eigen.eigenvalues.map(|e| {
            if largest > 0.0 && e > MIN_EIGENVALUE_RATIO * largest {
                1.0 / e
            } else {
                0.0
            }
        });
        let s_plus = eigen.eigenvectors
            * Matrix3::from_diagonal(&inverse_values)
            * eigen.eigenvectors.transpose();
        // p_i(at) = nw_i + b_iᵀ (at − t̄)/h with b_i = S⁺ Σ ŵ_k v_k (p_k,i − nw_i);
        // equivalently, the direction d = S⁺ (at − t̄)/h and p_i = nw_i + Σ ŵ_k (d·v_k)(p_k,i − nw_i).
        let d = s_plus * ((at.coords - mean) / h);
        let mut out = nw.clone();
        for &(k, wk) in &kept {
            let c = wk * d.dot(&v(k));
            for ((o, p), n) in out.iter_mut().zip(&self.values[k]).zip(&nw) {
                *o += c * (p - n);
            }
        }
        if !out.iter().all(|x| x.is_finite()) {
            return nw;
        }
        for ((o, lo), hi) in out.iter_mut().zip(self.lower).zip(self.upper) {
            *o = o.clamp(*lo, *hi);
        }
        out
    }

    /// The median distance from each target to its nearest distinct target; `None` when no
    /// two targets differ.
    fn median_nearest_distance(&self) -> Option<f64> {
        let mut nearest: Vec<f64> = self
            .targets
            .iter()
            .filter_map(|a| {
                self.targets
                    .iter()
                    .map(|b| (a - b).norm())
                    .filter(|&d| d > 0.0)
                    .min_by(f64::total_cmp)
            })
            .collect();
        if nearest.is_empty() {
            return None;
        }
        nearest.sort_by(f64::total_cmp);
        let n = nearest.len();
        Some(if n % 2 == 1 {
            nearest[n / 2]
        } else {
            0.5 * (nearest[n / 2 - 1] + nearest[n / 2])
        })
    }

    /// Root mean square leave-one-out error with bandwidth `h`, per entry relative to its
    /// bound width.
    fn loo_error(&self, h: f64, regression: Regression) -> f64 {
        let widths: Vec<f64> = self
            .lower
            .iter()
            .zip(self.upper)
            .map(|(lo, hi)| hi - lo)
            .collect();
        let mut sum = 0.0;
        let mut count = 0usize;
        for (j, (t, p)) in self.targets.iter().zip(self.values).enumerate() {
            let pred = self.predict(h, regression, t, Some(j));
            for ((q, v), wd) in pred.iter().zip(p).zip(&widths) {
                if *wd > 0.0 {
                    let e = (q - v) / wd;
                    sum += e * e;
                    count += 1;
                }
            }
        }
        if count == 0 {
            0.0
        } else {
            (sum / count as f64).sqrt()
        }
    }

    /// [`Bandwidth::Auto`]: the chosen h and every candidate's score; with `flat`, h = ∞ is
    /// a candidate too (an anchored field).
    pub(super) fn select(&self, regression: Regression, flat: bool) -> BandwidthChoice {
        let Some(d) = self.median_nearest_distance() else {
            return BandwidthChoice {
                bandwidth: FALLBACK_BANDWIDTH,
                selection: Vec::new(),
            };
        };
        let mut scores: Vec<BandwidthScore> = AUTO_FACTORS
            .par_iter()
            .map(|f| {
                let bandwidth = f * d;
                BandwidthScore {
                    bandwidth,
                    loo_error: self.loo_error(bandwidth, regression),
                    loo_distance_m: None,
                }
            })
            .collect();
        if flat {
            scores.push(BandwidthScore {
                bandwidth: f64::INFINITY,
                loo_error: self.loo_error(f64::INFINITY, regression),
                loo_distance_m: None,
            });
        }
        // Largest h first, strict improvement only: ties go to the smoother field.
        let best = scores
            .iter()
            .rev()
            .fold(None::<&BandwidthScore>, |best, s| match best {
                Some(b) if b.loo_error.total_cmp(&s.loo_error).is_le() => Some(b),
                _ => Some(s),
            })
            .map_or(FALLBACK_BANDWIDTH, |s| s.bandwidth);
        BandwidthChoice {
            bandwidth: best,
            selection: scores,
        }
    }
}
