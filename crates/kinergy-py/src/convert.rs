//! Python's plain arguments into the library's types, and library values back into Python
//! objects: names parsed with `FromStr`, the reading and export options, reports as dicts.
//! Below every other module of the crate (it names none of the classes).

use kinergy_motion::{
    ExportOptions, ExportUp, ImportOptions, LengthUnit, PositionReadingChoice, UnitChoice, UpChoice,
};
use kinergy_train::limits;
use pyo3::prelude::*;

use crate::errors;

/// Parses `value` of the keyword argument `name` with `FromStr`; errors name both.
pub fn parse<T: std::str::FromStr>(name: &str, value: &str) -> PyResult<T>
where
    T::Err: std::fmt::Display,
{
    value
        .parse()
        .map_err(|e| errors::input(format!("{name}={value:?}: {e}")))
}

/// `json.loads` of `value` serialized: a library report as Python dicts and lists, the same
/// document the CLI's `--json` prints.
pub fn to_python<'py, T: serde::Serialize + ?Sized>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    let text = serde_json::to_string(value)
        .map_err(|e| errors::KinergyError::new_err(format!("a report: {e}")))?;
    py.import("json")?.call_method1("loads", (text,))
}

/// The reading options of the keyword arguments `unit`, `up`, `positions` (the CLI's
/// `--from-unit`, `--up`, `--positions`).
#[derive(Debug, Clone, Copy)]
pub struct Reading<'a> {
    /// `m`, `cm`, `mm`, `in`, `cmu` or `auto`.
    pub unit: &'a str,
    /// `y`, `z`, `x`, `-y`, `-z`, `-x` or `auto`.
    pub up: &'a str,
    /// `auto`, `add` or `replace`.
    pub positions: &'a str,
}

impl Reading<'_> {
    /// The import options, at most `max_input_mb` read.
    pub fn options_up_to(&self, max_input_mb: u64) -> PyResult<ImportOptions> {
        errors::check_range("max_input_mb", max_input_mb, limits::MAX_INPUT_MB)?;
        Ok(ImportOptions {
            unit: parse::<UnitChoice>("unit", self.unit)?,
            position_reading: parse::<PositionReadingChoice>("positions", self.positions)?,
            up: parse::<UpChoice>("up", self.up)?,
            max_file_bytes: Some(max_input_mb.saturating_mul(kinergy_io::MIB)),
        })
    }

    /// The import options with the CLI's default size limit.
    pub fn options(&self) -> PyResult<ImportOptions> {
        self.options_up_to(limits::DEFAULT_INPUT_MB)
    }
}

/// The export options of `unit` and `up` (`as-read` or `y`).
pub fn export_options(unit: &str, up: &str) -> PyResult<ExportOptions> {
    Ok(ExportOptions {
        unit: parse::<LengthUnit>("unit", unit)?,
        up: match up {
            "as-read" => ExportUp::AsRead,
            "y" => ExportUp::Y,
            _ => {
                return Err(errors::input(format!(
                    "up={up:?}: expected \"as-read\" or \"y\""
                )));
            }
        },
    })
}
