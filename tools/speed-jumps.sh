#!/usr/bin/env bash
# Speed jumps of synthesized reaches against their captures (issue 23's measure), on the
# synthetic set: every reach fitted per clip (MODEL, default sd), replayed with its own
# parameters over its own frames (`synthesize --frames fit`), both hand speeds relative to the
# shoulder (`plot speed --relative --csv`), then counted by tools/speed_jumps.py.
# Usage: tools/speed-jumps.sh OUT_DIR   (from the repository root; builds the CLI first)
set -euo pipefail
OUT="$1"; mkdir -p "$OUT"
cargo build --release -q -p kinergy-cli
K=target/release/kinergy
[ -d "$OUT/fits" ] || "$K" fit data-synthetic --model "${MODEL:-sd}" --per clip --out-dir "$OUT/fits" -q
for f in "$OUT"/fits/*/*.json; do
  b="$(basename "$(dirname "$f")")_$(basename "$f" .json)"
  read -r clip a z < <(python3 -c "import json,sys; r=json.load(open(sys.argv[1]))['fit']['reaches'][0]; print(r['clip'], *r['frames'])" "$f")
  "$K" synthesize "$clip" --params "$f" -o "$OUT/$b.syn.bvh" --json > "$OUT/$b.json" 2>/dev/null || true
  "$K" convert "$clip" --frames "$a..$z" -o "$OUT/$b.cap.bvh" -q
  "$K" plot speed "$OUT/$b.cap.bvh" "$OUT/$b.syn.bvh" --relative -o "$OUT/$b.svg" --csv "$OUT/$b.csv" -q
done
python3 "$(dirname "$0")/speed_jumps.py" "$OUT"
