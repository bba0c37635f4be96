"""Shared part of check_wpl.py and check_plan.py: the expectation file and the
item-by-item comparison.

Expectation file (JSON)::

    {
      "tolerances": {"latlon_deg": 1e-7, "alt_m": 1e-3, "param_abs": 1e-4},  # optional
      "files": [
        {
          "path": "uav1.waypoints",   # relative to the expectation file, or absolute
          "count": 7,                 # number of mission items (optional if "items" given)
          "items": [                  # optional; when given, one entry per item, in order
            {"command": 16, "frame": 0, "lat": -33.87601, "lon": 151.191182, "alt": 20.0},
            {"command": 178, "params": [1, 6.5, -1, 0]},
            ...
          ],
          # check_plan.py only:
          "autopilot": "px4",         # or "ardupilot"; default from mission.firmwareType
          "geofence_count": 6, "geofence_items": [...],
          "rally_count": 0,    "rally_items": [...]
        }
      ]
    }

Every key of an expected item is optional: only the keys given are checked.
  command, frame, current, autocontinue, mission_type (plan only): exact integers.
  param1..param4 or params [p1, p2, p3, p4]: numbers, null means NaN is expected.
  lat, lon: degrees, within latlon_deg. (In a .plan import they are compared
      with x / 1e7 and y / 1e7, in a .waypoints file with the x and y columns.)
  x, y: the raw values (exact integers for a .plan import, degrees for .waypoints).
  alt (or z): metres, within alt_m.
"""

import json
import math
import os
import sys

DEFAULT_TOLERANCES = {"latlon_deg": 1e-7, "alt_m": 1e-3, "param_abs": 1e-4}

# Keys an expected item may have, for catching typos in expectation files.
ITEM_KEYS = {
    "command", "frame", "current", "autocontinue", "mission_type",
    "param1", "param2", "param3", "param4", "params",
    "lat", "lon", "x", "y", "alt", "z", "comment",
}


class SetupError(Exception):
    """Bad arguments, unreadable expectation file, missing file, timeout: exit 2."""


def load_expectations(path):
    try:
        with open(path, encoding="utf-8") as f:
            spec = json.load(f)
    except OSError as e:
        raise SetupError(f"cannot read expectation file {path}: {e}") from e
    except json.JSONDecodeError as e:
        raise SetupError(f"expectation file {path} is not valid JSON: {e}") from e
    if not isinstance(spec, dict) or not isinstance(spec.get("files"), list) or not spec["files"]:
        raise SetupError(f'{path}: expected an object with a non-empty "files" list')
    tolerances = dict(DEFAULT_TOLERANCES)
    for key, value in (spec.get("tolerances") or {}).items():
        if key not in DEFAULT_TOLERANCES:
            raise SetupError(f"{path}: unknown tolerance {key!r} (known: {sorted(DEFAULT_TOLERANCES)})")
        tolerances[key] = float(value)
    base = os.path.dirname(os.path.abspath(path))
    files = []
    for i, entry in enumerate(spec["files"]):
        if not isinstance(entry, dict) or not isinstance(entry.get("path"), str):
            raise SetupError(f'{path}: files[{i}] needs a "path" string')
        entry = dict(entry)
        entry["resolved_path"] = os.path.join(base, entry["path"])
        for list_key in ("items", "geofence_items", "rally_items"):
            for j, item in enumerate(entry.get(list_key) or []):
                unknown = set(item) - ITEM_KEYS
                if unknown:
                    raise SetupError(
                        f"{path}: files[{i}].{list_key}[{j}] has unknown keys {sorted(unknown)}"
                    )
        files.append(entry)
    return files, tolerances


def _fmt(v):
    if isinstance(v, float):
        return repr(v)
    return str(v)


def _num_close(actual, expected, tol):
    if expected is None:
        return isinstance(actual, float) and math.isnan(actual)
    if actual is None or (isinstance(actual, float) and math.isnan(actual)):
        return False
    return abs(float(actual) - float(expected)) <= tol


