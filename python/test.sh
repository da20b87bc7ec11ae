#!/usr/bin/env bash
# Builds the `kinergy` Python package into the shared venv (tools/python-env.sh) and runs its
# tests (python/tests: byte-identity with the CLI, numpy shapes, exceptions, Ctrl-C, memory).
#
#   python/test.sh                 # all
#   python/test.sh -k fit          # pytest's own arguments
set -euo pipefail
source "$(dirname "${BASH_SOURCE[0]}")/../tools/python-env.sh"
# The tests compare with the CLI of this checkout (the same release profile).
(cd "$REPO" && cargo build --release -p kinergy-cli)
export KINERGY="${CARGO_TARGET_DIR:-$REPO/target}/release/kinergy"
case "$KINERGY" in /*) ;; *) KINERGY="$REPO/$KINERGY" ;; esac
cd "$REPO/python"
exec "$VENV/bin/python" -m pytest -q "$@" tests
