# Stage 30: airway tracking (thesis 4.3.2, 6.2). Traces the airway tree of a real chest CT
# from a root in the trachea with automatic terminals (one search, resumed per terminal), writes
# SWC + JSON + VTK, prints the path table, then the Table-2-style graph figures of the full and
# the IsoRegion-pruned graph. Falls back to the vessel phantom of stage 10 when the data is missing.
# Sourced by scripts/demo.sh (VS, OUT, DATA set).
echo "== trace: airway / vessel tree from one root, automatic terminals =="
CT="$DATA/chest_cta_totalseg/ct_cropped.nii.gz"
if [ -f "$CT" ]; then
  # Root: trachea lumen (voxel 46,59,150; -990 HU). Dark tubes: cost from HU in the window
  # -1000..-950 (lumen cheap, walls and lung parenchyma expensive).
  "$VS" -q trace "$CT" --root 46,59,150 --auto-terminals 6 --min-length 20 \
    --cost intensity --polarity dark --window -1000,-950 --smooth 0 \
    --out "$OUT/airway_tree.swc" --vtk "$OUT/airway_tree.vtk" --json "$OUT/airway_trace.json"
  echo "-- the same search on the IsoRegion-pruned graph (values below -950 HU set to 0 first):"
  "$VS" -q trace "$CT" --root 46,59,150 --auto-terminals 6 --min-length 20 \
    --cost intensity --polarity dark --window -1000,-950 --smooth 0 \
    --prune isoregion --threshold -950 --json "$OUT/airway_trace_pruned.json" | grep -E '^(graph|search):'
  echo "wrote:     $OUT/airway_tree.swc, $OUT/airway_tree.vtk, $OUT/airway_trace.json"
else
  echo "($CT missing: tracing the vessel phantom of stage 10 instead)"
  "$VS" -q trace "$OUT/phantom_vessels.nii.gz" --targets-file "$OUT/phantom_vessels.json" --cost intensity \
    --out "$OUT/phantom_tree.swc" --json "$OUT/phantom_trace.json"
  "$VS" -q trace "$OUT/phantom_vessels.nii.gz" --targets-file "$OUT/phantom_vessels.json" --cost intensity \
    --prune isoregion --threshold 100 --json "$OUT/phantom_trace_pruned.json" | grep -E '^(graph|search):'
fi
