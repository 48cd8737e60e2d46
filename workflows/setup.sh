#!/usr/bin/env bash
# Installs portcal's dependencies from Debian's packages (idempotent: only
# missing packages are installed, so a second run takes seconds) and builds
# portcal into build/ (Release). Used by test.sh and demo.sh; arguments are
# more packages to install (test.sh: the browser of the page test); with
# --packages-only first, nothing is built (fuzz.sh and sanitize.sh build
# their own clang tree).
set -euo pipefail
cd "$(dirname "$0")/.."
build=1
if [ "${1:-}" = "--packages-only" ]; then build=0; shift; fi

packages=(
  build-essential cmake ccache pkg-config
  libceres-dev libeigen3-dev libgoogle-glog-dev libsuitesparse-dev
  libopencv-dev libopencv-contrib-dev
  libsqlite3-dev sqlite3
  libboost-program-options-dev
  libmrcal-dev mrcal python3-mrcal
  libgtest-dev libbenchmark-dev
  libopengv-dev libyaml-cpp-dev libzip-dev
  libcpp-httplib-dev nlohmann-json3-dev
  libopenmpi-dev openmpi-bin libmetis-dev
  colmap
  "$@"
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done
if [ "${#missing[@]}" -gt 0 ]; then
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  echo "setup: installing ${missing[*]}" >&2
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}"
fi

[ "$build" -eq 1 ] || exit 0
jobs="$(nproc 2>/dev/null || echo 2)"
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j"$jobs"
