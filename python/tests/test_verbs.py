"""The verbs: the same results as the CLI, the GIL released, Ctrl-C and progress."""

from __future__ import annotations

import json
import os
import sys
import signal
import threading
import time

import numpy as np
import pytest

import kinergy
from conftest import ROOT, run

R09 = "data-synthetic/p01/r09.bvh"


def test_segment_lists_what_the_cli_lists(cli, at_root):
    ours = kinergy.segment(R09)
    theirs = json.loads(run(cli, "segment", R09, "--json", quiet=False).stdout)["segments"]
    assert [(s["onset"], s["peak"], s["end"], s["label"], s["main"]) for s in ours] == [
        (s["onset"], s["peak"], s["end"], s["label"], s["main"]) for s in theirs
    ]
    assert kinergy.segment(kinergy.read_bvh(R09), select="main")[0]["main"]


def test_a_clip_fit_writes_the_cli_s_params_file_byte_for_byte(cli, at_root, tmp_path):
    [params] = kinergy.fit(R09, model="sc", per="clip", budget=240, seed=3)
    params.save(tmp_path / "py.json")
    run(cli, "fit", R09, "--model", "sc", "--per", "clip", "--budget", "240", "--seed", "3",
        "-o", str(tmp_path / "cli.json"))
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    assert list(params.distances) == ["sa", "sb", "sc"]
    assert params.distances["sc"] <= params.distances["sa"]
    assert params.model == "sc" and params.optimizer == "svd"
    assert set(params.vector) == set(json.loads(params.to_json())["values"])


def test_a_person_fit_of_a_folder_is_the_cli_s(cli, at_root, tmp_path):
    params = kinergy.fit("data-synthetic/p02", model="sb", budget=160, optimizer="njt")
    params.save(tmp_path / "py.json")
    run(cli, "fit", "data-synthetic/p02", "--model", "sb", "--budget", "160",
        "--optimizer", "njt", "-o", str(tmp_path / "cli.json"))
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    loaded = kinergy.Params.load(tmp_path / "cli.json")
    assert loaded.to_json() == params.to_json()
    assert len(loaded.record["reaches"]) == 14


def test_a_fit_with_the_speed_term_is_the_cli_s(cli, at_root, tmp_path):
    [params] = kinergy.fit(R09, model="sb", per="clip", budget=120, objective="positions+speed",
                           speed_weight=0.1)
    params.save(tmp_path / "py.json")
    run(cli, "fit", R09, "--model", "sb", "--per", "clip", "--budget", "120", "--objective",
        "positions+speed", "--speed-weight", "0.1", "-o", str(tmp_path / "cli.json"))
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    assert params.record["objective"] == {"kind": "positions+speed", "speed_weight_s": 0.1}
    with pytest.raises(kinergy.InputError):
        kinergy.fit(R09, objective="speed")


def test_an_s_e_fit_is_the_cli_s_and_synthesizes_as_it(cli, at_root, tmp_path):
    [params] = kinergy.fit(R09, model="se", per="clip", budget=160, seed=2)
    params.save(tmp_path / "py.json")
    run(cli, "fit", R09, "--model", "se", "--per", "clip", "--budget", "160", "--seed", "2",
        "-o", str(tmp_path / "cli.json"))
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    assert list(params.distances) == ["sa", "sb", "sc", "sd", "se"]
    assert params.distances["se"] <= params.distances["sd"]
    assert {"acceleration", "onset", "k_elbow_flexion"} <= set(params.vector)
    motion = kinergy.synthesize(R09, params, check=False)
    run(cli, "synthesize", R09, "--params", str(tmp_path / "cli.json"), "-o",
        str(tmp_path / "s.bvh"), ok=(0, 1))
    cli_motion = kinergy.read_bvh(tmp_path / "s.bvh")
    assert np.abs(motion.positions - cli_motion.positions).max() <= 1e-9


def test_the_fit_does_not_depend_on_threads(at_root):
    one = kinergy.fit(R09, model="sb", budget=160, threads=1)
    two = kinergy.fit(R09, model="sb", budget=160, threads=2)
    assert one.to_json() == two.to_json()


