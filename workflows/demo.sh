#!/usr/bin/env bash
# Set-up, then portcal's main job on a built-in default: a dome-port
# calibration from rendered images with exact ground truth.
#   1. portcal synthesize: an in-air chessboard set and an underwater set of
#      the same camera behind a decentred dome port (8 views each, 960 x 540).
#   2. target_extractor + camera_calibrator on the in-air set: intrinsics.
#   3. target_extractor + housing_calibrator on the underwater set, solved
#      jointly with the in-air views: the dome's decentering, the intrinsics
#      refined by both sets, so that the dome's standard deviations include
#      the intrinsics' uncertainty.
#   4. The estimates next to the truth.
# Everything it makes stays in demo_output/ (replaced on the next run), the
# reports among it; a run that fails leaves the previous demo_output/ as it
# was.
set -euo pipefail
cd "$(dirname "$0")/.."
bash workflows/setup.sh >/dev/null

output="$PWD/demo_output"
work="$(mktemp -d "$PWD/.demo_output.XXXXXX")"
trap 'rm -rf "$work"' EXIT
portcal=build/portcal

camera='{model: RADIAL, width: 960, height: 540, params: [648.68, 480.0, 270.0, -0.08, 0.01]}'
dome='{model: DOMEPORT, params: [0.004, -0.002, 0.006, 0.05, 0.006, 1.0, 1.473, 1.334]}'
target='{type: chessboard, cols: 10, rows: 7, square_size: 0.02, margin: 0.015}'
for set in air dome; do
  housing="null"
  [ "$set" = dome ] && housing="$dome"
  cat > "$work/$set.yaml" <<CONFIG
name: demo_$set
seed: $([ "$set" = air ] && echo 1 || echo 2)
num_images: 8
camera: $camera
housing: $housing
target: $target
poses: {distance: [0.35, 0.9], tilt_max_deg: 45, roll_max_deg: 30}
render: {spp: 4, noise_sigma: 1.0}
CONFIG
done

echo "== 1. Rendering 8 in-air and 8 underwater views (dome decentred by (4, -2, 6) mm)"
"$portcal" synthesize --log_level warn --config "$work/air.yaml" --output_path "$work/air"
"$portcal" synthesize --log_level warn --config "$work/dome.yaml" --output_path "$work/dome"

echo "== 2. In air: target_extractor, camera_calibrator (RADIAL)"
"$portcal" target_extractor --log_level warn --database_path "$work/air.db" \
  --image_path "$work/air/images" --ImageReader.camera_model RADIAL \
  --ImageReader.single_camera 1 --Target.cols 10 --Target.rows 7 --Target.square_size 0.02
"$portcal" camera_calibrator --log_level warn --database_path "$work/air.db" \
  --output_path "$work/air_calibration" --image_path "$work/air/images"
sed -n '/^Verdict/,/^$/p' "$work/air_calibration/calibration.txt"
sed -n '/^  parameter /,/^RMS/p' "$work/air_calibration/calibration.txt"
echo "-- truth: f 648.68, cx 480, cy 270, k1 -0.08, k2 0.01"

echo
echo "== 3. Under water: target_extractor, housing_calibrator (DOMEPORT; radius, thickness, indices given),"
echo "      jointly with the in-air views"
"$portcal" target_extractor --log_level warn --database_path "$work/dome.db" \
  --image_path "$work/dome/images" --ImageReader.camera_model RADIAL \
  --ImageReader.single_camera 1 --Target.cols 10 --Target.rows 7 --Target.square_size 0.02
"$portcal" housing_calibrator --log_level warn --database_path "$work/dome.db" \
  --input_calibration "$work/air_calibration/calibration.yaml" --in_air_database_path "$work/air.db" \
  --output_path "$work/dome_calibration" --image_path "$work/dome/images" \
  --Housing.model DOMEPORT --Housing.params 0,0,0,0.05,0.006,1.0,1.473,1.334
sed -n '/^Verdict/,/^$/p' "$work/dome_calibration/calibration.txt"
sed -n '/^Housing/,/^RMS/p' "$work/dome_calibration/calibration.txt"
echo "-- truth: Cx 0.004, Cy -0.002, Cz 0.006 m"

rm -rf "$output"
mv "$work" "$output"
trap - EXIT
echo
echo "Everything is in $output:"
echo "  images and truth: air/, dome/ (ground_truth.yaml); databases: air.db, dome.db"
echo "  reports (calibration.txt to read, calibration.yaml with calibmar's keys and standard deviations):"
echo "    $output/air_calibration/calibration.txt"
echo "    $output/dome_calibration/calibration.txt"
echo "  pages (the verdict first, then coverage, residuals, the worst views, uncertainty, distortion, the dome to scale), open in a browser:"
echo "    $output/air_calibration/report.html"
echo "    $output/dome_calibration/report.html"
