#!/usr/bin/env bash
# Quantification's cost against the trace's (issue 24): `volscissors trace --measure` of the 256^3
# vessel phantom (seed 7) from its root with 10 automatic terminals, default options, ROUNDS
# times; prints per run the report's features + search + refine seconds (the trace), the
# measure seconds, their ratio, the cross-sections and how many were measured. Wall seconds on
# a shared machine: the ratio is what counts (goal: measure <= 20 % of the trace).
#   bench/measure_cost.sh BINARY        e.g. build/volscissors
# Env: ROUNDS=2, SIZE=256, SEED=7, TERMINALS=10, WORK=/tmp/vs_measure_cost.
set -euo pipefail
[[ $# -ge 1 ]] || { sed -n 2,8p "$0"; exit 2; }
ROUNDS=${ROUNDS:-2} SIZE=${SIZE:-256} SEED=${SEED:-7} TERMINALS=${TERMINALS:-10}
WORK=${WORK:-/tmp/vs_measure_cost}
PY=/usr/bin/python3
mkdir -p "$WORK"
bin="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
v="$WORK/v${SIZE}_$SEED.nii.gz" t="$WORK/v${SIZE}_$SEED.json"
[[ -f $v ]] || "$bin" -q phantom vessels --seed "$SEED" --size "$SIZE,$SIZE,$SIZE" --out "$v" --truth "$t" > /dev/null
root=$($PY -c "import json,sys; print('%d,%d,%d' % tuple(json.load(open(sys.argv[1]))['root_voxel']))" "$t")
echo "# ${SIZE}^3 phantom seed $SEED, root $root, $TERMINALS automatic terminals; $(uptime)"
printf '%5s %6s %9s %9s %9s %9s %7s %9s %9s\n' round paths features search refine measure ratio sections measured
for r in $(seq "$ROUNDS"); do
  "$bin" -q trace "$v" --root "$root" --auto-terminals "$TERMINALS" --json "$WORK/r.json" --measure "$WORK/s.csv" \
    > /dev/null
  $PY - "$WORK/r.json" "$r" <<'PYEOF'
import json, sys
j = json.load(open(sys.argv[1]))
s = j["seconds"]
trace = s["features"] + s["search"] + s.get("refine", 0)
m = j["measure"]["sections"]
print("%5s %6d %9.3f %9.3f %9.3f %9.3f %6.1f%% %9d %9d" % (sys.argv[2], len(j["paths"]), s["features"], s["search"],
      s.get("refine", 0), s["measure"], 100 * s["measure"] / trace, m["total"], m["measured"]))
PYEOF
done
