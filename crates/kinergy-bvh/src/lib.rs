#![doc = include_str!("../README.md")]
#![warn(clippy::print_stdout, clippy::print_stderr)]
// The reader must never panic: no indexing, unwrapping or overflowing arithmetic outside tests.
#![cfg_attr(
    not(test),
    warn(
        clippy::indexing_slicing,
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::arithmetic_side_effects
    )
)]

use std::path::Path;

pub mod document;
mod error;
mod options;
mod read;
mod scan;
mod validate;
mod write;

pub use document::{Bvh, Channel, Joint};
pub use error::{Error, ParseError, ParseErrorKind, WriteError};
pub use options::{FrameCountPolicy, MAX_FILE_BYTES, ReadOptions};
pub use read::{MAX_DEPTH, MAX_FRAME_TIME, MAX_VALUE, MIN_FRAME_TIME};

/// Parses BVH text strictly: `parse_with(text, &ReadOptions::default())`.
pub fn parse(text: &str) -> Result<Bvh, ParseError> {
    parse_with(text, &ReadOptions::default())
}

/// Parses BVH text. A leading byte order mark is skipped.
pub fn parse_with(text: &str, options: &ReadOptions) -> Result<Bvh, ParseError> {
    read::parse_str(text, options)
}

/// Parses BVH bytes, which must be UTF-8 (a byte order mark is accepted). Otherwise the
/// error is [`ParseErrorKind::InvalidUtf8`] at the first invalid byte.
pub fn parse_bytes(bytes: &[u8], options: &ReadOptions) -> Result<Bvh, ParseError> {
    read::parse_bytes(bytes, options)
}

/// Reads and parses a BVH file. Errors name the file.
///
/// Only a regular file is read (a device, FIFO or folder is an [`Error::Io`] of kind
/// `InvalidInput` saying what it is, refused before it is opened), and at most
/// [`ReadOptions::max_file_bytes`] of it (one byte more is an [`Error::Io`] of kind
/// `FileTooLarge`).
pub fn read_file(path: &Path, options: &ReadOptions) -> Result<Bvh, Error> {
    let bytes =
        kinergy_io::read_limited(path, options.max_file_bytes).map_err(|source| Error::Io {
            path: path.to_owned(),
            source,
            reading: true,
        })?;
    parse_bytes(&bytes, options).map_err(|source| Error::Parse {
        path: path.to_owned(),
        source,
    })
}

/// The frame count a BVH file's `Frames:` line states, read from the file's start without
/// parsing it (for weighing a library's takes before reading them): `Ok(None)` when the
/// first 4 MiB hold no such line. Only a regular file is read.
pub fn header_frame_count(path: &Path) -> std::io::Result<Option<usize>> {
    use std::io::{BufRead, BufReader, Read};
    const HEADER_BYTES: u64 = 4 << 20;
    let metadata = std::fs::metadata(path)?;
    if let Some(e) = kinergy_io::not_regular(&metadata) {
        return Err(e);
    }
    let reader = BufReader::new(std::fs::File::open(path)?.take(HEADER_BYTES));
    for line in reader.split(b'\n') {
        let line = line?;
        let text = String::from_utf8_lossy(&line);
        let text = text.trim();
        if let Some(rest) = text.strip_prefix("Frames:") {
            return Ok(rest.trim().parse().ok());
        }
    }
    Ok(None)
}

/// Writes a document as BVH text, after [`Bvh::validate`].
pub fn to_string(bvh: &Bvh) -> Result<String, WriteError> {
    write::render(bvh)
}

/// Writes a document as BVH text to `out`, after [`Bvh::validate`]; nothing is written
/// if it fails ([`Error::Invalid`]). Output errors are [`Error::Stream`].
pub fn write<W: std::io::Write>(bvh: &Bvh, out: W) -> Result<(), Error> {
    write::write_to(bvh, out)
}

/// Writes a document to `path` atomically, after [`Bvh::validate`].
///
/// The text goes to a new temporary file in the same directory, which is synced and then
/// renamed over `path` (keeping an existing file's permissions); the directory is then
/// synced where the platform allows. On any error the temporary file is removed, so
/// `path` holds either its old contents or the whole new document, and no partial file is
/// left behind. Errors name `path`. A symbolic link at `path` is replaced, not followed.
pub fn write_file(path: &Path, bvh: &Bvh) -> Result<(), Error> {
    write::write_file(path, bvh)
}
