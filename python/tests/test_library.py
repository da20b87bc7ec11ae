"""A library from Python: the CLI's files, bytes and exit classes (`kinergy fit --out-dir`,
`kinergy collect`), sharded or not."""

from __future__ import annotations

import csv
import io

import pytest

import kinergy
from conftest import run

LIB = "data-synthetic/p03"


def table(path):
    """library.csv's rows, without the seconds each fit took."""
    rows = list(csv.DictReader(io.StringIO(path.read_text())))
    for r in rows:
        r.pop("seconds")
    return rows


def results(folder):
    """The result files of a library folder (its records in shards/ left out)."""
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*.json"))
            if p.relative_to(folder).parts[0] != "shards"}


def test_a_library_fit_writes_the_cli_s_files(cli, at_root, tmp_path):
    run(cli, "fit", LIB, "--model", "sa", "--per", "clip", "--budget", "200",
        "--out-dir", str(tmp_path / "cli"))
    out = kinergy.fit(LIB, model="sa", per="clip", budget=200, out_dir=tmp_path / "py")
    assert out["shard"] == (1, 1) and out["fitted"] == len(out["rows"]) > 0
    assert results(tmp_path / "py") == results(tmp_path / "cli")
    assert table(tmp_path / "py/library.csv") == table(tmp_path / "cli/library.csv")
    assert (tmp_path / "py/skipped.csv").read_bytes() == (tmp_path / "cli/skipped.csv").read_bytes()
    rows = kinergy.collect(tmp_path / "cli")
    assert [r["result"] for r in rows] == [r["result"] for r in out["rows"]]
    assert all(r["distance_sa_m"] > 0 and r["distance_sb_m"] is None for r in rows)


def test_shards_from_python_make_the_one_machine_library(at_root, tmp_path):
    whole = kinergy.fit(LIB, model="sa", per="clip", budget=200, out_dir=tmp_path / "one")
    for i in (1, 2):
        part = kinergy.fit(LIB, model="sa", per="clip", budget=200, out_dir=tmp_path / "two",
                           shard=f"{i}/2")
        assert "rows" not in part and part["shard"] == (i, 2)
    with pytest.raises(kinergy.KinergyError, match="not complete"):
        kinergy.collect(_half(tmp_path))
    rows = kinergy.collect(tmp_path / "two")
    assert results(tmp_path / "two") == results(tmp_path / "one")
    strip = lambda rs: [{k: v for k, v in r.items() if k != "seconds"} for r in rs]
    assert strip(rows) == strip(whole["rows"])
    # Resumed, every result is found complete: nothing is fitted again.
    again = kinergy.fit(LIB, model="sa", per="clip", budget=200, out_dir=tmp_path / "one",
                        resume=True)
    assert results(tmp_path / "one") == results(tmp_path / "two")
    assert all(r["seconds"] is None for r in again["rows"])


def test_warm_starts_from_python_are_the_cli_s(cli, at_root, tmp_path):
    run(cli, "fit", LIB, "--model", "sb", "--per", "clip", "--budget", "200", "--warm-start",
        "--out-dir", str(tmp_path / "cli"))
    out = kinergy.fit(LIB, model="sb", per="clip", budget=200, warm_start=True,
                      out_dir=tmp_path / "py")
    assert results(tmp_path / "py") == results(tmp_path / "cli")
    # The first take fits both models; the others S_B alone, from its vector.
    first, *others = out["rows"]
    assert first["distance_sa_m"] is not None
    assert others and all(r["distance_sa_m"] is None and r["distance_sb_m"] > 0
                          for r in others)


def _half(tmp_path):
    """A library of which only shard 1 of 2 ran."""
    kinergy.fit(LIB, model="sa", per="clip", budget=200, out_dir=tmp_path / "half",
                shard=(1, 2))
    return tmp_path / "half"


