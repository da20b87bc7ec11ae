//! Captured reaches from the command line: clip paths (files or folders), the reach's
//! frames (given, or the main segment of the hand-speed series), the arm and the base.

use std::path::{Path, PathBuf};

use kinergy_solver::BaseMode;
use kinergy_train::ReachData;
use kinergy_train::segment::{SegmentSettings, main_segment};

use crate::common::{ArmArgs, Failure, ReadArgs};

/// Which part of each clip is the reach, and how it is read.
#[derive(Debug, clap::Args)]
pub struct ReachArgs {
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

impl ReachArgs {
    /// The base mode chosen.
    pub fn mode(&self) -> BaseMode {
        if self.fixed_base {
            BaseMode::Fixed
        } else {
            BaseMode::Replay
        }
    }

    /// The reach of one clip file.
    pub fn load(&self, path: &Path) -> Result<ReachData, Failure> {
        let (clip, _) = self.read.read(path)?;
        let arm = self.arm.find(&clip, path)?;
        let name = path.display().to_string();
        let frames = match &self.frames {
            Some(text) => parse_frames(text)?,
            None => main_segment(&clip, &arm, &SegmentSettings::default(), &name)
                .map_err(|e| Failure::input(path, e))?
                .frames(),
        };
        ReachData::new(&name, &clip, &arm, frames, self.mode()).map_err(|e| Failure::input(path, e))
    }

    /// The reaches of every clip, in order.
    pub fn load_all(&self, clips: &[PathBuf]) -> Result<Vec<ReachData>, Failure> {
        clips.iter().map(|c| self.load(c)).collect()
    }
}

/// `A..B` → `A..B`, with `A < B`.
pub fn parse_frames(text: &str) -> Result<std::ops::Range<usize>, Failure> {
    let bad = |why: &str| Failure::Input(format!("--frames `{text}`: {why}"));
    let (a, b) = text
        .split_once("..")
        .ok_or_else(|| bad("expected A..B, e.g. 12..140"))?;
    let a: usize = a
        .trim()
        .parse()
        .map_err(|_| bad("A is not a frame number"))?;
    let b: usize = b
        .trim()
        .parse()
        .map_err(|_| bad("B is not a frame number"))?;
    if a >= b {
        return Err(bad("A must be smaller than B"));
    }
    Ok(a..b)
}

/// The BVH files named: files as given, folders expanded to the `*.bvh` files in them and
/// in their subfolders (sorted by path). An empty result or a missing path is bad input.
pub fn collect_clips(paths: &[PathBuf]) -> Result<Vec<PathBuf>, Failure> {
    let mut out = Vec::new();
    for p in paths {
        if p.is_dir() {
            let mut found = Vec::new();
            walk(p, &mut found)?;
            found.sort();
            if found.is_empty() {
                return Err(Failure::Input(format!(
                    "{}: no .bvh files in this folder",
                    p.display()
                )));
            }
            out.extend(found);
        } else if p.is_file() {
            out.push(p.clone());
        } else {
            return Err(Failure::Input(format!(
                "{}: no such file or folder",
                p.display()
            )));
        }
    }
    if out.is_empty() {
        return Err(Failure::Input("no clips given".into()));
    }
    Ok(out)
}

/// Every `*.bvh` file under `dir`.
fn walk(dir: &Path, out: &mut Vec<PathBuf>) -> Result<(), Failure> {
    let entries = std::fs::read_dir(dir).map_err(|e| Failure::input(dir, e))?;
    for entry in entries {
        let path = entry.map_err(|e| Failure::input(dir, e))?.path();
        if path.is_dir() {
            walk(&path, out)?;
        } else if path
            .extension()
            .is_some_and(|x| x.eq_ignore_ascii_case("bvh"))
        {
            out.push(path);
        }
    }
    Ok(())
}
