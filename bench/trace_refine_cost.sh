#!/usr/bin/env bash
# The refinement's cost against the search's (issue 12): `volscissors trace` of the 256^3 vessel
# phantom (seed 5) from its root to its first 10 terminals, default options (auto cost, refined
# centrelines), ROUNDS times per binary, binaries alternating in the same run. Prints per run the
# report's search and refine seconds, wall and CPU (all threads), their ratio, the settled nodes
# and refined points (tree points: shared path voxels once); then, with CALLGRIND=1, the
# instructions of the refinement alone (callgrind, one run per binary on the 128^3 phantom of
# seed 2, whose 8 terminals are all reached: the count does not depend on the load; the toggle
# pattern names the function itself, not its lambdas, whose entry would toggle collection off).
#   bench/trace_refine_cost.sh BINARY [BINARY2 ...]     e.g. build/volscissors /tmp/before/volscissors
# Env: ROUNDS=3, SIZE=256, SEED=5, TARGETS=10, CALLGRIND=0, WORK=/tmp/vs_trace_refine_cost.
set -euo pipefail
[[ $# -ge 1 ]] || { sed -n 2,10p "$0"; exit 2; }
ROUNDS=${ROUNDS:-3} SIZE=${SIZE:-256} SEED=${SEED:-5} TARGETS=${TARGETS:-10} CALLGRIND=${CALLGRIND:-0}
WORK=${WORK:-/tmp/vs_trace_refine_cost}
PY=/usr/bin/python3
mkdir -p "$WORK"
bins=()
for b in "$@"; do bins+=("$(cd "$(dirname "$b")" && pwd)/$(basename "$b")"); done
# phantom N SEED -> $WORK/vN_SEED.{nii.gz,targets} (first $TARGETS terminals), prints the root
phantom() {
  local n=$1 v="$WORK/v$1_$2.nii.gz" t="$WORK/v$1_$2.json"
  [[ -f $v ]] || "${bins[0]}" -q phantom vessels --seed "$2" --size "$n,$n,$n" --out "$v" --truth "$t" > /dev/null
  $PY - "$t" "$TARGETS" "$WORK/v$1_$2.targets" <<'PYEOF'
import json, sys
truth = json.load(open(sys.argv[1]))
terms = truth["terminals"][: int(sys.argv[2])]
with open(sys.argv[3], "w") as f:
    for t in terms:
        f.write("%d %d %d\n" % tuple(t["voxel"]))
print("%d,%d,%d" % tuple(truth["root_voxel"]))
PYEOF
}
root=$(phantom "$SIZE" "$SEED")
echo "# ${SIZE}^3 phantom seed $SEED, root $root, $TARGETS targets; $(uptime)"
printf '%-40s %5s %8s %8s %8s %8s %7s %7s %8s %7s\n' binary round settled points search_s search_cpu \
  refine_s refine_cpu wall% cpu%
for r in $(seq "$ROUNDS"); do
  for i in "${!bins[@]}"; do
    rep="$WORK/r_$i.json"
    "${bins[$i]}" -q trace "$WORK/v${SIZE}_$SEED.nii.gz" --root "$root" --targets-file "$WORK/v${SIZE}_$SEED.targets" \
      --out "$WORK/t_$i.swc" --json "$rep" > /dev/null
    $PY - "$rep" "${bins[$i]}" "$r" <<'PYEOF'
import json, sys
j = json.load(open(sys.argv[1]))
s = j["seconds"]
pts = len({tuple(q) for p in j["paths"] for q in p.get("points", [])})  # tree points
print("%-40s %5s %8d %8d %8.3f %8.3f %7.4f %7.4f %7.1f%% %6.1f%%" % (
    sys.argv[2][-40:], sys.argv[3], j["graph"]["settled"], pts, s["search"], s["search_cpu"], s["refine"],
    s["refine_cpu"], 100 * s["refine"] / s["search"], 100 * s["refine_cpu"] / s["search_cpu"]))
PYEOF
  done
done
if [[ $CALLGRIND == 1 ]]; then
  root=$(phantom 128 2)
  echo "# callgrind, 128^3 phantom seed 2, root $root, $TARGETS targets: instructions in vs::refineCentreline"
  for i in "${!bins[@]}"; do
    out="$WORK/cg_$i.out"
    VS_THREADS=1 valgrind --tool=callgrind --callgrind-out-file="$out" --collect-atstart=no \
      --toggle-collect='vs::refineCentreline(*&)' "${bins[$i]}" -q trace "$WORK/v128_2.nii.gz" --root "$root" \
      --targets-file "$WORK/v128_2.targets" --out "$WORK/cg_$i.swc" --json "$WORK/cg_$i.json" > /dev/null 2>&1
    pts=$($PY -c "import json,sys; print(len({tuple(q) for p in json.load(open(sys.argv[1]))['paths'] for q in p['points']}))" \
      "$WORK/cg_$i.json")
    ir=$(grep '^summary:' "$out" | awk '{print $2}')
    echo "${bins[$i]}: $ir instructions, $pts refined points, $((ir / pts)) per point"
  done
fi
