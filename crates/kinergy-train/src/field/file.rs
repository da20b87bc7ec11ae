//! The field file ([`FieldFile`]): a person's parameter field as a product.

use std::path::Path;

use kinergy_io::InvalidSetting;
use kinergy_motion::nalgebra::Point3;
use kinergy_solver::{
    Bounds, ControllerKind, FitGrouping, FitMethod, FitRecord, FitStatus, FittedArm, FittedReach,
    Model, Optimizer, ParamSpace, ParamsFile, PersonTempo, ReachTempo,
};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use super::param_field::{BandwidthChoice, LooRow, ParamField, target_problem};
use super::settings::{BandwidthScore, FieldSettings, infinite_as_null};
use crate::captured::{CapturedReach, person_tempo, under_person_tempo};
use crate::error::{Result, TrainError, in_file};
use crate::fit::{Fit, FitSettings, NestedFit, fit_nested};
use crate::objective::Objective;

/// The format version of a field file this crate writes and reads.
pub const FIELD_FORMAT_VERSION: u32 = 3;

/// A person's parameter field as a product (`kinergy fit CLIPS --per person
/// --field -o field.json`). Everything needed to run the person's synergy controller toward a
/// new target: the field (model, DoFs, bounds, kernel settings, the bandwidth chosen and the
/// leave-one-out scores it was chosen by, the person's single vector it is anchored to), the
/// optimizer, and per sample the reach it was fitted on (clip, frames, the arm: side, joints,
/// bones), its own fit's distance, its target and its fitted vector.
///
/// **Targets are in the arm's base frame** on the reach's first frame: meters, origin at the
/// shoulder, z lateral outward, y up, x = y × z (the capture convention of
/// [`kinergy_solver::CaptureArm`]; [`CapturedReach::local_target`]). A person may stand
/// anywhere and face any way in their captures; the target's place relative to the shoulder is
/// what the style depends on. One field holds one arm's reaches (the frame is not mirrored).
///
/// ```json
/// {
///   "format_version": 3,
///   "model": "sc",
///   "optimizer": { "kind": "svd", "rate": 4.0, "threshold": 0.01 },
///   "dof_names": ["shoulder_swing_x", "…"],
///   "bounds": { "gain": { "lower": -5.0, "upper": 5.0 }, "…": "…" },
///   "names": ["g_shoulder_swing_x", "…", "s", "o"],
///   "settings": { "bandwidth": "auto", "regression": "nadaraya_watson" },
///   "bandwidth": 0.21,
///   "selection": [ { "bandwidth": 0.053, "loo_error": 0.12 }, "…",
///                  { "bandwidth": null, "loo_error": 0.1 } ],
///   "anchor": [1.1, "…"],
///   "samples": [
///     { "clip": "p01/r01.bvh", "frames": [4, 72],
///       "arm": { "side": "right", "joints": ["…"], "upper_arm_m": 0.3, "forearm_m": 0.25,
///                "hand_m": 0.08 },
///       "distance_m": 0.012, "target": [0.05, -0.31, 0.22], "values": [1.2, "…"] }
///   ]
/// }
/// ```
///
/// `anchor` (optional) is the person's single vector, fitted on all the samples' reaches at
/// once, that the field is anchored to ([`ParamField::anchored`]); a `bandwidth` of `null`
/// is the flat field of an anchored one (∞: the anchor everywhere). Format 2 (no anchor) and
/// format 1 (world targets, no optimizer) are refused with a message saying to run `kinergy
/// fit --field` again. Reading checks everything a damaged or
/// hand-edited file could get wrong and names the field (`samples[2].values`).
#[derive(Debug, Clone, PartialEq)]
pub struct FieldFile {
    field: ParamField,
    optimizer: Optimizer,
    reaches: Vec<FittedReach>,
    /// The person's tempo law every sample was fitted under and every synthesis with the
    /// field runs under (`None`: one sample, the paper's controller, or a file written before
    /// the law was recorded — each synthesis then under its capture's own speed).
    tempo_law: Option<PersonTempo>,
    /// The synergy controller every sample was fitted under (`None`: a file written before it
    /// was recorded).
    controller: Option<ControllerKind>,
}

