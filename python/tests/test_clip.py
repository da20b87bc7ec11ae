"""Clips: numpy arrays out and in, BVH written back exactly."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest

import kinergy
from conftest import ROOT, run, shared

R09 = "data-synthetic/p01/r09.bvh"
CMU = "tests/data/006_14.bvh"


def test_arrays_have_the_documented_shapes_and_dtypes():
    clip = kinergy.read_bvh(ROOT / R09)
    frames, joints = len(clip), len(clip.joint_names)
    assert frames == clip.frame_count > 2
    for name, shape in [
        ("positions", (frames, joints, 3)),
        ("rotations", (frames, joints, 4)),
        ("root_translation", (frames, 3)),
        ("offsets", (joints, 3)),
        ("values", (frames, len(clip.dof_names))),
    ]:
        array = getattr(clip, name)
        assert isinstance(array, np.ndarray) and array.dtype == np.float64, name
        assert array.shape == shape, name
        assert array.flags["C_CONTIGUOUS"], name
    assert clip.parents[0] == -1 and all(0 <= p < i for i, p in enumerate(clip.parents) if i)
    assert np.allclose(np.linalg.norm(clip.rotations, axis=2), 1.0, atol=1e-12)
    assert np.array_equal(clip.root_translation, clip.positions[:, 0, :])
    assert clip.frame_time == pytest.approx(1 / 60)


def test_positions_are_forward_kinematics_of_offsets_and_rotations():
    # An independent forward kinematics in numpy from the exposed quaternions and offsets
    # (the synthetic character moves its root only: every other joint is offset + rotation).
    clip = kinergy.read_bvh(ROOT / R09)
    q, offsets, parents = clip.rotations, clip.offsets, clip.parents

    def matrix(w, x, y, z):
        return np.array([
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ])

    for f in (0, len(clip) // 2, len(clip) - 1):
        rot, pos = [None] * len(parents), [None] * len(parents)
        for j, p in enumerate(parents):
            r = matrix(*q[f, j])
            if p < 0:
                rot[j], pos[j] = r, clip.root_translation[f]
            else:
                rot[j] = rot[p] @ r
                pos[j] = pos[p] + rot[p] @ offsets[j]
        assert np.allclose(np.array(pos), clip.positions[f], atol=1e-12)


def test_units_and_up_axis_read_into_meters_y_up():
    in_cm = kinergy.read_bvh(ROOT / CMU, unit="cm")
    in_m = kinergy.read_bvh(ROOT / CMU, unit="m")
    assert np.allclose(in_cm.positions * 100, in_m.positions, rtol=1e-12, atol=1e-12)
    guessed = kinergy.read_bvh(ROOT / CMU)
    height = guessed.positions[0, :, 1].max() - guessed.positions[0, :, 1].min()
    assert 1.2 < height < 2.0, "the unit guess gives a human's height"
    zup = shared("formats")
    files = sorted(zup.glob("*.bvh"))
    assert files
    for path in files:
        clip = kinergy.read_bvh(path)
        extent = clip.positions[0].max(axis=0) - clip.positions[0].min(axis=0)
        assert extent[1] == extent.max(), f"{path.name}: tallest along Y"


@pytest.mark.parametrize("unit", ["cm", "m"])
def test_write_bvh_is_the_cli_s_convert_byte_for_byte(cli, tmp_path, unit):
    for source in (R09, CMU):
        ours = tmp_path / f"py-{unit}.bvh"
        theirs = tmp_path / f"cli-{unit}.bvh"
        kinergy.read_bvh(ROOT / source).write_bvh(ours, unit=unit)
        run(cli, "convert", source, "-o", str(theirs), "--unit", unit)
        assert ours.read_bytes() == theirs.read_bytes(), source
        assert kinergy.read_bvh(ROOT / source).to_bvh(unit=unit) == theirs.read_text()


def test_a_slice_writes_what_convert_frames_writes(cli, tmp_path):
    kinergy.read_bvh(ROOT / R09).slice(7, 87).write_bvh(tmp_path / "py.bvh")
    run(cli, "convert", R09, "--frames", "7..87", "-o", str(tmp_path / "cli.bvh"))
    assert (tmp_path / "py.bvh").read_bytes() == (tmp_path / "cli.bvh").read_bytes()


@pytest.mark.parametrize("source", [R09, CMU])
def test_from_arrays_round_trips_positions_and_through_a_file(tmp_path, source):
    clip = kinergy.read_bvh(ROOT / source)
    if any(name.endswith(("position",)) for name in clip.dof_names[6:]):
        pytest.skip("non-root translations are not part of from_arrays")
    made = kinergy.Clip.from_arrays(
        clip.joint_names, clip.parents, clip.offsets, clip.rotations,
        clip.root_translation, clip.frame_time, end_sites=clip.end_sites,
    )
    assert made.joint_names == clip.joint_names
    assert np.abs(made.positions - clip.positions).max() < 1e-9
    made.write_bvh(tmp_path / "made.bvh", unit="m")
    back = kinergy.read_bvh(tmp_path / "made.bvh", unit="m")
    assert np.abs(back.positions - clip.positions).max() < 1e-9
    # Euler angles stay continuous from frame to frame (no 2π jumps) where the capture's
    # own rotations are (006_14's left thumb turns by 3 rad in one frame).
    if np.abs(np.diff(clip.values[:, 6:], axis=0)).max() < 1.0:
        assert np.abs(np.diff(back.values[:, 3:], axis=0)).max() < 1.0


def test_a_z_up_clip_round_trips_through_from_arrays():
    path = shared("formats")
    for bvh in sorted(path.glob("*.bvh")):
        clip = kinergy.read_bvh(bvh)
        if any("position" in n for n in clip.dof_names[6:]):
            continue
        made = kinergy.Clip.from_arrays(
            clip.joint_names, clip.parents, clip.offsets, clip.rotations,
            clip.root_translation, clip.frame_time, end_sites=clip.end_sites,
        )
        assert np.abs(made.positions - clip.positions).max() < 1e-9, bvh.name


def test_from_arrays_refuses_what_is_not_a_skeleton():
    names, parents = ["a", "b"], [-1, 0]
    offsets = np.zeros((2, 3))
    rotations = np.tile([1.0, 0, 0, 0], (3, 2, 1))
    root = np.zeros((3, 3))
    kinergy.Clip.from_arrays(names, parents, offsets, rotations, root, 0.01)
    bad = [
        (names, [0, 0], offsets, rotations, root, 0.01),
        (names, [-1, 1], offsets, rotations, root, 0.01),
        (names, parents, np.zeros((3, 3)), rotations, root, 0.01),
        (names, parents, offsets, rotations[:, :, :3].copy(), root, 0.01),
        (names, parents, offsets, rotations, root[:2].copy(), 0.01),
        (names, parents, offsets, rotations * 2, root, 0.01),
        (names, parents, offsets, rotations * np.nan, root, 0.01),
        (names, parents, offsets, rotations, root, 0.0),
        (names, parents, offsets, rotations, np.full((3, 3), np.inf), 0.01),
        (["a", "a"], parents, offsets, rotations, root, 0.01),
    ]
    for args in bad:
        with pytest.raises(kinergy.InputError):
            kinergy.Clip.from_arrays(*args)


def test_reading_a_clip_many_times_does_not_grow_memory():
    def rss() -> int:
        with open("/proc/self/statm") as f:
            return int(f.read().split()[1]) * 4096

    path = ROOT / CMU
    for _ in range(50):
        kinergy.read_bvh(path).positions
    before = rss()
    for _ in range(1000):
        clip = kinergy.read_bvh(path)
        clip.positions, clip.rotations
        del clip
    grown = rss() - before
    assert grown < 16 * 2**20, f"RSS grew by {grown / 2**20:.1f} MiB over 1,000 reads"


def test_values_edited_in_numpy_write_back_exactly(cli, tmp_path):
    clip = kinergy.read_bvh(ROOT / CMU)
    same = clip.with_values(clip.values)
    assert same.to_bvh() == clip.to_bvh()
    # Doubling the frame rate by interpolating in numpy, written and read back.
    v = clip.values
    mid = 0.5 * (v[:-1] + v[1:])
    dense = np.empty((2 * len(v) - 1, v.shape[1]))
    dense[0::2], dense[1::2] = v, mid
    faster = clip.with_values(dense, frame_time=clip.frame_time / 2)
    faster.write_bvh(tmp_path / "dense.bvh")
    back = kinergy.read_bvh(tmp_path / "dense.bvh", unit="cm")
    assert len(back) == 2 * len(clip) - 1
    assert np.abs(back.positions[0::2] - clip.positions).max() < 1e-9
    with pytest.raises(kinergy.InputError):
        clip.with_values(v[:, :-1].copy())
    with pytest.raises(kinergy.InputError):
        clip.with_values(v * np.nan)


def test_clips_and_params_pickle_exactly():
    import pickle

    files = [ROOT / CMU, ROOT / R09] + sorted(shared("formats").glob("*.bvh"))[:1]
    for path in files:
        clip = kinergy.read_bvh(path)
        back = pickle.loads(pickle.dumps(clip))
        assert back.path == clip.path and back.joint_names == clip.joint_names
        assert isinstance(clip.path, pathlib.Path)  # as the stub says
        assert np.array_equal(back.values, clip.values)
        assert np.array_equal(back.positions, clip.positions), path.name
        assert back.to_bvh() == clip.to_bvh(), path.name
    motion = kinergy.synthesize(ROOT / R09, frames="auto", check=False)
    assert pickle.loads(pickle.dumps(motion)).report == motion.report
    params = kinergy.Params.load(ROOT / "tests/data/params/synthetic-p01-r09-sc.json")
    assert pickle.loads(pickle.dumps(params)).to_json() == params.to_json()
    for damaged in ("not json", '{"joints": [], "world_from_file": [1, 0, 0, 0, 1, 0, 0, 0, 1], '
                    '"frame_time": 0.1, "values": [0.0]}'):
        with pytest.raises(kinergy.InputError):
            kinergy._kinergy._clip_from_state((damaged, None, None))


def test_fits_in_worker_processes_are_the_fits_here():
    # The labs' pattern: one clip per worker process (multiprocessing pickles the results).
    from concurrent.futures import ProcessPoolExecutor

    clips = [str(ROOT / f"data-synthetic/p01/r0{i}.bvh") for i in (1, 2, 3)]
    here = [kinergy.fit(c, model="sb", per="clip", budget=80)[0].to_json() for c in clips]
    with ProcessPoolExecutor(max_workers=2) as pool:
        there = [p[0].to_json() for p in pool.map(_fit_one, clips)]
    assert there == here


def _fit_one(clip):
    return kinergy.fit(clip, model="sb", per="clip", budget=80)
