#!/usr/bin/env bash
# Thesis Table 2 re-measured: full single-source search (every node settled) on sub-volumes of
# real lung CT, without and with IsoRegion pruning (thesis 4.1), beside the thesis's SGI Octane
# R10000 times. Uses the 4D-CT DICOM series (extracted to a temp dir), else the chest CTA, else
# the project's vessel phantom. Cost: the thesis's 3D scissors cost (gradient, w_g 0.7, w_z 0.3),
# 26-connected. Two pruned graphs side by side:
#  * intensity: the IsoRegion map on the intensities (thesis 4.1 literal) with the thesis's
#    threshold trick adapted to HU: values below THRESHOLD (default -400 HU: air and lung) are
#    set to 0 first (--prune-on intensity --threshold);
#  * cost: the map on the node-cost field the search sees (--prune-on cost, the default), with
#    the relative COST_TOLERANCE (default 0 = exact). The gradient cost is continuous, so on CT it
#    is flat only where the gradient is exactly 0 (or clipped at maxG).
# A second table repeats it with a windowed intensity cost (WINDOW, default -1000,-950: airways
# dark; the cost is one flat value outside the window), where the cost field prunes the flat
# regions and the intensity field (no threshold) cannot.
# Usage: bench/table2.sh [BUILD_DIR]   (env THRESHOLD, TOLERANCE, COST_TOLERANCE, WINDOW)
set -euo pipefail
BUILD=${1:-build}
VS="$BUILD/volscissors"
DATA=${DATA:-../shared/data}
THRESHOLD=${THRESHOLD:--400}
TOLERANCE=${TOLERANCE:-0}
COST_TOLERANCE=${COST_TOLERANCE:-0}
WINDOW=${WINDOW:--1000,-950}
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
  VOL="$TMP/ph.nii.gz"; X0=0; Y0=0; Z0=0; NAME="vessel phantom"; THRESHOLD=100; WINDOW=100,160
fi
echo "Table 2 on $NAME; $("$VS" info "$VOL" | grep dims); threads: ${VS_THREADS:-$(nproc)}"
table() {  # $1: title, $2: cost arguments, $3: intensity-field pruning arguments
  echo "$1"
  printf "%-10s | %-19s | %-36s | %-36s | %-7s | %s\n" "" "full grid" "pruned, map on intensity" "pruned, map on cost" "thesis" \
    "RATIO thesis/ours"
  printf "%-10s | %7s %10s %8s | %7s %9s %6s %9s | %7s %9s %6s %9s | %7s | %5s %5s %5s | %s\n" size nodes edges search \
    nodes edges build search nodes edges build search time full int cost "cost-field paths/full"
  for size in 32,32,32 64,32,32 64,64,32 64,64,64 128,64,64; do
    IFS=, read -r SX SY SZ <<<"$size"
    ROI="$X0,$Y0,$Z0,$((X0 + SX - 1)),$((Y0 + SY - 1)),$((Z0 + SZ - 1))"
    ROOT="$((X0 + SX / 2)),$((Y0 + SY / 2)),$((Z0 + SZ / 2))"
    TGT="$((X0 + 1)),$((Y0 + 1)),$((Z0 + 1))"
    for mode in none intensity cost; do
      extra=""
      [ "$mode" = intensity ] && extra="--prune isoregion --prune-on intensity $3"
      [ "$mode" = cost ] && extra="--prune isoregion --prune-on cost --cost-tolerance $COST_TOLERANCE"
      # shellcheck disable=SC2086
      "$VS" -q trace "$VOL" --roi "$ROI" --root "$ROOT" --target "$TGT" --full $2 $extra \
        --json "$TMP/$mode.json" >/dev/null
    done
    $PY - "$TMP/none.json" "$TMP/intensity.json" "$TMP/cost.json" "$size" <<'PY'
import json, sys
f, p, c = (json.load(open(x)) for x in sys.argv[1:4])
thesis = {"32,32,32": 0.83, "64,32,32": 1.85, "64,64,32": 3.49, "64,64,64": 8.24, "128,64,64": 15.15}[sys.argv[4]]
g = f["graph"]
fs = f["seconds"]["search"]
def cols(r):
    h = r["graph"]
    return f"{h['nodes']:>7} {h['edges']:>9} {r['seconds']['graph']:>5.3f}s {r['seconds']['search']:>7.3f}s"
ratio = c["paths"][0]["cost"] / f["paths"][0]["cost"] if f["paths"][0]["cost"] > 0 else 1.0
print(f"{sys.argv[4].replace(',', 'x'):<10} | {g['nodes']:>7} {g['edges']:>10} {fs:>7.3f}s | {cols(p)} | {cols(c)} | "
      f"{thesis:>6.2f}s | {thesis / max(fs, 1e-6):>5.0f} {thesis / max(p['seconds']['search'], 1e-6):>5.0f} "
      f"{thesis / max(c['seconds']['search'], 1e-6):>5.0f} | cost x{ratio:.4f}")
PY
  done
}
table "-- thesis cost (gradient, w_g 0.7, w_z 0.3); intensity field with threshold $THRESHOLD, tolerance $TOLERANCE" \
  "--cost gradient" "--threshold $THRESHOLD --tolerance $TOLERANCE"
table "-- windowed intensity cost (dark, window $WINDOW, no smoothing); intensity field without threshold" \
  "--cost intensity --polarity dark --window $WINDOW --smooth 0" "--tolerance $TOLERANCE"
echo "edges: undirected. full grid = implicit 26-connected (nothing to build). search = single-source Dijkstra"
echo "until every node is settled; build = IsoRegion map + pruned CSR graph. cost-field paths/full: cost of the"
echo "root->target path on the cost-field graph / the full grid's (never below 1). thesis = SGI Octane R10000 on its"
echo "pruned graph (Table 2's largest row: 128x64x64, 390,123 nodes, 3,470,100 edges, 15.15 s). Ratios across 28"
echo "years of hardware, for scale only."
