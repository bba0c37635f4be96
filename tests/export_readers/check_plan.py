#!/usr/bin/env python3
"""Import QGroundControl .plan files with MAVSDK (mission_raw.import_qgroundcontrol_mission)
and check the items it returns against an expectation file (format: see expectations.py
or README.md).

    python check_plan.py EXPECT.json                # exit 0 ok, 1 mismatch, 2 setup error
    python check_plan.py --dump A.plan ...          # print what MAVSDK imports, as an expectation

How it runs headless (mavsdk 4.x, the native binding: no mavsdk_server process, no gRPC):
MAVSDK's importer is a method of the MissionRaw plugin, and a plugin needs a System, which
MAVSDK only creates once it has heard a HEARTBEAT. So the script
  1. opens Mavsdk as a ground station listening on udpin://127.0.0.1:<free port>,
  2. sends heartbeats to that port from a pymavlink udpout connection in a thread:
     system 1 says MAV_AUTOPILOT_PX4, system 2 says MAV_AUTOPILOT_ARDUPILOTMEGA,
  3. waits (--timeout, default 10 s) for the systems, imports each file through the
     MissionRaw plugin of the system whose autopilot the file is meant for, and
  4. always stops the thread and destroys the Mavsdk instance.

The autopilot matters: with an ArduPilot system MAVSDK inserts mission.plannedHomePosition
as item 0 (frame 5, command 16); with PX4 it does not. Per file it is taken from the
expectation's "autopilot" ("px4" / "ardupilot"), else from the plan's mission.firmwareType
(3 = ArduPilot, anything else = PX4).
"""

import argparse
import json
import os
import socket
import sys
import threading
import time

sys.dont_write_bytecode = True  # no __pycache__ beside the scripts in the repo
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from expectations import SetupError, compare_list, load_expectations, nan_to_none, report  # noqa: E402

try:
    from pymavlink import mavutil
except ImportError:  # pragma: no cover
    sys.exit("check_plan.py: pymavlink is not installed (pip install -r requirements.txt)")
try:
    import mavsdk
    from mavsdk import (
        ComponentType, Configuration, ConnectionResult, LogLevel, Mavsdk, log_subscribe, log_unsubscribe,
    )
    from mavsdk.plugins.mission_raw import MissionRaw, MissionRawError, MissionRawResult
except ImportError as e:  # pragma: no cover
    sys.exit(
        f"check_plan.py: needs the native mavsdk binding (mavsdk>=4, see requirements.txt): {e}"
    )

SYSTEM_IDS = {"px4": 1, "ardupilot": 2}
AUTOPILOT_IDS = {
    "px4": mavutil.mavlink.MAV_AUTOPILOT_PX4,
    "ardupilot": mavutil.mavlink.MAV_AUTOPILOT_ARDUPILOTMEGA,
}


def free_udp_port():
    s = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]
    finally:
        s.close()


class Heartbeats:
    """Sends 5 Hz heartbeats to 127.0.0.1:port, one fake autopilot per system id."""

    def __init__(self, port):
        self._stop = threading.Event()
        self._conns = {
            name: mavutil.mavlink_connection(
                f"udpout:127.0.0.1:{port}", source_system=sysid, source_component=1
            )
            for name, sysid in SYSTEM_IDS.items()
        }
        self._thread = threading.Thread(target=self._run, name="heartbeats", daemon=True)

    def _run(self):
        while not self._stop.is_set():
            for name, conn in self._conns.items():
                try:
                    conn.mav.heartbeat_send(
                        mavutil.mavlink.MAV_TYPE_QUADROTOR, AUTOPILOT_IDS[name], 0, 0,
                        mavutil.mavlink.MAV_STATE_STANDBY,
                    )
                except OSError:
                    pass
            self._stop.wait(0.2)

    def __enter__(self):
        self._thread.start()
        return self

    def __exit__(self, *exc):
        self._stop.set()
        self._thread.join(timeout=5)
        for conn in self._conns.values():
            conn.close()


class MavsdkLog:
    """Keeps MAVSDK's warnings and errors (e.g. why a .plan did not parse) for our messages."""

    def __init__(self, verbose):
        self.verbose = verbose
        self.lines = []
        self._lock = threading.Lock()

    def __call__(self, level, message, file, line):
        if level >= LogLevel.WARN:
            with self._lock:
                self.lines.append(message)
        return not self.verbose  # True: suppress MAVSDK's own printing

    def take(self):
        with self._lock:
            lines, self.lines = self.lines, []
        return lines


