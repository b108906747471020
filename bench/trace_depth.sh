#!/usr/bin/env bash
# Real-volume regression set of the tracking refinement (issue 21): `trace --auto-terminals 6` with
# defaults from the head CTA's seventeen and the head 3DRA's twelve roots of docs/notes/tracking.md (each
# fixed by a written rule before it was run), one JSON report per root in OUT_DIR. Compare two
# builds' reports with bench/trace_points_compare.py; check one with trace_measures.py branches.
#   bench/trace_depth.sh BUILD_DIR OUT_DIR
set -uo pipefail
if [ $# -lt 2 ] || [ ! -x "$1/volscissors" ]; then
  echo "usage: bench/trace_depth.sh BUILD_DIR OUT_DIR" >&2
  exit 2
fi
BUILD=$(cd "$1" && pwd)
OUT=$2
HERE=$(cd "$(dirname "$0")" && pwd)
D=${VS_DATA:-$HERE/../../shared/data}
if [ ! -d "$D" ]; then
  echo "trace depth: the shared data ($D) is missing; nothing run" >&2
  exit 2
fi
mkdir -p "$OUT"
run() {  # name volume root
  "$BUILD/volscissors" trace "$2" --root "$3" --auto-terminals 6 --json "$OUT/$1_${3//,/_}.json" \
    >"$OUT/$1_${3//,/_}.log" 2>&1 || echo "trace depth: $1 root $3 exited $?" >&2
}
for r in 196,96,5 94,132,8 229,150,6 135,57,10 69,197,10 40,113,41 63,84,103 83,41,53 150,171,139 130,77,128 \
  126,32,87 209,48,54 140,36,57 151,230,128 140,118,82 126,184,42 236,95,45; do
  run headcta "$D/head_cta_avm/AVM.nii.gz" "$r" &
  [ "$(jobs -r | wc -l)" -ge 2 ] && wait -n
done
for r in 126,95,183 125,78,154 183,40,153 130,121,166 135,54,169 151,131,185 193,131,173 86,196,199 90,154,191 \
  94,124,184 144,90,118 189,133,97; do
  run head3dra "$D/head_3dra_aneurism/aneurism.vti" "$r" &
  [ "$(jobs -r | wc -l)" -ge 2 ] && wait -n
done
wait
echo "trace depth: $(ls "$OUT"/*.json 2>/dev/null | wc -l) reports in $OUT"
