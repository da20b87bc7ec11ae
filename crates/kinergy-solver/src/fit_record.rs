//! The record of a fit in a parameters file (its `fit` object): how the values were found,
//! what they scored, and on which captured reaches.
//!
//! ```json
//! "fit": {
//!   "method": "simulated_annealing",
//!   "score_m": 0.0484, "start_score_m": 0.0694,
//!   "evaluations": 4000, "iterations": 499, "status": "budget_spent",
//!   "seed": 15755400384260043838,
//!   "reaches": [ { "clip": "p01/r09.bvh", "frames": [7, 87], "distance_m": 0.0484,
//!                  "arm": { "side": "left", "joints": ["LeftShoulder", "LeftArm", "LeftForeArm",
//!                           "LeftHand", "LeftHandEnd"],
//!                           "upper_arm_m": 0.28, "forearm_m": 0.26, "hand_m": 0.09 } } ],
//!   "per": "clip",
//!   "nested": [ { "model": "sa", "score_m": 0.0984, "evaluations": 760 }, … ]
//! }
//! ```
//!
//! Fields added after the first version are `Option`s that are left out of the JSON when
//! absent, so files written before them still read and files without them are written as
//! before; the arm each reach was fitted on (side, joint names, bone lengths: [`FittedArm`])
//! is one of them. Keys the record does not know are ignored.

use std::fmt;
use std::ops::Range;

use serde::{Deserialize, Serialize};

use kinergy_motion::Side;

use crate::synergy::Model;

mod tempo;

pub use tempo::{PersonTempo, ReachTempo};

/// How a parameters file's values were fitted.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FitRecord {
    /// The search: `simulated_annealing`, or `simulated_annealing+nelder_mead+levenberg_marquardt` when a
    /// local refinement followed (`kinergy fit --refine`); `parameter_field` for a vector a field file
    /// predicted for a target (then the scores, the reaches and their distances are those of
    /// the per-reach fits the field was made of; the predicted vector itself was not scored).
    pub method: FitMethod,
    /// The values' mean motion distance over the reaches, meters.
    pub score_m: f64,
    /// The start vector's mean motion distance (the neutral vector, or the poorer model's
    /// solution in a nested fit), meters.
    pub start_score_m: f64,
    /// Cost evaluations spent (each synthesizes every reach once).
    pub evaluations: usize,
    /// Search iterations.
    pub iterations: usize,
    /// Why the search ended: `converged`, `budget_spent` or `interrupted` (`predicted` for a
    /// field's prediction).
    pub status: FitStatus,
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
    /// What the fit minimized when not the paper's joint-position distance alone (absent:
    /// the distance). With [`FitObjective::PositionsSpeed`] every score and distance of the
    /// record is that objective's value, meters.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub objective: Option<FitObjective>,
    /// The DoFs no fitted reach could see ([`FitRecord::unobserved_dofs`]): on every reach's
    /// arm they cannot move the hand (captures without a hand bone: the forearm's twist and
    /// the wrist). Nothing in the captures decides their parameters — they are where the
    /// search wandered — yet on an arm with a hand (the full-body character's) they move it.
    /// Absent: every DoF was seen.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unobserved: Option<Vec<String>>,
    /// The person's tempo law the fit ran its reaches under ([`PersonTempo`]), what every
    /// synthesis in their style runs under. Absent in files written before it ([`FitRecord::tempo`]
    /// says what they mean).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tempo_law: Option<PersonTempo>,
    /// The synergy controller the fit ran its reaches under, what a replay of the values runs
    /// by default ([`FitRecord::controller`]). Absent in files written before it was
    /// recorded (they were fitted under the smooth controller, or say nothing).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub controller: Option<ControllerKind>,
    /// The result whose vector this fit's search started from, as its library names it: a
    /// library's warm start (`kinergy fit --warm-start`), the first reach of the same
    /// person, motion and arm. Absent for a fit from the neutral vector or from a poorer
    /// model's solution.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub started_from: Option<String>,
}

