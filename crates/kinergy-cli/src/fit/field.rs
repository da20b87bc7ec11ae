//! `kinergy fit --field`: after each reach's own nested fit and the person's single vector
//! (all the reaches at once), the person's parameter field over the reaches' targets (in the
//! arm's base frame), anchored to that vector, written as a field file
//! ([`kinergy_train::field::FieldFile`]), and a report of the bandwidth chosen and how well
//! the field of the other reaches predicts each reach (leave one reach out).

use std::path::Path;

use kinergy_solver::Model;
use kinergy_train::CapturedReach;
use kinergy_train::field::{BandwidthScore, FieldFile, FieldSettings};
use kinergy_train::fit::{Fit, FitSettings, NestedFit};
use serde::Serialize;

use super::args::Args;
use crate::common::{Failure, emit, print_json};

/// One reach of the field, as the report shows it.
#[derive(Debug, Serialize)]
struct SampleRow {
    clip: String,
    frames: [usize; 2],
    side: Option<String>,
    /// The target in the arm's base frame on the reach's first frame, meters.
    target_m: [f64; 3],
    /// The reach's own fit's distance, meters.
    distance_m: f64,
    /// The distance with the vector the field of the other reaches predicts, meters.
    loo_distance_m: Option<f64>,
}

/// The report of `kinergy fit --field`.
#[derive(Debug, Serialize)]
struct FieldReport {
    output: String,
    per: &'static str,
    kind: &'static str,
    optimizer: &'static str,
    model: &'static str,
    /// The bandwidth in use, meters; `null` when the field is flat: the person's single
    /// vector everywhere (the reaches show no dependence on the target).
    bandwidth_m: f64,
    /// The person's single vector's mean distance over all the reaches (the field's
    /// anchor), meters.
    anchor_distance_m: f64,
    /// The parameter-space leave-one-out error of that bandwidth (RMS over samples and
    /// entries, each relative to its bound width); `null` when there was nothing to choose
    /// from (fewer than two distinct targets).
    loo_error: Option<f64>,
    /// Every bandwidth tried, with its leave-one-out error.
    selection: Vec<BandwidthScore>,
    /// Mean over the reaches of their own fits' distances, meters.
    own_distance_m: f64,
    /// Mean over the reaches of their distance with the field of the other reaches (`null`
    /// with a single reach), meters.
    loo_distance_m: Option<f64>,
    samples: Vec<SampleRow>,
    nested_violations: Vec<String>,
}

/// Refuses reaches of both arms (before any fit): a field's targets are in one arm's base
/// frame.
pub fn check_one_arm(reaches: &[CapturedReach]) -> Result<(), Failure> {
    let Some(first) = reaches.first() else {
        return Ok(());
    };
    let side = first.fitted_arm().side;
    if let Some(other) = reaches.iter().find(|r| r.fitted_arm().side != side) {
        let name = |s: Option<kinergy_motion::Side>| s.map_or("unnamed".into(), |s| s.to_string());
        return Err(Failure::Input(format!(
            "--field: {} is a reach of the {} arm and {} of the {} arm; a field holds one \
             arm's reaches (its targets are in that arm's base frame): fit each arm on its own \
             (--arm, or one segments file per arm)",
            first.name(),
            name(side),
            other.name(),
            name(other.fitted_arm().side)
        )));
    }
    Ok(())
}

