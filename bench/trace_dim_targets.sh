#!/usr/bin/env bash
# Dim distal targets (issue 21): `trace` with defaults from ROOT to each target alone (reached or
# the refusal's message, cost per mm), then to all of them at once (report OUT.json, the share of
# refined points in the vessel by `trace_measures.py branches`, the paths over the three MIPs in
# OUT.png). Targets from bench/dim_targets.py (the rule, fixed before any trace).
#   bench/trace_dim_targets.sh BUILD_DIR VOLUME ROOT "x,y,z;x,y,z;..." OUT_PREFIX
set -uo pipefail
BUILD=$1 VOL=$2 ROOT=$3 TARGETS=$4 OUT=$5
HERE=$(dirname "$0")
IFS=';' read -ra T <<<"$TARGETS"
args=()
for i in "${!T[@]}"; do
  t=${T[$i]}
  args+=(--target "$t")
  if "$BUILD/volscissors" -q trace "$VOL" --root "$ROOT" --target "$t" --json "$OUT.t$((i + 1)).json" \
    >"$OUT.t$((i + 1)).txt" 2>&1; then
    /usr/bin/python3 -c "import json,sys; p=json.load(open(sys.argv[1]))['paths'][0]; \
print(f'target {sys.argv[2]} #{sys.argv[3]}: reached, {p[\"length_mm\"]:.1f} mm, cost/mm {p[\"cost\"]/max(p[\"length_mm\"],1e-9):.4f}')" \
      "$OUT.t$((i + 1)).json" "$t" "$((i + 1))"
  else
    echo "target $t #$((i + 1)): REFUSED: $(grep -i -m1 error "$OUT.t$((i + 1)).txt")"
  fi
done
if "$BUILD/volscissors" -q trace "$VOL" --root "$ROOT" "${args[@]}" --json "$OUT.json" >"$OUT.txt" 2>&1; then
  grep -m1 "cost:" "$OUT.txt"
  /usr/bin/python3 "$HERE/trace_measures.py" branches "$VOL" "$OUT.json" --cli "$BUILD/volscissors" | tail -1
  /usr/bin/python3 "$HERE/trace_mip.py" "$VOL" "$OUT.json" "$OUT.png" --cli "$BUILD/volscissors"
else
  echo "all targets at once: $(grep -i -m1 error "$OUT.txt")"
fi
