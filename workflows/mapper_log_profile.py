#!/usr/bin/python3
"""Where refractive_mapper's time goes, from its debug log.

Reads the stderr of `refractive_mapper --log_level debug` (e.g.
`LOG_LEVEL=debug workflows/bench_survey.sh N DIR 2> map.err`) and prints,
per bucket of model size, each registration's wall time (from one
"registered '...'" line's timestamp to the next), the local adjustment's
Ceres time within it, and the rest (pose, triangulation, the local
problem's set-up, the filter): a cost that grows with the bucket grows with
the model. Registrations that ran a global adjustment are left out of the
means. Then every global adjustment: model size, free poses, points,
residuals, iterations, seconds.
Usage: workflows/mapper_log_profile.py MAP_STDERR [BUCKET=100]
"""
import re
import statistics
import sys
from datetime import datetime

REGISTERED = re.compile(r"\] registered '")
ADJUSTMENT = re.compile(r"bundle adjustment: (\d+) free poses, (\d+) points, (\d+) residuals, "
                        r"(\d+) iterations, ([0-9.e+-]+) s")
LOCAL_MAX_FREE_POSES = 6  # the mapper's ba_local_num_images


def timestamp(line):
    # glog's prefix: Lyyyymmdd hh:mm:ss.uuuuuu
    return datetime.strptime(line[1:22], "%Y%m%d %H:%M:%S.%f").timestamp()


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    bucket = int(sys.argv[2]) if len(sys.argv) == 3 else 100
    registrations = []  # (model size, seconds, local Ceres seconds, ran a global adjustment)
    global_adjustments = []
    num_images, last, local_s, ran_global = 0, None, 0.0, False
    with open(sys.argv[1], errors="replace") as log:
        for line in log:
            m = ADJUSTMENT.search(line)
            if m:
                free, seconds = int(m[1]), float(m[5])
                if free <= LOCAL_MAX_FREE_POSES:
                    local_s += seconds
                else:
                    ran_global = True
                    global_adjustments.append((num_images, free, int(m[2]), int(m[3]), int(m[4]), seconds))
            elif REGISTERED.search(line):
                t = timestamp(line)
                if last is not None:
                    registrations.append((num_images, t - last, local_s, ran_global))
                last, num_images, local_s, ran_global = t, num_images + 1, 0.0, False
    if not registrations:
        sys.exit(f"{sys.argv[1]}: no registrations in a debug log")
    print("images  registrations  mean s  local Ceres s  rest s  (means without global adjustments)")
    for start in range(0, num_images, bucket):
        plain = [r for r in registrations if start <= r[0] < start + bucket and not r[3]]
        if plain:
            print(f"{start:6d}  {len(plain):13d}  {statistics.mean(r[1] for r in plain):6.3f}  "
                  f"{statistics.mean(r[2] for r in plain):13.3f}  {statistics.mean(r[1] - r[2] for r in plain):6.3f}")
    print("global adjustments: images, free poses, points, residuals, iterations, s")
    for g in global_adjustments:
        print(*g)


if __name__ == "__main__":
    main()
