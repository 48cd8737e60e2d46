#!/usr/bin/env bash
# The mapper's final adjustment, side by side on one survey: the
# refinement's schedule (--Mapper.ba_final_hold_weights 1: robust until the
# weights settle, then a solve with them held) against two robust solves to
# the cost change (0). Each setting maps WORK_DIR's database with
# bench_survey.sh's mapper flags and refines the model; the script prints
# each run's final solves (iterations, seconds), the stages' time and
# memory, and the errors against the ground truth. The scale is the
# navigation's, or with SCALE=markers the markers' (a work folder that
# bench_survey.sh made with SCALE=markers).
# WORK_DIR: a bench_survey.sh work folder after STAGES=extract (db.db and
# set/); the runs write fh_0*, fh_1* in it.
# HOLD="1" (default "1 0") runs the settings listed.
# Usage: [SCALE=navigation|markers] [HOLD="1 0"] workflows/bench_mapper_final.sh WORK_DIR
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/portcal ] || bash workflows/setup.sh >/dev/null
work="${1:?usage: workflows/bench_mapper_final.sh WORK_DIR}"
[ -f "$work/db.db" ] || { echo "bench_mapper_final.sh: $work/db.db: run bench_survey.sh STAGES=extract first" >&2; exit 2; }
P="$PWD/build/portcal"
source workflows/survey_common.sh
survey_scale "${SCALE:-navigation}"
eval_survey="$PWD/workflows/eval_survey.py"
cd "$work"
read -ra settings <<< "${HOLD:-1 0}"
for held in "${settings[@]}"; do
  case "$held" in 0|1) ;; *) echo "bench_mapper_final.sh: HOLD: $held: 0 or 1" >&2; exit 2 ;; esac
  rm -rf "fh_$held" "fh_${held}_ref" "fh_${held}_txt"
  /usr/bin/time -f "map (held=$held): %e s, %M KB" "$P" refractive_mapper --log_level debug --database_path db.db \
    --output_path "fh_$held" --Housing.model FLATPORT --Housing.params 0,0,1,0.01,0.010,1,1.473,1.334 \
    --Mapper.init_scene_depth 2.0 --Mapper.ba_refine_focal_length 0 --Mapper.ba_refine_extra_params 0 \
    --Mapper.ba_refine_housing 1 "${scale_flags[@]}" --Mapper.ba_final_hold_weights "$held" \
    > /dev/null 2> "fh_$held.err"
  # The model's last two global adjustments are the final ones.
  grep -a "bundle adjustment: .* free poses" "fh_$held.err" | grep -v " 6 free poses\| [0-5] free poses" | tail -2 |
    sed -e 's/.*bundle adjustment: /final solve: /' -e 's/ (Ceres.*Termination: / (/'
  tail -1 "fh_$held.err"
  /usr/bin/time -f "refine (held=$held): %e s, %M KB" "$P" refractive_bundle_adjuster --log_level warn \
    --input_path "fh_$held/0" --output_path "fh_${held}_ref" --database_path db.db "${scale_flags[@]}"
  "$P" model_converter --log_level warn --input_path "fh_${held}_ref" --output_path "fh_${held}_txt" --output_type TXT
  /usr/bin/python3 "$eval_survey" set/ground_truth.yaml "fh_${held}_ref/calibration.yaml" "fh_${held}_txt/images.txt"
done
