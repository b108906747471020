#!/usr/bin/env bash
# Variance of the full single-source map (issue 25): 10 identical full maps of the peers'
# vessels_128 cost volume (26-connected, /work/shared/peers make_volumes.py), each in a fresh
# process (as `volscissors trace --full` runs) and 10 in one process (searches reusing the pooled
# record mapping), with the default options; scikit-image MCP_Geometric.find_costs 10 times in
# the same run. Prints median, max/median and the ratio skimage/ours, for wall-clock time and for
# the CPU time of the search (which stays meaningful when other jobs load the machine), with the
# load average (the machine is shared: say so with the figures).
#
#   bench/full_map_variance.sh [BUILD_DIR]     (default build)
# Environment: RUNS=10, PEERS=../shared/peers, DATA=<BUILD_DIR>/peers-data, EXTRA="--queue radix" (bench_engine options)
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=$(cd "${1:-build}" && pwd)
RUNS=${RUNS:-10}
PEERS=${PEERS:-$(pwd)/../shared/peers}
DATA=${DATA:-$BUILD/peers-data}
PY=/usr/bin/python3
[[ -x "$BUILD/bench_engine" ]] || { echo "full_map_variance: build bench_engine first" >&2; exit 1; }
mkdir -p "$DATA"
if [[ ! -f "$DATA/vessels_128_cost.npy" ]]; then
  (cd "$PEERS" && $PY make_volumes.py --sizes 128 --outdir "$DATA" > /dev/null 2>&1) || true
fi
[[ -f "$DATA/vessels_128_cost.npy" ]] || { echo "full_map_variance: could not make the peers' inputs" >&2; exit 1; }
COST=$DATA/vessels_128_cost.npy
META=$DATA/vessels_128.json
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
fresh=()
# Each fresh process runs alone, its report parsed after it ends: a parser started beside it in a
# pipe (python's start-up) kept the second core busy while the engine decided how many threads
# to use, so fresh processes measured the one-thread map that a user's `trace --full` does not get.
out=$(mktemp)
trap 'rm -f "$out"' EXIT
for _ in $(seq "$RUNS"); do
  "$BUILD/bench_engine" --npy "$COST" --sidecar "$META" --repeat 1 --warmup 0 --full-only 1 ${EXTRA:-} > "$out"
  fresh+=("$(tail -1 "$out" | $PY -c 'import json,sys; d=json.load(sys.stdin); t=d["timings"]["full_total"]; print(t["runs_s"][0], t["cpu_runs_s"][0], d["threads_per_map"][0], sep=":")')")
done
inproc=$("$BUILD/bench_engine" --npy "$COST" --sidecar "$META" --repeat "$RUNS" --warmup 0 --full-only 1 ${EXTRA:-} | tail -1)
sk=$(cd "$PEERS" && $PY - "$COST" "$META" "$RUNS" <<'PYEOF'
import json, sys, time
import numpy as np
from skimage.graph import MCP_Geometric
cost = np.load(sys.argv[1]); meta = json.load(open(sys.argv[2])); rep = int(sys.argv[3])
root = tuple(meta["root"]); runs = []
for _ in range(rep):
    t0, c0 = time.perf_counter(), time.process_time()
    cum, _ = MCP_Geometric(cost, fully_connected=True).find_costs([root])
    runs.append((time.perf_counter() - t0, time.process_time() - c0))
print(json.dumps({"runs_s": [r[0] for r in runs], "cpu_runs_s": [r[1] for r in runs],
                  "terminal_costs": [float(cum[tuple(t)]) for t in meta["terminals"]]}))
PYEOF
)
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
$PY - "${fresh[*]}" "$inproc" "$sk" <<'PYEOF'
import json, statistics, sys
fresh = [float(x.split(":")[0]) for x in sys.argv[1].split()]
fresh_cpu = [float(x.split(":")[1]) for x in sys.argv[1].split()]
inproc = json.loads(sys.argv[2]); sk = json.loads(sys.argv[3])
runs = inproc["timings"]["full_total"]["runs_s"]
ours, theirs = inproc["terminal_costs"], sk["terminal_costs"]
err = max(abs(a - b) / max(abs(b), 1e-300) for a, b in zip(ours, theirs))
def line(name, r):
    m = statistics.median(r)
    print(f"{name:32s} median {m:.3f} s  max/median {max(r) / m:.2f}  runs {' '.join(f'{x:.3f}' for x in r)}")
    return m
mf = line("ours, fresh process each (wall)", fresh)
mi = line("ours, one process (wall)", runs)
ms = line("skimage find_costs (wall)", sk["runs_s"])
cf = line("ours, fresh process each (CPU)", fresh_cpu)
ci = line("ours, one process (CPU)", inproc["timings"]["full_total"]["cpu_runs_s"])
cs = line("skimage find_costs (CPU)", sk["cpu_runs_s"])
print(f"RATIO skimage/ours (medians): wall: fresh processes {ms / mf:.1f}x, one process {ms / mi:.1f}x; "
      f"CPU: fresh {cs / cf:.1f}x, one process {cs / ci:.1f}x; queue {inproc['queue']}; "
      f"terminal costs max rel. diff {err:.1e}")
fresh_threads = [int(x.split(":")[2]) for x in sys.argv[1].split()]
print(f"threads per map (automatic: two on an idle second core): fresh {fresh_threads}, "
      f"one process {inproc['threads_per_map']}")
PYEOF
