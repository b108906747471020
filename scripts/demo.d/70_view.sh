# Stage 70: the interactive viewer (`volscissors view`), driven by a script (the same code paths
# as the mouse) in a window on a virtual display (Xvfb + Mesa's software OpenGL). Session 1 on
# the chest CT of ../shared/data (the head phantom when missing): display modes, a closed
# live-wire contour around the descending aorta, stereo anaglyph, the session file; 1b: the same
# volume drawn by the CPU renderer (what a machine without OpenGL 3.3 shows). Session 2:
# tracking on the vessel phantom of stage 10 with automatic terminals (the CLI's defaults).
# Session 3: the nose cut off the head CT (the `cut` example's points). Writes screenshots.
# Skips with a message when no virtual display can be made. Sourced by scripts/demo.sh.
echo "== view: scripted sessions of the interactive viewer =="
if ! command -v xvfb-run >/dev/null 2>&1; then
  echo "(xvfb-run is not installed: no virtual display, the viewer demo is skipped)"
else
  view_run() {  # view_run SCRIPT [FILE [OPTIONS...]]: the viewer under Xvfb; 0 on success
    local script="$1" file="${2:-}"
    shift $(($# < 2 ? $# : 2))
    xvfb-run -a -s "-screen 0 1400x900x24" "$VS" view ${file:+"$file"} --size 1280x800 "$@" --script "$script" 2> "$OUT/view_err.txt"
  }
  CHEST="$DATA/chest_ct_lidc2/LIDC2.mha"
  if [ -f "$CHEST" ]; then
    # Slice pixels (u = x, v = y) of axial slice z=66 around the descending aorta.
    VOL="$CHEST" WIRE="point 124,94
point 134,83
point 145,94
point 134,105"
  else
    echo "($CHEST missing: the embedded head phantom instead)"
    VOL="" WIRE="point 30,64
point 64,20
point 98,64
point 64,108"
  fi
  cat > "$OUT/view_session1.txt" <<SCRIPT
view 20 15
screenshot $OUT/view_full.png
mode triplanar
screenshot $OUT/view_triplanar.png
mode mip
screenshot $OUT/view_mip.png
mode full
tool livewire
slice z=66
snap 2
$WIRE
close
screenshot $OUT/view_livewire.png
save $OUT/view_contour.json
stereo anaglyph
screenshot $OUT/view_anaglyph.png
session-save $OUT/view_session.json
quit
SCRIPT
  if [ -z "$VOL" ]; then sed -i 's/^slice z=66/slice z=64/' "$OUT/view_session1.txt"; fi
  if view_run "$OUT/view_session1.txt" "$VOL"; then
    echo "session 1: $(python3 -c "import json,sys; c=json.load(open(sys.argv[1])); print(f\"contour {len(c['points'])} px, {c['length_mm']:.1f} mm, area {c['area_mm2']:.0f} mm^2\")" "$OUT/view_contour.json" 2>/dev/null)"
    # Session 1b: the same volume drawn by the CPU renderer, as on a machine without OpenGL 3.3
    # (--renderer cpu; the note shows in the panel), panned 15 mm to the right.
    printf 'view 20 15\npan 15 0\nscreenshot %s\nquit\n' "$OUT/view_cpu.png" > "$OUT/view_session1b.txt"
    view_run "$OUT/view_session1b.txt" "$VOL" --renderer cpu &&
      echo "session 1b: the CPU renderer's 3D view (--renderer cpu): $OUT/view_cpu.png"
    if [ -f "$OUT/phantom_vessels.json" ] && command -v python3 >/dev/null 2>&1; then
      ROOT=$(python3 -c "import json,sys; print(','.join(map(str, json.load(open(sys.argv[1]))['root_voxel'])))" "$OUT/phantom_vessels.json")
      cat > "$OUT/view_session2.txt" <<SCRIPT
tf vessels
mode mip
view 30 10
tool trace
point $ROOT
auto-terminals 6
run
screenshot $OUT/view_trace.png
save $OUT/view_tree.swc
quit
SCRIPT
      view_run "$OUT/view_session2.txt" "$OUT/phantom_vessels.nii.gz" &&
        echo "session 2: tree of $(grep -vc '^#' "$OUT/view_tree.swc") SWC nodes from root $ROOT with 6 automatic terminals"
    fi
    HEAD="$DATA/head_ct_cranium_invesalius/cranium.nhdr"
    if [ -f "$HEAD" ]; then
      # Session 3: the nose cut off the head CT at the README's points (the `cut` example), the
      # parts shown in their label colours, then the cut-away part hidden.
      cat > "$OUT/view_session3.txt" <<SCRIPT
tf ct-skin
view 20 10
tool cut
cut-iso -300
$(echo "110,214,16;126,231,13;142,223,16;145,216,26;138,211,38;126,216,42;114,199,38;107,210,26" | tr ';' '\n' | sed 's/^/point /')
run
planes 126,215,26
screenshot $OUT/view_cut.png
label 2 off
screenshot $OUT/view_cut_hidden.png
save $OUT/view_cut_labels.nii.gz
quit
SCRIPT
      view_run "$OUT/view_session3.txt" "$HEAD" --orientation LAS && echo "session 3: the nose cut off the head CT: $OUT/view_cut_labels.nii.gz"
    fi
    echo "wrote:     $OUT/view_{full,triplanar,mip,livewire,anaglyph,cpu,trace,cut,cut_hidden}.png, view_contour.json, view_tree.swc, view_cut_labels.nii.gz, view_session.json"
  else
    echo "(the viewer could not run here: $(tail -1 "$OUT/view_err.txt"); skipped)"
  fi
fi
