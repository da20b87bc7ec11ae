//! What kind of failure an error is: one classification for every library error, from
//! which both front ends decide — the CLI its exit code, Python its exception class — so
//! that the two cannot drift.
//!
//! | kind | CLI exit | Python |
//! |---|---|---|
//! | [`Input`](ErrorKind::Input) | 2 | `InputError` |
//! | [`Capture`](ErrorKind::Capture) | 2 | `BvhError` |
//! | [`Params`](ErrorKind::Params) | 2 | `ParamsError` |
//! | [`NothingToFit`](ErrorKind::NothingToFit) | 1 | `NothingToFitError` |
//! | [`Unreachable`](ErrorKind::Unreachable) | 1 | `UnreachableError` |
//! | [`Io`](ErrorKind::Io), [`Task`](ErrorKind::Task), [`Interrupted`](ErrorKind::Interrupted) | 1 | `KinergyError` |

use std::path::PathBuf;

/// What kind of failure an error is ([module docs](self)).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ErrorKind {
    /// An argument, setting or file the user gave is refused: out of range, malformed, of
    /// another skeleton, an output over an input.
    Input,
    /// A capture (BVH file) cannot be read: missing, unreadable, not BVH.
    Capture,
    /// A parameters, field or checkpoint file cannot be read, is damaged, or does not fit
    /// what it drives.
    Params,
    /// The inputs are fine but hold nothing to work on: no take has a reach.
    NothingToFit,
    /// The goal was not reached: beyond the body, every posture collides, no path.
    Unreachable,
    /// A file could not be written (a full disk, permissions).
    Io,
    /// The user stopped the work (Ctrl-C).
    Interrupted,
    /// The task failed for another reason (a computation that did not converge, a library
    /// that is not complete).
    Task,
}

impl ErrorKind {
    /// The CLI's exit code: 2 when the input is at fault, 1 when a task could not be done.
    pub fn exit_code(self) -> u8 {
        if self.is_input() { 2 } else { 1 }
    }

    /// Whether the input is at fault ([`Input`](Self::Input), [`Capture`](Self::Capture),
    /// [`Params`](Self::Params)) rather than the task.
    pub fn is_input(self) -> bool {
        matches!(
            self,
            ErrorKind::Input | ErrorKind::Capture | ErrorKind::Params
        )
    }

    /// The kind's name, as in the table of the [module docs](self): `input`, `capture`, …
    pub fn name(self) -> &'static str {
        match self {
            ErrorKind::Input => "input",
            ErrorKind::Capture => "capture",
            ErrorKind::Params => "params",
            ErrorKind::NothingToFit => "nothing_to_fit",
            ErrorKind::Unreachable => "unreachable",
            ErrorKind::Io => "io",
            ErrorKind::Interrupted => "interrupted",
            ErrorKind::Task => "task",
        }
    }
}

/// Where in a file an error is, when it is about one: the path, and the 1-based line and
/// column where the reader knows them.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Location {
    /// The file.
    pub path: PathBuf,
    /// 1-based line.
    pub line: Option<usize>,
    /// 1-based column, in characters.
    pub column: Option<usize>,
}

/// An error that says what kind of failure it is. Every library crate's error implements
/// it; the front ends map [`kind`](Classify::kind) and nothing else.
pub trait Classify: std::error::Error {
    /// What kind of failure this is.
    fn kind(&self) -> ErrorKind;

    /// Where in a file the error is, when it is about one the reader located.
    fn location(&self) -> Option<Location> {
        None
    }
}

/// A setting or argument outside what it may be, named by its field: the one "invalid
/// setting" error of every crate (`anneal.population`, `person.height`, `rrt.step`).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("invalid `{field}`: {why}")]
pub struct InvalidSetting {
    /// The setting's name, e.g. `anneal.population`.
    pub field: String,
    /// What was expected.
    pub why: String,
}

impl InvalidSetting {
    /// `field` refused, saying `why`.
    pub fn new(field: impl Into<String>, why: impl Into<String>) -> InvalidSetting {
        InvalidSetting {
            field: field.into(),
            why: why.into(),
        }
    }

    /// `Ok` when `ok`, else `field` refused, saying `why`.
    pub fn require(ok: bool, field: &str, why: impl Into<String>) -> Result<(), InvalidSetting> {
        if ok {
            Ok(())
        } else {
            Err(InvalidSetting::new(field, why))
        }
    }
}

impl InvalidSetting {
    /// `Ok` when `value` is within `range` (both ends included; NaN never is), else `field`
    /// refused, saying the range.
    pub fn in_range<T: PartialOrd + std::fmt::Display + Copy>(
        field: &str,
        value: T,
        (lo, hi): (T, T),
    ) -> Result<(), InvalidSetting> {
        InvalidSetting::require(
            lo <= value && value <= hi,
            field,
            format!("{}: expected {lo} to {hi}", crate::quote_number(value)),
        )
    }
}

impl Classify for InvalidSetting {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Input
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_input_kinds_exit_2_and_the_rest_1() {
        let all = [
            ErrorKind::Input,
            ErrorKind::Capture,
            ErrorKind::Params,
            ErrorKind::NothingToFit,
            ErrorKind::Unreachable,
            ErrorKind::Io,
            ErrorKind::Interrupted,
            ErrorKind::Task,
        ];
        let input: Vec<_> = all.iter().filter(|k| k.exit_code() == 2).collect();
        assert_eq!(
            input,
            [&ErrorKind::Input, &ErrorKind::Capture, &ErrorKind::Params]
        );
        assert!(all.iter().all(|k| matches!(k.exit_code(), 1 | 2)));
        let names: std::collections::HashSet<_> = all.iter().map(|k| k.name()).collect();
        assert_eq!(names.len(), all.len());
    }

    #[test]
    fn an_invalid_setting_names_its_field() {
        let e = InvalidSetting::require(false, "anneal.population", "at least 2").unwrap_err();
        assert_eq!(e.to_string(), "invalid `anneal.population`: at least 2");
        assert!(InvalidSetting::require(true, "x", "y").is_ok());
        assert_eq!(e.kind(), ErrorKind::Input);
    }
}
