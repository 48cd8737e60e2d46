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
start=$SECONDS
# Each step on stderr with the time since the start.
say() { printf 'setup [%d:%02d] %s\n' $(((SECONDS - start) / 60)) $(((SECONDS - start) % 60)) "$*" >&2; }
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
if [ "${#missing[@]}" -eq 0 ]; then
  say "packages: all ${#packages[@]} present"
else
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  say "packages: installing ${#missing[@]} with apt-get (a few minutes): ${missing[*]}"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq "${missing[@]}"
fi

[ "$build" -eq 1 ] || exit 0
jobs="$(nproc 2>/dev/null || echo 2)"
mkdir -p build
say "configure: cmake, Release, into build/ (build/configure.log)"
if ! cmake -S . -B build -DCMAKE_BUILD_TYPE=Release > build/configure.log 2>&1; then
  tail -n 40 build/configure.log >&2
  say "configure FAILED (build/configure.log)"
  exit 1
fi
say "build: $jobs jobs; from scratch about 20 minutes on 2 cores, seconds when nothing changed (build/build.log)"
# The build's own lines go to the log; its progress here every 5 %.
set +o pipefail
cmake --build build -j"$jobs" 2>&1 | tee build/build.log | {
  last=-5
  while IFS= read -r line; do
    if [[ $line =~ ^\[\ *([0-9]+)%\] ]] && (( BASH_REMATCH[1] >= last + 5 )); then
      last=${BASH_REMATCH[1]}
      say "build: $last %"
    fi
  done
}
status=${PIPESTATUS[0]}
set -o pipefail
if [ "$status" -ne 0 ]; then
  grep -E "error|Error" build/build.log | head -n 30 >&2 || true
  say "build FAILED (build/build.log)"
  exit "$status"
fi
say "build: done, build/portcal"
# On the PATH, as `cmake --install` would put it, so that the docs' commands
# run as pasted: a link to this checkout's build (the last set-up wins).
link=/usr/local/bin/portcal
if [ -w /usr/local/bin ]; then
  ln -sfn "$PWD/build/portcal" "$link" && say "PATH: $link -> $PWD/build/portcal"
elif command -v sudo > /dev/null && sudo -n true 2> /dev/null; then
  sudo ln -sfn "$PWD/build/portcal" "$link" && say "PATH: $link -> $PWD/build/portcal"
else
  say "PATH: /usr/local/bin is not writable; run: export PATH=\"$PWD/build:\$PATH\""
fi
