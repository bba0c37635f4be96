#!/usr/bin/env python3
"""Read QGC WPL 110 (.waypoints) files with pymavlink and check them against an
expectation file (format: see expectations.py or README.md).

    python check_wpl.py EXPECT.json            # check; exit 0 ok, 1 mismatch, 2 setup error
    python check_wpl.py --dump A.waypoints ... # print what pymavlink reads, as an expectation

Two readers look at each file:
  * pymavlink's mavwp.MAVWPLoader().load(path), the one MAVProxy and many scripts use;
    its values are what is compared with the expectation. It splits on any whitespace,
    skips blank and '#' lines and renumbers seq itself.
  * a strict line check, because QGroundControl is stricter than pymavlink: it splits each
    line on TAB only and wants exactly 12 fields, with no blank or comment lines
    (MissionController::_loadTextMissionFile / MissionItem::load(QTextStream&)).
    Here also: the seq column must count 0, 1, 2, ...  --lenient turns this check off.
"""

import argparse
import json
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ beside the scripts in the repo
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from expectations import SetupError, compare_list, load_expectations, nan_to_none, report  # noqa: E402

try:
    from pymavlink import mavwp
except ImportError:  # pragma: no cover
    sys.exit("check_wpl.py: pymavlink is not installed (pip install -r requirements.txt)")

HEADER = "QGC WPL 110"


class ReadError(Exception):
    pass


def strict_line_errors(path, name):
    """QGroundControl-style structural checks of the raw text."""
    errors = []
    with open(path, encoding="utf-8", newline="") as f:
        text = f.read()
    lines = text.split("\n")
    if lines and lines[-1] == "":
        lines.pop()  # the file's final newline
    if not lines:
        return [f"{name}: empty file"]
    lines = [line.removesuffix("\r") for line in lines]
    if lines[0] != HEADER:
        errors.append(f"{name}: first line is {lines[0]!r}, expected {HEADER!r}")
    seq = 0
    for n, line in enumerate(lines[1:], start=2):
        if not line.strip() or line.startswith("#"):
            errors.append(f"{name} line {n}: blank or comment line (QGroundControl would reject the file)")
            continue
        fields = line.split("\t")
        if len(fields) != 12:
            seq += 1
            errors.append(
                f"{name} line {n}: {len(fields)} TAB-separated field(s), expected 12 "
                f"(QGroundControl would reject the file): {line!r}"
            )
            continue
        if fields[0] != str(seq):
            errors.append(f"{name} line {n}: seq column is {fields[0]!r}, expected {seq}")
        for k in (1, 2, 3, 11):
            if not fields[k].isdigit():
                errors.append(f"{name} line {n}: field {k + 1} {fields[k]!r} is not an unsigned integer")
        seq += 1
    return errors


def read_items(path):
    loader = mavwp.MAVWPLoader()
    try:
        loader.load(path)
    except (mavwp.MAVWPError, ValueError) as e:
        msg = getattr(e, "message", None) or str(e)
        raise ReadError(f"pymavlink could not load it: {msg}") from e
    items = []
    for i in range(loader.count()):
        w = loader.wp(i)
        items.append(
            {
                "seq": w.seq, "command": w.command, "frame": w.frame, "current": w.current,
                "autocontinue": w.autocontinue,
                "param1": w.param1, "param2": w.param2, "param3": w.param3, "param4": w.param4,
                "x": w.x, "y": w.y, "z": w.z,
            }
        )
    return items


def check(expect_path, lenient):
    files, tolerances = load_expectations(expect_path)
    errors = []
    for entry in files:
        path = entry["resolved_path"]
        if not os.path.isfile(path):
            errors.append(f"{entry['path']}: file not found ({path})")
            continue
        if not lenient:
            errors += strict_line_errors(path, entry["path"])
        try:
            items = read_items(path)
        except ReadError as e:
            errors.append(f"{entry['path']}: {e}")
            continue
        errors += compare_list(
            entry["path"], items, entry.get("count"), entry.get("items"), tolerances,
            latlon_scale=1.0, xy_exact=False,
        )
    return report(errors, len(files), "check_wpl")


def dump(paths):
    out = {"files": []}
    for path in paths:
        try:
            items = read_items(path)
        except ReadError as e:
            raise SetupError(f"{path}: {e}") from e
        out["files"].append(
            {
                "path": os.path.abspath(path),
                "count": len(items),
                "items": [
                    {
                        "command": it["command"], "frame": it["frame"], "current": it["current"],
                        "autocontinue": it["autocontinue"],
                        "params": [nan_to_none(it[f"param{k}"]) for k in range(1, 5)],
                        "lat": it["x"], "lon": it["y"], "alt": it["z"],
                    }
                    for it in items
                ],
            }
        )
    print(json.dumps(out, indent=2))
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("expectation", nargs="?", help="expectation JSON file")
    ap.add_argument("--lenient", action="store_true", help="skip the QGroundControl-style line checks")
    ap.add_argument("--dump", nargs="+", metavar="FILE", help="print the items pymavlink reads, as an expectation")
    args = ap.parse_args(argv)
    try:
        if args.dump:
            return dump(args.dump)
        if not args.expectation:
            ap.error("give an expectation file, or --dump FILE...")
        return check(args.expectation, args.lenient)
    except SetupError as e:
        print(f"check_wpl: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
