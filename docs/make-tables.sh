#!/usr/bin/env bash
# Regenerates the README's measured tables from deterministic runs and writes them between
# their marker comments in README.md:
#   <!-- tables:paper begin --> … <!-- tables:paper end -->
#       the paper's Fig. 3 and Fig. 4, from `kinergy compare --models sa,sb,sc,sd,se` on
#       data-synthetic/ (seed 1: the same numbers on every run and thread count).
#
# Usage: docs/make-tables.sh [--check] [--from DIR]
#   --check     regenerate into a temporary copy; exit 1 with a diff if README.md differs
#   --from DIR  use the summary.md of a compare run already made with those models
#               (e.g. compare-out/) instead of running compare (1–5 minutes on 2 cores)
# The binary is ${KINERGY:-target/release/kinergy} (build it with
# `cargo build --release -p kinergy-cli`). Exit codes: 0 done (or up to date), 1 the README
# differs (--check), 2 bad usage or a missing binary, summary or marker.
set -euo pipefail
REPO="$(cd "$(dirname "$0")/.." && pwd)"
cd "$REPO"
KINERGY="${KINERGY:-target/release/kinergy}"

check=0
from=""
while [ $# -gt 0 ]; do
    case "$1" in
        --check) check=1 ;;
        --from)
            [ $# -ge 2 ] || { echo "make-tables: --from needs a folder" >&2; exit 2; }
            from="$2"
            shift
            ;;
        -h | --help)
            awk 'NR > 1 && /^#/ { sub(/^# ?/, ""); print; next } NR > 1 { exit }' "$0"
            exit 0
            ;;
        *)
            echo "make-tables: unknown argument '$1' (see --help)" >&2
            exit 2
            ;;
    esac
    shift
done

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT

if [ -z "$from" ]; then
    if [ ! -x "$KINERGY" ]; then
        echo "make-tables: no binary at $KINERGY: run 'cargo build --release -p kinergy-cli' or set KINERGY" >&2
        exit 2
    fi
    "$KINERGY" compare --models sa,sb,sc,sd,se -o "$work/compare" -q
    from="$work/compare"
fi
summary="$from/summary.md"
if [ ! -f "$summary" ]; then
    echo "make-tables: $summary not found" >&2
    exit 2
fi

# The paper's table, from compare's summary.md: its settings line, the Fig. 3 rows
# (| S_A | mean | min | max | reduction | paper |) and the Fig. 4 rows
# (| JT | S_A mean (min–max) | S_C mean (min–max) | reduction | paper |).
awk '
    function trim(s) { gsub(/^ +| +$/, "", s); return s }
    function mm(s) { s = trim(s); sub(/ \(.*$/, "", s); return s }
    NR == 3 {
        clips = $1
        evals = $0; sub(/ evaluations per fit.*$/, "", evals); sub(/^.* /, "", evals)
    }
    /^## Fig\. 3/ { section = 3; next }
    /^## Fig\. 4/ { section = 4; next }
    /^## / { section = 0; next }
    section == 3 && /^\| S_/ {
        split($0, c, "|")
        fig3[++n3] = sprintf("| %s | %s | %s | %s |", trim(c[2]), mm(c[3]), trim(c[6]), trim(c[7]))
    }
    section == 4 && /^\| [A-Z]/ && !/^\| optimizer/ {
        split($0, c, "|")
        fig4[++n4] = sprintf("| %s | %s → %s | %s | %s |", trim(c[2]), mm(c[3]), mm(c[4]), trim(c[5]), trim(c[6]))
    }
    END {
        if (n3 == 0 || n4 == 0 || clips == "" || evals == "") {
            print "make-tables: no Fig. 3 / Fig. 4 rows in summary.md" > "/dev/stderr"
            exit 2
        }
        printf "<!-- Made by docs/make-tables.sh from `kinergy compare --models sa,sb,sc,sd,se`; do not edit by hand. -->\n"
        printf "%s reaches of `data-synthetic/`, one fit per reach, %s evaluations per fit, seed 1; mean\n", clips, evals
        printf "joint-position motion distance in mm. The paper: 14 seated reaches of one subject.\n\n"
        print "| Fig. 3 (SVD) | ours: mean (mm) | ours: reduction from the previous model | paper: reduction |"
        print "|---|---|---|---|"
        for (i = 1; i <= n3; i++) print fig3[i]
        print ""
        print "| Fig. 4: S_C instead of S_A | ours: S_A → S_C (mm) | ours: reduction | paper: reduction |"
        print "|---|---|---|---|"
        for (i = 1; i <= n4; i++) print fig4[i]
    }
' "$summary" > "$work/paper.md"

begin='<!-- tables:paper begin -->'
end='<!-- tables:paper end -->'
for marker in "$begin" "$end"; do
    count="$(grep -cxF -- "$marker" README.md || true)"
    if [ "$count" != 1 ]; then
        echo "make-tables: README.md must hold the line '$marker' once (found $count)" >&2
        exit 2
    fi
done

awk -v begin="$begin" -v end="$end" -v table="$work/paper.md" '
    $0 == begin { print; while ((getline line < table) > 0) print line; skip = 1; next }
    $0 == end { skip = 0 }
    !skip { print }
' README.md > "$work/README.md"

if [ "$check" = 1 ]; then
    if diff -u README.md "$work/README.md"; then
        echo "make-tables: README.md is up to date"
    else
        echo "make-tables: README.md differs from the regenerated tables (above); run docs/make-tables.sh" >&2
        exit 1
    fi
elif cmp -s README.md "$work/README.md"; then
    echo "make-tables: README.md unchanged"
else
    cp "$work/README.md" README.md.make-tables.tmp
    mv README.md.make-tables.tmp README.md
    echo "make-tables: README.md updated"
fi
