"""The Python package's cost against the CLI's (issue 25's targets), recorded in BENCHMARKS.md.

    target/notebook-venv/bin/python python/bench.py        # after python/test.sh built both

1. Reading a 10 MB BVH into numpy (`read_bvh(...).positions`) against `kinergy inspect` of the
   same file (the CLI reading it and reporting), both wall time, median of 7.
2. `kinergy.fit` against `kinergy fit` on the same clips and seed (wall time, median of 5).
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import kinergy

ROOT = Path(__file__).resolve().parents[1]
CLI = Path(os.environ.get("KINERGY", ROOT / "target/release/kinergy"))


def big_bvh(path: Path, megabytes: float = 10.0) -> Path:
    """The committed CMU walk with its motion repeated until the file holds `megabytes`."""
    text = (ROOT / "tests/data/cmu_12_01_walk.bvh").read_text()
    head, motion = text.split("MOTION", 1)
    lines = motion.strip().splitlines()
    frames = [l for l in lines[2:] if l.strip()]
    size = sum(len(l) + 1 for l in frames)
    repeats = max(1, int(megabytes * 2**20 / size) + 1)
    body = "\n".join(frames * repeats)
    path.write_text(f"{head}MOTION\nFrames: {len(frames) * repeats}\n{lines[1]}\n{body}\n")
    return path


def median_time(call, repeats: int) -> float:
    times = []
    for _ in range(repeats):
        t = time.perf_counter()
        call()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        big = big_bvh(Path(tmp) / "big.bvh")
        mb = big.stat().st_size / 2**20
        clip = kinergy.read_bvh(big)
        py = median_time(lambda: kinergy.read_bvh(big).positions, 7)
        cli = median_time(lambda: subprocess.run([CLI, "-q", "inspect", big], check=True), 7)
        print(f"read {mb:.1f} MiB ({len(clip)} frames, {len(clip.joint_names)} joints) into numpy: "
              f"{py * 1e3:.0f} ms; kinergy inspect: {cli * 1e3:.0f} ms; ratio {py / cli:.2f}")

        clips = [str(ROOT / "data-synthetic/p01")]
        args = ["--model", "sd", "--budget", "1000", "--seed", "1", "--threads", "2"]
        out = Path(tmp) / "p.json"
        py = median_time(lambda: kinergy.fit(clips, model="sd", budget=1000, seed=1, threads=2), 5)
        cli = median_time(
            lambda: subprocess.run([CLI, "-q", "fit", *clips, *args, "-o", out], check=True), 5)
        print(f"fit data-synthetic/p01 (14 reaches, S_A → S_D, 1000 evaluations each, 2 threads): "
              f"Python {py:.2f} s, CLI {cli:.2f} s, ratio {py / cli:.3f}")


if __name__ == "__main__":
    sys.exit(main())