def compare_item(where, actual, expected, tolerances, latlon_scale, xy_exact):
    """Compare one item.

    actual: dict with command, frame, current, autocontinue, param1..4, x, y, z
            (and mission_type for MAVSDK items).
    latlon_scale: divide x/y by this to get degrees (1e7 for MAVSDK, 1 for WPL).
    xy_exact: compare raw x/y exactly (MAVSDK ints) instead of with the lat/lon tolerance.
    Returns a list of error strings.
    """
    errors = []
    for key in ("command", "frame", "current", "autocontinue", "mission_type"):
        if key in expected and int(actual[key]) != int(expected[key]):
            errors.append(f"{where}: {key} is {actual[key]}, expected {expected[key]}")

    params = {}
    if "params" in expected:
        p = expected["params"]
        if not isinstance(p, list) or len(p) != 4:
            errors.append(f'{where}: expectation "params" must be a list of 4 values (null = NaN)')
        else:
            params = {f"param{i + 1}": p[i] for i in range(4)}
    for i in range(1, 5):
        if f"param{i}" in expected:
            params[f"param{i}"] = expected[f"param{i}"]
    for key, want in sorted(params.items()):
        got = actual[key]
        tol = tolerances["param_abs"] if want is None else max(tolerances["param_abs"], 1e-6 * abs(want))
        if not _num_close(got, want, tol):
            errors.append(f"{where}: {key} is {_fmt(got)}, expected {'NaN' if want is None else _fmt(want)}")

    for key, raw in (("lat", "x"), ("lon", "y")):
        if key in expected:
            got = actual[raw] / latlon_scale
            diff = abs(got - expected[key])
            if not diff <= tolerances["latlon_deg"]:
                errors.append(
                    f"{where}: {key} is {got:.9f}, expected {expected[key]:.9f} "
                    f"(off by {diff:.2e} deg > {tolerances['latlon_deg']:.0e})"
                )
    for raw in ("x", "y"):
        if raw in expected:
            got = actual[raw]
            if xy_exact:
                ok = int(got) == int(expected[raw])
            else:
                ok = _num_close(got, expected[raw], tolerances["latlon_deg"])
            if not ok:
                errors.append(f"{where}: {raw} is {_fmt(got)}, expected {_fmt(expected[raw])}")

    for key in ("alt", "z"):
        if key in expected and not _num_close(actual["z"], expected[key], tolerances["alt_m"]):
            errors.append(
                f"{where}: {key} is {_fmt(actual['z'])}, expected {_fmt(expected[key])} "
                f"(tolerance {tolerances['alt_m']} m)"
            )
    return errors


def compare_list(where, actual_items, expected_count, expected_items, tolerances, latlon_scale, xy_exact):
    errors = []
    if expected_count is None and expected_items is not None:
        expected_count = len(expected_items)
    if expected_items is not None and len(expected_items) != expected_count:
        errors.append(f'{where}: expectation lists {len(expected_items)} items but "count" is {expected_count}')
    if expected_count is not None and len(actual_items) != expected_count:
        errors.append(f"{where}: {len(actual_items)} items, expected {expected_count}")
    for i, want in enumerate(expected_items or []):
        if i >= len(actual_items):
            break
        errors += compare_item(f"{where} item {i}", actual_items[i], want, tolerances, latlon_scale, xy_exact)
    return errors


def report(errors, checked_files, label):
    """Print the result; return the process exit code."""
    if errors:
        print(f"{label}: {len(errors)} mismatch(es):", file=sys.stderr)
        for e in errors[:200]:
            print(f"  - {e}", file=sys.stderr)
        if len(errors) > 200:
            print(f"  ... and {len(errors) - 200} more", file=sys.stderr)
        return 1
    print(f"{label}: OK, {checked_files} file(s) match their expectations")
    return 0


def nan_to_none(v):
    return None if isinstance(v, float) and math.isnan(v) else v
