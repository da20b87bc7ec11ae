//! A person's motions judged **in real time** against their own repeats: for each
//! of a person's captures, the hand speed relative to the shoulder over the capture's main
//! reach is compared, second by second, with what each predictor makes of it:
//!
//! - **the person's own repeats** (the noise ceiling): the capture predicted by the mean
//!   time-normalized profile of the person's *other* captures, played over their mean
//!   duration at their mean peak speed (leave-one-out, [`kinergy_motion::fidelity::mean_profile`]);
//!   what the person's own past says of this take;
//! - **minimum jerk** (the floor): a zero-style bell over the capture's own hand path length,
//!   lasting the other captures' mean duration (Flash & Hogan 1985);
//! - **the arm on the captured torso** (`synthesize --params`): the person's controller
//!   replayed on the capture's own torso from its start posture and velocity;
//! - **the full body** (`reach --params` / `style`): the character of the capture's
//!   proportions reaching the capture's target with the person's parameters;
//! - **the default profile** (`reach` without parameters).
//!
//! Each predictor's figures against the capture are a [`Fidelity`]: the real-time error e (RMS
//! over time of the speed difference ÷ the capture's peak speed, the shorter series padded with
//! zeros), the duration and peak-speed ratios, the time to peak, SPARC smoothness beside the
//! capture's, and a real-time jump check (no frame-to-frame change of the speed larger than the
//! capture's own largest). Per person ([`PersonFidelity`]) the means, and each predictor's mean
//! e over the ceiling's mean e: 1 is as close as the person is to themself.
//!
//! Every series starts at its motion's onset (the capture: its main reach's first frame; a
//! synthesis: its first frame; the full body: the frame the arm starts) and is the hand point's
//! speed relative to the shoulder by central differences ([`kinergy_motion::speed_series`]),
//! the same for all: the capture's hand point (its hand, or its wrist where the skeleton has no
//! hand) and the same point of the synthesized arm.

use kinergy_motion::fidelity::{
    Fidelity, Speeds, duration, mean_profile, minimum_jerk, movement_duration, path_length,
    peak_speed,
};
use kinergy_motion::nalgebra::Point3;
use serde::Serialize;

/// A speed series: one value per frame (m/s), and the seconds per frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Series {
    /// The speeds, m/s, one per frame from the motion's onset.
    pub values: Vec<f64>,
    /// Seconds per frame.
    pub frame_time: f64,
}

impl Series {
    /// The speeds of the hand relative to the shoulder along `relative` (the hand point minus
    /// the shoulder, one per frame), by central differences.
    pub fn of_relative(relative: &[Point3<f64>], frame_time: f64) -> Series {
        Series {
            values: kinergy_motion::speed_series(relative, frame_time),
            frame_time,
        }
    }

    /// A view for the measures.
    pub fn speeds(&self) -> Speeds<'_> {
        Speeds {
            values: &self.values,
            frame_time: self.frame_time,
        }
    }
}

/// What is known of one capture: its hand speed over the main reach and each predictor's
/// motion toward it (absent where it was not made).
#[derive(Debug, Clone, PartialEq)]
pub struct TakeMotions {
    /// The capture's name.
    pub name: String,
    /// The capture's hand speed over its main reach.
    pub capture: Series,
    /// The person's controller on the captured torso (`synthesize --params`).
    pub arm: Option<Series>,
    /// The full-body character with the person's parameters (`reach --params`).
    pub body: Option<Series>,
    /// The full-body character with the default profile.
    pub profile: Option<Series>,
}

/// The predictors a capture is compared with, in the order of [`PersonFidelity::summaries`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Predictor {
    /// The person's other captures' mean profile (the noise ceiling).
    Ceiling,
    /// A minimum-jerk bell over the capture's path, lasting the others' mean duration.
    MinimumJerk,
    /// The person's controller on the captured torso.
    Arm,
    /// The full-body character with the person's parameters.
    Body,
    /// The full-body character with the default profile.
    Profile,
}

impl Predictor {
    /// Every predictor, in report order.
    pub const ALL: [Predictor; 5] = [
        Predictor::Ceiling,
        Predictor::MinimumJerk,
        Predictor::Arm,
        Predictor::Body,
        Predictor::Profile,
    ];

    /// The name columns and JSON use: `ceiling`, `minimum_jerk`, `arm`, `body`, `profile`.
    pub fn name(self) -> &'static str {
        match self {
            Predictor::Ceiling => "ceiling",
            Predictor::MinimumJerk => "minimum_jerk",
            Predictor::Arm => "arm",
            Predictor::Body => "body",
            Predictor::Profile => "profile",
        }
    }

    /// What a reader of a table calls it.
    pub fn label(self) -> &'static str {
        match self {
            Predictor::Ceiling => "the person's own repeats (ceiling)",
            Predictor::MinimumJerk => "minimum jerk, the person's mean duration",
            Predictor::Arm => "the arm on the captured torso",
            Predictor::Body => "the full body, the person's parameters",
            Predictor::Profile => "the full body, the default profile",
        }
    }
}

