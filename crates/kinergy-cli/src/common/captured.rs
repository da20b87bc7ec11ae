//! Captured reaches from the command line: which frames of which clips are reaches (given
//! frames, a segments file, or the labelled segments of the hand-speed series), how the
//! capture is read, the arm and the base.
//!
//! Frames are numbered from 0 and `A..B` excludes B everywhere (see "Frames" in
//! [`kinergy_motion::segment`]): what `kinergy segment` prints pastes into `--frames` and into
//! a segments file as it is.

use std::path::{Path, PathBuf};

use kinergy_motion::segment::Selection;
use kinergy_solver::BaseMode;
use kinergy_train::segments_file::SegmentsFile;
use kinergy_train::source::{
    ArmChoice, ArmRequest, Found, FoundReach, ReachFrames, ReachQuery, nothing_found, segment_clips,
};
pub use kinergy_train::source::{ControllerKind, Skipped};
use kinergy_train::{CapturedReach, TrainError};

use super::args::arm_failure_with;
use super::args::{ArmArgs, ArmSide, ReadArgs, parse_frames};
use super::clips::collect_clips;
use super::failure::Failure;

/// Which part of each clip is the reach, and how it is read.
#[derive(Debug, clap::Args)]
pub struct CaptureArgs {
    /// The reach's frames `A..B` (0-based, end excluded): one window, the same in every clip.
    /// Default: the segments `--select` picks.
    #[arg(long, value_name = "A..B")]
    pub frames: Option<String>,
    /// A segments file (`clip,onset,end,arm[,label,person,target_x,target_y,target_z,
    /// peak_speed_m_s,duration_s]`, as `kinergy segment --manifest` or `kinergy synth
    /// --params` writes it): every row is a reach, with its own frames and arm (`--arm` is not
    /// used), aimed at the row's target (world meters) where it has one, else at the hand's
    /// position on its last frame. A row with a tempo (a motion the full body's synergy arm
    /// made) is synthesized by that controller: its smooth bounds made for that tempo, from
    /// rest, the shoulder open as that arm's.
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
    /// The synergy controller: `smooth` (bounded accelerations, progress floor, the finish to
    /// the plain optimizer after the reach's frames, the capture's start velocity; see
    /// `docs/guide/fitting.md` "The controller: smooth (the default) or the paper's") or
    /// `paper` (Aubry et al.'s Θ ← clamp(Θ + S(t)·O(ΔX)) alone, from rest).
    #[arg(long, default_value_t = ControllerKind::Smooth, value_parser = crate::common::named::<ControllerKind>(ControllerKind::ALL.map(ControllerKind::name)))]
    pub controller: ControllerKind,
    #[command(flatten)]
    pub read: ReadArgs,
    #[command(flatten)]
    pub arm: ArmArgs,
}

/// The clips a command works on, with the segments file when it named them (so that it is
/// read once).
#[derive(Debug)]
pub struct CaptureClips {
    /// The clip files.
    pub paths: Vec<PathBuf>,
    segments: Option<SegmentsFile>,
}

impl CaptureClips {
    /// The segments file, when the clips came with one.
    pub fn segments(&self) -> Option<&SegmentsFile> {
        self.segments.as_ref()
    }

    /// Every clip file the command reads or could be asked to: [`paths`](Self::paths) and,
    /// with `--segments`, every clip the file names (also those CLIPS leave out), for the
    /// output check.
    pub fn inputs(&self) -> Vec<&Path> {
        let mut inputs: Vec<&Path> = self.paths.iter().map(PathBuf::as_path).collect();
        if let Some(segments) = &self.segments {
            inputs.extend(segments.rows().iter().map(|row| row.clip.as_path()));
        }
        inputs
    }
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

    /// The library's request for the reaches these arguments describe (checked: `--arm
    /// auto` finds each take's reaches itself, so not with one `--frames` window for all,
    /// nor with one numbered segment).
    pub fn query(&self) -> Result<ReachQuery, Failure> {
        let frames = match &self.frames {
            Some(text) => ReachFrames::Window(parse_frames(text)?),
            None => ReachFrames::Segments(self.select.unwrap_or_default()),
        };
        let arm = match self.arm.arm {
            ArmSide::Auto => ArmRequest::Auto,
            ArmSide::Side(side) => ArmRequest::Arm(ArmChoice {
                side,
                joints: self.arm.chain.clone(),
            }),
        };
        let query = ReachQuery {
            frames,
            arm,
            base: self.mode(),
            controller: self.controller,
            read: self.read.options(),
        };
        if self.segments.is_none() {
            query
                .validate()
                .map_err(|e| Failure::Input(flag_message(&e)))?;
        }
        Ok(query)
    }

    /// Checks the arguments before any work ([`query`](Self::query)).
    pub fn check_arm(&self) -> Result<(), Failure> {
        self.query().map(|_| ())
    }

