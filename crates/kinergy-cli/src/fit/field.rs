//! `kinergy fit --field`: after each reach's own nested fit and the person's single vector
//! (all the reaches at once), the person's parameter field over the reaches' targets (in the
//! arm's base frame), anchored to that vector, written as a field file
//! ([`kinergy_train::field::FieldFile`]), and a report of the bandwidth chosen and how well
//! the field of the other reaches predicts each reach (leave one reach out).

use std::path::Path;

use kinergy_solver::Model;
use kinergy_train::CapturedReach;
use kinergy_train::field::{FieldFile, FieldReport};
use kinergy_train::fit::{FitSettings, NestedFit};

use crate::common::{Failure, emit, print_json};

/// Refuses reaches of both arms (before any fit): a field's targets are in one arm's base
/// frame.
pub fn check_one_arm(reaches: &[CapturedReach]) -> Result<(), Failure> {
    kinergy_train::field::check_one_arm(reaches).map_err(|e| {
        Failure::Input(format!(
            "--field: {e} (--arm, or one segments file per arm)"
        ))
    })
}

/// Fits the field of the per-reach `fits` (one nested fit per reach, in order) anchored to
/// `person` (all the reaches at once), writes it to `dest` and reports.
pub fn finish(
    json: bool,
    dest: &Path,
    reaches: &[CapturedReach],
    fits: &[NestedFit],
    person: &NestedFit,
    settings: &FitSettings,
) -> Result<(), Failure> {
    let file = FieldFile::from_nested(reaches, fits, person, settings.tolerance)?;
    let output = dest.display().to_string();
    let report = FieldReport::of(&file, output, reaches, fits, person, settings.tolerance)?;
    file.write(dest).map_err(|e| Failure::task(dest, e))?;
    if json {
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
