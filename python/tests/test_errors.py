"""Bad input from Python: exceptions with the CLI's messages, never a crash."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

import kinergy
from conftest import ROOT

INVALID = sorted((ROOT / "tests/data/bvh-quirks/invalid").glob("*.bvh"))
R09 = ROOT / "data-synthetic/p01/r09.bvh"


def test_the_hierarchy_of_exceptions():
    for e in (kinergy.BvhError, kinergy.ParamsError, kinergy.UnreachableError, kinergy.InputError,
              kinergy.NothingToFitError):
        assert issubclass(e, kinergy.KinergyError) and issubclass(e, Exception)


@pytest.mark.parametrize("path", INVALID, ids=lambda p: p.name)
def test_every_malformed_bvh_raises_bvh_error_with_its_place(path):
    with pytest.raises(kinergy.KinergyError) as caught:
        kinergy.read_bvh(path)
    message = str(caught.value)
    assert path.name in message
    if isinstance(caught.value, kinergy.BvhError) and caught.value.line is not None:
        assert caught.value.line >= 1 and caught.value.column >= 1
        assert f"line {caught.value.line}" in message


def test_most_malformed_files_say_the_line():
    lines = 0
    for path in INVALID:
        try:
            kinergy.read_bvh(path)
        except kinergy.BvhError as e:
            lines += e.line is not None
        except kinergy.KinergyError:
            pass
    assert len(INVALID) >= 30 and lines >= len(INVALID) - 6


def test_a_missing_file_and_a_file_too_large():
    with pytest.raises(kinergy.BvhError) as caught:
        kinergy.read_bvh(ROOT / "no-such.bvh")
    assert caught.value.path.endswith("no-such.bvh") and caught.value.line is None
    with pytest.raises(kinergy.InputError):
        kinergy.read_bvh(R09, max_input_mb=0)


def test_bad_params_files_raise_params_error_naming_the_field(tmp_path):
    good = json.loads((ROOT / "tests/data/params/synthetic-p01-r09-sc.json").read_text())
    (tmp_path / "garbage.json").write_text("{ not json")
    bad = dict(good, values=dict(good["values"], **{next(iter(good["values"])): "fast"}))
    (tmp_path / "value.json").write_text(json.dumps(bad))
    unknown = dict(good, colour="blue")
    (tmp_path / "field.json").write_text(json.dumps(unknown))
    for name, says in [("garbage.json", "not JSON"), ("value.json", "values"), ("field.json", "colour")]:
        with pytest.raises(kinergy.ParamsError) as caught:
            kinergy.Params.load(tmp_path / name)
        assert name in str(caught.value) and says in str(caught.value), str(caught.value)
    with pytest.raises(kinergy.ParamsError):
        kinergy.Params.load(tmp_path / "absent.json")


def test_unreachable_targets_raise_with_the_motion_made():
    with pytest.raises(kinergy.UnreachableError) as caught:
        kinergy.reach([0.0, 1.2, 2.5])
    assert isinstance(caught.value.clip, kinergy.Clip) and len(caught.value.clip) > 10
    assert kinergy.reach([0.0, 1.2, 2.5], check=False).frame_count == len(caught.value.clip)
    with pytest.raises(kinergy.UnreachableError) as caught:
        kinergy.synthesize(R09, frames="auto", target=[0.0, 1.4, 3.0])
    assert caught.value.clip.joint_names == kinergy.read_bvh(R09).joint_names
    with pytest.raises(kinergy.InputError):
        kinergy.reach([0.0, 1.2, 1e6])


@pytest.mark.parametrize(
    "call",
    [
        lambda: kinergy.fit(R09, model="sf"),
        lambda: kinergy.fit(R09, optimizer="newton"),
        lambda: kinergy.fit(R09, per="day"),
        lambda: kinergy.fit(R09, budget=0),
        lambda: kinergy.fit(R09, budget=10, population=100),
        lambda: kinergy.fit(R09, threads=0),
        lambda: kinergy.fit(R09, arm="middle"),
        lambda: kinergy.fit(R09, frames=(9, 3)),
        lambda: kinergy.fit(R09, select="most"),
        lambda: kinergy.fit(R09, chain=["Nope", "Nada", "Rien"]),
        lambda: kinergy.fit([R09, 42]),
        lambda: kinergy.fit(),
        lambda: kinergy.fit(R09, arm="auto", frames=(0, 9)),
        lambda: kinergy.read_bvh(R09, unit="furlong"),
        lambda: kinergy.read_bvh(R09, up="sideways"),
        lambda: kinergy.segment(R09, min_peak_speed=-1.0),
        lambda: kinergy.segment(R09, min_peak_speed=50.0001),
        lambda: kinergy.segment(R09, arm="auto", world=True),
        lambda: kinergy.read_bvh(R09).with_values(np.zeros((0, kinergy.read_bvh(R09).values.shape[1]))),
        lambda: kinergy.Clip.from_arrays(["root"], [-1], np.zeros((1, 3)), np.zeros((0, 1, 4)),
                                         np.zeros((0, 3)), 0.1),
        lambda: kinergy.fit(R09, budget=10**7 + 1),
        lambda: kinergy.fit(R09, speed_weight=0.1),
        lambda: kinergy.reach([0, 1, 0.4], person=R09, height=1.2),
        lambda: kinergy.reach([0.3, 1.1, 0.4], v_s=0.0),
        lambda: kinergy.reach([0.3, 1.1, 0.4], profile="minimum-jerk", r_s=0.5),
        lambda: kinergy.reach([0.3, 1.1, 0.4], p_min=0.95),
        lambda: kinergy.reach([0.3, 1.1, 0.4], comfortable_angle_deg=float("nan")),
        lambda: kinergy.fit(R09, population=1001),
        lambda: kinergy.fit(R09, temperature=1e6 + 1),
        lambda: kinergy.fit(R09, stable_change=1.0001),
        lambda: kinergy.fit(R09, stable_window=100001),
        lambda: kinergy.compare(R09, temperature=1e6 + 1),
        lambda: kinergy.synthesize(R09, frames=(5, 2)),
        lambda: kinergy.synthesize(R09, frames="most"),
        lambda: kinergy.synthesize(R09, tolerance=float("nan")),
        lambda: kinergy.synthesize(R09, target=[float("nan"), 0, 0]),
        lambda: kinergy.reach([float("nan"), 1, 0]),
        lambda: kinergy.reach([0, 1, 0.4], height=9.0),
        lambda: kinergy.reach([0, 1, 0.4], profile="jerky"),
        lambda: kinergy.read_bvh(R09).slice(5, 5),
    ],
)
def test_bad_arguments_raise_kinergy_errors(call):
    with pytest.raises(kinergy.KinergyError):
        call()


def test_a_wrong_type_is_a_type_error_not_a_crash():
    with pytest.raises((TypeError, kinergy.KinergyError)):
        kinergy.read_bvh(42)
    with pytest.raises((TypeError, kinergy.KinergyError)):
        kinergy.Clip.from_arrays(["a"], [-1], np.zeros((1, 3), dtype=np.float32),
                                 np.ones((1, 1, 4)), np.zeros((1, 3)), 0.1)


def test_mangled_files_raise_kinergy_errors_never_a_panic(tmp_path):
    # Seeded mutations of a valid BVH and a valid parameters file: byte flips, cut ends,
    # lines dropped or doubled. Each must read or raise a KinergyError — a PanicException
    # (a Rust panic across the boundary) or any other exception is a defect.
    import random

    rng = random.Random(25)
    bvh = (ROOT / "data-synthetic/p01/r09.bvh").read_bytes()
    params = (ROOT / "tests/data/params/synthetic-p01-r09-sc.json").read_bytes()

    def mangle(data: bytes) -> bytes:
        data = bytearray(data)
        kind = rng.randrange(5)
        if kind == 4:  # digits changed: mostly still a valid file, with other values
            digits = [i for i, b in enumerate(data) if 48 <= b <= 57]
            for i in rng.sample(digits, 20):
                data[i] = rng.choice(b"0123456789")
        elif kind == 0:
            for _ in range(rng.randrange(1, 8)):
                data[rng.randrange(len(data))] = rng.choice(b"-.e9 \n{}:xX\x00\xff")
        elif kind == 1:
            data = data[: rng.randrange(len(data))]
        else:
            lines = bytes(data).split(b"\n")
            i = rng.randrange(len(lines))
            lines[i:i + 1] = [] if kind == 2 else [lines[i], lines[i]]
            data = bytearray(b"\n".join(lines))
        return bytes(data)

    path = tmp_path / "m.bvh"
    outcomes = {"read": 0, "raised": 0}
    for _ in range(150):
        path.write_bytes(mangle(bvh))
        try:
            clip = kinergy.read_bvh(path)
            clip.positions, clip.rotations
            kinergy.segment(clip)
            outcomes["read"] += 1
        except kinergy.KinergyError:
            outcomes["raised"] += 1
    assert outcomes["raised"] > 20 and outcomes["read"] > 10, outcomes
    clip = kinergy.read_bvh(R09)
    for _ in range(150):
        try:
            p = kinergy.Params.from_json(mangle(params).decode("utf-8", "replace"))
            kinergy.synthesize(clip, p, check=False)
        except kinergy.KinergyError:
            pass


def test_nothing_to_fit_is_its_own_class_as_the_cli_s_exit_1(cli, at_root, tmp_path):
    """A take with no reach on the arm asked for: the CLI exits 1 (the input is fine) and
    Python raises NothingToFitError, not InputError; both from the error's kind."""
    from conftest import run

    out = run(cli, "fit", "data-synthetic/p01/r09.bvh", "--arm", "left", "--model", "sa",
              "-o", str(tmp_path / "x.json"), ok=(1,))
    assert "nothing to fit" in out.stderr
    with pytest.raises(kinergy.NothingToFitError, match="nothing to fit|no main reach") as caught:
        kinergy.fit("data-synthetic/p01/r09.bvh", arm="left", model="sa")
    assert not isinstance(caught.value, kinergy.InputError)


