#!/usr/bin/env bash
# Stereo rig calibration in air: RIG_DIR holds one folder per camera (e.g.
# cam1/, cam2/) with the same file names for the same frame. Copy and adapt;
# behind housings, give --input_calibration1/2 from housing_calibrator.
# Usage: workflows/calibrate_stereo.sh RIG_DIR OUTPUT_DIR COLS ROWS SQUARE_M [MODEL]
#   your board: COLS x ROWS inner corners, square side in metres.
set -euo pipefail
if [ "$#" -lt 5 ]; then
  echo "usage: $0 RIG_DIR OUTPUT_DIR COLS ROWS SQUARE_M [MODEL]  (your board's inner corners and square side in metres)" >&2
  exit 2
fi
rig="$1"; out="$2"
cols="$3"; rows="$4"; square="$5"; model="${6:-OPENCV}"
portcal="$(dirname "$0")/../build/portcal"
mkdir -p "$out"
"$portcal" target_extractor --database_path "$out/database.db" --image_path "$rig" \
  --ImageReader.camera_model "$model" --ImageReader.single_camera_per_folder 1 \
  --Target.cols "$cols" --Target.rows "$rows" --Target.square_size "$square"
"$portcal" stereo_calibrator --database_path "$out/database.db" --output_path "$out" \
  --Stereo.refine_intrinsics 1
cat "$out/calibration.txt"
