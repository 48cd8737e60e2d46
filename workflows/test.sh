#!/usr/bin/env bash
# Set-up (dependencies + build), then the whole test suite: unit, interop
# (against the real colmap binary) and accuracy tests.
set -euo pipefail
cd "$(dirname "$0")/.."
# chromium: the live page's browser test (tests/pipelines/stages/live_page_test.cc).
bash workflows/setup.sh chromium
cd build
ctest --output-on-failure -j"$(nproc 2>/dev/null || echo 2)" --timeout 1500
