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
# With SCALE=markers, 16 ArUco markers of 15 cm lie on the seabed where the
# survey starts (its first lines see them), feature_masker stores them
# (keeping every feature), and the mapper and the refinement take the scale
# from their side instead of the navigation (which then only pairs images
# for matching): compare the similarity-aligned scale and positions. A
# markers run wants its own WORK_DIR (the renders differ).
# RENDER_SPP=2 renders 4 x faster (see survey_common.sh). A survey too long
# for one sitting runs in parts: STAGES lists the parts to run (default
# "extract map refine"; extract includes the priors, masks and matching),
# each on what the parts before it left in WORK_DIR (the stages write in
# transactions, so a part cut short leaves its inputs as they were).
# LOG_LEVEL=debug (default warn) logs each stage's steps and their seconds.
# MAPPER_ARGS="--Mapper.x v ..." adds options to the mapper's command line.
# PORTCAL=path runs another build's binary (to compare two builds' stages
# on one work folder).
# Usage: [SCALE=navigation|markers] [RENDER_SPP=4] [STAGES="extract map refine"] [LOG_LEVEL=warn] [PORTCAL=...]
#        workflows/bench_survey.sh [NUM_IMAGES=300] [WORK_DIR=temporary]
set -euo pipefail
# WORK_DIR and PORTCAL, if relative, are taken from where the script is
# called; the rest from the repository root.
caller="$PWD"
cd "$(dirname "$0")/.."
if [ -z "${PORTCAL:-}" ] && [ ! -x build/portcal ]; then bash workflows/setup.sh >/dev/null; fi
n="${1:-300}"
if [ -n "${2:-}" ]; then
  work="$(cd "$caller" && mkdir -p "$2" && realpath "$2")"
else
  work="$(mktemp -d)"; trap 'rm -rf "$work"' EXIT
fi
if [ -n "${PORTCAL:-}" ]; then P="$(cd "$caller" && realpath "$PORTCAL")"; else P="$(realpath build/portcal)"; fi
[ -x "$P" ] || { echo "bench_survey.sh: PORTCAL: $P is not an executable" >&2; exit 2; }
source workflows/survey_common.sh
scale="${SCALE:-navigation}"
survey_scale "$scale"
log_level="${LOG_LEVEL:-warn}"
read -ra mapper_args <<< "${MAPPER_ARGS:-}"
stages=" ${STAGES:-extract map refine} "
for stage in $stages; do
  case "$stage" in extract|map|refine) ;; *) echo "bench_survey.sh: STAGES: $stage: extract, map or refine" >&2; exit 2 ;; esac
done
runs() { [[ "$stages" == *" $1 "* ]]; }
survey_yaml survey_flat "$n" "$num_markers" > "$work/survey.yaml"
cd "$work"
[ -f set/ground_truth.yaml ] || timed render "$P" synthesize --log_level "$log_level" --config survey.yaml --output_path set --seed 3
if runs extract; then
  rm -rf db.db sparse refined
  timed extract "$P" feature_extractor --log_level "$log_level" --database_path db.db --image_path set/images \
    --ImageReader.single_camera 1 --ImageReader.camera_model RADIAL --ImageReader.camera_params 700,480,270,0,0
  "$P" pose_prior_importer --log_level "$log_level" --database_path db.db --input_path set/navigation.txt
  if [ "$scale" = markers ]; then
    timed mask "$P" feature_masker --log_level "$log_level" --database_path db.db --image_path set/images \
      --Mask.keep_all_features 1
  fi
  # Sequential pairs along each line, then the lines beside it by position.
  timed match_sequential "$P" sequential_matcher --log_level "$log_level" --database_path db.db \
    --SequentialMatching.overlap 5 --SequentialMatching.quadratic_overlap 0
  timed match_spatial "$P" spatial_matcher --log_level "$log_level" --database_path db.db
fi
if runs map; then
  [ -f db.db ] || { echo "bench_survey.sh: $work/db.db: run STAGES=extract first" >&2; exit 2; }
  rm -rf sparse refined
  # The port is refined in the mapper's global adjustments, with the
  # navigation as the scale.
  timed map "$P" refractive_mapper --log_level "$log_level" --database_path db.db --output_path sparse \
    --Housing.model FLATPORT --Housing.params 0,0,1,0.01,0.010,1,1.473,1.334 --Mapper.init_scene_depth 2.0 \
    --Mapper.ba_refine_focal_length 0 --Mapper.ba_refine_extra_params 0 --Mapper.ba_refine_housing 1 \
    "${scale_flags[@]}" ${mapper_args[@]+"${mapper_args[@]}"}
fi
runs refine || exit 0
[ -d sparse/0 ] || { echo "bench_survey.sh: $work/sparse/0: run STAGES=map first" >&2; exit 2; }
rm -rf refined refined_txt
timed refine "$P" refractive_bundle_adjuster --log_level "$log_level" --input_path sparse/0 --output_path refined \
  --database_path db.db "${scale_flags[@]}"
"$P" model_converter --log_level "$log_level" --input_path refined --output_path refined_txt --output_type TXT
/usr/bin/python3 "$OLDPWD/workflows/eval_survey.py" set/ground_truth.yaml refined/calibration.yaml refined_txt/images.txt
