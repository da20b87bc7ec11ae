"""Type stubs of the extension module `kinergy._kinergy` (crates/kinergy-py)."""

from __future__ import annotations

import os
import pathlib
from typing import Any, Callable, Literal, Sequence, Union, overload

import numpy as np
import numpy.typing as npt

__version__: str
RESULTS_COLUMNS: list[str]
"""The columns of `kinergy compare`'s results.csv, in order: what `compare` rows hold."""

PathLike = Union[str, "os.PathLike[str]"]
ClipLike = Union["Clip", PathLike]
Arm = Literal["right", "left"]
Model = Literal["sa", "sb", "sc", "sd", "se"]
Optimizer = Literal["jt", "njt", "svd", "dls"]

class KinergyError(Exception):
    """Every error Kinergy raises (the CLI's messages)."""

class BvhError(KinergyError):
    """A BVH file that cannot be read or written; `path`, `line` and `column` say where."""

    path: str | None
    line: int | None
    column: int | None

class ParamsError(KinergyError):
    """A parameters or field file that cannot be read, or does not fit the arm it drives."""

class UnreachableError(KinergyError):
    """A target the motion did not reach; `clip` holds the motion made."""

    clip: Clip

class InputError(KinergyError):
    """An argument Kinergy refuses (out of range, unknown name)."""

class NothingToFitError(KinergyError):
    """The captures hold nothing to fit: no take has a reach on the arm asked for."""

class Clip:
    """A motion: a skeleton and one pose per frame. World positions are meters, Y up."""

    @property
    def joint_names(self) -> list[str]:
        """The joints' names (End Sites are named "<parent>_End")."""
    @property
    def parents(self) -> list[int]:
        """Each joint's parent index, -1 for the root."""
    @property
    def end_sites(self) -> list[bool]:
        """True for the joints that are BVH End Sites."""
    @property
    def dof_names(self) -> list[str]:
        """The names of the pose values (`values`' columns): "<joint>.<channel>"."""
    @property
    def frame_time(self) -> float:
        """Seconds between frames."""
    @property
    def frame_rate(self) -> float:
        """Frames per second."""
    @property
    def frame_count(self) -> int:
        """The number of frames."""
    @property
    def path(self) -> pathlib.Path | None:
        """The file the clip was read from (a pathlib.Path), or None."""
    @property
    def report(self) -> dict[str, Any] | None:
        """How a synthesized or full-body motion ended (the CLI's `--json` report), or None."""
    @property
    def positions(self) -> npt.NDArray[np.float64]:
        """World joint positions, (frames, joints, 3), meters, Y up."""
    @property
    def rotations(self) -> npt.NDArray[np.float64]:
        """Local joint rotations, unit quaternions (w, x, y, z), (frames, joints, 4)."""
    @property
    def root_translation(self) -> npt.NDArray[np.float64]:
        """The root joint's world position, (frames, 3), meters, Y up."""
    @property
    def offsets(self) -> npt.NDArray[np.float64]:
        """Each joint's offset from its parent in the parent's frame, (joints, 3), meters."""
    @property
    def values(self) -> npt.NDArray[np.float64]:
        """The pose values as read (radians, meters in the file's frame), (frames, dofs)."""
    def __len__(self) -> int: ...
    def with_values(self, values: npt.ArrayLike, *, frame_time: float | None = None) -> Clip:
        """The same skeleton with other pose values (frames, dofs), e.g. `values` edited."""
    def slice(self, start: int, end: int) -> Clip:
        """Frames `start..end` (end excluded) as a new clip."""
    def write_bvh(
        self, path: PathLike, *, unit: str = "cm", up: Literal["as-read", "y"] = "as-read"
    ) -> None:
        """Writes the clip as BVH, atomically: the bytes `kinergy convert` writes."""
    def to_bvh(self, *, unit: str = "cm", up: Literal["as-read", "y"] = "as-read") -> str:
        """The BVH text `write_bvh` writes."""
    @staticmethod
    def from_arrays(
        joint_names: Sequence[str],
        parents: Sequence[int],
        offsets: npt.ArrayLike,
        rotations: npt.ArrayLike,
        root_translation: npt.ArrayLike,
        frame_time: float,
        *,
        end_sites: Sequence[bool] | None = None,
    ) -> Clip:
        """A clip from arrays (offsets (joints, 3) m, rotations (frames, joints, 4) w x y z,
        root_translation (frames, 3) m), Y up."""

