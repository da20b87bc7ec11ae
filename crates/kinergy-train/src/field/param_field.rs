//! The parameter field itself ([`ParamField`]): fitting it to (target, vector) samples,
//! evaluating it, and its leave-one-out evaluation ([`leave_one_out`]). The
//! [parent module](super) describes the method and re-exports these.

use kinergy_io::InvalidSetting;
use kinergy_motion::nalgebra::Point3;
use kinergy_solver::ParamSpace;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::regression::Data;
use super::settings::{Bandwidth, BandwidthScore, FieldSettings, Regression};
use crate::error::{Result, TrainError};

/// Parameters as a smooth function of the target, learned from per-clip fits (see the
/// [module docs](super) for the method and its properties).
#[derive(Debug, Clone, PartialEq)]
pub struct ParamField {
    space: ParamSpace,
    lower: Vec<f64>,
    upper: Vec<f64>,
    targets: Vec<Point3<f64>>,
    values: Vec<Vec<f64>>,
    settings: FieldSettings,
    bandwidth: f64,
    selection: Vec<BandwidthScore>,
    /// The person's single vector the field is anchored to ([`ParamField::anchored`]).
    anchor: Option<Vec<f64>>,
}

/// A field's bandwidth as chosen: the h in use, meters, and the candidates'
/// leave-one-out scores it was chosen among (empty for a fixed bandwidth, or when there was
/// no scale to choose from).
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct BandwidthChoice {
    /// h, meters (∞: flat).
    pub(crate) bandwidth: f64,
    /// The candidates tried, smallest h first.
    pub(crate) selection: Vec<BandwidthScore>,
}

impl ParamField {
    /// Fits the field of `samples` — (target in meters, fitted vector of `space`) — with
    /// `settings`. Errors name the offending field: `field.bandwidth`, `field.ridge`,
    /// `samples` (none given), `samples[k].target` (not finite), `samples[k].params` (wrong
    /// length or out of bounds; the message names the parameter).
    pub fn fit(
        space: &ParamSpace,
        samples: &[(Point3<f64>, Vec<f64>)],
        settings: &FieldSettings,
    ) -> Result<ParamField> {
        check_inputs(space, samples, settings)?;
        let (targets, values) = samples.iter().cloned().unzip();
        Ok(ParamField::build(
            space.clone(),
            targets,
            values,
            *settings,
            None,
        ))
    }

    /// The same samples anchored to `vector`, the person's single vector (see the
    /// [module docs](super#anchored-to-the-persons-vector)); an automatic bandwidth is chosen
    /// again, h = ∞ among the candidates. Errors name `anchor` (wrong length, out of bounds).
    pub fn anchored(&self, vector: Vec<f64>) -> Result<ParamField> {
        self.space
            .validate(&vector)
            .map_err(|e| TrainError::Setting(InvalidSetting::new("anchor", e.to_string())))?;
        Ok(ParamField::build(
            self.space.clone(),
            self.targets.clone(),
            self.values.clone(),
            self.settings,
            Some(vector),
        ))
    }

    /// Fits without checks (the inputs are known valid).
    fn build(
        space: ParamSpace,
        targets: Vec<Point3<f64>>,
        values: Vec<Vec<f64>>,
        settings: FieldSettings,
        anchor: Option<Vec<f64>>,
    ) -> ParamField {
        let lower = space.lower();
        let upper = space.upper();
        let choice = match settings.bandwidth {
            Bandwidth::Fixed(h) => BandwidthChoice {
                bandwidth: h,
                selection: Vec::new(),
            },
            Bandwidth::Auto => {
                let data = Data {
                    targets: &targets,
                    values: &values,
                    lower: &lower,
                    upper: &upper,
                };
                data.select(settings.regression, anchor.is_some())
            }
        };
        ParamField::stored(space, targets, values, settings, choice, anchor)
    }

    /// A field read back from a file: everything as stored, nothing chosen again.
    pub(crate) fn stored(
        space: ParamSpace,
        targets: Vec<Point3<f64>>,
        values: Vec<Vec<f64>>,
        settings: FieldSettings,
        choice: BandwidthChoice,
        anchor: Option<Vec<f64>>,
    ) -> ParamField {
        let BandwidthChoice {
            bandwidth,
            selection,
        } = choice;
        ParamField {
            lower: space.lower(),
            upper: space.upper(),
            space,
            targets,
            values,
            settings,
            bandwidth,
            selection,
            anchor,
        }
    }

