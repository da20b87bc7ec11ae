//! Captured reaches from the command line: the reach's frames (given, or the main segment
//! of the hand-speed series), how the capture is read, the arm and the base.

use std::path::{Path, PathBuf};

use kinergy_solver::BaseMode;
use kinergy_train::CapturedReach;
use kinergy_train::segment::{SegmentSettings, main_segment};

use super::{ArmArgs, Failure, ReadArgs, parse_frames};

/// Which part of each clip is the reach, and how it is read.
#[derive(Debug, clap::Args)]
pub struct CaptureArgs {
    /// The reach's frames `A..B` (0-based, end excluded), the same in every clip; default:
    /// the main reach segment found from the hand speed (see `kinergy segment`).
    #[arg(long, value_name = "A..B")]
    pub frames: Option<String>,
    /// Keep the shoulder where it is on the reach's first frame instead of replaying the
    /// capture's torso motion.
    #[arg(long)]
    pub fixed_base: bool,
    #[command(flatten)]
    pub read: ReadArgs,
    #[command(flatten)]
    pub arm: ArmArgs,
}

impl CaptureArgs {
    /// The base mode chosen.
    pub fn mode(&self) -> BaseMode {
        if self.fixed_base {
            BaseMode::Fixed
        } else {
            BaseMode::Replay
        }
    }

    /// The reach of one clip file.
    pub fn load(&self, path: &Path) -> Result<CapturedReach, Failure> {
        let (clip, _) = self.read.read(path)?;
        let arm = self.arm.find(&clip, path)?;
        let name = path.display().to_string();
        let frames = match &self.frames {
            Some(text) => parse_frames(text)?,
            None => main_segment(&clip, &arm, &SegmentSettings::default(), &name)
                .map_err(|e| Failure::input(path, e))?
                .frames(),
        };
        CapturedReach::new(&name, &clip, &arm, frames, self.mode())
            .map_err(|e| Failure::input(path, e))
    }

    /// The reaches of every clip, in order.
    pub fn load_all(&self, clips: &[PathBuf]) -> Result<Vec<CapturedReach>, Failure> {
        clips.iter().map(|c| self.load(c)).collect()
    }
}
