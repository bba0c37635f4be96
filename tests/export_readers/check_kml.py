#!/usr/bin/env python3
"""Read skyform's KML export with fastkml (validating it against the OGC KML 2.2 schema)
and check what it reads against the plan, with pymap3d's geodesy (independent of the
map_3d crate skyform uses).

    python check_kml.py EXPECT.json      # exit 0 ok, 1 mismatch, 2 setup error
    python check_kml.py --dump A.kml     # print the folders and placemarks fastkml reads

Expectation file (JSON)::

    {
      "tolerance_m": 0.01,                        # optional, metres
      "files": [
        {
          "path": "bridge-theta-pso.kml",         # relative to the expectation file
          "origin": {"latitude": -33.87601, "longitude": 151.191182, "altitude": 0.0},
          "verdict": "J = 181.37, 151.0 m, feasible",   # must be in the Document's description
          "vehicles": [                           # one folder each, in this order
            {"folder": "UAV 1", "color": "ffcfbe17",
             "home": [lat, lon, alt],                # the waypoint files' home
             "samples": [[x, y, z, altitude], ...]}  # ENU metres, the plan; its absolute altitude
          ],
          "obstacles": [{"name": "pier 1", "center": [x, y], "radius": 2.5, "top": 16.0,
                         "base": 0.0, "raised": false,   # base > 0: a closed solid
                         "footprint": []}],               # [[x, y], ...]: a polygon
          "bands": [{"name": "pier 1 band", "center": [x, y], "inner": 3.5, "outer": 7.5}]
        }
      ]
    }

What is checked, per file: the schema (fastkml parses with validation on), one Document
whose description holds the verdict, a "Mission" folder then one folder per vehicle in
order; each vehicle's track is a LineString with altitudeMode absolute, styled with the
vehicle's colour, whose vertices are the planned samples in order (samples at one place,
a vehicle holding, share a vertex): every sample's latitude/longitude within the tolerance
(horizontally, metres) of where pymap3d puts the ground point (x, y) of the plan's ENU
frame, its altitude within the tolerance of the expected absolute altitude
([origin].altitude + z, the export's convention); the vehicle's home Point at the expected
home. Each obstacle is an extruded Polygon, absolute, every vertex at its radius from its
centre (or one of its footprint's vertices) and at its top; one raised off the ground (a
deck) a MultiGeometry of polygons, every vertex at its base or its top; each band a ring on the ground between its two radii.
"""

import argparse
import json
import math
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ beside the scripts in the repo
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from expectations import SetupError, report  # noqa: E402

try:
    from fastkml import kml
    from fastkml.enums import AltitudeMode
except ImportError:  # pragma: no cover
    sys.exit("check_kml.py: fastkml is not installed (pip install -r requirements.txt)")
try:
    import pymap3d
except ImportError:  # pragma: no cover
    sys.exit("check_kml.py: pymap3d is not installed (pip install -r requirements.txt)")


def read(path):
    try:
        return kml.KML.parse(path, strict=True, validate=True)
    except OSError as e:
        raise SetupError(f"cannot read {path}: {e}") from e


def folders(feature):
    return [f for f in getattr(feature, "features", []) or [] if type(f).__name__ == "Folder"]


def placemarks(feature):
    return [f for f in getattr(feature, "features", []) or [] if type(f).__name__ == "Placemark"]


def coords_of(placemark):
    g = placemark.kml_geometry
    if type(g).__name__ == "Polygon":
        return list(placemark.geometry.exterior.coords)
    if type(g).__name__ == "MultiGeometry":
        return [c for part in placemark.geometry.geoms for c in part.exterior.coords]
    return list(placemark.geometry.coords)


def horizontal_error(lon, lat, x, y, origin):
    """Metres between the read (lon, lat) and the ground point (x, y) of the plan's ENU frame."""
    lat0, lon0, h0 = origin["latitude"], origin["longitude"], origin.get("altitude", 0.0)
    want_lat, want_lon, want_h = pymap3d.enu2geodetic(x, y, 0.0, lat0, lon0, h0)
    e, n, _ = pymap3d.geodetic2enu(lat, lon, want_h, want_lat, want_lon, want_h)
    return math.hypot(e, n)


def ground_point(lon, lat, origin):
    """ENU x, y of a read ground position (its height is the origin's, to well below 1 mm
    in x and y at any site distance skyform exports)."""
    lat0, lon0, h0 = origin["latitude"], origin["longitude"], origin.get("altitude", 0.0)
    e, n, _ = pymap3d.geodetic2enu(lat, lon, h0, lat0, lon0, h0)
    return e, n


