//! Bounded file input: every file Kinergy reads goes through [`read_limited`] or
//! [`read_to_string_limited`], so a huge file, `/dev/zero` or a FIFO cannot make a command
//! read until memory runs out or wait forever.
//!
//! - Only regular files are read: a device, FIFO, socket or folder is refused (before it is
//!   opened, since opening a FIFO waits for a writer) with an error saying what it is,
//!   e.g. `not a regular file (a character device)`.
//! - At most `limit` bytes are read (`take(limit + 1)`); one byte more is an error of kind
//!   [`io::ErrorKind::FileTooLarge`] saying the limit, whatever the file's size claims.

use std::fs::{File, Metadata};
use std::io::{self, Read};
use std::path::Path;

/// One mebibyte, the unit limits are given in.
pub const MIB: u64 = 1024 * 1024;

/// The default limit of a JSON document (parameters, checkpoints, scenes, fields) or a
/// CSV file (segments files): 16 MiB.
pub const MAX_JSON_BYTES: u64 = 16 * MIB;

/// The UTF-8 byte-order mark.
const UTF8_BOM: &[u8] = b"\xef\xbb\xbf";

/// The default limit of a motion capture (BVH) or a mesh (OBJ): 256 MiB.
pub const MAX_CAPTURE_BYTES: u64 = 256 * MIB;

/// What kind of file `metadata` describes, for messages: `a folder`, `a FIFO`, ...
pub fn describe_file_type(metadata: &Metadata) -> &'static str {
    let kind = metadata.file_type();
    if kind.is_file() {
        return "a regular file";
    }
    if kind.is_dir() {
        return "a folder";
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if kind.is_char_device() {
            return "a character device";
        }
        if kind.is_block_device() {
            return "a block device";
        }
        if kind.is_fifo() {
            return "a FIFO";
        }
        if kind.is_socket() {
            return "a socket";
        }
    }
    "not a file"
}

/// The error for a path that exists but is not a regular file; `None` for a regular file.
pub fn not_regular(metadata: &Metadata) -> Option<io::Error> {
    (!metadata.is_file()).then(|| {
        io::Error::new(
            io::ErrorKind::InvalidInput,
            format!("not a regular file ({})", describe_file_type(metadata)),
        )
    })
}

/// `limit` bytes in words: `16 MiB`, `1.5 MiB` or `512 bytes`.
pub fn format_limit(limit: u64) -> String {
    if limit >= MIB && limit.is_multiple_of(MIB / 2) {
        let mib = limit as f64 / MIB as f64;
        format!("{mib} MiB")
    } else {
        format!("{limit} bytes")
    }
}

/// Reads the regular file at `path`, at most `limit` bytes.
///
/// Errors: the open or read error; [`io::ErrorKind::InvalidInput`] `not a regular file
/// (a FIFO)` for anything but a regular file (checked before opening); and
/// [`io::ErrorKind::FileTooLarge`] `larger than the 16 MiB limit` when the file holds more
/// than `limit` bytes. The messages do not repeat the path.
pub fn read_limited(path: &Path, limit: u64) -> io::Result<Vec<u8>> {
    if let Some(e) = not_regular(&std::fs::metadata(path)?) {
        return Err(e);
    }
    let file = File::open(path)?;
    let metadata = file.metadata()?;
    if let Some(e) = not_regular(&metadata) {
        return Err(e);
    }
    let too_large = || {
        io::Error::new(
            io::ErrorKind::FileTooLarge,
            format!("larger than the {} limit", format_limit(limit)),
        )
    };
    if metadata.len() > limit {
        return Err(too_large());
    }
    let capacity = usize::try_from(metadata.len()).unwrap_or(0);
    let mut bytes = Vec::with_capacity(capacity);
    file.take(limit.saturating_add(1)).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > limit {
        return Err(too_large());
    }
    Ok(bytes)
}

/// [`read_limited`], then the bytes as UTF-8 (else [`io::ErrorKind::InvalidData`], as
/// `std::fs::read_to_string`), without the byte-order mark some Windows editors put first
/// (a JSON file saved with one read as "expected value at line 1 column 1").
pub fn read_to_string_limited(path: &Path, limit: u64) -> io::Result<String> {
    let mut bytes = read_limited(path, limit)?;
    if bytes.starts_with(UTF8_BOM) {
        bytes.drain(..UTF8_BOM.len());
    }
    String::from_utf8(bytes).map_err(|e| {
        io::Error::new(
            io::ErrorKind::InvalidData,
            format!(
                "stream did not contain valid UTF-8 (byte {})",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_byte_order_mark_is_not_part_of_the_text() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bom.json");
        std::fs::write(&path, b"\xef\xbb\xbf{\"a\": 1}").unwrap();
        assert_eq!(read_to_string_limited(&path, 100).unwrap(), "{\"a\": 1}");
        // Only first: elsewhere it is text.
        std::fs::write(&path, b"x\xef\xbb\xbf").unwrap();
        assert_eq!(read_to_string_limited(&path, 100).unwrap(), "x\u{feff}");
    }

    #[test]
    fn reads_a_file_up_to_its_limit_and_refuses_one_byte_more() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.txt");
        std::fs::write(&path, b"0123456789").unwrap();
        assert_eq!(read_limited(&path, 10).unwrap(), b"0123456789");
        let e = read_limited(&path, 9).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::FileTooLarge);
        assert_eq!(e.to_string(), "larger than the 9 bytes limit");
        assert_eq!(read_to_string_limited(&path, 10).unwrap(), "0123456789");
    }

    #[test]
    fn a_folder_is_not_a_regular_file() {
        let dir = tempfile::tempdir().unwrap();
        let e = read_limited(dir.path(), 10).unwrap_err();
        assert_eq!(e.to_string(), "not a regular file (a folder)");
    }

    #[cfg(unix)]
    #[test]
    fn dev_zero_is_refused_before_reading() {
        let e = read_limited(Path::new("/dev/zero"), MIB).unwrap_err();
        assert_eq!(e.to_string(), "not a regular file (a character device)");
    }

    #[test]
    fn limits_read_in_mebibytes() {
        assert_eq!(format_limit(16 * MIB), "16 MiB");
        assert_eq!(format_limit(3 * MIB / 2), "1.5 MiB");
        assert_eq!(format_limit(1000), "1000 bytes");
    }

    #[test]
    fn invalid_utf8_is_invalid_data() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("f.txt");
        std::fs::write(&path, [b'a', 0xff]).unwrap();
        let e = read_to_string_limited(&path, 10).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::InvalidData);
    }
}