/// What a fit minimizes (`kinergy fit --objective`).
///
/// `positions` — the paper's mean joint-position distance between the synthesized and the
/// captured arm, meters. `positions+speed` — that distance plus `speed_weight_s` times the
/// root-mean-square difference of the hand's speed (world, central differences, over the
/// captured frames), m/s × s = meters: a weight of 0.05 s charges 0.1 m/s of speed error as
/// 5 mm of distance.
#[derive(Debug, Clone, Copy, PartialEq, Default, Serialize, Deserialize)]
#[serde(tag = "kind", deny_unknown_fields)]
pub enum FitObjective {
    /// The joint-position distance alone (the paper's metric).
    #[default]
    #[serde(rename = "positions")]
    Positions,
    /// The distance plus the weighted hand-speed error.
    #[serde(rename = "positions+speed")]
    PositionsSpeed {
        /// Seconds: meters of distance per m/s of RMS hand-speed error.
        speed_weight_s: f64,
    },
}

impl FitObjective {
    /// The speed weight by default (`--speed-weight`), seconds: 0.1 m/s of RMS speed error
    /// costs as much as 5 mm of mean joint distance.
    pub const DEFAULT_SPEED_WEIGHT: f64 = 0.05;

    /// The weight of the hand-speed term, seconds (0 for [`FitObjective::Positions`]).
    pub fn speed_weight(self) -> f64 {
        match self {
            FitObjective::Positions => 0.0,
            FitObjective::PositionsSpeed { speed_weight_s } => speed_weight_s,
        }
    }

    /// The record's `objective`: `None` for the paper's metric (files as before).
    pub fn recorded(self) -> Option<FitObjective> {
        (self != FitObjective::Positions).then_some(self)
    }

    /// `positions` or `positions+speed`.
    pub fn name(self) -> &'static str {
        match self {
            FitObjective::Positions => "positions",
            FitObjective::PositionsSpeed { .. } => "positions+speed",
        }
    }
}

impl FitRecord {
    /// Checks what a damaged or hand-edited record could get wrong and the values' use
    /// depends on: every reach's frames `[start, end)` with start < end (a reach has frames),
    /// every distance and score finite and ≥ 0, every recorded bone finite and > 0 (the hand
    /// ≥ 0). Returns the first field that is wrong (`fit.reaches[2].frames`) and why.
    pub fn check(&self) -> Result<(), (String, String)> {
        let distance = |field: String, v: f64| {
            if v.is_finite() && v >= 0.0 {
                Ok(())
            } else {
                Err((field, format!("is {v}: expected a finite distance ≥ 0")))
            }
        };
        distance("fit.score_m".into(), self.score_m)?;
        distance("fit.start_score_m".into(), self.start_score_m)?;
        for (i, reach) in self.reaches.iter().enumerate() {
            let [start, end] = reach.frames;
            if start >= end {
                return Err((
                    format!("fit.reaches[{i}].frames"),
                    format!("is [{start}, {end}]: expected [start, end) with start < end"),
                ));
            }
            distance(format!("fit.reaches[{i}].distance_m"), reach.distance_m)?;
            if let Some(arm) = &reach.arm {
                arm.check()
                    .map_err(|(name, why)| (format!("fit.reaches[{i}].arm.{name}"), why))?;
            }
        }
        for (i, stage) in self.nested.iter().flatten().enumerate() {
            distance(format!("fit.nested[{i}].score_m"), stage.score_m)?;
        }
        if let Some(law) = &self.tempo_law {
            law.check()
                .map_err(|(name, why)| (format!("fit.tempo_law.{name}"), why))?;
        }
        Ok(())
    }

    /// The controller the values were fitted under: the recorded one, else (files written
    /// before it was recorded) the smooth controller, the only one there was by default.
    pub fn controller(&self) -> ControllerKind {
        self.controller.unwrap_or_default()
    }

    /// The reach fitted on the clip that `is_clip` recognizes by its name, if any.
    pub fn reach(&self, is_clip: impl Fn(&str) -> bool) -> Option<&FittedReach> {
        self.reaches.iter().find(|r| is_clip(&r.clip))
    }

    /// The arm the values were fitted on: that of the reach on the clip `is_clip` recognizes,
    /// else the first reach's that records one; `None` in files written before arms were
    /// recorded.
    pub fn arm(&self, is_clip: impl Fn(&str) -> bool) -> Option<&FittedArm> {
        self.reaches
            .iter()
            .find(|r| is_clip(&r.clip) && r.arm.is_some())
            .or_else(|| self.reaches.iter().find(|r| r.arm.is_some()))
            .and_then(|r| r.arm.as_ref())
    }
}

