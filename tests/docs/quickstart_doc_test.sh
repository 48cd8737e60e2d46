#!/usr/bin/env bash
# docs/quickstart.md runs as written: its ```bash blocks, in order, in one
# shell from the checkout with the built portcal first on the PATH and HOME
# in a temporary folder (the doc works in ~/portcal-quickstart); then every
# figure its outputs show with a standard deviation (the lens's fx ... k1,
# the dome's centre) must be within one standard deviation of today's, and
# its point counts and verdicts equal. Skipped (77) without ../shared's real dome set.
# Usage: quickstart_doc_test.sh CHECKOUT BUILD_DIR
set -euo pipefail
checkout="$(realpath "$1")"
build="$(realpath "$2")"
if [ ! -d "$checkout/../shared/datasets/real-dome/air" ]; then
  echo "quickstart_doc_test: ../shared/datasets/real-dome is absent: skipped"
  exit 77
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
doc="$checkout/docs/quickstart.md"

# The doc's commands, as a person pastes them (its step 0 puts build/ on the
# PATH: a `build` link to this build tree stands for the checkout's).
awk '/^```bash$/ {on = 1; next} /^```$/ {on = 0} on' "$doc" > "$work/commands.sh"
mkdir -p "$work/checkout"
ln -s "$build" "$work/checkout/build"
ln -s "$checkout/../shared" "$work/shared"
mkdir -p "$work/home"
if ! (cd "$work/checkout" && HOME="$work/home" bash -euo pipefail "$work/commands.sh") > "$work/out.log" 2>&1; then
  tail -n 30 "$work/out.log"
  echo "quickstart_doc_test: the doc's commands failed (above)"
  exit 1
fi

/usr/bin/python3 - "$doc" "$work/home/portcal-quickstart" <<'PY'
import re, sys
doc, run = open(sys.argv[1]).read(), sys.argv[2]
row = re.compile(r'^\s+(fx|fy|cx|cy|k1|k2|p1|p2|Cx|Cy|Cz)\s+(-?\d+\.\d+)\s+(\d+\.\d+)\s*$', re.M)
points = re.compile(r'RMS reprojection error ([\d.]+) px over (\d+) points')
def figures(text):
    return [(m.group(1), float(m.group(2)), float(m.group(3))) for m in row.finditer(text)]
shown = figures(doc)
air = open(run + '/air/calibration.txt').read()
water = open(run + '/water/calibration.txt').read()
today = {('air', n): (v, s) for n, v, s in figures(air)}
today.update({('water', n): (v, s) for n, v, s in figures(water)})
failures = 0
for name, value, sigma in shown:
    where = 'water' if name.startswith('C') else 'air'
    now, now_sigma = today[(where, name)]
    ok = abs(now - value) <= sigma
    failures += not ok
    print(f'{where:5} {name:3} doc {value:.6f} +- {sigma:.6f}, today {now:.6f}: {"ok" if ok else "DRIFTED"}')
doc_counts = [int(m.group(2)) for m in points.finditer(doc)]
now_counts = [int(m.group(2)) for m in points.finditer(air + water)]
for shown_count, now_count in zip(doc_counts, now_counts):
    ok = shown_count == now_count
    failures += not ok
    print(f'points: doc {shown_count}, today {now_count}: {"ok" if ok else "DRIFTED"}')
verdict = re.compile(r'^Verdict: (OK|CHECK|FAIL)$', re.M)
doc_verdicts, now_verdicts = verdict.findall(doc), verdict.findall(air + water)
for shown_verdict, now_verdict in zip(doc_verdicts, now_verdicts):
    ok = shown_verdict == now_verdict
    failures += not ok
    print(f'verdict: doc {shown_verdict}, today {now_verdict}: {"ok" if ok else "DRIFTED"}')
if len(doc_verdicts) != 2 or len(now_verdicts) != 2:
    print(f'quickstart_doc_test: {len(doc_verdicts)} verdicts in the doc, {len(now_verdicts)} today; expected 2')
    failures += 1
if len(shown) < 8 or len(doc_counts) < 2:
    print(f'quickstart_doc_test: the doc shows {len(shown)} figures and {len(doc_counts)} point counts; expected >= 8 and 2')
    failures += 1
sys.exit(1 if failures else 0)
PY