class Params:
    """A person's synergy parameters: one vector (a parameters file) or a field file."""

    @staticmethod
    def load(path: PathLike) -> Params:
        """Reads a parameters file or a field file (ParamsError naming the field)."""
    @staticmethod
    def from_json(text: str) -> Params:
        """Parses the text of a parameters or field file."""
    def save(self, path: PathLike) -> None:
        """Writes the file atomically: the bytes the CLI writes."""
    def to_json(self) -> str:
        """The file's JSON text."""
    @property
    def is_field(self) -> bool:
        """True for a field file."""
    @property
    def model(self) -> Model:
        """The synergy model."""
    @property
    def optimizer(self) -> Optimizer:
        """The IK optimizer the motions are synthesized with."""
    @property
    def vector(self) -> dict[str, float] | None:
        """The parameter vector by name (None for a field)."""
    @property
    def record(self) -> dict[str, Any] | None:
        """How the parameters were fitted (the file's `fit` record)."""
    @property
    def distances(self) -> dict[str, float]:
        """Each nested model's fitted distance, meters, by model name."""

def read_bvh(
    path: PathLike,
    *,
    unit: str = "auto",
    up: str = "auto",
    positions: Literal["auto", "add", "replace"] = "auto",
    max_input_mb: int = 256,
) -> Clip:
    """Reads a BVH file as every `kinergy` command reads it."""

def segment(
    clip: ClipLike,
    *,
    arm: Literal["right", "left", "auto"] = "right",
    chain: Sequence[str] | None = None,
    select: str | int | None = None,
    world: bool = False,
    min_peak_speed: float | None = None,
    unit: str = "auto",
    up: str = "auto",
    positions: str = "auto",
) -> list[dict[str, Any]]:
    """The labelled segments of a clip's hand speed (`kinergy segment --json`'s rows)."""

