#!/usr/bin/env python3
"""Every numeric field of every shipped mission, every extreme value, through
the command line as a user runs it, each process timed and its memory read
by /usr/bin/time (issue 37: "no run over 30 s, none over 2 GB, no abort").

For each `missions/*.toml`, each numeric leaf the file writes gets each of
0, -1, 1e-9, 1e9, 1e300, nan, inf (an integer field the integer forms that
TOML can hold). `skyform check` answers; where the mission is still valid,
`skyform run` runs the pipelines it is meant for. Every process is held to a
35 s timeout; the report lists the slowest, the largest and every run that
timed out, died of a signal or passed 30 s or 2 GB.

    python3 tests/extreme_values_cli.py SKYFORM_BINARY [--jobs 2] [--only FILE]

Needs `tomlkit` (pip install tomlkit): it edits one value and keeps the file.
"""

import argparse
import concurrent.futures
import math
import os
import pathlib
import subprocess
import sys
import tempfile

import tomlkit

ROOT = pathlib.Path(__file__).resolve().parent.parent
FLOATS = [0.0, -1.0, 1e-9, 1e9, 1e300, math.nan, math.inf]
INTEGERS = [0, -1, 1, 10**9, 2**63 - 1]
# Which pipelines each shipped mission is for (θ-PSO unless named).
PIPELINES = {
    "bridge-inspection.toml": ["theta-pso", "flatlo", "fleet"],
    "flatlo-squadron.toml": ["flatlo"],
    "fleet-triangle.toml": ["fleet"],
}
LIMIT_SECONDS = 30.0
LIMIT_KB = 2 * 1024 * 1024
TIMEOUT = 35


def leaves(node, path):
    """Paths of the numeric leaves under `node` (keys and indices)."""
    if isinstance(node, bool):
        return
    if isinstance(node, (int, float)):
        yield path, isinstance(node, int)
    elif isinstance(node, dict):
        for key, value in node.items():
            yield from leaves(value, path + [key])
    elif isinstance(node, list):
        for i, value in enumerate(node):
            yield from leaves(value, path + [i])


def with_value(text, path, value):
    doc = tomlkit.parse(text)
    node = doc
    for step in path[:-1]:
        node = node[step]
    node[path[-1]] = value
    return tomlkit.dumps(doc)


def timed(binary, args, cwd):
    """Runs `binary args` under /usr/bin/time: exit status, seconds, KB."""
    with tempfile.NamedTemporaryFile("r", suffix=".time") as report:
        cmd = ["/usr/bin/time", "-f", "%e %M", "-o", report.name, "timeout", "-s", "KILL",
               str(TIMEOUT), binary] + args
        done = subprocess.run(cmd, cwd=cwd, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
        fields = report.read().split()
        try:
            seconds, kb = float(fields[-2]), int(fields[-1])
        except (IndexError, ValueError):
            seconds, kb = float("nan"), 0
        return done.returncode, seconds, kb


def case(binary, mission, path, value):
    text = mission.read_text()
    try:
        changed = with_value(text, path, value)
    except Exception as e:  # a value TOML cannot write
        return [(mission.name, path, value, "write", None, 0.0, 0, str(e))]
    results = []
    with tempfile.TemporaryDirectory() as tmp:
        # Beside its terrain and survey files, as the shipped file is.
        for sibling in mission.parent.iterdir():
            if sibling.is_dir():
                os.symlink(sibling, pathlib.Path(tmp) / sibling.name)
        file = pathlib.Path(tmp) / mission.name
        file.write_text(changed)
        status, seconds, kb = timed(binary, ["check", str(file)], tmp)
        results.append((mission.name, path, value, "check", status, seconds, kb, ""))
        if status != 0:
            return results
        for pipeline in PIPELINES.get(mission.name, ["theta-pso"]):
            status, seconds, kb = timed(
                binary, ["run", pipeline, str(file), "--seed", "1"], tmp)
            results.append((mission.name, path, value, pipeline, status, seconds, kb, ""))
        if path[0] == "flight":
            # The flight check reads [flight]: it is the stage to bound.
            status, seconds, kb = timed(binary, ["fly", str(file), "--seed", "1"], tmp)
            results.append((mission.name, path, value, "fly", status, seconds, kb, ""))
    return results


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("binary")
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--only", default=None)
    args = parser.parse_args()
    binary = str(pathlib.Path(args.binary).resolve())
    missions = sorted((ROOT / "missions").glob("*.toml"))
    if args.only:
        missions = [m for m in missions if m.name == args.only]
    cases = []
    for mission in missions:
        tree = tomlkit.parse(mission.read_text()).unwrap()
        for path, integer in leaves(tree, []):
            for value in (INTEGERS if integer else FLOATS):
                cases.append((mission, path, value))
    print(f"{len(cases)} cases over {len(missions)} missions", flush=True)
    rows = []
    with concurrent.futures.ThreadPoolExecutor(args.jobs) as pool:
        for n, result in enumerate(pool.map(lambda c: case(binary, *c), cases), 1):
            rows.extend(result)
            if n % 200 == 0:
                print(f"  {n} cases", flush=True)
    runs = [r for r in rows if r[3] != "check"]
    bad = [r for r in rows if r[4] is not None and
           (r[4] in (124, 137) or r[4] < 0 or r[4] >= 128 or r[5] > LIMIT_SECONDS or r[6] > LIMIT_KB)]
    print(f"{len(rows)} processes: {sum(r[3] == 'check' for r in rows)} checks, {len(runs)} runs")
    by_status = {}
    for r in runs:
        by_status[r[4]] = by_status.get(r[4], 0) + 1
    print(f"run exit statuses: {dict(sorted(by_status.items(), key=lambda kv: str(kv[0])))}")
    fmt = lambda r: f"{r[0]} {'.'.join(map(str, r[1]))} = {r[2]}: {r[3]} exit {r[4]}, {r[5]:.2f} s, {r[6] / 1024:.0f} MB"
    for label, key in [("slowest", lambda r: -r[5] if not math.isnan(r[5]) else 0),
                       ("largest", lambda r: -r[6])]:
        print(f"{label}:")
        for r in sorted(rows, key=key)[:5]:
            print("  " + fmt(r))
    print(f"over {LIMIT_SECONDS:.0f} s or 2 GB, killed or aborted: {len(bad)}")
    for r in bad:
        print("  " + fmt(r))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
