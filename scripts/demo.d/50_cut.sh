# Stage 50: volume cutting (thesis ch. 3, Figure 31): cut the nose off the real head CT along a
# closed live-wire contour drawn around it on the skin; the cutting surface follows the image
# inside. Falls back to the project's head phantom (which has a nose) when the data is missing.
# Writes $OUT/cut_* (labels, cutting surface, contour, report) and two pictures: the nose
# coloured on the head, and the head after the cut. Sourced by scripts/demo.sh (VS, OUT, DATA set).
echo "== cut: the nose off a head (closed contour on the skin, internal cutting surface, split) =="
HEAD_CT="$DATA/head_ct_cranium_invesalius/cranium.nhdr"
# Eight points around the nose on the skin (0-based voxel index), in loop order.
NOSE_POINTS="110,214,16;126,231,13;142,223,16;145,216,26;138,211,38;126,216,42;114,199,38;107,210,26"
ISO=-300
VIEW=150,10
if [ ! -f "$HEAD_CT" ]; then
  echo "($HEAD_CT missing: cutting the phantom head's nose instead)"
  HEAD_CT="$OUT/phantom_head.nii.gz"
  [ -f "$HEAD_CT" ] || "$VS" -q phantom head --seed 1 --size 128,128,128 --out "$HEAD_CT"
  NOSE_POINTS="72,21,58;69,20,68;64,20,73;58,20,68;55,21,58;58,23,47;64,24,42;69,23,47"
  ISO=-480
  VIEW=0,10
fi
"$VS" -q cut "$HEAD_CT" --iso "$ISO" --points "$NOSE_POINTS" --labels "$OUT/cut_labels.nii.gz" \
  --cut-surface "$OUT/cut_surface.ply" --contour "$OUT/cut_contour.json" --parts "$OUT/cut" --json "$OUT/cut_report.json"
if command -v python3 >/dev/null 2>&1; then
  python3 -c "import json,sys; r=json.load(open(sys.argv[1])); s=r['seconds']; p=r['parts']; print(f\"cut:       mesh {r['mesh']['triangles']} triangles, contour {r['contour']['vertices']} vertices {r['contour']['length_mm']:.0f} mm; cut away {p['cut']['mm3']/1000:.1f} cm3, kept {p['kept']['mm3']/1000:.0f} cm3; mesh {s['mesh']:.2f} s, contour {s['contour']:.2f} s, surface {s['cutting_surface']:.2f} s, split {s['split']:.2f} s\")" "$OUT/cut_report.json"
fi
"$VS" -q render "$HEAD_CT" --tf ct-skin --view "$VIEW" --size 512x512 --zoom 1.3 --labels "$OUT/cut_labels.nii.gz" \
  --overlay "$OUT/cut_contour.json" --out "$OUT/cut_nose_labels.png"
"$VS" -q render "$OUT/cut_kept.nii.gz" --tf ct-skin --view "$VIEW" --size 512x512 --zoom 1.3 --out "$OUT/cut_head_after.png"
echo "wrote:     $OUT/cut_{labels.nii.gz,surface.ply,contour.json,report.json,kept.nii.gz,cut.nii.gz,nose_labels.png,head_after.png}"
