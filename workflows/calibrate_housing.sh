#!/usr/bin/env bash
# Housing calibration: in-air intrinsics first, then the port from the
# underwater views with the intrinsics fixed. Copy and adapt.
# Usage: workflows/calibrate_housing.sh AIR_DIR WATER_DIR OUTPUT_DIR MODEL PARAMS COLS ROWS SQUARE_M [CAMERA_MODEL]
#   MODEL FLATPORT|DOMEPORT; PARAMS the 8 housing parameters in metres, comma
#   separated (constants: thickness, radius, indices; the rest is a guess);
#   your board: COLS x ROWS inner corners, square side in metres; COLMAP
#   camera model (default OPENCV).
set -euo pipefail
if [ "$#" -lt 8 ]; then
  echo "usage: $0 AIR_DIR WATER_DIR OUTPUT_DIR MODEL PARAMS COLS ROWS SQUARE_M [CAMERA_MODEL]" >&2
  exit 2
fi
air="$1"; water="$2"; out="$3"; model="$4"; params="$5"
cols="$6"; rows="$7"; square="$8"; camera_model="${9:-OPENCV}"
portcal="$(dirname "$0")/../build/portcal"
mkdir -p "$out/air" "$out/water"
"$portcal" target_extractor --database_path "$out/air/database.db" --image_path "$air" \
  --ImageReader.camera_model "$camera_model" --ImageReader.single_camera 1 \
  --Target.cols "$cols" --Target.rows "$rows" --Target.square_size "$square"
"$portcal" camera_calibrator --database_path "$out/air/database.db" --output_path "$out/air"
"$portcal" target_extractor --database_path "$out/water/database.db" --image_path "$water" \
  --ImageReader.camera_model "$camera_model" --ImageReader.single_camera 1 \
  --Target.cols "$cols" --Target.rows "$rows" --Target.square_size "$square"
"$portcal" housing_calibrator --database_path "$out/water/database.db" \
  --input_calibration "$out/air/calibration.yaml" --output_path "$out/water" \
  --Housing.model "$model" --Housing.params "$params"
cat "$out/water/calibration.txt"
