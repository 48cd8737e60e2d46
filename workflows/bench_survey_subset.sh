#!/usr/bin/env bash
# The cheap path of a survey's self-calibration against the full one, on
# portcal's rendered lawnmower survey (bench_survey.sh's: 960 x 540, a flat
# port tilted 3 deg, navigation with 2 cm noise as the scale), both from
# the same matched database:
#   full:   refractive_mapper refining the port on every image, then
#           refractive_bundle_adjuster refining it;
#   subset: calibration_subset_selector picks SUBSET images, the mapper and
#           the adjuster refine the port on them (--image_list_path), then
#           every image is mapped and adjusted with that port held.
# Prints each path's stage times and its errors against the ground truth
# (workflows/eval_survey.py: port normal and distance, camera positions).
# Usage: workflows/bench_survey_subset.sh [NUM_IMAGES=240] [SUBSET=60] [WORK_DIR=temporary]
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/portcal ] || bash workflows/setup.sh >/dev/null
n="${1:-240}"; subset="${2:-60}"
if [ -n "${3:-}" ]; then work="$3"; mkdir -p "$work"; else work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT; fi
P="$PWD/build/portcal"; eval_survey="$PWD/workflows/eval_survey.py"
source workflows/survey_common.sh
survey_yaml survey_flat "$n" > "$work/survey.yaml"
cd "$work"
q=(--log_level warn)
if [ ! -f db.db ]; then
  [ -f set/ground_truth.yaml ] || "$P" synthesize "${q[@]}" --config survey.yaml --output_path set --seed 3
  "$P" feature_extractor "${q[@]}" --database_path db.db --image_path set/images --ImageReader.single_camera 1 \
    --ImageReader.camera_model RADIAL --ImageReader.camera_params 700,480,270,0,0
  "$P" pose_prior_importer "${q[@]}" --database_path db.db --input_path set/navigation.txt
  "$P" sequential_matcher "${q[@]}" --database_path db.db --SequentialMatching.overlap 5 \
    --SequentialMatching.quadratic_overlap 0
  "$P" spatial_matcher "${q[@]}" --database_path db.db
fi
guess=(--Housing.model FLATPORT --Housing.params 0,0,1,0.01,0.010,1,1.473,1.334)
map=(--Mapper.init_scene_depth 2.0 --Mapper.ba_refine_focal_length 0 --Mapper.ba_refine_extra_params 0
     --PosePrior.position_sigma 0.02)
evaluate() {  # the refined model in $1
  "$P" model_converter "${q[@]}" --input_path "$1" --output_path "$1_txt" --output_type TXT
  /usr/bin/python3 "$eval_survey" set/ground_truth.yaml "$1/calibration.yaml" "$1_txt/images.txt"
}
rm -rf full_sparse full_refined subset.txt subset_sparse subset_refined held_sparse held_refined
echo "== full: $n images, the port refined on all"
timed "map (port refined)" "$P" refractive_mapper "${q[@]}" --database_path db.db --output_path full_sparse \
  "${guess[@]}" "${map[@]}" --Mapper.ba_refine_housing 1
timed "refine (port refined)" "$P" refractive_bundle_adjuster "${q[@]}" --input_path full_sparse/0 \
  --output_path full_refined --database_path db.db --PosePrior.position_sigma 0.02
evaluate full_refined
echo "== subset: the port refined on $subset images, then held on all $n"
timed "select" "$P" calibration_subset_selector "${q[@]}" --database_path db.db --output_path subset.txt \
  --Subset.num_images "$subset"
echo "selected $(wc -l < subset.txt) images"
timed "map subset (port refined)" "$P" refractive_mapper "${q[@]}" --database_path db.db \
  --output_path subset_sparse --image_list_path subset.txt "${guess[@]}" "${map[@]}" --Mapper.ba_refine_housing 1
timed "refine subset (port refined)" "$P" refractive_bundle_adjuster "${q[@]}" --input_path subset_sparse/0 \
  --output_path subset_refined --database_path db.db --PosePrior.position_sigma 0.02
evaluate subset_refined
port=$(awk '!/^#/ && NF >= 10 { printf "%s", $3; for (i = 4; i <= NF; ++i) printf ",%s", $i; exit }' \
  subset_refined/housings.txt)
timed "map all (port held)" "$P" refractive_mapper "${q[@]}" --database_path db.db --output_path held_sparse \
  --Housing.model FLATPORT --Housing.params "$port" "${map[@]}" --Mapper.ba_refine_housing 0
timed "refine all (port held)" "$P" refractive_bundle_adjuster "${q[@]}" --input_path held_sparse/0 \
  --output_path held_refined --database_path db.db --PosePrior.position_sigma 0.02 \
  --BundleAdjustment.refine_housing 0
evaluate held_refined
