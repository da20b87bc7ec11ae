"""Shared fixtures: the repository root, the CLI to compare with, a scratch folder."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
SHARED = ROOT.parent / "shared" / "data"


def _cli() -> Path:
    given = os.environ.get("KINERGY")
    if given:
        return Path(given)
    target = Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    if not target.is_absolute():
        target = ROOT / target
    path = target / "release" / "kinergy"
    if not path.exists():
        # The release profile `cargo test --release` builds: in CI this is already done.
        subprocess.run(["cargo", "build", "--release", "-p", "kinergy-cli"], cwd=ROOT, check=True)
    return path


@pytest.fixture(scope="session")
def cli() -> Path:
    """The `kinergy` command of this checkout."""
    return _cli()


@pytest.fixture
def at_root(monkeypatch):
    """Runs the test in the repository root, where the CLI's relative paths start."""
    monkeypatch.chdir(ROOT)
    return ROOT


def run(cli: Path, *args: str, ok=(0,), quiet=True) -> subprocess.CompletedProcess:
    """Runs the CLI in the repository root (with `-q` unless its report is wanted); its exit
    code must be one of `ok`."""
    flags = ["-q"] if quiet else []
    done = subprocess.run([str(cli), *flags, *args], cwd=ROOT, capture_output=True, text=True)
    assert done.returncode in ok, f"kinergy {' '.join(args)}: exit {done.returncode}\n{done.stderr}"
    return done


def shared(*parts: str) -> Path:
    """A file of ../shared/data, or a skip saying it is absent (a failure where
    KINERGY_REQUIRE_SHARED=1, as in CI)."""
    path = SHARED.joinpath(*parts)
    if not path.exists():
        if os.environ.get("KINERGY_REQUIRE_SHARED") == "1":
            pytest.fail(f"{path} is absent and KINERGY_REQUIRE_SHARED=1")
        pytest.skip(f"{path} is absent (the shared captures are not committed)")
    return path
