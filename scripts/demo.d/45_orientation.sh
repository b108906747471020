# Stage 45: pictures a reader can trust and coordinates read off them. The MR with a face
# and the head CT as axial / coronal / sagittal slices in anatomical orientation (whatever the
# storage order) with orientation letters; one slice at one pixel per voxel with index ticks
# and its picture -> voxel mapping; a contour clicked on that picture with `livewire --picture`.
# Sourced by scripts/demo.sh (VS, OUT, DATA set).
echo "== orientation: anatomical slices, picture -> voxel mapping, clicks on the picture =="
MR="$DATA/head_mr_t1_face/chris_t1.nii.gz"
if [ ! -f "$MR" ]; then
  echo "($MR missing: using the phantom head)"
  MR="$OUT/phantom_head.nii.gz"
  [ -f "$MR" ] || "$VS" -q phantom head --seed 1 --size 128,128,128 --out "$MR"
fi
"$VS" info "$MR" --json "$OUT/orient_info.json" | grep -E "^(orientation|slices)"
read -r NX NY NZ < <(python3 -c "import json,sys; print(*json.load(open(sys.argv[1]))['dims'])" "$OUT/orient_info.json")
for p in "x=$((NX / 2))" "y=$((NY / 2))" "z=$((NZ / 2))"; do
  "$VS" -q render "$MR" --mode slice --plane "$p" --letters --size 384x384 --out "$OUT/orient_mr_${p%%=*}.png" \
    --json "$OUT/orient_mr_${p%%=*}.json"
  python3 -c "import json,sys; r=json.load(open(sys.argv[1])); e=r['edges']; print(f\"{sys.argv[2] + ':':10s} {r['slice']['plane']:8s} left {e['left']}, right {e['right']}, top {e['top']}, bottom {e['bottom']}\")" \
    "$OUT/orient_mr_${p%%=*}.json" "$p"
done
HEAD_CT="$DATA/head_ct_cranium_invesalius/cranium.nhdr"
if [ -f "$HEAD_CT" ]; then
  "$VS" -q render "$HEAD_CT" --mode slice --plane z=90 --voxel-pixels --ticks --letters --window 400,40 \
    --json "$OUT/orient_ct_z90.json" --out "$OUT/orient_ct_z90.png"
  "$VS" -q livewire "$HEAD_CT" --slice z=90 --picture --closed --snap 2 \
    --points "129,45;175,66;181,111;129,181;78,111" --out "$OUT/orient_ct_clicked.json"
  "$VS" -q render "$HEAD_CT" --mode slice --plane z=90 --voxel-pixels --letters --window 400,40 \
    --overlay "$OUT/orient_ct_clicked.json" --out "$OUT/orient_ct_clicked.png"
  echo "clicked:   5 picture pixels of $OUT/orient_ct_z90.png -> $OUT/orient_ct_clicked.{json,png}"
fi
echo "wrote:     $OUT/orient_mr_{x,y,z}.png (letters at the edges)"
