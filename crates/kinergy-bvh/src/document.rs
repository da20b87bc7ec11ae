//! The typed BVH document: what a file says, nothing more.

/// One channel of a joint, in the order the file lists it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Channel {
    /// Translation along the parent's X axis.
    Xposition,
    /// Translation along the parent's Y axis.
    Yposition,
    /// Translation along the parent's Z axis.
    Zposition,
    /// Rotation about X, in degrees in the file.
    Xrotation,
    /// Rotation about Y, in degrees in the file.
    Yrotation,
    /// Rotation about Z, in degrees in the file.
    Zrotation,
}

impl Channel {
    /// All six channels.
    pub const ALL: [Channel; 6] = [
        Channel::Xposition,
        Channel::Yposition,
        Channel::Zposition,
        Channel::Xrotation,
        Channel::Yrotation,
        Channel::Zrotation,
    ];

    /// The name the file uses, e.g. `"Zrotation"`.
    pub fn name(self) -> &'static str {
        match self {
            Channel::Xposition => "Xposition",
            Channel::Yposition => "Yposition",
            Channel::Zposition => "Zposition",
            Channel::Xrotation => "Xrotation",
            Channel::Yrotation => "Yrotation",
            Channel::Zrotation => "Zrotation",
        }
    }

    /// Parses a channel name. Case-insensitive, as real exporters vary
    /// (`Xposition`, `XPOSITION`, `xPosition`).
    pub fn from_name(name: &str) -> Option<Channel> {
        Channel::ALL
            .into_iter()
            .find(|c| c.name().eq_ignore_ascii_case(name))
    }

    /// True for the three rotation channels.
    pub fn is_rotation(self) -> bool {
        matches!(
            self,
            Channel::Xrotation | Channel::Yrotation | Channel::Zrotation
        )
    }

    /// True for the three position channels.
    pub fn is_position(self) -> bool {
        !self.is_rotation()
    }

    /// The axis index: 0 for X, 1 for Y, 2 for Z.
    pub fn axis(self) -> usize {
        match self {
            Channel::Xposition | Channel::Xrotation => 0,
            Channel::Yposition | Channel::Yrotation => 1,
            Channel::Zposition | Channel::Zrotation => 2,
        }
    }
}

impl std::fmt::Display for Channel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One node of the hierarchy: the `ROOT`, a `JOINT`, or an `End Site`.
#[derive(Debug, Clone, PartialEq)]
pub struct Joint {
    /// The joint's name; `None` for an End Site (the format gives them none).
    pub name: Option<String>,
    /// Index of the parent in [`Bvh::joints`]; `None` for the root.
    pub parent: Option<usize>,
    /// `OFFSET` from the parent, in the file's unit.
    pub offset: [f64; 3],
    /// `CHANNELS` in file order (empty for End Sites and channel-less joints).
    pub channels: Vec<Channel>,
    /// Index of this joint's first value in a frame row of [`Bvh::motion`].
    pub first_channel: usize,
    /// True for an `End Site`.
    pub end_site: bool,
    /// 1-based line of the `ROOT`/`JOINT`/`End` keyword in the source (0 if built in memory).
    pub line: usize,
}

impl Joint {
    /// The joint's name, or `"End Site"` for an End Site.
    pub fn display_name(&self) -> &str {
        self.name.as_deref().unwrap_or("End Site")
    }
}

/// A whole BVH file: the hierarchy, then the motion.
///
/// Joints are stored in file (depth-first) order, so a parent always comes before its
/// children and index 0 is the root. Frame `f` is the slice
/// `motion[f * channel_count .. (f + 1) * channel_count]`, values exactly as the file wrote
/// them (degrees for rotations, the file's length unit for positions).
#[derive(Debug, Clone, PartialEq)]
pub struct Bvh {
    /// The hierarchy in depth-first file order; index 0 is the root.
    pub joints: Vec<Joint>,
    /// `Frame Time` in seconds.
    pub frame_time: f64,
    /// The number of frames.
    pub frame_count: usize,
    /// All channel values, frame after frame (`frame_count * channel_count()` values).
    pub motion: Vec<f64>,
}

impl Bvh {
    /// The number of channels in one frame.
    pub fn channel_count(&self) -> usize {
        self.joints.iter().map(|j| j.channels.len()).sum()
    }

    /// The values of frame `index`, or `None` past the end.
    pub fn frame(&self, index: usize) -> Option<&[f64]> {
        let n = self.channel_count();
        if index >= self.frame_count {
            return None;
        }
        let start = index.checked_mul(n)?;
        self.motion.get(start..start.checked_add(n)?)
    }

    /// The index of the joint named `name` (End Sites have no names).
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints
            .iter()
            .position(|j| j.name.as_deref() == Some(name))
    }

    /// The indices of the children of joint `index`.
    pub fn children(&self, index: usize) -> impl Iterator<Item = usize> + '_ {
        self.joints
            .iter()
            .enumerate()
            .filter(move |(_, j)| j.parent == Some(index))
            .map(|(i, _)| i)
    }

    /// The number of frames per second, `1 / frame_time`.
    pub fn frame_rate(&self) -> f64 {
        1.0 / self.frame_time
    }

    /// True if `self` and `other` hold the same document: the same joints (names,
    /// parents, offsets, channels, first channels, End Sites), frame time, frame count and
    /// motion, ignoring [`Joint::line`] (which records where a joint was in its source
    /// text, so a written and re-read document differs there).
    ///
    /// Every `f64` is compared bit for bit, so `-0.0` and `0.0` differ: this is the
    /// equality a read → write → read round trip keeps.
    pub fn same_content(&self, other: &Bvh) -> bool {
        fn same_f64(a: &[f64], b: &[f64]) -> bool {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
        }
        self.frame_count == other.frame_count
            && self.frame_time.to_bits() == other.frame_time.to_bits()
            && self.joints.len() == other.joints.len()
            && self.joints.iter().zip(&other.joints).all(|(a, b)| {
                a.name == b.name
                    && a.parent == b.parent
                    && same_f64(&a.offset, &b.offset)
                    && a.channels == b.channels
                    && a.first_channel == b.first_channel
                    && a.end_site == b.end_site
            })
            && same_f64(&self.motion, &other.motion)
    }

    /// The number of End Sites.
    pub fn end_site_count(&self) -> usize {
        self.joints.iter().filter(|j| j.end_site).count()
    }
}

/// True if `name` can be a joint name in a file: not empty, not `{` or `}`, and without
/// whitespace or control characters (so the reader reads it back as one token).
pub(crate) fn is_valid_name(name: &str) -> bool {
    !name.is_empty()
        && name != "{"
        && name != "}"
        && !name.chars().any(|c| c.is_whitespace() || c.is_control())
}
