#!/usr/bin/env bash
# System packages some tests need beyond Python, gcc and the lock:
#   gcc-mingw-w64-x86-64  the native FMUs' binaries/win64 (x86_64-w64-mingw32-gcc; else zig from the lock builds them)
#   wine64, wine          running win64 programs (tests/fmu/test_native_win64.py, tests/fmu/test_cross_binaries.py)
#   qemu-user             running the aarch64-linux binaries (tests/fmu/test_cross_binaries.py)
#   libc6-arm64-cross     the aarch64 C library qemu-user loads them with
#   libtbb12              the ecos engine of the ecospy wheel (tests/hosts/test_native_hosts.py)
#   cmake                 fmpy's rebuild of a native FMU from its sources/ (tests/fmu/test_native_fmu.py)
#   chromium              a headless browser measuring the documentation site's layout (tests/docs/test_docs_site.py)
#
#   bash build_scripts/system_packages.sh
#
# As root on a Debian/Ubuntu machine (apt-get), the missing ones are installed quietly. Otherwise, or if
# the installation fails, it prints one line per missing package saying which tests will skip. It never
# fails: the tests that need a missing package skip and say why. .ci/run calls it before the tests.
set -u

declare -A SKIPS=(
    [gcc-mingw-w64-x86-64]="the native FMUs' Windows DLLs are built with zig (pip: ziglang, in the lock); without zig too, tests/fmu/test_native_win64.py skips and no binaries/win64 is built"
    [wine64]="tests/fmu/test_native_win64.py and the Windows runs of tests/fmu/test_cross_binaries.py skip (no Wine to run the win64 programs)"
    [qemu-user]="the aarch64-linux runs of tests/fmu/test_cross_binaries.py skip (no qemu-aarch64)"
    [libc6-arm64-cross]="the aarch64-linux runs of tests/fmu/test_cross_binaries.py skip (no aarch64 C library for qemu)"
    [libtbb12]="the ecos tests of tests/hosts/test_native_hosts.py skip (ecos needs libtbb.so.12)"
    [cmake]="tests/fmu/test_native_fmu.py::test_rebuilt_from_sources_by_fmpy skips (fmpy's rebuild uses cmake)"
    [chromium]="tests/docs/test_docs_site.py::test_code_blocks_stay_inside_the_column skips (no headless browser to measure the site's code blocks in)"
)
ORDER=(gcc-mingw-w64-x86-64 wine64 qemu-user libc6-arm64-cross libtbb12 cmake chromium)

have_lib() {
    local ldconfig
    ldconfig=$(command -v ldconfig || echo /sbin/ldconfig)
    [ -x "$ldconfig" ] && "$ldconfig" -p 2>/dev/null | grep -q "$1"
}

present() {  # what the tests look for, not the package database
    case "$1" in
        gcc-mingw-w64-x86-64) command -v x86_64-w64-mingw32-gcc >/dev/null ;;
        wine64) command -v wine64 >/dev/null || command -v wine >/dev/null || [ -x /usr/lib/wine/wine64 ] ;;
        qemu-user) command -v qemu-aarch64 >/dev/null ;;
        libc6-arm64-cross) [ -e /usr/aarch64-linux-gnu/lib/ld-linux-aarch64.so.1 ] ;;
        libtbb12) have_lib 'libtbb\.so\.12 ' ;;
        cmake) command -v cmake >/dev/null ;;
        chromium) [ -x /usr/bin/chromium ] ;;
    esac
}

missing() {
    local p
    for p in "${ORDER[@]}"; do
        present "$p" || echo "$p"
    done
}

todo=$(missing)
if [ -z "$todo" ]; then
    echo "system_packages: all present (${ORDER[*]})"
    exit 0
fi

if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    packages=$todo
    case " $(echo $todo) " in *" wine64 "*) packages="$todo wine" ;; esac  # wine: the 'wine' command
    echo "system_packages: installing $(echo $packages) (apt-get)"
    export DEBIAN_FRONTEND=noninteractive
    log=$(mktemp)
    if ! { timeout 600 apt-get -qq -o DPkg::Lock::Timeout=120 update >"$log" 2>&1 &&
           timeout 1200 apt-get -qq -y -o DPkg::Lock::Timeout=120 install $packages >>"$log" 2>&1; }; then
        echo "system_packages: apt-get failed; its last lines:"
        tail -n 5 "$log" | sed 's/^/    /'
    fi
    rm -f "$log"
    todo=$(missing)
fi

for p in $todo; do
    echo "system_packages: $p missing: ${SKIPS[$p]}"
done
exit 0