impl FieldFile {
    /// A field file of `field` (targets in the arm's base frame), run with `optimizer`, whose
    /// sample k was fitted on `reaches[k]` (which must record its arm). Errors name the field:
    /// `optimizer.*`, `samples` (not one reach per sample), `samples[k].frames`, `.distance_m`,
    /// `.arm` (missing, a bad bone, or another side than sample 0's).
    pub fn new(
        field: ParamField,
        optimizer: Optimizer,
        reaches: Vec<FittedReach>,
    ) -> Result<FieldFile> {
        optimizer.validate()?;
        InvalidSetting::require(
            reaches.len() == field.len(),
            "samples",
            format!(
                "one fitted reach per sample ({}), not {}",
                field.len(),
                reaches.len()
            ),
        )?;
        check_reaches(&reaches)
            .map_err(|(field, why)| TrainError::Setting(InvalidSetting::new(field, why)))?;
        Ok(FieldFile {
            field,
            optimizer,
            reaches,
            tempo_law: None,
            controller: None,
        })
    }

    /// The same file with the person's tempo `law` ([`FieldFile::tempo_law`]).
    pub fn with_tempo_law(self, law: Option<PersonTempo>) -> FieldFile {
        FieldFile {
            tempo_law: law,
            ..self
        }
    }

    /// The same file recording the synergy `controller` its samples were fitted under.
    pub fn with_controller(self, controller: Option<ControllerKind>) -> FieldFile {
        FieldFile { controller, ..self }
    }

    /// The synergy controller the samples were fitted under (`None`: not recorded).
    pub fn controller(&self) -> Option<ControllerKind> {
        self.controller
    }

    /// The person's tempo law the samples were fitted under and a synthesis with the field
    /// runs under: [`person_tempo`] of two or more reaches ([`under_person_tempo`]); `None`
    /// for one sample, the paper's controller, or a file written before it was recorded (each
    /// synthesis then runs under its capture's own speed).
    pub fn tempo_law(&self) -> Option<&PersonTempo> {
        self.tempo_law.as_ref()
    }

    /// `reach` as the field's samples were fitted: under the person's tempo law, if any.
    fn as_fitted(&self, reach: &CapturedReach) -> CapturedReach {
        match &self.tempo_law {
            Some(law) => reach.clone().under_tempo(law),
            None => reach.clone(),
        }
    }

    /// The field of per-reach fits: `fits[k]` fitted on `reaches[k]` alone (one model, one
    /// optimizer and one parameter space for all), sample k its vector at
    /// [`CapturedReach::local_target`], with `settings`.
    pub fn from_fits(
        reaches: &[CapturedReach],
        fits: &[Fit],
        settings: &FieldSettings,
    ) -> Result<FieldFile> {
        InvalidSetting::require(
            !fits.is_empty() && fits.len() == reaches.len(),
            "fits",
            format!(
                "one fit per reach ({} reaches, {} fits), at least one",
                reaches.len(),
                fits.len()
            ),
        )?;
        let first = &fits[0];
        for (k, f) in fits.iter().enumerate() {
            InvalidSetting::require(
                f.space == first.space && f.optimizer == first.optimizer,
                &format!("fits[{k}]"),
                "the model, DoFs, bounds and optimizer of fits[0]",
            )?;
        }
        let samples: Vec<(Point3<f64>, Vec<f64>)> = reaches
            .iter()
            .zip(fits)
            .map(|(r, f)| (r.local_target(), f.values.clone()))
            .collect();
        let records = reaches
            .iter()
            .zip(fits)
            .map(|(r, f)| FittedReach {
                clip: r.name().to_string(),
                frames: [r.frames().start, r.frames().end],
                distance_m: f.distances.first().copied().unwrap_or(f.score),
                arm: Some(r.fitted_arm().clone()),
                tempo: Some(r.tempo()),
            })
            .collect();
        let field = ParamField::fit(&first.space, &samples, settings)?;
        let law = (reaches.len() >= 2)
            .then(|| person_tempo(reaches))
            .flatten();
        Ok(FieldFile::new(field, first.optimizer, records)?
            .with_tempo_law(law)
            .with_controller(reaches.first().map(CapturedReach::controller)))
    }

