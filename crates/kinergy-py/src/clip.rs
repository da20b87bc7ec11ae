//! `kinergy.Clip`: a capture or a synthesized motion, with numpy arrays out and in.
//!
//! Arrays are made once per call from the clip's own values (an owned `ndarray` handed to
//! numpy without a further copy). World positions are Kinergy's: meters, Y up, whatever the
//! file's unit and up axis. Rotations are unit quaternions `(w, x, y, z)`, each joint's
//! rotation relative to its parent (the root's relative to the Y-up world).

use std::path::PathBuf;

use kinergy_motion::clip::RotationArrays;
use kinergy_train::limits;
use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray2, PyArray3, PyReadonlyArray2, PyReadonlyArray3};
use pyo3::prelude::*;

use crate::convert::{Reading, export_options};
use crate::errors;

/// A motion: a skeleton and one pose per frame (`kinergy.read_bvh`, `Clip.from_arrays`,
/// `kinergy.synthesize`, `kinergy.reach`).
#[pyclass(module = "kinergy", frozen, from_py_object)]
#[derive(Clone)]
pub struct Clip {
    /// The motion.
    pub inner: kinergy_motion::Clip,
    /// The file it was read from, if any (named in errors and by `fit`).
    pub path: Option<PathBuf>,
    /// How a made motion ended, as the CLI's `--json` report says it (JSON text), if any.
    pub report: Option<String>,
}

/// Reads a BVH file into a Clip, as every `kinergy` command reads it.
///
/// unit: the file's length unit — "m", "cm", "mm", "in", "cmu" or "auto" (guessed from the
/// body's size). up: "y", "z", "x", "-y", "-z", "-x" or "auto". positions: how position
/// channels combine with OFFSETs — "auto", "add" or "replace". max_input_mb: a larger file
/// is refused while reading. Raises BvhError (with path, line and column) for a file that
/// cannot be read.
#[pyfunction]
#[pyo3(signature = (path, *, unit = "auto", up = "auto", positions = "auto", max_input_mb = limits::DEFAULT_INPUT_MB))]
pub fn read_bvh(
    py: Python<'_>,
    path: PathBuf,
    unit: &str,
    up: &str,
    positions: &str,
    max_input_mb: u64,
) -> PyResult<Clip> {
    let options = Reading {
        unit,
        up,
        positions,
    }
    .options_up_to(max_input_mb)?;
    let read = py.detach(|| kinergy_motion::read_clip(&path, &options));
    let (inner, _) = read.map_err(errors::raise)?;
    Ok(Clip {
        inner,
        path: Some(path),
        report: None,
    })
}

impl Clip {
    /// A clip made here (no file).
    pub fn made(inner: kinergy_motion::Clip) -> Clip {
        Clip {
            inner,
            path: None,
            report: None,
        }
    }

    /// The same clip with the report of how it was made (`report` serialized).
    pub fn with_report<T: serde::Serialize>(mut self, report: &T) -> Clip {
        self.report = kinergy_io::to_pretty_json(report).ok();
        self
    }
}

