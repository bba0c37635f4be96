"""A flight-check campaign run as shards on a real Ray cluster (issue 52).

Starts a local single-node Ray cluster (`ray.init`), runs every case of the
campaign (missions x weathers) as N shards, each a Ray task that runs
`skyform fly ... --shard I/N --json PART`, merges each case's parts with
`skyform merge`, and compares the merged report with the one a single
`skyform fly --json` process writes, byte for byte. With `--rare-runs K`,
each case's rare-event estimate (`--rare --runs K`) is sharded too, one run
a shard, and compared the same way.

    python ray_campaign.py --skyform target/release/skyform --out /tmp/campaign \
        --mission missions/bridge-inspection.toml --flights 100 --shards 4 \
        --rare-runs 3 --per-level 20

Exit status 0 when every case's merged report is the single process's, 1
when one differs, 2 on a usage or run error. Prints one line per case.
"""

import argparse
import filecmp
import pathlib
import subprocess
import sys

# The campaign's weathers: (name, [flight] lines replaced).
WEATHERS = [
    ("as shipped", {}),
    ("RTK-grade fixes, moderate gusts", {
        "gnss_sigma_horizontal": "0.05",
        "gnss_sigma_vertical": "0.1",
        "turbulence": '"moderate"',
    }),
]


def weather_variant(text: str, changes: dict) -> str:
    """The mission text with each `key = ...` line of [flight] replaced (or added)."""
    lines = text.splitlines()
    out, in_flight, done = [], False, set()
    for line in lines:
        stripped = line.strip()
        if stripped.startswith("["):
            if in_flight:
                out.extend(f"{k} = {v}" for k, v in changes.items() if k not in done)
            in_flight = stripped.startswith("[flight]")
        key = stripped.split("=", 1)[0].strip()
        if in_flight and key in changes:
            out.append(f"{key} = {changes[key]}")
            done.add(key)
            continue
        out.append(line)
    if in_flight:
        out.extend(f"{k} = {v}" for k, v in changes.items() if k not in done)
    return "\n".join(out) + "\n"


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--skyform", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--mission", action="append", required=True)
    ap.add_argument("--flights", type=int, default=100)
    ap.add_argument("--shards", type=int, default=4)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--rare-runs", type=int, default=0,
                    help="also shard each case's --rare estimate of this many runs (0: none)")
    ap.add_argument("--per-level", type=int, default=100)
    args = ap.parse_args()

    import ray  # imported here so --help works without it

    out = pathlib.Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    skyform = str(pathlib.Path(args.skyform).resolve())
    ray.init(num_cpus=2, include_dashboard=False, log_to_driver=False)
    try:
        nodes = [n for n in ray.nodes() if n.get("Alive")]
        print(f"ray cluster: {len(nodes)} node(s), {ray.cluster_resources().get('CPU', 0):.0f} CPU")

        rare = ["--rare", "--runs", str(args.rare_runs), "--per-level", str(args.per_level)]

        @ray.remote(num_cpus=1)
        def shard(mission: str, i: int, n: int, part: str, extra: list) -> tuple:
            run = subprocess.run(
                [skyform, "fly", mission, "--seed", str(args.seed), "--flights",
                 str(args.flights), "--threads", "1", *extra, "--shard", f"{i}/{n}",
                 "--json", part],
                capture_output=True, text=True)
            return (run.returncode, run.stdout + run.stderr)

        cases, failed = [], False
        for m in args.mission:
            text = pathlib.Path(m).read_text()
            for k, (name, changes) in enumerate(WEATHERS):
                path = out / f"{pathlib.Path(m).stem}-w{k}.toml"
                path.write_text(weather_variant(text, changes))
                cases.append((path, name))
        # The kinds of work of each case: the check in --shards shards, and
        # the rare-event estimate one run a shard.
        kinds = [("check", [], args.shards)]
        if args.rare_runs > 0:
            kinds.append(("rare", rare, args.rare_runs))
        # Every shard of every case at once: Ray schedules them.
        tasks = {}
        for path, _ in cases:
            for kind, extra, n in kinds:
                for i in range(n):
                    part = out / f"{path.stem}-{kind}-part{i}.json"
                    tasks[(path, kind, i)] = (part, shard.remote(str(path), i, n, str(part), extra))
        for (path, kind, i), (part, task) in tasks.items():
            rc, log = ray.get(task, timeout=600)
            if rc != 0:
                print(f"{path.name} {kind} shard {i}: exit {rc}\n{log}", file=sys.stderr)
                return 2
        for path, name in cases:
            for kind, extra, n in kinds:
                parts = [str(tasks[(path, kind, i)][0]) for i in range(n)]
                merged = out / f"{path.stem}-{kind}-merged.json"
                single = out / f"{path.stem}-{kind}-one.json"
                m = subprocess.run([skyform, "merge", *reversed(parts), "--json", str(merged)],
                                   capture_output=True, text=True)
                s = subprocess.run([skyform, "fly", str(path), "--seed", str(args.seed),
                                    "--flights", str(args.flights), *extra, "--json", str(single)],
                                   capture_output=True, text=True)
                if m.returncode not in (0, 2) or s.returncode not in (0, 2):
                    print(f"{path.name} {kind}: merge exit {m.returncode}, fly exit "
                          f"{s.returncode}\n{m.stderr}{s.stderr}", file=sys.stderr)
                    return 2
                same = filecmp.cmp(merged, single, shallow=False)
                lines = m.stdout.splitlines()
                verdict = next((l.strip() for l in lines if "result" in l or "P =" in l), "")
                print(f"{path.name} ({name}): {kind}, {n} shards on Ray merged "
                      f"{'==' if same else '!='} one process; {verdict}")
                failed |= not same
        return 1 if failed else 0
    finally:
        ray.shutdown()


if __name__ == "__main__":
    sys.exit(main())
