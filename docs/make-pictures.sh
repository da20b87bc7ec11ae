#!/usr/bin/env bash
# Regenerates the README's pictures in docs/ from the committed data (a few minutes), and the
# README's tables (docs/make-tables.sh).
# Usage: docs/make-pictures.sh [--check]   (from anywhere; builds the CLI in release first)
#   --check   draw everything into a scratch folder and compare it with docs/ byte for byte
#             (summary*.md but for their wall-clock line), and the README's tables
#             (make-tables --check); exit 1 naming every file that differs. docs/ is untouched.
set -euo pipefail
REPO="$(cd "$(dirname "$0")/.." && pwd)"
cd "$REPO"
check=0
case "${1:-}" in
    --check) check=1 ;;
    "") ;;
    *) echo "make-pictures: unknown argument '$1' (usage: docs/make-pictures.sh [--check])" >&2; exit 2 ;;
esac
cargo build --release -q -p kinergy-cli
K="$REPO/target/release/kinergy"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
# Where the pictures go: docs/, or a scratch copy to compare with it.
OUT=docs
if [ "$check" = 1 ]; then
    OUT="$WORK/docs"
    mkdir -p "$OUT"
fi
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
    --title "Hand speed: captured vs S_A vs S_C ($CLIP)" -o "$OUT/speed.svg" > /dev/null
"$K" plot speed "$WORK/captured.bvh" "$WORK/S_A.bvh" "$WORK/S_C.bvh" \
    --title "Hand speed: captured vs S_A vs S_C ($CLIP)" -o "$OUT/speed.png" > /dev/null
"$K" animate "$WORK/captured.bvh" "$WORK/S_A.bvh" "$WORK/S_C.bvh" --view side --fps 15 \
    --size 480x360 -o "$OUT/overlay.gif" --strip "$OUT/overlay-strip.png" --strip-frames 6 > /dev/null

# Retargeting: the committed CMU walk onto the committed Character Creator rig, overlaid.
cp tests/data/cmu_12_01_walk.bvh "$WORK/cmu_walk.bvh"
"$K" retarget "$WORK/cmu_walk.bvh" --to tests/data/006_14.bvh -o "$WORK/on_character_creator.bvh" > /dev/null
"$K" animate "$WORK/cmu_walk.bvh" "$WORK/on_character_creator.bvh" --view side --fps 15 \
    --size 480x360 -o "$WORK/retarget.gif" --strip "$OUT/retarget-strip.png" --strip-frames 6 > /dev/null

# The paper's Fig. 5: the hand speed of four captured reaches (four targets) against S_A's and
# S_C's, each fitted to its reach, under the default smooth controller and the paper's.
for controller in smooth paper; do
    i=0
    for clip in p01/r09 p02/r02 p03/r06 p04/r13; do
        i=$((i + 1))
        C="data-synthetic/$clip.bvh"
        D="$WORK/fig5-$controller-$i"
        mkdir -p "$D"
        for model in sa sc; do
            "$K" fit "$C" --model "$model" --optimizer svd --per clip --controller "$controller" \
                -o "$D/$model.json" > /dev/null
            # sa -> S_A.bvh: plot speed names each clip by its file.
            "$K" synthesize --from "$C" --params "$D/$model.json" --frames auto --stop-at-reach \
                -o "$D/S_$(printf %s "${model:1:1}" | tr a-z A-Z).bvh" > /dev/null
        done
        F=$("$K" synthesize --from "$C" --params "$D/sc.json" --frames auto -o "$D/x.bvh" --json \
            | python3 -c "import json, sys; a, b = json.load(sys.stdin)['capture_frames']; print(f'{a}..{b}')")
        "$K" convert "$C" --frames "$F" -o "$D/captured.bvh"
        "$K" plot speed "$D/captured.bvh" "$D/S_A.bvh" "$D/S_C.bvh" --size 450x300 \
            --title "$clip, $controller controller" -o "$OUT/fig5-$controller-$i.png" > /dev/null
    done
done

# The paper's Fig. 3 (with S_E, beyond the paper) and Fig. 4 on the synthetic set, under both
# controllers (docs/make-tables.sh puts their tables in the README).
"$K" compare --models sa,sb,sc,sd,se -o "$WORK/compare" > /dev/null
cp "$WORK/compare/fig3.png" "$WORK/compare/fig4.png" "$WORK/compare/summary.md" "$OUT/"
"$K" compare --models sa,sb,sc,sd,se --controller paper -o "$WORK/compare-paper" > /dev/null
cp "$WORK/compare-paper/fig3.png" "$OUT/fig3-paper.png"
cp "$WORK/compare-paper/fig4.png" "$OUT/fig4-paper.png"
cp "$WORK/compare-paper/summary.md" "$OUT/summary-paper.md"
tables_differ=0
if [ "$check" = 1 ]; then
    KINERGY="$K" docs/make-tables.sh --check --from "$WORK/compare" \
        --from-paper "$WORK/compare-paper" || tables_differ=1
else
    KINERGY="$K" docs/make-tables.sh --from "$WORK/compare" --from-paper "$WORK/compare-paper"
fi

# Huang, Kapadia & Terzopoulos' Fig. 4: the gallery of situations a–h.
KINERGY="$K" WORK="$WORK" OUT="$OUT" docs/huang-fig4.sh

# The bookshelf relocation (Kallmann's Fig. 5), and its planner's search trees (his Fig. 4).
# Its JSON report holds the book's pose on every frame: animate draws the shelf and the book
# moving with the hand.
"$K" plan --scene examples/bookshelf/scene.json --task relocate --object blue_book \
    --to -0.22,1.49,0.50 -o "$WORK/relocate.bvh" --json \
    --tree-svg "$OUT/plan-trees.svg" --tree-view front > "$WORK/relocate.json"
"$K" animate "$WORK/relocate.bvh" --scene examples/bookshelf/scene.json \
    --report "$WORK/relocate.json" --view side --fps 10 --size 360x360 \
    -o "$OUT/relocate.gif" --strip "$OUT/relocate-strip.png" --strip-frames 6 > /dev/null
if [ "$check" = 0 ]; then
    ls -la docs
    exit 0
fi
# The wall-clock line of a compare's summary is the one thing a rerun changes.
strip_wall() { sed -E 's/; [0-9.]+ s wall\./; … s wall./' "$1"; }
differ=$tables_differ
for made in "$OUT"/*; do
    name="$(basename "$made")"
    if [ ! -e "docs/$name" ]; then
        echo "make-pictures: docs/$name is missing (drawn by this script)" >&2
        differ=1
    elif [[ "$name" == summary*.md ]]; then
        if ! cmp -s <(strip_wall "$made") <(strip_wall "docs/$name"); then
            echo "make-pictures: docs/$name differs from a fresh run" >&2
            differ=1
        fi
    elif ! cmp -s "$made" "docs/$name"; then
        echo "make-pictures: docs/$name differs from a fresh run" >&2
        differ=1
    fi
done
if [ "$differ" = 1 ]; then
    echo "make-pictures: run docs/make-pictures.sh and commit docs/" >&2
    exit 1
fi
echo "make-pictures: $(ls "$OUT" | wc -l) files in docs/ are what this script draws, byte for byte"
