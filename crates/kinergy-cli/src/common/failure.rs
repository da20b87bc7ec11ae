//! Why a command stopped, and its exit code: one rule for every command.
//!
//! | exit | meaning | examples |
//! |---|---|---|
//! | 0 | done | |
//! | 2 | the input or the command line is wrong ([`Failure::Input`]) | a file that cannot be read or is malformed, an option out of range, parameters that do not fit the arm or the target, a capture without the reach the command needs, an output that would overwrite an input |
//! | 1 | the input was right but the task could not be done ([`Failure::Task`]) | an unreachable or colliding goal, no path, a motion that did not reach, a file that could not be written (a full disk, permissions) |
//!
//! Library errors become failures by their kind ([`kinergy_io::ErrorKind`], the rule
//! Python's exception classes follow too): each crate's error says which of its variants are
//! the input's fault. A call site adds only the file the error is
//! about ([`Failure::naming`], [`Failure::input`] for a file read as input, [`Failure::task`]
//! for one written).

use std::fmt;
use std::path::Path;

/// Why a command stopped: bad input (exit 2) or a task that could not be done (exit 1).
#[derive(Debug)]
pub enum Failure {
    /// The input was wrong: a missing or malformed file, a bad argument.
    Input(String),
    /// The input was fine but the task failed (e.g. an unreachable target).
    Task(String),
}

impl Failure {
    /// The process's exit code: 2 for bad input, 1 for a failed task.
    pub fn exit_code(&self) -> u8 {
        match self {
            Failure::Input(_) => 2,
            Failure::Task(_) => 1,
        }
    }

    /// Bad input concerning `path`.
    pub fn input(path: &Path, e: impl fmt::Display) -> Failure {
        Failure::Input(naming(path, e))
    }

    /// The same failure, its message prefixed by `name: ` (a capture the command was
    /// working on).
    pub fn naming(self, name: &str) -> Failure {
        match self {
            Failure::Input(m) => Failure::Input(format!("{name}: {m}")),
            Failure::Task(m) => Failure::Task(format!("{name}: {m}")),
        }
    }

    /// A failed task concerning `path` (e.g. writing it).
    pub fn task(path: &Path, e: impl fmt::Display) -> Failure {
        Failure::Task(naming(path, e))
    }
}

/// `e` naming `path` once: library errors about files already name them.
fn naming(path: &Path, e: impl fmt::Display) -> String {
    let text = e.to_string();
    if text.contains(&*path.to_string_lossy()) {
        text
    } else {
        format!("{}: {text}", path.display())
    }
}

impl fmt::Display for Failure {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Failure::Input(m) | Failure::Task(m) => f.write_str(m),
        }
    }
}

/// A person's parameters or field file (`--params`), read once; its errors name the file.
pub fn read_person(path: &Path) -> Result<kinergy_train::PersonParams, Failure> {
    kinergy_train::PersonParams::read(path).map_err(Failure::from)
}

/// A failure of a person's drive ([`kinergy_reach::drive::PersonArm`]) whose parameters
/// are at `path`: parameters that do not fit name the file.
pub fn person_failure(path: &Path, e: kinergy_reach::ReachError) -> Failure {
    match e {
        kinergy_reach::ReachError::Params { source } => Failure::input(path, source),
        e => e.into(),
    }
}

impl<E: kinergy_io::Classify> From<E> for Failure {
    /// Every library error by its kind ([`kinergy_io::ErrorKind::exit_code`]): the input's
    /// fault exits 2, a task that could not be done 1.
    fn from(e: E) -> Failure {
        if e.kind().is_input() {
            Failure::Input(e.to_string())
        } else {
            Failure::Task(e.to_string())
        }
    }
}