/// Which synergy controller synthesizes a reach, and which one a fit ran its reaches under
/// (the record's `controller`: what every replay of the values runs unless told otherwise).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ControllerKind {
    /// Bounded accelerations, a progress floor, the finish to the plain optimizer after the
    /// reach's frames and the capture's start velocity (`smooth`, the default).
    #[default]
    Smooth,
    /// Aubry et al.'s Θ ← clamp(Θ + S(t)·O(ΔX)) alone, from rest (`paper`).
    Paper,
}

impl ControllerKind {
    /// Both, in the order the front ends list them.
    pub const ALL: [ControllerKind; 2] = [ControllerKind::Smooth, ControllerKind::Paper];

    /// `smooth` or `paper`.
    pub fn name(self) -> &'static str {
        match self {
            ControllerKind::Smooth => "smooth",
            ControllerKind::Paper => "paper",
        }
    }
}

impl fmt::Display for ControllerKind {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for ControllerKind {
    type Err = kinergy_io::InvalidSetting;
    fn from_str(s: &str) -> Result<ControllerKind, kinergy_io::InvalidSetting> {
        ControllerKind::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| {
                kinergy_io::InvalidSetting::new(
                    "controller",
                    format!("`{s}`: expected smooth or paper"),
                )
            })
    }
}

/// How a fit record's values were found: its `method`, written as the strings the files have
/// always held.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum FitMethod {
    /// Simulated annealing alone: `simulated_annealing`.
    #[serde(rename = "simulated_annealing")]
    SimulatedAnnealing,
    /// Simulated annealing, then Nelder–Mead and Levenberg–Marquardt from its vector
    /// (`kinergy fit --refine`): `simulated_annealing+nelder_mead+levenberg_marquardt`.
    #[serde(rename = "simulated_annealing+nelder_mead+levenberg_marquardt")]
    RefinedAnnealing,
    /// Predicted for a target by a parameter field: `parameter_field`.
    #[serde(rename = "parameter_field")]
    ParameterField,
}

impl FitMethod {
    /// The name the record's JSON holds.
    pub fn name(self) -> &'static str {
        match self {
            FitMethod::SimulatedAnnealing => "simulated_annealing",
            FitMethod::RefinedAnnealing => "simulated_annealing+nelder_mead+levenberg_marquardt",
            FitMethod::ParameterField => "parameter_field",
        }
    }
}

impl fmt::Display for FitMethod {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a fit's search ended: its `status`, written as the strings the files have always held.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitStatus {
    /// Still running (`running`): a search stopped before its first stop rule applied.
    Running,
    /// The stop rule was met (`converged`).
    Converged,
    /// The evaluation budget is spent (`budget_spent`).
    BudgetSpent,
    /// Stopped from outside (`interrupted`).
    Interrupted,
    /// Not searched: predicted for a target by a parameter field (`predicted`).
    Predicted,
}

impl FitStatus {
    /// The name the record's JSON holds.
    pub fn name(self) -> &'static str {
        match self {
            FitStatus::Running => "running",
            FitStatus::Converged => "converged",
            FitStatus::BudgetSpent => "budget_spent",
            FitStatus::Interrupted => "interrupted",
            FitStatus::Predicted => "predicted",
        }
    }
}

impl fmt::Display for FitStatus {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
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
    /// The arm the reach was captured with (absent in files written before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm: Option<FittedArm>,
    /// How fast the captured hand moved (absent in files written before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tempo: Option<ReachTempo>,
}

impl FitRecord {
    /// The DoFs (indices into [`kinergy_motion::Chain::arm`]'s, the order of a fitted arm's
    /// `dof_names`) that no reach of this record could see: on every reach's arm
    /// ([`FittedArm::unobserved_dofs`]) they cannot move the hand. Empty when a reach does
    /// not record its arm (it may have seen them).
    pub fn unobserved_dofs(&self) -> Vec<usize> {
        let mut hidden: Option<Vec<usize>> = None;
        for reach in &self.reaches {
            let Some(arm) = &reach.arm else {
                return Vec::new();
            };
            let here = arm.unobserved_dofs();
            hidden = Some(match hidden {
                None => here,
                Some(h) => h.into_iter().filter(|d| here.contains(d)).collect(),
            });
        }
        hidden.unwrap_or_default()
    }

