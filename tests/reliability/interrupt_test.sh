#!/usr/bin/env bash
# SIGINT and SIGTERM at seeded random moments of the stages that write an
# output folder or file (issue 70): each run either stops with exit 130
# and leaves its output as it was before (here: absent), or had already
# finished and exits 0 with the whole output of an uninterrupted run. Never
# exit 0 with a part, nor 130 with anything left.
# Usage: interrupt_test.sh PORTCAL SIGNALS_PER_STAGE SEED [WORK]
set -euo pipefail
# Job control: without it bash starts background jobs with SIGINT ignored,
# which would hide a stop asked for before main() sets its handler.
set -m
portcal="$1"; signals="$2"; seed="$3"
here="$(cd "$(dirname "$0")" && pwd)"
work="${4:-$(mktemp -d)}"
[ -n "${4:-}" ] || trap 'rm -rf "$work"' EXIT
RANDOM="$seed"
bash "$here/make_fixture.sh" "$portcal" "$work/fixture" >/dev/null
cd "$work"
failures=0; total=0; stopped=0; finished=0
fail() { echo "FAIL $*" >&2; failures=$((failures + 1)); }
listing() { [ -e "$1" ] && (cd "$1" 2>/dev/null && find . -type f | sort) || { [ -f "$1" ] && echo file; } || true; }

# check_stage NAME OUTPUT COMMAND...: OUTPUT is what the command makes.
check_stage() {
  local name="$1" out="$2"; shift 2
  rm -rf "$out" "$out".*
  local start end; start=$(date +%s%N)
  "$@" >/dev/null 2>&1 || { fail "$name: the uninterrupted run failed: $*"; return; }
  end=$(date +%s%N)
  local whole_ms=$(( (end - start) / 1000000 )) whole; whole="$(listing "$out")"
  local k
  for ((k = 1; k <= signals; k++)); do
    rm -rf "$out" "$out".*
    local at_ms=$(( RANDOM % (whole_ms > 1 ? whole_ms : 1) )) signal=INT
    [ $((k % 2)) -eq 0 ] && signal=TERM
    "$@" >/dev/null 2>"$work/stderr" &
    local pid=$!
    sleep "$(printf '%d.%03d' $((at_ms / 1000)) $((at_ms % 1000)))"
    kill -"$signal" "$pid" 2>/dev/null || true
    local code=0; wait "$pid" || code=$?
    total=$((total + 1))
    if [ "$code" -eq 130 ] || [ "$code" -eq 143 ]; then
      stopped=$((stopped + 1))
      [ -z "$(listing "$out")" ] || fail "$name: SIG$signal at ${at_ms} ms: exit $code with $out left behind"
    elif [ "$code" -eq 0 ]; then
      finished=$((finished + 1))
      [ "$(listing "$out")" = "$whole" ] || fail "$name: SIG$signal at ${at_ms} ms: exit 0 with a partial $out"
    else
      fail "$name: SIG$signal at ${at_ms} ms: exit $code: $(tail -1 "$work/stderr")"
    fi
  done
  echo "$name: $signals signals within its ${whole_ms} ms" >&2
}

f="$work/fixture"
check_stage image_undistorter "$work/und" "$portcal" image_undistorter --input_path "$f/model" \
  --image_path "$f/set/images/cam1" --output_path "$work/und" --Undistort.distance 1
check_stage synthesize "$work/syn" "$portcal" synthesize --config "$f/set.yaml" --output_path "$work/syn"
check_stage camera_calibrator "$work/cal" "$portcal" camera_calibrator --database_path "$f/cam1.db" \
  --output_path "$work/cal" --num_threads 1
check_stage model_converter "$work/conv" "$portcal" model_converter --input_path "$f/model" \
  --output_path "$work/conv" --output_type BIN
check_stage database_converter "$work/conv.db" "$portcal" database_converter --database_path "$f/matched.db" \
  --output_path "$work/conv.db" --Database.colmap_version 4.1

echo "$total signals ($stopped stopped, $finished after the end), $failures failures" >&2
[ "$failures" -eq 0 ]