def test_writes_refuse_what_is_not_a_regular_file(at_root, tmp_path):
    """A FIFO, a folder and (where the test may make one) a device node in the test's own
    folder are refused before anything is written, and stay what they were."""
    import stat

    clip = kinergy.read_bvh("data-synthetic/p01/r09.bvh")
    params = kinergy.Params.load("tests/data/params/synthetic-p01-r09-sc.json")
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    folder = tmp_path / "folder"
    folder.mkdir()
    targets = [fifo, folder]
    device = tmp_path / "null"
    try:
        os.mknod(device, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
        targets.append(device)
    except PermissionError:
        pass
    for target in targets:
        before = os.stat(target).st_mode
        for write in (clip.write_bvh, params.save):
            with pytest.raises(kinergy.KinergyError, match="not a regular file"):
                write(target)
        assert os.stat(target).st_mode == before, target
    assert not [p for p in tmp_path.iterdir() if p.name.endswith(".tmp")]


def test_slow_motions_are_found_down_to_the_documented_peak_speed(at_root):
    """min_peak_speed takes its whole documented range (0.001 to 50 m/s): the rest
    threshold is lowered with it, as in the CLI."""
    for speed in (0.001, 0.01, 0.05):
        rows = kinergy.segment(R09, min_peak_speed=speed)
        assert rows, speed


def test_a_destination_beyond_any_body_is_said_as_the_cli_says_it(at_root):
    with pytest.raises(kinergy.InputError, match="beyond what any body reaches"):
        kinergy.plan("examples/bookshelf/scene.json", task="relocate", object="blue_book",
                     to=[1e308, 1, 0])
