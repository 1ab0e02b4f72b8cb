#!/usr/bin/env bash
# One-command set-up and run, for a fresh machine with Python >= 3.11 and gcc.
#   bash build_scripts/quickstart.sh demo   # build dist/SpherePlateImpact.fmu alone (when stale) and bounce a ball through it
#   bash build_scripts/quickstart.sh test   # run the test suite (extra arguments go to pytest)
# Creates .venv/ in the repository (once) and installs into it exactly the versions of
# requirements/dev.lock (hash-checked; refresh it with build_scripts/lock.sh), then the package
# itself (editable, no dependencies of its own: the lock has them all). --no-compile: each module is
# byte-compiled when first imported, not every module of the lock at install (a third of the set-up's CPU).
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
    began=$SECONDS
    echo "quickstart: installing requirements/dev.lock ($(grep -c '^[A-Za-z0-9].*==' requirements/dev.lock) packages) into .venv: about a minute on two cores with pip's cache warm" >&2
    .venv/bin/python -m pip install --quiet --disable-pip-version-check --no-compile --require-hashes \
        -r requirements/dev.lock
    .venv/bin/python -m pip install --quiet --disable-pip-version-check --no-compile --no-deps -e .
    rm -f .venv/.installed-*
    touch "$stamp"
    echo "quickstart: .venv ready ($((SECONDS - began)) s)" >&2
fi
case "${1:-demo}" in
    demo)
        # builds (and validates) the one FMU it runs, dist/SpherePlateImpact.fmu (pythonfmu, this machine's
        # guard: seconds, no zig), when missing or built from other sources, else reuses it; every FMU for
        # every platform: .venv/bin/restitution fmu build
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