    /// The clip files: `given` (files or folders, see [`collect_clips`]); with `--segments`
    /// and nothing given, the segments file's clips in the order they first appear.
    pub fn clips(&self, given: &[PathBuf]) -> Result<CaptureClips, Failure> {
        match (&self.segments, given.is_empty()) {
            (Some(path), true) => {
                let segments = read_segments(path)?;
                let paths = segment_clips(&segments);
                if paths.is_empty() {
                    return Err(Failure::Input(format!(
                        "{}: no segment rows",
                        path.display()
                    )));
                }
                Ok(CaptureClips {
                    paths,
                    segments: Some(segments),
                })
            }
            // CLIPS filter the segments file's rows; the file is read now all the same, so
            // that the clips it names are known as inputs (an output over one is refused).
            (segments, _) => Ok(CaptureClips {
                paths: collect_clips(given)?,
                segments: segments.as_deref().map(read_segments).transpose()?,
            }),
        }
    }

    /// The reaches of every clip, in order (a clip's reaches in time order; with
    /// `--segments`, in the file's row order), and the takes skipped because they have
    /// nothing to fit ([`Skipped`]; said on stderr). Everything is checked before anything
    /// is fitted: with `--segments` every error names the segments file and the row's line
    /// (a clip that cannot be read, frames outside it, an arm its skeleton lacks). No reach
    /// at all is a failed task (exit 1) listing why each take was skipped.
    pub fn load_all(&self, clips: &CaptureClips) -> Result<Vec<CapturedReach>, Failure> {
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
        clips: &CaptureClips,
    ) -> Result<Vec<(CapturedReach, Option<String>)>, Failure> {
        let query = self.query()?;
        let found = match &self.segments {
            Some(path) => {
                let segments = match &clips.segments {
                    Some(segments) => segments,
                    None => &read_segments(path)?,
                };
                query
                    .find_rows(segments, &clips.paths)
                    .map_err(|e| self.render(path, e))?
            }
            None => {
                let mut found = Found::default();
                for path in &clips.paths {
                    match self.take_with(&query, path)? {
                        Ok(reaches) => {
                            found
                                .reaches
                                .extend(reaches.into_iter().map(|reach| FoundReach {
                                    reach,
                                    person: None,
                                }))
                        }
                        Err(skip) => found.skipped.push(skip),
                    }
                }
                found
            }
        };
        report_skipped(&found.skipped);
        Ok(found
            .require_some()?
            .reaches
            .into_iter()
            .map(|f| (f.reach, f.person))
            .collect())
    }

    /// The reaches of the take at `path` (without `--segments`), with the controller
    /// applied: `Ok(Err(skipped))` when it has nothing to fit (no reach on the arm asked
    /// for, or on any arm with `--arm auto`); an input error otherwise.
    /// (`query` is the request these arguments make, built once per command.)
    fn take_with(
        &self,
        query: &ReachQuery,
        path: &Path,
    ) -> Result<Result<Vec<CapturedReach>, Skipped>, Failure> {
        match query.take_at(path) {
            Ok(found) => Ok(found),
            Err(TrainError::Setting(kinergy_io::InvalidSetting { field, why })) => {
                Err(Failure::Input(format!("--{field}: {why}")))
            }
            Err(e) => Err(self.render(path, e)),
        }
    }

    /// A capture at `path` that gave no reaches, said for the command line (bad input).
    pub fn render(&self, path: &Path, e: TrainError) -> Failure {
        match e {
            TrainError::Clip { path, source } => self.read.failure(&path, source),
            TrainError::Arm {
                path,
                source,
                other_side,
            } => arm_failure_with(source, &path, other_side),
            TrainError::Row {
                file,
                line,
                clip,
                source,
            } => {
                let at = match line {
                    Some(line) => format!("{} line {line}", file.display()),
                    None => file.display().to_string(),
                };
                let why = match *source {
                    e @ (TrainError::Clip { .. } | TrainError::Arm { .. }) => {
                        self.render(&clip, e).to_string()
                    }
                    e => format!("{}: {e}", clip.display()),
                };
                Failure::Input(format!("{at}: {why}"))
            }
            e @ (TrainError::Segments { .. } | TrainError::NoRows { .. }) => {
                Failure::Input(e.to_string())
            }
            e => Failure::input(path, e),
        }
    }
}

/// Says on stderr which takes were skipped and why (the first few; the count of the rest).
pub fn report_skipped(skipped: &[Skipped]) {
    if skipped.is_empty() {
        return;
    }
    eprintln!(
        "skipped {} take{} with nothing to fit:",
        skipped.len(),
        if skipped.len() == 1 { "" } else { "s" }
    );
    for s in skipped.iter().take(SKIPPED_SHOWN) {
        eprintln!(
            "  {}: {}",
            s.clip.display(),
            kinergy_io::clip_text(&s.why, 300)
        );
    }
    if skipped.len() > SKIPPED_SHOWN {
        eprintln!("  … and {} more", skipped.len() - SKIPPED_SHOWN);
    }
}

/// How many skipped takes stderr names.
const SKIPPED_SHOWN: usize = 10;

/// The failure of a run where every take was skipped (exit 1: the input was fine, there is
/// nothing in it to fit).
pub fn nothing_to_fit(skipped: &[Skipped]) -> Failure {
    nothing_found(skipped).into()
}

/// A query's setting refused, said with its command-line flag.
fn flag_message(e: &kinergy_io::InvalidSetting) -> String {
    format!("--{}: {}", e.field, e.why)
}

/// The segments file at `path`, read as input: its errors (naming the file and the line) are
/// bad input.
fn read_segments(path: &Path) -> Result<SegmentsFile, Failure> {
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
