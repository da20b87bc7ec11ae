//! File I/O shared by every Kinergy crate, in one place:
//!
//! - [`write_atomic`]: replace a file so readers see the old content or the new, never a
//!   part (temporary file in the same folder, sync, rename), and [`AtomicFile`] for files
//!   written piece by piece; stale temporaries of killed writers are removed (see
//!   [`atomic`] for the rule);
//! - [`json`] (feature `json`, on by default): versioned JSON documents — the parameters
//!   file, checkpoints, scenes, fields — read with one rule for `format_version` and one
//!   error shape naming the line and column or the field, written pretty and atomically;
//! - [`ErrorKind`] and [`Classify`]: what kind of failure an error is, the one rule from which
//!   the CLI's exit codes and Python's exception classes come;
//! - [`clip_text`]: how much of an input a message may quote;
//! - [`read_limited`] / [`read_to_string_limited`]: bounded input, regular files only, so
//!   no file (or `/dev/zero`, or a FIFO) makes a command read without end.
//!
//! std + serde only, so the format crates at the bottom of the workspace can use it.
#![warn(clippy::print_stdout, clippy::print_stderr)]

pub mod atomic;
#[cfg(feature = "json")]
pub mod json;
pub mod kind;
pub mod names;
pub mod read;
mod text;

pub use atomic::{
    AtomicFile, STALE_AFTER, create_folder, describe_full_disk, is_disk_full,
    remove_stale_temporaries_in, write_atomic,
};
#[cfg(feature = "json")]
pub use json::{
    JsonError, check_version, parse_versioned, to_pretty_json, write_json, write_json_text,
};
pub use kind::{Classify, ErrorKind, InvalidSetting, Location};
pub use read::{
    MAX_CAPTURE_BYTES, MAX_JSON_BYTES, MIB, describe_file_type, format_limit, not_regular,
    read_limited, read_to_string_limited,
};
pub use text::{MAX_QUOTED_CHARS, Num, clip_text, list_some, meters, quote_number};
