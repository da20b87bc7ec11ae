//! A person's tempo in a parameters file: how fast each captured reach moved
//! ([`ReachTempo`]) and the law over distance a fit makes of them ([`PersonTempo`]).

use serde::{Deserialize, Serialize};

/// How fast a captured hand moved over a reach, relative to the shoulder: a person's tempo,
/// which a full-body reach in their style keeps ([`FitRecord::tempo`](super::FitRecord::tempo)).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ReachTempo {
    /// The hand's peak speed relative to the shoulder, m/s.
    pub peak_speed_m_s: f64,
    /// The reach's duration, seconds.
    pub duration_s: f64,
    /// The straight distance from the hand's first to its last place relative to the
    /// shoulder (in the arm's base frame on each frame), meters.
    pub travel_m: f64,
}

/// A person's tempo: how long their reach over a distance lasts and how fast it peaks — the
/// bounds of the smooth controller that every synthesis in their style runs under (the fit,
/// `synthesize`, the full body), so the person is delivered under the controller they were
/// fitted under. A reach over d meters lasts T(d) = `duration_s` · (d / `reference_m`)^`exponent`
/// and peaks at V(d) = `shape` · d / T(d) (1.875 for a minimum-jerk reach).
///
/// Made by a fit from its reaches ([`PersonTempo::of`]) and written in the parameters file
/// (`fit.tempo_law`). Files written before it hold only each reach's tempo: their law is the
/// medians' with `exponent` 1 (a reach's duration proportional to its distance, the person's
/// median mean speed), as those files were always delivered.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PersonTempo {
    /// The distance the law is anchored at (the median travel of the fitted reaches), meters.
    pub reference_m: f64,
    /// The duration of a reach over `reference_m`, seconds.
    pub duration_s: f64,
    /// How the duration grows with the distance (T ∝ d^exponent), in [0, 1].
    pub exponent: f64,
    /// Peak speed × duration ÷ travel (median over the reaches).
    pub shape: f64,
    /// The arm the law was fitted on (upper arm + forearm, median over the fitted reaches),
    /// meters: an arm of another length reads the law's distances in its own lengths
    /// ([`PersonTempo::for_reach_by`]). Absent in files written before it: distances in
    /// meters on any arm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub arm_m: Option<f64>,
}

/// The exponent of [`PersonTempo`] when the reaches' distances are too alike to tell it
/// (a spread of ln d below [`TEMPO_SPREAD`]): 1, the duration proportional to the distance
/// (the law files without one have always been delivered with).
pub const TEMPO_EXPONENT: f64 = 1.0;

/// The least standard deviation of the reaches' ln distance from which [`PersonTempo::of`]
/// fits the exponent (log-log least squares, at least three reaches): 0.15, distances that
/// differ by about a sixth.
pub const TEMPO_SPREAD: f64 = 0.15;

impl ReachTempo {
    /// Whether a person's tempo can be made of it: finite, positive values and a travel of at
    /// least 5 cm.
    pub fn is_usable(&self) -> bool {
        [self.peak_speed_m_s, self.duration_s, self.travel_m]
            .iter()
            .all(|v| v.is_finite() && *v > 0.0)
            && self.travel_m >= 0.05
    }
}

impl PersonTempo {
    /// Checks what a damaged or hand-edited law could get wrong: `reference_m`, `duration_s`,
    /// `shape` and `arm_m` (if given) finite and > 0, `exponent` in [0, 1]. Returns the first field that is wrong
    /// and why.
    pub fn check(&self) -> Result<(), (String, String)> {
        for (name, v) in [
            ("reference_m", self.reference_m),
            ("duration_s", self.duration_s),
            ("shape", self.shape),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err((name.into(), format!("is {v}: expected a finite number > 0")));
            }
        }
        if let Some(arm) = self.arm_m
            && !(arm.is_finite() && arm > 0.0)
        {
            return Err((
                "arm_m".into(),
                format!("is {arm}: expected a finite number > 0"),
            ));
        }
        if !(0.0..=1.0).contains(&self.exponent) {
            return Err((
                "exponent".into(),
                format!("is {}: expected a number in [0, 1]", self.exponent),
            ));
        }
        Ok(())
    }

    /// The peak speed (m/s) and duration (s) of the person's reach over `distance` meters.
    pub fn for_distance(&self, distance: f64) -> (f64, f64) {
        let duration = self.duration_s * (distance / self.reference_m).powf(self.exponent);
        (self.shape * distance / duration, duration)
    }

    /// The peak speed (m/s) and duration (s) of the person's reach over `distance` meters by an
    /// arm of `arm_m` (upper arm + forearm): the law read in arm lengths. A body `k` times the
    /// fitted arm reaching `k` times as far takes as long and peaks `k` times as fast — the
    /// timing a retargeted capture keeps (its paths scaled, its clock not), and what makes a
    /// person's tempo carry to bodies of other sizes. The law's own [`for_distance`] where it
    /// records no arm or `arm_m` is no length.
    ///
    /// [`for_distance`]: PersonTempo::for_distance
    pub fn for_reach_by(&self, distance: f64, arm_m: f64) -> (f64, f64) {
        match self.arm_m {
            Some(fitted) if arm_m.is_finite() && arm_m > 0.0 => {
                let k = arm_m / fitted;
                let (peak, duration) = self.for_distance(distance / k);
                (peak * k, duration)
            }
            _ => self.for_distance(distance),
        }
    }

    /// The law with the arm it was fitted on (`arm_m`, meters: upper arm + forearm).
    pub fn with_arm(self, arm_m: f64) -> PersonTempo {
        PersonTempo {
            arm_m: (arm_m.is_finite() && arm_m > 0.0).then_some(arm_m),
            ..self
        }
    }

    /// The law of `reaches`' tempos (each: the peak speed the smooth controller is bounded by,
    /// the duration and the travel), over those with finite, positive values and a travel of
    /// at least 5 cm; `None` when none has. The reference is the median travel, the duration
    /// at it the median duration scaled to it by the exponent, the shape the median shape.
    pub fn of(reaches: &[ReachTempo]) -> Option<PersonTempo> {
        let usable: Vec<ReachTempo> = reaches.iter().copied().filter(|t| t.is_usable()).collect();
        if usable.is_empty() {
            return None;
        }
        let median = |v: Vec<f64>| kinergy_motion::jumps::median(&v);
        let reference = median(usable.iter().map(|t| t.travel_m).collect());
        let logs: Vec<(f64, f64)> = usable
            .iter()
            .map(|t| (t.travel_m.ln(), t.duration_s.ln()))
            .collect();
        let n = logs.len() as f64;
        let mx = logs.iter().map(|l| l.0).sum::<f64>() / n;
        let my = logs.iter().map(|l| l.1).sum::<f64>() / n;
        let sxx = logs.iter().map(|l| (l.0 - mx).powi(2)).sum::<f64>();
        let sxy = logs.iter().map(|l| (l.0 - mx) * (l.1 - my)).sum::<f64>();
        let exponent = if logs.len() >= 3 && (sxx / n).sqrt() >= TEMPO_SPREAD {
            (sxy / sxx).clamp(0.0, 1.0)
        } else {
            TEMPO_EXPONENT
        };
        let duration = median(
            usable
                .iter()
                .map(|t| t.duration_s * (reference / t.travel_m).powf(exponent))
                .collect(),
        );
        Some(PersonTempo {
            reference_m: reference,
            duration_s: duration,
            exponent,
            shape: median(
                usable
                    .iter()
                    .map(|t| t.peak_speed_m_s * t.duration_s / t.travel_m)
                    .collect(),
            ),
            arm_m: None,
        })
    }
}
