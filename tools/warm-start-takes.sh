#!/usr/bin/env bash
# Warm starts judged in real time on the shared people: their 72 raises (takes 1-24 of each
# style) fitted as a library twice, nested and `--warm-start`, S_D per clip, seed 1; then take
# TAKE (default 5) of each style replayed on its captured torso with both results and its hand
# speed plotted beside the capture's: OUT/warm-PERSON.png, and the two libraries' mean S_D
# distance, evaluations and wall time (OUT/summary.txt).
# Usage: tools/warm-start-takes.sh OUT [KINERGY]   (from the repository root)
set -euo pipefail
OUT="$1"; K="${2:-target/release/kinergy}"; mkdir -p "$OUT"
D="${SHARED:-../shared/data}"
TAKE="$(printf "%03d" "${TAKE:-5}")"
: > "$OUT/wall.txt"
for how in nested warm; do
  flags=(); [ "$how" = warm ] && flags=(--warm-start)
  rm -rf "${OUT:?}/$how"
  start=$(date +%s.%N)
  "$K" fit "$D/bandai-raise-left" "$D/bandai-raise-left-more" --arm left --per clip --model sd \
    --person file "${flags[@]}" --out-dir "$OUT/$how" -q
  echo "$how $(python3 -c "import sys; print(round(float(sys.argv[2]) - float(sys.argv[1]), 2))" "$start" "$(date +%s.%N)") s" >> "$OUT/wall.txt"
done
for s in active elderly normal; do
  clip="$D/bandai-raise-left/${s}_$TAKE.bvh"
  for how in nested warm; do
    "$K" synthesize --from "$clip" --params "$OUT/$how/bandai-raise-left/${s}_$TAKE.bvh.json" \
      --arm left --frames auto -o "$OUT/$s-$how.bvh" -q
  done
  frames=$("$K" synthesize --from "$clip" --params "$OUT/nested/bandai-raise-left/${s}_$TAKE.bvh.json" \
    --arm left --frames auto -o "$OUT/x.bvh" --json \
    | python3 -c "import json, sys; a, b = json.load(sys.stdin)['capture_frames']; print(f'{a}..{b}')")
  "$K" convert "$clip" --frames "$frames" -o "$OUT/$s-captured.bvh" -q
  "$K" plot speed "$OUT/$s-captured.bvh" "$OUT/$s-nested.bvh" "$OUT/$s-warm.bvh" --arm left \
    --title "$s, take ${TAKE#00}: captured, S_D nested, S_D warm-started" -o "$OUT/warm-$s.png" -q
done
python3 - "$OUT" <<'PY' | tee "$OUT/summary.txt"
import glob, json, statistics as st, sys
out = sys.argv[1]
wall = dict(line.split()[:2] for line in open(f"{out}/wall.txt"))
for how in ["nested", "warm"]:
    fits = [json.load(open(f))["fit"] for f in glob.glob(f"{out}/{how}/**/*.bvh.json", recursive=True)]
    evals = sum(s["evaluations"] for f in fits for s in f["nested"])
    print(f"{how}: {len(fits)} reaches, mean S_D {1000 * st.mean(f['score_m'] for f in fits):.2f} mm, "
          f"{evals} evaluations, {wall[how]} s")
PY
