//! The crate's error types: [`ParseError`] for text, [`WriteError`] for documents that
//! cannot be written, and [`Error`], which adds the file path to either (or to an I/O error).

use std::path::PathBuf;

use crate::document::Channel;

/// Why a BVH text was rejected, and where.
///
/// `line` and `column` are 1-based; the column counts characters (not bytes) from the
/// start of the line. Displays as `line 12, column 5: expected a number after OFFSET,
/// found `abc``.
#[non_exhaustive]
#[derive(thiserror::Error, Debug, Clone, PartialEq, Eq)]
#[error("line {line}, column {column}: {kind}")]
pub struct ParseError {
    /// 1-based line of the offending token (or of the end of the text).
    pub line: usize,
    /// 1-based column, in characters, of the offending token.
    pub column: usize,
    /// What is wrong.
    pub kind: ParseErrorKind,
}

/// What is wrong with a BVH text. See [`ParseError`] for where.
///
/// Strings carrying the offending text (`found`, `value`, ...) are cut to 40 characters.
#[non_exhaustive]
#[derive(thiserror::Error, Debug, Clone, PartialEq, Eq)]
pub enum ParseErrorKind {
    /// The bytes are not UTF-8; the position is that of the first bad byte.
    #[error("the file is not valid UTF-8")]
    InvalidUtf8,
    /// The text ended where more was required.
    #[error("unexpected end of file: expected {expected}")]
    UnexpectedEof {
        /// What was required, e.g. `"MOTION"`.
        expected: &'static str,
    },
    /// A token other than the one the grammar requires here.
    #[error("expected {expected}, found `{found}`")]
    Expected {
        /// What was required, e.g. `"a number after OFFSET"`.
        expected: &'static str,
        /// The token found instead.
        found: String,
    },
    /// `ROOT` or `JOINT` without a name on the same line.
    #[error("{keyword} has no name on its line")]
    MissingName {
        /// `"ROOT"` or `"JOINT"`.
        keyword: &'static str,
    },
    /// A joint name containing a control character or non-ASCII whitespace (the writer
    /// could not reproduce it).
    #[error("invalid joint name `{name}`: names cannot contain whitespace or control characters")]
    InvalidName {
        /// The name as written (cut to 40 characters).
        name: String,
    },
    /// A `CHANNELS` entry that is not one of the six channel names.
    #[error(
        "unknown channel `{0}` (expected Xposition, Yposition, Zposition, Xrotation, Yrotation or Zrotation)"
    )]
    UnknownChannel(String),
    /// The same channel listed twice for one joint.
    #[error("channel {0} is listed twice for the same joint")]
    DuplicateChannel(Channel),
    /// The count after `CHANNELS` is missing, not an integer, or not in `0..=6`.
    #[error("bad CHANNELS count `{found}`: expected an integer from 0 to 6")]
    BadChannelCount {
        /// The count as written (empty when missing).
        found: String,
    },
    /// The count after `CHANNELS` differs from the number of names on the line.
    #[error("CHANNELS declares {declared} channels but its line lists {listed}")]
    ChannelCountMismatch {
        /// The count after `CHANNELS`.
        declared: usize,
        /// The number of channel names on the line.
        listed: usize,
    },
    /// `CHANNELS` after a child `JOINT`: the frame layout would be ambiguous.
    #[error("CHANNELS must come before the joint's children")]
    ChannelsAfterChild,
    /// `OFFSET` or `CHANNELS` given twice for one joint.
    #[error("{keyword} is given twice for the same joint")]
    Repeated {
        /// `"OFFSET"` or `"CHANNELS"`.
        keyword: &'static str,
    },
    /// A joint or End Site closed without an `OFFSET`.
    #[error("`{joint}` has no OFFSET")]
    MissingOffset {
        /// The joint's name, or `End Site`.
        joint: String,
    },
    /// An End Site with `CHANNELS`.
    #[error("an End Site cannot have CHANNELS")]
    EndSiteChannels,
    /// An End Site with a `JOINT` or `End Site` inside.
    #[error("an End Site cannot have children")]
    EndSiteChildren,
    /// A `}` without a matching `{` (`unclosed` is 0), or `MOTION` / the end of the text
    /// while `unclosed` braces are still open.
    #[error("unbalanced braces: {}", unbalanced_message(*.unclosed))]
    UnbalancedBraces {
        /// How many `{` were still open (0 for a stray `}`).
        unclosed: usize,
    },
    /// Joints nested deeper than [`MAX_DEPTH`](crate::MAX_DEPTH).
    #[error("joints are nested deeper than {max} levels")]
    TooDeep {
        /// The limit.
        max: usize,
    },
    /// A second `ROOT` after the first one closed.
    #[error("a second ROOT: only one skeleton per file is supported")]
    MultipleRoots,
    /// A second `HIERARCHY` keyword.
    #[error("a second HIERARCHY")]
    DuplicateHierarchy,
    /// The count after `Frames:` is missing, negative or not an integer.
    #[error("bad frame count `{found}`: expected a non-negative integer")]
    BadFrameCount {
        /// The count as written.
        found: String,
    },
    /// The header declares more frames than the rest of the file could possibly hold
    /// (each value needs at least one character and one separator); checked before
    /// anything is allocated, in [`FrameCountPolicy::Strict`](crate::FrameCountPolicy::Strict)
    /// only. Reported at the header's count.
    #[error(
        "the header declares {declared} frames but the rest of the file can hold at most {max_possible}"
    )]
    TooManyFrames {
        /// The count after `Frames:`.
        declared: usize,
        /// The most complete frames the remaining bytes could hold.
        max_possible: usize,
    },
    /// The value after `Frame Time:` is not a finite number greater than zero.
    #[error("bad frame time `{found}`: expected a finite number of seconds greater than 0")]
    BadFrameTime {
        /// The value as written.
        found: String,
    },
    /// A frame time outside [`MIN_FRAME_TIME`](crate::MIN_FRAME_TIME) to
    /// [`MAX_FRAME_TIME`](crate::MAX_FRAME_TIME) seconds (10 kHz to 0.1 Hz): a rate no
    /// capture has, and one that would make "seconds ÷ frame time" frame counts unbounded.
    #[error(
        "frame time `{found}` is out of range: expected {} to {} seconds (10 kHz to 0.1 Hz)",
        crate::MIN_FRAME_TIME,
        crate::MAX_FRAME_TIME
    )]
    FrameTimeOutOfRange {
        /// The value as written.
        found: String,
    },
    /// In a file written one frame per line (its first motion line holds exactly one
    /// frame), a line holding another number of values. Reported at the line: at its
    /// first surplus value, or at its last value when it holds too few.
    #[error(
        "{values} values on this line, but the skeleton has {channels} channels (one frame per line)"
    )]
    LineValues {
        /// The number of values on the line.
        values: usize,
        /// The number of values in a frame.
        channels: usize,
    },
    /// A number that is NaN or infinite, or overflows `f64` (`nan`, `inf`, `1e999`).
    #[error("`{value}` is not a finite number")]
    NonFinite {
        /// The value as written.
        value: String,
    },
    /// An `OFFSET` component or a motion value beyond ±[`MAX_VALUE`](crate::MAX_VALUE),
    /// with [`ReadOptions::bounded_values`](crate::ReadOptions::bounded_values): no length
    /// or angle a capture holds.
    #[error(
        "`{value}` ({what}) is beyond ±{:e}: no length or angle of a capture is that large \
         (a damaged file?)",
        crate::MAX_VALUE
    )]
    ValueTooLarge {
        /// The value as written (shortened; boxed, as `what`).
        value: Box<str>,
        /// Where it is: "Hips Xposition", "an OFFSET component of Hips" (boxed, so that the
        /// error stays as small as the others).
        what: Box<str>,
    },
    /// The number of complete frames differs from the header's count
    /// ([`FrameCountPolicy::Strict`](crate::FrameCountPolicy::Strict) only). Reported at
    /// the header's count.
    #[error("the header declares {declared} frames but the motion data has {found}")]
    FrameCountMismatch {
        /// The count after `Frames:`.
        declared: usize,
        /// The number of complete frames in the data.
        found: usize,
    },
    /// The motion data ends inside a frame (in every mode). Reported at the last value.
    #[error("the last frame is incomplete: {values} of {channels} values")]
    PartialFrame {
        /// The number of values in the incomplete frame.
        values: usize,
        /// The number of values in a frame.
        channels: usize,
    },
    /// Something other than a number after the last frame.
    #[error("unexpected `{found}` after the motion data")]
    TrailingGarbage {
        /// The token found.
        found: String,
    },
}

