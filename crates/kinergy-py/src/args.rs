//! Python's polymorphic arguments into the library's types: the polymorphic arguments as
//! `FromPyObject` enums (a Clip or a path, a Params or a path, a segment by name or number,
//! frames by name or window, a shard as text or pair), the reading options, the reach source
//! of `fit` and `compare`, thread pools, and library values back into Python objects.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use kinergy_motion::segment::Selection;
use kinergy_motion::{ImportOptions, Side};
use kinergy_solver::BaseMode;
use kinergy_train::library::Shard;
use kinergy_train::segments_file::SegmentsFile;
use kinergy_train::source::{
    ArmChoice, ArmRequest, Capture, ControllerKind, Found, FrameChoice, ReachFrames, ReachQuery,
    Take, segment_clips, walk_captures,
};
use kinergy_train::{CapturedReach, PersonParams, limits};
use pyo3::prelude::*;

use crate::clip::Clip;
pub use crate::convert::{Reading, export_options, parse, to_python};
use crate::errors;
use crate::params::Params;

/// A polymorphic argument (`T`: one of the enums below) whose wrong type raises InputError
/// saying what is expected, as every other bad argument does (a `TypeError` would say only
/// which variants failed).
pub struct Arg<T>(pub T);

/// What an argument enum takes, for its message.
pub trait Expected {
    /// E.g. `a kinergy.Clip or a path to a BVH file`.
    const EXPECTED: &'static str;
}

impl<'a, 'py, T> FromPyObject<'a, 'py> for Arg<T>
where
    T: FromPyObject<'a, 'py> + Expected,
{
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        T::extract(obj).map(Arg).map_err(|_| {
            let got = obj
                .get_type()
                .name()
                .map_or_else(|_| "?".to_string(), |n| n.to_string());
            errors::input(format!("expected {}, got {got}", T::EXPECTED))
        })
    }
}

/// Implements [`Expected`].
macro_rules! expected {
    ($($t:ty => $text:literal),* $(,)?) => {
        $(impl Expected for $t {
            const EXPECTED: &'static str = $text;
        })*
    };
}

expected! {
    ClipArg => "a kinergy.Clip or a path to a BVH file",
    ClipsArg => "paths (files or folders) or kinergy.Clip objects, or a list of them",
    ParamsArg => "a kinergy.Params or a path to its file",
    SelectArg => "select: \"main\", \"all\" or a segment number",
    FramesArg => "frames: \"fit\", \"auto\", \"all\" or (start, end)",
    ShardArg => "shard: \"I/N\" or a tuple (I, N)",
}

/// A clip argument: a `Clip`, or a path to a BVH file.
#[derive(FromPyObject)]
pub enum ClipArg {
    /// A clip.
    Clip(Clip),
    /// A path, read with the call's reading options.
    Path(PathBuf),
}

impl ClipArg {
    /// The clip and the path it is named by (a made clip: `<clip>`).
    pub fn load(
        self,
        py: Python<'_>,
        options: &ImportOptions,
    ) -> PyResult<(kinergy_motion::Clip, PathBuf)> {
        match self {
            ClipArg::Clip(clip) => {
                let path = clip.path.unwrap_or_else(|| PathBuf::from("<clip>"));
                Ok((clip.inner, path))
            }
            ClipArg::Path(path) => {
                let read = py.detach(|| kinergy_motion::read_clip(&path, options));
                let (clip, _) = read.map_err(errors::raise)?;
                Ok((clip, path))
            }
        }
    }

    /// The take it is to a reach query: a Clip as read, a path (file or folder) as the
    /// capture files under it.
    fn takes(self, py: Python<'_>) -> PyResult<Vec<Take>> {
        Ok(match self {
            ClipArg::Clip(clip) => vec![Take::Read(Capture::from_clip(
                clip.path.as_deref().unwrap_or(Path::new("<clip>")),
                clip.inner,
            ))],
            ClipArg::Path(path) => capture_files(py, &[path])?
                .into_iter()
                .map(Take::File)
                .collect(),
        })
    }
}

/// `clips=`: one path or Clip, or a list or tuple of them.
#[derive(FromPyObject)]
pub enum ClipsArg {
    /// Several.
    Many(Vec<ClipArg>),
    /// One.
    One(ClipArg),
}

impl ClipsArg {
    /// The clips, in order.
    pub fn into_vec(self) -> Vec<ClipArg> {
        match self {
            ClipsArg::Many(v) => v,
            ClipsArg::One(c) => vec![c],
        }
    }
}

