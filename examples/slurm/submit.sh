#!/usr/bin/env bash
# Fits a library on a Slurm cluster: an array of SHARDS tasks, then a collect job that runs
# when they are all over (ok or not: collect says what is missing).
#   examples/slurm/submit.sh TAKES_DIR OUT_DIR SHARDS [fit options…]
# Prints the two job ids. Add --wait to sbatch yourself to block until the end.
set -euo pipefail
if [ $# -lt 3 ]; then
    echo "usage: $0 TAKES_DIR OUT_DIR SHARDS [fit options…]" >&2
    exit 2
fi
here="$(cd "$(dirname "$0")" && pwd)"
takes="$1"; out="$2"; shards="$3"; shift 3
mkdir -p "$out"
array=$(sbatch --parsable --array="1-${shards}" "$here/fit-library.sbatch" "$takes" "$out" "$@")
collect=$(sbatch --parsable --dependency="afterany:${array%%;*}" "$here/collect.sbatch" "$out")
echo "array job ${array%%;*} (${shards} shards), collect job ${collect%%;*}"
