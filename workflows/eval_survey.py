#!/usr/bin/python3
"""Compares a self-calibrated survey with its ground truth.

Usage: eval_survey.py ground_truth.yaml calibration.yaml images.txt

Prints the flat port's normal error (degrees) and distance error (mm), each
with its standard deviation, and the camera positions' errors as a fraction
of the path length: directly in the navigation frame the priors define, and
after a similarity alignment (which removes what the priors' noise leaves in
the frame). Exit status 0; the caller judges the numbers.
"""
import math
import sys

import numpy as np
import yaml


def quat_to_matrix(w, x, y, z):
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)]])


def centre(q, t):
    return -quat_to_matrix(*q).T @ np.asarray(t)


def umeyama(src, dst):
    mu_s, mu_d = src.mean(0), dst.mean(0)
    a, b = src - mu_s, dst - mu_d
    u, s, vt = np.linalg.svd(b.T @ a / len(src))
    d = np.eye(3)
    if np.linalg.det(u) * np.linalg.det(vt) < 0:
        d[2, 2] = -1
    r = u @ d @ vt
    scale = np.trace(np.diag(s) @ d) / (a ** 2).sum(1).mean()
    return scale, r, mu_d - scale * r @ mu_s


def main():
    truth = yaml.safe_load(open(sys.argv[1]))
    result = yaml.safe_load(open(sys.argv[2]))
    n_true = np.asarray(truth["housing"]["params"][0:3])
    n_est = np.asarray(result["non_svp_parameters"][0:3])
    sd = result["non_svp_parameters_std_dev"]
    angle = math.degrees(math.acos(min(1.0, n_true @ n_est / np.linalg.norm(n_true) / np.linalg.norm(n_est))))
    angle_sd = math.degrees(math.hypot(sd[0], sd[1]))
    dist_err = (result["non_svp_parameters"][3] - truth["housing"]["params"][3]) * 1000
    print(f"normal error {angle:.4f} deg (sd {angle_sd:.4f}); distance error {dist_err:+.3f} mm "
          f"(sd {sd[3] * 1000:.3f})")
    print(f"normal {np.round(n_est, 6).tolist()} (truth {n_true.tolist()}); distance "
          f"{result['non_svp_parameters'][3] * 1000:.3f} mm (truth {truth['housing']['params'][3] * 1000:.3f})")

    true_centres = {}
    for frame in truth["images"]:
        cam = frame.get("cam1", frame)
        name = cam["file"].split("images/", 1)[-1]
        pose = cam["cam_from_target"]
        true_centres[name] = centre(pose["rotation_wxyz"], pose["translation"])
    est = {}
    lines = [l for l in open(sys.argv[3]) if l.strip() and not l.startswith("#")]
    for line in lines[0::2]:
        f = line.split()
        est[f[9]] = centre([float(v) for v in f[1:5]], [float(v) for v in f[5:8]])
    ordered = sorted(true_centres)
    path = sum(np.linalg.norm(true_centres[b] - true_centres[a]) for a, b in zip(ordered, ordered[1:]))
    names = sorted(set(est) & set(true_centres))
    e = np.array([est[n] for n in names])
    t = np.array([true_centres[n] for n in names])
    direct = np.linalg.norm(e - t, axis=1)
    s, r, tr = umeyama(e, t)
    aligned = np.linalg.norm((s * (r @ e.T)).T + tr - t, axis=1)
    print(f"images {len(names)} of {len(true_centres)} registered; path {path:.2f} m")
    print(f"positions (navigation frame): RMS {math.sqrt((direct ** 2).mean()) * 1000:.1f} mm, "
          f"max {direct.max() * 1000:.1f} mm = {100 * direct.max() / path:.3f} % of the path")
    print(f"positions (similarity-aligned, scale {s:.5f}): RMS {math.sqrt((aligned ** 2).mean()) * 1000:.1f} mm, "
          f"max {aligned.max() * 1000:.1f} mm = {100 * aligned.max() / path:.3f} % of the path")


if __name__ == "__main__":
    main()
