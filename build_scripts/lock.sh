#!/usr/bin/env bash
# Refresh requirements/dev.lock: exact versions, with hashes, of every package of .[dev] for
# CPython 3.11 on Linux x86-64, resolved by uv from PyPI. Run after changing the dependencies in
# pyproject.toml, then run the tests (bash build_scripts/quickstart.sh test installs the new lock).
#   bash build_scripts/lock.sh
set -euo pipefail
cd "$(dirname "$0")/.."
tool=".lock-tool"  # a private venv for uv, so the project's .venv holds only what the lock says
if [ ! -x "$tool/bin/uv" ]; then
    python3 -m venv "$tool"
    "$tool/bin/python" -m pip install --quiet "uv==0.13.9"
fi
mkdir -p requirements
# No index URLs or local paths in the output (uv writes none unless asked): the lock must work
# on any machine that reaches PyPI.
"$tool/bin/uv" pip compile pyproject.toml --extra dev --generate-hashes \
    --python-version 3.11 --python-platform x86_64-manylinux_2_28 \
    --index-url https://pypi.org/simple --no-emit-index-url \
    --custom-compile-command "bash build_scripts/lock.sh" \
    --output-file requirements/dev.lock --quiet
echo "wrote requirements/dev.lock ($(grep -c '^[a-z0-9]' requirements/dev.lock) packages)"