    /// Whether every reach of this record was fitted on an arm that ends at its wrist
    /// (`hand_m` 0: captures without a hand bone, Bandai Namco's). Such a synergy never saw a
    /// hand: what it drives on a capture is driven to the wrist too, whatever hand that body
    /// has ([`crate::PersonStyle::arm_as_fitted`]). False when a reach does not record its arm.
    pub fn ends_at_wrist(&self) -> bool {
        !self.reaches.is_empty()
            && self
                .reaches
                .iter()
                .all(|r| r.arm.as_ref().is_some_and(|a| a.hand_m == 0.0))
    }

    /// The person's tempo: the law the fit recorded (`tempo_law`), else (files written before
    /// it) the medians of the reaches that record their tempo with the duration proportional
    /// to the distance ([`PersonTempo`]); `None` when neither is there.
    pub fn tempo(&self) -> Option<PersonTempo> {
        if let Some(law) = self.tempo_law {
            return Some(law);
        }
        let reaches: Vec<ReachTempo> = self.reaches.iter().filter_map(|r| r.tempo).collect();
        let law = PersonTempo::of(&reaches)?;
        // The old rule: T = d ÷ (median travel ÷ duration), V = median shape × d ÷ T.
        let usable: Vec<&ReachTempo> = reaches.iter().filter(|t| t.is_usable()).collect();
        let mean_speed = kinergy_motion::jumps::median(
            &usable
                .iter()
                .map(|t| t.travel_m / t.duration_s)
                .collect::<Vec<_>>(),
        );
        Some(PersonTempo {
            reference_m: 1.0,
            duration_s: 1.0 / mean_speed,
            exponent: 1.0,
            shape: law.shape,
            arm_m: None,
        })
    }
}

/// The captured arm a reach was fitted on: which side, its joints, its bones.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct FittedArm {
    /// Right or left (absent when the joints were named by hand and their side is unclear).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub side: Option<Side>,
    /// The chain's joint names in the capture, clavicle (if any) to hand point (if any).
    pub joints: Vec<String>,
    /// Shoulder to elbow on the reach's first frame, meters.
    pub upper_arm_m: f64,
    /// Elbow to wrist, meters.
    pub forearm_m: f64,
    /// Wrist to the hand point, meters (0 when the wrist has none).
    pub hand_m: f64,
}

impl FittedArm {
    /// The DoFs of this arm's chain ([`kinergy_motion::Chain::arm`] of its bones) that cannot
    /// move its hand point in any posture: their Jacobian column is zero (below 1e-9 m/rad)
    /// at each of a few generic postures. On an arm without a hand bone (`hand_m` 0, the
    /// hand point at the wrist) these are the forearm's twist and the wrist's two swings: a
    /// fit of such captures cannot tell their parameters. Empty when the bones are not valid.
    pub fn unobserved_dofs(&self) -> Vec<usize> {
        const ZERO: f64 = 1e-9;
        let Ok(chain) = kinergy_motion::Chain::arm(self.upper_arm_m, self.forearm_m, self.hand_m)
        else {
            return Vec::new();
        };
        let n = chain.dof_count();
        let base = kinergy_motion::nalgebra::IsometryMatrix3::identity();
        let mut lin = kinergy_motion::Linearization::default();
        let mut seen = vec![false; n];
        // Postures of a few tenths of a radian on every DoF, different for each: no two
        // axes line up by chance (a straight elbow would hide the shoulder's twist).
        for k in 0..3 {
            let q: Vec<f64> = (0..n)
                .map(|i| 0.3 + 0.2 * (1.3 * i as f64 + 2.1 * k as f64).sin())
                .collect();
            if chain.linearize_into(&base, &q, &mut lin).is_err() {
                return Vec::new();
            }
            for (i, s) in seen.iter_mut().enumerate() {
                *s |= lin.linear.column(i).norm() > ZERO;
            }
        }
        (0..n).filter(|&i| !seen[i]).collect()
    }

