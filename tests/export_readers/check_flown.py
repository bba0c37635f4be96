#!/usr/bin/env python3
"""Read one export's files as the autopilot tools read them, fly what they read, and check
the flights against the plan; check that every file has the same home and heights.

    python check_flown.py EXPECT.json      # exit 0 ok, 1 mismatch, 2 setup error

Readers: MAVSDK's MissionRaw.import_qgroundcontrol_mission (.plan, as PX4 or ArduPilot per
mission.firmwareType, and once more as ArduPilot, whose import puts plannedHomePosition
first: the home as MAVSDK reads it), pymavlink's mavwp.MAVWPLoader (.waypoints, turned into
MAVLink int32 1e-7 degrees by truncation, int(x * 1e7), as MAVProxy uploads them), Python's
csv module (.csv) and fastkml (.kml). Positions go back to the plan's ENU frame with pymap3d
(a geodesy independent of the map_3d crate skyform uses), in the export's convention
(docs/export.md, "One altitude convention"): latitude and longitude are those of the ground
point (x, y) of the ENU frame; the altitude is [origin].altitude + z; a waypoint's frame-3
altitude is z minus the height of the ground at the vehicle's home.

Flying (docs/export.md, "Re-verification as flown"): every vehicle starts at its first
NAV_WAYPOINT at the plan's first instant, together with the others; holds param1 seconds at
each waypoint; flies each leg in a straight line, a multicopter at the DO_CHANGE_SPEED ground
speed in force (horizontal; at most its speed limit) with its vertical speed at most its climb
or descent limit (the slower governs), a fixed wing at the commanded airspeed along the leg.
The CSV is flown in straight lines between its samples as read.

Checked, per export: every flight within the announced tolerance of the plan at every planned
instant; the closest pair of vehicles at least the closest limit (2 r_Q for theta-PSO) and every
vehicle's clearance to every obstacle at least the clearance limit (flat ground only); the same
home (1e-7 degrees, 1 mm) in the .plan (JSON and MAVSDK), the .waypoints and the KML; the same
relative heights in the .plan and .waypoints items; at each waypoint's planned instant, the
CSV's rel_alt equal to the waypoint's height; every CSV and KML sample's altitude minus the
home's altitude equal to the CSV's rel_alt.

Expectation file (JSON), written by tests/export.rs::flight_expectation:

    {"origin": {"latitude": .., "longitude": .., "altitude": ..},
     "tolerance": 0.1, "closest": 1.0, "clearance": 0.5, "flat_ground": true,
     "obstacles": [{"center": [x, y], "radius": r, "height": h}],
     "kml": "path.kml", "fixed_wing": false,
     "vehicles": [{"name": "UAV 1", "plan": "..", "waypoints": "..", "csv": "..",
                   "limits": {"speed": 12, "climb": 3, "descent": 1.5},
                   "waypoint_times": [t0, t1, ..],
                   "track": [[t, x, y, z], ..]}]}
"""

import argparse
import csv
import json
import math
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ beside the scripts in the repo
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from expectations import SetupError, report  # noqa: E402

try:
    import pymap3d
    from fastkml import kml
    from pymavlink import mavwp
except ImportError as e:  # pragma: no cover
    sys.exit(f"check_flown.py: {e} (pip install -r requirements.txt)")
from check_plan import Importer, plan_autopilot  # noqa: E402

NAV_WAYPOINT, NAV_TAKEOFF, DO_CHANGE_SPEED = 16, 22, 178


class Geo:
    """The export's convention about one origin, through pymap3d."""

    def __init__(self, origin):
        self.lat0, self.lon0 = origin["latitude"], origin["longitude"]
        self.h0 = origin.get("altitude", 0.0)

    def ground_xy(self, lat, lon):
        """The ENU ground point (x, y, 0) whose geodetic latitude and longitude these are."""
        h = self.h0
        for _ in range(5):
            e, n, _ = pymap3d.geodetic2enu(lat, lon, h, self.lat0, self.lon0, self.h0)
            _, _, h = pymap3d.enu2geodetic(e, n, 0.0, self.lat0, self.lon0, self.h0)
        return e, n

    def enu(self, lat, lon, z):
        e, n = self.ground_xy(lat, lon)
        return (e, n, z)


def trunc_e7(deg):
    """MAVProxy's int(x * 1e7): toward zero."""
    return int(deg * 1e7)


def round_e7(deg):
    return int(round(deg * 1e7))


