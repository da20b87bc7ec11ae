//! `kinergy compare --per person --holdout K`: per person, the models fitted on all but the
//! last K takes (in name order) and scored on those K, against neutral parameters, against
//! every other person's vector, and — the person's parameter field of the training takes
//! (each fitted on its own) predicting each held-out take at its own target — against the
//! single vector. The experiment is [`kinergy_train::experiment::run_holdout`]; who each
//! take belongs to is the library's person rule ([`kinergy_train::who`]); this module
//! renders `DIR/holdout.csv`, `DIR/summary.md` and `--json`.

use std::time::Instant;

use kinergy_solver::Model;
use kinergy_train::CapturedReach;
use kinergy_train::experiment::{
    self, HeldOutTempo, HoldoutResults, HoldoutSettings, HoldoutSummary, Stats, Take,
};
use kinergy_train::field::FieldSettings;
use kinergy_train::who::PersonRule;
use serde::Serialize;

use super::args::{Args, model_label};
use crate::common::{Bar, Failure, emit, print_json};

/// One held-out take's row of holdout.csv.
#[derive(Debug, Serialize)]
struct CsvRow<'a> {
    person: &'a str,
    clip: &'a str,
    arm: String,
    onset: usize,
    end: usize,
    /// Whose training takes the vector was fitted on; empty for the neutral parameters.
    fitted_on: &'a str,
    model: &'static str,
    optimizer: &'static str,
    distance_m: f64,
    frames: usize,
    /// `neutral`, `vector` (one fitted vector) or `field` (the vector the person's field
    /// predicts at the take's target).
    params: &'static str,
}

/// Runs the held-out experiment on `reaches` with the options of `args` (`holdout` ≥ 1).
/// Each reach comes with the person its segments-file row names (`None` without one).
pub fn run(
    args: &Args,
    reaches: Vec<(CapturedReach, Option<String>)>,
    holdout: usize,
) -> Result<(), Failure> {
    let takes = persons(args.person.as_ref().unwrap_or(&PersonRule::Auto), reaches)?;
    let cross_model = HoldoutSettings::default_cross_model(&args.models)
        .ok_or_else(|| Failure::Input("--models needs at least one model".into()))?;
    let settings = HoldoutSettings {
        holdout,
        models: args.models.clone(),
        optimizer: args.optimizer,
        cross_model,
        fit: args.search.settings()?,
        field: Some(FieldSettings::default()),
        tempo: args.held_out_tempo.into(),
    };
    settings.fit.anneal.validate().map_err(Failure::from)?;
    experiment::check_split(&takes, holdout)
        .map_err(|e| Failure::Input(format!("--holdout {holdout}: {}", why(&e))))?;
    let persons = experiment::group_by_person(&takes).len();
    let clock = Instant::now();
    let bar = Bar::counting(persons as u64, "persons");
    let results = experiment::run_holdout(&takes, &settings, &|| bar.inc());
    bar.finish();
    let results = results.map_err(Failure::from)?;
    // Made once there is something to write: a failed run leaves no empty folder.
    crate::common::make_folder(&args.output)?;
    let seconds = clock.elapsed().as_secs_f64();

    let csv_path = args.output.join("holdout.csv");
    crate::common::write_csv(
        &csv_path,
        results.rows.iter().map(|r| CsvRow {
            person: &r.person,
            clip: &r.clip,
            arm: r.arm.map_or_else(String::new, |s| s.to_string()),
            onset: r.onset,
            end: r.end,
            fitted_on: r.params.fitted_on().unwrap_or(""),
            model: r.params.model().name(),
            optimizer: settings.optimizer.name(),
            distance_m: r.distance_m,
            frames: r.frames,
            params: r.params.kind(),
        }),
    )?;

    let summary = HoldoutSummary::of(&results, &settings);
    let report = Report::new(&summary, &results, &settings, takes.len(), seconds);
    let markdown = markdown(&report, &summary, &results, &settings);
    let md_path = args.output.join("summary.md");
    kinergy_io::write_atomic(&md_path, markdown.as_bytes())
        .map_err(|e| Failure::task(&md_path, e))?;
    if args.json {
        return print_json(&report);
    }
    emit(&format!(
        "{markdown}\nwritten: {}, {}\n",
        csv_path.display(),
        md_path.display()
    ))
}

