#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test.
#   scripts/test.sh               Release build in build/
#   scripts/test.sh --sanitize    AddressSanitizer + UBSan build in build-asan/
# Extra arguments after the options go to ctest (e.g. -L unit, -R cli).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cmake_args=()
if [ "${1:-}" = "--sanitize" ]; then
  shift
  export BIMART_BUILD_DIR=${BIMART_BUILD_DIR:-$root/build-asan}
  export BIMART_BUILD_TYPE=RelWithDebInfo
  cmake_args+=(-DBIMART_SANITIZE=ON)
  # Leak checking is left off: libtorch and OpenBLAS keep process-lifetime allocations.
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0:abort_on_error=1}
  export UBSAN_OPTIONS=${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}
fi
build=${BIMART_BUILD_DIR:-$root/build}

bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh" "${cmake_args[@]}"
ctest --test-dir "$build" --output-on-failure -j "$(nproc)" "$@"
