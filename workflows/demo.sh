#!/usr/bin/env bash
# Set-up, then portcal's main job on a built-in default: render a small
# dome-port chessboard set with exact ground truth (portcal synthesize), then
# the calibration that exists so far: target_extractor (sub-pixel corners
# into the database) and camera_calibrator (an OPENCV model fitted to the
# underwater views, refraction absorbed), printed next to the truth; then
# the camera + dome model itself, imported from the refractive COLMAP fork's
# cameras.txt, projecting and back-projecting through the dome.
set -euo pipefail
cd "$(dirname "$0")/.."
bash workflows/setup.sh >/dev/null

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
portcal=build/portcal

echo "== Rendering a small dome-port chessboard set (8 views, 960 x 540, 4 x 4 supersampling)"
cat > "$work/dome_set.yaml" <<'CONFIG'
name: demo_domeport
description: Decentred dome port (10, 6, 2) mm, RADIAL camera, 10x7 inner-corner chessboard.
seed: 3
num_images: 8
camera: {model: RADIAL, width: 960, height: 540, params: [648.68, 480.0, 270.0, 0.0, 0.0]}
housing: {model: DOMEPORT, params: [0.01, 0.006, 0.002, 0.05, 0.006, 1.0, 1.473, 1.334]}
target: {type: chessboard, cols: 10, rows: 7, square_size: 0.02, margin: 0.015}
poses: {distance: [0.35, 0.9], tilt_max_deg: 40, roll_max_deg: 30}
render: {spp: 4, noise_sigma: 1.0}
CONFIG
"$portcal" synthesize --log_level warn --config "$work/dome_set.yaml" --output_path "$work/dome_set"
echo "-- $(ls "$work/dome_set/images" | wc -l) images and ground_truth.yaml in the set:"
sed -n '/^camera:/,/^stereo:/p' "$work/dome_set/ground_truth.yaml"
echo

echo "== target_extractor: chessboard corners of every view into a COLMAP database"
"$portcal" target_extractor --log_level warn --database_path "$work/demo.db" \
  --image_path "$work/dome_set/images" --ImageReader.camera_model OPENCV \
  --ImageReader.single_camera 1 --Target.cols 10 --Target.rows 7 --Target.square_size 0.02
echo "-- views with the board found: $(sqlite3 "$work/demo.db" 'SELECT count(*) FROM portcal_target_detections WHERE found = 1') of 8"
echo
echo "== camera_calibrator: OPENCV fitted to the underwater views (refraction absorbed by the lens model)"
"$portcal" camera_calibrator --log_level warn --database_path "$work/demo.db" --output_path "$work/calibration"
sed -n '/parameter/,/^RMS/p' "$work/calibration/calibration.txt"
echo "-- truth: f = 648.68 px, (cx, cy) = (480, 270) px behind a dome decentred by (10, 6, 2) mm;"
echo "   the housing calibrator (next) models the dome instead of absorbing it."
echo


echo "== A RADIAL camera behind a dome port decentred by (10, 6, 2) mm"
mkdir -p "$work/fork"
cat > "$work/fork/cameras.txt" <<'CAMERAS'
# CAMERA_ID MODEL WIDTH HEIGHT PARAMS[] HOUSING HOUSING_PARAMS[]
1 RADIAL 1920 1080 1297.3655 960 540 0 0 DOMEPORT 0.01 0.006 0.002 0.05 0.006 1.0 1.473 1.334
CAMERAS
: > "$work/fork/images.txt"
: > "$work/fork/points3D.txt"
"$portcal" model_converter --log_level warn --input_path "$work/fork" \
  --output_path "$work/model" --output_type TXT
echo "-- housings.txt written beside the COLMAP model:"
grep -v '^#' "$work/model/housings.txt"

echo
echo "== Chessboard corners 0.8 m in front of the camera, projected in air and through the dome"
awk 'BEGIN { for (r = 0; r < 3; ++r) for (c = 0; c < 4; ++c)
               printf "%g %g 0.8\n", -0.03 + 0.02 * c, -0.02 + 0.02 * r }' > "$work/corners.txt"
"$portcal" project_points --log_level warn --points_path "$work/corners.txt" \
  --Camera.model RADIAL --Camera.params 1297.3655,960,540,0,0 \
  --Camera.width 1920 --Camera.height 1080 > "$work/air.txt"
"$portcal" project_points --log_level warn --points_path "$work/corners.txt" \
  --input_path "$work/model" --camera_id 1 > "$work/dome.txt"
paste "$work/corners.txt" "$work/air.txt" "$work/dome.txt" | \
  awk '{printf "X=(%6.3f %6.3f %4.2f)  in air (%8.3f, %8.3f)  behind the dome (%8.3f, %8.3f)  shift %.2f px\n",
        $1, $2, $3, $4, $5, $6, $7, sqrt(($6-$4)^2 + ($7-$5)^2)}'

echo
echo "== Back-projection of the dome pixels: rays in water (origin on the outer glass surface)"
"$portcal" project_points --log_level warn --unproject 1 --points_path "$work/dome.txt" \
  --input_path "$work/model" --camera_id 1 | head -3