/// One predictor's motion of a capture and its figures against it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Predicted {
    /// Which predictor.
    pub predictor: Predictor,
    /// Its real-time figures against the capture.
    pub fidelity: Fidelity,
    /// Its speed series (for pictures).
    #[serde(skip)]
    pub series: Series,
}

/// One capture's real-time comparison with every predictor that was made.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TakeFidelity {
    /// The capture's name.
    pub name: String,
    /// The capture's main reach's duration, seconds
    /// ([`kinergy_motion::fidelity::movement_duration`]).
    pub capture_duration_s: f64,
    /// The capture's peak speed, m/s.
    pub capture_peak_m_s: f64,
    /// The capture's hand path relative to the shoulder, meters.
    pub capture_path_m: f64,
    /// Each predictor made for it, in [`Predictor::ALL`]'s order (the ceiling and minimum
    /// jerk need at least one other capture of the person).
    pub predicted: Vec<Predicted>,
    /// The capture's series (for pictures).
    #[serde(skip)]
    pub capture: Series,
}

impl TakeFidelity {
    /// The figures of `predictor`, if it was made.
    pub fn get(&self, predictor: Predictor) -> Option<&Predicted> {
        self.predicted.iter().find(|p| p.predictor == predictor)
    }
}

/// One predictor over a person's captures.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PredictorSummary {
    /// Which predictor.
    pub predictor: Predictor,
    /// Captures it was made for.
    pub takes: usize,
    /// Mean real-time error e.
    pub error: f64,
    /// Mean e over the ceiling's mean e on the same captures (1: as close as the person's own
    /// repeats; NaN without a ceiling).
    pub error_over_ceiling: f64,
    /// Mean duration ratio (predictor ÷ capture).
    pub duration_ratio: f64,
    /// Mean peak-speed ratio.
    pub peak_ratio: f64,
    /// Mean time to peak, seconds.
    pub time_to_peak_s: f64,
    /// Mean SPARC (the captures': [`PersonFidelity::capture_sparc`]).
    pub sparc: f64,
    /// Captures whose e is below minimum jerk's.
    pub beats_minimum_jerk: usize,
    /// Captures with a real-time speed jump the capture lacks.
    pub jumps: usize,
}

/// A person's captures judged in real time ([`PersonFidelity::of`]).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PersonFidelity {
    /// Each capture.
    pub takes: Vec<TakeFidelity>,
    /// Each predictor made for at least one capture, in [`Predictor::ALL`]'s order.
    pub summaries: Vec<PredictorSummary>,
    /// The captures' mean SPARC.
    pub capture_sparc: f64,
    /// The captures' mean duration, seconds.
    pub capture_duration_s: f64,
    /// The captures' mean peak speed, m/s.
    pub capture_peak_m_s: f64,
}

impl PersonFidelity {
    /// The person's captures `takes`, each with the motions made of it: the ceiling and the
    /// minimum-jerk floor of each capture come from the *other* captures (leave-one-out), so a
    /// person needs two captures for them.
    pub fn of(takes: &[TakeMotions]) -> PersonFidelity {
        let captures: Vec<Speeds<'_>> = takes.iter().map(|t| t.capture.speeds()).collect();
        let rows: Vec<TakeFidelity> = takes
            .iter()
            .enumerate()
            .map(|(i, take)| take_fidelity(i, take, &captures))
            .collect();
        let summaries = Predictor::ALL
            .iter()
            .filter_map(|&p| summary(p, &rows))
            .collect();
        let mean = |f: &dyn Fn(&TakeFidelity) -> f64| mean(rows.iter().map(f));
        PersonFidelity {
            capture_sparc: mean(&|t| {
                t.predicted
                    .first()
                    .map_or(f64::NAN, |p| p.fidelity.capture_sparc)
            }),
            capture_duration_s: mean(&|t| t.capture_duration_s),
            capture_peak_m_s: mean(&|t| t.capture_peak_m_s),
            takes: rows,
            summaries,
        }
    }

    /// The summary of `predictor`, if it was made for any capture.
    pub fn summary(&self, predictor: Predictor) -> Option<&PredictorSummary> {
        self.summaries.iter().find(|s| s.predictor == predictor)
    }
}