def plan_autopilot(entry):
    if entry.get("autopilot"):
        name = str(entry["autopilot"]).lower()
        if name not in SYSTEM_IDS:
            raise SetupError(f"{entry['path']}: autopilot must be one of {sorted(SYSTEM_IDS)}, got {name!r}")
        return name
    try:
        with open(entry["resolved_path"], encoding="utf-8") as f:
            firmware = json.load(f).get("mission", {}).get("firmwareType")
    except (OSError, ValueError, AttributeError):
        firmware = None  # MAVSDK will report the problem
    return "ardupilot" if firmware == mavutil.mavlink.MAV_AUTOPILOT_ARDUPILOTMEGA else "px4"


def explain_plan(path):
    """What MAVSDK's importer (mission_import.cpp) requires, checked in Python, to say *why*
    an import failed: MAVSDK logs nothing for a missing geoFence or rallyPoints."""
    try:
        with open(path, encoding="utf-8") as f:
            plan = json.load(f)
    except ValueError as e:
        return [f"not valid JSON: {e}"]
    except OSError as e:
        return [str(e)]
    if not isinstance(plan, dict):
        return ["top level is not a JSON object"]
    problems = []

    def need_int(obj, key, value, where):
        v = obj.get(key) if isinstance(obj, dict) else None
        if not (isinstance(v, int) and not isinstance(v, bool) and v == value):
            problems.append(f'{where}"{key}" must be the integer {value} (found {v!r})')

    need_int(plan, "version", 1, "")
    for section, version in (("mission", 2), ("geoFence", 2), ("rallyPoints", 2)):
        obj = plan.get(section)
        if not isinstance(obj, dict) or not obj:
            problems.append(f'"{section}" must be a non-empty object (MAVSDK rejects the plan without it)')
        else:
            need_int(obj, "version", version, f"{section}.")
    mission = plan.get("mission") if isinstance(plan.get("mission"), dict) else {}
    home = mission.get("plannedHomePosition")
    if home is not None and not (isinstance(home, list) and len(home) == 3):
        problems.append("mission.plannedHomePosition must be [lat, lon, alt] (3 numbers)")
    for i, item in enumerate(mission.get("items") or []):
        if not isinstance(item, dict):
            problems.append(f"mission.items[{i}] is not an object")
            continue
        if item.get("type") == "SimpleItem":
            for key in ("command", "autoContinue", "frame", "params"):
                if item.get(key) is None or item.get(key) == []:
                    problems.append(f'mission.items[{i}] has no "{key}"')
        elif item.get("type") != "ComplexItem":
            problems.append(f'mission.items[{i}].type is {item.get("type")!r}, not "SimpleItem"')
    return problems


def item_dict(it):
    return {
        "seq": it.seq, "command": it.command, "frame": it.frame, "current": it.current,
        "autocontinue": it.autocontinue, "mission_type": it.mission_type,
        "param1": it.param1, "param2": it.param2, "param3": it.param3, "param4": it.param4,
        "x": it.x, "y": it.y, "z": it.z,
    }


class Importer:
    """Context manager: a Mavsdk instance with a connected PX4 and ArduPilot system."""

    def __init__(self, timeout, verbose):
        self.timeout = timeout
        self.log = MavsdkLog(verbose)
        self.mavsdk = None
        self.heartbeats = None
        self.plugins = {}

    def __enter__(self):
        log_subscribe(self.log)
        try:
            self._start()
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def _start(self):
        self.mavsdk = Mavsdk(Configuration.create_with_component_type(ComponentType.GROUND_STATION))
        for _attempt in range(5):
            port = free_udp_port()
            result = self.mavsdk.add_any_connection(f"udpin://127.0.0.1:{port}")
            if result == ConnectionResult.SUCCESS:
                break
        else:
            raise SetupError(f"MAVSDK could not listen on a loopback UDP port (last result: {result.name})")
        self.heartbeats = Heartbeats(port).__enter__()
        deadline = time.monotonic() + self.timeout
        wanted = set(SYSTEM_IDS.values())
        systems = {}
        while time.monotonic() < deadline:
            systems = {s.get_system_id(): s for s in self.mavsdk.get_systems()}
            if wanted <= set(systems) and all(systems[i].has_autopilot() for i in wanted):
                break
            time.sleep(0.05)
        else:
            raise SetupError(
                f"timed out after {self.timeout:g} s waiting for MAVSDK to discover the fake "
                f"autopilots (system ids {sorted(wanted)}) heartbeating to udp 127.0.0.1:{port}; "
                f"found {sorted(systems)}. Is loopback UDP blocked?"
            )
        for name, sysid in SYSTEM_IDS.items():
            self.plugins[name] = MissionRaw(systems[sysid])

    def __exit__(self, *exc):
        self.plugins.clear()
        if self.mavsdk is not None:
            self.mavsdk.destroy()  # releases plugins, systems and connections
            self.mavsdk = None
        if self.heartbeats is not None:
            self.heartbeats.__exit__(None, None, None)
            self.heartbeats = None
        log_unsubscribe()

    def import_plan(self, path, autopilot):
        """Returns (MissionImportData, None) or (None, error message)."""
        self.log.take()
        try:
            data = self.plugins[autopilot].import_qgroundcontrol_mission(path)
            return data, None
        except MissionRawError as e:
            detail = self.log.take()
            if e.result == MissionRawResult.FAILED_TO_PARSE_QGC_PLAN:
                detail += [f"check: {p}" for p in explain_plan(path)]
            return None, f"MAVSDK import failed: {e.result.name} ({'; '.join(detail) or 'no detail'})"