#[pymethods]
impl Clip {
    /// The joints' names (End Sites are named "<parent>_End").
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.inner
            .skeleton()
            .joints()
            .iter()
            .map(|j| j.name.clone())
            .collect()
    }

    /// Each joint's parent index, -1 for the root.
    #[getter]
    fn parents(&self) -> Vec<i64> {
        self.inner
            .skeleton()
            .joints()
            .iter()
            .map(|j| j.parent.map_or(-1, |p| p as i64))
            .collect()
    }

    /// True for the joints that are BVH End Sites.
    #[getter]
    fn end_sites(&self) -> Vec<bool> {
        self.inner
            .skeleton()
            .joints()
            .iter()
            .map(|j| j.end_site)
            .collect()
    }

    /// The names of the pose values (`values`' columns): "<joint>.<channel>".
    #[getter]
    fn dof_names(&self) -> Vec<String> {
        let skeleton = self.inner.skeleton();
        (0..skeleton.dof_count())
            .map(|d| skeleton.dof_name(d).unwrap_or_default())
            .collect()
    }

    /// Seconds between frames.
    #[getter]
    fn frame_time(&self) -> f64 {
        self.inner.frame_time()
    }

    /// Frames per second.
    #[getter]
    fn frame_rate(&self) -> f64 {
        self.inner.frame_rate()
    }

    /// The number of frames.
    #[getter]
    fn frame_count(&self) -> usize {
        self.inner.frame_count()
    }

    /// How a synthesized or full-body motion ended (a dict, what the CLI's `--json` reports:
    /// the stop reason, frames, the final hand error, a hand-over to plain IK, …), or None
    /// for a clip read from a file or made from arrays.
    #[getter]
    fn report<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        match &self.report {
            None => Ok(None),
            Some(text) => py
                .import("json")?
                .call_method1("loads", (text.as_str(),))
                .map(Some),
        }
    }

    /// The file the clip was read from, or None.
    #[getter]
    fn path(&self) -> Option<PathBuf> {
        self.path.clone()
    }

    fn __len__(&self) -> usize {
        self.inner.frame_count()
    }

    fn __repr__(&self) -> String {
        format!(
            "Clip({}{} joints, {} frames at {:.4} s)",
            self.path
                .as_ref()
                .map_or_else(String::new, |p| format!("{:?}, ", p.display().to_string())),
            self.inner.skeleton().joint_count(),
            self.inner.frame_count(),
            self.inner.frame_time()
        )
    }

    /// World joint positions, float64 (frames, joints, 3), meters, Y up.
    #[getter]
    fn positions<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let joints = self.inner.skeleton().joint_count();
        let world = py
            .detach(|| self.inner.world_positions())
            .map_err(errors::raise)?;
        let flat = world.iter().flat_map(|p| [p.x, p.y, p.z]).collect();
        array3(py, (self.inner.frame_count(), joints, 3), flat)
    }

    /// Local joint rotations as unit quaternions (w, x, y, z), float64 (frames, joints, 4):
    /// each relative to its parent's frame, the root's relative to the Y-up world.
    #[getter]
    fn rotations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray3<f64>>> {
        let joints = self.inner.skeleton().joint_count();
        let flat = self.inner.to_rotations().rotations.concat();
        array3(py, (self.inner.frame_count(), joints, 4), flat)
    }

    /// The root joint's world position, float64 (frames, 3), meters, Y up.
    #[getter]
    fn root_translation<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let flat = self.inner.to_rotations().root_translation.concat();
        array2(py, (self.inner.frame_count(), 3), flat)
    }

    /// Each joint's offset from its parent in the parent's frame, float64 (joints, 3),
    /// meters (the root's turned into the Y-up world): with `parents` and `rotations`, what
    /// `Clip.from_arrays` takes.
    #[getter]
    fn offsets<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let flat = self.inner.to_rotations().offsets.concat();
        array2(py, (self.inner.skeleton().joint_count(), 3), flat)
    }

    /// The pose values as read (radians, meters in the file's frame), float64 (frames,
    /// dofs); `dof_names` names the columns.
    #[getter]
    fn values<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray2<f64>>> {
        let dofs = self.inner.skeleton().dof_count();
        array2(
            py,
            (self.inner.frame_count(), dofs),
            self.inner.values().to_vec(),
        )
    }

    /// The same skeleton with other pose values (frames, dofs) — e.g. `clip.values` edited
    /// in numpy — and optionally another frame time: written back, every channel keeps its
    /// joint and order, so an unedited value writes the bytes it was read as.
    #[pyo3(signature = (values, *, frame_time = None))]
    fn with_values(
        &self,
        values: PyReadonlyArray2<'_, f64>,
        frame_time: Option<f64>,
    ) -> PyResult<Clip> {
        let values = values.as_array();
        let dofs = self.inner.skeleton().dof_count();
        if values.ncols() != dofs {
            return Err(errors::input(format!(
                "with_values: {} columns, the skeleton has {dofs} DoFs (see dof_names)",
                values.ncols()
            )));
        }
        if values.nrows() == 0 {
            return Err(errors::input(
                "with_values: no frames (a clip has at least one)",
            ));
        }
        let flat: Vec<f64> = values.iter().copied().collect();
        let inner = kinergy_motion::Clip::new(
            self.inner.skeleton().clone(),
            frame_time.unwrap_or(self.inner.frame_time()),
            flat,
        )
        .map_err(errors::raise)?;
        Ok(Clip {
            inner,
            path: self.path.clone(),
            report: None,
        })
    }

    /// Pickling (multiprocessing, joblib): the clip's exact state (skeleton, frame time,
    /// values bit for bit, as JSON), its path and report.
    fn __reduce__<'py>(&self, py: Python<'py>) -> PyResult<(Bound<'py, PyAny>, (ClipState,))> {
        let state = serde_json::to_string(&self.inner.state())
            .map_err(|e| errors::KinergyError::new_err(format!("pickling a clip: {e}")))?;
        let rebuild = py.import("kinergy._kinergy")?.getattr("_clip_from_state")?;
        Ok((rebuild, ((state, self.path.clone(), self.report.clone()),)))
    }

    /// Frames `start..end` (end excluded) as a new clip.
    fn slice(&self, start: usize, end: usize) -> PyResult<Clip> {
        if start >= end || end > self.inner.frame_count() {
            return Err(errors::input(format!(
                "slice({start}, {end}): the clip has {} frames; expected start < end ≤ {}",
                self.inner.frame_count(),
                self.inner.frame_count()
            )));
        }
        let inner = self.inner.slice(start..end).map_err(errors::raise)?;
        Ok(Clip {
            inner,
            path: self.path.clone(),
            report: None,
        })
    }

    /// Writes the clip as BVH, atomically (a temporary file renamed into place): the same
    /// bytes as `kinergy convert` of the same clip with the same unit and up.
    ///
    /// unit: "cm" (default), "m", "mm", "in" or "cmu". up: "as-read" (the file's own axis)
    /// or "y" (the turn baked into the root).
    #[pyo3(signature = (path, *, unit = "cm", up = "as-read"))]
    fn write_bvh(&self, py: Python<'_>, path: PathBuf, unit: &str, up: &str) -> PyResult<()> {
        let options = export_options(unit, up)?;
        py.detach(|| kinergy_motion::write_clip(&path, &self.inner, &options))
            .map_err(errors::raise)
    }

    /// The BVH text `write_bvh` writes.
    #[pyo3(signature = (*, unit = "cm", up = "as-read"))]
    fn to_bvh(&self, unit: &str, up: &str) -> PyResult<String> {
        let options = export_options(unit, up)?;
        kinergy_bvh::to_string(&kinergy_motion::clip_to_bvh(&self.inner, &options))
            .map_err(|e| errors::BvhError::new_err(e.to_string()))
    }

    /// A clip from arrays: joint names, parent indices (-1 for the root, parents before
    /// children), offsets (joints, 3) meters, local rotations (frames, joints, 4) as unit
    /// quaternions (w, x, y, z), the root's world position (frames, 3), the frame time, and
    /// optionally which joints are End Sites (no rotation). Y up. Every joint but End Sites
    /// gets three rotation channels (Z, X, Y), the root also three position channels; the
    /// Euler angles are kept continuous from frame to frame.
    #[staticmethod]
    #[pyo3(signature = (joint_names, parents, offsets, rotations, root_translation, frame_time, *, end_sites = None))]
    #[allow(clippy::too_many_arguments)]
    fn from_arrays(
        joint_names: Vec<String>,
        parents: Vec<i64>,
        offsets: PyReadonlyArray2<'_, f64>,
        rotations: PyReadonlyArray3<'_, f64>,
        root_translation: PyReadonlyArray2<'_, f64>,
        frame_time: f64,
        end_sites: Option<Vec<bool>>,
    ) -> PyResult<Clip> {
        let n = joint_names.len();
        let shape = |what: &str, found: &[usize], expected: String| {
            errors::input(format!(
                "from_arrays: {what} has shape {found:?}, expected {expected}"
            ))
        };
        let rows3 = |a: numpy::ndarray::ArrayView2<'_, f64>| -> Vec<[f64; 3]> {
            a.rows().into_iter().map(|r| [r[0], r[1], r[2]]).collect()
        };
        let (offsets, rotations, root) = (
            offsets.as_array(),
            rotations.as_array(),
            root_translation.as_array(),
        );
        if offsets.shape() != [n, 3] {
            return Err(shape("offsets", offsets.shape(), format!("({n}, 3)")));
        }
        let frames = rotations.shape()[0];
        if rotations.shape() != [frames, n, 4] {
            let expected = format!("(frames, {n}, 4)");
            return Err(shape("rotations", rotations.shape(), expected));
        }
        if root.shape() != [frames, 3] {
            let expected = format!("({frames}, 3) (one row per frame of rotations)");
            return Err(shape("root_translation", root.shape(), expected));
        }
        let quaternions: Vec<[f64; 4]> = rotations
            .rows()
            .into_iter()
            .map(|q| [q[0], q[1], q[2], q[3]])
            .collect();
        let arrays = RotationArrays {
            joint_names: &joint_names,
            parents: &parents,
            offsets: &rows3(offsets),
            rotations: &quaternions,
            root_translation: &rows3(root),
            frame_time,
            end_sites: end_sites.as_deref(),
        };
        let inner = kinergy_motion::Clip::from_rotations(arrays)
            .map_err(|e| errors::input(format!("from_arrays: {e}")))?;
        Ok(Clip::made(inner))
    }
}

