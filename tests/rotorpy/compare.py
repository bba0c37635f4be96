#!/usr/bin/env python3
"""Cross-check `skyform fly` against RotorPy (rotorpy==3.0.0), outside `cargo test`.

For a mission (default: missions/bridge-inspection.toml) in two airs, calm and a
steady 5 m/s wind from the west (no turbulence), both with GNSS noise and take-off
skew off, it
  1. runs `skyform fly EDITED.toml --seed S --flights 1 --json` (nothing random is
     left, so one flight is every flight) for skyform's cross-track error per vehicle;
  2. runs `skyform export EDITED.toml --seed S --format plan` (the same plan: the
     fly check flies the export's reduction) and reads each vehicle's waypoints,
     holds and DO_CHANGE_SPEED speeds back into ENU metres;
  3. flies each vehicle's schedule in RotorPy: `Multirotor` (AscTec Hummingbird
     parameters by default, RotorPy's aero on) + `SE3Control`, tracking the
     piecewise-linear, constant-speed schedule the export's re-verification and the
     fly check use (legs at their written speeds, holds waited, arrival times as
     export::reverify::Flight), handed on as a setpoint generator would: smoothed
     over `--smooth` seconds (1 s; `Smoothed`), so no step in the velocity
     reference reaches the controller; wind from `rotorpy.wind.ConstantWind`;
  4. measures cross-track error the way skyform does (src/flight/mod.rs): at 20 Hz,
     the 3-D distance from the leg the schedule has the vehicle on (the waypoint
     itself while it holds, before take-off and after its last one), and prints
     the per-flight maximum (what skyform reports: its p50/p99/max are over flights
     of that maximum, so with one flight they are all the same number) beside
     RotorPy's maximum and median over time, and the ratio of the maxima;
  5. and, since skyform builds a flight as the schedule plus the departure the air
     causes (its calm flight is the schedule exactly), the same for RotorPy: the
     schedule + (RotorPy in this air - RotorPy in calm air), "air-only", which takes
     RotorPy's own corner-tracking error out of the comparison.

Modelling differences (why the numbers are not expected to match closely):
  * Controller. skyform: PX4's cascade, position P (MPC_XY_P 0.95 /s) -> velocity PID
    (MPC_XY_VEL_P_ACC 1.8 /s, I 0.4, D 0.2) with an integral that removes a steady
    wind's offset. RotorPy SE3Control: PD on position, kp 6.5 /s^2, kd 4.0 /s
    horizontally (15 / 9 vertically), no integral: much stiffer (natural frequency
    2.5 rad/s vs ~1.3 rad/s for PX4's defaults) but a steady wind leaves an offset
    of (drag acceleration) / kp.
  * Drag. skyform: linear, 0.3 /s x mass x (wind - velocity). RotorPy (aero=True):
    quadratic parasitic drag c_D |v| v (Hummingbird 0.5e-2 N/(m/s)^2) plus rotor
    H-force k_d * omega * v per rotor (1.19e-4), about 2.4 m/s^2 at 5 m/s
    airspeed for the 0.5 kg Hummingbird, vs skyform's 1.5 m/s^2 at 5 m/s.
  * Trajectory. skyform superposes the departure on the schedule: in calm air its
    error is exactly 0 (the autopilot's trajectory generator is assumed to fly the
    legs). RotorPy tracks the schedule with velocity feed-forward only, so every
    corner (a step in the commanded velocity) and the start show as a tracking error
    even in calm air. No acceptance-radius logic here: the schedule is flown on time
    (skyform's clock would only stop if a vehicle were > 2 m off when a waypoint fell
    due, which does not happen in these airs).
  * Vehicle. skyform's body is `[fleet]`'s; RotorPy's is the chosen params file, with
    motor dynamics (tau_m) and attitude loop.

Turbulence (`--turbulence light --flights N`): a third case, the same 5 m/s wind with
Dryden gusts (MIL-F-8785C low altitude, the same scales and filters as skyform's
src/flight/air.rs: u first order, v and w second order, exactly discretised, time
constants L/V at the vehicle's airspeed), N flights on each side, each RotorPy flight
on a gust series of its own. skyform reports each vehicle's per-flight maximum
cross-track error as p50 / p99 / max over its N flights; RotorPy's "air-only" maxima
(schedule + turbulent flight - calm flight) give the same figures. `--se3-gains` also
flies skyform with [vehicle] gains that match SE3Control's loop (position 1.625 /s, velocity
4.0 /s horizontally: s^2 + 4.0 s + 6.5, SE3's kd and kp; 1.667 and 9.0 vertically; no velocity
integral, as SE3 has none), so the comparison is of the air and the airframe, not of two
autopilots' tuning.

Run with the venv of requirements.txt (see README.md); about a minute a case.
"""
import argparse
import glob
import importlib
import json
import math
import os
import re
import subprocess
import sys
import tempfile
import time
import tomllib

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
NAV_WAYPOINT, DO_CHANGE_SPEED = 16, 178