fn unbalanced_message(unclosed: usize) -> String {
    if unclosed == 0 {
        "`}` without a matching `{`".to_owned()
    } else {
        format!("{unclosed} `{{` not closed")
    }
}

/// Why a [`Bvh`](crate::Bvh) cannot be written: the first inconsistency
/// [`Bvh::validate`](crate::Bvh::validate) found. `joint` fields are indices into
/// [`Bvh::joints`](crate::Bvh::joints).
#[non_exhaustive]
#[derive(thiserror::Error, Debug, Clone, PartialEq)]
pub enum WriteError {
    /// The document has no joints.
    #[error("the document has no joints")]
    NoJoints,
    /// Joint 0 has a parent, or is an End Site.
    #[error("joint 0 must be the root: no parent, not an End Site")]
    RootNotFirst,
    /// A joint other than joint 0 has no parent.
    #[error("joint {joint} has no parent: only joint 0 may be a root")]
    MultipleRoots {
        /// The joint.
        joint: usize,
    },
    /// A joint's parent does not come before it.
    #[error("joint {joint} has parent {parent}, which does not come before it")]
    ParentAfterChild {
        /// The joint.
        joint: usize,
        /// Its parent.
        parent: usize,
    },
    /// The joints are not in depth-first order: the parent of `joint` is neither the
    /// joint before it nor one of that joint's ancestors, so a written file would list
    /// the joints (and their channels) in another order.
    #[error("joint {joint} is not in depth-first order")]
    NotDepthFirst {
        /// The joint.
        joint: usize,
    },
    /// Joints nested deeper than [`MAX_DEPTH`](crate::MAX_DEPTH), which the reader refuses.
    #[error("joint {joint} is nested deeper than {max} levels")]
    TooDeep {
        /// The joint.
        joint: usize,
        /// The limit.
        max: usize,
    },
    /// An End Site that is a parent.
    #[error("End Site {joint} has children")]
    EndSiteChildren {
        /// The End Site.
        joint: usize,
    },
    /// An End Site with channels.
    #[error("End Site {joint} has channels")]
    EndSiteChannels {
        /// The End Site.
        joint: usize,
    },
    /// An End Site with a name (the format has no place for it).
    #[error("End Site {joint} has a name")]
    EndSiteName {
        /// The End Site.
        joint: usize,
    },
    /// A joint that is not an End Site without a name.
    #[error("joint {joint} has no name")]
    MissingName {
        /// The joint.
        joint: usize,
    },
    /// A name that is empty, `{` or `}`, or contains whitespace or control characters.
    #[error("joint {joint} has an invalid name `{name}`")]
    InvalidName {
        /// The joint.
        joint: usize,
        /// The name.
        name: String,
    },
    /// A channel listed twice for one joint.
    #[error("joint {joint} lists channel {channel} twice")]
    DuplicateChannel {
        /// The joint.
        joint: usize,
        /// The repeated channel.
        channel: Channel,
    },
    /// `first_channel` is not the number of channels of the joints before.
    #[error("joint {joint} has first_channel {found}, expected {expected}")]
    ChannelOffset {
        /// The joint.
        joint: usize,
        /// The number of channels of the joints before it.
        expected: usize,
        /// Its `first_channel`.
        found: usize,
    },
    /// `motion.len()` is not `frame_count * channel_count()`.
    #[error("motion has {values} values, expected {frame_count} frames x {channel_count} channels")]
    MotionLength {
        /// `frame_count`.
        frame_count: usize,
        /// `channel_count()`.
        channel_count: usize,
        /// `motion.len()`.
        values: usize,
    },
    /// A NaN or infinite OFFSET component.
    #[error("joint {joint} has a non-finite OFFSET")]
    NonFiniteOffset {
        /// The joint.
        joint: usize,
    },
    /// A NaN or infinite motion value.
    #[error("frame {frame}, channel {channel}: non-finite value")]
    NonFiniteMotion {
        /// 0-based frame.
        frame: usize,
        /// 0-based channel within the frame.
        channel: usize,
    },
    /// A frame time outside [`MIN_FRAME_TIME`](crate::MIN_FRAME_TIME) to
    /// [`MAX_FRAME_TIME`](crate::MAX_FRAME_TIME) seconds (or not finite): the reader would
    /// refuse the file.
    #[error(
        "frame time {value} is not a number of seconds from {} to {}",
        crate::MIN_FRAME_TIME,
        crate::MAX_FRAME_TIME
    )]
    BadFrameTime {
        /// The frame time.
        value: f64,
    },
}

