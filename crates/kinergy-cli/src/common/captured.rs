//! Captured reaches from the command line: which frames of which clips are reaches (given
//! frames, a segments file, or the labelled segments of the hand-speed series), how the
//! capture is read, the arm and the base.
//!
//! Frames are numbered from 0 and `A..B` excludes B everywhere (see "Frames" in
//! [`kinergy_train::segment`]): what `kinergy segment` prints pastes into `--frames` and into
//! a segments file as it is.

use std::path::{Path, PathBuf};

use kinergy_motion::nalgebra::Point3;
use kinergy_solver::BaseMode;
use kinergy_train::CapturedReach;
use kinergy_train::segment::{SegmentSettings, Selection, find_segments, select};
use kinergy_train::segments_file::{SegmentRow, SegmentsFile};

use super::{ArmArgs, Failure, ReadArgs, collect_clips, parse_frames};

/// Which part of each clip is the reach, and how it is read.
#[derive(Debug, clap::Args)]
pub struct CaptureArgs {
    /// The reach's frames `A..B` (0-based, end excluded): one window, the same in every clip.
    /// Default: the segments `--select` picks.
    #[arg(long, value_name = "A..B")]
    pub frames: Option<String>,
    /// A segments file (`clip,onset,end,arm[,label,person,target_x,target_y,target_z]`, as
    /// `kinergy segment --manifest` or `kinergy synth --params` writes it): every row is a
    /// reach, with its own frames and arm (`--arm` is not used), aimed at the row's target
    /// (world meters) where it has one, else at the hand's position on its last frame.
    /// Without CLIPS the file's clips are used; CLIPS given keep only the rows of those clips.
    #[arg(long, value_name = "segments.csv", conflicts_with_all = ["frames", "select", "chain"])]
    pub segments: Option<PathBuf>,
    /// Which labelled segments of each clip are reaches when neither `--frames` nor
    /// `--segments` is given: `main` (the clip's main reach), `all` (every segment labelled
    /// reach) or `N` (segment N as `kinergy segment` lists them, from 0, whatever its label).
    #[arg(long, value_name = "main|all|N", conflicts_with = "frames")]
    pub select: Option<Selection>,
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

    /// The clip files: `given` (files or folders, see [`collect_clips`]); with `--segments`
    /// and nothing given, the segments file's clips in the order they first appear.
    pub fn clips(&self, given: &[PathBuf]) -> Result<Vec<PathBuf>, Failure> {
        match (&self.segments, given.is_empty()) {
            (Some(path), true) => {
                let manifest = read_manifest(path)?;
                let mut clips: Vec<PathBuf> = Vec::new();
                for row in manifest.rows() {
                    if !clips.contains(&row.clip) {
                        clips.push(row.clip.clone());
                    }
                }
                if clips.is_empty() {
                    return Err(Failure::Input(format!(
                        "{}: no segment rows",
                        path.display()
                    )));
                }
                Ok(clips)
            }
            _ => collect_clips(given),
        }
    }

    /// The reaches of one clip file: one for `--frames`, else those `--select` picks.
    pub fn load(&self, path: &Path) -> Result<Vec<CapturedReach>, Failure> {
        let (clip, _) = self.read.read(path)?;
        let arm = self.arm.find(&clip, path)?;
        let name = path.display().to_string();
        let windows = match &self.frames {
            Some(text) => vec![parse_frames(text)?],
            None => {
                let segments = find_segments(&clip, &arm, &SegmentSettings::default())
                    .map_err(|e| Failure::input(path, e))?;
                select(&segments, self.select.unwrap_or_default(), &name)
                    .map_err(|e| Failure::input(path, e))?
                    .iter()
                    .map(|s| s.frames())
                    .collect()
            }
        };
        windows
            .into_iter()
            .map(|frames| {
                CapturedReach::new(&name, &clip, &arm, frames, self.mode())
                    .map_err(|e| Failure::input(path, e))
            })
            .collect()
    }

    /// The reaches of every clip, in order (a clip's reaches in time order; with
    /// `--segments`, in the file's row order). Everything is checked before anything is
    /// fitted: with `--segments` every error names the segments file and the row's line (a
    /// clip that cannot be read, frames outside it, an arm its skeleton lacks).
    pub fn load_all(&self, clips: &[PathBuf]) -> Result<Vec<CapturedReach>, Failure> {
        Ok(self
            .load_all_with_persons(clips)?
            .into_iter()
            .map(|(reach, _)| reach)
            .collect())
    }

    /// [`load_all`](Self::load_all), each reach with the person its segments-file row names
    /// (`None` without `--segments`).
    pub fn load_all_with_persons(
        &self,
        clips: &[PathBuf],
    ) -> Result<Vec<(CapturedReach, Option<String>)>, Failure> {
        let Some(path) = &self.segments else {
            let mut out = Vec::new();
            for c in clips {
                out.extend(self.load(c)?.into_iter().map(|r| (r, None)));
            }
            return Ok(out);
        };
        let manifest = read_manifest(path)?;
        let mut out = Vec::new();
        for c in clips {
            let rows: Vec<&SegmentRow> = manifest.rows_for(c).collect();
            if rows.is_empty() {
                continue;
            }
            let at = |row: &SegmentRow| match row.line {
                Some(line) => format!("{} line {line}", path.display()),
                None => path.display().to_string(),
            };
            let (clip, _) = self
                .read
                .read(c)
                .map_err(|e| Failure::Input(format!("{}: {e}", at(rows[0]))))?;
            let name = c.display().to_string();
            for row in rows {
                let frames = manifest
                    .resolve(row, &clip)
                    .map_err(|e| Failure::Input(e.to_string()))?;
                let side_arm = ArmArgs {
                    arm: row.arm,
                    chain: None,
                };
                let arm = side_arm
                    .find(&clip, c)
                    .map_err(|e| Failure::Input(format!("{}: {e}", at(row))))?;
                let mut reach = CapturedReach::new(&name, &clip, &arm, frames, self.mode())
                    .map_err(|e| Failure::Input(format!("{}: {}: {e}", at(row), c.display())))?;
                if let Some(t) = row.target {
                    reach = reach.with_target(Point3::from(t));
                }
                out.push((reach, Some(row.person.clone())));
            }
        }
        if out.is_empty() {
            return Err(Failure::Input(format!(
                "{}: no row names any of the clips given",
                path.display()
            )));
        }
        Ok(out)
    }
}

fn read_manifest(path: &Path) -> Result<SegmentsFile, Failure> {
    SegmentsFile::read(path).map_err(|e| Failure::Input(e.to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        capture: CaptureArgs,
    }

    #[test]
    fn segments_exclude_frames_and_select() {
        assert!(Cli::try_parse_from(["x", "--segments", "s.csv", "--frames", "1..9"]).is_err());
        assert!(Cli::try_parse_from(["x", "--segments", "s.csv", "--select", "all"]).is_err());
        assert!(Cli::try_parse_from(["x", "--frames", "1..9", "--select", "2"]).is_err());
        let cli = Cli::try_parse_from(["x", "--select", "2"]).expect("parses");
        assert_eq!(cli.capture.select, Some(Selection::Nth(2)));
    }
}
