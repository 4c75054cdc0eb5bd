#!/usr/bin/env bash
# Sets vdmsim up on Debian 12: installs the Debian packages it needs (if missing), then
# configures and builds it in ./build.  Usage: ./setup.sh [--no-install] [--no-build]
set -euo pipefail
cd "$(dirname "$0")"

install=1
build=1
for arg in "$@"; do
  case "$arg" in
    --no-install) install=0 ;;
    --no-build) build=0 ;;
    -h|--help) sed -n '2,3p' "$0"; exit 0 ;;
    *) echo "setup.sh: unknown option '$arg'" >&2; exit 2 ;;
  esac
done

packages=(
  build-essential cmake ninja-build pkg-config dpkg-dev file
  libeigen3-dev libassimp-dev libcli11-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libfcl-dev libyaml-cpp-dev libpng-dev libdeflate-dev libosmesa6-dev libglm-dev libimgui-dev
  fonts-dejavu-core ffmpeg gmsh libgmsh-dev libsuitesparse-dev libopenblas0-serial libbullet-dev
  python3-meshio libcgal-dev
)

if [ "$install" = 1 ]; then
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
  else
    echo "setup: all Debian packages present"
  fi
fi

if [ "$build" = 1 ]; then
  cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo
  cmake --build build -j "$(nproc)"
  echo "setup: built ./build/vdmsim"
fi
