#!/usr/bin/env bash
# Speed jumps of a synthetic set itself (issue 23's measure on what `kinergy synth` makes):
# every clip's hand speed relative to the shoulder (`plot speed --relative --arm right --csv`),
# a jump a frame-to-frame change > 0.25 m/s and > 4x the clip's median change. Prints the
# clips that have any and the count.
# Usage: tools/set-jumps.sh SET_DIR   (from the repository root; uses target/release/kinergy)
set -euo pipefail
SET="$1"; K=target/release/kinergy
TMP="$(mktemp -d)"; trap 'rm -rf "$TMP"' EXIT
for person in "$SET"/*/; do
  p="$(basename "$person")"
  files=("$person"*.bvh)
  for ((i = 0; i < ${#files[@]}; i += 12)); do
    "$K" plot speed "${files[@]:i:12}" --relative --arm right -o "$TMP/$p.$i.svg" --csv "$TMP/$p.$i.csv" -q
  done
done
python3 - "$TMP" <<'PY'
import csv, glob, os, statistics, sys
bad = n = 0
for f in sorted(glob.glob(sys.argv[1] + '/*.csv')):
    clips = {}
    for r in csv.DictReader(open(f)):
        clips.setdefault(r['clip'], []).append(float(r['speed_m_s']))
    for name, v in clips.items():
        d = [abs(b - a) for a, b in zip(v, v[1:])]
        t = max(0.25, 4 * statistics.median(d)) if d else 0
        j = [i for i, x in enumerate(d) if x > t]
        n += 1
        if j:
            bad += 1
            print(f'{os.path.basename(f).split(".")[0]}/{name}: {len(j)} jumps at frames {j[:6]}')
print(f'{n} clips, {bad} with speed jumps')
PY
