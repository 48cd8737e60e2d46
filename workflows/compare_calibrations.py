#!/usr/bin/python3
"""Compares two self-calibrations of the same survey (calibration.yaml of
refractive_bundle_adjuster): how far apart their flat ports lie, in units
of the first's standard deviations, and their camera centres.

Usage: compare_calibrations.py first/calibration.yaml second/calibration.yaml
Exit status 0; the caller judges the numbers.
"""
import math
import sys

import numpy as np
import yaml


def centres(calibration):
    out = {}
    for view in calibration["per_view"]:
        pose = view["cam_from_world"]
        w, x, y, z = pose["rotation_wxyz"]
        r = np.array([
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])
        out[view["image"]] = -r.T @ np.asarray(pose["translation"])
    return out


def main():
    a = yaml.safe_load(open(sys.argv[1]))
    b = yaml.safe_load(open(sys.argv[2]))
    pa, pb = np.asarray(a["non_svp_parameters"]), np.asarray(b["non_svp_parameters"])
    sd = a["non_svp_parameters_std_dev"]
    na, nb = pa[0:3] / np.linalg.norm(pa[0:3]), pb[0:3] / np.linalg.norm(pb[0:3])
    angle = math.degrees(math.acos(min(1.0, float(na @ nb))))
    angle_sd = math.degrees(math.hypot(sd[0], sd[1]))
    distance = (pb[3] - pa[3]) * 1000
    print(f"port: normals {angle:.5f} deg apart ({angle / angle_sd:.3f} sd of the first), distances "
          f"{pa[3] * 1000:.3f} / {pb[3] * 1000:.3f} mm ({distance:+.3f} mm, {distance / (sd[3] * 1000):+.3f} sd)")
    ca, cb = centres(a), centres(b)
    names = sorted(set(ca) & set(cb))
    d = np.array([np.linalg.norm(ca[n] - cb[n]) for n in names])
    print(f"images: {len(ca)} / {len(cb)}, {len(names)} in both; their centres apart by RMS "
          f"{math.sqrt((d ** 2).mean()) * 1000:.2f} mm, max {d.max() * 1000:.2f} mm")


if __name__ == "__main__":
    main()
