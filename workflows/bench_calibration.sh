#!/usr/bin/env bash
# Speed of target-based calibration, images to report: target_extractor and
# camera_calibrator on the 25 views (1920 x 1080) of a shared rendered set,
# both cores. (The published tool needs ~18 s to detect and ~1 s to
# calibrate the same views on this machine type; it is not packaged for
# Debian, so it is not run here.) Usage: workflows/bench_calibration.sh [SET_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/portcal ] || bash workflows/setup.sh >/dev/null
set_dir="${1:-../shared/datasets/rendered/chess_domeport}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
t0=$(date +%s.%N)
build/portcal target_extractor --log_level warn --database_path "$work/db.db" \
  --image_path "$set_dir/images" --ImageReader.camera_model RADIAL --ImageReader.single_camera 1
t1=$(date +%s.%N)
build/portcal camera_calibrator --log_level warn --database_path "$work/db.db" --output_path "$work/out"
t2=$(date +%s.%N)
awk -v a="$t0" -v b="$t1" -v c="$t2" -v n="$(ls "$set_dir/images" | wc -l)" 'BEGIN {
  printf "detection: %.2f s for %d images (%.3f s/image)\ncalibration: %.2f s\ntotal: %.2f s\n",
         b - a, n, (b - a) / n, c - b, c - a }'