def style_color(document, url):
    wanted = (url or "").lstrip("#")
    for style in document.styles or []:
        if style.id == wanted:
            for sub in style.styles or []:
                if type(sub).__name__ == "LineStyle":
                    return sub.color
    return None


def check_file(entry, tol):
    errors = []
    name = entry["path"]
    origin = entry["origin"]
    doc_root = read(entry["resolved_path"])
    documents = [f for f in doc_root.features if type(f).__name__ == "Document"]
    if len(documents) != 1:
        return [f"{name}: {len(documents)} Documents, expected 1"], 0.0, 0.0
    doc = documents[0]
    if entry.get("verdict") and entry["verdict"] not in (doc.description or ""):
        errors.append(f"{name}: the description does not hold the verdict {entry['verdict']!r}")
    top = folders(doc)
    want_names = ["Mission"] + [v["folder"] for v in entry.get("vehicles", [])]
    got_names = [f.name for f in top]
    if got_names != want_names:
        errors.append(f"{name}: folders {got_names}, expected {want_names}")
    worst_h = worst_v = 0.0
    by_name = {f.name: f for f in top}
    for v in entry.get("vehicles", []):
        where = f"{name} {v['folder']}"
        folder = by_name.get(v["folder"])
        marks = placemarks(folder) if folder else []
        tracks = [m for m in marks if (m.name or "").endswith(" track")]
        homes = [m for m in marks if (m.name or "").endswith(" home")]
        if len(tracks) != 1 or len(marks) != len(tracks) + len(homes):
            errors.append(f"{where}: placemarks {[m.name for m in marks]}, expected one track (and its home)")
            continue
        if v.get("home") is not None:
            if len(homes) != 1:
                errors.append(f"{where}: no home placemark")
            else:
                c = homes[0].geometry.coords[0]
                lat, lon, alt = v["home"]
                if abs(c[1] - lat) > 1e-9 or abs(c[0] - lon) > 1e-9 or abs(c[2] - alt) > tol:
                    errors.append(f"{where}: home at {c}, expected {v['home']} (lat, lon, alt)")
                if homes[0].kml_geometry.altitude_mode != AltitudeMode.absolute:
                    errors.append(f"{where}: the home's altitudeMode is not absolute")
        track = tracks[0]
        geometry = track.kml_geometry
        if type(geometry).__name__ != "LineString":
            errors.append(f"{where}: the track is a {type(geometry).__name__}, expected LineString")
            continue
        if geometry.altitude_mode != AltitudeMode.absolute:
            errors.append(f"{where}: altitudeMode {geometry.altitude_mode}, expected absolute")
        url = track.style_url.url if track.style_url else None
        color = style_color(doc, url)
        if v.get("color") and color != v["color"]:
            errors.append(f"{where}: colour {color} (style {url}), expected {v['color']}")
        got = coords_of(track)
        want = v["samples"]
        # In order, every planned sample at a vertex of the track (consecutive
        # samples at one place, a vehicle holding, share one vertex), and every
        # vertex at a sample.
        j = 0
        used = set()
        for k, (x, y, z, altitude) in enumerate(want):
            def off(i):
                g = got[i]
                alt = g[2] if len(g) > 2 else 0.0
                return horizontal_error(g[0], g[1], x, y, origin), abs(alt - altitude)
            if not got:
                break
            h, d = off(j)
            # The sample's own vertex is the next one whenever that is nearer.
            while j + 1 < len(got):
                h2, d2 = off(j + 1)
                if math.hypot(h2, d2) > math.hypot(h, d):
                    break
                j, h, d = j + 1, h2, d2
            used.add(j)
            worst_h, worst_v = max(worst_h, h), max(worst_v, d)
            if h > tol or d > tol:
                errors.append(
                    f"{where} sample {k}: {h:.4f} m off horizontally, {d:.4f} m vertically from "
                    f"vertex {j} (tolerance {tol} m)"
                )
                if len(errors) > 50:
                    break
        if got and len(used) != len(got):
            errors.append(f"{where}: {len(got)} vertices, {len(used)} of them at a planned sample")
        if not got and want:
            errors.append(f"{where}: the track has no positions")
    mission = by_name.get("Mission")
    sub = {f.name: f for f in folders(mission)} if mission else {}
    marks = {p.name: p for f in sub.values() for p in placemarks(f)}
    for o in entry.get("obstacles", []):
        where = f"{name} obstacle {o['name']!r}"
        p = marks.get(o["name"])
        if p is None:
            errors.append(f"{where}: not found")
            continue
        g = p.kml_geometry
        raised = o.get("raised", False)
        if raised:
            # A deck: a closed solid (MultiGeometry of polygons) from base to top.
            if type(g).__name__ != "MultiGeometry":
                errors.append(f"{where}: expected a MultiGeometry solid, got {type(g).__name__}")
                continue
            heights = (o["base"], o["top"])
        else:
            if type(g).__name__ != "Polygon" or not g.extrude:
                errors.append(f"{where}: expected an extruded Polygon, got {type(g).__name__}")
                continue
            if g.altitude_mode != AltitudeMode.absolute:
                errors.append(f"{where}: altitudeMode {g.altitude_mode}, expected absolute")
            heights = (o["top"],)
        footprint = o.get("footprint") or []
        for c in coords_of(p):
            e, n = ground_point(c[0], c[1], origin)
            if footprint:
                # A surveyed footprint: every vertex is one of its vertices.
                off = min(math.hypot(e - x, n - y) for x, y in footprint)
            else:
                off = abs(math.hypot(e - o["center"][0], n - o["center"][1]) - o["radius"])
            worst_h = max(worst_h, off)
            if off > tol or min(abs(c[2] - h) for h in heights) > tol:
                errors.append(f"{where}: vertex {c} is {off:.4f} m off its outline or not at its height")
                break
    for b in entry.get("bands", []):
        where = f"{name} band {b['name']!r}"
        p = marks.get(b["name"])
        if p is None or type(p.kml_geometry).__name__ != "Polygon":
            errors.append(f"{where}: not found as a Polygon")
            continue
        rings = [list(p.geometry.exterior.coords)] + [list(r.coords) for r in p.geometry.interiors]
        if len(rings) != 2:
            errors.append(f"{where}: {len(rings)} rings, expected an outer and an inner one")
            continue
        for ring, radius in zip(rings, (b["outer"], b["inner"])):
            for c in ring:
                e, n = ground_point(c[0], c[1], origin)
                off = abs(math.hypot(e - b["center"][0], n - b["center"][1]) - radius)
                if off > tol:
                    errors.append(f"{where}: a vertex is {off:.4f} m off its circle of {radius} m")
                    break
    return errors, worst_h, worst_v


