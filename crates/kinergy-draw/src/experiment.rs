//! The paper's bar charts of the synergy experiments ([`kinergy_train::experiment`]): Fig. 3
//! (per model) and Fig. 4 (per optimizer, S_A and S_C), the mean motion distance to the
//! capture with min–max whiskers, in millimetres — from a run's results ([`fig3`], [`fig4`],
//! [`save_figures`]) or from a fitted library's table ([`library_fig3`]).

use std::path::{Path, PathBuf};

use kinergy_solver::{Model, OptimizerKind};
use kinergy_train::experiment::{Method, Results, Stats};
use kinergy_train::library::PersonLine;

use crate::{Bar, BarChart, DrawError, save};

/// The size of every experiment chart, pixels.
pub const SIZE: (u32, u32) = (800, 500);

/// A model as the charts and tables name it: `S_A` for `sa`.
pub fn model_label(model: Model) -> String {
    model.name().to_uppercase().replacen('S', "S_", 1)
}

/// One bar of `series`: the nested fits' distances of `model` with `optimizer`, mm (none
/// without a fit).
fn bar(results: &Results, series: usize, model: Model, optimizer: OptimizerKind) -> Option<Bar> {
    Stats::of(
        results
            .select(model, optimizer, Method::NestedAnnealing)
            .map(|r| r.distance_m * 1e3),
    )
    .map(|s| bar_of(series, &s))
}

fn bar_of(series: usize, s: &Stats) -> Bar {
    Bar {
        series,
        mean: s.mean,
        min: s.min,
        max: s.max,
    }
}

/// Fig. 3: each of `models` (sorted, once each) fitted with `optimizer`.
pub fn fig3(results: &Results, models: &[Model], optimizer: OptimizerKind) -> BarChart {
    let mut models = models.to_vec();
    models.sort();
    models.dedup();
    BarChart {
        title: format!(
            "Fig. 3: synergy models ({}, {} clips)",
            optimizer.name().to_uppercase(),
            results.clip_count()
        ),
        x_label: "synergy model".into(),
        y_label: "motion distance to the capture (mm)".into(),
        series: vec!["mean, min–max".into()],
        groups: models
            .iter()
            .filter_map(|&m| {
                let b = bar(results, 0, m, optimizer)?;
                Some((model_label(m), vec![b]))
            })
            .collect(),
    }
}

/// Fig. 4: each of `optimizers` with S_A and with S_C.
pub fn fig4(results: &Results, optimizers: &[OptimizerKind]) -> BarChart {
    BarChart {
        title: "Fig. 4: optimizers with S_A and S_C".into(),
        x_label: "optimizer".into(),
        y_label: "motion distance to the capture (mm)".into(),
        series: vec!["S_A".into(), "S_C".into()],
        groups: optimizers
            .iter()
            .map(|&o| {
                let bars = [bar(results, 0, Model::Sa, o), bar(results, 1, Model::Sc, o)]
                    .into_iter()
                    .flatten()
                    .collect();
                (o.name().to_uppercase(), bars)
            })
            .collect(),
    }
}

/// Draws [`fig3`] and [`fig4`] as `dir/fig3.svg|png` and `dir/fig4.svg|png`, leaving out a
/// chart without a bar; returns the files written.
pub fn save_figures(
    results: &Results,
    models: &[Model],
    optimizers: &[OptimizerKind],
    optimizer: OptimizerKind,
    dir: &Path,
) -> Result<Vec<PathBuf>, DrawError> {
    let fig3 = fig3(results, models, optimizer);
    let fig4 = fig4(results, optimizers);
    let mut written = Vec::new();
    for (name, chart) in [("fig3", &fig3), ("fig4", &fig4)] {
        if chart.groups.iter().all(|g| g.1.is_empty()) {
            continue;
        }
        for ext in ["svg", "png"] {
            let path = dir.join(format!("{name}.{ext}"));
            save(chart, &path, SIZE)?;
            written.push(path);
        }
    }
    Ok(written)
}

/// Fig. 3 of a fitted library: the `all` line's models (its distances already in mm), over
/// `persons` persons.
pub fn library_fig3(all: &PersonLine, persons: usize) -> BarChart {
    BarChart {
        title: format!(
            "Fig. 3: synergy models ({} reaches of {persons} persons)",
            all.reaches
        ),
        x_label: "synergy model".into(),
        y_label: "motion distance to the capture (mm)".into(),
        series: vec!["mean, min–max".into()],
        groups: all
            .models
            .iter()
            .map(|(m, s)| (model_label(*m), vec![bar_of(0, s)]))
            .collect(),
    }
}

/// The page `compare -o DIR` writes beside its charts: [`VIEW`].
pub const VIEW: &str = "view.html";

/// `DIR/view.html` ([`VIEW`]): the first reach of a run, captured (`captured`: the capture
/// cut to the reach's frames), beside each model's motion of it (`motions`, from
/// [`kinergy_train::experiment::fig3_clips`]), overlaid in the browser ([`crate::viewer`]) with
/// the hand of `side` on the speed chart, the target, and Fig. 3 (`fig3.svg` in `dir`, where
/// it was drawn) under it — the paper's Fig. 6, to turn around and play.
pub fn save_view(
    dir: &Path,
    name: &str,
    captured: &kinergy_motion::Clip,
    motions: &[(Model, kinergy_motion::Clip)],
    side: Option<kinergy_motion::Side>,
    target: kinergy_motion::nalgebra::Point3<f64>,
) -> Result<PathBuf, DrawError> {
    use crate::viewer::{Hand, ViewerClip, ViewerPage, page_html};
    let hand = side.map_or(Hand::Auto, Hand::Side);
    let path = Path::new(name);
    let short = path
        .file_stem()
        .map_or_else(|| name.to_string(), |s| s.to_string_lossy().into_owned());
    let mut clips = vec![ViewerClip::of_clip(
        captured,
        path,
        format!("{short} (captured)"),
        hand,
    )?];
    for (model, motion) in motions {
        clips.push(ViewerClip::of_clip(
            motion,
            path,
            format!("{short} ({})", model.paper_name()),
            hand,
        )?);
    }
    let figures = std::fs::read_to_string(dir.join("fig3.svg"))
        .ok()
        .map(|svg| {
            vec![(
                "Fig. 3: each model's mean distance to the captures".to_string(),
                svg,
            )]
        })
        .unwrap_or_default();
    let page = ViewerPage {
        title: format!("{short}: captured and each model's synthesis"),
        clips,
        target: Some(target),
        figures,
        ..ViewerPage::default()
    };
    let html = page_html(&page)?;
    let out = dir.join(VIEW);
    kinergy_io::write_atomic(&out, html.as_bytes()).map_err(|e| DrawError::io(&out, e))?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn models_are_labelled_as_in_the_paper() {
        assert_eq!(model_label(Model::Sa), "S_A");
        assert_eq!(model_label(Model::Sd), "S_D");
    }
}
