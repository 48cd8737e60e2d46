#!/usr/bin/env bash
# Rendering speed of `portcal synthesize` at full size: 1920 x 1080, 4 x 4
# supersampling, behind a dome port, both cores. Prints the time to compute
# the camera's rays (once per set) and the time per image; the issue's goal
# is <= 2 s per image. Usage: workflows/bench_synthesize.sh [num_images]
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/portcal ] || bash workflows/setup.sh >/dev/null
n="${1:-10}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
cat > "$work/bench.yaml" <<CONFIG
name: bench_synthesize
seed: 1
num_images: $n
camera: {model: RADIAL, width: 1920, height: 1080, params: [1297.3655, 960.0, 540.0, -0.1, -0.02]}
housing: {model: DOMEPORT, params: [0.01, 0.006, 0.002, 0.05, 0.006, 1.0, 1.473, 1.334]}
target: {type: chessboard, cols: 10, rows: 7, square_size: 0.02, margin: 0.015}
poses: {distance: [0.4, 1.4], tilt_max_deg: 45, roll_max_deg: 30}
render: {spp: 4, noise_sigma: 1.0}
CONFIG
start=$(date +%s.%N)
build/portcal synthesize --config "$work/bench.yaml" --output_path "$work/out" --num_threads 2 2>&1 |
  grep -E "frames in" | sed 's/^.*synthesize: /synthesize: /'
end=$(date +%s.%N)
awk -v s="$start" -v e="$end" -v n="$n" 'BEGIN { printf "wall time %.2f s for %d images: %.2f s per image including the rays\n", e - s, n, (e - s) / n }'
