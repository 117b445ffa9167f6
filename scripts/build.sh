#!/usr/bin/env bash
# Configures and builds bimart (Release, ccache when present) into build/ — or into
# $BIMART_BUILD_DIR. Extra arguments go to CMake's configure step, e.g. -DBIMART_SANITIZE=ON.
# $BIMART_BUILD_TARGET builds one target instead of all (scripts/test.sh --fuzz: fuzz_all).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build=${BIMART_BUILD_DIR:-$root/build}
mkdir -p "$build"
# ccache keys on absolute paths unless told the tree's root: with it, another clone of the
# repository (CI's clean clone, a worktree) reuses the objects this one compiled.
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$root}

cmake -S "$root" -B "$build" -DCMAKE_BUILD_TYPE="${BIMART_BUILD_TYPE:-Release}" "$@" > "$build/configure.log" 2>&1 \
  || { cat "$build/configure.log"; echo "build: CMake configure failed (log above)"; exit 1; }
echo "build: compiling into $build (a first build takes a few minutes)"
# Show warnings and errors, not the progress lines.
set +e
cmake --build "$build" -j "$(nproc)" ${BIMART_BUILD_TARGET:+--target "$BIMART_BUILD_TARGET"} 2>&1 | grep -Ev '^\[ *[0-9]+%\] (Building|Linking|Built)'
status=${PIPESTATUS[0]}
set -e
[ "$status" -eq 0 ] || { echo "build: compilation failed"; exit 1; }
echo "build: done"
