#!/usr/bin/python3
"""Hostile values for every numeric option of 14 commands (issue 70).

Each command's options with a numeric default (from its -h) are given
nan, inf, -inf, 1e308, -1e308 and 4294967297, one at a time, on the inputs
of tests/reliability/make_fixture.sh. A run is flagged when it is killed by
a signal, outlasts 40 s, ends with a library's bare words (stoi, map::at,
bad_alloc, an assertion, SQL), or exits 0 with a non-finite value. Huge
finite values that exit 0 are listed apart: thresholds that mean "never".

Usage: workflows/option_sweep.py PORTCAL FIXTURE [VALUES=nan,inf,-inf,1e308,-1e308,4294967297]
"""
import concurrent.futures
import re
import shutil
import subprocess
import sys
import tempfile

portcal, fixture = sys.argv[1], sys.argv[2]
values = (sys.argv[3] if len(sys.argv) > 3 else "nan,inf,-inf,1e308,-1e308,4294967297").split(",")
board = ["--Target.cols", "9", "--Target.rows", "6", "--Target.square_size", "0.03"]
F = fixture


def copy(name, work):
    shutil.copy(f"{F}/{name}", f"{work}/{name}")
    return f"{work}/{name}"


BASE = {
    "camera_calibrator": lambda w: ["--database_path", f"{F}/cam1.db", "--output_path", f"{w}/out"],
    "housing_calibrator": lambda w: ["--database_path", f"{F}/cam1.db", "--input_calibration",
                                     f"{F}/cal1/calibration.yaml", "--output_path", f"{w}/out", "--Housing.model",
                                     "FLATPORT", "--Housing.params", "0,0,1,0.01,0.005,1.0,1.0,1.0",
                                     "--Calibration.initialize_from_data", "0"],
    "stereo_calibrator": lambda w: ["--database_path", f"{F}/rig.db", "--output_path", f"{w}/out"],
    "calibration_evaluator": lambda w: ["--database_path", f"{F}/cam1.db", "--input_calibration",
                                        f"{F}/cal1/calibration.yaml", "--output_path", f"{w}/out"],
    "feature_extractor": lambda w: ["--database_path", f"{w}/new.db", "--image_path", f"{F}/set/images/cam1",
                                    "--ImageReader.single_camera", "1"],
    "exhaustive_matcher": lambda w: ["--database_path", copy("feat.db", w)],
    "sequential_matcher": lambda w: ["--database_path", copy("feat.db", w)],
    "refractive_mapper": lambda w: ["--database_path", copy("matched.db", w), "--output_path", f"{w}/out"],
    "image_undistorter": lambda w: ["--input_path", f"{F}/model", "--image_path", f"{F}/set/images/cam1",
                                    "--output_path", f"{w}/out", "--Undistort.distance", "1"],
    "pose_suggester": lambda w: ["--database_path", f"{F}/cam1.db", "--output_path", f"{w}/out"] + board,
    "synthesize": lambda w: ["--config", f"{F}/set.yaml", "--output_path", f"{w}/out"],
    "target_extractor": lambda w: ["--database_path", f"{w}/new.db", "--image_path", f"{F}/set/images/cam1",
                                   "--ImageReader.single_camera", "1"] + board,
    "cross_check": lambda w: ["--database_path", f"{F}/cam1.db", "--input_calibration",
                              f"{F}/cal1/calibration.yaml", "--output_path", f"{w}/out"],
    "model_converter": lambda w: ["--input_path", f"{F}/model", "--output_path", f"{w}/out", "--output_type", "BIN"],
}
BARE = re.compile(r"stoi|stod|map::at|bad_alloc|vector::|basic_string|_M_|Assertion|terminate|\[SQL", re.I)
OPTION = re.compile(r"^\s+--([A-Za-z_.0-9]+) arg \(=(-?[0-9.e+-]+)\)", re.M)


def options(command):
    text = subprocess.run([portcal, command, "-h"], capture_output=True, text=True).stdout
    return [m.group(1) for m in OPTION.finditer(text)]


def run(job):
    command, option, value = job
    work = tempfile.mkdtemp(prefix="sweep_")
    try:
        args = [portcal, command] + BASE[command](work) + ["--" + option, value, "--log_level", "warn"]
        try:
            r = subprocess.run(args, capture_output=True, text=True, timeout=40, errors="replace")
            code, lines = r.returncode, (r.stdout + r.stderr).strip().splitlines()
            last = lines[-1] if lines else ""
        except subprocess.TimeoutExpired:
            code, last = "timeout", ""
        finite = value not in ("nan", "inf", "-inf")
        if code == "timeout" or (isinstance(code, int) and code < 0) or BARE.search(last):
            kind = "FLAW"
        elif code == 0:
            kind = "huge accepted" if finite else "FLAW"
        else:
            kind = ""
        return command, option, value, code, kind, last[:160]
    finally:
        shutil.rmtree(work, ignore_errors=True)


jobs = [(c, o, v) for c in BASE for o in options(c) for v in values]
flaws = huge = 0
with concurrent.futures.ThreadPoolExecutor(2) as pool:
    for command, option, value, code, kind, last in pool.map(run, jobs):
        if kind:
            print(f"{kind:14} {command} --{option} {value}: exit {code} {last}")
        flaws += kind == "FLAW"
        huge += kind == "huge accepted"
print(f"{len(jobs)} runs of {len(BASE)} commands: {flaws} flaws, {huge} huge values accepted")
sys.exit(1 if flaws else 0)
