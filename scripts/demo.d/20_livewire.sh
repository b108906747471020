# Stage 20: 2D live-wire (intelligent scissors, thesis 2.3). A closed contour around the skull
# on an axial slice of the InVesalius head CT from 8 clicked points (falls back to the shapes2d
# phantom when ../shared/data is missing); contour JSON and a label mask go to $OUT.
# Sourced by scripts/demo.sh (VS, OUT, DATA set).
echo "== livewire: closed 2D live-wire contour from a handful of points =="
if [ -f "$DATA/head_ct_cranium_invesalius/cranium.nhdr" ]; then
  # Outer skull boundary on z = 90 (bone ring closed there); points on the bone edge.
  "$VS" -q livewire "$DATA/head_ct_cranium_invesalius/cranium.nhdr" --slice z=90 \
    --points "181,111;172,153;129,181;85,156;78,111;86,68;129,45;175,66" --closed --snap 2 \
    --out "$OUT/livewire_skull.json" --mask "$OUT/livewire_skull_mask.nii.gz"
  echo "saved:     $OUT/livewire_skull.json, $OUT/livewire_skull_mask.nii.gz (uint8 label volume, slice z=90 filled)"
else
  echo "(shared data missing: $DATA; using the shapes2d phantom)"
  "$VS" -q phantom shapes2d --seed 1 --out "$OUT/livewire_shapes.nii.gz" --truth "$OUT/livewire_shapes.json"
  # Four points on the true boundary of shape 0 (a disc), read from the truth file.
  LW_POINTS=$(python3 -c '
import json, sys
b = json.load(open(sys.argv[1]))["shapes"][0]["boundary"]
print(";".join(f"{round(b[i * len(b) // 4][0])},{round(b[i * len(b) // 4][1])}" for i in range(4)))' "$OUT/livewire_shapes.json")
  "$VS" -q livewire "$OUT/livewire_shapes.nii.gz" --points "$LW_POINTS" --closed \
    --out "$OUT/livewire_shapes_contour.json" --mask "$OUT/livewire_shapes_mask.nii.gz"
  echo "saved:     $OUT/livewire_shapes_contour.json, $OUT/livewire_shapes_mask.nii.gz"
fi
