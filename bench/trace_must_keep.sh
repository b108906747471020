#!/usr/bin/env bash
# The tracking must-keep sets (issue 21): what every change to the automatic cost, the terminal
# scan or the refinement must keep passing. Figures are printed; the exit status is the number of
# sets that failed. Needs ../shared/data (or VS_DATA) and Debian's python3-numpy / python3-scipy.
#   bench/trace_must_keep.sh BUILD_DIR [OUT_DIR]
# Sets (docs/notes/tracking.md, sessions 8-18):
#   airway   README chest CTA airway example: every path voxel and refined point < -900 HU, < 10 %
#            of the points within 0.5 mm of the wall (trace_measures.py airway)
#   trachea  4D-CT mid trachea 239,242,92 --auto-terminals 6: the same airway criteria
#   aorta    aorta MRA, 4 roots along the aorta, --auto-terminals 6: >= 6 paths, every refined point
#            in the vessel, no pair side by side 1-4 mm for > 10 % (trace_measures.py branches)
#   carotid  carotid MRA root 18,23,10 and head CTA root 196,96,5: the 5 dim targets of
#   headcta  bench/dim_targets.py each reached (bench/trace_dim_targets.sh), share in the vessel
set -uo pipefail
BUILD=$(cd "$1" && pwd)
OUT=${2:-$(mktemp -d)}
HERE=$(cd "$(dirname "$0")" && pwd)
D=${VS_DATA:-$HERE/../../shared/data}
VS="$BUILD/volscissors"
PY=/usr/bin/python3
mkdir -p "$OUT"
if [ ! -d "$D" ]; then
  echo "must-keep: the shared data ($D) is missing; nothing checked" >&2
  exit 2
fi
failed=0
fail() {
  echo "FAIL: $*"
  failed=$((failed + 1))
}

echo "== airway (README example)"
CTA=$D/chest_cta_totalseg/ct_cropped.nii.gz
if "$VS" -q trace "$CTA" --root 46,59,150 --auto-terminals 6 --min-length 20 --json "$OUT/airway.json" \
  >"$OUT/airway.txt" 2>&1; then
  $PY "$HERE/trace_measures.py" airway "$CTA" "$OUT/airway.json" --cli "$VS" | tail -2 || fail airway
else
  fail "airway trace: $(grep -i -m1 error "$OUT/airway.txt")"
fi

echo "== 4D-CT mid trachea"
if [ ! -d "$OUT/4dct" ]; then
  mkdir -p "$OUT/4dct" && tar -xzf "$D/chest_ct_4dct_dicom/chest_ct_4dct_dicom_00.tar.gz" -C "$OUT/4dct"
fi
DCM=$OUT/4dct/chest_ct_4dct_dicom_00
if "$VS" -q trace "$DCM" --root 239,242,92 --auto-terminals 6 --json "$OUT/trachea.json" \
  >"$OUT/trachea.txt" 2>&1; then
  $PY "$HERE/trace_measures.py" airway "$DCM" "$OUT/trachea.json" --cli "$VS" | tail -2 || fail trachea
else
  fail "trachea trace: $(grep -i -m1 error "$OUT/trachea.txt")"
fi

echo "== aorta MRA, 4 roots, --auto-terminals 6"
AO=$D/abdomen_mra_aorta_vmtk/aorta.mha
for r in 75,172,14 74,140,16 70,250,14 72,300,17; do
  if "$VS" -q trace "$AO" --root "$r" --auto-terminals 6 --json "$OUT/aorta_$r.json" >"$OUT/aorta_$r.txt" 2>&1; then
    echo -n "root $r: "
    $PY "$HERE/trace_measures.py" branches "$AO" "$OUT/aorta_$r.json" --cli "$VS" | tail -1 || fail "aorta $r"
  else
    fail "aorta $r trace: $(grep -i -m1 error "$OUT/aorta_$r.txt")"
  fi
done

dim_set() { # name volume root
  echo "== $1 dim targets (root $3)"
  local t
  # awk reads to the end (grep -m1 closed the pipe early: a BrokenPipeError from the script)
  t=$($PY "$HERE/dim_targets.py" "$2" "$3" --cli "$VS" | awk '/;/ && !f {print; f = 1}')
  "$HERE/trace_dim_targets.sh" "$BUILD" "$2" "$3" "$t" "$OUT/$1" | tee "$OUT/$1.summary"
  if grep -q "REFUSED\|all targets at once:" "$OUT/$1.summary"; then fail "$1 dim targets"; fi
}
dim_set carotid "$D/neck_mra_carotid_vtk/carotid.vtk" 18,23,10
dim_set headcta "$D/head_cta_avm/AVM.nii.gz" 196,96,5

echo "must-keep: $failed set(s) failed; reports in $OUT"
exit "$failed"
