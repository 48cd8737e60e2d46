#!/usr/bin/env bash
# SIGKILL at seeded random moments of every stage that writes the database
# (issue 27): after each kill the database passes PRAGMA integrity_check,
# holds either all of the stage's rows or none of them (its dump equals the
# one before the stage or the one after an uninterrupted run; a stage that
# creates its database may leave it empty), and a rerun of a rolled-back
# stage gives exactly the uninterrupted run's rows.
# Usage: kill_test.sh PORTCAL KILLS_PER_STAGE SEED [WORK]
#   (ctest: 3 kills per stage; workflows/reliability.sh: 10 or more)
set -euo pipefail
portcal="$1"; kills="$2"; seed="$3"
here="$(cd "$(dirname "$0")" && pwd)"
work="${4:-$(mktemp -d)}"
[ -n "${4:-}" ] || trap 'rm -rf "$work"' EXIT
RANDOM="$seed"
bash "$here/make_fixture.sh" "$portcal" "$work/fixture" >/dev/null
cd "$work"
board=(--Target.cols 9 --Target.rows 6 --Target.square_size 0.03)
failures=0; total_kills=0; complete=0; rolled_back=0

# The rows of a database but the run log (a rerun logs itself again), and
# the number of logged runs.
rows() {
  sqlite3 "$1" .dump |
    grep -v -e '^INSERT INTO portcal_stage_log' -e "^INSERT INTO sqlite_sequence VALUES('portcal_stage_log'"
}
runs() { sqlite3 "$1" 'SELECT count(*) FROM portcal_stage_log' 2>/dev/null || echo none; }

fail() { echo "FAIL $*" >&2; failures=$((failures + 1)); }

# check_stage NAME INPUT_DB COMMAND...: COMMAND (with @DB for the database)
# run once whole, then KILLS times killed after a random fraction of its
# whole run's time and rerun.
check_stage() {
  local name="$1" input="$2"; shift 2
  local cmd=("$@") db="$work/$name.db"
  local run=("${cmd[@]/@DB/$db}")
  # Before a stage that creates its database: an empty one (a kill may come
  # after the schema is made and before the stage's transaction).
  if [ -n "$input" ]; then
    cp "$input" "$db"
  else
    rm -f "$db"
    "$portcal" database_creator --database_path "$db" >/dev/null 2>&1
  fi
  local before before_runs; before="$(rows "$db")"; before_runs="$(runs "$db")"
  [ -n "$input" ] || rm -f "$db"
  local start end; start=$(date +%s%N)
  "${run[@]}" >/dev/null 2>&1 || { fail "$name: the uninterrupted run failed: ${run[*]}"; return; }
  end=$(date +%s%N)
  local whole_ms=$(( (end - start) / 1000000 ))
  local after after_runs; after="$(rows "$db")"; after_runs="$(runs "$db")"
  local k
  for ((k = 1; k <= kills; k++)); do
    if [ -n "$input" ]; then cp "$input" "$db"; else rm -f "$db"; fi
    rm -f "$db-journal"
    local at_ms=$(( RANDOM % (whole_ms > 1 ? whole_ms : 1) ))
    "${run[@]}" >/dev/null 2>&1 &
    local pid=$!
    sleep "$(printf '%d.%03d' $((at_ms / 1000)) $((at_ms % 1000)))"
    kill -KILL "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
    total_kills=$((total_kills + 1))
    local tables=0
    [ -f "$db" ] && tables="$(sqlite3 "$db" 'SELECT count(*) FROM sqlite_master')"
    if [ -f "$db" ] && { [ -n "$input" ] || [ "$tables" -gt 0 ]; }; then
      local integrity; integrity="$(sqlite3 "$db" 'PRAGMA integrity_check')"
      [ "$integrity" = "ok" ] || fail "$name: kill $k at ${at_ms} ms: integrity_check: $integrity"
      local now now_runs; now="$(rows "$db")"; now_runs="$(runs "$db")"
      # All or nothing: the rows before with no new run logged, or all the
      # rows of the whole run with its log row.
      if ! { [ "$now" = "$before" ] && [ "$now_runs" = "$before_runs" ]; } &&
         ! { [ "$now" = "$after" ] && [ "$now_runs" = "$after_runs" ]; }; then
        fail "$name: kill $k at ${at_ms} ms: the database holds part of the stage's rows"
        diff <(echo "$before") <(echo "$now") | head -5 >&2 || true
      fi
    elif [ -n "$input" ]; then
      fail "$name: kill $k at ${at_ms} ms: the database is gone"
    fi
    # A run killed after its commit is complete: a rerun would be a second
    # run (a calibrator would start from its own result).
    if [ -f "$db" ] && [ "$tables" -gt 0 ] && [ "$(rows "$db")" = "$after" ]; then
      complete=$((complete + 1))
      continue
    fi
    rolled_back=$((rolled_back + 1))
    "${run[@]}" >/dev/null 2>&1 || { fail "$name: kill $k at ${at_ms} ms: the rerun failed"; continue; }
    if [ "$(rows "$db")" != "$after" ]; then
      fail "$name: kill $k at ${at_ms} ms: the rerun differs from an uninterrupted run"
      diff <(echo "$after") <(rows "$db") | cut -c1-160 | head -5 >&2 || true
    fi
  done
  echo "$name: $kills kills within its ${whole_ms} ms" >&2
}

