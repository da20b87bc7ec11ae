#!/usr/bin/env bash
# Issue 23's measure on the shared people (../shared/data/bandai-raise-left, 3 styles x 8
# takes): per style, MODEL (default sc) fitted per person on takes 1-4, then every held-out
# take 5-8 synthesized with the person's parameters over its main reach on the captured torso
# (`synthesize --frames auto`), both hand speeds relative to the shoulder, counted by
# tools/speed_jumps.py (jumps, stops, first-frame speed, correlation).
# Usage: tools/style-takes.sh OUT_DIR   (from the repository root; builds the CLI first)
# FIT_FLAGS adds options to the fits (e.g. FIT_FLAGS="--objective positions+speed").
set -euo pipefail
OUT="$1"; mkdir -p "$OUT"
B="${SHARED:-../shared/data}/bandai-raise-left"
cargo build --release -q -p kinergy-cli
K=target/release/kinergy
for s in active elderly normal; do
  [ -f "$OUT/$s.params" ] || "$K" fit "$B/${s}_00"{1,2,3,4}.bvh --arm left --model "${MODEL:-sc}" --per person ${FIT_FLAGS:-} -o "$OUT/$s.params" -q
  for t in 5 6 7 8; do
    b="${s}_00$t"; clip="$B/$b.bvh"
    "$K" synthesize "$clip" --params "$OUT/$s.params" --frames auto -o "$OUT/$b.syn.bvh" --json > "$OUT/$b.json" 2>/dev/null || true
    read -r a z < <(python3 -c "import json,sys; print(*json.load(open(sys.argv[1]))['capture_frames'])" "$OUT/$b.json")
    "$K" convert "$clip" --frames "$a..$((z + 1))" -o "$OUT/$b.cap.bvh" -q
    "$K" plot speed "$OUT/$b.cap.bvh" "$OUT/$b.syn.bvh" --relative --arm left -o "$OUT/$b.svg" --csv "$OUT/$b.csv" -q
  done
done
python3 "$(dirname "$0")/speed_jumps.py" "$OUT"