/// Each reach with its person by `rule` ([`PersonRule::who_of_paths`]: every take the rule
/// cannot name is named at once).
fn persons(
    rule: &PersonRule,
    reaches: Vec<(CapturedReach, Option<String>)>,
) -> Result<Vec<Take>, Failure> {
    let whos = rule.who_of_paths(
        reaches
            .iter()
            .map(|(r, listed)| (std::path::Path::new(r.name()), listed.as_deref())),
    )?;
    Ok(reaches
        .into_iter()
        .zip(whos)
        .map(|((reach, _), who)| Take {
            person: who.person,
            reach,
        })
        .collect())
}

/// A setting error's reason without the field name (the flag is named instead).
fn why(e: &kinergy_train::TrainError) -> String {
    match e {
        kinergy_train::TrainError::Setting(s) => s.why.clone(),
        other => other.to_string(),
    }
}

/// One person's split and in-sample scores, as `--json` prints it.
#[derive(Debug, Serialize)]
struct SplitReport {
    person: String,
    train: Vec<String>,
    held_out: Vec<String>,
    /// Each model's mean distance on the training takes, meters.
    train_scores: Vec<(String, f64)>,
    /// Each model's fitted vector.
    values: Vec<(String, Vec<f64>)>,
    /// The field of the training takes: its bandwidth (m; `null` also when the field is
    /// flat, the single vector everywhere: see `field_flat`) and parameter-space leave-one-out
    /// error (`null` with fewer than two distinct targets).
    field_bandwidth_m: Option<f64>,
    /// True when the field chose no dependence on the target: it is the single vector.
    field_flat: Option<bool>,
    field_loo_error: Option<f64>,
    evaluations: usize,
    seconds: f64,
}

/// One line of the field-against-vector table, as `--json` prints it.
#[derive(Debug, Serialize)]
struct FieldLineReport {
    /// `null`: all persons' held-out takes together.
    person: Option<String>,
    model: String,
    field: Stats,
    vector: Stats,
    /// Whether the field's mean distance is at most the single vector's.
    field_at_least_as_good: bool,
}

/// One line of the own-vector table, as `--json` prints it.
#[derive(Debug, Serialize)]
struct LineReport {
    /// `null`: all persons' held-out takes together.
    person: Option<String>,
    neutral: Stats,
    models: Vec<(String, Stats)>,
}

/// The held-out summary as `--json` prints it.
#[derive(Debug, Serialize)]
struct Report {
    takes: usize,
    holdout: usize,
    optimizer: &'static str,
    seconds: f64,
    budget: usize,
    seed: u64,
    splits: Vec<SplitReport>,
    own: Vec<LineReport>,
    /// The field of each person's training takes against the single vector of the same
    /// model, on the held-out takes.
    field: Vec<FieldLineReport>,
    cross_model: &'static str,
    persons: Vec<String>,
    /// `cross[i][j]`: person i's vector on person j's held-out takes, mean distance, meters.
    cross: Vec<Vec<f64>>,
    /// Per person: whether its own vector is the best on its held-out takes.
    own_vector_wins: Vec<bool>,
}

