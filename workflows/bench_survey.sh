#!/usr/bin/env bash
# Self-calibration of a flat port on a rendered survey (no target, no
# markers): portcal's renderer makes a lawnmower survey 2 m over a rough
# seabed behind a port tilted 3 deg (960 x 540, known in-air intrinsics,
# navigation positions with 2 cm noise); then extract, pose_prior_importer,
# sequential_matcher along the lines and spatial_matcher across them,
# refractive_mapper from an untilted guess refining the port with the
# position priors as the scale, and refractive_bundle_adjuster (the same).
# Prints each stage's time and the errors against the ground truth
# (workflows/eval_survey.py). Goal (issue 5): normal <= 0.05 deg, distance
# <= 2 mm, camera positions within 0.5 % of the path length.
# Usage: workflows/bench_survey.sh [NUM_IMAGES=300] [WORK_DIR=temporary]
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/portcal ] || bash workflows/setup.sh >/dev/null
n="${1:-300}"
if [ -n "${2:-}" ]; then work="$2"; mkdir -p "$work"; else work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT; fi
P="$PWD/build/portcal"
source workflows/survey_common.sh
survey_yaml survey_flat "$n" > "$work/survey.yaml"
cd "$work"
[ -f set/ground_truth.yaml ] || timed render "$P" synthesize --log_level warn --config survey.yaml --output_path set --seed 3
rm -rf db.db sparse refined
timed extract "$P" feature_extractor --log_level warn --database_path db.db --image_path set/images \
  --ImageReader.single_camera 1 --ImageReader.camera_model RADIAL --ImageReader.camera_params 700,480,270,0,0
"$P" pose_prior_importer --log_level warn --database_path db.db --input_path set/navigation.txt
# Sequential pairs along each line, then the lines beside it by position.
timed match_sequential "$P" sequential_matcher --log_level warn --database_path db.db \
  --SequentialMatching.overlap 5 --SequentialMatching.quadratic_overlap 0
timed match_spatial "$P" spatial_matcher --log_level warn --database_path db.db
# The port is refined in the mapper's global adjustments, with the
# navigation as the scale.
timed map "$P" refractive_mapper --log_level warn --database_path db.db --output_path sparse \
  --Housing.model FLATPORT --Housing.params 0,0,1,0.01,0.010,1,1.473,1.334 --Mapper.init_scene_depth 2.0 \
  --Mapper.ba_refine_focal_length 0 --Mapper.ba_refine_extra_params 0 --Mapper.ba_refine_housing 1 \
  --PosePrior.position_sigma 0.02
timed refine "$P" refractive_bundle_adjuster --log_level warn --input_path sparse/0 --output_path refined \
  --database_path db.db --PosePrior.position_sigma 0.02
"$P" model_converter --log_level warn --input_path refined --output_path refined_txt --output_type TXT
/usr/bin/python3 "$OLDPWD/workflows/eval_survey.py" set/ground_truth.yaml refined/calibration.yaml refined_txt/images.txt