    /// Checks the bones: upper arm and forearm finite and > 0, the hand finite and ≥ 0.
    /// Returns the first that is wrong (`upper_arm_m`) and why.
    pub fn check(&self) -> Result<(), (String, String)> {
        for (name, v, min) in [
            ("upper_arm_m", self.upper_arm_m, f64::MIN_POSITIVE),
            ("forearm_m", self.forearm_m, f64::MIN_POSITIVE),
            ("hand_m", self.hand_m, 0.0),
        ] {
            if !(v.is_finite() && v >= min) {
                return Err((
                    name.to_string(),
                    format!(
                        "is {v}: expected a finite length{}",
                        if min > 0.0 { " > 0" } else { " ≥ 0" }
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The largest relative difference between this arm's bones and `other`'s (upper arm,
    /// forearm, and the hand when both have one), e.g. 0.12 for 12 %.
    pub fn length_difference(&self, other: &FittedArm) -> f64 {
        let rel = |a: f64, b: f64| {
            if a.max(b) > 0.0 {
                (a - b).abs() / a.max(b)
            } else {
                0.0
            }
        };
        let mut d =
            rel(self.upper_arm_m, other.upper_arm_m).max(rel(self.forearm_m, other.forearm_m));
        if self.hand_m > 0.0 && other.hand_m > 0.0 {
            d = d.max(rel(self.hand_m, other.hand_m));
        }
        d
    }
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

impl std::str::FromStr for FitGrouping {
    type Err = kinergy_io::InvalidSetting;
    /// `clip` or `person`.
    fn from_str(s: &str) -> Result<FitGrouping, Self::Err> {
        [FitGrouping::Clip, FitGrouping::Person]
            .into_iter()
            .find(|g| g.name() == s)
            .ok_or_else(|| {
                kinergy_io::InvalidSetting::new("per", format!("`{s}`: expected clip or person"))
            })
    }
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
            objective: None,
            unobserved: None,
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

    #[test]
    fn the_controller_is_recorded_by_name_and_smooth_where_it_is_not() {
        let before: FitRecord = serde_json::from_str(WRITTEN).expect("record");
        assert_eq!(before.controller, None);
        assert_eq!(before.controller(), ControllerKind::Smooth);
        let paper = FitRecord {
            controller: Some(ControllerKind::Paper),
            ..before
        };
        let text = serde_json::to_string(&paper).expect("json");
        assert!(text.contains(r#""controller":"paper""#), "{text}");
        let back: FitRecord = serde_json::from_str(&text).expect("back");
        assert_eq!(back.controller(), ControllerKind::Paper);
        for c in ControllerKind::ALL {
            assert_eq!(c.name().parse::<ControllerKind>(), Ok(c));
        }
        let e = "fast".parse::<ControllerKind>().unwrap_err();
        assert_eq!(e.field, "controller");
        assert!(
            e.to_string().contains("`fast`: expected smooth or paper"),
            "{e}"
        );
    }

    #[test]
    fn methods_and_statuses_are_written_as_before() {
        for m in [
            FitMethod::SimulatedAnnealing,
            FitMethod::RefinedAnnealing,
            FitMethod::ParameterField,
        ] {
            let text = serde_json::to_string(&m).expect("json");
            assert_eq!(text, format!("\"{m}\""));
            assert_eq!(serde_json::from_str::<FitMethod>(&text).expect("back"), m);
        }
        for s in [
            FitStatus::Running,
            FitStatus::Converged,
            FitStatus::BudgetSpent,
            FitStatus::Interrupted,
            FitStatus::Predicted,
        ] {
            let text = serde_json::to_string(&s).expect("json");
            assert_eq!(text, format!("\"{s}\""));
            assert_eq!(serde_json::from_str::<FitStatus>(&text).expect("back"), s);
        }
        assert_eq!(
            FitMethod::RefinedAnnealing.name(),
            "simulated_annealing+nelder_mead+levenberg_marquardt"
        );
        assert_eq!(FitStatus::BudgetSpent.name(), "budget_spent");
        let record: FitRecord = serde_json::from_str(WRITTEN).expect("record");
        assert_eq!(
            (record.method, record.status),
            (FitMethod::SimulatedAnnealing, FitStatus::BudgetSpent)
        );
    }

    #[test]
    fn arms_are_recorded_per_reach_and_compared_by_bone() {
        let mut record: FitRecord = serde_json::from_str(WRITTEN).expect("record");
        assert_eq!(record.arm(|_| true), None);
        let arm = FittedArm {
            side: Some(Side::Left),
            joints: vec!["LeftArm".into(), "LeftForeArm".into(), "LeftHand".into()],
            upper_arm_m: 0.30,
            forearm_m: 0.25,
            hand_m: 0.0,
        };
        record.reaches[0].arm = Some(arm.clone());
        let text = serde_json::to_string(&record).expect("json");
        let back: FitRecord = serde_json::from_str(&text).expect("back");
        assert_eq!(back.arm(|c| c.ends_with("other.bvh")), Some(&arm));
        let longer = FittedArm {
            upper_arm_m: 0.36,
            hand_m: 0.08,
            ..arm.clone()
        };
        approx::assert_relative_eq!(arm.length_difference(&longer), 0.06 / 0.36);
    }

    /// An arm without a hand bone cannot move its hand point with the forearm's twist or the
    /// wrist (their columns vanish: the point lies on the twist's axis and at the wrist);
    /// with a hand every DoF moves it. A record's unobserved DoFs are those of every reach.
    #[test]
    fn an_arm_without_a_hand_cannot_see_its_forearm_twist_and_wrist() {
        let arm = |hand_m: f64| FittedArm {
            side: Some(Side::Left),
            joints: vec!["LeftArm".into(), "LeftForeArm".into(), "LeftHand".into()],
            upper_arm_m: 0.30,
            forearm_m: 0.25,
            hand_m,
        };
        assert_eq!(arm(0.0).unobserved_dofs(), vec![4, 5, 6]);
        assert_eq!(arm(0.08).unobserved_dofs(), Vec::<usize>::new());
        let chain = kinergy_motion::Chain::arm(0.3, 0.25, 0.0).expect("arm");
        let names: Vec<&str> = chain.dof_names().collect();
        assert_eq!(
            [names[4], names[5], names[6]],
            ["elbow_twist", "wrist_swing_x", "wrist_swing_y"]
        );
        // The columns the test reads as zero are zero to rounding, the others far from it.
        let mut lin = kinergy_motion::Linearization::default();
        let q = [0.4, -0.3, 0.7, 1.1, 0.5, 0.2, -0.1];
        chain
            .linearize_into(
                &kinergy_motion::nalgebra::IsometryMatrix3::identity(),
                &q,
                &mut lin,
            )
            .expect("linearize");
        for i in 0..7 {
            let norm = lin.linear.column(i).norm();
            assert!(
                if i >= 4 { norm < 1e-12 } else { norm > 0.05 },
                "DoF {i}: {norm}"
            );
        }

        let mut record: FitRecord = serde_json::from_str(WRITTEN).expect("record");
        assert_eq!(
            record.unobserved_dofs(),
            Vec::<usize>::new(),
            "no arm recorded"
        );
        for reach in &mut record.reaches {
            reach.arm = Some(arm(0.0));
        }
        assert_eq!(record.unobserved_dofs(), vec![4, 5, 6]);
        // Every reach at the wrist: the person's arm ends there, and a capture's arm with a
        // hand point is driven without it (`PersonStyle::arm_as_fitted`).
        assert!(record.ends_at_wrist());
        let dofs = vec!["elbow".to_string()];
        let space = crate::ParamSpace::new(crate::Model::Sa, &dofs, crate::Bounds::default())
            .expect("space");
        let mut file = crate::ParamsFile::new(
            &space,
            crate::OptimizerKind::Svd.default_optimizer(),
            &[1.5],
        )
        .expect("parameters file");
        let with_hand = kinergy_motion::ArmJoints {
            side: Some(kinergy_motion::Side::Left),
            clavicle: Some(0),
            shoulder: 1,
            elbow: 2,
            wrist: 3,
            hand: Some(4),
        };
        use crate::PersonStyle;
        assert_eq!(
            file.arm_as_fitted(&with_hand),
            with_hand,
            "no record: as given"
        );
        file.fit = Some(record.clone());
        let driven = file.arm_as_fitted(&with_hand);
        assert_eq!(driven.hand, None);
        assert_eq!((driven.shoulder, driven.wrist), (1, 3));
        record.reaches[0].arm = Some(arm(0.08));
        assert_eq!(
            record.unobserved_dofs(),
            Vec::<usize>::new(),
            "one reach saw them"
        );
        assert!(!record.ends_at_wrist(), "one reach had a hand");
        file.fit = Some(record.clone());
        assert_eq!(file.arm_as_fitted(&with_hand), with_hand);
        record.reaches[0].arm = None;
        assert!(
            !record.ends_at_wrist(),
            "a reach without its arm may have had a hand"
        );
    }

    /// The law read in arm lengths: a body `k` times the fitted arm, reaching `k` times as far,
    /// takes as long and peaks `k` times as fast (the law's exponent whatever it is); on the
    /// fitted arm, or a law without its arm, it is the law in meters.
    #[test]
    fn a_law_read_in_arm_lengths_scales_with_the_body() {
        let reach = |d: f64, t: f64| ReachTempo {
            peak_speed_m_s: 1.875 * d / t,
            duration_s: t,
            travel_m: d,
        };
        let law =
            PersonTempo::of(&[reach(0.2, 0.5), reach(0.4, 0.7), reach(0.6, 0.85)]).expect("law");
        assert!(law.exponent > 0.0 && law.exponent < 1.0, "{law:?}");
        let fitted = law.with_arm(0.55);
        assert_eq!(fitted.check(), Ok(()));
        for d in [0.15, 0.3, 0.5] {
            assert_eq!(fitted.for_reach_by(d, 0.55), law.for_distance(d));
            assert_eq!(
                law.for_reach_by(d, 0.8),
                law.for_distance(d),
                "no arm recorded"
            );
            for k in [0.8, 1.13, 1.5] {
                let (peak, duration) = fitted.for_reach_by(k * d, k * 0.55);
                let (peak_own, duration_own) = law.for_distance(d);
                approx::assert_relative_eq!(duration, duration_own, max_relative = 1e-12);
                approx::assert_relative_eq!(peak, k * peak_own, max_relative = 1e-12);
            }
        }
        assert_eq!(law.with_arm(f64::NAN).arm_m, None);
    }

    /// A law's check names the field a damaged file got wrong, and a good law passes: the
    /// law of reaches whose duration is proportional to the distance has that exponent.
    #[test]
    fn a_damaged_tempo_law_is_named_and_a_made_one_passes() {
        let reach = |d: f64| ReachTempo {
            peak_speed_m_s: 1.875 * d / (2.0 * d),
            duration_s: 2.0 * d,
            travel_m: d,
        };
        let law = PersonTempo::of(&[reach(0.2), reach(0.4), reach(0.6)]).expect("law");
        assert_eq!(law.check(), Ok(()));
        approx::assert_relative_eq!(law.exponent, 1.0, epsilon = 1e-12);
        let (peak, duration) = law.for_distance(0.5);
        approx::assert_relative_eq!(duration, 1.0, epsilon = 1e-12);
        approx::assert_relative_eq!(peak, 1.875 * 0.5, epsilon = 1e-12);
        for (bad, field) in [
            (
                PersonTempo {
                    reference_m: 0.0,
                    ..law
                },
                "reference_m",
            ),
            (
                PersonTempo {
                    duration_s: f64::NAN,
                    ..law
                },
                "duration_s",
            ),
            (PersonTempo { shape: -1.0, ..law }, "shape"),
            (
                PersonTempo {
                    arm_m: Some(0.0),
                    ..law
                },
                "arm_m",
            ),
            (
                PersonTempo {
                    exponent: 1.5,
                    ..law
                },
                "exponent",
            ),
        ] {
            assert_eq!(bad.check().map_err(|(f, _)| f), Err(field.to_string()));
            let record = FitRecord {
                tempo_law: Some(bad),
                ..serde_json::from_str::<FitRecord>(
                    r#"{"method": "simulated_annealing",
                    "score_m": 0.01, "start_score_m": 0.02, "evaluations": 1, "iterations": 1,
                    "status": "converged", "seed": 1, "reaches": []}"#,
                )
                .expect("record")
            };
            assert_eq!(
                record.check().map_err(|(f, _)| f),
                Err(format!("fit.tempo_law.{field}"))
            );
        }
    }
}