    /// The field of all samples but sample `k`, fitted with the same settings (an automatic
    /// bandwidth is chosen again, from the remaining samples only) and the same anchor. Needs
    /// ≥ 2 samples.
    pub fn without(&self, k: usize) -> Result<ParamField> {
        InvalidSetting::require(
            self.targets.len() >= 2,
            "samples",
            "at least two samples to leave one out",
        )?;
        InvalidSetting::require(
            k < self.targets.len(),
            "k",
            format!("a sample index below {}", self.targets.len()),
        )?;
        let mut targets = self.targets.clone();
        let mut values = self.values.clone();
        targets.remove(k);
        values.remove(k);
        Ok(ParamField::build(
            self.space.clone(),
            targets,
            values,
            self.settings,
            self.anchor.clone(),
        ))
    }

    /// The field of all samples but sample `k` with bandwidth `h` (∞: flat) and the same
    /// anchor, nothing chosen. Needs ≥ 2 samples and `k` in range (callers check).
    pub(crate) fn without_at(&self, k: usize, h: f64) -> ParamField {
        let mut targets = self.targets.clone();
        let mut values = self.values.clone();
        targets.remove(k);
        values.remove(k);
        let settings = FieldSettings {
            bandwidth: Bandwidth::Fixed(h),
            ..self.settings
        };
        ParamField::build(
            self.space.clone(),
            targets,
            values,
            settings,
            self.anchor.clone(),
        )
    }

    /// The same field with the bandwidth `choice`.
    pub(crate) fn with_bandwidth(&self, choice: BandwidthChoice) -> ParamField {
        ParamField {
            bandwidth: choice.bandwidth,
            selection: choice.selection,
            ..self.clone()
        }
    }

    /// The parameters at `target`, always within the bounds (see the [module docs](super)).
    /// A non-finite target carries no position: it gets the mean of the samples' vectors
    /// (use [`ParamField::try_evaluate`] to have it refused instead).
    pub fn evaluate(&self, target: &Point3<f64>) -> Vec<f64> {
        let data = self.data();
        let p = data.predict(self.bandwidth, self.settings.regression, target, None);
        let Some(anchor) = &self.anchor else {
            return p;
        };
        // p̄, the h → ∞ limit, computed as p is (for h = ∞ the two agree bit for bit and the
        // field is the anchor exactly).
        let mean = data.predict(
            f64::INFINITY,
            Regression::NadarayaWatson,
            &Point3::origin(),
            None,
        );
        (0..anchor.len())
            .map(|i| (anchor[i] + (p[i] - mean[i])).clamp(self.lower[i], self.upper[i]))
            .collect()
    }

    /// The person's single vector the field is anchored to, if it is.
    pub fn anchor(&self) -> Option<&[f64]> {
        self.anchor.as_deref()
    }

    /// [`ParamField::evaluate`], refusing a target that is not finite (`target`).
    pub fn try_evaluate(&self, target: &Point3<f64>) -> Result<Vec<f64>> {
        InvalidSetting::require(
            target.iter().all(|c| c.is_finite()),
            "target",
            "finite coordinates",
        )?;
        Ok(self.evaluate(target))
    }

    /// The bandwidth h in use, meters (the chosen one for [`Bandwidth::Auto`]; ∞ for an
    /// anchored field that is flat).
    pub fn bandwidth(&self) -> f64 {
        self.bandwidth
    }

    /// The candidates [`Bandwidth::Auto`] tried with their errors, smallest h first (empty
    /// for a fixed bandwidth or when there was no scale to choose from).
    pub fn selection(&self) -> &[BandwidthScore] {
        &self.selection
    }

    /// The settings it was fitted with.
    pub fn settings(&self) -> &FieldSettings {
        &self.settings
    }

    /// The parameter space.
    pub fn space(&self) -> &ParamSpace {
        &self.space
    }

    /// The samples' targets, meters.
    pub fn targets(&self) -> &[Point3<f64>] {
        &self.targets
    }

    /// The samples' fitted vectors, in the order of the targets.
    pub fn values(&self) -> &[Vec<f64>] {
        &self.values
    }

    /// The number of samples.
    pub fn len(&self) -> usize {
        self.targets.len()
    }

    /// Always false: a field has at least one sample.
    pub fn is_empty(&self) -> bool {
        self.targets.is_empty()
    }

