#!/bin/sh
# Build modelica's C fmusim, to run tests/test_fmusim.py (INFLOWSIM_FMUSIM=.../bin/fmusim).
#
#   tools/fmusim/build.sh REFERENCE_FMUS_GIT_DIR OUT_DIR
#
# REFERENCE_FMUS_GIT_DIR: a clone of https://github.com/modelica/Reference-FMUs (its .git
# folder or a bare repository).  The C fmusim is taken from commit c8d4e6d, the last
# before it was replaced by a Rust one.  Needs a C compiler, make and the development
# files of libxml2, zlib, minizip and SUNDIALS (Debian/Ubuntu: libxml2-dev zlib1g-dev
# libminizip-dev libsundials-dev).
set -eu
GIT_DIR=$1
OUT=$2
HERE=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$OUT/src"
# (git archive may report a missing blob of fmusim-gui's plotly bundle: not needed)
git --git-dir="$GIT_DIR" archive c8d4e6d90fa14be49d7622badf30e38eebea5e0a \
    fmusim include src | tar -x -C "$OUT/src" || true
test -f "$OUT/src/fmusim/fmusim.c"
make -f "$HERE/Makefile" -C "$OUT" SRC=src
echo "$OUT/bin/fmusim"