# check_new_file NAME OUTPUT COMMAND...: a stage that writes a new database
# at OUTPUT (refusing an existing one), killed as above: OUTPUT is then
# absent or the whole of an uninterrupted run's, and a rerun succeeds.
check_new_file() {
  local name="$1" out="$2"; shift 2
  rm -f "$out"*
  local start end; start=$(date +%s%N)
  "$@" >/dev/null 2>&1 || { fail "$name: the uninterrupted run failed: $*"; return; }
  end=$(date +%s%N)
  local whole_ms=$(( (end - start) / 1000000 ))
  local after; after="$(rows "$out")"
  local k
  for ((k = 1; k <= kills; k++)); do
    rm -f "$out"
    local at_ms=$(( RANDOM % (whole_ms > 1 ? whole_ms : 1) ))
    "$@" >/dev/null 2>&1 &
    local pid=$!
    sleep "$(printf '%d.%03d' $((at_ms / 1000)) $((at_ms % 1000)))"
    kill -KILL "$pid" 2>/dev/null || true
    wait "$pid" 2>/dev/null || true
    total_kills=$((total_kills + 1))
    if [ -f "$out" ]; then
      complete=$((complete + 1))
      [ "$(sqlite3 "$out" 'PRAGMA integrity_check')" = "ok" ] || fail "$name: kill $k at ${at_ms} ms: damaged $out"
      [ "$(rows "$out")" = "$after" ] || fail "$name: kill $k at ${at_ms} ms: $out holds part of the run's rows"
      continue
    fi
    rolled_back=$((rolled_back + 1))
    "$@" >/dev/null 2>&1 || { fail "$name: kill $k at ${at_ms} ms: the rerun failed"; continue; }
    [ "$(rows "$out")" = "$after" ] || fail "$name: kill $k at ${at_ms} ms: the rerun differs from an uninterrupted run"
  done
  echo "$name: $kills kills within its ${whole_ms} ms" >&2
}

f="$work/fixture"
check_stage database_creator "" "$portcal" database_creator --database_path @DB
check_stage target_extractor "" "$portcal" target_extractor --database_path @DB --image_path "$f/set/images" \
  --ImageReader.single_camera_per_folder 1 --ImageReader.camera_model OPENCV "${board[@]}"
check_stage feature_extractor "" "$portcal" feature_extractor --database_path @DB --image_path "$f/set/images/cam1" \
  --ImageReader.single_camera 1
check_stage feature_masker "$f/markers.db" "$portcal" feature_masker --database_path @DB \
  --image_path "$f/markers/images"
check_stage exhaustive_matcher "$f/feat.db" "$portcal" exhaustive_matcher --database_path @DB
check_stage sequential_matcher "$f/feat.db" "$portcal" sequential_matcher --database_path @DB \
  --SequentialMatching.overlap 3
check_stage pose_prior_importer "$f/feat.db" "$portcal" pose_prior_importer --database_path @DB \
  --input_path "$f/priors.txt"
check_stage database_converter "$f/matched.db" "$portcal" database_converter --database_path @DB \
  --Database.colmap_version 4.1
check_new_file database_converter_output "$work/converted.db" "$portcal" database_converter \
  --database_path "$f/matched.db" --output_path "$work/converted.db" --Database.colmap_version 4.1
check_new_file database_merger "$work/merged.db" "$portcal" database_merger \
  --database_path1 "$f/matched.db" --database_path2 "$f/rig.db" --merged_database_path "$work/merged.db"
# The calibrators on one thread: with two, Ceres sums its threads' costs in
# varying order and the last bits of the parameters vary from run to run.
check_stage camera_calibrator "$f/cam1.db" "$portcal" camera_calibrator --database_path @DB \
  --output_path "$work/cal" --update_database 1 --num_threads 1
check_stage housing_calibrator "$f/cam1.db" "$portcal" housing_calibrator --database_path @DB \
  --input_calibration "$f/cal1/calibration.yaml" --output_path "$work/housing" --update_database 1 \
  --Housing.model FLATPORT --Housing.params 0,0,1,0.01,0.005,1.0,1.0,1.0 --Calibration.initialize_from_data 0 \
  --num_threads 1

echo "$total_kills kills ($rolled_back rolled back and rerun, $complete after the commit), $failures failures" >&2
[ "$failures" -eq 0 ]
