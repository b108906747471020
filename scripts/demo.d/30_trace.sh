# Stage 30: airway tracking (thesis 4.3.2, 6.2). Traces the airway tree of a real chest CT
# from a root in the trachea with automatic terminals (one search, resumed per terminal), writes
# SWC + JSON + VTK, prints the path table, then the Table-2-style graph figures of the full grid
# and of the IsoRegion-pruned graph computed on the node-cost field (default: the windowed cost is
# one flat value outside the lumen) and on the intensities (the thesis's literal rule: noisy HU,
# almost nothing pruned), with the pruned paths' costs against the full grid's.
# Falls back to the vessel phantom of stage 10 when the data is missing.
# Sourced by scripts/demo.sh (VS, OUT, DATA set).
echo "== trace: airway / vessel tree from one root, automatic terminals =="
# Compares the paths of two trace JSON reports (same terminals? cost ratio pruned / full).
compare_paths() {
  command -v python3 >/dev/null 2>&1 || return 0
  python3 - "$1" "$2" <<'PY'
import json, sys
f, p = (json.load(open(x)) for x in sys.argv[1:3])
a, b = f["paths"], p["paths"]
same = len(a) == len(b) and all(x["target"] == y["target"] for x, y in zip(a, b))
r = [y["cost"] / x["cost"] for x, y in zip(a, b) if x["cost"] > 0]
print(f"   paths vs full grid: {len(b)} of {len(a)}, same terminals: {'yes' if same else 'no'}, "
      f"cost ratio pruned/full {min(r):.4f}..{max(r):.4f}; nodes {p['graph']['nodes'] / f['graph']['nodes']:.1%} of the full grid")
PY
}
CT="$DATA/chest_cta_totalseg/ct_cropped.nii.gz"
if [ -f "$CT" ]; then
  # Root: trachea lumen (voxel 46,59,150). The default (auto) cost estimates polarity (dark) and
  # window at the root against its surroundings and prints them; paths are refined to the lumen
  # centre with a radius per point.
  ARGS=(--root 46,59,150 --auto-terminals 6 --min-length 20)
  "$VS" -q trace "$CT" "${ARGS[@]}" \
    --out "$OUT/airway_tree.swc" --vtk "$OUT/airway_tree.vtk" --json "$OUT/airway_trace.json"
  # The airway criteria: every path point below -900 HU, < 10 % of refined points within 0.5 mm
  # of the wall (EDT distance to the nearest voxel >= -900 HU).
  if /usr/bin/python3 -c "import scipy" 2>/dev/null; then
    /usr/bin/python3 bench/trace_measures.py airway "$CT" "$OUT/airway_trace.json" --cli "$VS" | tail -1
  fi
  echo "-- the same search on the IsoRegion-pruned graph, map on the node costs (--prune isoregion, default --prune-on cost):"
  "$VS" -q trace "$CT" "${ARGS[@]}" --prune isoregion --json "$OUT/airway_trace_pruned.json" | grep -E '^(graph|search):'
  compare_paths "$OUT/airway_trace.json" "$OUT/airway_trace_pruned.json"
  echo "-- map on the intensities (thesis 4.1 literal, --prune-on intensity --threshold -950): noisy HU, little is pruned:"
  "$VS" -q trace "$CT" "${ARGS[@]}" --prune isoregion --prune-on intensity --threshold -950 \
    --json "$OUT/airway_trace_pruned_intensity.json" | grep -E '^(graph|search):'
  compare_paths "$OUT/airway_trace.json" "$OUT/airway_trace_pruned_intensity.json"
  echo "wrote:     $OUT/airway_tree.swc, $OUT/airway_tree.vtk, $OUT/airway_trace.json"
else
  echo "($CT missing: tracing the vessel phantom of stage 10 instead, default (auto) cost)"
  ARGS=(--targets-file "$OUT/phantom_vessels.json")
  "$VS" -q trace "$OUT/phantom_vessels.nii.gz" "${ARGS[@]}" --out "$OUT/phantom_tree.swc" --json "$OUT/phantom_trace.json"
  echo "-- pruned, map on the node costs (default):"
  "$VS" -q trace "$OUT/phantom_vessels.nii.gz" "${ARGS[@]}" --prune isoregion --json "$OUT/phantom_trace_pruned.json" |
    grep -E '^(graph|search):'
  compare_paths "$OUT/phantom_trace.json" "$OUT/phantom_trace_pruned.json"
  echo "-- pruned, map on the intensities (thesis 4.1, values below 100 set to 0):"
  "$VS" -q trace "$OUT/phantom_vessels.nii.gz" "${ARGS[@]}" --prune isoregion --prune-on intensity --threshold 100 \
    --json "$OUT/phantom_trace_pruned_intensity.json" | grep -E '^(graph|search):'
  compare_paths "$OUT/phantom_trace.json" "$OUT/phantom_trace_pruned_intensity.json"
fi