# (name, [flight] overrides): GNSS noise and take-off skew off in both.
CASES = [
    ("calm", dict(wind_speed=0.0, wind_from_deg=270.0, turbulence="none")),
    ("wind 5 m/s W", dict(wind_speed=5.0, wind_from_deg=270.0, turbulence="none")),
]
QUIET = dict(gnss_sigma_horizontal=0.0, gnss_sigma_vertical=0.0, takeoff_skew=0.0)


# ---------------------------------------------------------------- the mission

def toml_value(v):
    return f'"{v}"' if isinstance(v, str) else repr(float(v))


def edit_section(text, section, overrides):
    """The mission text with `[section]`'s keys set (the section added if missing)."""
    lines = text.splitlines()
    start = next((i for i, l in enumerate(lines) if re.match(rf"\s*\[{section}\]", l)), None)
    if start is None:
        lines += ["", f"[{section}]"]
        start = len(lines) - 1
    end = next((i for i in range(start + 1, len(lines)) if re.match(r"\s*\[", lines[i])), len(lines))
    todo = dict(overrides)
    for i in range(start + 1, end):
        m = re.match(r"\s*(\w+)\s*=", lines[i])
        if m and m.group(1) in todo:
            lines[i] = f"{m.group(1)} = {toml_value(todo.pop(m.group(1)))}"
    lines[start + 1:start + 1] = [f"{k} = {toml_value(v)}" for k, v in todo.items()]
    out = "\n".join(lines) + "\n"
    table = tomllib.loads(out)[section]
    assert all(table[k] == v for k, v in overrides.items()), table
    return out


def edit_flight(text, overrides):
    """The mission text with `[flight]`'s keys set."""
    return edit_section(text, "flight", overrides)


# ---------------------------------------------------------------- WGS-84 -> ENU

A_WGS, F_WGS = 6378137.0, 1 / 298.257223563
E2 = F_WGS * (2 - F_WGS)


def ecef(lat, lon, h):
    lat, lon = math.radians(lat), math.radians(lon)
    n = A_WGS / math.sqrt(1 - E2 * math.sin(lat) ** 2)
    return np.array([(n + h) * math.cos(lat) * math.cos(lon),
                     (n + h) * math.cos(lat) * math.sin(lon),
                     (n * (1 - E2) + h) * math.sin(lat)])


class Frame:
    """docs/export.md's convention: a waypoint's latitude/longitude are those of the
    ENU ground point (x, y, 0); its frame-3 altitude is z above the home, which is at
    `[origin].altitude` (flat ground, no `[terrain]`)."""

    def __init__(self, origin):
        self.lat0, self.lon0 = origin["latitude"], origin["longitude"]
        self.h0 = origin.get("altitude", 0.0)
        self.o = ecef(self.lat0, self.lon0, self.h0)
        la, lo = math.radians(self.lat0), math.radians(self.lon0)
        self.r = np.array([[-math.sin(lo), math.cos(lo), 0.0],
                           [-math.sin(la) * math.cos(lo), -math.sin(la) * math.sin(lo), math.cos(la)],
                           [math.cos(la) * math.cos(lo), math.cos(la) * math.sin(lo), math.sin(la)]])

    def enu(self, lat, lon, rel_alt):
        h = self.h0
        for _ in range(3):  # the height of the ground point (x, y, 0) above the ellipsoid
            e, n, u = self.r @ (ecef(lat, lon, h) - self.o)
            h -= u
        return np.array([e, n, rel_alt])