impl Report {
    fn new(
        summary: &HoldoutSummary,
        results: &HoldoutResults,
        settings: &HoldoutSettings,
        takes: usize,
        seconds: f64,
    ) -> Report {
        let name = |m: Model| m.name().to_string();
        Report {
            takes,
            holdout: settings.holdout,
            optimizer: settings.optimizer.name(),
            seconds,
            budget: settings.fit.anneal.max_evaluations,
            seed: settings.fit.anneal.seed,
            splits: results
                .fits
                .iter()
                .map(|f| SplitReport {
                    person: f.person.clone(),
                    train: f.train.clone(),
                    held_out: f.held_out.clone(),
                    train_scores: f.models.iter().map(|(m, _, s)| (name(*m), *s)).collect(),
                    values: f
                        .models
                        .iter()
                        .map(|(m, v, _)| (name(*m), v.clone()))
                        .collect(),
                    field_bandwidth_m: f.field.as_ref().map(|x| x.field().bandwidth()),
                    field_flat: f
                        .field
                        .as_ref()
                        .map(|x| x.field().bandwidth().is_infinite()),
                    field_loo_error: f.field.as_ref().and_then(|x| x.loo_error()),
                    evaluations: f.evaluations,
                    seconds: f.seconds,
                })
                .collect(),
            own: summary
                .own
                .iter()
                .map(|l| LineReport {
                    person: l.person.clone(),
                    neutral: l.neutral,
                    models: l.models.iter().map(|(m, s)| (name(*m), *s)).collect(),
                })
                .collect(),
            field: summary
                .field
                .iter()
                .map(|l| FieldLineReport {
                    person: l.person.clone(),
                    model: name(l.model),
                    field: l.field,
                    vector: l.vector,
                    field_at_least_as_good: l.field.mean <= l.vector.mean,
                })
                .collect(),
            cross_model: summary.cross_model.name(),
            persons: summary.persons.clone(),
            cross: summary.cross.clone(),
            own_vector_wins: summary.own_vector_wins(),
        }
    }
}

/// summary.md of the held-out experiment: the own-vector table, the person × person table
/// and the in-sample scores.
fn markdown(
    report: &Report,
    summary: &HoldoutSummary,
    results: &HoldoutResults,
    settings: &HoldoutSettings,
) -> String {
    let mm = |v: f64| format!("{:.2}", v * 1e3);
    let persons = summary.persons.len();
    let mut md = String::new();
    md.push_str("# Per person, on held-out takes\n\n");
    md.push_str(&format!(
        "{} takes of {persons} person{}; per person the last {} take{} in name order held out, the models fitted (nested) on the rest; {}; {}; {:.1} s wall.\nDistances are the mean joint-position motion distance (shoulder, elbow, wrist, hand) of the held-out takes, each synthesized from its own start posture to its own target {}, in millimeters.\n\n",
        report.takes,
        if persons == 1 { "" } else { "s" },
        settings.holdout,
        if settings.holdout == 1 { "" } else { "s" },
        settings.optimizer.name().to_uppercase(),
        super::search_line(&settings.fit),
        report.seconds,
        match settings.tempo {
            HeldOutTempo::Person => "under the fitted person's tempo law (the smooth controller bounded as their reach over that distance, not as the held-out capture moved: `--held-out-tempo person`)",
            HeldOutTempo::Capture => "under the held-out capture's own speed (`--held-out-tempo capture`: the synthesis is told how fast the take moved)",
        }
    ));
    let models: Vec<Model> = summary
        .own
        .first()
        .map(|l| l.models.iter().map(|(m, _)| *m).collect())
        .unwrap_or_default();
    md.push_str("## Own vector against neutral — held-out takes, mean (min–max)\n\n| person | takes fitted / held out | neutral (S_A, g = 1) |");
    for m in &models {
        md.push_str(&format!(" {} |", model_label(*m)));
    }
    md.push_str(" best against neutral |\n|---|---|---|");
    md.push_str(&"---|".repeat(models.len() + 1));
    md.push('\n');
    let cell = |s: &Stats| format!("{} ({}–{})", mm(s.mean), mm(s.min), mm(s.max));
    for line in &summary.own {
        let split = match &line.person {
            Some(p) => results
                .fits
                .iter()
                .find(|f| &f.person == p)
                .map_or("—".into(), |f| {
                    format!("{} / {}", f.train.len(), f.held_out.len())
                }),
            None => {
                let train: usize = results.fits.iter().map(|f| f.train.len()).sum();
                let held: usize = results.fits.iter().map(|f| f.held_out.len()).sum();
                format!("{train} / {held}")
            }
        };
        let name = line
            .person
            .as_deref()
            .map_or("**all**".to_string(), md_code);
        md.push_str(&format!("| {name} | {split} | {} |", cell(&line.neutral)));
        for (_, s) in &line.models {
            md.push_str(&format!(" {} |", cell(s)));
        }
        let best = line
            .models
            .iter()
            .min_by(|a, b| a.1.mean.total_cmp(&b.1.mean))
            .map_or("—".into(), |(m, s)| {
                format!(
                    "{} {:+.0} %",
                    model_label(*m),
                    100.0 * (s.mean / line.neutral.mean - 1.0)
                )
            });
        md.push_str(&format!(" {best} |\n"));
    }
    md.push_str(&cross_table(summary));
    if !summary.field.is_empty() {
        md.push_str(&field_table(summary, results));
    }
    // A field holds one arm's reaches: a person whose takes reach with both has none.
    let without: Vec<String> = results
        .fits
        .iter()
        .filter(|f| f.field.is_none())
        .map(|f| md_code(&f.person))
        .collect();
    if settings.field.is_some() && !without.is_empty() {
        md.push_str(&format!(
            "
No parameter field for {}: their takes reach with both arms, and a field holds \
             one arm's reaches (its targets are in that arm's base frame); their single vector \
             is fitted on both.\n",
            without.join(", ")
        ));
    }
    md.push_str("\n## In sample — the same vectors on the training takes, mean\n\n| person |");
    for m in &models {
        md.push_str(&format!(" {} |", model_label(*m)));
    }
    md.push_str("\n|---|");
    md.push_str(&"---|".repeat(models.len()));
    md.push('\n');
    for f in &results.fits {
        md.push_str(&format!("| {} |", md_code(&f.person)));
        for (_, _, score) in &f.models {
            md.push_str(&format!(" {} |", mm(*score)));
        }
        md.push('\n');
    }
    md
}

