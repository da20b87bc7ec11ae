#!/usr/bin/env bash
# How much the full-body style of the shared people (../shared/data/bandai-raise-left) depends
# on the fit's seed and stopping rule: for seeds 1..SEEDS (default 6), the default stopping
# rule and the coarse one (--stable-change 0.001 --stable-window 15), S_C fitted per person on
# takes 1-4 with `style` on takes 5-8 (the setting of the test
# smooth_cli::held_out_full_body_reaches_keep_each_persons_style) and S_D on takes 1-6 with
# `style` on 7-8; then tools/style_seeds.py OUT prints every run and, per rule, model and
# person, the mean and least hand-speed correlation, the hand-overs and the mean peak error.
# Usage: tools/style-seeds.sh OUT_DIR   (from the repository root; ~2 min on 2 cores)
# KINERGY=path/to/kinergy runs another build; MODELS="sc sd se" adds S_E (fitted on takes
# 1-6, `style` on 7-8, as S_D); SEEDS=N runs seeds 1..N.
set -euo pipefail
OUT="$1"; mkdir -p "$OUT"
B="${SHARED:-../shared/data}/bandai-raise-left"
if [ -z "${KINERGY:-}" ]; then
  cargo build --release -q -p kinergy-cli
  KINERGY=target/release/kinergy
fi
for seed in $(seq 1 "${SEEDS:-6}"); do
  for rule in default coarse; do
    flags=(--seed "$seed")
    [ "$rule" = coarse ] && flags+=(--stable-change 0.001 --stable-window 15)
    for model in ${MODELS:-sc sd}; do
      if [ "$model" = sc ]; then fit=(1 2 3 4); held=(5 6 7 8); else fit=(1 2 3 4 5 6); held=(7 8); fi
      run="$OUT/$rule-$model-s$seed"; mkdir -p "$run"
      for person in active elderly normal; do
        takes() { for t in "$@"; do echo "$B/${person}_00$t.bvh"; done; }
        mapfile -t fitted < <(takes "${fit[@]}")
        mapfile -t tried < <(takes "${held[@]}")
        "$KINERGY" fit "${fitted[@]}" --arm left --model "$model" --per person -q \
          "${flags[@]}" -o "$run/$person.json"
        "$KINERGY" style "${tried[@]}" --arm left --params "$run/$person.json" \
          -o "$run/style-$person" --json > "$run/$person.style.json"
      done
    done
  done
done
python3 "$(dirname "$0")/style_seeds.py" "$OUT" "$KINERGY"
