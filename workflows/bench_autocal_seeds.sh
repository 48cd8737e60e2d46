#!/usr/bin/env bash
# Are auto-calibration's standard deviations honest? Renders N sets of the
# same scene with different seeds (view poses, noise; portcal's renderer:
# 960 x 540, 12 views of the two-face ArUco target behind a flat port
# tilted 4 deg; principal point 4 and 3.5 px off the centre), auto-calibrates each with the intrinsics unknown, and
# prints per seed and over all seeds the RMS of (estimate - truth) / sigma
# for f, the principal point, the normal's Nx and Ny, and the port distance
# (honest: 0.7-1.4), with the reported std devs and with each of the two
# estimates they are the larger of (by the noise, by the clusters' spread:
# images and tracks).
# CAMERA "wide" instead: a camera like a real one (issue 21), OPENCV with
# k1 = -0.3, k2 = 0.09, tangential terms, fx != fy and the principal point
# (10, -7.5) px off, 15 views at 0.3-0.8 m, behind a flat port tilted 2.5
# deg at 30 mm; calibrated as OPENCV (fx, fy, cx, cy, Nx, Ny, distance).
# CAMERA "fisheye": the same views and port with an OPENCV_FISHEYE lens
# (about 100 deg across, principal point (-8, 6) px off), calibrated as
# OPENCV_FISHEYE.
# Usage: workflows/bench_autocal_seeds.sh [N=10] [CAMERA=centred|wide|fisheye]
set -euo pipefail
cd "$(dirname "$0")/.."
[ -x build/portcal ] || bash workflows/setup.sh >/dev/null
n="${1:-10}"
camera="${2:-centred}"
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
# The wide and fisheye lenses' views and port: 15 views at 0.3-0.8 m, the
# port tilted 2.5 deg at 30 mm, guessed untilted.
tilted_port_guess=0,0,1,0.03,0.008,1,1.473,1.334
tilted_port_views='housing: {model: FLATPORT, params: [0.0436194, 0.0, 0.9990482, 0.03, 0.008, 1.0, 1.473, 1.334]}
poses: {distance: [0.3, 0.8], tilt_max_deg: 45, roll_max_deg: 180, visibility: markers, border_margin_px: 10, max_view_angle_deg: 70}'
case "$camera" in
  centred)
    model=RADIAL
    guess=0,0,1,0.015,0.010,1,1.473,1.334
    scene='num_images: 12
camera: {model: RADIAL, width: 960, height: 540, params: [650.0, 484.0, 266.5, 0.0, 0.0]}
housing: {model: FLATPORT, params: [0.0697565, 0.0, 0.9975641, 0.015, 0.010, 1.0, 1.473, 1.334]}
poses: {distance: [0.4, 1.0], tilt_max_deg: 45, roll_max_deg: 180, visibility: markers, border_margin_px: 10, max_view_angle_deg: 70}' ;;
  wide)
    model=OPENCV
    guess=$tilted_port_guess
    scene="num_images: 15
camera: {model: OPENCV, width: 960, height: 540, params: [452.0, 450.5, 490.0, 262.5, -0.30, 0.09, 0.0012, 0.0009]}
$tilted_port_views" ;;
  fisheye)
    model=OPENCV_FISHEYE
    guess=$tilted_port_guess
    scene="num_images: 15
camera: {model: OPENCV_FISHEYE, width: 960, height: 540, params: [380.0, 379.0, 472.0, 276.0, 0.06, -0.02, 0.004, -0.001]}
$tilted_port_views" ;;
  *) echo "bench_autocal_seeds.sh: CAMERA must be centred, wide or fisheye, not '$camera'" >&2; exit 2 ;;
esac
{ echo "name: seeds"; echo "$scene"; cat <<'YAML'; } > "$work/set.yaml"
target:
  type: target3d
  num_faces: 2
  fold_angle_deg: 120
  face_width: 0.2
  face_height: 0.25
  aruco_dict: DICT_4X4_50
  marker_ids: [0, 1]
  marker_size: 0.06
  quiet_zone_modules: 1
  dots: {seed: 11, r_min: 0.0015, r_max: 0.009, coverage: 0.5, gray_min: 20, gray_max: 110, edge_margin: 0.004}
