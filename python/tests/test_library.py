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
    return {p.relative_to(folder): p.read_bytes() for p in sorted(folder.rglob("*.json"))}


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
    with pytest.raises(kinergy.InputError):
        kinergy.collect(tmp_path / "not-a-library")
    assert not (tmp_path / "x").exists()


def test_a_library_of_takes_with_nothing_to_fit_is_the_cli_s_exit_1(cli, at_root, tmp_path):
    run(cli, "fit", "data-synthetic/p01/r09.bvh", "--arm", "left", "--model", "sa", "--per",
        "clip", "--out-dir", str(tmp_path / "cli"), ok=(1,))
    with pytest.raises(kinergy.NothingToFitError):
        kinergy.fit("data-synthetic/p01/r09.bvh", arm="left", model="sa", per="clip",
                    out_dir=tmp_path / "py")
