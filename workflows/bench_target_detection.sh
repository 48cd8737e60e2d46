#!/usr/bin/env bash
# Speed of chessboard detection, side by side with OpenCV in one run: for
# each set, portcal target_extractor (images read, board found, corners
# fitted, database written) on one and on two threads against OpenCV 4.6's
# findChessboardCorners (adaptive threshold, normalised, fast check) +
# cornerSubPix (11 x 11) on one thread, images read included. Each time is
# the fastest of three runs (this machine's times vary by 20 % from run to
# run). Prints the times, the views and corners each found, and portcal's
# time over OpenCV's (goal: <= 1.0 on one thread), with and without
# portcal's process start.
# Usage: workflows/bench_target_detection.sh [SHARED=../shared]
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/portcal ] || bash workflows/setup.sh >/dev/null
shared="${1:-../shared}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
now() { date +%s.%N; }
elapsed() { awk -v a="$1" -v b="$2" 'BEGIN { printf "%.2f", b - a }'; }

# Five textured renders without a chessboard (the 3-D target's views).
noboard="$work/no_chessboard"
mkdir -p "$noboard"
for i in 1 2 3 4 5; do
  image="$shared/datasets/rendered/target3d_flatport/images/img_00$i.png"
  [ -f "$image" ] && ln -s "$(realpath "$image")" "$noboard/"
done

# name, images, inner corners (cols rows), square size (m)
sets=(
  "real-dome/air  $shared/datasets/real-dome/air  8 6 0.03"
  "chess_air_distorted  $shared/datasets/rendered/chess_air_distorted/images  10 7 0.02"
  "chess_flatport  $shared/datasets/rendered/chess_flatport/images  10 7 0.02"
  "no_chessboard(5)  $noboard  10 7 0.02"
)
# portcal's process start (loading its ~170 shared libraries; GDAL among
# them, through OpenCV's image codecs), fastest of three: the OpenCV times
# are taken inside Python after `import cv2`, so ratio_1_run compares the
# two without their process start.
start=""
for run in 1 2 3; do
  t0=$(now)
  build/portcal help >/dev/null
  t1=$(now)
  start=$(awk -v a="$start" -v b="$(elapsed "$t0" "$t1")" 'BEGIN { print (a == "" || b < a) ? b : a }')
done
echo "portcal's process start: $start s"
printf "%-22s %8s %8s %8s %12s %12s %8s %12s\n" set portcal_1 portcal_2 opencv_1 "portcal views" "opencv views" \
  "ratio_1" "ratio_1_run"
for entry in "${sets[@]}"; do
  read -r name images cols rows square <<<"$entry"
  [ -n "$(ls -A "$images" 2>/dev/null)" ] || { echo "$name: $images absent, skipped"; continue; }
  times=()
  for threads in 1 2; do
    best=""
    for run in 1 2 3; do
      db="$work/$threads.db"
      rm -f "$db"
      t0=$(now)
      build/portcal target_extractor --log_level warn --database_path "$db" --image_path "$images" \
        --Target.cols "$cols" --Target.rows "$rows" --Target.square_size "$square" --num_threads "$threads"
      t1=$(now)
      best=$(awk -v a="$best" -v b="$(elapsed "$t0" "$t1")" 'BEGIN { print (a == "" || b < a) ? b : a }')
    done
    times+=("$best")
  done
  views=$(sqlite3 "$work/1.db" "SELECT COUNT(*) || ' / ' || IFNULL(SUM(num_points), 0) FROM portcal_target_detections WHERE found = 1;")
  opencv_s=""
  for run in 1 2 3; do
    read -r seconds opencv_views opencv_corners < <(/usr/bin/python3 workflows/bench_target_detection.py "$images" "$cols" "$rows")
    opencv_s=$(awk -v a="$opencv_s" -v b="$seconds" 'BEGIN { print (a == "" || b < a) ? b : a }')
  done
  ratio=$(awk -v a="${times[0]}" -v b="$opencv_s" 'BEGIN { printf "%.2f", a / b }')
  ratio_run=$(awk -v a="${times[0]}" -v s="$start" -v b="$opencv_s" 'BEGIN { printf "%.2f", (a - s) / b }')
  printf "%-22s %8s %8s %8s %12s %12s %8s %12s\n" "$name" "${times[0]}" "${times[1]}" "$opencv_s" "$views" \
    "$opencv_views / $opencv_corners" "$ratio" "$ratio_run"
done