def read_plan(path, frame):
    """(points [n x 3] ENU, speeds into each waypoint, holds at each) of a .plan."""
    items = json.load(open(path))["mission"]["items"]
    points, speeds, holds, speed = [], [], [], 0.0
    for it in items:
        if it["command"] == DO_CHANGE_SPEED:
            speed = it["params"][1]
        elif it["command"] == NAV_WAYPOINT:
            p = it["params"]
            points.append(frame.enu(p[4], p[5], p[6]))
            speeds.append(speed)
            holds.append(p[0])
    return np.array(points), speeds, holds


# ---------------------------------------------------------------- the schedule

class Schedule:
    """export::reverify::Flight: straight legs at the written (horizontal) speed,
    held to the vertical rates, holds waited; position/velocity at t.
    Also a RotorPy trajectory (update(t) -> flat outputs)."""

    def __init__(self, points, speeds, holds, limits, start=0.0):
        self.p = points
        self.arrive, self.depart = [], []
        t = start
        for i in range(len(points)):
            if i > 0:
                d = points[i] - points[i - 1]
                v = min(speeds[i], limits["max_speed"])
                h = math.hypot(d[0], d[1])
                rate = limits["max_climb_rate"] if d[2] >= 0 else limits["max_descent_rate"]
                t += max(h / v if v > 0 else 0.0, abs(d[2]) / rate)
            self.arrive.append(t)
            t += holds[i]
            self.depart.append(t)
        self.end = self.arrive[-1]

    def leg(self, t):
        i = int(np.searchsorted(self.depart, t, side="left"))  # first depart >= t
        return min(i, len(self.depart) - 1)

    def at(self, t):
        i = self.leg(t)
        if i == 0 or t >= self.arrive[i]:
            return self.p[i], np.zeros(3)
        span = self.arrive[i] - self.depart[i - 1]
        if span <= 0:
            return self.p[i], np.zeros(3)
        s = min(1.0, max(0.0, (t - self.depart[i - 1]) / span))
        a, b = self.p[i - 1], self.p[i]
        return a + (b - a) * s, (b - a) / span

    def line(self, t):
        """The leg its mission has it on (both ends the waypoint while it holds)."""
        i = self.leg(t)
        if i == 0 or t >= self.arrive[i] or t > self.end:
            return self.p[i], self.p[i]
        return self.p[i - 1], self.p[i]

    def update(self, t):
        x, v = self.at(t)
        z3 = np.zeros(3)
        return dict(x=x, x_dot=v, x_ddot=z3, x_dddot=z3, x_ddddot=z3, yaw=0.0, yaw_dot=0.0, yaw_ddot=0.0)


class Smoothed:
    """The schedule as a vehicle's setpoint generator would hand it on: its positions
    averaged twice over a centred window of `width` seconds (a triangle kernel), so the
    velocity is continuous and the acceleration is bounded by (velocity step) / width,
    with the acceleration fed forward. Centred, so it does not lag the schedule; a
    corner is rounded within width / 2 of it. PX4 limits jerk and acceleration the same
    way (MPC_JERK_AUTO, MPC_ACC_HOR); a step in the velocity reference, which the
    schedule itself has at every waypoint, is what no autopilot is given."""

    def __init__(self, sched, width, dt=0.01):
        self.dt = dt
        n = max(1, int(round(width / dt)))
        self.t0 = -width
        ts = np.arange(self.t0, sched.end + 2 * width + dt, dt)
        raw = np.array([sched.at(t)[0] for t in ts])
        box = np.ones(n) / n
        x = raw
        for _ in range(2):
            pad = np.pad(x, ((n, n), (0, 0)), mode="edge")
            x = np.stack([np.convolve(pad[:, i], box, mode="same") for i in range(3)], axis=1)[n:-n]
        self.x = x
        self.v = np.gradient(x, dt, axis=0)
        self.a = np.gradient(self.v, dt, axis=0)

    def update(self, t):
        k = min(max(int(round((t - self.t0) / self.dt)), 0), len(self.x) - 1)
        z3 = np.zeros(3)
        return dict(x=self.x[k], x_dot=self.v[k], x_ddot=self.a[k], x_dddot=z3, x_ddddot=z3,
                    yaw=0.0, yaw_dot=0.0, yaw_ddot=0.0)


def reference(sched, smooth):
    """What the vehicle is told to fly: the schedule itself (smooth = 0), or smoothed."""
    return Smoothed(sched, smooth) if smooth > 0 else sched


