#!/usr/bin/env bash
# One-command set-up and run, for a fresh machine with Python >= 3.11 and gcc.
#   bash build_scripts/quickstart.sh demo   # build dist/SpherePlateImpact.fmu (when stale) and bounce a ball through it
#   bash build_scripts/quickstart.sh test   # run the test suite (extra arguments go to pytest)
# Creates .venv/ in the repository (once) and installs into it exactly the versions of
# requirements/dev.lock (hash-checked; refresh it with build_scripts/lock.sh), then the package
# itself (editable, no dependencies of its own: the lock has them all).
set -euo pipefail
cd "$(dirname "$0")/.."
PYTHON="${PYTHON:-python3}"
if ! "$PYTHON" -c 'import sys; sys.exit(sys.version_info < (3, 11))' 2>/dev/null; then
    echo "quickstart: needs Python >= 3.11 as '$PYTHON' (set PYTHON=/path/to/python3.11)" >&2
    exit 2
fi
if [ ! -x .venv/bin/python ]; then
    "$PYTHON" -m venv .venv
fi
stamp=.venv/.installed-$(cat pyproject.toml requirements/dev.lock | sha1sum | cut -c1-12)
if [ ! -f "$stamp" ]; then
    .venv/bin/python -m pip install --quiet --disable-pip-version-check --require-hashes \
        -r requirements/dev.lock
    .venv/bin/python -m pip install --quiet --disable-pip-version-check --no-deps -e .
    rm -f .venv/.installed-*
    touch "$stamp"
fi
case "${1:-demo}" in
    demo)
        # builds (and validates) dist/*.fmu when missing or built from other sources, else reuses them
        .venv/bin/python examples/quickstart_bounce.py
        ;;
    test)
        shift || true
        .venv/bin/python -m pytest "$@"
        ;;
    *)
        echo "usage: bash build_scripts/quickstart.sh [demo|test [pytest args]]" >&2
        exit 2
        ;;
esac
