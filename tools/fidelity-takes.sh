#!/usr/bin/env bash
# Issue 40's real-time measure on the shared people: per style, MODEL (default sc) fitted per
# person on takes FIT (default 1-4) with seed SEED (default 1), then `kinergy style` on takes
# TEST (default 5-8), which replays each held-out take on its captured torso and on the full
# body and judges every motion in real time against the person's own repeats (leave-one-out
# over the held-out takes) and minimum jerk: OUT/style-PERSON/{summary.md,style.csv,realtime.png}.
# Usage: tools/fidelity-takes.sh OUT [KINERGY]   (from the repository root)
#   FIT="1 2 3 4" TEST="5 6 7 8" SEED=1 MODEL=sc; MORE=1 fits takes 1-12 and tests 13-24
#   (../shared/data/bandai-raise-left-more holds takes 9-24).
set -euo pipefail
OUT="$1"; K="${2:-target/release/kinergy}"; mkdir -p "$OUT"
D="${SHARED:-../shared/data}"
take() { local n; n=$(printf "%03d" "$2"); if [ "$2" -le 8 ]; then echo "$D/bandai-raise-left/$1_$n.bvh"; else echo "$D/bandai-raise-left-more/$1_$n.bvh"; fi; }
if [ "${MORE:-0}" = 1 ]; then FIT="${FIT:-$(seq -s ' ' 1 12)}"; TEST="${TEST:-$(seq -s ' ' 13 24)}"; fi
FIT="${FIT:-1 2 3 4}"; TEST="${TEST:-5 6 7 8}"
for s in active elderly normal; do
  fit=(); for t in $FIT; do fit+=("$(take $s $t)"); done
  test=(); for t in $TEST; do test+=("$(take $s $t)"); done
  [ -f "$OUT/$s.params" ] || "$K" fit "${fit[@]}" --arm left --model "${MODEL:-sc}" --per person --seed "${SEED:-1}" ${FIT_FLAGS:-} -o "$OUT/$s.params" -q
  "$K" style "${test[@]}" --arm left --params "$OUT/$s.params" -o "$OUT/style-$s" -q
done
python3 - "$OUT" <<'PY'
import csv, sys, statistics as st
out = sys.argv[1]
print("| person | ceiling e | minimum jerk ×ceil | arm ×ceil | body ×ceil | body duration ÷ capture | body peak ÷ capture | arm jumps | body jumps |")
print("|---|---|---|---|---|---|---|---|---|")
for s in ["active", "elderly", "normal"]:
    rows = list(csv.DictReader(open(f"{out}/style-{s}/style.csv")))
    m = lambda k: st.mean(float(r[k]) for r in rows)
    c = m("e_ceiling")
    j = lambda k: sum(r[k] == "true" for r in rows)
    print(f"| {s} | {c:.3f} | {m('e_minimum_jerk')/c:.2f} | {m('e_arm')/c:.2f} | {m('e_body')/c:.2f} | {m('duration_ratio_body'):.2f} | {m('peak_ratio_body'):.2f} | {j('jump_arm')} | {j('jump_body')} |")
PY
