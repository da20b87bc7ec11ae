#!/usr/bin/env bash
# Issue 44's cross-body measure: does a person's style survive retargeting? Per Bandai Namco
# style (a person), S_C fitted per person on takes 1-4 (seed 1), then `kinergy style` on the
# held-out takes 5-8 twice: on their own rig, and retargeted onto TEMPLATE's skeleton
# (`kinergy retarget`). Prints each person's real-time errors in multiples of the ceiling (the
# person's own repeats), as tools/fidelity-takes.sh does, for both bodies.
# Usage: tools/fidelity-retarget.sh OUT TEMPLATE.bvh [KINERGY]   (from the repository root)
#   e.g. tools/fidelity-retarget.sh /tmp/fid tests/data/006_14.bvh
# ARMS=source retargets with the performer's arm proportions (`retarget --arms source`).
set -euo pipefail
OUT="$1"; T="$2"; K="${3:-target/release/kinergy}"; mkdir -p "$OUT"
D="${SHARED:-../shared/data}/bandai-raise-left"
N="$(basename "$T" .bvh)"; ARMS="${ARMS:-template}"; [ "$ARMS" = template ] || N="$N-arms-$ARMS"
for s in active elderly normal; do
  [ -f "$OUT/$s.params" ] || "$K" fit "$D/${s}_00"{1,2,3,4}.bvh --arm left --model sc --per person --seed 1 -o "$OUT/$s.params" -q
  [ -d "$OUT/style-$s" ] || "$K" style "$D/${s}_00"{5,6,7,8}.bvh --arm left --params "$OUT/$s.params" -o "$OUT/style-$s" -q
  mkdir -p "$OUT/$N-$s"
  for t in 5 6 7 8; do "$K" retarget "$D/${s}_00$t.bvh" --to "$T" -o "$OUT/$N-$s/${s}_00$t.bvh" --arms "$ARMS" -q; done
  "$K" style "$OUT/$N-$s/${s}_00"{5,6,7,8}.bvh --arm left --params "$OUT/$s.params" -o "$OUT/style-$N-$s" -q 2>/dev/null
done
python3 - "$OUT" "$N" <<'PY'
import csv, sys, statistics as st
out, n = sys.argv[1], sys.argv[2]
print("| person | body | ceiling e | minimum jerk ×ceil | arm ×ceil | body ×ceil | arm duration ÷ capture |")
print("|---|---|---|---|---|---|---|")
for s in ["active", "elderly", "normal"]:
    for body, d in [("Bandai (own)", f"{out}/style-{s}"), (f"{n} (retargeted)", f"{out}/style-{n}-{s}")]:
        rows = list(csv.DictReader(open(f"{d}/style.csv")))
        m = lambda k: st.mean(float(r[k]) for r in rows)
        c = m("e_ceiling")
        print(f"| {s} | {body} | {c:.3f} | {m('e_minimum_jerk')/c:.2f} | {m('e_arm')/c:.2f} | {m('e_body')/c:.2f} | {m('duration_ratio_arm'):.2f} |")
PY
