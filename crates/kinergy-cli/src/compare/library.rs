//! `compare --library DIR`: a fitted library's results as a whole, from its `library.csv`
//! (`fit --per clip --out-dir DIR`, or `collect`), without refitting: per person and per
//! model, the reaches' motion distances, and the Fig. 3 chart.

use std::path::{Path, PathBuf};

use kinergy_solver::Model;
use kinergy_train::experiment::Stats;
use kinergy_train::library::{LIBRARY, LibraryTable, PersonLine};
use serde::Serialize;

use super::Args;
use super::args::model_label;
use crate::common::{Failure, emit, print_json};

/// One person's (or everyone's) line as `--json` prints it: each model's distances in mm.
#[derive(Debug, Serialize)]
struct Line {
    person: String,
    reaches: usize,
    takes: usize,
    models: Vec<(String, Stats)>,
}

impl From<PersonLine> for Line {
    fn from(l: PersonLine) -> Line {
        Line {
            person: l.person,
            reaches: l.reaches,
            takes: l.takes,
            models: l
                .models
                .into_iter()
                .map(|(m, s)| (model_label(m), s))
                .collect(),
        }
    }
}

/// The files `compare --library -o DIR` writes.
pub const FILES: [&str; 3] = ["summary.md", "fig3.svg", "fig3.png"];

/// Runs `compare --library DIR`.
pub fn run(args: &Args, library: &Path) -> Result<(), Failure> {
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

/// The summary: per person, each model's mean (min–max) distance, and the richest model's
/// reduction against S_A.
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
    for m in models {
        md.push_str(&format!(" {} |", model_label(*m)));
    }
    md.push_str(" richest vs S_A |\n|---|---|");
    md.push_str(&"---|".repeat(models.len() + 1));
    md.push('\n');
    for l in lines {
        let name = if std::ptr::eq(l, all) {
            "**all**".to_string()
        } else {
            super::holdout::md_code(&l.person)
        };
        md.push_str(&format!("| {name} | {} |", l.reaches));
        for m in models {
            let label = model_label(*m);
            match l.models.iter().find(|(x, _)| *x == label) {
                Some((_, s)) => {
                    // A model some reaches lack is said, not averaged silently over fewer.
                    let of = if s.count < l.reaches {
                        format!(", {} of {} reaches", s.count, l.reaches)
                    } else {
                        String::new()
                    };
                    md.push_str(&format!(" {:.2} ({:.2}–{:.2}{of}) |", s.mean, s.min, s.max))
                }
                None => md.push_str(" — |"),
            }
        }
        let reduction = match (l.models.first(), l.models.last()) {
            (Some((_, first)), Some((_, last))) if l.models.len() > 1 && first.mean > 0.0 => {
                format!("{:+.0} %", (last.mean / first.mean - 1.0) * 100.0)
            }
            _ => "—".into(),
        };
        md.push_str(&format!(" {reduction} |\n"));
    }
    md
}
