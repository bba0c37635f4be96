#!/usr/bin/env python3
"""A second independent answer to "does a passage exist?", from OMPL.

Reads only mission TOML files (the bounds, the route's start and goal, the
obstacles' shapes, heights and `overfly`), none of skyform's code, and asks
OMPL's PRM, its samples drawn by the bridge test (narrow passages), for a
path of a point that keeps `clearance` from every
obstacle's prism (3-D distance; one that may not be flown over reaches the
sky), inside the bounds, from the start to the goal. Validity is decided on
the exact geometry, a motion by conservative advancement along it.

A sampling planner proves a passage exists when it finds one; when it finds
none within its time it proves nothing, so the answer is "found" or
"unknown", never "closed". One JSON line per file:

    {"file": ..., "found": true, "length": 93.2, "seconds": 0.4, "states": 12}

Usage: oracle.py [--clearance C | --clearance-add A] [--time S] [--seed N]
                 [--resolution M] [--bridge M] FILE...
"""

import argparse
import json
import math
import os
import sys
import time
import tomllib


def prisms(mission, path):
    """Each obstacle as (centre, radius, polygon or None, base, top)."""
    out = []
    for i, o in enumerate(mission.get("obstacles", [])):
        where = f"{path}: obstacles[{i}] ('{o.get('name', '?')}')"
        if "wire" in o:
            raise SystemExit(f"{where}: a wire is not read by this oracle")
        footprint = [tuple(p) for p in o.get("footprint", [])]
        if len(footprint) >= 3:
            xs = [p[0] for p in footprint]
            ys = [p[1] for p in footprint]
            centre = (sum(xs) / len(xs), sum(ys) / len(ys))
            radius = max(math.dist(centre, p) for p in footprint)
        else:
            if "center" not in o or "radius" not in o:
                raise SystemExit(f"{where}: a cylinder needs center and radius")
            centre, radius, footprint = tuple(o["center"]), o["radius"], None
        if "height" not in o:
            raise SystemExit(f"{where}: no height")
        top = o["height"] + o.get("clearance_above", 0.0) if o.get("overfly", True) else math.inf
        out.append((centre, radius, footprint, o.get("base", 0.0), top))
    return out


def to_segment(p, a, b):
    abx, aby = b[0] - a[0], b[1] - a[1]
    t = ((p[0] - a[0]) * abx + (p[1] - a[1]) * aby) / max(abx * abx + aby * aby, 1e-300)
    t = min(1.0, max(0.0, t))
    return math.hypot(a[0] + abx * t - p[0], a[1] + aby * t - p[1])


def horizontal(prism, p):
    """Horizontal distance from p to the prism's footprint (0 inside)."""
    centre, radius, poly, _, _ = prism
    if poly is None:
        return max(0.0, math.dist(centre, p) - radius)
    inside, best = False, math.inf
    for i, a in enumerate(poly):
        b = poly[(i + 1) % len(poly)]
        best = min(best, to_segment(p, a, b))
        if (a[1] > p[1]) != (b[1] > p[1]) and p[0] < a[0] + (p[1] - a[1]) * (b[0] - a[0]) / (b[1] - a[1]):
            inside = not inside
    return 0.0 if inside else best


def clear(prisms_, p, clearance):
    """Does p keep `clearance` from every prism? (Stops at the first that
    it does not: the validity check, called most.)"""
    for prism in prisms_:
        centre, radius, _, base, top = prism
        dz = max(base - p[2], p[2] - top, 0.0)
        if dz >= clearance or math.dist(centre, p[:2]) - radius >= clearance:
            continue
        dh = horizontal(prism, p[:2])
        if dh * dh + dz * dz < clearance * clearance:
            return False
    return True


def distance(prisms_, p):
    """Least 3-D distance from p to any prism (0 inside one)."""
    best = math.inf
    for prism in prisms_:
        centre, radius, _, base, top = prism
        dz = max(base - p[2], p[2] - top, 0.0)
        # The bounding circle gives a lower bound: skip the polygon when
        # even that is farther than the best so far.
        if math.hypot(max(0.0, math.dist(centre, p[:2]) - radius), dz) >= best:
            continue
        best = min(best, math.hypot(horizontal(prism, p[:2]), dz))
    return best