    /// Fits each reach on its own — `models` nested, poorest first, as `kinergy fit --per clip`
    /// does, but under the person's tempo law of all the reaches ([`under_person_tempo`]: the
    /// bounds the field's every synthesis runs under) — then the field of the richest model's vectors with `field`, anchored to the
    /// person's single vector (the same models nested on all the reaches at once, as
    /// `kinergy fit --per person` does), its bandwidth chosen by the motion
    /// ([`FieldFile::anchored`]). Reaches are fitted in parallel; the result does not
    /// depend on the thread count. Returns the file and every reach's nested fit, in the
    /// reaches' order.
    pub fn fit(
        reaches: &[CapturedReach],
        models: &[Model],
        optimizer: Optimizer,
        fit: &FitSettings,
        field: &FieldSettings,
    ) -> Result<(FieldFile, Vec<NestedFit>)> {
        let (file, nested) = FieldFile::fit_reaches(reaches, models, optimizer, fit, field)?;
        let person = fit_nested(reaches, models, optimizer, fit)?;
        let anchor = person
            .fits
            .last()
            .map(|f| f.values.clone())
            .unwrap_or_default();
        let file = file.anchored(anchor, reaches, fit.tolerance)?;
        Ok((file, nested))
    }

    /// [`FieldFile::fit`] without the anchor: the field of the per-reach fits alone (for a
    /// caller that has fitted the person's vector already and anchors it with
    /// [`FieldFile::anchored`]).
    pub fn fit_reaches(
        reaches: &[CapturedReach],
        models: &[Model],
        optimizer: Optimizer,
        fit: &FitSettings,
        field: &FieldSettings,
    ) -> Result<(FieldFile, Vec<NestedFit>)> {
        InvalidSetting::require(!reaches.is_empty(), "reaches", "at least one reach")?;
        let nested: Vec<NestedFit> = under_person_tempo(reaches)
            .par_iter()
            .map(|r| fit_nested(std::slice::from_ref(r), models, optimizer, fit))
            .collect::<Result<_>>()?;
        let last: Vec<Fit> = nested
            .iter()
            .map(|n| {
                n.fits.last().cloned().ok_or_else(|| {
                    TrainError::Setting(InvalidSetting::new("models", "at least one model to fit"))
                })
            })
            .collect::<Result<_>>()?;
        Ok((FieldFile::from_fits(reaches, &last, field)?, nested))
    }

    /// The same file, its field anchored to the person's single `vector` (fitted on all the
    /// samples' reaches at once: [`ParamField::anchored`]), its bandwidth then chosen by the
    /// motion: for every candidate of the selection (h = ∞ included), each of `reaches` (the
    /// field's own, in sample order) synthesized (ε = `tolerance`) with the field of the other
    /// samples with that h at its target, and the h of the smallest mean distance kept (ties
    /// to the larger h: the flat field, the person's vector everywhere, is the largest). With
    /// fewer than two samples or no candidates (a fixed bandwidth, one distinct target) the
    /// anchored field keeps its bandwidth. Every (candidate, reach) runs in parallel; the
    /// choice does not depend on the thread count.
    ///
    /// The anchor was fitted on every reach, k included, so the comparison leans toward the
    /// flat field on purpose: the field departs from the person's vector only where the other
    /// reaches' dependence on the target predicts reach k better than a vector fitted on
    /// reach k itself (among the others).
    pub fn anchored(
        self,
        vector: Vec<f64>,
        reaches: &[CapturedReach],
        tolerance: f64,
    ) -> Result<FieldFile> {
        FieldFile {
            field: self.field.anchored(vector)?,
            ..self
        }
        .chosen_by_motion(reaches, tolerance)
    }

