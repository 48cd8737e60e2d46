#!/usr/bin/env bash
# The nightly-sized reliability run (issue 27): the bad-input catalogue
# (tests/reliability/bad_inputs.tsv) and KILLS SIGKILLs at seeded moments
# of every database-writing stage (tests/reliability/kill_test.sh; ctest
# kills 3 per stage). The fuzzers' long runs are workflows/fuzz.sh.
# Usage: workflows/reliability.sh [KILLS=10] [SEED=1]
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/portcal ] || bash workflows/setup.sh >/dev/null
cmake --build build -j"$(nproc)" --target portcal bad_input_catalogue_test >/dev/null
build/tests/bad_input_catalogue_test --gtest_brief=1
bash tests/reliability/kill_test.sh "$(realpath build/portcal)" "${1:-10}" "${2:-1}"