/// A clip whose joints are at `positions` (float (frames, joints, 3), meters, Y up: SMPL
/// joints, a pose estimator's 3-D keypoints, C3D joint centres), the hierarchy given by
/// `joint_names` and `parents` (-1 for the root, parents before children), `frame_time`
/// seconds apart (`kinergy_motion::Clip::from_positions`): the first frame is the rest pose,
/// each bone at its median length, each joint's rotation from where its children are. Its
/// `report`: the largest distance of any joint from its position (`max_error_m`) and each
/// joint's (`joint_max_error_m`), the joints whose twist the positions do not determine
/// (`undetermined`, kept from frame to frame), the bones whose length varies (`stretched`),
/// and the arms whose rotations leave Kinergy's human arm limits with the DoFs past them
/// (`arms_beyond_limits`: [side, [dof, ...]] pairs, as `kinergy from-positions` reports).
/// `stretch`: "hold" such a bone at its median length, or "keep" it, its child joint given
/// position channels carrying each frame's length (as `kinergy from-positions --stretch`).
/// The clip's joints are in BVH's depth-first order.
#[pyfunction]
#[pyo3(signature = (positions, joint_names, parents, *, frame_time = 1.0 / 30.0, stretch = "hold"))]
pub fn from_positions(
    py: Python<'_>,
    positions: PyReadonlyArray3<'_, f64>,
    joint_names: Vec<String>,
    parents: Vec<i64>,
    frame_time: f64,
    stretch: &str,
) -> PyResult<Clip> {
    let stretch: kinergy_motion::Stretch = stretch
        .parse()
        .map_err(|e| errors::input(format!("from_positions: stretch {e}")))?;
    let array = positions.as_array();
    let n = joint_names.len();
    if array.shape().len() != 3 || array.shape()[1] != n || array.shape()[2] != 3 {
        return Err(errors::input(format!(
            "from_positions: positions has shape {:?}, expected (frames, {n}, 3)",
            array.shape()
        )));
    }
    if !(frame_time.is_finite() && frame_time > 0.0) {
        return Err(errors::input(format!(
            "from_positions: frame_time {frame_time} is not a positive number of seconds"
        )));
    }
    let flat: Vec<[f64; 3]> = array
        .outer_iter()
        .flat_map(|frame| {
            frame
                .outer_iter()
                .map(|p| [p[0], p[1], p[2]])
                .collect::<Vec<_>>()
        })
        .collect();
    let made = py
        .detach(|| {
            kinergy_motion::Clip::from_positions_with(
                kinergy_motion::PositionArrays {
                    joint_names: &joint_names,
                    parents: &parents,
                    positions: &flat,
                    frame_time,
                },
                stretch,
            )
        })
        .map_err(|e| errors::input(format!("from_positions: {e}")))?;
    let arms_beyond_limits = kinergy_solver::arms_beyond_limits(&made.clip)
        .map_err(|e| errors::input(format!("from_positions: {e}")))?;
    let joint_max: serde_json::Map<String, serde_json::Value> = made
        .joint_max_error_m()
        .into_iter()
        .map(|(name, worst)| (name, serde_json::json!(worst)))
        .collect();
    let report = serde_json::json!({
        "max_error_m": made.max_error_m(),
        "joint_max_error_m": joint_max,
        "undetermined": made.undetermined,
        "stretched": made.stretched,
        "arms_beyond_limits": arms_beyond_limits,
    });
    Ok(Clip {
        inner: made.clip,
        path: None,
        report: Some(report.to_string()),
    })
}

