#!/usr/bin/env bash
# The FMU build and the tests that depend on its platform set, as on a machine with only Python and gcc
# (the README's Quickstart). Run by .ci/run after the test command, from the repository with .venv set up.
set -euo pipefail
cd "$(dirname "$0")/.."
# Again as on a machine with only Python and gcc (the README's Quickstart): every cross compiler this one
# has (mingw-w64, clang), Wine and qemu hidden from PATH (a directory of links to the other commands stands
# in for each PATH directory that holds one), one FMU build checked against the platforms it declares
# (tests/fmu_platforms.py), then the tests that depend on the platform set (what needs qemu to run a
# binary skips, naming it; the Wine tests still find /usr/lib/wine/wine64 off PATH where Debian's wine64
# is installed, and then run the zig-built Windows DLLs). zig stays: it comes from PyPI with the lock
# (python -m ziglang, not a PATH command), so the build still writes every platform, Windows included.
# About 2.5 min (more the first time: zig builds each target's C runtime into its cache, ~1 min for Windows).
is_cross() { case "$1" in *mingw32*|clang*|wine*|qemu-*) return 0 ;; esac; return 1; }
bare=$(mktemp -d)
trap 'rm -rf "$bare"' EXIT
bare_path="" hidden="" n=0
IFS=: read -r -a path_dirs <<< "$PATH"
for dir in "${path_dirs[@]}"; do
    [ -d "$dir" ] || continue
    found=""
    for tool in "$dir"/*; do
        if is_cross "${tool##*/}"; then found=1; hidden+="${tool##*/}"$'\n'; fi
    done
    if [ -n "$found" ]; then
        n=$((n + 1))
        link_dir="$bare/path$n"
        mkdir "$link_dir"
        for tool in "$dir"/*; do
            if ! is_cross "${tool##*/}"; then ln -s "$tool" "$link_dir/"; fi
        done
        dir="$link_dir"
    fi
    bare_path+="${bare_path:+:}$dir"
done
if [ -n "$hidden" ]; then
    families=$(printf '%s' "$hidden" | sed -E 's/^(.*mingw32[^-]*-).*/\1*/; s/^(clang|wine|qemu-).*/\1*/' | sort -u | paste -sd, -)
    echo "platform tests as on a machine with only Python and gcc: $(printf '%s' "$hidden" | sort -u | wc -l) commands hidden from PATH (${families//,/, })"
else
    echo "platform tests as on a machine with only Python and gcc: no cross compiler on PATH to hide"
fi
start=$SECONDS
PATH="$bare_path" .venv/bin/python -m restitution.fmu build --out "$bare/fmus"
PATH="$bare_path" .venv/bin/python tests/fmu_platforms.py "$bare/fmus"
PATH="$bare_path" bash build_scripts/quickstart.sh test -q -rs -p no:cacheprovider tests/fmu/test_fmu_platforms.py \
    tests/hosts/test_native_hosts.py tests/fmu/test_native_fmu.py tests/fmu/test_native_win64.py \
    tests/fmu/test_cross_binaries.py -k "platform or fmutool or binaries or win64"
echo "platform tests without cross compilers: $((SECONDS - start)) s"

