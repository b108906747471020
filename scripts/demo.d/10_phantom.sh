# Stage 10: the project's own synthetic data. Generates the vessel-tree phantom
# (128^3, seed 1) with its ground truth, reads it back with `info`, and summarises
# the truth (branches, terminals, root). Sourced by scripts/demo.sh (VS, OUT, DATA set).
echo "== phantom: synthetic vessel tree with ground truth =="
"$VS" -q phantom vessels --seed 1 --size 128,128,128 --out "$OUT/phantom_vessels.nii.gz" \
  --truth "$OUT/phantom_vessels.json"
"$VS" info "$OUT/phantom_vessels.nii.gz" | grep -E '^(dims|spacing|type|range):'
if command -v python3 >/dev/null 2>&1; then
  python3 - "$OUT/phantom_vessels.json" <<'PY'
import json, sys
t = json.load(open(sys.argv[1]))
b = t["branches"]
radii = [r for br in b for r in br["radii_mm"]]
print(f"truth:     {len(b)} branches, {len(t['terminals'])} terminals, {len(t['branch_points'])} branch points, "
      f"radius {min(radii):.1f}..{max(radii):.1f} mm, iso {t['iso']:g}")
print(f"root:      voxel {t['root_voxel']}; first terminal voxel {t['terminals'][0]['voxel']}")
PY
fi
"$VS" -q phantom head --seed 1 --size 128,128,128 --out "$OUT/phantom_head.nii.gz" --truth "$OUT/phantom_head.json"
"$VS" -q phantom shapes2d --seed 1 --out "$OUT/phantom_shapes2d.nii.gz" --truth "$OUT/phantom_shapes2d.json" \
  --labels "$OUT/phantom_shapes2d_labels.nii.gz"
echo "also:      $OUT/phantom_head.nii.gz (int16 HU), $OUT/phantom_shapes2d.nii.gz (+ labels), truths as .json"
