#!/usr/bin/env bash
# docs/viewer.png: a screenshot of the page `kinergy view` writes, in headless Chromium
# (Debian's chromium, or KINERGY_CHROMIUM). Not part of make-pictures.sh --check: a browser's
# rasterizer is not byte-for-byte the same across versions.
# Usage: docs/make-viewer-picture.sh   (from anywhere; builds the CLI in release first)
set -euo pipefail
REPO="$(cd "$(dirname "$0")/.." && pwd)"
cd "$REPO"
cargo build --release -q -p kinergy-cli
K="$REPO/target/release/kinergy"
BROWSER="${KINERGY_CHROMIUM:-chromium}"
WORK="$(mktemp -d)"
trap 'rm -rf "$WORK"' EXIT
"$K" view data-synthetic/p01/r09.bvh data-synthetic/p01/r03.bvh data-synthetic/p02/r02.bvh \
    -o "$WORK/view.html" -q
"$BROWSER" --headless --no-sandbox --disable-gpu --use-angle=swiftshader --enable-unsafe-swiftshader \
    --disable-quic --no-first-run --disable-background-networking --disable-component-update \
    --disable-sync --hide-scrollbars --user-data-dir="$WORK/profile" --window-size=1000,700 \
    --virtual-time-budget=4000 --screenshot="$WORK/viewer.png" \
    "file://$WORK/view.html#t=0.6,view=1000x440" 2>/dev/null
mv "$WORK/viewer.png" docs/viewer.png
echo "docs/viewer.png"