def segment_distance(a, b, p):
    ab = b - a
    L2 = float(ab @ ab)
    s = 0.0 if L2 == 0 else min(1.0, max(0.0, float((p - a) @ ab) / L2))
    return float(np.linalg.norm(a + s * ab - p))


# ---------------------------------------------------------------- RotorPy

def fly_rotorpy(sched, wind_enu, params_module, t_end, smooth, dt=0.01, sample_every=5):
    """RotorPy's positions at 20 Hz (t = 0, 0.05, ...) flying `sched` in a constant wind."""
    from rotorpy.vehicles.multirotor import Multirotor
    from rotorpy.controllers.quadrotor_control import SE3Control
    from rotorpy.wind.default_winds import ConstantWind

    qp = importlib.import_module(f"rotorpy.vehicles.{params_module}").quad_params
    hover = math.sqrt(qp["mass"] * 9.81 / (qp["num_rotors"] * qp["k_eta"]))
    state = dict(x=np.array(sched.p[0], float), v=np.zeros(3), q=np.array([0.0, 0, 0, 1]),
                 w=np.zeros(3), wind=np.zeros(3), rotor_speeds=np.full(qp["num_rotors"], hover))
    vehicle = Multirotor(qp, initial_state=state, aero=True)  # RK45 over each step
    ctrl = SE3Control(qp)
    ref = reference(sched, smooth)
    wind = ConstantWind(*wind_enu)
    xs = []
    steps = int(round(t_end / dt))
    for k in range(steps + 1):
        t = k * dt
        if k % sample_every == 0:
            xs.append(np.array(state["x"], float))
        state["wind"] = wind.update(t, state["x"])
        state = vehicle.step(state, ctrl.update(t, state, ref.update(t)), dt)
        if not np.all(np.isfinite(state["x"])):
            raise RuntimeError(f"RotorPy diverged at t = {t:.2f} s")
    return np.array(xs)


FOOT, KNOT = 0.3048, 0.514444
W20 = {"light": 15.0 * KNOT, "moderate": 30.0 * KNOT, "severe": 45.0 * KNOT}


def dryden_scales(h, w20):
    """src/flight/air.rs `dryden_scales`: (L_uv, L_w, sigma_uv, sigma_w)."""
    h_ft = min(max(h / FOOT, 10.0), 1000.0)
    k = 0.177 + 0.000823 * h_ft
    sigma_w = 0.1 * w20
    return h_ft / k ** 1.2 * FOOT, h_ft * FOOT, sigma_w / k ** 0.4, sigma_w


class Dryden:
    """src/flight/air.rs `Air`: the mean wind plus u (along it, first order), v (across,
    second order) and w (up, second order), each exactly discretised in units of its sigma."""

    P = np.array([[1.0, 0.5], [0.5, 0.5]])

    def __init__(self, mean, w20, rng):
        self.mean = np.array(mean, float)
        speed = np.linalg.norm(self.mean)
        self.along = self.mean / speed if speed > 0 else np.array([1.0, 0.0, 0.0])
        self.across = np.array([-self.along[1], self.along[0], 0.0])
        self.w20, self.rng = w20, rng
        self.u = rng.standard_normal()
        a, b = rng.standard_normal(2)
        self.v = np.array([a, 0.5 * a + 0.5 * b])
        a, b = rng.standard_normal(2)
        self.w = np.array([a, 0.5 * a + 0.5 * b])

    def _second(self, x, dt, tau):
        phi = math.exp(-dt / tau)
        T = np.array([[phi, 0.0], [phi * dt / tau, phi]])
        L = np.linalg.cholesky(self.P - T @ self.P @ T.T + 1e-15 * np.eye(2))
        x = T @ x + L @ self.rng.standard_normal(2)
        return x, (math.sqrt(3) * x[0] + (1 - math.sqrt(3)) * x[1]) / math.sqrt(2)

    def step(self, dt, h, velocity):
        luv, lw, suv, sw = dryden_scales(h, self.w20)
        airspeed = max(np.linalg.norm(np.asarray(velocity) - self.mean), 1.0)
        phi = math.exp(-dt * airspeed / luv)
        self.u = phi * self.u + math.sqrt(max(0.0, 1 - phi * phi)) * self.rng.standard_normal()
        self.v, v = self._second(self.v, dt, luv / airspeed)
        self.w, w = self._second(self.w, dt, lw / airspeed)
        return self.mean + self.along * self.u * suv + self.across * v * suv + np.array([0, 0, w * sw])


