#!/usr/bin/env bash
# The commands of docs/quickstart.md, as written there, on the real dome set
# of ../shared (or DATA): in-air calibration, the mrcal cross-check, the
# dome port solved jointly with the in-air views, the exports. A test checks that
# every portcal command of the page stands here.
# Usage: workflows/quickstart.sh [DATA=../shared/datasets/real-dome] [WORK=a temporary folder]
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/portcal ] || bash workflows/setup.sh >/dev/null
data="$(realpath "${1:-../shared/datasets/real-dome}")"
work="${2:-$(mktemp -d)}"
mkdir -p "$work"
portcal="$(realpath build/portcal)"
cd "$work"
ln -sfn "$data" real-dome

echo "== 1. In air: corners, intrinsics (OPENCV), the report"
"$portcal" target_extractor --database_path air.db --image_path real-dome/air \
  --ImageReader.camera_model OPENCV --ImageReader.single_camera 1 \
  --Target.cols 8 --Target.rows 6 --Target.square_size 0.03
"$portcal" camera_calibrator --database_path air.db --output_path air --image_path real-dome/air
sed -n '/^Verdict/,/^$/p' air/calibration.txt
sed -n '/^  parameter /,/^RMS/p' air/calibration.txt

echo "== 2. Second opinion: mrcal on the same corners, 3-fold cross-validation"
"$portcal" cross_check --database_path air.db --input_calibration air/calibration.yaml \
  --output_path air/cross_check --CrossCheck.folds 3 | tail -n 1

echo "== 3. Under water: the dome port, solved jointly with the in-air views"
"$portcal" target_extractor --database_path water.db --image_path real-dome/water \
  --ImageReader.camera_model OPENCV --ImageReader.single_camera 1 \
  --Target.cols 8 --Target.rows 6 --Target.square_size 0.03
"$portcal" housing_calibrator --database_path water.db --in_air_database_path air.db \
  --input_calibration air/calibration.yaml --output_path water --image_path real-dome/water \
  --Housing.model DOMEPORT --Housing.params 0,0,0,0.043552,0.00375,1.0,1.495,1.333
sed -n '/^Verdict/,/^$/p' water/calibration.txt
sed -n '/^Housing/,/^RMS/p' water/calibration.txt

echo "== 4. Hand-off: OpenCV and ROS files of the in-air camera; mrcal's uncertainty of its solve"
"$portcal" model_converter --input_path air/calibration.yaml --output_path air/camera_opencv.yaml \
  --output_type OPENCV_YAML
"$portcal" model_converter --input_path air/calibration.yaml --output_path air/camera_info.yaml \
  --output_type ROS_YAML
if command -v mrcal-show-projection-uncertainty >/dev/null; then
  mrcal-show-projection-uncertainty air/camera.cameramodel \
    --hardcopy air/mrcal_uncertainty.png --terminal 'pngcairo size 800,600'
fi
ls air
echo "Results in $work"
