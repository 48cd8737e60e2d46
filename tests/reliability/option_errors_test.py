#!/usr/bin/python3
"""Every option error names an option the command has (issue 71).

The stages' Check() functions name the flag of a field they refuse; the
flag is spelled again where the command registers it. This runs each
command with each numeric option of its -h set, one at a time, to values
that the option's checks refuse in most cases (-1e300, 1e300), the
required options pointing into a file used as a folder (so nothing can be
read or written), and asserts that every --option a message names is one
of that command's options, and that no run crashes or outlasts 30 s.

usage: option_errors_test.py PORTCAL
"""
import concurrent.futures
import os
import re
import subprocess
import sys
import tempfile

PORTCAL = sys.argv[1]
VALUES = ["-1e300", "1e300"]
OPTION = re.compile(r"^\s+--([A-Za-z_][A-Za-z_.0-9]*)(?: arg)?(?: \(=([^)]*)\))?", re.M)
NAMED = re.compile(r"--([A-Za-z_][A-Za-z_0-9]*(?:\.[A-Za-z_0-9]+)?)")
NUMBER = re.compile(r"^-?[0-9.]+(e[+-]?[0-9]+)?$")


def commands():
    text = subprocess.run([PORTCAL, "help"], capture_output=True, text=True).stdout
    section = text.split("Commands:", 1)[1]
    return [m.group(1) for m in re.finditer(r"^  ([a-z_]+)\s", section, re.M) if m.group(1) != "help"]


def options(command):
    text = subprocess.run([PORTCAL, command, "-h"], capture_output=True, text=True).stdout
    found = {}
    for m in OPTION.finditer(text):
        found[m.group(1)] = m.group(2)
    return found


def required_options(command, nowhere):
    """The options the command cannot run without, each set to `nowhere`."""
    required = []
    for _ in range(10):
        text = subprocess.run([PORTCAL, command] + required, capture_output=True, text=True).stderr
        missing = re.search(r"the option '--([A-Za-z_.0-9]+)' is required but missing", text)
        if not missing:
            return required
        required += [f"--{missing.group(1)}", nowhere]
    raise RuntimeError(f"{command}: more than 10 required options")


def run(command, required, name, value):
    args = [PORTCAL, command, "--log_level", "error"] + required + [f"--{name}", value]
    try:
        done = subprocess.run(args, capture_output=True, text=True, timeout=30)
    except subprocess.TimeoutExpired:
        return (command, name, value, None, "timed out after 30 s")
    return (command, name, value, done.returncode, done.stdout + done.stderr)


def main():
    blocker = os.path.join(tempfile.mkdtemp(prefix="option_errors_"), "a_file")
    open(blocker, "w").close()
    nowhere = os.path.join(blocker, "x")  # no one can read or create it
    jobs, known = [], {}
    for command in commands():
        opts = options(command)
        known[command] = set(opts) | {"help", "log_level", "project_path", "busy_timeout"}
        required = required_options(command, nowhere)
        for name, default in opts.items():
            if default is not None and NUMBER.match(default):
                jobs += [(command, required, name, value) for value in VALUES]
    failures, refused = [], 0
    with concurrent.futures.ThreadPoolExecutor(max_workers=os.cpu_count() or 2) as pool:
        for command, name, value, code, text in pool.map(lambda job: run(*job), jobs):
            where = f"{command} --{name} {value}"
            if code is None or code < 0 or code > 128:
                failures.append(f"{where}: {'crashed, code ' + str(code) if code is not None else text}")
                continue
            if f"option --{name} = " in text:
                refused += 1
            unknown = sorted({n for n in NAMED.findall(text) if n not in known[command]})
            if unknown:
                failures.append(f"{where}: the message names --{', --'.join(unknown)}, not an option of "
                                f"{command}: {text.strip().splitlines()[-1]}")
    print(f"{len(jobs)} runs over {len(known)} commands; {refused} refused the value naming its option")
    for failure in failures:
        print("FAIL", failure)
    # About a quarter of the runs are refused by a check (the rest are
    # values an option accepts, e.g. "never" thresholds); far fewer means
    # the runs stop before the checks (a required option not found).
    if refused < len(jobs) // 10:
        print("FAIL too few runs reached an option check: the test no longer exercises Check()")
        return 1
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
