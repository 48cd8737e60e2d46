#!/usr/bin/env bash
# The mapper against COLMAP's on one database, side by side: portcal's
# refractive_mapper with no housing (ordinary SfM through the same code) and
# `colmap mapper` (2 threads each, their default options otherwise), each
# timed alone, each model summarised by `colmap model_analyzer` (models,
# registered images, points, observations, mean reprojection error).
# Usage: workflows/bench_mapper_vs_colmap.sh DATABASE IMAGE_DIR [WORK_DIR]
# The database is copied first; neither run changes it.
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/portcal ] || bash workflows/setup.sh >/dev/null
if [ $# -lt 2 ]; then
  echo "usage: $0 DATABASE IMAGE_DIR [WORK_DIR]" >&2
  exit 2
fi
database="$(realpath "$1")"
images="$(realpath "$2")"
[ -f "$database" ] || { echo "$0: no database '$1'" >&2; exit 2; }
[ -d "$images" ] || { echo "$0: no image directory '$2'" >&2; exit 2; }
command -v colmap >/dev/null || { echo "$0: the colmap binary is not installed" >&2; exit 2; }
if [ -n "${3:-}" ]; then work="$3"; mkdir -p "$work"; else work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT; fi
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", b - a }'; }
summary() {  # the largest model, and how many there are
  local dir="$1" best="" best_n=-1 n
  if ! compgen -G "$dir/*/" >/dev/null; then echo "no model"; return; fi
  for model in "$dir"/*/; do
    n=$(colmap model_analyzer --path "$model" 2>&1 | awk -F': ' '/Registered images/ { print $2 }')
    if [ "${n:-0}" -gt "$best_n" ]; then best_n=$n; best=$model; fi
  done
  local count; count=$(find "$dir" -mindepth 1 -maxdepth 1 -type d | wc -l)
  colmap model_analyzer --path "$best" 2>&1 |
    awk -F': ' -v models="$count" '/Registered images|Points|Observations|Mean reprojection error/ {
      sub(/^.*\] /, "", $1); out = out sprintf("%s %s, ", $1, $2) }
      END { printf "%d model(s); largest: %s\n", models, substr(out, 1, length(out) - 2) }'
}

cp "$database" "$work/portcal.db"
cp "$database" "$work/colmap.db"
rm -rf "$work/portcal_sparse" "$work/colmap_sparse"
mkdir -p "$work/portcal_sparse" "$work/colmap_sparse"

t0=$(now)
build/portcal refractive_mapper --log_level warn --database_path "$work/portcal.db" \
  --output_path "$work/portcal_sparse" --num_threads 2
t1=$(now)
portcal_s=$(elapsed "$t0" "$t1")

t0=$(now)
colmap mapper --database_path "$work/colmap.db" --image_path "$images" --output_path "$work/colmap_sparse" \
  --Mapper.num_threads 2 >"$work/colmap_mapper.log" 2>&1
t1=$(now)
colmap_s=$(elapsed "$t0" "$t1")

echo "portcal refractive_mapper (no housing): ${portcal_s} s; $(summary "$work/portcal_sparse")"
echo "colmap mapper:                          ${colmap_s} s; $(summary "$work/colmap_sparse")"
awk -v p="$portcal_s" -v c="$colmap_s" 'BEGIN { printf "time ratio (portcal / colmap): %.2f\n", p / c }'
