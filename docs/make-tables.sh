#!/usr/bin/env bash
# Regenerates the README's measured tables from deterministic runs and writes them between
# their marker comments in README.md:
#   <!-- tables:paper begin --> … <!-- tables:paper end -->
#       the paper's Fig. 3 and Fig. 4, from `kinergy compare --models sa,sb,sc,sd,se` on
#       data-synthetic/ (seed 1: the same numbers on every run and thread count), under the
#       default smooth controller and under the paper's (`--controller paper`), side by side.
#
# Usage: docs/make-tables.sh [--check] [--from DIR] [--from-paper DIR]
#   --check           regenerate into a temporary copy; exit 1 with a diff if README.md differs
#   --from DIR        use the summary.md of a compare run already made with those models
#                     (e.g. compare-out/) instead of running compare (1–5 minutes on 2 cores)
#   --from-paper DIR  the same for the run with --controller paper
# The binary is ${KINERGY:-target/release/kinergy} (build it with
# `cargo build --release -p kinergy-cli`). Exit codes: 0 done (or up to date), 1 the README
# differs (--check), 2 bad usage or a missing binary, summary or marker.
set -euo pipefail
REPO="$(cd "$(dirname "$0")/.." && pwd)"
cd "$REPO"
KINERGY="${KINERGY:-target/release/kinergy}"

check=0
from=""
from_paper=""
while [ $# -gt 0 ]; do
    case "$1" in
        --check) check=1 ;;
        --from)
            [ $# -ge 2 ] || { echo "make-tables: --from needs a folder" >&2; exit 2; }
            from="$2"
            shift
            ;;
        --from-paper)
            [ $# -ge 2 ] || { echo "make-tables: --from-paper needs a folder" >&2; exit 2; }
            from_paper="$2"
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

if { [ -z "$from" ] || [ -z "$from_paper" ]; } && [ ! -x "$KINERGY" ]; then
    echo "make-tables: no binary at $KINERGY: run 'cargo build --release -p kinergy-cli' or set KINERGY" >&2
    exit 2
fi
if [ -z "$from" ]; then
    "$KINERGY" compare --models sa,sb,sc,sd,se -o "$work/compare" -q
    from="$work/compare"
fi
if [ -z "$from_paper" ]; then
    "$KINERGY" compare --models sa,sb,sc,sd,se --controller paper -o "$work/compare-paper" -q
    from_paper="$work/compare-paper"
fi
for summary in "$from/summary.md" "$from_paper/summary.md"; do
    if [ ! -f "$summary" ]; then
        echo "make-tables: $summary not found" >&2
        exit 2
    fi
done

# The paper's table, from each compare's summary.md: its settings line, the Fig. 3 rows
# (| S_A | mean | min | max | reduction | paper |) and the Fig. 4 rows
# (| JT | S_A mean (min–max) | S_C mean (min–max) | reduction | paper |), the two controllers
# side by side.
python3 - "$from/summary.md" "$from_paper/summary.md" > "$work/paper.md" <<'PY'
import re, sys

def cells(line):
    return [c.strip() for c in line.strip().strip("|").split("|")]

def mm(text):
    return re.sub(r" \(.*$", "", text.strip())

def read(path):
    lines = open(path, encoding="utf-8").read().split("\n")
    first = lines[2].split()
    clips, evals = first[0], re.search(r"(\S+) evaluations per fit", lines[2])
    fig3, fig4, section = {}, {}, 0
    for line in lines:
        if line.startswith("## Fig. 3"):
            section = 3
        elif line.startswith("## Fig. 4"):
            section = 4
        elif line.startswith("## "):
            section = 0
        elif section == 3 and line.startswith("| S_"):
            c = cells(line)
            fig3[c[0]] = (mm(c[1]), c[4], c[5])
        elif section == 4 and re.match(r"^\| [A-Z]", line) and not line.startswith("| optimizer"):
            c = cells(line)
            fig4[c[0]] = ("%s → %s" % (mm(c[1]), mm(c[2])), c[3], c[4])
    if not fig3 or not fig4 or evals is None:
        sys.exit("make-tables: no Fig. 3 / Fig. 4 rows in %s" % path)
    return clips, evals.group(1), fig3, fig4

smooth, paper = read(sys.argv[1]), read(sys.argv[2])
if smooth[:2] != paper[:2] or smooth[2].keys() != paper[2].keys() or smooth[3].keys() != paper[3].keys():
    sys.exit("make-tables: the two compare runs differ in their reaches, budgets or rows")
clips, evals = smooth[0], smooth[1]
print("<!-- Made by docs/make-tables.sh from `kinergy compare --models sa,sb,sc,sd,se` and the same with `--controller paper`; do not edit by hand. -->")
print("%s reaches of `data-synthetic/`, one fit per reach, %s evaluations per fit, seed 1; mean" % (clips, evals))
print("joint-position motion distance in mm, under the default smooth controller and under the")
print("paper's (`--controller paper`). The paper: 14 seated reaches of one subject.")
print()
def side_by_side(title, value, smooth_rows, paper_rows):
    """One figure's table: each row's value and reduction under both controllers, and the paper's."""
    print("| %s | smooth: %s | smooth: reduction | paper's controller: %s | paper's controller: reduction | paper: reduction |" % (title, value, value))
    print("|---|---|---|---|---|---|")
    for key, (v, red, ref) in smooth_rows.items():
        pv, pred, _ = paper_rows[key]
        print("| %s | %s | %s | %s | %s | %s |" % (key, v, red, pv, pred, ref))

side_by_side("Fig. 3 (SVD)", "mean (mm)", smooth[2], paper[2])
print()
side_by_side("Fig. 4: S_C instead of S_A", "S_A → S_C (mm)", smooth[3], paper[3])
PY

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
