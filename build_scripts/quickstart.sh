#!/usr/bin/env bash
# One-command set-up and run, for a fresh machine with Python >= 3.10 and gcc.
#   bash build_scripts/quickstart.sh demo   # build dist/SpherePlateImpact.fmu and bounce a ball through it
#   bash build_scripts/quickstart.sh test   # run the test suite
# Creates .venv/ in the repository (once) and installs the package with its extras into it.
set -euo pipefail
cd "$(dirname "$0")/.."
PYTHON="${PYTHON:-python3}"
if [ ! -x .venv/bin/python ]; then
    "$PYTHON" -m venv .venv
fi
stamp=.venv/.installed-$(sha1sum pyproject.toml | cut -c1-12)
if [ ! -f "$stamp" ]; then
    .venv/bin/python -m pip install --quiet --upgrade pip
    .venv/bin/python -m pip install --quiet -e ".[dev]"
    touch "$stamp"
fi
case "${1:-demo}" in
    demo)
        .venv/bin/python build_scripts/build_fmu.py --out dist
        .venv/bin/python examples/quickstart_bounce.py --fmu dist/SpherePlateImpact.fmu
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
