//! [`Stats`]: the mean, min and max the experiment's tables and the held-out takes report.

use serde::Serialize;

/// Mean, min and max of a set of distances.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stats {
    /// The mean.
    pub mean: f64,
    /// The smallest.
    pub min: f64,
    /// The largest.
    pub max: f64,
    /// How many.
    pub count: usize,
}

impl Stats {
    /// The statistics of `values`, `None` when there are none.
    pub fn of(values: impl Iterator<Item = f64>) -> Option<Stats> {
        let v: Vec<f64> = values.collect();
        if v.is_empty() {
            return None;
        }
        Some(Stats {
            mean: v.iter().sum::<f64>() / v.len() as f64,
            min: v.iter().copied().fold(f64::INFINITY, f64::min),
            max: v.iter().copied().fold(f64::NEG_INFINITY, f64::max),
            count: v.len(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stats_are_mean_min_max_and_count() {
        assert_eq!(Stats::of(std::iter::empty()), None);
        let s = Stats::of([3.0, 1.0, 2.0].into_iter()).expect("stats");
        assert_eq!((s.mean, s.min, s.max, s.count), (2.0, 1.0, 3.0, 3), "{s:?}");
    }
}