    /// [`FieldFile::anchored`]'s choice of the bandwidth by the motion.
    fn chosen_by_motion(self, reaches: &[CapturedReach], tolerance: f64) -> Result<FieldFile> {
        InvalidSetting::require(
            reaches.len() == self.field.len(),
            "reaches",
            format!("the field's {} reaches, in order", self.field.len()),
        )?;
        let field = &self.field;
        if field.anchor().is_none() || field.len() < 2 || field.selection().is_empty() {
            return Ok(self);
        }
        let space = field.space();
        let n = field.len();
        let candidates = field.selection().to_vec();
        let distances: Vec<f64> = (0..candidates.len() * n)
            .into_par_iter()
            .map(|i| {
                let (c, k) = (i / n, i % n);
                let params = field
                    .without_at(k, candidates[c].bandwidth)
                    .evaluate(&field.targets()[k]);
                Objective::new(
                    vec![self.as_fitted(&reaches[k])],
                    space.clone(),
                    self.optimizer,
                )?
                .with_tolerance(tolerance)?
                .score(&params)
            })
            .collect::<Result<_>>()?;
        let selection: Vec<BandwidthScore> = candidates
            .iter()
            .enumerate()
            .map(|(c, s)| BandwidthScore {
                loo_distance_m: Some(distances[c * n..(c + 1) * n].iter().sum::<f64>() / n as f64),
                ..*s
            })
            .collect();
        // Largest h first, strict improvement only.
        let mut best: Option<&BandwidthScore> = None;
        for s in selection.iter().rev() {
            if best.is_none_or(|b| s.loo_distance_m < b.loo_distance_m) {
                best = Some(s);
            }
        }
        let h = best.map_or(field.bandwidth(), |b| b.bandwidth);
        Ok(FieldFile {
            field: field.with_bandwidth(BandwidthChoice {
                bandwidth: h,
                selection,
            }),
            ..self
        })
    }

    /// The field (targets in the arm's base frame).
    pub fn field(&self) -> &ParamField {
        &self.field
    }

    /// The optimizer the vectors were fitted with and a controller runs with.
    pub fn optimizer(&self) -> Optimizer {
        self.optimizer
    }

    /// The synergy model.
    pub fn model(&self) -> Model {
        self.field.space().model()
    }

    /// The reach each sample was fitted on, in sample order, each with its arm and its own
    /// fit's distance.
    pub fn reaches(&self) -> &[FittedReach] {
        &self.reaches
    }

    /// The arm of the first sample's reach (every sample's arm is of the same side).
    pub fn arm(&self) -> Option<&FittedArm> {
        self.reaches.first().and_then(|r| r.arm.as_ref())
    }

    /// The parameter-space leave-one-out error of the bandwidth in use (see
    /// [`BandwidthScore`]); `None` when it was not chosen by leave-one-out (fixed, or fewer
    /// than two distinct targets).
    pub fn loo_error(&self) -> Option<f64> {
        self.field
            .selection()
            .iter()
            .find(|s| s.bandwidth == self.field.bandwidth())
            .map(|s| s.loo_error)
    }

    /// The fit record a predicted parameters file carries: method `parameter_field`, status
    /// `predicted`, the samples' reaches with their own fits' distances, and as scores their
    /// mean (the predicted vector itself is not scored); per person.
    pub fn record(&self) -> FitRecord {
        let mean = self.reaches.iter().map(|r| r.distance_m).sum::<f64>()
            / self.reaches.len().max(1) as f64;
        FitRecord {
            method: FitMethod::ParameterField,
            score_m: mean,
            start_score_m: mean,
            evaluations: 0,
            iterations: 0,
            status: FitStatus::Predicted,
            seed: 0,
            reaches: self.reaches.clone(),
            per: Some(FitGrouping::Person),
            nested: None,
            objective: None,
            unobserved: None,
            tempo_law: self.tempo_law,
            controller: self.controller,
            started_from: None,
        }
    }

