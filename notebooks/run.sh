#!/usr/bin/env bash
# Executes every notebooks/*.ipynb headless and fails if any cell fails.
#
#   notebooks/run.sh                 # all notebooks
#   notebooks/run.sh fig5_speed      # only these (names or paths)
#
# Environment: KINERGY_VENV (the venv, with the kinergy package built into it by
# tools/python-env.sh; default target/notebook-venv), KINERGY_NOTEBOOK_OUT (executed copies
# and results, default target/notebooks), KINERGY_BUDGET, KINERGY_SEED, KINERGY_REAL_BVH,
# KINERGY_FIG5_CLIP, KINERGY_PERSON, KINERGY_PERSON_ARM (read by the notebooks), PYTHON (the
# interpreter that creates the venv, default python3). See notebooks/README.md.
set -euo pipefail

OUT_DIR="${KINERGY_NOTEBOOK_OUT:-$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)/target/notebooks}"
start=$SECONDS

# 1. The Python environment and the `kinergy` package (tools/python-env.sh).
source "$(dirname "${BASH_SOURCE[0]}")/../tools/python-env.sh"
# The venv's own kernel, found before any user-wide "python3" kernelspec (JUPYTER_PATH comes first).
export JUPYTER_PATH="$VENV/share/jupyter"
export JUPYTER_PLATFORM_DIRS=1
export IPYTHONDIR="$VENV/ipython"
export MPLCONFIGDIR="$VENV/matplotlib"
if [ ! -f "$JUPYTER_PATH/kernels/python3/kernel.json" ]; then
    "$VENV/bin/python" -m ipykernel install --prefix "$VENV" --name python3 >/dev/null
fi

# 2. The notebooks (they call the package, not the CLI), executed in notebooks/ (their
#    relative paths start there); executed copies go to $OUT_DIR, the committed notebooks
#    are never written.
mkdir -p "$OUT_DIR"
export KINERGY_NOTEBOOK_OUT="$(cd "$OUT_DIR" && pwd)"
notebooks=()
if [ $# -eq 0 ]; then
    notebooks=("$REPO"/notebooks/*.ipynb)
else
    for name in "$@"; do
        name="$(basename "$name" .ipynb)"
        notebooks+=("$REPO/notebooks/$name.ipynb")
    done
fi

"$VENV/bin/python" - "$REPO/notebooks" "$KINERGY_NOTEBOOK_OUT" "${notebooks[@]}" <<'PY'
import sys
import time
from pathlib import Path

import nbclient
import nbformat
from nbclient.exceptions import CellExecutionError

cwd, out_dir, paths = sys.argv[1], Path(sys.argv[2]), [Path(p) for p in sys.argv[3:]]
failed = []
for path in paths:
    nb = nbformat.read(path, as_version=4)
    dirty = [c.get("id") for c in nb.cells if c.cell_type == "code" and (c.outputs or c.execution_count)]
    if dirty:
        print(f"FAIL {path.name}: committed with outputs in cells {dirty}; clear them first", flush=True)
        failed.append(path.name)
        continue
    out = out_dir / path.name
    t0 = time.perf_counter()
    try:
        nbclient.NotebookClient(nb, timeout=900, kernel_name="python3",
                                resources={"metadata": {"path": cwd}}).execute()
        status = "ok"
    except Exception as e:  # a failing cell, a dead kernel, a timeout
        status = "FAIL"
        failed.append(path.name)
        print(e if isinstance(e, CellExecutionError) else repr(e), file=sys.stderr)
    finally:
        nbformat.write(nb, out)
    print(f"{status:4} {path.name}: {time.perf_counter() - t0:.1f} s -> {out}", flush=True)
if failed:
    sys.exit(f"failed: {', '.join(failed)}")
PY

echo "notebooks done in $((SECONDS - start)) s (outputs in $KINERGY_NOTEBOOK_OUT)"