def test_a_synthesized_clip_is_the_cli_s_output_read_back(cli, at_root, tmp_path):
    [params] = kinergy.fit(R09, model="sc", per="clip", budget=160)
    params.save(tmp_path / "p.json")
    motion = kinergy.synthesize(R09, params, check=False)
    run(cli, "synthesize", R09, "--params", str(tmp_path / "p.json"), "-o",
        str(tmp_path / "s.bvh"), ok=(0, 1))
    back = kinergy.read_bvh(tmp_path / "s.bvh", unit="cm")
    assert motion.positions.shape == back.positions.shape
    assert np.abs(motion.positions - back.positions).max() <= 1e-9
    said = json.loads(run(cli, "synthesize", R09, "--params", str(tmp_path / "p.json"), "-o",
                          str(tmp_path / "s2.bvh"), "--json", ok=(0, 1), quiet=False).stdout)
    # One library report, serialized by both: equal but for the file the CLI wrote.
    report = dict(motion.report)
    assert report.pop("output") is None and said.pop("output").endswith("s2.bvh")
    assert report == said
    assert kinergy.read_bvh(R09).report is None
    # Also with the neutral model and a given target.
    neutral = kinergy.synthesize(R09, frames="auto", target=[-0.2, 1.3, 0.4], check=False)
    run(cli, "synthesize", R09, "--frames", "auto", "--target", "-0.2,1.3,0.4", "-o",
        str(tmp_path / "n.bvh"), ok=(0, 1))
    back = kinergy.read_bvh(tmp_path / "n.bvh", unit="cm")
    assert np.abs(neutral.positions - back.positions).max() <= 1e-9


def test_synthesize_selects_a_segment_and_warns_of_another_arm_as_the_cli_does(cli, at_root, tmp_path):
    by_select = kinergy.synthesize(R09, select="main", check=False)
    by_frames = kinergy.synthesize(R09, frames="auto", check=False)
    assert by_select.report["capture_frames"] == by_frames.report["capture_frames"]
    with pytest.raises(kinergy.InputError, match="not both"):
        kinergy.synthesize(R09, frames="auto", select=0)
    with pytest.raises(kinergy.InputError, match="one reach"):
        kinergy.synthesize(R09, select="all")
    [params] = kinergy.fit(R09, model="sa", per="clip", budget=60)
    params.save(tmp_path / "p.json")
    said = run(cli, "synthesize", R09, "--params", str(tmp_path / "p.json"), "--arm", "left",
               "--frames", "all", "-o", str(tmp_path / "l.bvh"), ok=(0, 1), quiet=False).stderr
    assert "warning: the parameters were fitted on a right arm" in said
    with pytest.warns(UserWarning, match="fitted on a right arm"):
        kinergy.synthesize(R09, params, arm="left", frames="all", check=False)


def test_a_full_body_reach_in_a_person_s_style_is_the_cli_s(cli, at_root, tmp_path):
    params = kinergy.Params.load("tests/data/params/synthetic-p01-r09-sc.json")
    body = kinergy.reach([-0.3, 1.3, 0.45], params=params)
    run(cli, "reach", "--target", "-0.3,1.3,0.45", "--params",
        "tests/data/params/synthetic-p01-r09-sc.json", "-o", str(tmp_path / "r.bvh"))
    back = kinergy.read_bvh(tmp_path / "r.bvh", unit="cm")
    assert np.abs(body.positions - back.positions).max() <= 1e-9
    said = json.loads(run(cli, "reach", "--target", "-0.3,1.3,0.45", "--params",
                          "tests/data/params/synthetic-p01-r09-sc.json", "-o",
                          str(tmp_path / "r2.bvh"), "--json", quiet=False).stdout)
    # One library report, serialized by both: equal but for the file the CLI wrote.
    report = dict(body.report)
    assert report.pop("output") is None and said.pop("output").endswith("r2.bvh")
    assert report == said
    # The hand point (the hand's End Site) arrives at the target.
    hand = body.joint_names.index("RightHand_End")
    assert np.linalg.norm(body.positions[-1, hand] - [-0.3, 1.3, 0.45]) < 0.01


def test_compare_rows_are_the_cli_s_results_csv(cli, at_root, tmp_path):
    import csv

    clips = ["data-synthetic/p01/r01.bvh", R09, "data-synthetic/p02/r03.bvh"]
    for baselines in (False, True):
        seen = []
        ours = kinergy.compare(clips, models=["sa", "sc"], optimizers=["jt", "svd"],
                               baselines=baselines, budget=80, seed=2,
                               progress=lambda done, total: seen.append((done, total)))
        flags = [] if baselines else ["--no-baselines"]
        run(cli, "compare", *clips, "--models", "sa,sc", "--optimizers", "jt,svd", "--budget", "80",
            "--seed", "2", *flags, "-o", str(tmp_path / "c"))
        with open(tmp_path / "c" / "results.csv") as f:
            theirs = list(csv.DictReader(f))
        assert len(ours) == len(theirs) > 0
        for a, b in zip(ours, theirs):
            for key in ("clip", "arm", "model", "optimizer", "method"):
                assert str(a[key]) == b[key], (key, a, b)
            for key in ("onset", "end", "frames", "evaluations"):
                assert a[key] == int(b[key]), (key, a, b)
            assert a["distance_m"] == float(b["distance_m"]), (a, b)
        assert seen and seen[-1] == (3, 3)
    # Fig. 3 with S_A alone; Fig. 4 fits S_A and S_C with SVD (Fig. 3 has no S_C to serve it).
    records = kinergy.compare([R09], models=["sa"], optimizers=["svd"], baselines=False, budget=40,
                              as_records=True)
    assert list(records.model) == ["sa", "sa", "sc"] and records.distance_m.dtype == float


