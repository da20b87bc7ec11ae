#!/usr/bin/env bash
# Issue 26 #3: does the hand-speed term of `--objective positions+speed` help on held-out takes?
# For seeds 1-3 and speed weights 0 (the paper's `positions`), 0.02, 0.05, 0.1, 0.2 s, on the
# shared people (../shared/data/bandai-raise-left): `compare --per person --holdout 1|2` (the
# held-out takes' joint-position distances, scored without the speed term) and
# tools/style-takes.sh with MODEL=sd (fits on takes 1-4, the held-out takes 5-8 replayed:
# hand-speed correlation, jumps, first-frame speed); then tools/objective_sweep.py OUT prints
# the table the README quotes.
# Usage: tools/objective-sweep.sh OUT_DIR   (from the repository root; ~5 min on 2 cores)
set -euo pipefail
OUT="$1"; mkdir -p "$OUT"
B="${SHARED:-../shared/data}/bandai-raise-left"
cargo build --release -q -p kinergy-cli
K=target/release/kinergy
for seed in 1 2 3; do
  for w in 0 0.02 0.05 0.1 0.2; do
    if [ "$w" = 0 ]; then F="--objective positions"; else F="--objective positions+speed --speed-weight $w"; fi
    tag="s$seed-w$w"
    for h in 1 2; do
      # shellcheck disable=SC2086
      "$K" -q compare "$B" --arm left --person prefix --per person --holdout "$h" --seed "$seed" $F -o "$OUT/hc-$tag-h$h"
    done
    rm -rf "$OUT/st-$tag"
    MODEL=sd FIT_FLAGS="$F --seed $seed" "$(dirname "$0")/style-takes.sh" "$OUT/st-$tag" > "$OUT/st-$tag.log" 2>&1 || true
  done
done
python3 "$(dirname "$0")/objective_sweep.py" "$OUT"
