#!/usr/bin/env bash
# feature_extractor and the matchers in one process against the same under
# `mpirun -np 2` (pipelines/distributed/), on portcal's rendered lawnmower
# survey (960 x 540, as bench_survey.sh): the same cores either way (one
# process of 2 threads; 2 ranks of 1 thread), so the ratio is what the
# sharding costs or saves on one machine: shard copies, merges, the second
# listing of the images and pairs. Prints each stage's seconds side by side
# with the ratio, and whether the two databases hold the same rows (every
# table but the stage log).
# Usage: workflows/bench_mpi.sh [NUM_IMAGES=200] [WORK_DIR=temporary]
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/portcal ] || bash workflows/setup.sh >/dev/null
n="${1:-200}"
if [ -n "${2:-}" ]; then work="$2"; mkdir -p "$work"; else work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT; fi
P="$PWD/build/portcal"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
source workflows/survey_common.sh
survey_yaml survey_mpi "$n" > "$work/survey.yaml"
cd "$work"
[ -f set/ground_truth.yaml ] || "$P" synthesize --log_level warn --config survey.yaml --output_path set --seed 3
seconds() {  # runs the command, prints its wall time in seconds
  local t0; t0=$(date +%s%N); "$@" >/dev/null 2>&1
  awk -v t0="$t0" -v t1="$(date +%s%N)" 'BEGIN { printf "%.2f", (t1 - t0) / 1e9 }'
}
declare -A time
for run in one mpi; do
  if [ "$run" = one ]; then launch=(); threads=2; else launch=(mpirun -np 2 --oversubscribe); threads=1; fi
  db="$run.db"; rm -f "$db"
  time[$run,extract]=$(seconds "${launch[@]}" "$P" feature_extractor --database_path "$db" --image_path set/images \
    --ImageReader.single_camera 1 --ImageReader.camera_model RADIAL --ImageReader.camera_params 700,480,270,0,0 \
    --num_threads $threads)
  "$P" pose_prior_importer --log_level warn --database_path "$db" --input_path set/navigation.txt
  time[$run,sequential]=$(seconds "${launch[@]}" "$P" sequential_matcher --database_path "$db" \
    --SequentialMatching.overlap 5 --SequentialMatching.quadratic_overlap 0 --num_threads $threads)
  time[$run,spatial]=$(seconds "${launch[@]}" "$P" spatial_matcher --database_path "$db" --num_threads $threads)
done
rows() {
  for table in $(sqlite3 "$1" "SELECT name FROM sqlite_master WHERE type='table' AND name != 'portcal_stage_log' ORDER BY name"); do
    sqlite3 "$1" "SELECT * FROM $table ORDER BY 1, 2"
  done | md5sum | cut -d' ' -f1
}
same=no; [ "$(rows one.db)" = "$(rows mpi.db)" ] && same=yes
printf '%s images\n%-12s %14s %14s %8s\n' "$n" stage "1 process, s" "2 ranks, s" ratio
for stage in extract sequential spatial; do
  printf '%-12s %14s %14s %8s\n' "$stage" "${time[one,$stage]}" "${time[mpi,$stage]}" \
    "$(awk -v a="${time[mpi,$stage]}" -v b="${time[one,$stage]}" 'BEGIN { printf "%.2f", a / b }')"
done
echo "same rows in every table: $same"