def check(expect_path, timeout, verbose):
    files, tolerances = load_expectations(expect_path)
    errors = []
    with Importer(timeout, verbose) as importer:
        for entry in files:
            path = entry["resolved_path"]
            where = entry["path"]
            if not os.path.isfile(path):
                errors.append(f"{where}: file not found ({path})")
                continue
            autopilot = plan_autopilot(entry)
            data, err = importer.import_plan(path, autopilot)
            if err:
                errors.append(f"{where}: {err}")
                continue
            for label, actual, count_key, items_key in (
                ("mission", data.mission_items, "count", "items"),
                ("geofence", data.geofence_items, "geofence_count", "geofence_items"),
                ("rally", data.rally_items, "rally_count", "rally_items"),
            ):
                errors += compare_list(
                    f"{where} [{autopilot}] {label}", [item_dict(i) for i in actual],
                    entry.get(count_key), entry.get(items_key), tolerances,
                    latlon_scale=1e7, xy_exact=True,
                )
    return report(errors, len(files), "check_plan")


def dump(paths, autopilot, timeout, verbose):
    def expected(it):
        d = item_dict(it)
        return {
            "command": d["command"], "frame": d["frame"], "current": d["current"],
            "autocontinue": d["autocontinue"], "mission_type": d["mission_type"],
            "params": [nan_to_none(d[f"param{k}"]) for k in range(1, 5)],
            "x": d["x"], "y": d["y"], "alt": d["z"],
        }

    out = {"files": []}
    with Importer(timeout, verbose) as importer:
        for path in paths:
            entry = {"path": path, "resolved_path": path, "autopilot": autopilot}
            ap = plan_autopilot(entry)
            data, err = importer.import_plan(os.path.abspath(path), ap)
            if err:
                raise SetupError(f"{path}: {err}")
            out["files"].append(
                {
                    "path": os.path.abspath(path), "autopilot": ap,
                    "count": len(data.mission_items), "items": [expected(i) for i in data.mission_items],
                    "geofence_count": len(data.geofence_items),
                    "geofence_items": [expected(i) for i in data.geofence_items],
                    "rally_count": len(data.rally_items),
                    "rally_items": [expected(i) for i in data.rally_items],
                }
            )
    print(json.dumps(out, indent=2))
    return 0


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("expectation", nargs="?", help="expectation JSON file")
    ap.add_argument("--timeout", type=float, default=10.0, help="seconds to wait for MAVSDK (default 10)")
    ap.add_argument("--verbose", "-v", action="store_true", help="let MAVSDK print its own log")
    ap.add_argument("--dump", nargs="+", metavar="FILE", help="print what MAVSDK imports, as an expectation")
    ap.add_argument("--autopilot", choices=sorted(SYSTEM_IDS), help="with --dump: autopilot to import for")
    args = ap.parse_args(argv)
    try:
        if args.dump:
            return dump(args.dump, args.autopilot, args.timeout, args.verbose)
        if not args.expectation:
            ap.error("give an expectation file, or --dump FILE...")
        return check(args.expectation, args.timeout, args.verbose)
    except SetupError as e:
        print(f"check_plan (mavsdk {mavsdk.__version__}): {e}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