/// `params=`: a Params, or the path of a parameters or field file.
#[derive(FromPyObject)]
pub enum ParamsArg {
    /// Parameters.
    Params(Py<Params>),
    /// A file.
    Path(PathBuf),
}

impl ParamsArg {
    /// The person's parameters (a file read, naming it in its errors).
    pub fn load(self) -> PyResult<PersonParams> {
        match self {
            ParamsArg::Params(p) => Ok(p.get().inner.clone()),
            ParamsArg::Path(path) => PersonParams::read(&path).map_err(errors::raise),
        }
    }
}

/// `select=`: `"main"`, `"all"` or a segment number.
#[derive(FromPyObject)]
pub enum SelectArg {
    /// A segment's number, as `segment` lists them.
    Nth(usize),
    /// `main` or `all`.
    Named(String),
}

impl SelectArg {
    /// The selection.
    pub fn selection(self) -> PyResult<Selection> {
        match self {
            SelectArg::Nth(n) => Ok(Selection::Nth(n)),
            SelectArg::Named(text) => parse::<Selection>("select", &text),
        }
    }
}

/// `frames=` of `synthesize`: `"fit"`, `"auto"`, `"all"` or `(start, end)`.
#[derive(FromPyObject)]
pub enum FramesArg {
    /// A window, end excluded.
    Window((usize, usize)),
    /// By name.
    Named(String),
}

impl FramesArg {
    /// The frame choice.
    pub fn choice(self) -> PyResult<FrameChoice> {
        match self {
            FramesArg::Window(w) => window(w).map(FrameChoice::Window),
            FramesArg::Named(name) => match name.as_str() {
                "fit" => Ok(FrameChoice::Fitted),
                "auto" => Ok(FrameChoice::Main),
                "all" => Ok(FrameChoice::All),
                other => Err(errors::input(format!(
                    "frames={other:?}: expected \"fit\", \"auto\", \"all\" or (start, end)"
                ))),
            },
        }
    }
}

/// `(start, end)` with start < end.
fn window((a, b): (usize, usize)) -> PyResult<std::ops::Range<usize>> {
    if a < b {
        Ok(a..b)
    } else {
        Err(errors::input(format!(
            "frames=({a}, {b}): expected (start, end) with start < end"
        )))
    }
}

/// `shard=`: `"I/N"` or a pair `(I, N)`.
#[derive(FromPyObject)]
pub enum ShardArg {
    /// `(I, N)`.
    Pair((usize, usize)),
    /// `"I/N"`.
    Text(String),
}

impl ShardArg {
    /// The shard (None: the whole library).
    pub fn shard(arg: Option<Arg<ShardArg>>) -> PyResult<Shard> {
        let text = match arg {
            None => return Ok(Shard::ALL),
            Some(Arg(ShardArg::Pair((i, n)))) => format!("{i}/{n}"),
            Some(Arg(ShardArg::Text(text))) => text,
        };
        Shard::parse(&text).map_err(|e| errors::input(format!("shard {e}")))
    }
}

/// The arm named by `side` or by `chain` in `clip` read from `path`.
pub fn arm_joints(
    clip: &kinergy_motion::Clip,
    path: &Path,
    side: Side,
    chain: Option<Vec<String>>,
) -> PyResult<kinergy_motion::ArmJoints> {
    ArmChoice {
        side,
        joints: chain,
    }
    .find(clip, path)
    .map_err(errors::raise)
}

/// Where `fit` and `compare` take their reaches from: the captures, the segments file, the
/// arm, the frames and the reading.
pub struct ReachSource<'a> {
    /// The captures (none only with `segments`).
    pub clips: Option<Arg<ClipsArg>>,
    /// A segments file.
    pub segments: Option<PathBuf>,
    /// `right`, `left` or `auto`.
    pub arm: &'a str,
    /// The arm's joints by name.
    pub chain: Option<Vec<String>>,
    /// The segments taken.
    pub select: Option<Arg<SelectArg>>,
    /// One window (start, end) for every clip.
    pub frames: Option<(usize, usize)>,
    /// Keep the shoulder where it is on the reach's first frame.
    pub fixed_base: bool,
    /// The reading.
    pub reading: Reading<'a>,
}