/// The person × person table of [`markdown`]: each person's vector on every person's
/// held-out takes, and how often the own vector wins.
fn cross_table(summary: &HoldoutSummary) -> String {
    let mm = |v: f64| format!("{:.2}", v * 1e3);
    let persons = summary.persons.len();
    let mut md = String::new();
    let cm = model_label(summary.cross_model);
    md.push_str(&format!(
        "\n## Person × person — each person's {cm} vector on every person's held-out takes, mean\n\n| vector of ↓ · takes of → |"
    ));
    for p in &summary.persons {
        md.push_str(&format!(" {} |", md_code(p)));
    }
    md.push_str("\n|---|");
    md.push_str(&"---|".repeat(persons));
    md.push('\n');
    for (i, p) in summary.persons.iter().enumerate() {
        md.push_str(&format!("| {} |", md_code(p)));
        for j in 0..persons {
            let v = mm(summary.cross[i][j]);
            if i == j {
                md.push_str(&format!(" **{v}** |"));
            } else {
                md.push_str(&format!(" {v} |"));
            }
        }
        md.push('\n');
    }
    let wins = summary.own_vector_wins();
    let losers: Vec<&str> = summary
        .persons
        .iter()
        .zip(&wins)
        .filter(|(_, w)| !**w)
        .map(|(p, _)| p.as_str())
        .collect();
    md.push_str(&format!(
        "\nThe diagonal (bold) is the person's own vector. Own vector best on its own held-out takes: {} of {persons}{}.\n",
        wins.iter().filter(|w| **w).count(),
        if losers.is_empty() {
            String::new()
        } else {
            format!(
                " (not for {})",
                losers
                    .iter()
                    .map(|p| format!("`{p}`"))
                    .collect::<Vec<_>>()
                    .join(", ")
            )
        }
    ));
    md
}

