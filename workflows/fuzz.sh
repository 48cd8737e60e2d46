#!/usr/bin/env bash
# libFuzzer runs of every parser of user files (tests/fuzz/*_fuzzer.cc), built
# with clang, AddressSanitizer and UndefinedBehaviorSanitizer into
# build-sanitize/ (shared with workflows/sanitize.sh). Each target starts
# from its seed corpus in tests/fuzz/corpus and runs RUNS executions (default
# 10 million); a crash, a sanitizer report or an exception other than
# portcal's stops it and leaves the input in build-sanitize/fuzz/TARGET/ (make
# it a file of tests/fuzz/regressions/TARGET, which ctest replays). Prints a
# table: target, executions, seconds, coverage, result. Do not pause a run
# (kill -STOP): libFuzzer's 1200 s timeout counts wall time, so a long pause
# is reported as a hang (replay the timeout-* input to tell).
# Beside a benchmark, start it niced in a session of its own (`setsid nice
# -n 19 workflows/fuzz.sh ...`): Linux' autogroups weigh sessions against
# each other before nice counts, so a fuzzer alone in its session would take
# a full core from the benchmark whatever its nice (docs/scale.md); as the
# leader of its session it gives the session's group its own nice.
# Usage: workflows/fuzz.sh [RUNS=10000000] [TARGET...]; PORTCAL_FUZZ_SLICE
# (50000) executions per libFuzzer process.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ "$(nice)" -gt 0 ] && [ "$(ps -o sid= -p $$ | tr -d ' ')" = "$$" ] && [ -w /proc/self/autogroup ]; then
  echo "$(nice)" > /proc/self/autogroup
fi
build="${PORTCAL_SANITIZE_BUILD:-build-sanitize}"  # the clang tree
runs="${1:-10000000}"; shift || true
slice_runs="${PORTCAL_FUZZ_SLICE:-50000}"  # executions per process
targets=("$@")
if [ "${#targets[@]}" -eq 0 ]; then
  targets=(pose_priors housings points_file cameramodel sparse_model_binary sparse_model_text opencv_yaml
           dataset_config database_blobs calibration_file ground_truth stereo_calibration model_rigs)
fi
bash workflows/setup.sh --packages-only clang libclang-rt-14-dev >/dev/null
# One configure and build at a time on the tree: two runs started together
# (one per core) otherwise collide in CMake's try_compile folders.
mkdir -p "$build"
(
  flock 9
  CC=clang CXX=clang++ cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DPORTCAL_SANITIZE=address,undefined -DPORTCAL_FUZZ=ON -DPORTCAL_BUILD_BENCHMARKS=OFF >/dev/null
  cmake --build "$build" -j"$(nproc)" --target "${targets[@]/%/_fuzzer}" >/dev/null
) 9> "$build/.fuzz_build.lock"
# The targets write their input to a file each run: tmpfs, not the disk.
export TMPDIR=/dev/shm
# No leak check: OpenCV's and yaml-cpp's caches live to the end. No
# allocation stacks: recording them at every malloc cost a fifth of the YAML
# targets' time (docs/benchmarks.md); a report still names the bad access
# and its stack, and replaying the saved input gives the rest.
export ASAN_OPTIONS=detect_leaks=0:malloc_context_size=0
printf '%-20s %12s %8s %8s  %s\n' target executions seconds coverage result
status=0
for target in "${targets[@]}"; do
  work="$build/fuzz/$target"
  mkdir -p "$work/corpus"
  cp -n "tests/fuzz/corpus/$target"/* "$work/corpus/" 2>/dev/null || true
  # Inputs up to twice the largest seed (4 KB at least): longer ones only
  # slow the run down.
  max_len=$(( $(ls -S -l "tests/fuzz/corpus/$target" | awk 'NR==2 {print $5}') * 2 ))
  [ "$max_len" -ge 4096 ] || max_len=4096
  start=$(date +%s)
  # In slices of fresh processes over the one corpus folder: a libFuzzer
  # process under ASan slows as it runs (ground_truth after 5 million
  # executions: 431 a CPU second; a new process on the same corpus 1950,
  # not slowing over its 60 000; docs/benchmarks.md). Each slice appends
  # its output to the log.
  : > "$work/log.txt"
  done_runs=0; rc=0
  while [ "$done_runs" -lt "$runs" ]; do
    slice=$(( runs - done_runs < slice_runs ? runs - done_runs : slice_runs ))
    "$build/tests/${target}_fuzzer" -runs="$slice" -max_len="$max_len" -print_final_stats=1 \
      -artifact_prefix="$work/" "$work/corpus" > "$work/slice.txt" 2>&1 || rc=$?
    cat "$work/slice.txt" >> "$work/log.txt"
    slice_done=$(grep -a -oP 'stat::number_of_executed_units:\s*\K[0-9]+' "$work/slice.txt" || echo 0)
    done_runs=$(( done_runs + slice_done ))
    [ "$rc" -eq 0 ] && [ "$slice_done" -gt 0 ] || break
  done
  if [ "$rc" -eq 0 ]; then
    result="0 crashes, 0 sanitizer reports"
  else
    result="FAILED: see $work/log.txt and $work/crash-*"; status=1
  fi
  coverage=$(grep -a -oP 'cov: \K[0-9]+' "$work/log.txt" | tail -1 || echo '?')
  printf '%-20s %12s %8s %8s  %s\n' "$target" "$done_runs" $(( $(date +%s) - start )) "$coverage" "$result"
done
exit "$status"
