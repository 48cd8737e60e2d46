# What the survey benchmarks share (sourced by bench_survey.sh,
# bench_survey_subset.sh, bench_mpi.sh, bench_mapper_final.sh, sourced from
# the project root): the rendered survey, its scale source and a timer.
bash workflows/setup.sh --packages-only time >/dev/null  # GNU time, for the peak memory

# survey_yaml NAME NUM_IMAGES [MARKERS=0]: the lawnmower survey 2 m over a
# rough seabed behind a flat port tilted 3 deg (960 x 540, known in-air
# intrinsics, navigation positions with 2 cm noise), as synthesize's config;
# with MARKERS > 0, that many ArUco markers of 15 cm lie on the seabed where
# the survey starts (a grid 1.5 m apart). RENDER_SPP (default 4) sets the
# renderer's samples per pixel side (spp^2 rays a pixel): the render's time
# goes with its square, the stages after it see nearly the same images.
survey_yaml() {
  local markers=""
  [ "${3:-0}" -gt 0 ] && markers=",
         markers: {count: $3, side: 0.15, spacing: 1.5}"
  cat <<YAML
name: $1
num_images: $2
camera: {model: RADIAL, width: 960, height: 540, params: [700.0, 480.0, 270.0, 0.0, 0.0]}
housing: {model: FLATPORT, params: [0.0523360, 0.0, 0.9986295, 0.02, 0.010, 1.0, 1.473, 1.334]}
survey: {height: 2.0, speed: 0.5, frame_rate: 1.0, side_overlap: 0.6, line_length: 15.0,
         roughness: 0.15, relief_wavelength: 2.0, navigation_sigma: 0.02$markers}
render: {spp: ${RENDER_SPP:-4}, noise_sigma: 1.0, white: 220, black: 30, background: 110}
YAML
}

# survey_scale SCALE: sets num_markers (for survey_yaml) and scale_flags
# (the mapper's and the refinement's scale options) for SCALE=navigation
# (the position priors, 2 cm) or markers (16 markers of 15 cm); exits 2
# naming the script otherwise.
survey_scale() {
  case "$1" in
    navigation) num_markers=0; scale_flags=(--PosePrior.position_sigma 0.02) ;;
    markers) num_markers=16; scale_flags=(--Markers.side_length 0.15) ;;
    *) echo "$(basename "$0"): SCALE=$1: navigation or markers" >&2; exit 2 ;;
  esac
}

# timed NAME COMMAND...: runs the command, then prints NAME, its wall time
# and its peak memory (the largest resident set of the command or any
# process it waited for, by GNU time).
timed() {
  local name="$1" t0 rss; shift; t0=$(date +%s%N)
  rss="$(mktemp)"
  /usr/bin/time -q -f %M -o "$rss" "$@"
  local ms=$(( ($(date +%s%N) - t0) / 1000000 ))
  printf '%-28s %8d.%03d s %8d MB\n' "$name" $((ms / 1000)) $((ms % 1000)) $(( $(tail -1 "$rss") / 1024 ))
  rm -f "$rss"
}
