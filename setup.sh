#!/usr/bin/env bash
# Sets vdmsim up on Debian 12: installs the Debian packages the program needs (if missing), then
# configures ./build and builds the program in it (vdmsim and its assimp module; ./test.sh
# builds the tests).  Usage: ./setup.sh [--no-install] [--no-build] [--test-packages]
#   --test-packages: also install what the tests need (./test.sh passes it)
set -euo pipefail
cd "$(dirname "$0")"

install=1
build=1
test_packages=0
for arg in "$@"; do
  case "$arg" in
    --no-install) install=0 ;;
    --no-build) build=0 ;;
    --test-packages) test_packages=1 ;;
    -h|--help) sed -n '2,5p' "$0"; exit 0 ;;
    *) echo "setup.sh: unknown option '$arg'" >&2; exit 2 ;;
  esac
done

# What building and running vdmsim needs (CHOLMOD and OpenBLAS: the FEM reference's fast direct
# solves; libdeflate: fast PNG compression; dpkg-dev and file: `cpack -G DEB`).
packages=(
  build-essential cmake ninja-build pkg-config dpkg-dev file
  libeigen3-dev libassimp-dev libcli11-dev libfcl-dev libyaml-cpp-dev libcgal-dev
  libpng-dev libdeflate-dev libosmesa6-dev libglm-dev libimgui-dev fonts-dejavu-core
  libsuitesparse-dev libopenblas0-serial gmsh libgmsh-dev
)
# What the tests need besides: GoogleTest, Bullet (the bench's comparison case), meshio (the
# mesh export read back), ffmpeg (`run --video`), Google Benchmark (-DVDMSIM_BENCHMARKS=ON).
test_package_list=(
  libgtest-dev libgmock-dev libbullet-dev python3-meshio ffmpeg libbenchmark-dev
)
[ "$test_packages" = 0 ] || packages+=("${test_package_list[@]}")

if [ "$install" = 1 ]; then
  start=$SECONDS
  missing=()
  for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
  done
  if [ "${#missing[@]}" -gt 0 ]; then
    echo "setup: installing ${missing[*]}"
    sudo_cmd=()
    [ "$(id -u)" = 0 ] || sudo_cmd=(sudo)
    "${sudo_cmd[@]}" apt-get update -qq
    DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
    echo "setup: packages installed in $((SECONDS - start)) s"
  else
    echo "setup: all Debian packages present"
  fi
fi

# A new ./build is a unity build, four of a target's files compiled as one source: the headers
# and inline code they share are compiled once per four files instead of once per file, and
# the first build of vdmsim takes about a third less CPU (docs/developing.md, "Build and CI
# time"). Four, not more: an edited file recompiles with its three neighbours. A ./build
# configured before keeps its setting (-DCMAKE_UNITY_BUILD=OFF: file by file). ./test.sh
# configures a new ./build the same way.
unity=()
[ -f build/CMakeCache.txt ] || unity=(-DCMAKE_UNITY_BUILD=ON -DCMAKE_UNITY_BUILD_BATCH_SIZE=4)

if [ "$build" = 1 ]; then
  start=$SECONDS
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo "${unity[@]}"
  cmake --build build -j "$(nproc)" --target vdmsim vdmsim_assimp
  echo "setup: built ./build/vdmsim in $((SECONDS - start)) s"
fi
