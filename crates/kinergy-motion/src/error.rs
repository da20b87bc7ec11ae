//! The error type of `kinergy-motion`.

use crate::side::Side;

/// Everything that can go wrong in `kinergy-motion`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MotionError {
    /// A BVH file could not be read or written.
    #[error(transparent)]
    Bvh(#[from] kinergy_bvh::Error),
    /// A pose or frame has the wrong number of values for its skeleton or chain.
    #[error("a pose needs {expected} values, got {found}")]
    PoseLength {
        /// Values the skeleton or chain expects.
        expected: usize,
        /// Values given.
        found: usize,
    },
    /// No joint has this name.
    #[error("no joint named `{name}`; joints are: {}", .available.join(", "))]
    UnknownJoint {
        /// The name asked for.
        name: String,
        /// Every joint name of the skeleton.
        available: Vec<String>,
    },
    /// The joints given for an arm chain do not form a parent-to-child chain.
    #[error("`{child}` is not a descendant of `{ancestor}`, so they cannot form an arm chain")]
    NotAChain {
        /// The joint expected higher up.
        ancestor: String,
        /// The joint expected below it.
        child: String,
    },
    /// No arm chain with the usual joint names was found.
    #[error(
        "no {side} arm chain found (clavicle → upper arm → forearm → hand); arm-like joints: {}",
        if .candidates.is_empty() { "none".to_string() } else { .candidates.join(", ") }
    )]
    ArmNotFound {
        /// Which arm was looked for.
        side: Side,
        /// Joints whose names look like arm joints.
        candidates: Vec<String>,
    },
    /// No leg with the usual joint names was found.
    #[error(
        "no {side} leg found (UpLeg/Thigh/Hip → Leg/Knee/Shin/Calf → Foot/Ankle); leg-like joints: {}",
        if .candidates.is_empty() { "none".to_string() } else { .candidates.join(", ") }
    )]
    LegNotFound {
        /// Which leg was looked for.
        side: Side,
        /// Joints whose names look like leg joints.
        candidates: Vec<String>,
    },
    /// A leg's ankle has no joint or End Site below it to be the toe tip.
    #[error("the {side} ankle `{ankle}` has no toe joint or End Site below it")]
    NoToe {
        /// Which leg.
        side: Side,
        /// The ankle's name.
        ankle: String,
    },
    /// A value that must be finite is NaN or infinite.
    #[error("{what} is not finite")]
    NonFinite {
        /// What held the value.
        what: String,
    },
    /// An argument is outside what the function accepts.
    #[error("invalid {what}: {why}")]
    Invalid {
        /// Which argument.
        what: &'static str,
        /// Why it was refused.
        why: String,
    },
    /// A setting is outside what it may be (named by its field, e.g. `segment.hold`).
    #[error(transparent)]
    Setting(#[from] kinergy_io::InvalidSetting),
    /// A clip has no reach segment, or not the one asked for ([`crate::segment`]).
    #[error("{clip}: {why}")]
    Reach {
        /// The clip's name.
        clip: String,
        /// What is wrong.
        why: String,
    },
    /// A clip has no frames where frames are needed.
    #[error("the clip has no frames")]
    EmptyClip,
    /// Two motions compared by the distance track a different number of joints.
    #[error("motions track different joints: {left} vs {right} per frame")]
    JointCountMismatch {
        /// Joints per frame in the first motion.
        left: usize,
        /// Joints per frame in the second motion.
        right: usize,
    },
}

/// Shorthand for results of this crate.
pub type Result<T, E = MotionError> = std::result::Result<T, E>;

impl kinergy_io::Classify for MotionError {
    /// A BVH file's errors by their own kind; everything else here is about a skeleton, a
    /// clip or an argument that does not have what is needed: the input's fault.
    fn kind(&self) -> kinergy_io::ErrorKind {
        match self {
            MotionError::Bvh(e) => e.kind(),
            _ => kinergy_io::ErrorKind::Input,
        }
    }

    fn location(&self) -> Option<kinergy_io::Location> {
        match self {
            MotionError::Bvh(e) => e.location(),
            _ => None,
        }
    }
}