fn take_fidelity(i: usize, take: &TakeMotions, captures: &[Speeds<'_>]) -> TakeFidelity {
    let capture = take.capture.speeds();
    let dt = take.capture.frame_time;
    let others: Vec<Speeds<'_>> = captures
        .iter()
        .enumerate()
        .filter(|&(k, _)| k != i)
        .map(|(_, s)| *s)
        .collect();
    let mut made: Vec<(Predictor, Series)> = Vec::new();
    if !others.is_empty() {
        made.push((
            Predictor::Ceiling,
            Series {
                values: mean_profile(&others, dt),
                frame_time: dt,
            },
        ));
        let others_duration = mean(others.iter().map(|s| duration(*s)));
        made.push((
            Predictor::MinimumJerk,
            Series {
                values: minimum_jerk(path_length(capture), others_duration, dt),
                frame_time: dt,
            },
        ));
    }
    for (p, s) in [
        (Predictor::Arm, &take.arm),
        (Predictor::Body, &take.body),
        (Predictor::Profile, &take.profile),
    ] {
        if let Some(s) = s {
            made.push((p, s.clone()));
        }
    }
    TakeFidelity {
        name: take.name.clone(),
        capture_duration_s: movement_duration(capture),
        capture_peak_m_s: peak_speed(capture),
        capture_path_m: path_length(capture),
        predicted: made
            .into_iter()
            .map(|(predictor, series)| Predicted {
                predictor,
                fidelity: Fidelity::of(series.speeds(), capture),
                series,
            })
            .collect(),
        capture: take.capture.clone(),
    }
}

fn summary(predictor: Predictor, rows: &[TakeFidelity]) -> Option<PredictorSummary> {
    let with: Vec<(&TakeFidelity, &Fidelity)> = rows
        .iter()
        .filter_map(|t| t.get(predictor).map(|p| (t, &p.fidelity)))
        .collect();
    if with.is_empty() {
        return None;
    }
    let m = |f: &dyn Fn(&Fidelity) -> f64| mean(with.iter().map(|(_, x)| f(x)));
    let ceiling = mean(with.iter().map(|(t, _)| {
        t.get(Predictor::Ceiling)
            .map_or(f64::NAN, |c| c.fidelity.error)
    }));
    let error = m(&|f| f.error);
    Some(PredictorSummary {
        predictor,
        takes: with.len(),
        error,
        error_over_ceiling: error / ceiling,
        duration_ratio: m(&|f| f.duration_ratio),
        peak_ratio: m(&|f| f.peak_ratio),
        time_to_peak_s: m(&|f| f.time_to_peak_s),
        sparc: m(&|f| f.sparc),
        beats_minimum_jerk: with
            .iter()
            .filter(|(t, f)| {
                t.get(Predictor::MinimumJerk)
                    .is_some_and(|mj| f.error < mj.fidelity.error)
            })
            .count(),
        jumps: with.iter().filter(|(_, f)| f.jumps).count(),
    })
}

/// The mean of `values` (NaN for none).
fn mean(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v, n + 1));
    if n == 0 { f64::NAN } else { sum / n as f64 }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bell(length: f64, seconds: f64, dt: f64) -> Series {
        Series {
            values: minimum_jerk(length, seconds, dt),
            frame_time: dt,
        }
    }

    fn take(name: &str, capture: Series, arm: Option<Series>) -> TakeMotions {
        TakeMotions {
            name: name.into(),
            capture,
            arm,
            body: None,
            profile: None,
        }
    }

    /// A person who repeats one minimum-jerk reach exactly: their own repeats, minimum jerk
    /// and an arm that copies the capture all predict it with e = 0; an arm twice as slow is
    /// far from it, and the summaries say so.
    #[test]
    fn a_person_who_repeats_one_bell_has_a_ceiling_of_zero() {
        let dt = 1.0 / 30.0;
        let takes: Vec<TakeMotions> = (0..3)
            .map(|k| {
                let c = bell(0.6, 0.9, dt);
                let arm = if k == 0 {
                    bell(0.6, 1.8, dt)
                } else {
                    c.clone()
                };
                take(&format!("t{k}"), c, Some(arm))
            })
            .collect();
        let f = PersonFidelity::of(&takes);
        for t in &f.takes {
            let ceiling = t.get(Predictor::Ceiling).expect("ceiling").fidelity.error;
            let mj = t.get(Predictor::MinimumJerk).expect("mj").fidelity.error;
            // To the interpolation through the 101-sample normalized profile and the
            // trapezoid path length at 30 Hz.
            approx::assert_abs_diff_eq!(ceiling, 0.0, epsilon = 2e-3);
            approx::assert_abs_diff_eq!(mj, 0.0, epsilon = 2e-3);
        }
        let arm = f.summary(Predictor::Arm).expect("arm");
        approx::assert_relative_eq!(
            arm.duration_ratio,
            (2.0 + 1.0 + 1.0) / 3.0,
            max_relative = 0.03
        );
        assert!(arm.error > 0.1, "{arm:?}");
        // The two exact copies beat the floor (its path and duration are interpolated), the slow
        // one does not.
        assert_eq!(arm.beats_minimum_jerk, 2);
        assert!(f.summary(Predictor::Body).is_none());
    }

    /// One capture has no ceiling (nothing to leave out) and its floor is not made either.
    #[test]
    fn a_single_capture_has_no_ceiling() {
        let dt = 0.01;
        let f = PersonFidelity::of(&[take("only", bell(0.5, 1.0, dt), None)]);
        assert!(f.takes[0].get(Predictor::Ceiling).is_none());
        assert!(f.summary(Predictor::Ceiling).is_none());
    }
}
