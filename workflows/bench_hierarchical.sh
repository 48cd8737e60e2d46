#!/usr/bin/env bash
# The survey of bench_survey.sh mapped in clusters (hierarchical_mapper,
# under mpirun) instead of one incremental model, then refined the same way:
# each stage's time and peak memory, the errors against the ground truth,
# and how far the result lies from the sequential one's (in its standard
# deviations). WORK_DIR holds bench_survey.sh's run of the same size, which
# is made first if absent.
# Usage: workflows/bench_hierarchical.sh NUM_IMAGES WORK_DIR [RANKS=2] [LEAF=250] [OVERLAP=50]
set -euo pipefail
cd "$(dirname "$0")/.."
n="${1:?usage: bench_hierarchical.sh NUM_IMAGES WORK_DIR [RANKS] [LEAF] [OVERLAP]}"
work="${2:?usage: bench_hierarchical.sh NUM_IMAGES WORK_DIR [RANKS] [LEAF] [OVERLAP]}"
ranks="${3:-2}"; leaf="${4:-250}"; overlap="${5:-50}"
[ -f "$work/refined/calibration.yaml" ] || bash workflows/bench_survey.sh "$n" "$work"
P="${PORTCAL_BINARY:-$PWD/build/portcal}"; tools="$PWD/workflows"  # PORTCAL_BINARY: another build
source workflows/survey_common.sh
cd "$work"
rm -rf hierarchical hierarchical_refined hierarchical_refined_txt
# As root, OpenMPI wants to be told.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
timed "hierarchical map (np $ranks)" mpirun -np "$ranks" --oversubscribe "$P" hierarchical_mapper --log_level warn \
  --database_path db.db --output_path hierarchical \
  --Housing.model FLATPORT --Housing.params 0,0,1,0.01,0.010,1,1.473,1.334 --Mapper.init_scene_depth 2.0 \
  --Mapper.ba_refine_focal_length 0 --Mapper.ba_refine_extra_params 0 --Mapper.ba_refine_housing 1 \
  --PosePrior.position_sigma 0.02 --Hierarchical.leaf_max_num_images "$leaf" --Hierarchical.image_overlap "$overlap"
echo "clusters: $(ls hierarchical/clusters/*.txt | wc -l) ($(cat hierarchical/clusters/*.txt | wc -l) images with the overlaps)"
timed refine "$P" refractive_bundle_adjuster --log_level warn --input_path hierarchical/0 \
  --output_path hierarchical_refined --database_path db.db --PosePrior.position_sigma 0.02
"$P" model_converter --log_level warn --input_path hierarchical_refined --output_path hierarchical_refined_txt \
  --output_type TXT
echo "== hierarchical against the truth"
/usr/bin/python3 "$tools/eval_survey.py" set/ground_truth.yaml hierarchical_refined/calibration.yaml \
  hierarchical_refined_txt/images.txt
echo "== sequential (bench_survey.sh) against the truth"
[ -d refined_txt ] || "$P" model_converter --log_level warn --input_path refined --output_path refined_txt \
  --output_type TXT
/usr/bin/python3 "$tools/eval_survey.py" set/ground_truth.yaml refined/calibration.yaml refined_txt/images.txt
echo "== hierarchical against sequential"
/usr/bin/python3 "$tools/compare_calibrations.py" refined/calibration.yaml hierarchical_refined/calibration.yaml
