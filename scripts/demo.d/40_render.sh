# Stage 40: volume rendering, the thesis's display modes (ch. 5) on the CPU ray caster:
# full volume (skin and bone transfer functions), cut-box, triplanar, monoplanar, MIP and
# flat slices of a real head CT (a phantom head when the data is missing), then the airway
# (or vessel) tree of stage 30 overlaid on its CT (the phantom tree on a MIP, where overlays are on top). PNGs go to $OUT/render_*.png.
# Sourced by scripts/demo.sh (VS, OUT, DATA set).
echo "== render: display modes (full, cut-box, triplanar, monoplanar, MIP, slices) =="
HEAD_CT="$DATA/head_ct_cranium_invesalius/cranium.nhdr"
SLICES="z=60 y=128 x=128"
# The head CT's header states no orientation; its axes run to the patient's left, anterior (the
# face is at high y) and superior: LAS. Stated, the views below show the face from the front
# and the slices carry the right letters.
ORIENT=(--orientation LAS)
if [ ! -f "$HEAD_CT" ]; then
  SLICES="z=60 y=64 x=64"
  echo "($HEAD_CT missing: rendering the phantom head instead)"
  HEAD_CT="$OUT/phantom_head.nii.gz"
  ORIENT=()
  [ -f "$HEAD_CT" ] || "$VS" -q phantom head --seed 1 --size 128,128,128 --out "$HEAD_CT"
fi
R=("$VS" -q render "$HEAD_CT" "${ORIENT[@]}" --size 512x512 --zoom 1.3)
"${R[@]}" --tf ct-skin --view 0,10 --out "$OUT/render_head_skin.png" --json "$OUT/render_head_skin.json"
"${R[@]}" --tf ct-bone --view -35,15 --perspective --out "$OUT/render_head_bone.png"
"${R[@]}" --mode cutbox --tf ct-skin --view -35,25 --window 400,40 --out "$OUT/render_head_cutbox.png"
"${R[@]}" --mode triplanar --view -35,15 --window 400,40 --out "$OUT/render_head_triplanar.png"
"${R[@]}" --mode monoplanar --plane z=60 --view -20,35 --window 400,40 --out "$OUT/render_head_monoplanar.png"
"${R[@]}" --mode mip --view 0,0 --window 2000,800 --out "$OUT/render_head_mip.png"
for p in $SLICES; do
  "$VS" -q render "$HEAD_CT" "${ORIENT[@]}" --mode slice --plane "$p" --window 400,40 --out "$OUT/render_head_slice_${p%%=*}.png"
done
if command -v python3 >/dev/null 2>&1; then
  python3 -c "import json,sys; r=json.load(open(sys.argv[1])); s=r['seconds']; print(f\"head:      {r['dims'][0]}x{r['dims'][1]}x{r['dims'][2]}, 512x512 full mode with shading: load {s['load']:.2f} s, prepare {s['prepare']:.2f} s, frame {s['frame_median']*1000:.0f} ms on {r['threads']} threads\")" "$OUT/render_head_skin.json"
fi
echo "wrote:     $OUT/render_head_{skin,bone,cutbox,triplanar,monoplanar,mip,slice_z,slice_y,slice_x}.png"

# The traced tree of stage 30 over its CT (bone TF: the airways show through soft tissue).
CHEST_CT="$DATA/chest_cta_totalseg/ct_cropped.nii.gz"
if [ -f "$OUT/airway_tree.swc" ] && [ -f "$CHEST_CT" ]; then
  "$VS" -q render "$CHEST_CT" --tf ct-bone --view 0,10 --overlay "$OUT/airway_tree.swc" --out "$OUT/render_chest_tree.png"
  "$VS" -q render "$CHEST_CT" --mode triplanar --view 30,25 --window 1500,-300 --overlay "$OUT/airway_tree.swc" \
    --out "$OUT/render_chest_tree_triplanar.png"
  echo "tree:      $OUT/airway_tree.swc over $CHEST_CT -> $OUT/render_chest_tree{,_triplanar}.png"
elif [ -f "$OUT/phantom_tree.swc" ] && [ -f "$OUT/phantom_vessels.nii.gz" ]; then
  "$VS" -q render "$OUT/phantom_vessels.nii.gz" --mode mip --window 200,110 --view 30,20 --overlay "$OUT/phantom_tree.swc" \
    --overlay-radius 0.6 --out "$OUT/render_phantom_tree.png"
  echo "tree:      $OUT/phantom_tree.swc over the vessel phantom -> $OUT/render_phantom_tree.png"
else
  echo "(no traced tree from stage 30 found: skipping the overlay picture)"
fi
