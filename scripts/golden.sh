#!/usr/bin/env bash
# The golden harness: what a refactor must leave byte for byte as it was.
#
#   scripts/golden.sh BIN OUT        write BIN's outputs into OUT
#   diff -r OUT_BEFORE OUT_AFTER     nothing, or the refactor changed behaviour
#
# For every shipped mission, pipeline and seed 0-19: the JSON outcome and the
# printed summary of `skyform run`; per mission, `check`, a sweep table and the
# exports; on the bridge and the viaduct, a flight check (brute force, and a
# margin search on the bridge) and its JSON. Wall and CPU times are cut from
# what is kept, nothing else; a JSON is kept as its SHA-256. Two runs at
# once (the machine has two cores); about three minutes on this one.
set -euo pipefail
bin=$(realpath "$1")
out=$2
root=$(cd "$(dirname "$0")/.." && pwd)
mkdir -p "$out"
out=$(realpath "$out")
cd "$root"

# Times vary from run to run: drop the lines and columns that give them.
untimed() { sed -E -e '/(wall|CPU|elapsed| in [0-9.]+ s\b|flights\/s|evaluations\/s)/d'; }
export -f untimed
export bin out

jobs=()
for mission in missions/*.toml; do
  name=$(basename "$mission" .toml)
  for pipeline in theta-pso flatlo fleet; do
    for seed in $(seq 0 19); do
      jobs+=("run $pipeline $mission $seed $name")
    done
    jobs+=("sweep $pipeline $mission 0 $name")
  done
  jobs+=("check - $mission 0 $name")
  jobs+=("export - $mission 0 $name")
done
jobs+=("fly - missions/bridge-inspection.toml 3 bridge-inspection")
jobs+=("fly - missions/viaduct-inspection.toml 3 viaduct-inspection")
jobs+=("target - missions/bridge-inspection.toml 1 bridge-inspection")

one() {
  read -r what pipeline mission seed name <<<"$1"
  local base="$out/$name.$what.$pipeline.$seed"
  case $what in
    run) "$bin" run "$pipeline" "$mission" --seed "$seed" --json "$base.json" 2>/dev/null | untimed >"$base.txt" || true ;;
    sweep) "$bin" sweep "$mission" --pipeline "$pipeline" --seeds 0..3 --jobs 1 --csv "$base.csv" 2>/dev/null | untimed >"$base.txt" || true
           [ -f "$base.csv" ] && python3 - "$base.csv" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
keep = [i for i, h in enumerate(rows[0]) if not any(w in h.lower() for w in ("wall", "cpu", "per_s", "/s"))] if rows else []
with open(sys.argv[1], "w", newline="") as f:
    csv.writer(f).writerows([[r[i] for i in keep] for r in rows])
PY
           ;;
    check) "$bin" check "$mission" >"$base.txt" 2>&1 || true ;;
    export) rm -rf "$base.d"; "$bin" export "$mission" --out "$base.d" --format plan --format wpl --format csv --format kml >"$base.txt" 2>&1 || true
            untimed <"$base.txt" | sed "s|$out/||g" >"$base.tmp" && mv "$base.tmp" "$base.txt" ;;
    fly) "$bin" fly "$mission" --flights 200 --seed "$seed" --threads 1 --json "$base.json" 2>/dev/null | untimed >"$base.txt" || true ;;
    target) "$bin" fly "$mission" --flights 200 --seed "$seed" --threads 1 --target 0.01 --json "$base.json" 2>/dev/null | untimed >"$base.txt" || true ;;
  esac
}
export -f one
printf '%s\n' "${jobs[@]}" | xargs -P 2 -I{} bash -c 'one "$@"' _ {}
# Outcomes run to hundreds of megabytes (a squadron's tracks): keep each
# JSON's digest, not the file. None carries a time (checked: no key names
# wall, CPU or elapsed time).
find "$out" -name '*.json' -print0 | while IFS= read -r -d '' f; do
  sha256sum <"$f" | cut -d' ' -f1 >"$f.sha256" && rm "$f"
done
echo "golden: $(find "$out" -type f | wc -l) files in $out"