def test_library_arguments_are_checked_as_the_cli_checks_them(at_root, tmp_path):
    with pytest.raises(kinergy.InputError, match="shard"):
        kinergy.fit(LIB, per="clip", out_dir=tmp_path / "x", shard="3/2")
    with pytest.raises(kinergy.InputError, match="per"):
        kinergy.fit(LIB, per="person", out_dir=tmp_path / "x")
    with pytest.raises(kinergy.InputError, match="out_dir"):
        kinergy.fit(LIB, shard="1/2")
    with pytest.raises(kinergy.InputError, match="warm_start"):
        kinergy.fit(LIB, warm_start=True)
    with pytest.raises(kinergy.InputError):
        kinergy.collect(tmp_path / "not-a-library")
    assert not (tmp_path / "x").exists()


def test_a_library_of_takes_with_nothing_to_fit_is_the_cli_s_exit_1(cli, at_root, tmp_path):
    run(cli, "fit", "data-synthetic/p01/r09.bvh", "--arm", "left", "--model", "sa", "--per",
        "clip", "--out-dir", str(tmp_path / "cli"), ok=(1,))
    with pytest.raises(kinergy.NothingToFitError):
        kinergy.fit("data-synthetic/p01/r09.bvh", arm="left", model="sa", per="clip",
                    out_dir=tmp_path / "py")


# ---- Issue 42: nothing lost in a library, through Python ----


def _takes(tmp_path, n=3, name="takes"):
    """A folder of `n` takes copied from the synthetic set's first person."""
    import shutil
    folder = tmp_path / name
    folder.mkdir(parents=True)
    for i in range(1, n + 1):
        shutil.copy(f"data-synthetic/p01/r{i:02}.bvh", folder / f"r{i:02}.bvh")
    return folder


def _fit(takes, out, **kw):
    return kinergy.fit(str(takes), model="sa", per="clip", budget=20, out_dir=out, **kw)


def test_results_are_named_by_the_take_s_whole_file_name(at_root, tmp_path):
    out = _fit(_takes(tmp_path, 2), tmp_path / "fits")
    assert sorted(r["result"] for r in out["rows"]) == ["r01.bvh.json", "r02.bvh.json"]
    assert all(len(r["settings"]) == 16 for r in out["rows"])


def test_shards_with_other_settings_are_refused(at_root, tmp_path):
    takes = _takes(tmp_path)
    _fit(takes, tmp_path / "fits", shard="1/2")
    with pytest.raises(kinergy.InputError, match=r"ran with other settings: seed 1 \(this run: 7\)"):
        _fit(takes, tmp_path / "fits", shard="2/2", seed=7)
    with pytest.raises(kinergy.InputError, match=r"controller smooth \(this run: paper\)"):
        _fit(takes, tmp_path / "fits", shard="2/2", controller="paper")
    assert not (tmp_path / "fits/shards/2-of-2.csv").exists()


def test_collect_names_takes_changed_between_shards(at_root, tmp_path):
    takes = _takes(tmp_path, 4)
    _fit(takes, tmp_path / "fits", shard="1/2")
    (takes / "r02.bvh").write_text((takes / "r02.bvh").read_text() + "\n")
    (takes / "r04.bvh").unlink()
    _fit(takes, tmp_path / "fits", shard="2/2")
    with pytest.raises(kinergy.InputError) as e:
        kinergy.collect(tmp_path / "fits")
    assert "r02.bvh grown (" in str(e.value) and "r04.bvh removed" in str(e.value)
    for i in (1, 2):
        _fit(takes, tmp_path / "fits", shard=f"{i}/2", resume=True)
    rows = kinergy.collect(tmp_path / "fits")
    assert sorted(r["clip"] for r in rows) == ["r01.bvh", "r02.bvh", "r03.bvh"]


def test_collect_refuses_a_result_that_is_not_the_one_recorded(at_root, tmp_path):
    out = tmp_path / "fits"
    takes = _takes(tmp_path)
    _fit(takes, out)
    whole = results(out)
    (out / "r02.bvh.json").write_bytes((out / "r03.bvh.json").read_bytes())
    with pytest.raises(kinergy.InputError, match="r02.bvh.json: not the result shard 1/1 recorded"):
        kinergy.collect(out)
    again = _fit(takes, out, resume=True)
    assert [r["seconds"] is None for r in again["rows"]] == [True, False, True]
    assert results(out) == whole


