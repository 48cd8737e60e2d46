#!/usr/bin/env bash
# The unit tests under AddressSanitizer and UndefinedBehaviorSanitizer
# (clang; any report fails the test that made it), in build-sanitize/ (shared
# with workflows/fuzz.sh). Not in CI: the instrumented build and run take
# ~2.5 hours on 2 cores (docs/benchmarks.md). Arguments go to ctest (e.g.
# -R Database).
# Usage: workflows/sanitize.sh [CTEST_ARGS...]
set -euo pipefail
cd "$(dirname "$0")/.."
build="${PORTCAL_SANITIZE_BUILD:-build-sanitize}"  # the clang tree
bash workflows/setup.sh --packages-only clang libclang-rt-14-dev chromium >/dev/null
CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DPORTCAL_SANITIZE=address,undefined -DPORTCAL_FUZZ=ON -DPORTCAL_BUILD_BENCHMARKS=OFF >/dev/null
cmake --build "$build" -j"$(nproc)"
# Leaks are not errors here: OpenCV, Ceres and yaml-cpp keep caches to exit.
export ASAN_OPTIONS=detect_leaks=0:halt_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
cd "$build"
ctest -L unit -j"$(nproc)" --timeout 3000 --output-on-failure "$@"
