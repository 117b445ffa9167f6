#!/usr/bin/env bash
# Installs what is missing, builds, and runs every test.
#   scripts/test.sh               Release build in build/
#   scripts/test.sh --sanitize    AddressSanitizer + UBSan build in build-asan/
#   scripts/test.sh --fuzz        libFuzzer harnesses (clang, ASan + UBSan) in build-fuzz/,
#                                 each run for $BIMART_FUZZ_SECONDS (default 30) s (docs/reliability.md)
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
ctest_args=(-j "$(nproc)")
if [ "${1:-}" = "--fuzz" ]; then
  shift
  export BIMART_BUILD_DIR=${BIMART_BUILD_DIR:-$root/build-fuzz}
  export BIMART_BUILD_TYPE=RelWithDebInfo
  export BIMART_BUILD_TARGET=fuzz_all
  cmake_args+=(-DBIMART_FUZZ=ON -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_C_COMPILER=clang
               -DBIMART_FUZZ_SECONDS="${BIMART_FUZZ_SECONDS:-30}")
  # One harness at a time: each already keeps a core busy, and the timings stay honest.
  ctest_args=(-L fuzz -j 1)
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0}
fi
build=${BIMART_BUILD_DIR:-$root/build}

bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh" "${cmake_args[@]}"
ctest --test-dir "$build" --output-on-failure "${ctest_args[@]}" "$@"
