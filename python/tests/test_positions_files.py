"""`kinergy from-positions` on files numpy writes: `.npy` arrays in float64 and float32, shaped
(frames, joints, 3) or (frames, joints × 3), named by a names file or in a built-in dataset's
order (COCO's 17 keypoints, its root made at the hips' midpoint); what numpy writes and the CLI
reads are the same positions, checked against the BVH the CLI writes, read back by the package."""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

import kinergy


def run(cli, *args):
    return subprocess.run([str(cli), *map(str, args)], capture_output=True, text=True)


def test_npy_arrays_numpy_writes_come_back_as_their_positions(cli, tmp_path, at_root):
    clip = kinergy.read_bvh("tests/data/006_14.bvh")
    names = clip.joint_names
    (tmp_path / "names.txt").write_text("\n".join(names) + "\n")
    for dtype, shape in [(np.float64, "3d"), (np.float32, "3d"), (np.float64, "wide")]:
        array = clip.positions.astype(dtype)
        if shape == "wide":
            array = array.reshape(array.shape[0], -1)
        path = tmp_path / f"p-{np.dtype(dtype).name}-{shape}.npy"
        np.save(path, array)
        out = tmp_path / f"{path.stem}.bvh"
        done = run(cli, "from-positions", path, "--names", tmp_path / "names.txt",
                   "--skeleton", "tests/data/006_14.bvh", "--frame-rate", 1 / clip.frame_time,
                   "-o", out)
        assert done.returncode == 0, done.stderr
        back = kinergy.read_bvh(out)
        tolerance = 1e-3 if dtype == np.float64 else 2e-3  # float32 holds ~0.1 mm at 2 m
        assert back.positions.shape == clip.positions.shape
        assert np.abs(back.positions - clip.positions).max() < tolerance


def test_coco_keypoints_in_their_own_order_get_a_root_at_the_hips(cli, tmp_path):
    order = ["nose", "left_eye", "right_eye", "left_ear", "right_ear", "left_shoulder",
             "right_shoulder", "left_elbow", "right_elbow", "left_wrist", "right_wrist",
             "left_hip", "right_hip", "left_knee", "right_knee", "left_ankle", "right_ankle"]
    rng = np.random.default_rng(7)
    # A rigid body of 17 keypoints turned about Y frame by frame: its positions come back.
    body = rng.uniform(-0.3, 0.3, (17, 3)) + [0.0, 1.0, 0.0]
    frames = []
    for k in range(20):
        a = 0.05 * k
        turn = np.array([[np.cos(a), 0, np.sin(a)], [0, 1, 0], [-np.sin(a), 0, np.cos(a)]])
        frames.append(body @ turn.T + [0.01 * k, 0.0, 0.0])
    keypoints = np.array(frames)
    path = tmp_path / "coco.npy"
    np.save(path, keypoints)
    out = tmp_path / "coco.bvh"
    # A random body is no human shape: its unit and up axis are given, not detected.
    done = run(cli, "from-positions", path, "--skeleton", "coco17", "--unit", "m", "--up", "y",
               "-o", out, "--json")
    assert done.returncode == 0, done.stderr
    back = kinergy.read_bvh(out, unit="cm")  # written in cm; this small body reads as inches
    assert back.joint_names[0] == "mid_hip" and len(back.joint_names) == 19
    # The leaves (ears, wrists, ankles) are End Sites, which BVH names after their parent.
    parent = {"left_ear": "left_eye", "right_ear": "right_eye", "left_wrist": "left_elbow",
              "right_wrist": "right_elbow", "left_ankle": "left_knee",
              "right_ankle": "right_knee"}
    def column(name):
        written = f"{parent[name]}_End" if name in parent else name
        return back.positions[:, back.joint_names.index(written)]
    got = {name: column(name) for name in order}
    for i, name in enumerate(order):
        assert np.abs(got[name] - keypoints[:, i]).max() < 1e-3, name
    hips = 0.5 * (keypoints[:, 11] + keypoints[:, 12])
    assert np.abs(back.positions[:, 0] - hips).max() < 1e-3
    # A names file that lacks a joint the map reads is refused, naming it.
    (tmp_path / "few.txt").write_text("\n".join(order[:-1] + ["tail"]) + "\n")
    done = run(cli, "from-positions", path, "--names", tmp_path / "few.txt",
               "--skeleton", "coco17", "-o", tmp_path / "x.bvh")
    assert done.returncode == 2 and "right_ankle" in done.stderr, done.stderr
    assert not (tmp_path / "x.bvh").exists()
