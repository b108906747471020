#!/usr/bin/env bash
# `volscissors trace --cost given --full` (the whole CLI job: load, one search from the root
# resumed for the 16 terminals, then completed to every voxel) vs scikit-image MCP_Geometric
# (find_costs, full map) and SciPy csgraph.dijkstra (full map, CSR graph) on the peers' inputs
# (/work/shared/peers/make_volumes.py: vessels_N_cost.nii.gz / .npy, identical float32 costs).
# Prints terminal-cost agreement (must be within 0.5 %), RATIO lines (peer / project, medians)
# and peak RSS per voxel (/usr/bin/time -v, whole process).
# Needs: apt-get install python3-numpy python3-scipy python3-skimage python3-nibabel time;
# /usr/bin/python3.
#   bench/trace_vs_peers.sh [BUILD_DIR]
# Env: SIZES="128" (add 256 for the big run), SCIPY_SIZES="128" (256 needs ~6.3 GB and ~2 min),
#   REPEAT=3, PEERS=../shared/peers, DATA=<BUILD_DIR>/peers-data, OUT=<BUILD_DIR>/trace-vs-peers.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=$(cd "${1:-build}" && pwd)
VS="$BUILD/volscissors"
PEERS=${PEERS:-$(pwd)/../shared/peers}
DATA=${DATA:-$BUILD/peers-data}
OUT=${OUT:-$BUILD/trace-vs-peers}
SIZES=${SIZES:-128}
SCIPY_SIZES=${SCIPY_SIZES:-128}
REPEAT=${REPEAT:-3}
PY=/usr/bin/python3
TIME=/usr/bin/time
mkdir -p "$DATA" "$OUT"
$PY -c "import numpy, scipy, skimage, nibabel" 2>/dev/null ||
  { echo "trace_vs_peers: apt-get install -y python3-numpy python3-scipy python3-skimage python3-nibabel" >&2; exit 1; }
[[ -x $TIME ]] || { echo "trace_vs_peers: apt-get install -y time" >&2; exit 1; }
for n in $SIZES; do
  if [[ ! -f "$DATA/vessels_${n}_cost.nii.gz" ]]; then
    echo "== generating the peers' inputs in $DATA"
    (cd "$PEERS" && $PY make_volumes.py --sizes $SIZES --outdir "$DATA")
  fi
done
rss() { grep "Maximum resident" "$1" | awk '{print $NF}'; }  # KB

for n in $SIZES; do
  echo "== vessels_$n: project CLI x$REPEAT"
  for r in $(seq "$REPEAT"); do
    $TIME -v "$VS" -q trace "$DATA/vessels_${n}_cost.nii.gz" --cost given --targets-file "$DATA/vessels_${n}.json" \
      --full --json "$OUT/project_${n}_$r.json" >/dev/null 2>"$OUT/project_${n}_$r.time"
  done
  echo "== vessels_$n: scikit-image (repeat $REPEAT)"
  (cd "$PEERS" && $TIME -v $PY sssp_skimage.py "$DATA/vessels_${n}.npy" --repeat "$REPEAT" --warmup 0 --route-repeat 1 \
    >"$OUT/skimage_$n.json" 2>"$OUT/skimage_$n.time")
  rm -f "$OUT/scipy_$n.json"
  if [[ " $SCIPY_SIZES " == *" $n "* ]]; then
    echo "== vessels_$n: scipy (repeat $REPEAT)"
    (cd "$PEERS" && $TIME -v $PY sssp_scipy.py "$DATA/vessels_${n}_cost.npy" --repeat "$REPEAT" --warmup 0 --no-variants \
      >"$OUT/scipy_$n.json" 2>"$OUT/scipy_$n.time")
  fi
  $PY - "$OUT" "$n" "$REPEAT" <<'PYEOF'
import json, os, statistics, sys
out, n, rep = sys.argv[1], sys.argv[2], int(sys.argv[3])
def rss(p):
    for line in open(p):
        if "Maximum resident" in line: return int(line.split()[-1]) * 1024
last = lambda p: json.loads(open(p).read().strip().splitlines()[-1])
runs = [json.load(open(os.path.join(out, f"project_{n}_{r}.json"))) for r in range(1, rep + 1)]
me_search = statistics.median(r["seconds"]["search"] for r in runs)
me_total = statistics.median(sum(r["seconds"].values()) for r in runs)
me_rss = max(rss(os.path.join(out, f"project_{n}_{r}.time")) for r in range(1, rep + 1))
vox = runs[0]["graph"]["voxels"]
me_costs = [p["cost"] for p in runs[0]["paths"]]
print(f"project : search (16 terminals + full map) {me_search:.3f} s, whole CLI job {me_total:.3f} s, "
      f"settled {runs[0]['graph']['settled']}/{vox}, peak RSS {me_rss / 2**20:.0f} MiB = {me_rss / vox:.1f} B/voxel")
ok = True
peers = [("skimage", "full_total", "find_costs_median_s")]
if os.path.exists(os.path.join(out, f"scipy_{n}.json")): peers.append(("scipy", "dijkstra_full", None))
for name, key, sub in peers:
    j = last(os.path.join(out, f"{name}_{n}.json"))
    t = j["timings"][key]
    search = t.get(sub) if sub else t["median_s"]
    r = rss(os.path.join(out, f"{name}_{n}.time"))
    dev = max(abs(a - b) / max(abs(b), 1e-300) for a, b in zip(me_costs, j["terminal_costs"]))
    ok &= dev <= 0.005
    extra = f" + graph build {j['timings']['graph_build']['median_s']:.3f} s" if name == "scipy" else \
            f" (with constructor {t['median_s']:.3f} s)"
    print(f"{name:8}: full map {search:.3f} s{extra}, peak RSS {r / 2**20:.0f} MiB = {r / vox:.1f} B/voxel; "
          f"terminal costs max rel. diff {dev:.2e} {'OK' if dev <= 0.005 else 'MISMATCH'}")
    print(f"RATIO {name}/project vessels_{n} full-map search: {search / me_search:.2f}x; "
          f"peer search vs whole project CLI job: {search / me_total:.2f}x; memory {r / me_rss:.2f}x")
sys.exit(0 if ok else 1)
PYEOF
done
