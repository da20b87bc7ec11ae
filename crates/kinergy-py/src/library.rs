//! A library of captures from Python: `fit(..., per="clip", out_dir=DIR, shard=, resume=)`
//! runs a shard of it and `collect(DIR)` tables it, with the library's own run, files and
//! checks ([`kinergy_train::library`]) — the bytes `kinergy fit --out-dir` and `kinergy
//! collect` write.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use kinergy_train::anneal::Observer;
use kinergy_train::fit::FitJob;
use kinergy_train::library::{Shard, ShardEvent, ShardRun, Takes};
use kinergy_train::segments_file::SegmentsFile;
use kinergy_train::source::{ReachQuery, nothing_found, segment_clips};
use kinergy_train::who::PersonRule;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::args::{on_pool, to_python};
use crate::errors;
use crate::progress::watched;

/// A library fit as `fit(..., out_dir=)` asks for it.
pub struct LibraryFit {
    /// The captures given: paths (files or folders; not Clips, whose results would have
    /// no name), none with a segments file alone.
    pub clips: Vec<PathBuf>,
    /// The segments file.
    pub segments: Option<PathBuf>,
    /// How each take's reaches are found.
    pub query: ReachQuery,
    /// How each reach is fitted.
    pub job: FitJob,
    /// The library folder.
    pub dir: PathBuf,
    /// This run's share of the takes.
    pub shard: Shard,
    /// Keep the results already complete.
    pub resume: bool,
    /// Who moves in each take.
    pub person: PersonRule,
    /// Each person's, motion's and arm's reaches fitted from the first one's fit.
    pub warm_start: bool,
    /// The worker threads (None: rayon's global pool).
    pub pool: Option<rayon::ThreadPool>,
}

/// Runs a shard of the library of `source` into `dir` and, with one shard, collects it.
/// Returns a dict: `dir`, `shard` (I, N), `takes` (dealt to the shard), `fitted`, `skipped`
/// (a list of (clip, why)), `record`, and with one shard `rows` (library.csv's rows).
pub fn fit_library<'py>(py: Python<'py>, fit: LibraryFit) -> PyResult<Bound<'py, PyDict>> {
    let LibraryFit {
        clips,
        segments: segments_path,
        query,
        job,
        dir,
        shard,
        resume,
        person,
        warm_start,
        pool,
    } = fit;
    let dir = dir.as_path();
    job.validate().map_err(errors::raise)?;
    if dir.exists() && !dir.is_dir() {
        return Err(errors::input(format!(
            "out_dir={}: not a folder",
            dir.display()
        )));
    }
    let segments = segments_path
        .as_deref()
        .map(SegmentsFile::read)
        .transpose()
        .map_err(|e| errors::input(e.to_string()))?;
    let paths = match (&segments, clips.is_empty()) {
        (Some(file), true) => segment_clips(file),
        _ => crate::args::capture_files(py, &clips)?,
    };
    let mut inputs = paths.clone();
    inputs.extend(segments_path.iter().cloned());
    if let Some(file) = &segments {
        inputs.extend(file.rows().iter().map(|row| row.clip.clone()));
    }
    let takes = Takes::of(&paths, segments.as_ref()).walked_from(&clips);
    let interrupt = AtomicBool::new(false);
    let observer = || -> Box<dyn Observer> { Box::new(()) };
    let run = ShardRun {
        dir,
        takes: &takes,
        query: &query,
        job: &job,
        person: &person,
        shard,
        warm_start,
        resume,
        inputs: &inputs,
        interrupt: &interrupt,
        observer: &observer,
    };
    let on_event = |_: ShardEvent<'_>| {};
    let outcome = watched(
        py,
        &interrupt,
        || {
            on_pool(&pool, || {
                run.plan().and_then(|plan| run.run(&plan, &on_event))
            })
        },
        |_| Ok(()),
    )?
    .map_err(errors::raise)?;
    if let Some((take, e)) = outcome.failed {
        return Err(errors::raise_naming(&take, e));
    }
    let out = PyDict::new(py);
    out.set_item("dir", dir.display().to_string())?;
    out.set_item("shard", (shard.index, shard.count))?;
    out.set_item("takes", outcome.dealt)?;
    out.set_item("fitted", outcome.fitted)?;
    let skipped: Vec<(String, String)> = outcome
        .skipped
        .iter()
        .map(|s| (s.clip.display().to_string(), s.why.clone()))
        .collect();
    out.set_item("skipped", skipped)?;
    out.set_item("record", outcome.record.display().to_string())?;
    // One shard is collected at its end, as the CLI does, before saying nothing was fitted.
    if shard.count == 1 {
        out.set_item("rows", collect_rows(py, dir, None)?)?;
    }
    if outcome.fitted == 0 && outcome.dealt > 0 {
        return Err(errors::raise(nothing_found(&outcome.skipped)));
    }
    Ok(out)
}

/// Tables a library fitted into `dir` (by `fit(..., out_dir=)` or `kinergy fit --out-dir`,
/// in one or several shards), as `kinergy collect` does: checks that every take dealt was
/// fitted or skipped and every result is there and complete, writes `library.csv` and
/// `skipped.csv`, and returns library.csv's rows as dicts (clip, person, arm, onset, end,
/// frames, model, optimizer, distance_sa_m … distance_se_m, evaluations, seconds, result).
/// person: name each reach's person (and motion) by this rule instead of the library's own,
/// as `kinergy collect --person` does. An incomplete library raises KinergyError naming what
/// is missing (the tables are written all the same); a folder that is no library, or a rule
/// that cannot name every take, raises InputError.
#[pyfunction]
#[pyo3(signature = (dir, *, person = None))]
pub fn collect<'py>(
    py: Python<'py>,
    dir: PathBuf,
    person: Option<&str>,
) -> PyResult<Bound<'py, PyList>> {
    let person = person.map(|p| person_rule(Some(p))).transpose()?;
    collect_rows(py, &dir, person.as_ref())
}

/// The person rule `person=` spells ("auto" when not given), as `--person` reads it.
pub fn person_rule(person: Option<&str>) -> PyResult<PersonRule> {
    person
        .unwrap_or("auto")
        .parse::<PersonRule>()
        .map_err(|e| errors::input(format!("person={e}")))
}

/// library.csv's rows after [`kinergy_train::library::collect_with`], as dicts.
fn collect_rows<'py>(
    py: Python<'py>,
    dir: &Path,
    person: Option<&PersonRule>,
) -> PyResult<Bound<'py, PyList>> {
    let collected = py
        .detach(|| kinergy_train::library::collect_with(dir, person))
        .map_err(errors::raise)?;
    Ok(to_python(py, &collected.table.rows)?.cast_into::<PyList>()?)
}
