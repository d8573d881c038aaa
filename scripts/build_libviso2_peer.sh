#!/usr/bin/env bash
# Builds libviso2 outside the sunvo tree for `sunvo_bench_vo --peer libviso2`.
#
#   scripts/build_libviso2_peer.sh LIBVISO2_SRC OUT_DIR
#
# LIBVISO2_SRC: libviso2's src/ folder (matcher.cpp, viso_stereo.cpp, ... and headers), obtained
# separately from libviso2's authors (GPL; https://www.cvlibs.net/software/libviso/); sunvo
# neither ships nor downloads it. OUT_DIR (outside the tree) receives include/*.h and
# lib/libviso2.a; then configure sunvo with -DSUNVO_LIBVISO2_DIR=OUT_DIR.
# The recipe is scripts/peers/libviso2/CMakeLists.txt (-O3 -msse3, as libviso2's own).
set -euo pipefail
if [[ $# -ne 2 ]]; then
  sed -n '2,11p' "$0" >&2
  exit 2
fi
src=$(cd "$1" && pwd)
out=$(mkdir -p "$2" && cd "$2" && pwd)
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/.." && pwd)
case "$out/" in
  "$repo"/*) echo "build_libviso2_peer.sh: OUT_DIR must be outside the sunvo tree" >&2; exit 2 ;;
esac
launcher=()
if command -v ccache >/dev/null; then launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache); fi
cmake -S "$here/peers/libviso2" -B "$out/build" -DLIBVISO2_SRC="$src" \
  -DCMAKE_INSTALL_PREFIX="$out" "${launcher[@]}" >/dev/null
cmake --build "$out/build" -j "${JOBS:-2}"
cmake --install "$out/build" >/dev/null
echo "libviso2 peer installed in $out: configure sunvo with -DSUNVO_LIBVISO2_DIR=$out"