/// A clip as pickled ([`Clip::__reduce__`]): its state as JSON, path, report.
type ClipState = (String, Option<PathBuf>, Option<String>);

/// Unpickles a clip ([`Clip::__reduce__`]'s state); a state that is not one is an InputError.
#[pyfunction]
pub fn _clip_from_state(state: ClipState) -> PyResult<Clip> {
    let (json, path, report) = state;
    let bad = |why: String| errors::input(format!("not a pickled kinergy.Clip: {why}"));
    let state = serde_json::from_str(&json).map_err(|e| bad(e.to_string()))?;
    let inner = kinergy_motion::Clip::from_state(state).map_err(|e| bad(e.to_string()))?;
    Ok(Clip {
        inner,
        path,
        report,
    })
}

/// `values` as a numpy array of `shape`, handed over without a copy.
fn array3(
    py: Python<'_>,
    shape: (usize, usize, usize),
    values: Vec<f64>,
) -> PyResult<Bound<'_, PyArray3<f64>>> {
    let array = Array3::from_shape_vec(shape, values)
        .map_err(|e| errors::KinergyError::new_err(e.to_string()))?;
    Ok(array.into_pyarray(py))
}

/// `values` as a numpy array of `shape`, handed over without a copy.
fn array2(
    py: Python<'_>,
    shape: (usize, usize),
    values: Vec<f64>,
) -> PyResult<Bound<'_, PyArray2<f64>>> {
    let array = Array2::from_shape_vec(shape, values)
        .map_err(|e| errors::KinergyError::new_err(e.to_string()))?;
    Ok(array.into_pyarray(py))
}

/// `UnreachableError(message)` carrying the motion made as `clip`.
pub fn unreachable(py: Python<'_>, message: String, clip: Clip) -> PyErr {
    let err = errors::UnreachableError::new_err(message);
    if let Ok(clip) = Bound::new(py, clip) {
        let _ = err.value(py).setattr("clip", clip);
    }
    err
}
