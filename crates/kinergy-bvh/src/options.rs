//! How strictly to read.

/// The default [`ReadOptions::max_file_bytes`]: 256 MiB.
pub const MAX_FILE_BYTES: u64 = kinergy_io::MAX_CAPTURE_BYTES;

/// Options for [`parse_with`](crate::parse_with), [`parse_bytes`](crate::parse_bytes) and
/// [`read_file`](crate::read_file). The default is strict, with files up to
/// [`MAX_FILE_BYTES`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReadOptions {
    /// What to do when the `Frames:` count disagrees with the motion data.
    pub frame_count: FrameCountPolicy,
    /// [`read_file`](crate::read_file) refuses a file holding more bytes than this
    /// (an [`Error::Io`](crate::Error::Io) of kind `FileTooLarge`), checked while reading.
    pub max_file_bytes: u64,
    /// Refuse an `OFFSET` component or a motion value beyond ±[`MAX_VALUE`](crate::MAX_VALUE)
    /// ([`ParseErrorKind::ValueTooLarge`](crate::ParseErrorKind::ValueTooLarge), naming
    /// the joint and channel), as a reader of captures wants; off by default, where every
    /// finite number is kept as the format allows.
    pub bounded_values: bool,
}

impl Default for ReadOptions {
    fn default() -> Self {
        ReadOptions {
            frame_count: FrameCountPolicy::default(),
            max_file_bytes: MAX_FILE_BYTES,
            bounded_values: false,
        }
    }
}

/// What to do when the header's `Frames:` count disagrees with the motion data.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub enum FrameCountPolicy {
    /// The data must hold exactly the declared number of frames, or the read fails with
    /// [`ParseErrorKind::FrameCountMismatch`](crate::ParseErrorKind::FrameCountMismatch)
    /// (or [`TooManyFrames`](crate::ParseErrorKind::TooManyFrames) when the file is too
    /// short to possibly hold them).
    #[default]
    Strict,
    /// Keep every complete frame present, whatever the header says; `frame_count` is then
    /// the number of frames read. A trailing partial frame is still an error
    /// ([`PartialFrame`](crate::ParseErrorKind::PartialFrame)): a value missing anywhere
    /// shifts every later frame, and the reader cannot tell that from a clean cut, so it
    /// does not guess.
    AcceptCompleteFrames,
}