def test_progress_is_reported_and_its_exception_stops_the_fit(at_root):
    seen = []
    kinergy.fit(R09, model="sb", budget=160, progress=seen.append)
    assert seen and {s["model"] for s in seen} == {"sa", "sb"}
    assert all(s["evaluations"] <= s["max_evaluations"] for s in seen)

    class Stop(Exception):
        pass

    def stop_after_three(info, calls=[]):
        calls.append(info)
        if len(calls) == 3:
            raise Stop("enough")

    with pytest.raises(Stop) as raised:
        kinergy.fit(R09, model="sd", budget=4000, progress=stop_after_three)
    assert str(raised.value) == "enough"
    if sys.version_info >= (3, 11):
        assert any("the progress callback raised at iteration" in n
                   for n in raised.value.__notes__), raised.value.__notes__

    def bare_interrupt(info):
        raise KeyboardInterrupt

    # A bare KeyboardInterrupt from the callback says where it stopped the fit (issue 42).
    with pytest.raises(KeyboardInterrupt, match="progress callback raised at iteration 1 of sa"
                       ) as raised:
        kinergy.fit(R09, model="sd", budget=4000, progress=bare_interrupt)
    assert isinstance(raised.value.__cause__, KeyboardInterrupt)


def test_progress_names_each_stage_whatever_its_length(at_root):
    """Stages of one iteration (budget = population × 2) and S_E's phases are each named by
    the model the nested fit runs, in order."""
    for model, budget in (("sd", 16), ("se", 64)):
        seen = []
        kinergy.fit(R09, model=model, budget=budget, population=8, progress=seen.append)
        stages = []
        for s in seen:
            if not stages or stages[-1] != (s["model"], s["stage"]):
                stages.append((s["model"], s["stage"]))
        names = ["sa", "sb", "sc", "sd", "se"][: ["sa", "sb", "sc", "sd", "se"].index(model) + 1]
        assert stages == list(zip(names, range(len(names)))), (model, stages)


def test_ctrl_c_raises_keyboard_interrupt_promptly(at_root):
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            kinergy.fit("data-synthetic/p01", model="sd", budget=100000)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 10


