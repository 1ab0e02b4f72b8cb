#!/usr/bin/env bash
# Builds fmusim, the Modelica Reference FMUs' FMI 1/2/3 simulator, from a checkout of its public sources
# (https://github.com/modelica/Reference-FMUs, tag v0.0.39) against Debian's libraries, for the test that
# runs BouncingBall with early return and event mode in it (tests/hosts/test_event_mode.py: it finds the
# binary on PATH or in RESTITUTION_FMUSIM).
#
#   apt-get install libxml2-dev libminizip-dev zlib1g-dev libsundials-dev   # (Debian 12: sundials 6.4)
#   git clone --branch v0.0.39 https://github.com/modelica/Reference-FMUs
#   bash build_scripts/build_fmusim.sh Reference-FMUs /usr/local/bin/fmusim
#
# Upstream builds its own zlib, libxml2 and CVode with CMake; here the system's serve (minizip from
# libminizip-dev, CVode 6, where SUN_COMM_NULL is spelled NULL).
set -euo pipefail
src=${1:?usage: build_fmusim.sh REFERENCE_FMUS_CHECKOUT OUT_BINARY}
out=${2:?usage: build_fmusim.sh REFERENCE_FMUS_CHECKOUT OUT_BINARY}
cd "$src/fmusim"
# the .c files the upstream CMakeLists.txt lists by name (not the ones under its downloaded zlib)
mapfile -t sources < <(grep -E '^\s+[^$ ]+\.c$' CMakeLists.txt | tr -d ' ')
gcc -O2 -w -o "$out" -I. -I../include -I/usr/include/libxml2 -I/usr/include/minizip \
    '-DFMUSIM_VERSION="0.0.39"' -DSUN_COMM_NULL=NULL "${sources[@]}" \
    -lxml2 -lminizip -lz -lsundials_cvode -lsundials_nvecserial -ldl -lm
"$out" --version