/// The field against the single vector: per person, the held-out takes' distances with the
/// vector the field of the training takes predicts at each take's target, beside the single
/// vector of the same model fitted on the same takes.
fn field_table(summary: &HoldoutSummary, results: &HoldoutResults) -> String {
    let mm = |v: f64| format!("{:.2}", v * 1e3);
    let Some(model) = summary.field.first().map(|l| model_label(l.model)) else {
        return String::new();
    };
    let mut md = format!(
        "\n## Parameter field against the single vector — held-out takes, mean (min–max)\n\n\
         Each training take fitted on its own (nested up to {model}), the field of those vectors \
         over their targets in the arm's base frame (Gaussian kernel, Nadaraya–Watson), anchored \
         to the single {model} vector fitted on all the training takes (that vector plus how the \
         takes vary with the target; bandwidth by leave-one-out on the motion, *flat*: no \
         dependence found, the vector itself), evaluated at each held-out take's own target; \
         beside it that single vector.\n\n\
         | person | field ({model}) | single vector ({model}) | field − vector | bandwidth |\n\
         |---|---|---|---|---|\n"
    );
    let cell = |s: &Stats| format!("{} ({}–{})", mm(s.mean), mm(s.min), mm(s.max));
    for line in &summary.field {
        let name = line
            .person
            .as_deref()
            .map_or("**all**".to_string(), md_code);
        let bandwidth = line
            .person
            .as_deref()
            .and_then(|p| results.fits.iter().find(|f| f.person == p))
            .and_then(|f| f.field.as_ref())
            .map_or("—".to_string(), |f| {
                let h = f.field().bandwidth();
                if h.is_infinite() {
                    "flat".to_string()
                } else {
                    format!("{:.0} mm", h * 1e3)
                }
            });
        md.push_str(&format!(
            "| {name} | {} | {} | {:+.2} mm | {bandwidth} |\n",
            cell(&line.field),
            cell(&line.vector),
            (line.field.mean - line.vector.mean) * 1e3
        ));
    }
    let (better, persons): (usize, usize) = summary
        .field
        .iter()
        .filter(|l| l.person.is_some())
        .fold((0, 0), |(b, n), l| {
            (b + usize::from(l.field.mean <= l.vector.mean), n + 1)
        });
    md.push_str(&format!(
        "\nThe field is at least as good as the single vector for {better} of {persons} person{}.\n",
        if persons == 1 { "" } else { "s" }
    ));
    md
}

/// `text` as an inline code span in a Markdown table cell: a fence of one backtick more than
/// the longest run inside (padded where the text starts or ends with one), `|` escaped (GFM
/// splits cells on it even inside code) and line breaks as spaces. A person named `a|b` or
/// with a backtick broke the tables' columns.
pub(super) fn md_code(text: &str) -> String {
    let mut longest = 0;
    let mut run = 0;
    for c in text.chars() {
        run = if c == '`' { run + 1 } else { 0 };
        longest = longest.max(run);
    }
    let fence = "`".repeat(longest + 1);
    let pad = if text.starts_with('`') || text.ends_with('`') {
        " "
    } else {
        ""
    };
    let body = text.replace('|', "\\|").replace(['\n', '\r'], " ");
    format!("{fence}{pad}{body}{pad}{fence}")
}

#[cfg(test)]
mod md_tests {
    use super::md_code;

    #[test]
    fn a_person_name_stays_in_its_cell() {
        assert_eq!(md_code("active"), "`active`");
        assert_eq!(md_code("a|b"), "`a\\|b`");
        assert_eq!(md_code("a`b"), "``a`b``");
        assert_eq!(md_code("`x"), "`` `x ``");
        assert_eq!(md_code("two\nlines"), "`two lines`");
        // A GFM table row splits on `|` not preceded by a backslash: this row has two cells.
        let row = format!("| {} | 1 |", md_code("x|y|z"));
        let bars = row
            .char_indices()
            .filter(|&(i, c)| c == '|' && !row[..i].ends_with('\\'))
            .count();
        assert_eq!(bars, 3, "{row}");
    }
}