@overload
def fit(
    clips: ClipLike | Sequence[ClipLike] | None = None,
    *,
    model: Model = "sc",
    optimizer: Optimizer = "svd",
    per: Literal["person"] = "person",
    nested: bool = True,
    field: bool = False,
    arm: Literal["right", "left", "auto"] = "right",
    chain: Sequence[str] | None = None,
    select: str | int | None = None,
    frames: tuple[int, int] | None = None,
    segments: PathLike | None = None,
    fixed_base: bool = False,
    controller: Literal["smooth", "paper"] = "smooth",
    seed: int = 1,
    budget: int | None = None,
    population: int | None = None,
    temperature: float | None = None,
    stable_change: float | None = None,
    stable_window: int | None = None,
    objective: Literal["positions", "positions+speed"] = "positions",
    speed_weight: float | None = None,
    refine: int | None = None,
    threads: int | None = None,
    progress: Callable[[dict[str, Any]], object] | None = None,
    out_dir: None = None,
    shard: None = None,
    resume: Literal[False] = False,
    person: None = None,
    warm_start: Literal[False] = False,
    unit: str = "auto",
    up: str = "auto",
    positions: str = "auto",
) -> Params: ...
@overload
def fit(
    clips: ClipLike | Sequence[ClipLike] | None = None,
    *,
    model: Model = "sc",
    optimizer: Optimizer = "svd",
    per: Literal["clip"],
    nested: bool = True,
    field: bool = False,
    arm: Literal["right", "left", "auto"] = "right",
    chain: Sequence[str] | None = None,
    select: str | int | None = None,
    frames: tuple[int, int] | None = None,
    segments: PathLike | None = None,
    fixed_base: bool = False,
    controller: Literal["smooth", "paper"] = "smooth",
    seed: int = 1,
    budget: int | None = None,
    population: int | None = None,
    temperature: float | None = None,
    stable_change: float | None = None,
    stable_window: int | None = None,
    objective: Literal["positions", "positions+speed"] = "positions",
    speed_weight: float | None = None,
    refine: int | None = None,
    threads: int | None = None,
    progress: Callable[[dict[str, Any]], object] | None = None,
    out_dir: None = None,
    shard: None = None,
    resume: Literal[False] = False,
    person: None = None,
    warm_start: Literal[False] = False,
    unit: str = "auto",
    up: str = "auto",
    positions: str = "auto",
) -> list[Params]: ...
@overload
def fit(
    clips: PathLike | Sequence[PathLike] | None = None,
    *,
    model: Model = "sc",
    optimizer: Optimizer = "svd",
    per: Literal["clip"],
    nested: bool = True,
    field: Literal[False] = False,
    arm: Literal["right", "left", "auto"] = "right",
    chain: Sequence[str] | None = None,
    select: str | int | None = None,
    frames: tuple[int, int] | None = None,
    segments: PathLike | None = None,
    fixed_base: bool = False,
    controller: Literal["smooth", "paper"] = "smooth",
    seed: int = 1,
    budget: int | None = None,
    population: int | None = None,
    temperature: float | None = None,
    stable_change: float | None = None,
    stable_window: int | None = None,
    objective: Literal["positions", "positions+speed"] = "positions",
    speed_weight: float | None = None,
    refine: int | None = None,
    threads: int | None = None,
    progress: None = None,
    out_dir: PathLike,
    shard: str | tuple[int, int] | None = None,
    resume: bool = False,
    person: str | None = None,
    warm_start: bool = False,
    unit: str = "auto",
    up: str = "auto",
    positions: str = "auto",
) -> dict[str, Any]:
    """A library into `out_dir` (`kinergy fit --per clip --out-dir`): this shard of the takes,
    one result file per reach, the shard's record; with one shard, collected (`rows`).
    `person`: the library's person rule, as `--person` spells it (default "auto");
    `warm_start`: each person's, motion's and arm's reaches fitted from the first one's fit
    (`--warm-start`)."""
    ...
def collect(dir: PathLike, *, person: str | None = None) -> list[dict[str, Any]]:
    """Tables a library folder as `kinergy collect` does; returns library.csv's rows.
    `person`: name the persons by this rule instead (`kinergy collect --person`)."""
    ...
def synthesize(
    clip: ClipLike,
    params: Params | PathLike | None = None,
    *,
    frames: str | tuple[int, int] | None = None,
    select: str | int | None = None,
    target: Sequence[float] | None = None,
    model: Model = "sa",
    optimizer: Optimizer = "svd",
    arm: Arm | None = None,
    chain: Sequence[str] | None = None,
    fixed_base: bool = False,
    controller: Literal["smooth", "paper"] | None = None,
    stop_at_reach: bool = False,
    tolerance: float = 0.005,
    max_seconds: float = 10.0,
    check: bool = True,
    unit: str = "auto",
    up: str = "auto",
    positions: str = "auto",
) -> Clip:
    """A synergy reach on a capture's skeleton, as `kinergy synthesize` makes it."""

def reach(
    target: Sequence[float],
    *,
    params: Params | PathLike | None = None,
    height: float | None = None,
    person: ClipLike | None = None,
    flexibility: float = 1.0,
    arm: Arm | None = None,
    profile: Literal["ease-out", "minimum-jerk"] = "ease-out",
    seed: int = 0,
    timeout: float | None = None,
    check: bool = True,
    v_s: float | None = None,
    r_s: float | None = None,
    r_st: float | None = None,
    r_tw: float | None = None,
    comfortable_angle_deg: float | None = None,
    start_swing_distance_m: float | None = None,
    head_speed_deg_s: float | None = None,
    p_max: float | None = None,
    p_min: float | None = None,
) -> Clip:
    """One full-body reach of the 43-DoF character, as `kinergy reach` makes it."""

