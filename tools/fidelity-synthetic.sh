#!/usr/bin/env bash
# Issue 40's synthetic-set bar: the body made data-synthetic/, so the full body driven by each
# clip's own per-clip fit (MODEL, default sc, seed SEED, default 1) toward that clip's target
# (`kinergy style CLIP --params CLIP.json`) should give back the clip's hand-speed profile in
# real time. Writes OUT/fits (the library), OUT/style/CLIP.json (each style --json) and prints
# the distribution of e, the duration and peak ratios and the real-time jumps over the clips.
# Usage: tools/fidelity-synthetic.sh OUT [KINERGY]   (from the repository root)
set -euo pipefail
OUT="$1"; K="${2:-target/release/kinergy}"; mkdir -p "$OUT/style"
[ -f "$OUT/fits/library.csv" ] || "$K" fit data-synthetic --per clip --model "${MODEL:-sc}" --seed "${SEED:-1}" --out-dir "$OUT/fits" -q
for clip in data-synthetic/p*/r*.bvh; do
  rel="${clip#data-synthetic/}"; name="${rel%.bvh}"; mkdir -p "$OUT/style/$(dirname "$name")"
  [ -f "$OUT/style/$name.json" ] || "$K" style "$clip" --params "$OUT/fits/$name.json" --json > "$OUT/style/$name.json"
done
python3 - "$OUT" <<'PY'
import json, sys, glob, statistics as st
out = sys.argv[1]
rows = []
for f in sorted(glob.glob(f"{out}/style/p*/r*.json")):
    d = json.load(open(f))
    t = d["fidelity"]["takes"][0]
    body = next(p["fidelity"] for p in t["predicted"] if p["predictor"] == "body")
    arm = next((p["fidelity"] for p in t["predicted"] if p["predictor"] == "arm"), None)
    rows.append((f[len(out) + 7:-5], body, arm))
def q(v):
    v = sorted(v); n = len(v)
    return f"median {st.median(v):.3f}, p90 {v[int(0.9 * (n - 1))]:.3f}, max {v[-1]:.3f}"
for who in ["body", "arm"]:
    sel = [(n, b if who == "body" else a) for n, b, a in rows if (b if who == "body" else a)]
    e = [f["error"] for _, f in sel]
    d = [f["duration_ratio"] for _, f in sel]
    p = [f["peak_ratio"] for _, f in sel]
    j = [n for n, f in sel if f["jumps"]]
    off = [n for n, f in sel if abs(f["duration_ratio"] - 1) > 0.1]
    print(f"{who}: {len(sel)} clips; e {q(e)}; duration ratio {min(d):.2f}–{max(d):.2f} ({len(off)} beyond 10 %: {' '.join(off)}); peak ratio {min(p):.2f}–{max(p):.2f}; real-time jumps {len(j)}: {' '.join(j)}")
PY