    /// The parameters file of the vector the field predicts at `target` (meters in the arm's
    /// base frame, finite; else a `target` error): within the bounds, with the field's model,
    /// optimizer and DoF names, and [`FieldFile::record`] as its fit record (the arms).
    pub fn params_for(&self, target: &Point3<f64>) -> Result<ParamsFile> {
        let values = self.field.try_evaluate(target)?;
        let mut record = self.record();
        record.unobserved = crate::fit::unobserved_names(self.field.space(), &record);
        let mut file = ParamsFile::new(self.field.space(), self.optimizer, &values)?;
        file.fit = Some(record);
        Ok(file)
    }

    /// Leave one reach out: for each sample k, the field of the others (its bandwidth chosen
    /// again without k, the same anchor) predicts reach k's vector at its target and
    /// `reaches[k]` is synthesized with it (ε = `tolerance`) and scored. `reaches` are the
    /// field's own, in sample order; needs ≥ 2. Rows run in parallel, in sample order.
    pub fn leave_one_out(&self, reaches: &[CapturedReach], tolerance: f64) -> Result<Vec<LooRow>> {
        InvalidSetting::require(
            reaches.len() == self.field.len(),
            "reaches",
            format!("the field's {} reaches, in order", self.field.len()),
        )?;
        let space = self.field.space();
        (0..self.field.len())
            .into_par_iter()
            .map(|k| {
                let others = self.field.without(k)?;
                let target = self.field.targets()[k];
                let field_params = others.evaluate(&target);
                let field_distance = Objective::new(
                    vec![self.as_fitted(&reaches[k])],
                    space.clone(),
                    self.optimizer,
                )?
                .with_tolerance(tolerance)?
                .score(&field_params)?;
                Ok(LooRow {
                    index: k,
                    target: [target.x, target.y, target.z],
                    bandwidth: others.bandwidth(),
                    field_params,
                    field_distance,
                })
            })
            .collect()
    }

    /// Pretty JSON.
    pub fn to_json(&self) -> String {
        kinergy_io::to_pretty_json(&Doc::of(self)).unwrap_or_default()
    }

    /// Parses and checks a field file's text. Errors ([`TrainError::File`]) name the field
    /// or the line and column; a file of format 1 is refused with what to do about it.
    pub fn from_json(text: &str) -> Result<FieldFile> {
        let bad = |why: String| TrainError::File { path: None, why };
        if let Some(found) = serde_json::from_str::<serde_json::Value>(text)
            .ok()
            .and_then(|v| v.get("format_version").and_then(serde_json::Value::as_u64))
            .filter(|&v| v < u64::from(FIELD_FORMAT_VERSION))
        {
            let holds = if found < 2 {
                "world targets and no optimizer"
            } else {
                "no anchor (the person's single vector)"
            };
            return Err(bad(format!(
                "`format_version` is {found}: a field file of format {found} holds {holds}, \
                 and this version of Kinergy reads format {FIELD_FORMAT_VERSION}: run \
                 `kinergy fit --field` again to make it"
            )));
        }
        let doc: Doc = kinergy_io::parse_versioned(text, FIELD_FORMAT_VERSION)
            .map_err(|e| bad(e.to_string()))?;
        doc.into_file()
            .map_err(|(field, why)| bad(said(&field, &why)))
    }

    /// Reads and checks a field file; errors name the file and the field.
    pub fn read(path: &Path) -> Result<FieldFile> {
        let text =
            kinergy_io::read_to_string_limited(path, kinergy_io::MAX_JSON_BYTES).map_err(|e| {
                TrainError::File {
                    path: Some(path.to_path_buf()),
                    why: format!("cannot read it: {e}"),
                }
            })?;
        FieldFile::from_json(&text).map_err(|e| in_file(e, path))
    }

