//! A person's field as `fit --field` makes it: each reach fitted on its own under the
//! person's tempo law, the person's single vector over all of them (the anchor), the field
//! of the reaches' fits anchored to it, and the report of how well it predicts each reach
//! from the others.

use kinergy_motion::Side;
use serde::Serialize;

use super::{BandwidthScore, FieldFile, FieldSettings};
use crate::fit::{Fit, NestedFit};
use crate::{CapturedReach, Result, TrainError, under_person_tempo};

/// Refuses reaches of more than one arm (before any fit): a field's targets are in one arm's
/// base frame.
pub fn check_one_arm(reaches: &[CapturedReach]) -> Result<()> {
    let Some(first) = reaches.first() else {
        return Ok(());
    };
    let side = first.fitted_arm().side;
    match reaches.iter().find(|r| r.fitted_arm().side != side) {
        Some(other) => Err(TrainError::MixedArms {
            first: first.name().to_string(),
            first_side: side,
            other: other.name().to_string(),
            other_side: other.fitted_arm().side,
        }),
        None => Ok(()),
    }
}

/// The groups a field fits one by one: each reach alone, under the person's tempo law of
/// all of them (as the field runs it).
pub fn field_groups(reaches: &[CapturedReach]) -> Vec<Vec<CapturedReach>> {
    under_person_tempo(reaches)
        .into_iter()
        .map(|r| vec![r])
        .collect()
}

impl FieldFile {
    /// The field of `per_reach` (each reach's nested fit, in order) anchored to `person`'s
    /// last model (all the reaches at once), with the default field settings.
    pub fn from_nested(
        reaches: &[CapturedReach],
        per_reach: &[NestedFit],
        person: &NestedFit,
        tolerance: f64,
    ) -> Result<FieldFile> {
        let last: Vec<Fit> = per_reach
            .iter()
            .filter_map(|f| f.fits.last().cloned())
            .collect();
        let anchor = person.fits.last().ok_or_else(|| TrainError::Reach {
            clip: "the person".into(),
            why: "no model was fitted".into(),
        })?;
        FieldFile::from_fits(reaches, &last, &FieldSettings::default())?.anchored(
            anchor.values.clone(),
            reaches,
            tolerance,
        )
    }
}

/// One reach of the field, as the report shows it.
#[derive(Debug, Clone, Serialize)]
pub struct FieldSample {
    /// The capture.
    pub clip: String,
    /// The reach's frames, end excluded.
    pub frames: [usize; 2],
    /// The arm's side.
    pub side: Option<String>,
    /// The target in the arm's base frame on the reach's first frame, meters.
    pub target_m: [f64; 3],
    /// The reach's own fit's distance, meters.
    pub distance_m: f64,
    /// The distance with the vector the field of the other reaches predicts, meters.
    pub loo_distance_m: Option<f64>,
}

/// The report of a person's field (`kinergy fit --field`).
#[derive(Debug, Clone, Serialize)]
pub struct FieldReport {
    /// Where the field file was written.
    pub output: String,
    /// Always `person`.
    pub per: &'static str,
    /// Always `field`.
    pub kind: &'static str,
    /// The optimizer's name.
    pub optimizer: &'static str,
    /// The field's model.
    pub model: &'static str,
    /// The bandwidth in use, meters; `null` when the field is flat: the person's single
    /// vector everywhere (the reaches show no dependence on the target).
    pub bandwidth_m: f64,
    /// The person's single vector's mean distance over all the reaches (the field's
    /// anchor), meters.
    pub anchor_distance_m: f64,
    /// The parameter-space leave-one-out error of that bandwidth (RMS over samples and
    /// entries, each relative to its bound width); `null` when there was nothing to choose
    /// from (fewer than two distinct targets).
    pub loo_error: Option<f64>,
    /// Every bandwidth tried, with its leave-one-out error.
    pub selection: Vec<BandwidthScore>,
    /// Mean over the reaches of their own fits' distances, meters.
    pub own_distance_m: f64,
    /// Mean over the reaches of their distance with the field of the other reaches (`null`
    /// with a single reach), meters.
    pub loo_distance_m: Option<f64>,
    /// The reaches.
    pub samples: Vec<FieldSample>,
    /// Richer models that ended worse than poorer ones, reach by reach.
    pub nested_violations: Vec<String>,
}

impl FieldReport {
    /// The report of `file` (written to `output`) fitted from `per_reach` and `person`:
    /// with two reaches or more, each reach is also synthesized with the field of the
    /// others (leave one reach out).
    pub fn of(
        file: &FieldFile,
        output: String,
        reaches: &[CapturedReach],
        per_reach: &[NestedFit],
        person: &NestedFit,
        tolerance: f64,
    ) -> Result<FieldReport> {
        let loo = if reaches.len() >= 2 {
            Some(file.leave_one_out(reaches, tolerance)?)
        } else {
            None
        };
        let mean = |v: &mut dyn Iterator<Item = f64>| {
            let (sum, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
            sum / n.max(1) as f64
        };
        let samples: Vec<FieldSample> = file
            .reaches()
            .iter()
            .zip(file.field().targets())
            .enumerate()
            .map(|(k, (r, t))| FieldSample {
                clip: r.clip.clone(),
                frames: r.frames,
                side: r
                    .arm
                    .as_ref()
                    .and_then(|a| a.side)
                    .map(|s: Side| s.to_string()),
                target_m: [t.x, t.y, t.z],
                distance_m: r.distance_m,
                loo_distance_m: loo.as_ref().map(|rows| rows[k].field_distance),
            })
            .collect();
        Ok(FieldReport {
            output,
            per: "person",
            kind: "field",
            optimizer: file.optimizer().kind().name(),
            model: file.model().name(),
            bandwidth_m: file.field().bandwidth(),
            anchor_distance_m: person.fits.last().map_or(f64::NAN, |f| f.score),
            loo_error: file.loo_error(),
            selection: file.field().selection().to_vec(),
            own_distance_m: mean(&mut samples.iter().map(|s| s.distance_m)),
            loo_distance_m: loo
                .as_ref()
                .map(|rows| mean(&mut rows.iter().map(|r| r.field_distance))),
            samples,
            nested_violations: per_reach
                .iter()
                .zip(reaches)
                .flat_map(|(f, r)| {
                    f.violations().into_iter().map(move |(a, b)| {
                        format!("{}: {} ended worse than {}", r.name(), b.name(), a.name())
                    })
                })
                .collect(),
        })
    }
}