def fly_rotorpy_turbulent(sched, wind_enu, w20, seed, params_module, t_end, smooth, dt=0.01,
                          sample_every=5):
    """`fly_rotorpy` in Dryden gusts on the mean wind (one gust series, seeded)."""
    from rotorpy.vehicles.multirotor import Multirotor
    from rotorpy.controllers.quadrotor_control import SE3Control

    qp = importlib.import_module(f"rotorpy.vehicles.{params_module}").quad_params
    hover = math.sqrt(qp["mass"] * 9.81 / (qp["num_rotors"] * qp["k_eta"]))
    state = dict(x=np.array(sched.p[0], float), v=np.zeros(3), q=np.array([0.0, 0, 0, 1]),
                 w=np.zeros(3), wind=np.zeros(3), rotor_speeds=np.full(qp["num_rotors"], hover))
    vehicle = Multirotor(qp, initial_state=state, aero=True)
    ctrl = SE3Control(qp)
    ref = reference(sched, smooth)
    air = Dryden(wind_enu, w20, np.random.default_rng(seed))
    xs = []
    for k in range(int(round(t_end / dt)) + 1):
        t = k * dt
        if k % sample_every == 0:
            xs.append(np.array(state["x"], float))
        state["wind"] = air.step(dt, float(state["x"][2]), state["v"])
        state = vehicle.step(state, ctrl.update(t, state, ref.update(t)), dt)
        if not np.all(np.isfinite(state["x"])):
            raise RuntimeError(f"RotorPy diverged at t = {t:.2f} s")
    return np.array(xs)


def cross_track(sched, xs, dt=0.05):
    """skyform's measure at each sample: distance from the leg the schedule is on."""
    return np.array([segment_distance(*sched.line(k * dt), x) for k, x in enumerate(xs)])


# ---------------------------------------------------------------- main