def mission_of(items, start_index):
    """(waypoints [(lat_e7, lon_e7, rel_alt, hold)], speeds [speed of the leg into each]) of
    MAVLink items read by a tool (dicts with command, param1, param2, x, y, z)."""
    waypoints, speeds = [], []
    speed = None
    for it in items[start_index:]:
        if it["command"] == DO_CHANGE_SPEED:
            speed = it["param2"]
        elif it["command"] == NAV_WAYPOINT:
            waypoints.append((it["x"], it["y"], it["z"], it["param1"]))
            speeds.append(speed if speed is not None else 0.0)
    return waypoints, speeds


def flight(points, speeds, holds, start, limits, fixed_wing):
    """(arrive, depart) per waypoint: straight legs flown as docs/export.md says."""
    arrive, depart = [], []
    t = start
    for i, p in enumerate(points):
        if i > 0:
            a = points[i - 1]
            dx, dy, dz = p[0] - a[0], p[1] - a[1], p[2] - a[2]
            v = speeds[i]
            if fixed_wing:
                t += math.sqrt(dx * dx + dy * dy + dz * dz) / v if v > 0 else 0.0
            else:
                h = math.hypot(dx, dy)
                vh = min(v, limits["speed"]) if limits.get("speed") else v
                horizontal = h / vh if vh > 0 else 0.0
                rate = limits.get("climb") if dz >= 0 else limits.get("descent")
                vertical = abs(dz) / rate if rate else 0.0
                t += max(horizontal, vertical)
        arrive.append(t)
        t += holds[i]
        depart.append(t)
    return arrive, depart


def position(points, arrive, depart, t):
    """Where the flown vehicle is at t (holding at the ends)."""
    if t <= depart[0]:
        return points[0]
    for i in range(1, len(points)):
        if t <= depart[i]:
            if t >= arrive[i]:
                return points[i]
            span = arrive[i] - depart[i - 1]
            s = 0.0 if span <= 0 else min(1.0, max(0.0, (t - depart[i - 1]) / span))
            a, b = points[i - 1], points[i]
            return tuple(a[k] + (b[k] - a[k]) * s for k in range(3))
    return points[-1]


def outward(p, o):
    """Signed distance in the plane from p to o's outline: its circle, or its footprint
    polygon when it has one (negative inside, even-odd rule)."""
    footprint = o.get("footprint") or []
    if not footprint:
        return math.hypot(p[0] - o["center"][0], p[1] - o["center"][1]) - o["radius"]
    nearest, inside, n = math.inf, False, len(footprint)
    for i in range(n):
        (ax, ay), (bx, by) = footprint[i], footprint[(i + 1) % n]
        dx, dy = bx - ax, by - ay
        length2 = dx * dx + dy * dy
        t = 0.0 if length2 == 0 else max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / length2))
        nearest = min(nearest, math.hypot(ax + t * dx - p[0], ay + t * dy - p[1]))
        if (ay > p[1]) != (by > p[1]) and p[0] < ax + (p[1] - ay) / (by - ay) * (bx - ax):
            inside = not inside
    return -nearest if inside else nearest


def clearance(p, o):
    """Distance from p to the solid prism o (flat ground): beside it, to its outline; above
    its top or below its base, to the nearest point of that face."""
    side = outward(p, o)
    if p[2] > o["height"]:
        off = p[2] - o["height"]
    elif p[2] < o.get("base", 0.0):
        off = o["base"] - p[2]
    else:
        return side
    return math.hypot(max(side, 0.0), off)


def read_csv(path):
    with open(path, encoding="utf-8", newline="") as f:
        return [{k: float(v) for k, v in row.items()} for row in csv.DictReader(f)]


def read_kml(path):
    """{folder name: (track coords [(lon, lat, alt)], home (lon, lat, alt) or None)}."""
    root = kml.KML.parse(path, strict=True, validate=True)
    doc = [f for f in root.features if type(f).__name__ == "Document"][0]
    out = {}
    for folder in doc.features:
        if type(folder).__name__ != "Folder" or folder.name == "Mission":
            continue
        track, home = [], None
        for p in folder.features:
            if p.name.endswith(" track"):
                track = list(p.geometry.coords)
                if p.kml_geometry.altitude_mode.value != "absolute":
                    raise SetupError(f"{path} {folder.name}: track altitudeMode is not absolute")
            elif p.name.endswith(" home"):
                home = tuple(p.geometry.coords[0])
        out[folder.name] = (track, home)
    return out


