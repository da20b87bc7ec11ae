"""`kinergy.retarget`: a motion moved onto another skeleton, as `kinergy retarget` moves it —
the round trip between the committed CMU and Character Creator captures gives the wrists'
paths back, planted feet do not slide, and bad maps raise InputError naming what is wrong."""

from __future__ import annotations

import json

import numpy as np
import pytest

import kinergy
from conftest import ROOT, run

CMU = ROOT / "tests/data/cmu_12_01_walk.bvh"
CC = ROOT / "tests/data/006_14.bvh"
WRISTS = ["CC_Base_R_Hand", "CC_Base_L_Hand"]


@pytest.fixture(scope="module")
def clips():
    return kinergy.read_bvh(CC), kinergy.read_bvh(CMU)


def test_cc_to_cmu_and_back_gives_the_wrists_paths_back(clips):
    cc, cmu = clips
    there, report_there = kinergy.retarget(cc, cmu)
    assert there.joint_names == cmu.joint_names
    assert there.frame_count == cc.frame_count and there.frame_time == cc.frame_time
    back, report_back = kinergy.retarget(there, cc, map="cmu", to_map="cc")
    assert back.joint_names == cc.joint_names
    assert back.frame_count == cc.frame_count and back.frame_time == cc.frame_time
    wrists = [cc.joint_names.index(n) for n in WRISTS]
    error = np.linalg.norm(back.positions[:, wrists] - cc.positions[:, wrists], axis=-1).max()
    # Where a foot was beyond a leg's reach, the pelvis came down (reported): the body with it.
    bound = 0.015 + report_there["pelvis_drop_m"] + report_back["pelvis_drop_m"]
    assert error <= bound, f"CC → CMU → CC: the wrists off by {error} m"


def test_the_report_holds_the_plants_and_the_feet_do_not_slide(clips):
    cc, cmu = clips
    _, report = kinergy.retarget(cc, cmu)
    assert set(report) == {
        "roles", "unmapped", "leg_scale", "arm_scale", "plants", "foot_slide_m",
        "foot_error_m", "hand_error_m", "bend_limited_frames", "pelvis_drop_m",
    }
    assert report["foot_slide_m"] <= 1e-3
    assert len(report["plants"]) == 2 and all(report["plants"]), report["plants"]
    for plants in report["plants"]:
        for plant in plants:
            assert set(plant) == {"first", "last", "at"}
            assert 0 <= plant["first"] <= plant["last"] < cc.frame_count and len(plant["at"]) == 3
    assert ["right_wrist", "CC_Base_R_Hand", "RightHand"] in report["roles"]
    assert len(report["arm_scale"]) == 2 and report["leg_scale"] > 0


def test_the_motion_and_report_are_the_cli_s(cli, tmp_path):
    cc, cmu = kinergy.read_bvh(CC), kinergy.read_bvh(CMU)
    moved, report = kinergy.retarget(cc, cmu)
    out = tmp_path / "moved.bvh"
    said = json.loads(run(cli, "retarget", str(CC), "--to", str(CMU), "-o", str(out), "--json",
                          quiet=False).stdout)
    assert {k: said[k] for k in report} == report
    back = kinergy.read_bvh(out)
    assert back.joint_names == moved.joint_names
    assert np.abs(back.positions - moved.positions).max() <= 1e-9


def test_a_map_of_joints_given_as_a_json_file(clips, tmp_path):
    cc, cmu = clips
    path = tmp_path / "cc.json"
    roles = {
        "pelvis": "CC_Base_Hip", "spine": ["CC_Base_Waist", "CC_Base_Spine01", "CC_Base_Spine02"],
        "neck": ["CC_Base_NeckTwist01", "CC_Base_NeckTwist02"], "head": "CC_Base_Head",
    }
    for side, s in [("right", "R"), ("left", "L")]:
        roles |= {
            f"{side}_clavicle": f"CC_Base_{s}_Clavicle", f"{side}_shoulder": f"CC_Base_{s}_Upperarm",
            f"{side}_elbow": f"CC_Base_{s}_Forearm", f"{side}_wrist": f"CC_Base_{s}_Hand",
            f"{side}_hip": f"CC_Base_{s}_Thigh", f"{side}_knee": f"CC_Base_{s}_Calf",
            f"{side}_ankle": f"CC_Base_{s}_Foot",
        }
    path.write_text(json.dumps(roles))
    by_file, _ = kinergy.retarget(cc, cmu, map=str(path))
    by_name, _ = kinergy.retarget(cc, cmu, map="cc")
    assert np.array_equal(by_file.values, by_name.values)
    path.write_text(json.dumps(roles | {"pelvis": "NoSuchHip"}))
    with pytest.raises(kinergy.InputError, match="NoSuchHip"):
        kinergy.retarget(cc, cmu, map=str(path))
    with pytest.raises(kinergy.InputError, match="absent.json"):
        kinergy.retarget(cc, cmu, map=str(tmp_path / "absent.json"))


def test_unknown_maps_and_missing_joints_raise_input_error(clips):
    cc, cmu = clips
    with pytest.raises(kinergy.InputError, match="nope"):
        kinergy.retarget(cc, cmu, map="nope")
    with pytest.raises(kinergy.InputError, match="UpperArm_R"):
        kinergy.retarget(cmu, cc, to_map="bandai")
    with pytest.raises(TypeError):
        kinergy.retarget(CC, cmu)


def test_the_performers_arms_as_the_cli_gives_them(clips, cli, tmp_path):
    """arms="source": the template's skeleton with the clip performer's upper arms and
    forearms times the bodies' size ratio (the report's leg scale), as `--arms source` writes
    it; another value raises InputError naming it."""
    cc, cmu = clips
    moved, report = kinergy.retarget(cc, cmu, arms="source")
    scale = report["leg_scale"]
    assert report["arm_scale"] == pytest.approx([scale, scale], rel=1e-9)

    def bones(clip, names):
        p = clip.positions[0, [clip.joint_names.index(n) for n in names]]
        return np.linalg.norm(np.diff(p, axis=0), axis=-1)

    for cc_arm, cmu_arm in [
        (["CC_Base_R_Upperarm", "CC_Base_R_Forearm", "CC_Base_R_Hand"],
         ["RightArm", "RightForeArm", "RightHand"]),
        (["CC_Base_L_Upperarm", "CC_Base_L_Forearm", "CC_Base_L_Hand"],
         ["LeftArm", "LeftForeArm", "LeftHand"]),
    ]:
        assert bones(moved, cmu_arm) == pytest.approx(bones(cc, cc_arm) * scale, rel=1e-9)
        # The template's own arms differ: the option changed something.
        assert not np.allclose(bones(cmu, cmu_arm), bones(moved, cmu_arm), rtol=0.02)
    out = tmp_path / "moved.bvh"
    run(cli, "retarget", str(CC), "--to", str(CMU), "-o", str(out), "--arms", "source")
    assert np.abs(kinergy.read_bvh(out).positions - moved.positions).max() <= 1e-9
    with pytest.raises(kinergy.InputError, match="performer"):
        kinergy.retarget(cc, cmu, arms="performer")
