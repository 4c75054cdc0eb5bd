#!/usr/bin/env bash
# Builds and runs the whole test suite: installs what the tests need (./setup.sh
# --test-packages, when something is missing), the normal build and every test, then the unit
# tests built with AddressSanitizer and UndefinedBehaviorSanitizer (their own CMake
# configuration, build-asan/). Prints how long each phase took.
# Usage: ./test.sh [--no-sanitizers] [--no-install]
set -euo pipefail
cd "$(dirname "$0")"
jobs="$(nproc)"

sanitizers=1
install=1
for arg in "$@"; do
  case "$arg" in
    --no-sanitizers) sanitizers=0 ;;
    --no-install) install=0 ;;
    -h|--help) sed -n '2,6p' "$0"; exit 0 ;;
    *) echo "test.sh: unknown option '$arg'" >&2; exit 2 ;;
  esac
done

# phase NAME COMMAND...: runs the command, prints its wall time; the summary at the end lists them.
phases=()
running=""
phase() {
  local name="$1" start=$SECONDS
  shift
  echo "== test.sh: $name"
  running="$name"
  "$@"
  running=""
  phases+=("$(printf '%6d s  %s' $((SECONDS - start)) "$name")")
  echo "== test.sh: $name: $((SECONDS - start)) s"
}
# The summary, also when a phase fails (then named as the one that failed).
summary() {
  echo "== test.sh: wall time per phase"
  [ "${#phases[@]}" = 0 ] || printf '%s\n' "${phases[@]}"
  [ -z "$running" ] || echo "        $running: failed"
  printf '%6d s  total\n' $((SECONDS - total_start))
}
total_start=$SECONDS
trap summary EXIT

if [ "$install" = 1 ]; then
  phase "packages" ./setup.sh --no-build --test-packages
fi

# The normal build: the same configuration as ./setup.sh's (whose objects are reused), now with
# the tests. A new ./build is a unity build of four files a compile, as ./setup.sh makes it; a
# ./build configured before keeps its setting. The long and e2e tests start first (their COST,
# tests/CMakeLists.txt).
unity=()
[ -f build/CMakeCache.txt ] || unity=(-DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=4)
phase "configure" cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "${unity[@]}" > /dev/null
phase "build" cmake --build build -j "$jobs"
phase "tests" ctest --test-dir build --output-on-failure -j "$jobs" --no-tests=error

if [ "$sanitizers" = 1 ]; then
  # Debug (assertions on, Eigen's included) at -O1: at -O0 the Eigen-heavy tests ran about
  # 100x slower than in the normal build. -g1: line tables, all a sanitizer's stack trace
  # shows, at less compile time than -g. A unity build (eight files a compile): the templates
  # and inline functions they share are instrumented and compiled once per batch, not once per
  # file (docs/developing.md, "Build and CI time"); this folder is rebuilt whole more often
  # than edited file by file.
  phase "sanitizer configure" cmake -S . -B build-asan -G Ninja -DCMAKE_BUILD_TYPE=Debug \
    -DCMAKE_CXX_FLAGS_DEBUG="-g1 -O1" -DVDMSIM_SANITIZE=ON \
    -DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=8 > /dev/null
  # Only what the sanitizer pass runs: the unit tests and the binary some of them call (the
  # long, e2e and bench executables run in the first pass only, and so do the unit tests
  # labelled numerics: tests/numerics_labels.cmake).
  phase "sanitizer build" cmake --build build-asan -j "$jobs" --target vdmsim vdmsim_tests vdmsim_render_tests
  # alloc_dealloc_mismatch=0: Debian's libfcl.so allocates BVH arrays with Eigen's aligned
  # operator new[] (malloc) while the header-instantiated ~BVHModel frees them with the plain
  # delete[]; both end in malloc/free, but ASan flags the pair inside FCL.
  # tests/lsan.supp: small records Mesa's OSMesa keeps after a context is destroyed.
  phase "sanitizer tests" env \
    LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0" \
    ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:alloc_dealloc_mismatch=0 \
    UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build-asan --output-on-failure -j "$jobs" --no-tests=error -LE "long|e2e|numerics" -E NOT_BUILT
fi