def from_positions(
    positions: npt.ArrayLike,
    joint_names: Sequence[str],
    parents: Sequence[int],
    *,
    frame_time: float = 1.0 / 30.0,
    stretch: Literal["hold", "keep"] = "hold",
) -> Clip:
    """A clip whose joints are at `positions` (frames, joints, 3), the hierarchy by `parents`;
    bones that stretch held at their median (`stretch="hold"`) or kept in position channels."""

def retarget(
    clip: Clip,
    template: Clip,
    *,
    map: str = "auto",
    to_map: str = "auto",
    arms: Literal["template", "source"] = "template",
) -> tuple[Clip, dict[str, Any]]:
    """`clip`'s motion on `template`'s skeleton, as `kinergy retarget` makes it (roles by
    `map` / `to_map`: "auto", "cmu", "bandai", "mixamo", "cc" or a .json map; `arms`: the
    template's or the source performer's, scaled with the body); the report."""

def view(
    clips: ClipLike | Sequence[ClipLike],
    output: PathLike,
    *,
    target: Sequence[float] | None = None,
    scene: PathLike | None = None,
    hand: Literal["right", "left", "auto", "none"] = "auto",
    title: str | None = None,
    labels: Sequence[str] | None = None,
    unit: str = "auto",
    up: str = "auto",
    positions: str = "auto",
) -> int:
    """Writes `kinergy view`'s page of the clips (one self-contained HTML file); its size."""

def hand_speed(
    clip: ClipLike,
    *,
    arm: Arm = "right",
    chain: Sequence[str] | None = None,
    relative: bool = False,
    smoothing: float = 0.0,
    unit: str = "auto",
    up: str = "auto",
    positions: str = "auto",
) -> npt.NDArray[np.float64]:
    """The hand's speed, m/s, per frame, as `kinergy plot speed --csv` computes it."""

def style(
    clips: Sequence[PathLike],
    params: Params | PathLike,
    *,
    arm: Arm = "right",
    chain: Sequence[str] | None = None,
    motions: bool = False,
    unit: str = "auto",
    up: str = "auto",
    positions: str = "auto",
) -> dict[str, Any]:
    """Whether a person's drive reaches in their style, as `kinergy style` measures it:
    `summary`, `rows` and with motions=True the full-body Clips."""

def plan(
    scene: PathLike,
    *,
    target: Sequence[float] | None = None,
    task: Literal["grasp", "relocate", "pull", "push"] | None = None,
    object: str | None = None,
    to: Sequence[float] | None = None,
    distance: float = 0.2,
    arm: Arm = "right",
    level: Literal["ik", "straight", "planner", "auto"] = "auto",
    seed: int = 0,
    params: Params | PathLike | None = None,
    budget_ms: int | None = None,
) -> Clip:
    """Collision-free reaching and manipulation in a scene, as `kinergy plan` makes it."""

def compare(
    clips: ClipLike | Sequence[ClipLike] | None = None,
    *,
    models: Sequence[Model] = ("sa", "sb", "sc", "sd"),
    optimizers: Sequence[Optimizer] = ("jt", "njt", "svd"),
    optimizer: Optimizer = "svd",
    baselines: bool = True,
    arm: Literal["right", "left", "auto"] = "right",
    chain: Sequence[str] | None = None,
    select: str | int | None = None,
    frames: tuple[int, int] | None = None,
    segments: PathLike | None = None,
    fixed_base: bool = False,
    seed: int = 1,
    budget: int | None = None,
    population: int | None = None,
    temperature: float | None = None,
    stable_change: float | None = None,
    stable_window: int | None = None,
    objective: Literal["positions", "positions+speed"] = "positions",
    speed_weight: float | None = None,
    threads: int | None = None,
    progress: Callable[[int, int], object] | None = None,
    unit: str = "auto",
    up: str = "auto",
    positions: str = "auto",
) -> list[dict[str, Any]]:
    """The paper's experiments, as `kinergy compare` runs them: results.csv's rows as dicts."""