    /// Writes the file atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        kinergy_io::write_json_text(path, &self.to_json()).map_err(|source| TrainError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// "`field` is 0: expected …", or "`field`: why" when `why` starts with a colon.
fn said(field: &str, why: &str) -> String {
    if why.starts_with(':') {
        format!("`{field}`{why}")
    } else {
        format!("`{field}` {why}")
    }
}

/// Every reach's frames, distance and arm, and one side for all: the first field that is
/// wrong (`samples[2].arm.side`) and why.
fn check_reaches(reaches: &[FittedReach]) -> std::result::Result<(), (String, String)> {
    let side = reaches.first().and_then(|r| r.arm.as_ref()).map(|a| a.side);
    for (k, reach) in reaches.iter().enumerate() {
        let [start, end] = reach.frames;
        if start >= end {
            return Err((
                format!("samples[{k}].frames"),
                format!("is [{start}, {end}]: expected [start, end) with start < end"),
            ));
        }
        if !(reach.distance_m.is_finite() && reach.distance_m >= 0.0) {
            return Err((
                format!("samples[{k}].distance_m"),
                format!("is {}: expected a finite distance ≥ 0", reach.distance_m),
            ));
        }
        let Some(arm) = &reach.arm else {
            return Err((
                format!("samples[{k}].arm"),
                "is missing: every sample records the arm it was fitted on".into(),
            ));
        };
        arm.check()
            .map_err(|(name, why)| (format!("samples[{k}].arm.{name}"), why))?;
        if Some(arm.side) != side {
            let name =
                |s: Option<kinergy_motion::Side>| s.map_or("unnamed".into(), |s| s.to_string());
            return Err((
                format!("samples[{k}].arm.side"),
                format!(
                    "is {} but sample 0's is {}: a field holds one arm's reaches (its targets \
                     are in that arm's base frame); fit each arm on its own",
                    name(arm.side),
                    name(side.flatten())
                ),
            ));
        }
    }
    Ok(())
}

/// The serialized form of a [`FieldFile`].
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Doc {
    format_version: u32,
    model: Model,
    optimizer: Optimizer,
    dof_names: Vec<String>,
    bounds: Bounds,
    /// The entries' names, in vector order (for readers; checked on load).
    names: Vec<String>,
    settings: FieldSettings,
    /// `null`: ∞, the flat field of an anchored one.
    #[serde(with = "infinite_as_null")]
    bandwidth: f64,
    #[serde(default)]
    selection: Vec<BandwidthScore>,
    /// The person's single vector the field is anchored to.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    anchor: Option<Vec<f64>>,
    /// The person's tempo law ([`FieldFile::tempo_law`]; absent in files written before it
    /// was recorded: each synthesis under its capture's own speed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    tempo_law: Option<PersonTempo>,
    /// The controller the samples were fitted under ([`FieldFile::controller`]; absent in
    /// files written before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    controller: Option<ControllerKind>,
    samples: Vec<SampleDoc>,
}

/// One sample: the reach, its own fit's distance, its target (arm base frame) and vector.
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct SampleDoc {
    clip: String,
    frames: [usize; 2],
    arm: FittedArm,
    distance_m: f64,
    /// How fast the captured hand moved (absent in files written before it was recorded).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    tempo: Option<ReachTempo>,
    target: [f64; 3],
    values: Vec<f64>,
}

impl Doc {
    fn of(file: &FieldFile) -> Doc {
        let field = &file.field;
        let space = field.space();
        Doc {
            format_version: FIELD_FORMAT_VERSION,
            model: space.model(),
            optimizer: file.optimizer,
            dof_names: space.dof_names().to_vec(),
            bounds: *space.bounds(),
            names: space.names().to_vec(),
            settings: *field.settings(),
            bandwidth: field.bandwidth(),
            selection: field.selection().to_vec(),
            anchor: field.anchor().map(<[f64]>::to_vec),
            tempo_law: file.tempo_law,
            controller: file.controller,
            samples: file
                .reaches
                .iter()
                .zip(field.targets())
                .zip(field.values())
                .map(|((r, t), values)| SampleDoc {
                    clip: r.clip.clone(),
                    frames: r.frames,
                    arm: r.arm.clone().unwrap_or_else(|| FittedArm {
                        side: None,
                        joints: Vec::new(),
                        upper_arm_m: 0.0,
                        forearm_m: 0.0,
                        hand_m: 0.0,
                    }),
                    distance_m: r.distance_m,
                    tempo: r.tempo,
                    target: [t.x, t.y, t.z],
                    values: values.clone(),
                })
                .collect(),
        }
    }

