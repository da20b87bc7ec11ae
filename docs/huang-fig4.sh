#!/usr/bin/env bash
# Huang, Kapadia & Terzopoulos' Fig. 4 as film strips: each situation of
# examples/huang-fig4/gallery.csv reached by `kinergy reach` and drawn by `kinergy animate`
# with its object at the target, into docs/huang-fig4-<panel>.png (or $OUT/). Called by
# docs/make-pictures.sh; `KINERGY` is the binary, `WORK` a scratch folder.
set -euo pipefail
REPO="$(cd "$(dirname "$0")/.." && pwd)"
cd "$REPO"
K="${KINERGY:-$REPO/target/release/kinergy}"
WORK="${WORK:-$(mktemp -d)}"
# Where the strips go (docs/, or make-pictures --check's scratch copy).
OUT="${OUT:-docs}"
python3 - "$WORK" examples/huang-fig4/gallery.csv <<'PY' | while IFS='|' read -r panel name target flexibility seed p_max p_min view scene; do
import csv, json, os, sys
work, table = sys.argv[1], sys.argv[2]
shapes = {
    "apple": lambda r: {"type": "sphere", "radius": r},
    "basketball": lambda r: {"type": "sphere", "radius": r},
    "glass": lambda r: {"type": "capsule", "half_height": 1.5 * r, "radius": r},
    "box": lambda r: {"type": "box", "half_extents": [r, r, r]},
}
for row in csv.DictReader(open(table)):
    r = float(row["radius_m"])
    t = [float(row[k]) for k in ("target_x", "target_y", "target_z")]
    scene = {
        "format_version": 1,
        "character": {"height": 1.75},
        "objects": [
            {"name": "floor", "shape": {"type": "box", "half_extents": [1.5, 0.01, 1.5]},
             "position": [0, -0.01, 0]},
            {"name": row["object"], "shape": shapes[row["object"]](r), "position": t},
        ],
    }
    path = os.path.join(work, "fig4-%s.json" % row["panel"])
    json.dump(scene, open(path, "w"))
    name = "%s) %s" % (row["panel"], row["caption"])
    print("|".join([row["panel"], name.replace(" ", "_"), ",".join(row[k] for k in ("target_x", "target_y", "target_z")),
                    row["flexibility"], row["seed"], row["p_max"], row["p_min"], row["view"], path]))
PY
    "$K" reach --target "$target" --flexibility "$flexibility" --seed "$seed" \
        --p-max "$p_max" --p-min "$p_min" --timeout 30 -o "$WORK/$name.bvh" > /dev/null
    "$K" animate "$WORK/$name.bvh" --scene "$scene" --view "$view" --fps 10 \
        --size 200x280 -o "$WORK/fig4-$panel.gif" --strip "$OUT/huang-fig4-$panel.png" \
        --strip-frames 5 > /dev/null
done
