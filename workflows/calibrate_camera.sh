#!/usr/bin/env bash
# Camera calibration from chessboard images, end to end. Copy and adapt.
# Usage: workflows/calibrate_camera.sh IMAGE_DIR OUTPUT_DIR [COLS ROWS SQUARE_M MODEL]
#   COLS x ROWS inner corners (default 10 7), square side in metres (0.02),
#   COLMAP camera model (OPENCV).
set -euo pipefail
images="$1"; out="$2"
cols="${3:-10}"; rows="${4:-7}"; square="${5:-0.02}"; model="${6:-OPENCV}"
portcal="$(dirname "$0")/../build/portcal"
mkdir -p "$out"
"$portcal" target_extractor --database_path "$out/database.db" --image_path "$images" \
  --ImageReader.camera_model "$model" --ImageReader.single_camera 1 \
  --Target.cols "$cols" --Target.rows "$rows" --Target.square_size "$square"
"$portcal" camera_calibrator --database_path "$out/database.db" --output_path "$out" \
  --Calibration.drop_outlier_views 1
cat "$out/calibration.txt"
# Second opinion: mrcal on the same corners (needs a model mrcal can express:
# PINHOLE, RADIAL, OPENCV, FULL_OPENCV ...), 3-fold cross-validation. The
# last line says PASS or FAIL; details and heat maps in $out/cross_check/.
"$portcal" cross_check --database_path "$out/database.db" \
  --input_calibration "$out/calibration.yaml" --output_path "$out/cross_check" \
  --CrossCheck.folds 3 | tail -n 1