render: {spp: 4, noise_sigma: 1.0, white: 220, black: 30, background: 110}
YAML
for seed in $(seq 1 "$n"); do
  build/portcal synthesize --log_level warn --config "$work/set.yaml" --output_path "$work/s$seed" --seed "$seed"
  if build/portcal auto_calibrator --log_level error --image_path "$work/s$seed/images" \
       --output_path "$work/o$seed" --ImageReader.camera_model "$model" --Housing.model FLATPORT \
       --Housing.params "$guess" --Markers.side_length 0.06; then
    echo "$seed $work/s$seed/ground_truth.yaml $work/o$seed/calibration.yaml"
  else
    echo "$seed failed"
  fi
done > "$work/runs.txt"
/usr/bin/python3 - "$work/runs.txt" <<'PY'
import math, sys, yaml
# The reported std devs, and the two estimates they are the larger of.
kinds = {"reported": "", "by the noise": "_by_noise", "by the clusters": "_by_clusters"}
# Over all seeds, and over those whose report carries no warning (what a
# user would take as trustworthy).
groups = {"all": {}, "unwarned": {}}
names = None
counts = {"all": 0, "unwarned": 0}
failed = 0
for line in open(sys.argv[1]):
    parts = line.split()
    if parts[1] == "failed":
        print(f"seed {parts[0]}: auto_calibrator failed")
        failed += 1
        continue
    truth = yaml.safe_load(open(parts[1]))
    result = yaml.safe_load(open(parts[2]))
    # The focal length(s) and the principal point lead every model's list.
    m = 4 if result["parameter_names"][1] == "fy" else 3
    if names is None:
        names = result["parameter_names"][0:m] + ["Nx", "Ny", "distance"]
        n = len(names)
        for g in groups:
            groups[g] = {kind: ([0.0] * n, [0] * n) for kind in kinds}
    t = truth["camera"]["params"][0:m] + truth["housing"]["params"][0:2] + [truth["housing"]["params"][3]]
    e = result["parameters"][0:m] + result["non_svp_parameters"][0:2] + [result["non_svp_parameters"][3]]
    warnings = result.get("warnings") or []
    members = ["all"] + ([] if warnings else ["unwarned"])
    for kind, suffix in kinds.items():
        cam = result.get("parameters_std_dev" + suffix)
        hou = result.get("non_svp_parameters_std_dev" + suffix)
        if cam is None or hou is None:
            sys.exit(f"{parts[2]}: no parameters_std_dev{suffix} / non_svp_parameters_std_dev{suffix}")
        s = cam[0:m] + hou[0:2] + [hou[3]]
        # A parameter held (sd 0, the principal point at the centre) or
        # undetermined (null) has no z.
        z = [(e[i] - t[i]) / s[i] if s[i] else None for i in range(n)]
        if kind == "reported":
            print(f"seed {parts[0]}: " + ", ".join(
                f"{names[i]} {e[i] - t[i]:+.5g} " + (f"(sd {s[i]:.3g}, z {z[i]:+.2f})" if z[i] is not None else "(held)")
                for i in range(n)) + (f"; {len(warnings)} warning(s): " + " | ".join(w[:90] for w in warnings) if warnings else ""))
        for g in members:
            sums, num = groups[g][kind]
            for i in range(n):
                if z[i] is not None:
                    sums[i] += z[i] ** 2
                    num[i] += 1
    for g in members:
        counts[g] += 1
print(f"{counts['all']} seeds calibrated ({counts['all'] - counts['unwarned']} with a warning), {failed} failed (an error, no report)")
for g in groups:
    if not counts[g]:
        continue
    for kind in kinds:
        sums, num = groups[g][kind]
        print(f"RMS z over the {counts[g]} {'' if g == 'all' else 'unwarned '}seeds, std devs {kind} (honest: 0.7-1.4): " +
              ", ".join(f"{names[i]} " + (f"{math.sqrt(sums[i] / num[i]):.2f}" if num[i] else "held") for i in range(n)))
PY
