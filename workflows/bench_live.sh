#!/usr/bin/env bash
# The live calibrator end to end at 1920 x 1080, 25 fps (issue 25's goals):
# a rendered hand-held trajectory (three pauses) played in real time as a
# video, the page open (its Motion JPEG stream read by curl, so that every
# frame's overlay is drawn and encoded), and printed side by side with the
# source: the frames processed per second against the source's 25 (ratio,
# goal 1.0), the mean time from a frame's arrival to its encoded overlay
# (goal <= 100 ms, the network not included), and for each kept view the
# time until its suggestion was ready (goal <= 1 s). Then the per-frame and
# per-suggestion costs from build/tests/bench_live.
# Usage: workflows/bench_live.sh [PORT=18093]
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/portcal ] || bash workflows/setup.sh >/dev/null
port="${1:-18093}"
work="$(mktemp -d)"
trap 'kill $(jobs -p) 2>/dev/null || true; rm -rf "$work"' EXIT

cat > "$work/trajectory.yaml" <<'YAML'
name: bench_live
seed: 11
camera: {model: OPENCV, width: 1920, height: 1080, params: [1500, 1497, 957, 543, -0.08, 0.02, 0.0004, -0.0003]}
housing: null
target: {type: chessboard, cols: 10, rows: 7, square_size: 0.03, margin: 0.02}
poses: {distance: [0.5, 1.0], tilt_max_deg: 40, roll_max_deg: 20, border_margin_px: 30}
trajectory: {fps: 25, pauses: 3, pause_seconds: 1.6, move_seconds: 1.5, exposure: 0.02}
render: {spp: 1, blur_sigma: 0.8, noise_sigma: 2.0}
YAML
echo "bench_live: rendering the 1080p trajectory (about a minute)" >&2
build/portcal synthesize --config "$work/trajectory.yaml" --output_path "$work/set" --log_level warn
frames=$(ls "$work/set/images" | wc -l)

build/portcal live_calibrator --source "$work/set/trajectory.avi" --database_path "$work/live.db" \
  --image_path "$work/kept" --output_path "$work/out" --Target.cols 10 --Target.rows 7 \
  --Target.square_size 0.03 --ImageReader.camera_model OPENCV --Live.distance_range 0.5,1.0 \
  --Live.address "127.0.0.1:$port" --Live.status_interval 1 --calibrate_at_end 0 > "$work/log.txt" 2>&1 &
live=$!
for _ in $(seq 50); do curl -s -o /dev/null "http://127.0.0.1:$port/state.json" && break; sleep 0.1; done
curl -s -o /dev/null "http://127.0.0.1:$port/stream.mjpg" &
# The state once a second while the video plays: the last full second's
# rate and the mean latency so far.
: > "$work/states.txt"
while kill -0 $live 2>/dev/null; do
  curl -s "http://127.0.0.1:$port/state.json" >> "$work/states.txt" && echo >> "$work/states.txt" || true
  sleep 1
done
wait $live || true

/usr/bin/python3 - "$work" "$frames" <<'PY'
import json, re, sys, datetime
work, frames = sys.argv[1], int(sys.argv[2])
states = [json.loads(line) for line in open(f"{work}/states.txt") if line.strip().startswith("{")]
fps = [s["fps"] for s in states if s["fps"] > 0]
latency = states[-1]["latency_ms"] if states else float("nan")
log = open(f"{work}/log.txt").read()
done = re.search(r"(\d+) frames in ([\d.]+) s", log)
def stamp(line):
    t = re.match(r"[IWE]\d{8} (\d\d):(\d\d):(\d\d\.\d+)", line)
    return int(t[1]) * 3600 + int(t[2]) * 60 + float(t[3])
waits, kept_at = [], None
for line in log.splitlines():
    if "live: kept " in line: kept_at = stamp(line)
    elif "live: next pose" in line and kept_at is not None:
        waits.append(stamp(line) - kept_at); kept_at = None
median_fps = sorted(fps)[len(fps) // 2] if fps else float("nan")
print(f"source: {frames} frames of 1920x1080 at 25 fps ({frames / 25:.1f} s)")
print(f"{'measure':40s} {'portcal':>10s} {'goal':>10s} {'ratio':>8s}")
print(f"{'frames processed / s (median of seconds)':40s} {median_fps:10.1f} {25:10.1f} {median_fps / 25:8.2f}")
if done:
    processed, seconds = int(done[1]), float(done[2])
    print(f"{'frames processed of the source':40s} {processed:10d} {frames:10d} {processed / frames:8.2f}")
print(f"{'arrival -> overlay encoded, mean ms':40s} {latency:10.1f} {100:10.1f} {latency / 100:8.2f}")
for k, w in enumerate(waits):
    print(f"{'kept view %d -> suggestion ready, s' % (k + 1):40s} {w:10.2f} {1:10.1f} {w:8.2f}")
PY
echo
build/tests/bench_live --benchmark_min_time=0.5 2>/dev/null | grep -E "^BM_|^Benchmark" || true
