//! The error type of `kinergy-plan`.

use std::path::PathBuf;

use kinergy_motion::MotionError;
use kinergy_reach::ReachError;
use kinergy_solver::analytic::AnalyticError;

use crate::level::{Level, LevelTry};

/// Everything that can go wrong in `kinergy-plan`: bad input (scene files, OBJ meshes,
/// settings) and the planner's typed failures.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlanError {
    /// A file could not be read.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// A scene file is malformed: `field` is the JSON path of the offending value, e.g.
    /// `objects[2].shape.box.half_extents`.
    #[error("{}: `{field}`: {why}", path.display())]
    Scene {
        /// The scene file (empty when the scene came from a string).
        path: PathBuf,
        /// The JSON path of the offending value.
        field: String,
        /// What was expected.
        why: String,
    },
    /// An OBJ mesh is malformed.
    #[error("{}:{line}: {why}", path.display())]
    Obj {
        /// The mesh file.
        path: PathBuf,
        /// 1-based line number (0 for the file as a whole).
        line: usize,
        /// What was expected.
        why: String,
    },
    /// A setting or argument is outside what it may be (named by its field, e.g. `rrt.step`).
    #[error(transparent)]
    Setting(#[from] kinergy_io::InvalidSetting),
    /// The character could not be built or exported.
    #[error(transparent)]
    Reach(#[from] ReachError),
    /// A skeleton or clip operation failed.
    #[error(transparent)]
    Motion(#[from] MotionError),
    /// The start posture already collides: the planner has nowhere to start from.
    #[error("the start posture is in collision: {contact}")]
    StartInCollision {
        /// The first colliding pair, e.g. `right_forearm × shelf`.
        contact: String,
    },
    /// An object would not stand where it is to be placed: it would intersect another object
    /// or float with nothing under it.
    #[error("cannot place `{object}` there: {why}")]
    Placement {
        /// The object placed.
        object: String,
        /// What is wrong with the place.
        why: String,
    },
    /// No posture of the arm reaches the goal within the joint limits, whatever the
    /// collisions.
    #[error("the goal is unreachable: {why}")]
    GoalUnreachable {
        /// Why, from the analytic IK.
        why: String,
    },
    /// Postures reach the goal within the joint limits, but every one the orbit-angle search
    /// tried collides.
    #[error(
        "the goal is in collision at every orbit angle tried ({tried} postures within limits; first contact {contact})"
    )]
    GoalInCollision {
        /// Postures within the joint limits that were tried.
        tried: usize,
        /// The first colliding pair found at the first posture.
        contact: String,
    },
    /// The planner's budget ran out before the two trees met.
    #[error(
        "no collision-free path within the budget ({iterations} iterations, {elapsed_ms:.1} ms, \
         {nodes} nodes); the trees came within {gap:.3} m of each other"
    )]
    NoPath {
        /// Iterations done.
        iterations: usize,
        /// Time spent, milliseconds.
        elapsed_ms: f64,
        /// Nodes in both trees.
        nodes: usize,
        /// The best progress: the smallest distance (the planner's metric, meters) seen
        /// between a node of one tree and a node of the other.
        gap: f64,
    },
    /// A straight hand path (a reach's `ik` or `straight` level, [`crate::level`]) is blocked:
    /// on some frame no posture of the orbit-angle search is free, or the motion between two
    /// frames collides.
    #[error(
        "the straight hand path is blocked {:.0} % of the way (frame {frame} of {frames}): {why}",
        100.0 * .fraction
    )]
    PathBlocked {
        /// The frame, 1-based from the start's (frame 0).
        frame: usize,
        /// The frames after the start's.
        frames: usize,
        /// How far along the hand's line, 0 to 1.
        fraction: f64,
        /// What blocks it: the first contact, or why the IK found no posture.
        why: String,
    },
    /// A reach failed at the level asked for (`plan --level`), or at every level `auto` tried
    /// ([`crate::level`]).
    #[error("{}", say_levels(*.asked, .tried, .cause))]
    Level {
        /// The level asked for.
        asked: Level,
        /// The levels tried, in order, each with why it failed.
        tried: Vec<LevelTry>,
        /// The last failure; the error is of its kind.
        cause: Box<PlanError>,
    },
    /// A value was NaN or infinite.
    #[error("{0} is not finite")]
    NonFinite(String),
    /// A person's synergy moves the hand with no bell-shaped speed, so their timing cannot
    /// warp a plan ([`crate::person::person_warp`]).
    #[error(
        "the person's synergy moves the hand with no bell-shaped speed (over {frames} frames \
         of a reach 0.4 m in front of the shoulder): their timing cannot play a plan"
    )]
    NoBell {
        /// The frames of the synergy's own part of the reach.
        frames: usize,
    },
    /// A task's report ([`crate::report`]) is not JSON of a report.
    #[error("not a `kinergy plan --json` report: {why}")]
    ReportJson {
        /// What the JSON reader said (at most 120 characters).
        why: String,
    },
    /// A report has no frame time: it was written before reports recorded it.
    #[error(
        "the report has no frame_time_s: it was written by an older kinergy; run `kinergy plan ... --json` again"
    )]
    ReportNoFrameTime,
    /// A report's frame time is not a number > 0.
    #[error("frame_time_s {0}: expected a number > 0")]
    ReportFrameTime(f64),
    /// A report's object has no per-frame poses: it was written before reports recorded them.
    #[error(
        "object `{}` has no per-frame poses: the report was written by an older kinergy; run `kinergy plan ... --json` again",
        kinergy_io::clip_text(object, 120)
    )]
    ReportNoPoses {
        /// The object's name.
        object: String,
    },
    /// A report's object has no poses or too many.
    #[error(
        "object `{}`: {count} poses, expected 1 to {max}",
        kinergy_io::clip_text(object, 120)
    )]
    ReportPoseCount {
        /// The object's name.
        object: String,
        /// The poses it has.
        count: usize,
        /// The most it may have ([`crate::report::MAX_OBJECT_POSES`]).
        max: usize,
    },
    /// A report's object pose has a number that is not finite or a zero rotation.
    #[error(
        "object `{}` pose {index}: expected finite numbers and a non-zero rotation",
        kinergy_io::clip_text(object, 120)
    )]
    ReportPose {
        /// The object's name.
        object: String,
        /// The pose's frame.
        index: usize,
    },
}

