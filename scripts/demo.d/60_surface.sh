# Stage 60: surface extraction from three orthogonal contours (thesis 4.3.1, Figure 22): the skin
# of one octant of a real head CT at levels 0-5, drawn over the volume (bone transfer function:
# the skin is see-through, the patch red), then a closed surface of the phantom head (eight
# octants stitched watertight). Falls back to the phantom head when the data is missing.
# Sourced by scripts/demo.sh (VS, OUT, DATA set).
echo "== surface: deformed-triangle subdivision from three contours (levels 0-5, closed) =="
SURF_CT="$DATA/head_ct_cranium_invesalius/cranium.nhdr"
SURF_PLANES=128,128,54
SURF_VIEW=135,25
if [ ! -f "$SURF_CT" ]; then
  echo "($SURF_CT missing: the phantom head instead)"
  SURF_CT="$OUT/phantom_head.nii.gz"
  SURF_PLANES=64,64,64
  [ -f "$SURF_CT" ] || "$VS" -q phantom head --seed 1 --size 128,128,128 --out "$SURF_CT"
fi
for level in 0 1 2 3 4 5; do
  "$VS" -q surface "$SURF_CT" --planes "$SURF_PLANES" --octant +x+y+z --level "$level" \
    --out "$OUT/surface_octant_l$level.ply" --json "$OUT/surface_octant_l$level.json"
  "$VS" -q render "$SURF_CT" --tf ct-bone --view "$SURF_VIEW" --size 256x256 --zoom 1.2 \
    --overlay "$OUT/surface_octant_l$level.ply" --out "$OUT/surface_octant_l$level.png"
done
"$VS" -q render "$SURF_CT" --tf ct-bone --view "$SURF_VIEW" --size 512x512 --zoom 1.2 \
  --overlay "$OUT/surface_octant_l5.ply" --out "$OUT/surface_octant.png"
if command -v python3 >/dev/null 2>&1; then
  python3 - "$OUT" <<'PY'
import json, sys
for level in range(6):
    r = json.load(open(f"{sys.argv[1]}/surface_octant_l{level}.json"))
    paths = sum(l["paths"] for l in r["levels"])
    print(f"octant +x+y+z level {level}: {r['mesh']['triangles']:5d} triangles, {paths:4d} 3D paths, "
          f"{r['seconds']['total']:.2f} s (iso {r['iso']:.0f}, Otsu)")
PY
fi
# Closed: the phantom head (its skin is a closed ellipsoid with a nose), eight octants at level 4.
SURF_PH="$OUT/phantom_head.nii.gz"
[ -f "$SURF_PH" ] || "$VS" -q phantom head --seed 1 --size 128,128,128 --out "$SURF_PH"
"$VS" -q surface "$SURF_PH" --planes 64,64,64 --closed --level 4 --out "$OUT/surface_closed.ply" \
  --json "$OUT/surface_closed.json"
"$VS" -q render "$SURF_PH" --tf ct-bone --view 150,20 --size 512x512 --overlay "$OUT/surface_closed.ply" \
  --out "$OUT/surface_closed.png"
if command -v python3 >/dev/null 2>&1; then
  python3 -c "import json,sys; r=json.load(open(sys.argv[1])); m=r['mesh']; print(f\"closed phantom head level 4: {m['triangles']} triangles, Euler characteristic {m['euler_characteristic']}, watertight {m['watertight']}, {r['seconds']['total']:.2f} s\")" "$OUT/surface_closed.json"
fi
echo "wrote:     $OUT/surface_octant_l{0..5}.{ply,json,png}, $OUT/surface_octant.png, $OUT/surface_closed.{ply,json,png}"
