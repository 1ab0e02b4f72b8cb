#!/usr/bin/env bash
# The release as a user installs it: the sdist and the wheel of DIR (built by `python -m build` when DIR
# lacks them; the test run of .ci/run leaves them there), twine check, then the wheel installed into a new
# venv with the package's runtime dependencies and fmpy only (the versions of requirements/dev.lock, from
# pip's cache or the index; no ziglang), and, with a PATH of that venv's bin/ alone (no C compiler
# reachable), `restitution fmu path`, `restitution fmu copy` and fmpy simulating every installed FMU.
#   bash build_scripts/release_check.sh [DIR]     (default: a temporary folder; needs .venv: quickstart.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
release="${1:-$(mktemp -d)}"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
start=$SECONDS
mkdir -p "$release"
if ! ls "$release"/restitution-*.tar.gz "$release"/restitution-*-py3-none-any.whl > /dev/null 2>&1; then
    .venv/bin/python -m build --no-isolation --outdir "$release" . > "$work/build.log" 2>&1 \
        || { tail -30 "$work/build.log" >&2; exit 1; }
fi
sdist=$(ls "$release"/restitution-*.tar.gz) wheel=$(ls "$release"/restitution-*-py3-none-any.whl)
.venv/bin/python -m twine check --strict "$sdist" "$wheel"
python3 -m venv "$work/venv"
pins=$(grep -E '^(numpy|scipy|pint|fmpy)==' requirements/dev.lock | sed 's/ .*//' | tr '\n' ' ')
# shellcheck disable=SC2086  # one argument per pin
"$work/venv/bin/python" -m pip install --quiet --disable-pip-version-check $pins "$wheel" 2>&1 \
    | { grep -v "^WARNING: Location" || true; } >&2
mkdir "$work/elsewhere" "$work/home"
cd "$work/elsewhere"
# every command below sees a PATH of the new venv's bin/ alone
bare() { env PATH="$work/venv/bin" HOME="$work/home" XDG_CACHE_HOME="$work/cache" "$@"; }
for compiler in gcc cc clang x86_64-w64-mingw32-gcc zig; do
    if bare /bin/sh -c "command -v $compiler" > /dev/null; then
        echo "release check: $compiler is reachable" >&2
        exit 1
    fi
done
bare restitution fmu path SpherePlateImpact
bare restitution fmu path SpherePlateImpact --fmi 3
copied=$(bare restitution fmu copy --out "$work/fmus" | grep -c '^copied')
echo "release check: restitution fmu copy: $copied files"
bare python - <<'EOF_PY'
import fmpy, importlib.util
from restitution.fmu import path
assert importlib.util.find_spec("ziglang") is None, "ziglang installed: the release check must have no compiler"
for model, stop, output in (("SpherePlateImpact", 1e-3, "e"), ("BouncingBall", 0.2, "h")):
    for fmi, implementation in (("2", "pythonfmu"), ("2", "native"), ("3", "native")):
        result = fmpy.simulate_fmu(str(path(model, fmi, implementation)), stop_time=stop, output=[output])
        print(f"release check: FMI {fmi} {implementation} {model}: {output} = {result[output][-1]:.6g}")
EOF_PY
echo "release check: wheel $(du -k "$wheel" | cut -f1) KiB, sdist $(du -k "$sdist" | cut -f1) KiB, $((SECONDS - start)) s"