/// An error reading or writing a BVH file, or writing to a stream.
///
/// The file variants display the path first: `walk.bvh: line 12, column 5: ...`.
#[non_exhaustive]
#[derive(thiserror::Error, Debug)]
pub enum Error {
    /// The file could not be read, created, written, synced or renamed.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file being read or written (for writes, the destination, not the temporary file).
        path: PathBuf,
        /// The operating system's error.
        source: std::io::Error,
        /// Whether the file was being read (an input that cannot be read) rather than
        /// written (a task that failed).
        reading: bool,
    },
    /// The file's text is not valid BVH.
    #[error("{}: {source}", path.display())]
    Parse {
        /// The file.
        path: PathBuf,
        /// Where and why.
        source: ParseError,
    },
    /// The document cannot be written to this file.
    #[error("{}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The inconsistency.
        source: WriteError,
    },
    /// [`write`](crate::write) was given a document it cannot write.
    #[error("cannot write BVH: {source}")]
    Invalid {
        /// The inconsistency.
        source: WriteError,
    },
    /// [`write`](crate::write)'s output failed.
    #[error("writing BVH: {source}")]
    Stream {
        /// The writer's error.
        source: std::io::Error,
    },
}

impl kinergy_io::Classify for Error {
    /// A file that cannot be read, is not BVH or holds a document that cannot be written is
    /// a capture's fault; a write the system refused is a failed task.
    fn kind(&self) -> kinergy_io::ErrorKind {
        match self {
            Error::Io { reading: false, .. } | Error::Stream { .. } => kinergy_io::ErrorKind::Io,
            _ => kinergy_io::ErrorKind::Capture,
        }
    }

    fn location(&self) -> Option<kinergy_io::Location> {
        let (path, line, column) = match self {
            Error::Parse { path, source } => (path, Some(source.line), Some(source.column)),
            Error::Io { path, .. } | Error::Write { path, .. } => (path, None, None),
            Error::Invalid { .. } | Error::Stream { .. } => return None,
        };
        Some(kinergy_io::Location {
            path: path.clone(),
            line,
            column,
        })
    }
}

impl kinergy_io::Classify for ParseError {
    fn kind(&self) -> kinergy_io::ErrorKind {
        kinergy_io::ErrorKind::Capture
    }
}