def run(cmd):
    r = subprocess.run(cmd, capture_output=True, text=True)
    if r.returncode not in (0, 2):  # 2: some flight broke a limit (still a report)
        sys.exit(f"{' '.join(cmd)} failed ({r.returncode}):\n{r.stderr[-2000:]}")
    return r


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--skyform", default=os.path.join(REPO, "target", "release", "skyform"))
    ap.add_argument("--mission", default=os.path.join(REPO, "missions", "bridge-inspection.toml"))
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--params", default="hummingbird_params",
                    help="rotorpy.vehicles module with quad_params (hummingbird_params, crazyflie_params, ...)")
    ap.add_argument("--keep", help="keep the edited missions, reports and exports in this folder")
    ap.add_argument("--turbulence", choices=sorted(W20), help="add a case in this Dryden turbulence")
    ap.add_argument("--flights", type=int, default=8, help="flights a side in turbulence")
    ap.add_argument("--se3-gains", action="store_true",
                    help="in turbulence, also fly skyform with [vehicle] gains matching SE3Control's loop")
    ap.add_argument("--match-drag", action="store_true",
                    help="in turbulence, also fly skyform with SE3-matched gains and [flight] drag set to "
                         "the RotorPy airframe's drag, linearised about the mean wind")
    ap.add_argument("--smooth", type=float, default=1.0,
                    help="seconds of the setpoint smoothing window (0: fly the schedule's steps as they are)")
    args = ap.parse_args()
    if not os.access(args.skyform, os.X_OK):
        sys.exit(f"no skyform binary at {args.skyform} (cargo build --release, or --skyform)")

    text = open(args.mission).read()
    mission = tomllib.loads(text)
    frame = Frame(mission["origin"])
    vehicle = mission.get("vehicle", {})
    # [vehicle]'s defaults (src/mission/model.rs; per-UAV `uavs` overrides ignored here)
    limits = {k: vehicle.get(k, d) for k, d in
              (("max_speed", 12.0), ("max_climb_rate", 3.0), ("max_descent_rate", 1.5))}

    work = args.keep or tempfile.mkdtemp(prefix="skyform-rotorpy-")
    os.makedirs(work, exist_ok=True)
    rows, calm, t0 = [], {}, time.time()
    for name, air in CASES:
        tag = name.split()[0]
        path = os.path.join(work, f"{tag}.toml")
        open(path, "w").write(edit_flight(text, {**air, **QUIET}))
        report_path = os.path.join(work, f"{tag}.json")
        run([args.skyform, "fly", path, "--seed", str(args.seed), "--flights", "1", "--json", report_path])
        report = json.load(open(report_path))
        sky = {c["vehicle"]: c["max"] for c in report["cross_track"]}
        out = os.path.join(work, f"export-{tag}")
        run([args.skyform, "export", path, "--seed", str(args.seed), "--format", "plan", "--out", out])
        plans = sorted(glob.glob(os.path.join(out, "*.plan")),
                       key=lambda p: int(re.search(r"uav(\d+)\.plan$", p).group(1)))
        if not plans:
            sys.exit(f"skyform export wrote no .plan in {out}")
        scheds = [Schedule(*read_plan(p, frame), limits) for p in plans]
        # The check flies until every vehicle has taken its last waypoint.
        t_end = max(s.end for s in scheds)
        frm = math.radians(air["wind_from_deg"])  # meteorological: blows FROM
        wind = (-air["wind_speed"] * math.sin(frm), -air["wind_speed"] * math.cos(frm), 0.0)
        for v, s in enumerate(scheds, start=1):
            tv = time.time()
            key = (s.p.tobytes(), tuple(s.arrive), t_end)
            if key not in calm:  # the same schedule flown in calm air (reused across cases)
                calm[key] = fly_rotorpy(s, (0.0, 0.0, 0.0), args.params, t_end, args.smooth)
            xs = calm[key] if not any(wind) else fly_rotorpy(s, wind, args.params, t_end, args.smooth)
            off = cross_track(s, xs)
            # skyform's construction: the schedule plus the departure the air causes
            # (here: wind flight - calm flight), so corner-tracking error cancels out.
            nominal = np.array([s.at(k * 0.05)[0] for k in range(len(xs))])
            sup = cross_track(s, nominal + xs - calm[key])
            rows.append((name, v, len(s.p), sky.get(v, float("nan")), float(np.median(off)),
                         float(off.max()), float(sup.max()), time.time() - tv))
            print(f"  {name}: UAV {v} flown in RotorPy in {rows[-1][-1]:.1f} s", file=sys.stderr)

    print(f"\n{os.path.basename(args.mission)}, seed {args.seed}, RotorPy {args.params} + SE3Control; "
          f"GNSS noise and take-off skew off; cross-track error in metres (20 Hz samples)")
    print(f"{'case':<14}{'UAV':>4}{'wps':>5}{'skyform max':>13}{'RotorPy p50':>13}{'RotorPy max':>13}"
          f"{'ratio':>7}{'RotorPy air-only max':>22}{'ratio':>7}")
    for name, v, n, sk, p50, mx, sup, _ in rows:
        r1 = f"{mx / sk:.2f}" if sk > 1e-6 else "-"
        r2 = f"{sup / sk:.2f}" if sk > 1e-6 else "-"
        print(f"{name:<14}{v:>4}{n:>5}{sk:>13.3f}{p50:>13.3f}{mx:>13.3f}{r1:>7}{sup:>22.3f}{r2:>7}")
    print("ratio = RotorPy / skyform maximum. air-only: the schedule + (RotorPy in this air - RotorPy in calm air),\n"
          "skyform's own construction (its calm flight is the schedule exactly), so RotorPy's corner-tracking\n"
          "error drops out. skyform's p50 = p99 = max over one flight; its per-sample median is not in the report.")
    if args.turbulence:
        turbulent(args, text, frame, limits, work, calm)
    print(f"total {time.time() - t0:.0f} s; files in {work}")


# SE3Control's loop as PX4's cascade: kd and kp (6.5, 4.0 /s horizontally; 15, 9 vertically)
# are s^2 + K_v s + K_v K_p, and SE3 has no integral.
SE3_GAINS = dict(position_gain_xy=6.5 / 4.0, velocity_gain_xy=4.0, position_gain_z=15.0 / 9.0,
                 velocity_gain_z=9.0, velocity_integral_xy=0.0, velocity_integral_z=0.0)


