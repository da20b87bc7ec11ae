# Sourced by notebooks/run.sh and python/test.sh: the Python environment they share.
#
# 1. A venv (KINERGY_VENV, default target/notebook-venv) with notebooks/requirements.txt,
#    created once and reinstalled only when that file changes (wheels only, from PyPI).
# 2. The `kinergy` package (python/, crates/kinergy-py) built by maturin in the release
#    profile (the one `cargo test --release` builds, so dependencies compile once) and
#    installed into the venv (editable: python/kinergy/*.py are used in place).
# Sets VENV and REPO; PYTHON is the interpreter that creates the venv (default python3).
REPO="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="${KINERGY_VENV:-$REPO/target/notebook-venv}"
REQUIREMENTS="$REPO/notebooks/requirements.txt"
if [ ! -x "$VENV/bin/python" ]; then
    echo "creating the Python venv in $VENV"
    "${PYTHON:-python3}" -m venv "$VENV"
fi
stamp="$VENV/.kinergy-requirements"
if ! cmp -s "$REQUIREMENTS" "$stamp"; then
    echo "installing notebooks/requirements.txt"
    "$VENV/bin/python" -m pip install --quiet --disable-pip-version-check --only-binary=:all: \
        -r "$REQUIREMENTS"
    cp "$REQUIREMENTS" "$stamp"
fi
echo "building the kinergy Python package into $VENV"
(cd "$REPO/python" && VIRTUAL_ENV="$VENV" "$VENV/bin/maturin" develop --release --quiet \
    --pip-path "$VENV/bin/pip") 2>&1 | grep -v '^\s*$' | tail -n 3
"$VENV/bin/python" -c "import kinergy" ||
    { echo "error: the kinergy package did not build (see above)" >&2; exit 1; }
