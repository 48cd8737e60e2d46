#!/usr/bin/env bash
# Speed of auto-calibration, side by side with COLMAP 3.8 in one run, on the
# 25 views (1920 x 1080) of a shared rendered 3-D target set (default: the
# flat-port one), both cores:
#   1. portcal auto_calibrator, images to report (goal <= 60 s; the
#      published tool: 3.5-4.5 min);
#   2. feature extraction: portcal feature_extractor against
#      colmap feature_extractor --SiftExtraction.use_gpu 0, same images,
#      same max_num_features, counts printed (goal: portcal >= 1.5x faster);
#   3. mapping on one database (portcal's extracted + masked + matched):
#      portcal refractive_mapper with no housing against colmap mapper
#      (goal: portcal <= 1.5x colmap's time).
# Prints the times and ratios. Usage: workflows/bench_autocalibration.sh [SET_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/portcal ] || bash workflows/setup.sh >/dev/null
set_dir="${1:-../shared/datasets/rendered/target3d_flatport}"
images="$set_dir/images"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", b - a }'; }
count() { sqlite3 "$1" "SELECT IFNULL(SUM(rows), 0) FROM keypoints;"; }

echo "== auto_calibrator (FLATPORT guess, markers 0.06 m) on $images"
t0=$(now)
build/portcal auto_calibrator --log_level warn --image_path "$images" --output_path "$work/auto" \
  --Housing.model FLATPORT --Housing.params "0,0,1,0.02,0.014,1,1.473,1.334" --Markers.side_length 0.06
t1=$(now)
echo "auto_calibrator: $(elapsed "$t0" "$t1") s"

echo "== feature extraction, 8192 features max, 2 threads"
t0=$(now)
build/portcal feature_extractor --log_level warn --database_path "$work/portcal.db" --image_path "$images" \
  --ImageReader.single_camera 1 --SiftExtraction.max_num_features 8192 --num_threads 2
t1=$(now)
portcal_s=$(elapsed "$t0" "$t1")
colmap_s=nan
colmap_n=0
if command -v colmap >/dev/null; then
  t0=$(now)
  colmap feature_extractor --database_path "$work/colmap.db" --image_path "$images" \
    --ImageReader.single_camera 1 --SiftExtraction.use_gpu 0 --SiftExtraction.num_threads 2 \
    --SiftExtraction.max_num_features 8192 >/dev/null 2>&1
  t1=$(now)
  colmap_s=$(elapsed "$t0" "$t1")
  colmap_n=$(count "$work/colmap.db")
fi
echo "portcal feature_extractor: ${portcal_s} s, $(count "$work/portcal.db") features"
echo "colmap feature_extractor:  ${colmap_s} s, ${colmap_n} features"
awk -v p="$portcal_s" -v c="$colmap_s" 'BEGIN { if (c != "nan") printf "extraction speed-up (colmap / portcal): %.2fx\n", c / p }'

echo "== mapping one database (portcal: extracted, masked, matched), no housing"
if command -v colmap >/dev/null; then
  workflows/bench_mapper_vs_colmap.sh "$work/auto/database.db" "$images" "$work/mappers"
else
  echo "colmap is not installed: no mapper comparison"
fi
