#!/usr/bin/env bash
# Builds and runs the whole test suite: the normal build, then the same unit tests built with
# AddressSanitizer and UndefinedBehaviorSanitizer (their own CMake configuration, build-asan/).
# Usage: ./test.sh [--no-sanitizers]
set -euo pipefail
cd "$(dirname "$0")"
jobs="$(nproc)"

cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo > /dev/null
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs"

if [ "${1:-}" != "--no-sanitizers" ]; then
  echo "== sanitizers (address, undefined) =="
  # Debug (assertions on, Eigen's included) at -O1: at -O0 the Eigen-heavy tests ran about
  # 100x slower than in the normal build.
  cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g -O1" -DVDMSIM_SANITIZE=ON > /dev/null
  # Only what the sanitizer pass runs: the unit tests and the binary some of them call (the
  # long, e2e and bench executables run in the first pass only).
  cmake --build build-asan -j "$jobs" --target vdmsim vdmsim_tests vdmsim_render_tests
  # alloc_dealloc_mismatch=0: Debian's libfcl.so allocates BVH arrays with Eigen's aligned
  # operator new[] (malloc) while the header-instantiated ~BVHModel frees them with the plain
  # delete[]; both end in malloc/free, but ASan flags the pair inside FCL.
  # tests/lsan.supp: small records Mesa's OSMesa keeps after a context is destroyed.
  LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0" \
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:alloc_dealloc_mismatch=0 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-asan --output-on-failure -j "$jobs" -LE "long|e2e" -E NOT_BUILT
fi
