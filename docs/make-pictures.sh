#!/usr/bin/env bash
# Regenerates the README's pictures in docs/ from the committed data (a few minutes).
# Usage: docs/make-pictures.sh   (from anywhere; builds the CLI in release first)
set -euo pipefail
REPO="$(cd "$(dirname "$0")/.." && pwd)"
cd "$REPO"
cargo build --release -q -p kinergy-cli
K="$REPO/target/release/kinergy"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
CLIP=data-synthetic/p01/r09.bvh

# A capture, its fitted S_A and S_C parameters, and their syntheses of the same reach.
"$K" fit "$CLIP" --model sa --optimizer svd --per clip -o "$WORK/sa.json" > /dev/null
"$K" fit "$CLIP" --model sc --optimizer svd --per clip -o "$WORK/sc.json" > /dev/null
"$K" synthesize --from "$CLIP" --params "$WORK/sa.json" --frames auto --stop-at-reach -o "$WORK/S_A.bvh" > /dev/null
"$K" synthesize --from "$CLIP" --params "$WORK/sc.json" --frames auto --stop-at-reach -o "$WORK/S_C.bvh" > /dev/null
# The captured reach cut to the same frames (`synthesize --frames auto` = the main segment).
FRAMES=$("$K" synthesize --from "$CLIP" --params "$WORK/sc.json" --frames auto -o "$WORK/x.bvh" --json \
    | python3 -c "import json, sys; a, b = json.load(sys.stdin)['capture_frames']; print(f'{a}..{b}')")
"$K" convert "$CLIP" --frames "$FRAMES" -o "$WORK/captured.bvh"

"$K" plot speed "$WORK/captured.bvh" "$WORK/S_A.bvh" "$WORK/S_C.bvh" \
    --title "Hand speed: captured vs S_A vs S_C ($CLIP)" -o docs/speed.svg > /dev/null
"$K" plot speed "$WORK/captured.bvh" "$WORK/S_A.bvh" "$WORK/S_C.bvh" \
    --title "Hand speed: captured vs S_A vs S_C ($CLIP)" -o docs/speed.png > /dev/null
"$K" animate "$WORK/captured.bvh" "$WORK/S_A.bvh" "$WORK/S_C.bvh" --view side --fps 15 \
    --size 480x360 -o docs/overlay.gif --strip docs/overlay-strip.png --strip-frames 6 > /dev/null

# The paper's Fig. 3 (with S_E, beyond the paper) and Fig. 4 on the synthetic set.
"$K" compare --models sa,sb,sc,sd,se -o "$WORK/compare" > /dev/null
cp "$WORK/compare/fig3.png" "$WORK/compare/fig4.png" "$WORK/compare/summary.md" docs/

# The bookshelf relocation (Kallmann's Fig. 5), and its planner's search trees (his Fig. 4).
# Its JSON report holds the book's pose on every frame: animate draws the shelf and the book
# moving with the hand.
"$K" plan --scene examples/bookshelf/scene.json --task relocate --object blue_book \
    --to -0.22,1.49,0.50 -o "$WORK/relocate.bvh" --json \
    --tree-svg docs/plan-trees.svg --tree-view front > "$WORK/relocate.json"
"$K" animate "$WORK/relocate.bvh" --scene examples/bookshelf/scene.json \
    --report "$WORK/relocate.json" --view side --fps 10 --size 360x360 \
    -o docs/relocate.gif --strip docs/relocate-strip.png --strip-frames 6 > /dev/null
ls -la docs
