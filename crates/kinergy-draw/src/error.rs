//! Why a picture was not made: [`DrawError`], classified for the front ends
//! ([`kinergy_io::Classify`]): a file name, clip, scene or report that is not what it should be
//! is the input's fault; a picture that could not be written, drawn or encoded is the task's.

use std::fmt;
use std::path::{Path, PathBuf};

use kinergy_io::ErrorKind;

/// Why a picture was not made. Messages about a file name it once.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DrawError {
    /// A chart's file name ends in neither `.svg` nor `.png`.
    #[error("{}: the file name must end in .svg or .png", .path.display())]
    Format {
        /// The picture asked for.
        path: PathBuf,
    },
    /// A picture could not be written (a full disk, permissions).
    #[error("{}", naming(.path, .source))]
    Io {
        /// The picture.
        path: PathBuf,
        /// What the system said.
        source: std::io::Error,
    },
    /// A picture could not be drawn or encoded.
    #[error("{}", naming(.path, .why))]
    Drawing {
        /// The picture.
        path: PathBuf,
        /// What failed, as people read it.
        why: String,
    },
    /// A clip to animate has no frames (or no joints).
    #[error("{}", naming(.path, &"the clip has no frames to draw"))]
    NoFrames {
        /// The clip's file.
        path: PathBuf,
    },
    /// A clip's joints could not be placed (forward kinematics failed).
    #[error("{}", naming(.path, .source))]
    Figure {
        /// The clip's file.
        path: PathBuf,
        /// Why.
        source: kinergy_motion::MotionError,
    },
    /// A scene drawn behind the figures cannot be read.
    #[error("{}", naming(.path, .source))]
    Scene {
        /// The scene file.
        path: PathBuf,
        /// Why.
        source: kinergy_plan::PlanError,
    },
    /// A plan report (the moved objects' poses) cannot be read.
    #[error("{}", naming(.path, .source))]
    ReportRead {
        /// The report file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// A plan report is not what it should be (JSON, frame time, poses).
    #[error("{}", naming(.path, .source))]
    Report {
        /// The report file.
        path: PathBuf,
        /// Why.
        source: kinergy_plan::PlanError,
    },
    /// A plan report moves an object the scene does not have.
    #[error("{}", naming(.path, &format!("object `{}` is not in the scene {}", kinergy_io::clip_text(.object, 120), .scene.display())))]
    NotInScene {
        /// The report file.
        path: PathBuf,
        /// The object's name.
        object: String,
        /// The scene file.
        scene: PathBuf,
    },
    /// A style run's capture has no frame where its picture needs one.
    #[error("{name}: no frame {frame}")]
    NoFrame {
        /// The capture's name.
        name: String,
        /// The frame asked for.
        frame: usize,
    },
    /// A style run's pose could not be placed (forward kinematics failed).
    #[error("{name}: {source}")]
    Pose {
        /// The capture's name.
        name: String,
        /// Why.
        source: kinergy_motion::MotionError,
    },
    /// A clip or page the viewer cannot show (no frames, positions not finite, too many
    /// clips).
    #[error("{clip}: {why}")]
    View {
        /// The clip's file or label (the page's title for the page).
        clip: String,
        /// Why, as people read it.
        why: String,
    },
    /// A style run's capture could not be carried onto the character, or the character's
    /// poses made into a clip.
    #[error("{name}: {source}")]
    Character {
        /// The capture's name.
        name: String,
        /// Why.
        source: kinergy_reach::ReachError,
    },
}

impl DrawError {
    /// Writing `path` failed with `source`.
    pub(crate) fn io(path: &Path, source: std::io::Error) -> DrawError {
        DrawError::Io {
            path: path.to_path_buf(),
            source,
        }
    }

    /// Drawing or encoding `path` failed, saying `why`.
    pub(crate) fn drawing(path: &Path, why: impl fmt::Display) -> DrawError {
        DrawError::Drawing {
            path: path.to_path_buf(),
            why: why.to_string(),
        }
    }
}

/// `e` naming `path` once: errors about files often name them already.
fn naming(path: &Path, e: &dyn fmt::Display) -> String {
    let text = e.to_string();
    if text.contains(&*path.to_string_lossy()) {
        text
    } else {
        format!("{}: {text}", path.display())
    }
}

impl kinergy_io::Classify for DrawError {
    /// A picture that could not be written is [`ErrorKind::Io`], one that could not be drawn or
    /// a style run's figure that could not be posed [`ErrorKind::Task`]; a file name, clip,
    /// scene or report that is not what it should be is the input's ([`ErrorKind::Input`]).
    fn kind(&self) -> ErrorKind {
        match self {
            DrawError::Io { .. } => ErrorKind::Io,
            DrawError::Drawing { .. }
            | DrawError::NoFrame { .. }
            | DrawError::Pose { .. }
            | DrawError::Character { .. } => ErrorKind::Task,
            DrawError::Format { .. }
            | DrawError::NoFrames { .. }
            | DrawError::Figure { .. }
            | DrawError::Scene { .. }
            | DrawError::ReportRead { .. }
            | DrawError::Report { .. }
            | DrawError::NotInScene { .. }
            | DrawError::View { .. } => ErrorKind::Input,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use kinergy_io::Classify as _;

    #[test]
    fn a_file_is_named_once() {
        let path = Path::new("out/speed.svg");
        let named = std::io::Error::other("out/speed.svg: denied");
        assert_eq!(
            DrawError::io(path, named).to_string(),
            "out/speed.svg: denied"
        );
        let bare = std::io::Error::other("denied");
        assert_eq!(
            DrawError::io(path, bare).to_string(),
            "out/speed.svg: denied"
        );
    }

    #[test]
    fn bad_files_are_the_inputs_fault_and_failed_writes_the_tasks() {
        let path = PathBuf::from("a.gif");
        assert_eq!(
            DrawError::Format { path: path.clone() }.kind(),
            ErrorKind::Input
        );
        assert_eq!(
            DrawError::NoFrames { path: path.clone() }.to_string(),
            "a.gif: the clip has no frames to draw"
        );
        let full = std::io::Error::from(std::io::ErrorKind::StorageFull);
        assert_eq!(DrawError::io(&path, full).kind(), ErrorKind::Io);
        assert!(!DrawError::drawing(&path, "x").kind().is_input());
    }
}