    fn data(&self) -> Data<'_> {
        Data {
            targets: &self.targets,
            values: &self.values,
            lower: &self.lower,
            upper: &self.upper,
        }
    }
}

/// One row of [`leave_one_out`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LooRow {
    /// The sample (reach) left out and scored.
    pub index: usize,
    /// Its target, meters.
    pub target: [f64; 3],
    /// The bandwidth of the field of the other samples, meters.
    pub bandwidth: f64,
    /// That field's parameters at the target.
    pub field_params: Vec<f64>,
    /// The caller's score (the reach's motion distance) with those parameters.
    pub field_distance: f64,
}

/// Leave-one-target-out evaluation: for each sample k, the field of the other samples (its
/// automatic bandwidth included, chosen without sample k) evaluated at t_k, and
/// `score(k, params)` — the caller synthesizes reach k with `params` and returns its
/// distance, reported as given. Needs ≥ 2 samples (validated as in [`ParamField::fit`]).
/// Rows run in parallel and come back in sample order; if scores fail, the error of the
/// lowest k is returned.
pub fn leave_one_out<F>(
    space: &ParamSpace,
    samples: &[(Point3<f64>, Vec<f64>)],
    settings: &FieldSettings,
    score: F,
) -> Result<Vec<LooRow>>
where
    F: Fn(usize, &[f64]) -> Result<f64> + Sync,
{
    check_inputs(space, samples, settings)?;
    InvalidSetting::require(
        samples.len() >= 2,
        "samples",
        "at least two samples to leave one out",
    )?;
    let rows: Vec<Result<LooRow>> = (0..samples.len())
        .into_par_iter()
        .map(|k| {
            let (targets, values) = samples
                .iter()
                .enumerate()
                .filter(|&(j, _)| j != k)
                .map(|(_, s)| s.clone())
                .unzip();
            let field = ParamField::build(space.clone(), targets, values, *settings, None);
            let target = samples[k].0;
            let field_params = field.evaluate(&target);
            let field_distance = score(k, &field_params)?;
            Ok(LooRow {
                index: k,
                target: [target.x, target.y, target.z],
                bandwidth: field.bandwidth(),
                field_params,
                field_distance,
            })
        })
        .collect();
    rows.into_iter().collect()
}

/// What is wrong with sample `k`'s `target`, if anything: the field (`samples[k].target`,
/// or the coordinate) and why. A target is finite and within
/// [`MAX_TARGET_DISTANCE`](crate::MAX_TARGET_DISTANCE) of its arm's base: one no arm
/// reaches (1e308 m, from a damaged file) would make every kernel weight overflow and the
/// field's parameters NaN. Numbers are said short.
pub(crate) fn target_problem(k: usize, target: &Point3<f64>) -> Option<(String, String)> {
    let num = kinergy_io::Num;
    if !target.iter().all(|c| c.is_finite()) {
        return Some((
            format!("samples[{k}].target"),
            format!(
                "is ({}, {}, {}): expected finite coordinates",
                num(target.x),
                num(target.y),
                num(target.z)
            ),
        ));
    }
    let distance = target.x.hypot(target.y).hypot(target.z);
    let max = crate::MAX_TARGET_DISTANCE;
    if distance <= max {
        return None;
    }
    let i = (0..3).find(|&i| target[i].abs() > max).unwrap_or(0);
    Some((
        format!("samples[{k}].target[{i}]"),
        format!(
            "is {}: the sample's target is {} m from its arm's base, beyond the {max} m a \
             target may lie: a damaged file?",
            num(target[i]),
            num(distance)
        ),
    ))
}

fn check_inputs(
    space: &ParamSpace,
    samples: &[(Point3<f64>, Vec<f64>)],
    settings: &FieldSettings,
) -> Result<()> {
    settings.validate()?;
    InvalidSetting::require(
        !samples.is_empty(),
        "samples",
        "at least one (target, parameters) sample",
    )?;
    for (k, (t, p)) in samples.iter().enumerate() {
        check_sample(space, k, t, p)?;
    }
    Ok(())
}

fn check_sample(space: &ParamSpace, k: usize, target: &Point3<f64>, params: &[f64]) -> Result<()> {
    if let Some((field, why)) = target_problem(k, target) {
        return Err(TrainError::Setting(InvalidSetting::new(field, why)));
    }
    space.validate(params).map_err(|e| {
        TrainError::Setting(InvalidSetting::new(
            format!("samples[{k}].params"),
            e.to_string(),
        ))
    })
}