def answer(path, args):
    from ompl import base as ob, geometric as og, util as ou

    class Bridge(ob.ValidStateSampler):
        """The bridge test (Hsu et al. 2003): two invalid states a short
        Gaussian step apart whose midpoint is valid lie across a narrow
        passage; one sample in four is plain uniform, for the open space."""

        def __init__(self, si, valid, sigma):
            super().__init__(si)
            self.valid, self.sigma = valid, sigma
            self.uniform = si.allocStateSampler()
            self.other = si.allocState()
            self.rng = ou.RNG()

        def sample(self, state):
            for _ in range(100):
                self.uniform.sampleUniform(state)
                if self.rng.uniform01() < 0.25:
                    if self.valid(state):
                        return True
                    continue
                if self.valid(state):
                    continue
                self.uniform.sampleGaussian(self.other, state, self.sigma)
                if self.valid(self.other):
                    continue
                for axis in range(3):
                    state[axis] = (state[axis] + self.other[axis]) / 2.0
                if self.valid(state):
                    return True
            return False

        def sampleNear(self, state, near, distance):
            self.uniform.sampleUniformNear(state, near, distance)
            return self.valid(state)

    with open(path, "rb") as f:
        mission = tomllib.load(f)
    formation = mission.get("formation", {})
    clearance = args.clearance
    if clearance is None:
        clearance = (
            formation.get("uav_radius", 0.0)
            + formation.get("safety_margin", 0.0)
            + formation.get("obstacle_margin", 0.0)
            + args.clearance_add
        )
    obstacles = prisms(mission, path)
    bounds = mission["bounds"]
    space = ob.RealVectorStateSpace(3)
    b = ob.RealVectorBounds(3)
    for axis, key in enumerate("xyz"):
        b.setLow(axis, bounds[key][0])
        b.setHigh(axis, bounds[key][1])
    space.setBounds(b)
    setup = og.SimpleSetup(space)
    checks = [0]

    def valid(s):
        checks[0] += 1
        return clear(obstacles, (s[0], s[1], s[2]), clearance)

    class Advance(ob.MotionValidator):
        """A straight motion is valid when every point of it keeps the
        clearance. The distance to the nearest obstacle changes by at most
        the distance moved, so stepping by the room to spare never steps
        over an obstacle (conservative advancement), and steps are long
        through open air. The least step, `--resolution` (1 mm), bounds the
        work where a motion grazes an obstacle: that close, a motion is
        exact to the least step, and a found path is checked again."""

        def __init__(self, si):
            super().__init__(si)

        def checkMotion(self, a, b):
            ends = [(a[i], b[i]) for i in range(3)]
            length = math.sqrt(sum((e[1] - e[0]) ** 2 for e in ends))
            done = 0.0
            while True:
                t = min(done / length, 1.0) if length > 0.0 else 1.0
                q = tuple(e[0] + (e[1] - e[0]) * t for e in ends)
                checks[0] += 1
                spare = distance(obstacles, q) - clearance
                if spare < 0.0:
                    return False
                if t >= 1.0:
                    return True
                done += max(spare, args.resolution)

    setup.setStateValidityChecker(valid)
    ends = []
    for key in ("start", "goal"):
        s = space.allocState()
        for axis in range(3):
            s[axis] = mission["route"][key][axis]
        ends.append(s)
    setup.setStartAndGoalStates(ends[0], ends[1])
    info = setup.getSpaceInformation()
    info.setMotionValidator(Advance(info))
    samplers = []

    def bridge(si):
        samplers.append(Bridge(si, valid, args.bridge))
        return samplers[-1]

    info.setValidStateSamplerAllocator(bridge)
    setup.setPlanner(og.PRM(info))
    started = time.monotonic()
    setup.solve(args.time)
    found = bool(setup.haveExactSolutionPath())
    row = {
        "file": path,
        "found": found,
        "clearance": clearance,
        "seconds": round(time.monotonic() - started, 3),
        "checks": checks[0],
    }
    if found:
        route = setup.getSolutionPath()
        points = [route.getState(k) for k in range(route.getStateCount())]
        points = [(s[0], s[1], s[2]) for s in points]
        # Re-check the path every millimetre, by brute force rather than by
        # the advancement: a found path is a claim.
        step = 0.001
        for a, c in zip(points, points[1:]):
            n = max(1, math.ceil(math.dist(a, c) / step))
            for k in range(n + 1):
                q = tuple(a[i] + (c[i] - a[i]) * k / n for i in range(3))
                if distance(obstacles, q) < clearance * (1.0 - 1e-9):
                    raise SystemExit(f"{path}: OMPL's path touches an obstacle at {q}")
        row["length"] = round(route.length(), 3)
        row["states"] = len(points)
    return row


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("files", nargs="+")
    parser.add_argument("--clearance", type=float, help="metres kept from every obstacle")
    parser.add_argument(
        "--clearance-add",
        type=float,
        default=0.0,
        help="metres added to the file's uav_radius + safety_margin + obstacle_margin",
    )
    parser.add_argument("--time", type=float, default=10.0, help="seconds per file")
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--bridge", type=float, default=1.0, help="the bridge test's step, metres")
    parser.add_argument("--resolution", type=float, default=0.001, help="least step of a motion check, metres")
    args = parser.parse_args()
    from ompl import util as ou

    # Before any sampler exists, or OMPL ignores it.
    ou.RNG.setSeed(args.seed)
    ou.setLogLevel(ou.LogLevel.LOG_NONE)
    for path in args.files:
        print(json.dumps(answer(path, args)), flush=True)
    # At interpreter exit nanobind reports OMPL's objects as leaked (the
    # bindings' reference counts, not this script's); every answer is
    # written, so leave without the teardown.
    sys.stdout.flush()
    os._exit(0)


if __name__ == "__main__":
    main()