def linear_drag(params_module, airspeed):
    """The RotorPy airframe's drag per unit mass, 1/s, as skyform's linear model
    (force = drag x mass x (wind - velocity)) would write it: the slope of its drag
    about `airspeed` in hover, d(a)/d(v) = 4 k_d omega_hover / m (the rotors' H-force,
    linear in v) + 2 c_D |v| / m (the parasitic drag, quadratic)."""
    qp = importlib.import_module(f"rotorpy.vehicles.{params_module}").quad_params
    hover = math.sqrt(qp["mass"] * 9.81 / (qp["num_rotors"] * qp["k_eta"]))
    rotors = qp["num_rotors"] * qp["k_d"] * hover / qp["mass"]
    parasitic = 2.0 * qp["c_Dx"] * airspeed / qp["mass"]
    return rotors + parasitic


def turbulent(args, text, frame, limits, work, calm):
    """The wind case in Dryden gusts, `args.flights` flights a side: per vehicle, p50 / p99 /
    max over the flights of each flight's largest cross-track error."""
    air = dict(wind_speed=5.0, wind_from_deg=270.0, turbulence=args.turbulence)
    base = edit_flight(text, {**air, **QUIET})
    variants = [("skyform, PX4 default gains", base)]
    if args.se3_gains:
        variants.append(("skyform, SE3-matched gains", edit_section(base, "vehicle", SE3_GAINS)))
    if args.match_drag:
        drag = linear_drag(args.params, 5.0)
        variants.append((f"skyform, SE3 gains, drag {drag:.2f}",
                         edit_flight(edit_section(base, "vehicle", SE3_GAINS), {"drag": round(drag, 4)})))
    rows = []
    scheds = None
    for label, mission_text in variants:
        tag = "turbulent" + ("-se3" if "SE3" in label else "") + ("-drag" if "drag" in label else "")
        path = os.path.join(work, f"{tag}.toml")
        open(path, "w").write(mission_text)
        report_path = os.path.join(work, f"{tag}.json")
        run([args.skyform, "fly", path, "--seed", str(args.seed), "--flights", str(args.flights),
             "--json", report_path])
        report = json.load(open(report_path))
        for c in report["cross_track"]:
            rows.append((label, c["vehicle"], c["p50"], c["p99"], c["max"]))
        if scheds is None:
            out = os.path.join(work, f"export-{tag}")
            run([args.skyform, "export", path, "--seed", str(args.seed), "--format", "plan", "--out", out])
            plans = sorted(glob.glob(os.path.join(out, "*.plan")),
                           key=lambda p: int(re.search(r"uav(\d+)\.plan$", p).group(1)))
            scheds = [Schedule(*read_plan(p, frame), limits) for p in plans]
    t_end = max(s.end for s in scheds)
    wind = (5.0, 0.0, 0.0)  # from the west: towards +x (east)
    for v, s in enumerate(scheds, start=1):
        key = (s.p.tobytes(), tuple(s.arrive), t_end)
        if key not in calm:
            calm[key] = fly_rotorpy(s, (0.0, 0.0, 0.0), args.params, t_end, args.smooth)
        nominal = np.array([s.at(k * 0.05)[0] for k in range(len(calm[key]))])
        raw, only = [], []
        for k in range(args.flights):
            tv = time.time()
            xs = fly_rotorpy_turbulent(s, wind, W20[args.turbulence], 1000 * args.seed + 100 * v + k,
                                       args.params, t_end, args.smooth)
            raw.append(cross_track(s, xs).max())
            only.append(cross_track(s, nominal + xs - calm[key]).max())
            print(f"  {args.turbulence} turbulence: UAV {v} flight {k} in RotorPy in {time.time() - tv:.1f} s",
                  file=sys.stderr)
        for label, values in (("RotorPy, air-only", only), ("RotorPy, as flown", raw)):
            values = np.sort(values)
            rows.append((label, v, float(np.percentile(values, 50, method="inverted_cdf")),
                         float(np.percentile(values, 99, method="inverted_cdf")), float(values[-1])))
    print(f"\nwind 5 m/s W, {args.turbulence} turbulence (Dryden), {args.flights} flights a side; per vehicle, "
          "each flight's largest cross-track error (m), over the flights:")
    print(f"{'who':<30}{'UAV':>4}{'p50':>9}{'p99':>9}{'max':>9}")
    for label, v, p50, p99, mx in sorted(rows, key=lambda r: (r[1], r[0])):
        print(f"{label:<30}{v:>4}{p50:>9.3f}{p99:>9.3f}{mx:>9.3f}")

if __name__ == "__main__":
    main()
