#!/usr/bin/env bash
# Builds far_timing (OpenSubdiv Far timing on subdyn's bench torus).
#
#   benches/opensubdiv/build.sh OSD_PREFIX OUTPUT
#
# OSD_PREFIX is an OpenSubdiv 3.6 install prefix (what `make install` of a
# CMake build writes): OSD_PREFIX/include/opensubdiv/far/stencilTableFactory.h
# and OSD_PREFIX/lib/libosdCPU.a must exist. OUTPUT is the binary to write.
# Compiles with g++ -O3 -std=c++14 (override with CXX / CXXFLAGS), links the
# static libosdCPU.a, no OpenMP/TBB: the program runs on one thread.
set -euo pipefail

if [ $# -ne 2 ]; then
    echo "usage: $0 OSD_PREFIX OUTPUT  (OSD_PREFIX holds include/opensubdiv/ and lib/libosdCPU.a)" >&2
    exit 2
fi
prefix=$1
out=$2
header=$prefix/include/opensubdiv/far/stencilTableFactory.h
lib=$prefix/lib/libosdCPU.a
for f in "$header" "$lib"; do
    if [ ! -f "$f" ]; then
        echo "$0: $f not found: OSD_PREFIX must be an OpenSubdiv install prefix with include/opensubdiv/ and lib/libosdCPU.a" >&2
        exit 1
    fi
done
here=$(cd "$(dirname "$0")" && pwd)
${CXX:-g++} ${CXXFLAGS:--O3 -DNDEBUG} -std=c++14 -Wall -Wextra \
    -I"$prefix/include" "$here/far_timing.cpp" "$lib" -o "$out"
echo "built $out"