@pytest.mark.parametrize("kwargs", [dict(threads=2), dict(threads=1), dict(refine=10**6)])
def test_ctrl_c_reaches_fits_on_any_pool_and_refinements(at_root, kwargs):
    """Signals are watched from the calling thread whatever pool the fit runs on, and a
    refinement stops with the flag (it used to raise only when it ended)."""
    timer = threading.Timer(1.0, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            budget = 16 if "refine" in kwargs else 10**6
            # The refinement of one reach can end within the second (0.8-0.9 s here): a
            # person's fourteen reaches refine for about 3 s.
            clips = "data-synthetic/p01" if "refine" in kwargs else R09
            kinergy.fit(clips, model="sd", budget=budget, stable_window=100000, **kwargs)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 15, kwargs


def test_the_gil_is_released_while_fitting(at_root):
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(1)
            time.sleep(0.001)

    ticker = threading.Thread(target=tick)
    ticker.start()
    try:
        start = time.monotonic()
        kinergy.fit("data-synthetic/p01", model="sb", budget=400, threads=1)
        elapsed = time.monotonic() - start
    finally:
        done.set()
        ticker.join()
    # The ticker ran through the fit, not only in the moments between iterations.
    assert len(ticks) > 0.3 * elapsed / 0.0011


def test_hand_speed_is_the_cli_s_speed_csv(cli, at_root, tmp_path):
    for relative in (False, True):
        flags = ["--relative"] if relative else []
        run(cli, "plot", "speed", R09, "-o", str(tmp_path / "s.svg"), "--csv",
            str(tmp_path / "s.csv"), *flags)
        theirs = np.loadtxt(tmp_path / "s.csv", delimiter=",", skiprows=1, usecols=2)
        ours = kinergy.hand_speed(R09, relative=relative)
        assert ours.shape == theirs.shape and np.allclose(ours, theirs, rtol=1e-12, atol=1e-12)
    # Independent: central differences of the hand point's world positions, in numpy.
    clip = kinergy.read_bvh(R09)
    speed = kinergy.hand_speed(clip)
    hand = clip.positions[:, clip.joint_names.index("RightHand_End")]
    inner = np.linalg.norm(hand[2:] - hand[:-2], axis=1) / (2 * clip.frame_time)
    assert np.allclose(speed[1:-1], inner, atol=1e-9)


def test_style_rows_are_the_cli_s(cli, at_root):
    params = "tests/data/params/synthetic-p01-r09-sc.json"
    clips = ["data-synthetic/p01/r09.bvh", "data-synthetic/p01/r02.bvh"]
    ours = kinergy.style(clips, params, motions=True)
    theirs = json.loads(run(cli, "style", *clips, "--params", params, "--json", quiet=False).stdout)
    assert ours["rows"] == theirs["rows"] and ours["summary"] == theirs["summary"]
    # The real-time figures: the same as the CLI's, the body judged against the
    # person's own repeats and minimum jerk.
    assert ours["fidelity"] == theirs["fidelity"]
    names = [s["predictor"] for s in ours["fidelity"]["summaries"]]
    assert {"ceiling", "minimum_jerk", "arm", "body"} <= set(names)
    assert [m["clip"] for m in ours["motions"]] == clips
    assert all(isinstance(m["params"], kinergy.Clip) for m in ours["motions"])


def test_a_planned_grasp_is_the_cli_s(cli, at_root, tmp_path):
    scene = "examples/bookshelf/scene.json"
    ours = kinergy.plan(scene, task="grasp", object="blue_book", seed=2)
    run(cli, "plan", "--scene", scene, "--task", "grasp", "--object", "blue_book", "--seed", "2",
        "-o", str(tmp_path / "g.bvh"))
    back = kinergy.read_bvh(tmp_path / "g.bvh", unit="cm")
    assert np.abs(ours.positions - back.positions).max() <= 1e-9
    said = json.loads(run(cli, "plan", "--scene", scene, "--task", "grasp", "--object",
                          "blue_book", "--seed", "2", "-o", str(tmp_path / "g2.bvh"), "--json",
                          quiet=False).stdout)

    def timeless(report):
        """The report without the planner's wall times."""
        report = json.loads(json.dumps(report))
        for phase in report["phases"]:
            for key in ("plan_ms", "smooth_ms"):
                (phase.get("planned") or {}).pop(key, None)
        return report

    # One library report, serialized by both: equal but for the file and the wall times.
    report = timeless(ours.report)
    assert report.pop("output") is None and said.pop("output").endswith("g2.bvh")
    assert report == timeless(said)
    with pytest.raises(kinergy.InputError, match="did you mean `blue_book`"):
        kinergy.plan(scene, task="grasp", object="blue_bok")
    with pytest.raises(kinergy.InputError, match="atlass"):
        kinergy.plan(scene, task="grasp", object="atlass")
    with pytest.raises(kinergy.InputError):
        kinergy.plan(scene)


def test_plan_levels_are_the_cli_s(cli, at_root, tmp_path):
    """`plan(level=)` is parsed and run as `plan --level`: the same motion, the same levels in
    the report; a forced level that fails raises UnreachableError naming it; a bad level, or a
    level for a task, is an InputError."""
    board = "examples/levels/board.json"
    target = [-0.2, 1.15, 0.35]
    ours = kinergy.plan(board, target=target)
    assert ours.report["level"] == "planner"
    assert [(l["level"], l["solved"]) for l in ours.report["levels"]] == [
        ("ik", False), ("straight", False), ("planner", True)]
    said = json.loads(run(cli, "plan", "--scene", board, "--target=-0.2,1.15,0.35", "-o",
                          str(tmp_path / "b.bvh"), "--json", quiet=False).stdout)
    assert [l["level"] for l in said["levels"]] == [l["level"] for l in ours.report["levels"]]
    back = kinergy.read_bvh(tmp_path / "b.bvh", unit="cm")
    assert np.abs(ours.positions - back.positions).max() <= 1e-9
    with pytest.raises(kinergy.UnreachableError, match="level straight failed"):
        kinergy.plan(board, target=target, level="straight")
    with pytest.raises(kinergy.InputError, match="level"):
        kinergy.plan(board, target=target, level="rrt")
    with pytest.raises(kinergy.InputError, match="a task's moves are planned"):
        kinergy.plan("examples/bookshelf/scene.json", task="grasp", object="blue_book", level="ik")


def test_a_field_fit_is_the_cli_s_field_file_and_drives_as_it(cli, at_root, tmp_path):
    clips = ["data-synthetic/p01/r01.bvh", "data-synthetic/p01/r02.bvh", "data-synthetic/p01/r03.bvh"]
    field = kinergy.fit(clips, model="sb", field=True, budget=80)
    assert field.is_field and field.vector is None
    field.save(tmp_path / "py.json")
    run(cli, "fit", *clips, "--model", "sb", "--field", "--budget", "80", "-o", str(tmp_path / "cli.json"))
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    motion = kinergy.synthesize(R09, field, frames="auto", check=False)
    run(cli, "synthesize", R09, "--params", str(tmp_path / "cli.json"), "--frames", "auto",
        "-o", str(tmp_path / "s.bvh"), ok=(0, 1))
    back = kinergy.read_bvh(tmp_path / "s.bvh", unit="cm")
    assert np.abs(motion.positions - back.positions).max() <= 1e-9
    with pytest.raises(kinergy.InputError):
        kinergy.fit(clips, field=True, per="clip", budget=80)


def test_ctrl_c_stops_compare_promptly(at_root):
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            kinergy.compare("data-synthetic", budget=100000)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 15


def test_view_writes_the_cli_s_page(cli, at_root, tmp_path):
    clips = [R09, "data-synthetic/p01/r03.bvh"]
    ours = tmp_path / "ours.html"
    size = kinergy.view(clips, ours, target=[0.2, 1.0, 0.5])
    theirs = tmp_path / "theirs.html"
    run(cli, "view", *clips, "--target", "0.2,1.0,0.5", "-o", str(theirs))
    # The same page, byte for byte, and its size returned.
    assert ours.read_bytes() == theirs.read_bytes()
    assert size == len(ours.read_bytes())
    # A Clip made in memory is labelled, and what was read is what the page holds.
    clip = kinergy.read_bvh(R09)
    page = tmp_path / "mem.html"
    kinergy.view([clip], page, labels=["mine"], hand="right")
    text = page.read_text()
    assert '"label":"mine"' in text and f'"frames":{clip.frame_count}' in text


def test_view_refuses_bad_arguments_before_writing(at_root, tmp_path):
    out = tmp_path / "v.html"
    with pytest.raises(kinergy.InputError, match=r"\.html"):
        kinergy.view([R09], tmp_path / "v.png")
    with pytest.raises(kinergy.InputError, match="labels"):
        kinergy.view([R09], out, labels=["a", "b"])
    with pytest.raises(kinergy.InputError, match="hand"):
        kinergy.view([R09], out, hand="both")
    with pytest.raises(kinergy.InputError, match="target"):
        kinergy.view([R09], out, target=[0.0, float("nan"), 0.0])
    assert not out.exists()


def test_from_positions_gives_the_positions_back(at_root):
    clip = kinergy.read_bvh("tests/data/006_14.bvh")
    parents = clip.parents
    made = kinergy.from_positions(clip.positions, clip.joint_names, parents,
                                  frame_time=clip.frame_time)
    # Independent of the report: numpy's difference of the two clips' positions.
    assert made.positions.shape == clip.positions.shape
    # (A micrometre: the CMU rig's near-zero hip bones carry little direction.)
    assert np.abs(made.positions - clip.positions).max() < 1e-5
    assert made.report["max_error_m"] < 1e-5 and made.report["stretched"] == []
    assert made.frame_time == clip.frame_time and made.joint_names == clip.joint_names
    # The capture's right shoulder twists past the arm's ±90°: the made rotations say so.
    beyond = dict(made.report["arms_beyond_limits"])
    assert "shoulder_twist" in beyond["right"], made.report["arms_beyond_limits"]
    # A bone that stretches is reported, and its joint is off by no more than its range.
    moved = clip.positions.copy()
    moved[::2, 1:] += [0.0, 0.05, 0.0]  # every second frame the body floats off its root
    odd = kinergy.from_positions(moved, clip.joint_names, parents)
    assert [name for name, _ in odd.report["stretched"]] != []
    # Kept in position channels, the stretching bone puts every joint back where it was.
    kept = kinergy.from_positions(moved, clip.joint_names, parents, stretch="keep")
    assert np.abs(kept.positions - moved).max() < 1e-6
    assert kept.report["max_error_m"] < 1e-6
    with pytest.raises(kinergy.InputError, match="hold or keep"):
        kinergy.from_positions(moved, clip.joint_names, parents, stretch="loose")
    with pytest.raises(kinergy.InputError, match=r"\(frames, 141, 3\)"):
        kinergy.from_positions(clip.positions[:, :3], clip.joint_names, parents)
