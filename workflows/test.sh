#!/usr/bin/env bash
# Set-up (dependencies + build), then the whole test suite: unit, interop
# (against the real colmap binary) and accuracy tests.
set -euo pipefail
cd "$(dirname "$0")/.."
# chromium: the live page's browser test (tests/pipelines/stages/live_page_test.cc);
# clang-format: the format check (tests/tools/format_check.sh).
bash workflows/setup.sh chromium clang-format
cd build
jobs="$(nproc 2>/dev/null || echo 2)"
echo "test: ctest, $jobs at a time (about 20 minutes on 2 cores; a line per test as it ends)" >&2
start=$SECONDS
status=0
ctest --output-on-failure -j"$jobs" --timeout 1500 || status=$?
echo "test: done in $(((SECONDS - start) / 60)) min $(((SECONDS - start) % 60)) s, exit $status" >&2
exit "$status"