impl ReachSource<'_> {
    /// The library's request for these arguments (checked as the CLI checks its flags).
    pub fn query(&mut self, controller: ControllerKind) -> PyResult<ReachQuery> {
        let frames = match self.frames {
            Some(w) => ReachFrames::Window(window(w)?),
            None => ReachFrames::Segments(match self.select.take() {
                Some(Arg(s)) => s.selection()?,
                None => Selection::default(),
            }),
        };
        let arm = match self.arm {
            "auto" => ArmRequest::Auto,
            arm => ArmRequest::Arm(ArmChoice {
                side: parse::<Side>("arm", arm)?,
                joints: self.chain.clone(),
            }),
        };
        let query = ReachQuery {
            frames,
            arm,
            base: if self.fixed_base {
                BaseMode::Fixed
            } else {
                BaseMode::Replay
            },
            controller,
            read: self.reading.options()?,
        };
        if self.segments.is_none() {
            query.validate().map_err(errors::raise)?;
        }
        Ok(query)
    }

    /// The captures as paths (files or folders): a library's results are named by their
    /// captures' paths, so not Clips.
    pub fn paths(&mut self) -> PyResult<Vec<PathBuf>> {
        let clips = self
            .clips
            .take()
            .map(|c| c.0.into_vec())
            .unwrap_or_default();
        clips
            .into_iter()
            .map(|c| match c {
                ClipArg::Path(p) => Ok(p),
                ClipArg::Clip(_) => Err(errors::input(
                    "clips: a library takes paths (files or folders), not Clips",
                )),
            })
            .collect()
    }

    /// The reaches, read and cut as the CLI reads and cuts them, under `controller`:
    /// [`ReachQuery::find`] of the captures given (paths, folders or Clips), or
    /// [`ReachQuery::find_rows`] of a segments file's rows; `NothingToFitError` when every
    /// take was skipped.
    pub fn load(
        mut self,
        py: Python<'_>,
        controller: ControllerKind,
    ) -> PyResult<Vec<CapturedReach>> {
        let query = self.query(controller)?;
        let clips = self
            .clips
            .take()
            .map(|c| c.0.into_vec())
            .unwrap_or_default();
        if clips.is_empty() && self.segments.is_none() {
            return Err(errors::input(
                "name the captures (paths, folders or Clips), or a segments file with segments=",
            ));
        }
        let found = match self.segments {
            Some(file) => {
                let file = SegmentsFile::read(&file).map_err(|e| errors::input(e.to_string()))?;
                let given: Vec<PathBuf> = clips
                    .into_iter()
                    .filter_map(|c| match c {
                        ClipArg::Path(p) => Some(p),
                        ClipArg::Clip(_) => None,
                    })
                    .collect();
                let wanted = if given.is_empty() {
                    segment_clips(&file)
                } else {
                    capture_files(py, &given)?
                };
                py.detach(|| query.find_rows(&file, &wanted))
            }
            None => {
                let mut takes = Vec::new();
                for c in clips {
                    takes.extend(c.takes(py)?);
                }
                py.detach(|| query.find(takes))
            }
        };
        Ok(found
            .and_then(Found::require_some)
            .map_err(errors::raise)?
            .into_reaches())
    }
}

/// The capture files `paths` name (folders walked, each folder and file once however many
/// links lead to it); the links not followed are said in one `UserWarning`.
pub fn capture_files(py: Python<'_>, paths: &[PathBuf]) -> PyResult<Vec<PathBuf>> {
    let walk = walk_captures(paths).map_err(errors::raise)?;
    if !walk.repeats.is_empty() {
        let message = format!(
            "{} link(s) to folders or files already taken, not followed: {}",
            walk.repeats.len(),
            kinergy_io::list_some(&walk.repeats, 5)
        );
        py.import("warnings")?.call_method1("warn", (message,))?;
    }
    Ok(walk.files)
}

/// The process that loaded the module. A process forked from it (multiprocessing's default
/// start method on Linux, after a fit here) inherits rayon's global pool without its threads:
/// a parallel loop on it would wait forever. Such a process runs on pools of its own.
pub static LOADED_BY: OnceLock<u32> = OnceLock::new();

/// A rayon pool of `threads` workers, or None for the global pool (all cores) — in a forked
/// process ([`LOADED_BY`]) always a pool of its own.
pub fn thread_pool(threads: Option<usize>) -> PyResult<Option<rayon::ThreadPool>> {
    let forked = LOADED_BY
        .get()
        .is_some_and(|pid| *pid != std::process::id());
    let n = match threads {
        None if !forked => return Ok(None),
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
        Some(n) => {
            errors::check_range("threads", n, limits::THREADS)?;
            n
        }
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map(Some)
        .map_err(|e| errors::KinergyError::new_err(format!("threads={n}: {e}")))
}

/// `work` on `pool` (or the global pool).
pub fn on_pool<R: Send>(pool: &Option<rayon::ThreadPool>, work: impl FnOnce() -> R + Send) -> R {
    match pool {
        Some(pool) => pool.install(work),
        None => work(),
    }
}
