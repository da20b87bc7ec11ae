//! `kinergy.Params`: a person's parameters — a fitted vector (a parameters file) or a field
//! over targets (a field file) — read, written and looked at from Python. The files are the
//! CLI's: `save` writes the bytes `kinergy fit -o` writes, `load` reads what it reads.

use std::path::PathBuf;

use kinergy_train::PersonParams;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::convert::to_python;
use crate::errors;

/// A person's synergy parameters: one vector, or a field (kinergy.fit, Params.load).
#[pyclass(module = "kinergy", frozen, from_py_object)]
#[derive(Clone)]
pub struct Params {
    /// The parameters.
    pub inner: PersonParams,
}

impl Params {
    /// Python's view of `inner`.
    pub fn of(inner: PersonParams) -> Params {
        Params { inner }
    }

    /// The file's JSON text.
    pub fn json(&self) -> String {
        match &self.inner {
            PersonParams::Vector(file) => file.to_json(),
            PersonParams::Field(field) => field.to_json(),
        }
    }
}

#[pymethods]
impl Params {
    /// Reads a parameters file (`kinergy fit -o`) or a field file (`kinergy fit --field`).
    /// Raises ParamsError naming the file and the field.
    #[staticmethod]
    fn load(path: PathBuf) -> PyResult<Params> {
        PersonParams::read(&path)
            .map(|inner| Params { inner })
            .map_err(errors::raise)
    }

    /// Parses the text of a parameters or field file.
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Params> {
        PersonParams::from_json(text)
            .map(|inner| Params { inner })
            .map_err(errors::raise)
    }

    /// Writes the file atomically: the same bytes the CLI writes.
    fn save(&self, path: PathBuf) -> PyResult<()> {
        match &self.inner {
            PersonParams::Vector(file) => file.write(&path).map_err(errors::raise),
            PersonParams::Field(field) => field.write(&path).map_err(errors::raise),
        }
    }

    /// The file's JSON text.
    fn to_json(&self) -> String {
        self.json()
    }

    /// Pickling (multiprocessing, joblib): the file's text, read back by `Params.from_json`.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (String,))> {
        let from_json = py
            .import("kinergy._kinergy")?
            .getattr("Params")?
            .getattr("from_json")?;
        Ok((from_json, (self.json(),)))
    }

    /// True for a field file (a vector per target).
    #[getter]
    fn is_field(&self) -> bool {
        matches!(self.inner, PersonParams::Field(_))
    }

    /// The synergy model: "sa", "sb", "sc" or "sd".
    #[getter]
    fn model(&self) -> String {
        self.inner.model().name().to_string()
    }

    /// The IK optimizer the motions are synthesized with: "jt", "njt", "svd" or "dls".
    #[getter]
    fn optimizer(&self) -> String {
        self.inner.optimizer().kind().name().to_string()
    }

    /// The parameter vector by name, or None for a field (its vector depends on the target).
    #[getter]
    fn vector<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        match &self.inner {
            PersonParams::Vector(file) => to_python(py, &file.values).map(Some),
            PersonParams::Field(_) => Ok(None),
        }
    }

    /// How the parameters were fitted (the file's `fit` record as a dict), or None.
    #[getter]
    fn record<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        match self.inner.record() {
            None => Ok(None),
            Some(record) => to_python(py, &record).map(Some),
        }
    }

    /// The fitted distance of each model of the nested fit, meters, by model name ("sa" …):
    /// the mean joint-position distance to the captured reaches. Empty without a record.
    #[getter]
    fn distances<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let out = PyDict::new(py);
        if let Some(record) = self.inner.record() {
            match &record.nested {
                Some(stages) => {
                    for s in stages {
                        out.set_item(s.model.name(), s.score_m)?;
                    }
                }
                None => out.set_item(self.inner.model().name().to_string(), record.score_m)?,
            }
        }
        Ok(out)
    }

    fn __repr__(&self) -> String {
        let kind = if self.is_field() { "field" } else { "vector" };
        let score = self
            .inner
            .record()
            .map_or_else(String::new, |r| format!(", {:.3} mm", r.score_m * 1e3));
        format!(
            "Params({} {kind}, {}{score})",
            self.model(),
            self.optimizer()
        )
    }
}
