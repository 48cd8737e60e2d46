#!/usr/bin/env bash
# The inputs the bad-input catalogue (bad_inputs.tsv) spoils, made once per
# run into DIR with portcal itself: a rendered stereo chessboard set (480 x 360,
# 6 frames), a database of each kind a stage reads (target corners of one
# camera and of the rig, SIFT features), a calibration of each kind, a sparse
# model with a housing, and the text files of pose_prior_importer and
# project_points. Every case runs in its own copy of DIR.
# Usage: make_fixture.sh PORTCAL DIR
set -euo pipefail
portcal="$1"; dir="$2"
mkdir -p "$dir"; cd "$dir"
q=(--log_level warn)

cat > set.yaml <<'YAML'
name: catalogue
seed: 27
num_images: 6
camera: {model: OPENCV, width: 480, height: 360, params: [420, 410, 243.5, 178.0, -0.05, 0.01, 0.0, 0.0]}
housing: null
stereo:
  cam2_from_cam1: {rotation_axis_angle_deg: [0, 1, 0, 2], translation: [-0.1, 0, 0]}
target: {type: chessboard, cols: 9, rows: 6, square_size: 0.03, margin: 0.02}
poses: {distance: [0.45, 0.8], tilt_max_deg: 35, roll_max_deg: 20, border_margin_px: 8}
render: {spp: 2, blur_sigma: 0.3, noise_sigma: 1.0}
YAML
"$portcal" synthesize "${q[@]}" --config set.yaml --output_path set
board=(--Target.cols 9 --Target.rows 6 --Target.square_size 0.03)
"$portcal" target_extractor "${q[@]}" --database_path cam1.db --image_path set/images/cam1 \
  --ImageReader.camera_model OPENCV --ImageReader.single_camera 1 "${board[@]}"
"$portcal" camera_calibrator "${q[@]}" --database_path cam1.db --output_path cal1
"$portcal" target_extractor "${q[@]}" --database_path rig.db --image_path set/images \
  --ImageReader.camera_model OPENCV --ImageReader.single_camera_per_folder 1 "${board[@]}"
"$portcal" feature_extractor "${q[@]}" --database_path feat.db --image_path set/images/cam1 \
  --ImageReader.single_camera 1
# ArUco markers for feature_masker: an ArUco grid seen in 3 views.
cat > markers.yaml <<'YAML'
name: markers
seed: 28
num_images: 3
camera: {model: SIMPLE_RADIAL, width: 400, height: 300, params: [380, 200.5, 150.5, -0.02]}
housing: null
target: {type: aruco_grid, markers_x: 3, markers_y: 2, marker_size: 0.05, marker_separation: 0.015,
         dictionary: DICT_4X4_50, first_marker: 0, margin: 0.02}
poses: {distance: [0.5, 0.7], tilt_max_deg: 30, roll_max_deg: 20, border_margin_px: 8}
render: {spp: 2, blur_sigma: 0.3, noise_sigma: 1.0}
YAML
"$portcal" synthesize "${q[@]}" --config markers.yaml --output_path markers
"$portcal" feature_extractor "${q[@]}" --database_path markers.db --image_path markers/images \
  --ImageReader.single_camera 1
cp feat.db matched.db
"$portcal" exhaustive_matcher "${q[@]}" --database_path matched.db
"$portcal" model_converter "${q[@]}" --input_path cal1/calibration.yaml --output_path cam1.cameramodel \
  --output_type CAMERAMODEL
"$portcal" model_converter "${q[@]}" --input_path cal1/calibration.yaml --output_path cam1_opencv.yaml \
  --output_type OPENCV_YAML

# A sparse model of two images of camera 1 behind a flat port, as text.
mkdir -p model
printf '1 OPENCV 480 360 420 410 243.5 178 -0.05 0.01 0 0\n' > model/cameras.txt
printf '1 1 0 0 0 0 0 0 1 img_001.png\n\n2 1 0 0 0 -0.1 0 0 1 img_002.png\n\n' > model/images.txt
: > model/points3D.txt
printf '1 FLATPORT 0 0 1 0.01 0.005 1.0 1.49 1.333\n' > model/housings.txt
"$portcal" model_converter "${q[@]}" --input_path model --output_path model_bin --output_type BIN

printf '0.1 0.2 1\n-0.1 0.05 2\n' > points.txt
for i in 1 2 3 4 5 6; do printf 'img_%03d.png %d 0 -2\n' "$i" "$i"; done > priors.txt

# Uncompressed 24-bit BMPs of any size: a 8 x 8 image (too small to hold a
# target) and a 64 x 48 one (not the camera's size).
le32() {  # a 32-bit little-endian integer as printf escapes
  printf '\\x%02x\\x%02x\\x%02x\\x%02x' $(($1 & 255)) $(($1 >> 8 & 255)) $(($1 >> 16 & 255)) $(($1 >> 24 & 255))
}
bmp() {  # WIDTH HEIGHT FILE: a gray 24-bit BMP
  local w="$1" h="$2" out="$3" row=$(( ($1 * 3 + 3) / 4 * 4 ))
  local data=$(( row * h ))
  {
    printf "BM$(le32 $((data + 54)))$(le32 0)$(le32 54)"                        # file header
    printf "$(le32 40)$(le32 "$w")$(le32 "$h")\\x01\\x00\\x18\\x00$(le32 0)"        # info: 1 plane, 24 bits
    printf "$(le32 "$data")$(le32 2835)$(le32 2835)$(le32 0)$(le32 0)"          # 72 dpi, no palette
    head -c "$data" /dev/zero | tr '\0' '\200'
  } > "$out"
}
bmp 8 8 tiny.bmp
bmp 64 48 small.bmp