def check(spec_path, timeout):
    try:
        with open(spec_path, encoding="utf-8") as f:
            spec = json.load(f)
    except (OSError, ValueError) as e:
        raise SetupError(f"cannot read {spec_path}: {e}") from e
    base = os.path.dirname(os.path.abspath(spec_path))
    path = lambda p: os.path.join(base, p)  # noqa: E731
    geo = Geo(spec["origin"])
    h0 = geo.h0
    tol = spec["tolerance"]
    fixed_wing = spec.get("fixed_wing", False)
    errors = []
    kml_read = read_kml(path(spec["kml"])) if spec.get("kml") else {}
    flown = {"plan": [], "waypoints": [], "csv": []}  # per vehicle: position at each instant
    times = None
    worst = {"plan": 0.0, "waypoints": 0.0, "csv": 0.0}
    with Importer(timeout, False) as importer:
        for v in spec["vehicles"]:
            name = v["name"]
            track = v["track"]
            times = times or [s[0] for s in track]
            # The .plan: MAVSDK, for the autopilot it is written for; and as ArduPilot for the home.
            entry = {"path": v["plan"], "resolved_path": path(v["plan"])}
            autopilot = plan_autopilot(entry)
            data, err = importer.import_plan(path(v["plan"]), autopilot)
            home_data, home_err = importer.import_plan(path(v["plan"]), "ardupilot")
            if err or home_err:
                errors.append(f"{name}: MAVSDK: {err or home_err}")
                continue
            items = [
                {"command": i.command, "param1": i.param1, "param2": i.param2,
                 "x": i.x, "y": i.y, "z": i.z}
                for i in data.mission_items
            ]
            first = 1 if autopilot == "ardupilot" else 0
            h = home_data.mission_items[0]
            homes = {"plan (MAVSDK)": (h.x, h.y, h.z)}
            with open(path(v["plan"]), encoding="utf-8") as f:
                planned_home = json.load(f)["mission"]["plannedHomePosition"]
            homes["plan (plannedHomePosition)"] = (
                round_e7(planned_home[0]), round_e7(planned_home[1]), planned_home[2])
            # The .waypoints: pymavlink, to int32 as MAVProxy does (truncating) and as a
            # rounding reader does: both must agree.
            loader = mavwp.MAVWPLoader()
            loader.load(path(v["waypoints"]))
            wpl = [loader.wp(i) for i in range(loader.count())]
            for w in wpl:
                if trunc_e7(w.x) != round_e7(w.x) or trunc_e7(w.y) != round_e7(w.y):
                    errors.append(f"{name} .waypoints item {w.seq}: {w.x}, {w.y} truncate and "
                                  f"round to different 1e-7 degrees")
            homes["waypoints item 0 (pymavlink)"] = (trunc_e7(wpl[0].x), trunc_e7(wpl[0].y), wpl[0].z)
            wpl_items = [
                {"command": w.command, "param1": w.param1, "param2": w.param2,
                 "x": trunc_e7(w.x), "y": trunc_e7(w.y), "z": w.z}
                for w in wpl
            ]
            track_kml, home_kml = kml_read.get(name, ([], None))
            if home_kml is None:
                errors.append(f"{name}: no home placemark in the KML")
            else:
                homes["KML home"] = (round_e7(home_kml[1]), round_e7(home_kml[0]), home_kml[2])
            ref = homes["plan (MAVSDK)"]
            for what, hm in homes.items():
                if hm[0] != ref[0] or hm[1] != ref[1] or abs(hm[2] - ref[2]) > 1e-3:
                    errors.append(f"{name}: home in {what} is {hm}, in the .plan as MAVSDK reads it {ref}")
            home_alt = ref[2]
            home_z = home_alt - h0
            # The same heights: .plan and .waypoints items.
            plan_pos = [i for i in items[first:] if i["command"] in (NAV_WAYPOINT, NAV_TAKEOFF)]
            wpl_pos = [i for i in wpl_items[1:] if i["command"] in (NAV_WAYPOINT, NAV_TAKEOFF)]
            if len(plan_pos) != len(wpl_pos):
                errors.append(f"{name}: {len(plan_pos)} positioned items in the .plan, {len(wpl_pos)} in the .waypoints")
            for k, (a, b) in enumerate(zip(plan_pos, wpl_pos)):
                if a["x"] != b["x"] or a["y"] != b["y"] or abs(a["z"] - b["z"]) > 1e-4:
                    errors.append(f"{name} positioned item {k}: .plan {a}, .waypoints {b}")
                    break
            # The CSV: heights at the waypoints' instants, and its own altitudes.
            rows = read_csv(path(v["csv"]))
            by_t = {round(r["t"], 3): r for r in rows}
            wps = [i for i in items[first:] if i["command"] == NAV_WAYPOINT]
            for k, (t, w) in enumerate(zip(v["waypoint_times"], wps)):
                r = by_t.get(round(t, 3))
                if r is None:
                    errors.append(f"{name}: no CSV row at waypoint {k + 1}'s t = {t}")
                    break
                if abs(r["rel_alt"] - w["z"]) > 1e-3:
                    errors.append(f"{name} waypoint {k + 1}: height {w['z']} in the .plan, "
                                  f"rel_alt {r['rel_alt']} in the CSV")
                # The .plan's 1e-7 degrees are the CSV's (to 1e-9 degrees) rounded.
                if max(abs(r["lat"] * 1e7 - w["x"]), abs(r["lon"] * 1e7 - w["y"])) > 0.5 + 0.01:
                    errors.append(f"{name} waypoint {k + 1}: the CSV's lat/lon at t = {t} are "
                                  f"{r['lat']}, {r['lon']}; the .plan has {w['x']}, {w['y']} (1e-7 deg)")
            for r in rows:
                if abs(r["alt"] - home_alt - r["rel_alt"]) > 1e-3:
                    errors.append(f"{name} CSV t = {r['t']}: alt {r['alt']} - home {home_alt} is not rel_alt {r['rel_alt']}")
                    break
            # The KML's track: every CSV sample at a vertex (in order; a vehicle holding
            # still shares one), its altitude minus the home's the sample's rel_alt.
            j = 0

            def off(r, c):
                return math.hypot((c[0] - r["lon"]) * 1e7, (c[1] - r["lat"]) * 1e7) + abs(c[2] - r["alt"])

            for r in rows if track_kml else []:
                while j + 1 < len(track_kml) and off(r, track_kml[j + 1]) <= off(r, track_kml[j]):
                    j += 1
                c = track_kml[j]
                if abs((c[2] - home_alt) - r["rel_alt"]) > 1e-3 or off(r, c) > 0.05:
                    errors.append(f"{name} t = {r['t']}: the KML's vertex {c} (altitude - home "
                                  f"{c[2] - home_alt:.4f}) is not the CSV's sample (rel_alt {r['rel_alt']})")
                    break
            # Fly the .plan (MAVSDK's reading) and the .waypoints (pymavlink's).
            start = track[0][0]
            for label, its, idx in (("plan", items, first), ("waypoints", wpl_items, 1)):
                wp, speeds = mission_of(its, idx)
                pts = [geo.enu(x / 1e7, y / 1e7, z + home_z) for (x, y, z, _) in wp]
                holds = [hold for (_, _, _, hold) in wp]
                arrive, depart = flight(pts, speeds, holds, start, v["limits"], fixed_wing)
                path_flown = [position(pts, arrive, depart, s[0]) for s in track]
                deviation, when = max((math.dist(p, s[1:4]), s[0]) for p, s in zip(path_flown, track))
                worst[label] = max(worst[label], deviation)
                if deviation > tol + 1e-6:
                    errors.append(f"{name} .{label} flown: {deviation:.4f} m from the plan at "
                                  f"t = {when} (tolerance {tol} m)")
                flown[label].append(path_flown)
            # The CSV as read.
            pts = [geo.enu(r["lat"], r["lon"], r["alt"] - h0) for r in rows]
            for p, s in zip(pts, track):
                worst["csv"] = max(worst["csv"], math.dist(p, s[1:4]))
            if worst["csv"] > 1e-3:
                errors.append(f"{name} CSV as read: {worst['csv']:.4f} m from the plan")
            flown["csv"].append(pts)
    closest = {}
    least_clearance = {}
    for label, paths in flown.items():
        if len(paths) != len(spec["vehicles"]):
            continue
        c, cl = math.inf, math.inf
        for k in range(len(times)):
            for i in range(len(paths)):
                if spec.get("flat_ground", True):
                    for o in spec.get("obstacles", []):
                        cl = min(cl, clearance(paths[i][k], o))
                for j in range(i + 1, len(paths)):
                    c = min(c, math.dist(paths[i][k], paths[j][k]))
        closest[label], least_clearance[label] = c, cl
        if c < spec["closest"]:
            errors.append(f".{label} flown: closest pair {c:.4f} m < {spec['closest']} m")
        if cl < spec["clearance"]:
            errors.append(f".{label} flown: clearance {cl:.4f} m < {spec['clearance']} m")
    if not errors:
        figures = ", ".join(
            f".{k}: deviation {worst[k]:.4f} m, closest pair {closest.get(k, math.inf):.3f} m, "
            f"clearance {least_clearance.get(k, math.inf):.3f} m"
            for k in worst
        )
        print(f"check_flown.py: tolerance {tol} m; {figures}")
    return report(errors, len(spec["vehicles"]), "check_flown.py")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("expect", help="expectation JSON file")
    ap.add_argument("--timeout", type=float, default=10.0, help="seconds to wait for MAVSDK (default 10)")
    args = ap.parse_args()
    try:
        return check(args.expect, args.timeout)
    except SetupError as e:
        print(f"check_flown.py: {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
