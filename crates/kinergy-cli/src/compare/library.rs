//! `compare --library DIR`: a fitted library's results as a whole, from its `library.csv`
//! (`fit --per clip --out-dir DIR`, or `collect`), without refitting: per person, per motion
//! (where the takes' motions are known) and per model, the reaches' motion distances, and
//! the Fig. 3 chart.

use std::path::{Path, PathBuf};

use kinergy_solver::Model;
use kinergy_train::experiment::Stats;
use kinergy_train::library::{LIBRARY, LibraryTable, PersonLine};
use serde::Serialize;

use super::Args;
use super::args::model_label;
use crate::common::{Failure, emit, print_json};

/// One person's (or everyone's) line as `--json` prints it: each model's distances in mm,
/// and per motion where motions are known.
#[derive(Debug, Serialize)]
struct Line {
    person: String,
    reaches: usize,
    takes: usize,
    models: Vec<(String, Stats)>,
    #[serde(skip_serializing_if = "Vec::is_empty")]
    motions: Vec<Motion>,
}

/// One motion's line (of a person, or of everyone) as `--json` prints it.
#[derive(Debug, Serialize)]
struct Motion {
    /// Empty: reaches of no known motion.
    motion: String,
    persons: usize,
    reaches: usize,
    takes: usize,
    models: Vec<(String, Stats)>,
}

fn labelled(models: Vec<(Model, Stats)>) -> Vec<(String, Stats)> {
    models
        .into_iter()
        .map(|(m, s)| (model_label(m), s))
        .collect()
}

impl From<PersonLine> for Line {
    fn from(l: PersonLine) -> Line {
        Line {
            person: l.person,
            reaches: l.reaches,
            takes: l.takes,
            models: labelled(l.models),
            motions: l
                .motions
                .into_iter()
                .map(|m| Motion {
                    motion: m.motion,
                    persons: m.persons,
                    reaches: m.reaches,
                    takes: m.takes,
                    models: labelled(m.models),
                })
                .collect(),
        }
    }
}

/// The files `compare --library -o DIR` writes.
pub const FILES: [&str; 3] = ["summary.md", "fig3.svg", "fig3.png"];

/// Runs `compare --library DIR`.
pub fn run(args: &Args, library: &Path) -> Result<(), Failure> {
    if args.person.is_some() {
        return Err(Failure::Input(format!(
            "--person with --library: a library's persons are named as it is tabled: \
             `kinergy collect {} --person RULE`, then compare --library",
            library.display()
        )));
    }
    let table = if library.is_dir() {
        library.join(LIBRARY)
    } else {
        library.to_path_buf()
    };
    let files: Vec<PathBuf> = FILES.iter().map(|f| args.output.join(f)).collect();
    crate::common::check_outputs(
        &[&table],
        &[crate::common::Output::Folder("-o", &args.output, &files)],
    )?;
    let library = LibraryTable::read(&table)?;
    if library.rows.is_empty() {
        return Err(Failure::Input(format!(
            "{}: no reach: nothing to compare",
            table.display()
        )));
    }
    let by_person = library.by_person();
    let all = by_person.last().expect("the all line");
    let chart = kinergy_draw::experiment::library_fig3(all, by_person.len() - 1);
    let lines: Vec<Line> = by_person.into_iter().map(Line::from).collect();
    let models = library.models();
    let markdown = markdown(&table, &lines, &models);
    crate::common::make_folder(&args.output)?;
    let md = args.output.join("summary.md");
    kinergy_io::write_atomic(&md, markdown.as_bytes()).map_err(|e| Failure::task(&md, e))?;
    let size = kinergy_draw::experiment::SIZE;
    kinergy_draw::save_both(&chart, &args.output, "fig3", size)?;
    if args.json {
        return print_json(&lines);
    }
    emit(&format!(
        "{markdown}\nwritten: {}, {} and {}\n",
        md.display(),
        args.output.join("fig3.svg").display(),
        args.output.join("fig3.png").display()
    ))
}

/// The summary: per person, then per motion where motions are known, each model's mean
/// (min–max) distance, and the richest model's reduction against S_A.
fn markdown(table: &Path, lines: &[Line], models: &[Model]) -> String {
    let all = &lines[lines.len() - 1];
    let mut md = format!(
        "# A library's fits, per person and model\n\n{} reaches of {} takes, {} persons, from \
         `{}` (nested fits: each model's distance is that of its stage). Mean motion distance \
         to the capture, mm (min–max).\n\n| person | reaches |",
        all.reaches,
        all.takes,
        lines.len() - 1,
        table.display()
    );
    md.push_str(&model_header(models, 2));
    for l in lines {
        let name = if std::ptr::eq(l, all) {
            "**all**".to_string()
        } else {
            super::holdout::md_code(&l.person)
        };
        md.push_str(&format!("| {name} | {} |", l.reaches));
        md.push_str(&model_cells(&l.models, l.reaches, models));
    }
    if !all.motions.is_empty() {
        let known = all.motions.iter().filter(|m| !m.motion.is_empty()).count();
        md.push_str(&format!(
            "\n## Per motion\n\n{known} motion{} (as the person rule or the takes' names say \
             them), every person's reaches of each.\n\n| motion | persons | reaches |",
            if known == 1 { "" } else { "s" }
        ));
        md.push_str(&model_header(models, 3));
        for m in &all.motions {
            let name = if m.motion.is_empty() {
                "*no known motion*".to_string()
            } else {
                super::holdout::md_code(&m.motion)
            };
            md.push_str(&format!("| {name} | {} | {} |", m.persons, m.reaches));
            md.push_str(&model_cells(&m.models, m.reaches, models));
        }
    }
    md
}

/// The model columns' headers, after the `leading` first columns' headers, and the
/// table's rule.
fn model_header(models: &[Model], leading: usize) -> String {
    let mut md = String::new();
    for m in models {
        md.push_str(&format!(" {} |", model_label(*m)));
    }
    md.push_str(" richest vs S_A |\n|");
    md.push_str(&"---|".repeat(leading + models.len() + 1));
    md.push('\n');
    md
}

/// A line's model cells — each model's mean (min–max) over its `reaches` — and the richest
/// model's reduction against S_A, ending the row.
fn model_cells(line: &[(String, Stats)], reaches: usize, models: &[Model]) -> String {
    let mut md = String::new();
    for m in models {
        let label = model_label(*m);
        match line.iter().find(|(x, _)| *x == label) {
            Some((_, s)) => {
                // A model some reaches lack is said, not averaged silently over fewer.
                let of = if s.count < reaches {
                    format!(", {} of {reaches} reaches", s.count)
                } else {
                    String::new()
                };
                md.push_str(&format!(" {:.2} ({:.2}–{:.2}{of}) |", s.mean, s.min, s.max))
            }
            None => md.push_str(" — |"),
        }
    }
    let reduction = match (line.first(), line.last()) {
        (Some((_, first)), Some((_, last))) if line.len() > 1 && first.mean > 0.0 => {
            format!("{:+.0} %", (last.mean / first.mean - 1.0) * 100.0)
        }
        _ => "—".into(),
    };
    md.push_str(&format!(" {reduction} |\n"));
    md
}