    /// The file, checked: the first field that is wrong and why.
    fn into_file(self) -> std::result::Result<FieldFile, (String, String)> {
        let err = |field: &str, why: String| (field.to_string(), why);
        self.optimizer
            .validate()
            .map_err(|e| err("optimizer", format!(": {e}")))?;
        let space = ParamSpace::new(self.model, &self.dof_names, self.bounds)
            .map_err(|e| err("bounds", format!(": {e}")))?;
        if self.names != space.names() {
            return Err(err(
                "names",
                format!(
                    "are [{}]: expected [{}] for model {} on these DoFs",
                    kinergy_io::list_some(&self.names, 8),
                    kinergy_io::list_some(space.names(), 8),
                    self.model
                ),
            ));
        }
        self.settings
            .validate()
            .map_err(|e| err("settings", format!(": {e}")))?;
        // ∞ (`null`) only for the flat field of an anchored one.
        let anchored = self.anchor.is_some();
        let positive = |v: f64| v > 0.0 && (v.is_finite() || (anchored && v == f64::INFINITY));
        if !positive(self.bandwidth) {
            return Err(err(
                "bandwidth",
                format!(
                    "is {}: expected a finite number of meters > 0{}",
                    self.bandwidth,
                    if anchored {
                        ", or null (flat)"
                    } else {
                        " (null, flat, needs an anchor)"
                    }
                ),
            ));
        }
        for (i, s) in self.selection.iter().enumerate() {
            if !(positive(s.bandwidth) && s.loo_error.is_finite() && s.loo_error >= 0.0) {
                return Err(err(
                    &format!("selection[{i}]"),
                    "expected a bandwidth > 0 (finite, or null for an anchored field) and a \
                     finite leave-one-out error ≥ 0"
                        .into(),
                ));
            }
        }
        if let Some(anchor) = &self.anchor {
            space
                .validate(anchor)
                .map_err(|e| err("anchor", format!(": {e}")))?;
        }
        if let Some(law) = &self.tempo_law {
            law.check()
                .map_err(|(name, why)| err(&format!("tempo_law.{name}"), why))?;
        }
        if self.samples.is_empty() {
            return Err(err("samples", "is empty: expected at least one".into()));
        }
        let mut targets = Vec::with_capacity(self.samples.len());
        let mut values = Vec::with_capacity(self.samples.len());
        let mut reaches = Vec::with_capacity(self.samples.len());
        for (k, s) in self.samples.into_iter().enumerate() {
            if let Some(problem) = target_problem(k, &Point3::from(s.target)) {
                return Err(problem);
            }
            space
                .validate(&s.values)
                .map_err(|e| err(&format!("samples[{k}].values"), format!(": {e}")))?;
            targets.push(Point3::from(s.target));
            values.push(s.values);
            reaches.push(FittedReach {
                clip: s.clip,
                frames: s.frames,
                distance_m: s.distance_m,
                arm: Some(s.arm),
                tempo: s.tempo,
            });
        }
        check_reaches(&reaches)?;
        Ok(FieldFile {
            field: ParamField::stored(
                space,
                targets,
                values,
                self.settings,
                BandwidthChoice {
                    bandwidth: self.bandwidth,
                    selection: self.selection,
                },
                self.anchor,
            ),
            optimizer: self.optimizer,
            reaches,
            tempo_law: self.tempo_law,
            controller: self.controller,
        })
    }
}
