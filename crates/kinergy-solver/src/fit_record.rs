//! The record of a fit in a parameters file (its `fit` object): how the values were found,
//! what they scored, and on which captured reaches.
//!
//! ```json
//! "fit": {
//!   "method": "simulated_annealing",
//!   "score_m": 0.0484, "start_score_m": 0.0694,
//!   "evaluations": 4000, "iterations": 499, "status": "budget_spent",
//!   "seed": 15755400384260043838,
//!   "reaches": [ { "clip": "p01/r09.bvh", "frames": [7, 87], "distance_m": 0.0484 } ],
//!   "per": "clip",
//!   "nested": [ { "model": "sa", "score_m": 0.0984, "evaluations": 760 }, … ]
//! }
//! ```
//!
//! Fields added after the first version are `Option`s that are left out of the JSON when
//! absent, so files written before them still read and files without them are written as
//! before; the arm the values were fitted on (side, joint names, bone lengths) is meant to
//! join them that way. Keys the record does not know are ignored.

use std::ops::Range;

use serde::{Deserialize, Serialize};

use crate::synergy::Model;

/// How a parameters file's values were fitted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitRecord {
    /// The search: `simulated_annealing`.
    pub method: String,
    /// The values' mean motion distance over the reaches, meters.
    pub score_m: f64,
    /// The start vector's mean motion distance (the neutral vector, or the poorer model's
    /// solution in a nested fit), meters.
    pub start_score_m: f64,
    /// Cost evaluations spent (each synthesizes every reach once).
    pub evaluations: usize,
    /// Search iterations.
    pub iterations: usize,
    /// Why the search ended: `converged`, `budget_spent` or `interrupted`.
    pub status: String,
    /// The seed the search drew from.
    pub seed: u64,
    /// The captured reaches fitted, with the values' distance on each.
    pub reaches: Vec<FittedReach>,
    /// One vector per clip or per person (how the clips were grouped into fits).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub per: Option<FitGrouping>,
    /// Every model of a nested fit, poorest first (the last is the file's model).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub nested: Option<Vec<StageScore>>,
}

impl FitRecord {
    /// The reach fitted on the clip that `is_clip` recognizes by its name, if any.
    pub fn reach(&self, is_clip: impl Fn(&str) -> bool) -> Option<&FittedReach> {
        self.reaches.iter().find(|r| is_clip(&r.clip))
    }
}

/// One captured reach a fit scored.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FittedReach {
    /// The clip's name (its path as given to the fit).
    pub clip: String,
    /// The reach's frames `[start, end)` in the clip.
    pub frames: [usize; 2],
    /// The fitted values' motion distance on this reach, meters.
    pub distance_m: f64,
}

impl FittedReach {
    /// The reach's frames as a range.
    pub fn frames(&self) -> Range<usize> {
        self.frames[0]..self.frames[1]
    }
}

/// How clips were grouped into fits.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitGrouping {
    /// One vector per clip (the paper's experiment).
    Clip,
    /// One vector for all the clips (one person's).
    Person,
}

impl FitGrouping {
    /// `clip` or `person`.
    pub fn name(self) -> &'static str {
        match self {
            FitGrouping::Clip => "clip",
            FitGrouping::Person => "person",
        }
    }
}

/// One model's result in a nested fit.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StageScore {
    /// The model.
    pub model: Model,
    /// Its best mean motion distance, meters.
    pub score_m: f64,
    /// Evaluations it spent.
    pub evaluations: usize,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A record as `kinergy fit` wrote it before the record was typed.
    const WRITTEN: &str = r#"{
  "method": "simulated_annealing",
  "score_m": 0.048407695701244716,
  "start_score_m": 0.0693805048718952,
  "evaluations": 4000,
  "iterations": 499,
  "status": "budget_spent",
  "seed": 15755400384260043838,
  "reaches": [
    {
      "clip": "data-synthetic/p01/r09.bvh",
      "frames": [
        7,
        87
      ],
      "distance_m": 0.048407695701244716
    }
  ],
  "per": "clip",
  "nested": [
    {
      "model": "sa",
      "score_m": 0.09836106869320659,
      "evaluations": 760
    },
    {
      "model": "sc",
      "score_m": 0.048407695701244716,
      "evaluations": 4000
    }
  ]
}"#;

    #[test]
    fn reads_and_writes_the_records_written_before_it_was_typed() {
        let record: FitRecord = serde_json::from_str(WRITTEN).expect("record");
        assert_eq!(record.per, Some(FitGrouping::Clip));
        assert_eq!(record.reaches[0].frames(), 7..87);
        assert_eq!(
            record.reach(|c| c.ends_with("r09.bvh")),
            Some(&record.reaches[0])
        );
        assert_eq!(
            serde_json::to_string_pretty(&record).expect("json"),
            WRITTEN
        );
        // Without the optional parts, as the library writes it before grouping.
        let bare = FitRecord {
            per: None,
            nested: None,
            ..record
        };
        let text = serde_json::to_string(&bare).expect("json");
        assert!(
            !text.contains("\"per\"") && !text.contains("\"nested\""),
            "{text}"
        );
        assert_eq!(
            serde_json::from_str::<FitRecord>(&text).expect("back"),
            bare
        );
    }
}