@pytest.mark.parametrize("stray", ["2-of-1.csv", "0-of-1.csv", "01-of-1.csv",
                                   "1-of-99999999999.csv", "1-of-1000000.csv"])
def test_collect_refuses_stray_and_absurd_records(at_root, tmp_path, stray):
    out = tmp_path / "fits"
    _fit(_takes(tmp_path, 1), out)
    (out / "shards" / stray).write_bytes((out / "shards/1-of-1.csv").read_bytes())
    with pytest.raises(kinergy.InputError, match="a stray record") as e:
        kinergy.collect(out)
    assert stray in str(e.value) and len(str(e.value)) < 1000


@pytest.mark.parametrize("case,said", [
    ("empty", "empty"),
    ("header", "line 1: the header line and no row"),
    ("bom", "line 1 starts with a byte-order mark"),
    ("column", "line 1: the columns are"),
])
def test_collect_refuses_records_that_cannot_be_true(at_root, tmp_path, case, said):
    out = tmp_path / "fits"
    _fit(_takes(tmp_path, 1), out)
    record = out / "shards/1-of-1.csv"
    text = record.read_bytes()
    spoilt = {
        "empty": b"",
        "header": text.split(b"\n")[0] + b"\n",
        "bom": b"\xef\xbb\xbf" + text,
        "column": text.replace(b",why\n", b",why,extra\n", 1),
    }[case]
    record.write_bytes(spoilt)
    with pytest.raises(kinergy.InputError, match=said) as e:
        kinergy.collect(out)
    assert "1-of-1.csv" in str(e.value)


def test_resume_finds_the_results_from_another_folder_and_spelling(at_root, tmp_path, monkeypatch):
    takes = _takes(tmp_path, 2, name="D/p01")
    out = tmp_path / "fits"
    first = _fit(takes, out)
    monkeypatch.chdir(tmp_path)
    for spelled in ["./D/p01", "D/../D/p01", str(takes.resolve())]:
        again = kinergy.fit(spelled, model="sa", per="clip", budget=20, out_dir="fits", resume=True)
        assert all(r["seconds"] is None for r in again["rows"]), spelled
        assert [r["result"] for r in again["rows"]] == [r["result"] for r in first["rows"]]


# ---- Issue 45: who, in the table ----


def test_a_library_s_person_rule_is_the_cli_s(cli, at_root, tmp_path):
    """`person=` is `--person`: the same table; `collect(person=)` names the persons anew;
    a rule that cannot name a take is the CLI's bad input."""
    takes = tmp_path / "styles"
    takes.mkdir()
    for person, take, name in [("p01", "r01", "active_001"), ("p01", "r02", "active_002"),
                               ("p02", "r01", "elderly_001")]:
        (takes / f"{name}.bvh").write_bytes((at_root / f"data-synthetic/{person}/{take}.bvh").read_bytes())
    run(cli, "fit", str(takes), "--model", "sa", "--per", "clip", "--budget", "20",
        "--person", "file", "--out-dir", str(tmp_path / "cli"))
    out = kinergy.fit(takes, model="sa", per="clip", budget=20, person="file",
                      out_dir=tmp_path / "py")
    assert [r["person"] for r in out["rows"]] == ["active", "active", "elderly"]
    assert table(tmp_path / "py/library.csv") == table(tmp_path / "cli/library.csv")
    rows = kinergy.collect(tmp_path / "py", person="folder")
    assert [r["person"] for r in rows] == ["styles"] * 3
    with pytest.raises(kinergy.InputError, match="elderly_001.bvh"):
        kinergy.collect(tmp_path / "py", person="regex:^(active)_")
    with pytest.raises(kinergy.InputError, match="not a person rule"):
        kinergy.fit(takes, per="clip", person="nobody", out_dir=tmp_path / "x")
    with pytest.raises(kinergy.InputError, match="person="):
        kinergy.fit(takes, person="file")
    assert not (tmp_path / "x").exists()
