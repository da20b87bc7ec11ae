//! How strictly to read.

/// Options for [`parse_with`](crate::parse_with), [`parse_bytes`](crate::parse_bytes) and
/// [`read_file`](crate::read_file). The default is strict.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct ReadOptions {
    /// What to do when the `Frames:` count disagrees with the motion data.
    pub frame_count: FrameCountPolicy,
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
