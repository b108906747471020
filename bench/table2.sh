#!/usr/bin/env bash
# Thesis Table 2 re-measured: full single-source search (every node settled) on sub-volumes of
# real lung CT, without and with IsoRegion pruning (thesis 4.1), beside the thesis's SGI Octane
# R10000 times. Uses the 4D-CT DICOM series (extracted to a temp dir), else the chest CTA, else
# the project's vessel phantom. Cost: the thesis's 3D scissors cost (gradient, w_g 0.7, w_z 0.3),
# 26-connected. Pruning uses the thesis's threshold trick adapted to HU: values below
# THRESHOLD (default -400 HU: air and lung) are set to 0 before the IsoRegion map.
# Usage: bench/table2.sh [BUILD_DIR]   (env THRESHOLD, TOLERANCE)
set -euo pipefail
BUILD=${1:-build}
VS="$BUILD/volscissors"
DATA=${DATA:-../shared/data}
THRESHOLD=${THRESHOLD:--400}
TOLERANCE=${TOLERANCE:-0}
PY=/usr/bin/python3
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

if [ -f "$DATA/chest_ct_4dct_dicom/chest_ct_4dct_dicom_00.tar.gz" ]; then
  tar xzf "$DATA/chest_ct_4dct_dicom/chest_ct_4dct_dicom_00.tar.gz" -C "$TMP"
  VOL="$TMP/chest_ct_4dct_dicom_00"; X0=120; Y0=180; Z0=40; NAME="4D-CT lung (DICOM, 0.98x0.98x2 mm)"
elif [ -f "$DATA/chest_cta_totalseg/ct_cropped.nii.gz" ]; then
  VOL="$DATA/chest_cta_totalseg/ct_cropped.nii.gz"; X0=0; Y0=30; Z0=20; NAME="chest CTA (1.5 mm)"
else
  "$VS" -q phantom vessels --seed 1 --size 160,96,96 --out "$TMP/ph.nii.gz"
  VOL="$TMP/ph.nii.gz"; X0=0; Y0=0; Z0=0; NAME="vessel phantom"; THRESHOLD=100
fi
echo "Table 2 on $NAME; $("$VS" info "$VOL" | grep dims); threads: ${VS_THREADS:-$(nproc)}"
printf "%-10s | %-19s | %-44s | %-7s | %s\n" "" "full grid" "IsoRegion-pruned graph" "thesis" "RATIO thesis/ours"
printf "%-10s | %7s %10s %8s | %7s %9s %6s %9s %8s | %7s | %6s %6s\n" size nodes edges search nodes edges repair build search \
  time full pruned
for size in 32,32,32 64,32,32 64,64,32 64,64,64 128,64,64; do
  IFS=, read -r SX SY SZ <<<"$size"
  ROI="$X0,$Y0,$Z0,$((X0 + SX - 1)),$((Y0 + SY - 1)),$((Z0 + SZ - 1))"
  ROOT="$((X0 + SX / 2)),$((Y0 + SY / 2)),$((Z0 + SZ / 2))"
  TGT="$((X0 + 1)),$((Y0 + 1)),$((Z0 + 1))"
  for mode in none isoregion; do
    extra=""
    [ "$mode" = isoregion ] && extra="--threshold $THRESHOLD --tolerance $TOLERANCE"
    # shellcheck disable=SC2086
    "$VS" -q trace "$VOL" --roi "$ROI" --root "$ROOT" --target "$TGT" --full --prune "$mode" $extra \
      --json "$TMP/$mode.json" >/dev/null
  done
  $PY - "$TMP/none.json" "$TMP/isoregion.json" "$size" <<'PY'
import json, sys
f, p = (json.load(open(x)) for x in sys.argv[1:3])
thesis = {"32,32,32": 0.83, "64,32,32": 1.85, "64,64,32": 3.49, "64,64,64": 8.24, "128,64,64": 15.15}[sys.argv[3]]
g, h = f["graph"], p["graph"]
fs, ps = f["seconds"]["search"], p["seconds"]["search"]
print(f"{sys.argv[3].replace(',', 'x'):<10} | {g['nodes']:>7} {g['edges']:>10} {fs:>7.3f}s | {h['nodes']:>7} {h['edges']:>9} "
      f"{h['repair_edges']:>6} {p['seconds']['graph']:>8.3f}s {ps:>7.3f}s | {thesis:>6.2f}s | {thesis / max(fs, 1e-6):>6.0f} "
      f"{thesis / max(ps, 1e-6):>6.0f}")
PY
done
echo "edges: undirected. full grid = implicit 26-connected (nothing to build). search = single-source Dijkstra"
echo "until every node is settled. thesis = SGI Octane R10000 on its pruned graph (Table 2's largest row:"
echo "128x64x64, 390,123 nodes, 3,470,100 edges, 15.15 s). Ratios across 28 years of hardware, for scale only."