impl kinergy_io::Classify for PlanError {
    /// A goal or start the arm cannot take, no path, or an object that would not stand where
    /// it is put is the task's failure
    /// ([`ErrorKind::Unreachable`](kinergy_io::ErrorKind::Unreachable)); scenes, meshes, settings and reports that are
    /// not what they should be are the input's.
    fn kind(&self) -> kinergy_io::ErrorKind {
        use kinergy_io::ErrorKind;
        match self {
            PlanError::Reach(e) => e.kind(),
            PlanError::Level { cause, .. } => cause.kind(),
            PlanError::StartInCollision { .. }
            | PlanError::GoalUnreachable { .. }
            | PlanError::GoalInCollision { .. }
            | PlanError::NoPath { .. }
            | PlanError::PathBlocked { .. }
            | PlanError::Placement { .. } => ErrorKind::Unreachable,
            _ => ErrorKind::Input,
        }
    }
}

impl From<AnalyticError> for PlanError {
    fn from(e: AnalyticError) -> PlanError {
        match e {
            AnalyticError::NonFinite(what) => PlanError::NonFinite(what),
            AnalyticError::Setting(_) => {
                PlanError::Setting(kinergy_io::InvalidSetting::new("ik", e.to_string()))
            }
            other => PlanError::GoalUnreachable {
                why: other.to_string(),
            },
        }
    }
}

/// A level failure as people read it: `level straight failed: …` for a forced level;
/// `level auto: ik failed: …; straight failed: …; planner failed: …` after escalating, or
/// where the escalation stopped and why.
fn say_levels(asked: Level, tried: &[LevelTry], cause: &PlanError) -> String {
    let last = tried.last().map_or(asked, |t| t.level);
    if asked != Level::Auto {
        return format!("level {asked} failed: {cause}");
    }
    let mut text = String::from("level auto: ");
    for t in &tried[..tried.len().saturating_sub(1)] {
        text += &format!(
            "{} failed: {}; ",
            t.level,
            t.failure.as_deref().unwrap_or("?")
        );
    }
    // `auto` stops before the planner only on a failure no level mends.
    if last == Level::Planner {
        text += &format!("{last} failed: {cause}");
    } else {
        text += &format!("stopped at {last}, as no level can mend this: {cause}");
    }
    text
}

/// Shorthand for results of this crate.
pub type Result<T, E = PlanError> = std::result::Result<T, E>;