/// Fits the field of the per-reach `fits` (one nested fit per reach, in order) anchored to
/// `person` (all the reaches at once), writes it to `dest` and reports.
pub fn finish(
    args: &Args,
    dest: &Path,
    reaches: &[CapturedReach],
    fits: &[NestedFit],
    person: &NestedFit,
    settings: &FitSettings,
) -> Result<(), Failure> {
    let last: Vec<Fit> = fits.iter().filter_map(|f| f.fits.last().cloned()).collect();
    let anchor = person
        .fits
        .last()
        .ok_or_else(|| Failure::Task("no model was fitted".into()))?;
    let file = FieldFile::from_fits(reaches, &last, &FieldSettings::default())
        .and_then(|f| f.anchored(anchor.values.clone(), reaches, settings.tolerance))
        .map_err(Failure::from)?;
    let loo = if reaches.len() >= 2 {
        Some(
            file.leave_one_out(reaches, settings.tolerance)
                .map_err(Failure::from)?,
        )
    } else {
        None
    };
    file.write(dest).map_err(|e| Failure::task(dest, e))?;

    let mean = |v: &mut dyn Iterator<Item = f64>| {
        let (sum, n) = v.fold((0.0, 0usize), |(s, n), x| (s + x, n + 1));
        sum / n.max(1) as f64
    };
    let samples: Vec<SampleRow> = file
        .reaches()
        .iter()
        .zip(file.field().targets())
        .enumerate()
        .map(|(k, (r, t))| SampleRow {
            clip: r.clip.clone(),
            frames: r.frames,
            side: r.arm.as_ref().and_then(|a| a.side).map(|s| s.to_string()),
            target_m: [t.x, t.y, t.z],
            distance_m: r.distance_m,
            loo_distance_m: loo.as_ref().map(|rows| rows[k].field_distance),
        })
        .collect();
    let report = FieldReport {
        output: dest.display().to_string(),
        per: "person",
        kind: "field",
        optimizer: args.optimizer.name(),
        model: file.model().name(),
        bandwidth_m: file.field().bandwidth(),
        anchor_distance_m: anchor.score,
        loo_error: file.loo_error(),
        selection: file.field().selection().to_vec(),
        own_distance_m: mean(&mut samples.iter().map(|s| s.distance_m)),
        loo_distance_m: loo
            .as_ref()
            .map(|rows| mean(&mut rows.iter().map(|r| r.field_distance))),
        samples,
        nested_violations: fits
            .iter()
            .zip(reaches)
            .flat_map(|(f, r)| {
                f.violations().into_iter().map(move |(a, b)| {
                    format!("{}: {} ended worse than {}", r.name(), b.name(), a.name())
                })
            })
            .collect(),
    };
    if args.json {
        return print_json(&report);
    }
    emit(&text(&report, file.model()))
}

fn text(r: &FieldReport, model: Model) -> String {
    let mm = |m: f64| format!("{:.3} mm", m * 1e3);
    let mut s = format!(
        "{} (field of {} reach{}, {}, {}; targets in the arm's base frame):\n",
        r.output,
        r.samples.len(),
        if r.samples.len() == 1 { "" } else { "es" },
        r.optimizer,
        model.name()
    );
    s.push_str(&format!(
        "  anchored to the person's single vector ({} over all the reaches)\n",
        mm(r.anchor_distance_m)
    ));
    s.push_str(&match r.loo_error {
        Some(e) if r.bandwidth_m.is_infinite() => format!(
            "  flat: the person's vector everywhere, chosen by leave-one-out among {} \
             (parameter error {:.1} % of the bounds): the reaches show no dependence on the target\n",
            r.selection.len(),
            e * 100.0
        ),
        Some(e) => format!(
            "  bandwidth {:.3} m, chosen by leave-one-out among {} (parameter error {:.1} % of the bounds)\n",
            r.bandwidth_m,
            r.selection.len(),
            e * 100.0
        ),
        None => format!(
            "  bandwidth {:.3} m (fewer than two distinct targets: the field is constant)\n",
            r.bandwidth_m
        ),
    });
    if let Some(d) = r.loo_distance_m {
        s.push_str(&format!(
            "  leave one reach out: {} with the field of the other reaches, {} with each reach's own fit (means)\n",
            mm(d),
            mm(r.own_distance_m)
        ));
    }
    for sample in &r.samples {
        s.push_str(&format!(
            "  {}  frames {}..{}{}  target ({:.3}, {:.3}, {:.3}) m  own fit {}{}\n",
            sample.clip,
            sample.frames[0],
            sample.frames[1],
            sample
                .side
                .as_ref()
                .map_or_else(String::new, |side| format!("  {side} arm")),
            sample.target_m[0],
            sample.target_m[1],
            sample.target_m[2],
            mm(sample.distance_m),
            sample
                .loo_distance_m
                .map_or_else(String::new, |d| format!("  field of the others {}", mm(d)))
        ));
    }
    for v in &r.nested_violations {
        s.push_str(&format!("  note: {v}\n"));
    }
    s
}
