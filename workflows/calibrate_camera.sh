#!/usr/bin/env bash
# Camera calibration from chessboard images, end to end. Copy and adapt.
# Usage: workflows/calibrate_camera.sh IMAGE_DIR OUTPUT_DIR COLS ROWS SQUARE_M [MODEL]
#   your board: COLS x ROWS inner corners, square side in metres (e.g. 0.03
#   for 30 mm); COLMAP camera model (default OPENCV).
set -euo pipefail
if [ "$#" -lt 5 ]; then
  echo "usage: $0 IMAGE_DIR OUTPUT_DIR COLS ROWS SQUARE_M [MODEL]  (your board's inner corners and square side in metres)" >&2
  exit 2
fi
images="$1"; out="$2"
cols="$3"; rows="$4"; square="$5"; model="${6:-OPENCV}"
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