def dump(paths):
    for path in paths:
        doc = read(path).features[0]
        print(f"{path}: Document {doc.name!r}")
        for f in folders(doc):
            print(f"  Folder {f.name!r}: {len(placemarks(f))} placemarks")
            for s in folders(f):
                print(f"    Folder {s.name!r}: {len(placemarks(s))} placemarks")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("expect", nargs="?", help="expectation JSON file")
    ap.add_argument("--dump", nargs="+", metavar="KML", help="print what fastkml reads")
    args = ap.parse_args()
    try:
        if args.dump:
            dump(args.dump)
            return 0
        if not args.expect:
            raise SetupError("give an expectation file, or --dump FILE...")
        try:
            with open(args.expect, encoding="utf-8") as f:
                spec = json.load(f)
        except (OSError, json.JSONDecodeError) as e:
            raise SetupError(f"cannot read expectation file {args.expect}: {e}") from e
        tol = float(spec.get("tolerance_m", 0.01))
        base = os.path.dirname(os.path.abspath(args.expect))
        errors = []
        worst_h = worst_v = 0.0
        for entry in spec.get("files") or []:
            entry["resolved_path"] = os.path.join(base, entry["path"])
            e, h, v = check_file(entry, tol)
            errors += e
            worst_h, worst_v = max(worst_h, h), max(worst_v, v)
        if not spec.get("files"):
            raise SetupError(f'{args.expect}: expected a non-empty "files" list')
        if not errors:
            print(f"check_kml.py: largest difference {worst_h:.6f} m horizontally, "
                  f"{worst_v:.6f} m vertically (tolerance {tol} m)")
        return report(errors, len(spec["files"]), "check_kml.py (fastkml)")
    except SetupError as e:
        print(f"check_kml.py: {e}", file=sys.stderr)
        return 2
    except Exception as e:  # a reader that refuses the file (schema, syntax) is a mismatch
        print(f"check_kml.py: fastkml could not read the file: {type(e).__name__}: {e}", file=sys.stderr)
        return 1


if __name__ == "__main__":
    sys.exit(main())
