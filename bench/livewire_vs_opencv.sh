#!/usr/bin/env bash
# Live-wire speed next to OpenCV's IntelligentScissorsMB (peer) on the same 512x512 image,
# in the same run: features/costs vs applyImage, full single-source map vs buildMap, and our
# cursor-move (resumed search) median. Prints the times and RATIO lines (> 1: we are faster).
#   bench/livewire_vs_opencv.sh [BUILD_DIR]      (default build; needs target bench_livewire)
# Needs /usr/bin/python3 with numpy, scipy, scikit-image, opencv, nibabel (Debian packages
# python3-numpy python3-scipy python3-skimage python3-opencv python3-nibabel).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-build}
case "$BUILD" in /*) ;; *) BUILD="$ROOT/$BUILD" ;; esac
PEERS=${VS_PEERS_DIR:-$ROOT/../shared/peers}
PY=/usr/bin/python3
[ -x "$BUILD/bench_livewire" ] || { echo "missing $BUILD/bench_livewire (cmake --build $BUILD --target bench_livewire)" >&2; exit 1; }
[ -f "$PEERS/livewire_opencv.py" ] || { echo "peer scripts missing: $PEERS" >&2; exit 1; }

TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
IMG="$PEERS/data/shapes_512.png"
if [ ! -f "$IMG" ]; then
  echo "generating the peers' inputs into $TMP (make_volumes.py)" >&2
  "$PY" "$PEERS/make_volumes.py" --sizes 128 --outdir "$TMP/data" >/dev/null
  IMG="$TMP/data/shapes_512.png"
fi
# Seed and cursor targets from the sidecar ([row, col] -> u = col, v = row).
read -r SEED TARGETS < <("$PY" - "${IMG%.png}.json" <<'PYEOF'
import json, sys
m = json.load(open(sys.argv[1]))
print(f"{m['root'][1]},{m['root'][0]}", ";".join(f"{c},{r}" for r, c in m["terminals"]))
PYEOF
)

VS_BENCH_IMAGE="$IMG" VS_BENCH_SEED="$SEED" VS_BENCH_TARGETS="$TARGETS" \
  "$BUILD/bench_livewire" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
  --benchmark_format=json > "$TMP/ours.json" 2>/dev/null
(cd "$PEERS" && "$PY" livewire_opencv.py "$IMG" --repeat 9) > "$TMP/opencv.json"

"$PY" - "$TMP/ours.json" "$TMP/opencv.json" <<'PYEOF'
import json, sys
ours = {b["name"]: b for b in json.load(open(sys.argv[1]))["benchmarks"]}
cv = json.loads(open(sys.argv[2]).read().strip().splitlines()[-1])
def med(name):
    b = ours[f"{name}/real_time_median"]
    assert b["time_unit"] == "ms"
    return b
feat, fmap, moves = med("BM_FeaturesAndCosts")["real_time"], med("BM_FullMap")["real_time"], med("BM_CursorMoves")
zc = cv["timings"]["zero_crossing"]
cv_apply, cv_map = zc["applyImage"]["median_s"] * 1e3, zc["buildMap"]["median_s"] * 1e3
print(f"image {cv['input']} {cv['shape'][1]}x{cv['shape'][0]}, seed {cv['seed_xy']}, OpenCV {cv['version']} (zero-crossing mode, {cv['cv_threads']} threads)")
print(f"features+costs   ours {feat:8.2f} ms   OpenCV applyImage {cv_apply:8.2f} ms   RATIO {cv_apply / feat:5.2f}")
print(f"full map         ours {fmap:8.2f} ms   OpenCV buildMap   {cv_map:8.2f} ms   RATIO {cv_map / fmap:5.2f}  (goal >= 3)")
print(f"cursor move      ours median {moves['move_median_ms']:.4f} ms, p95 {moves['move_p95_ms']:.3f} ms, max {moves['move_max_ms']:.2f} ms "
      f"over {int(moves['moves'])} moves from a fresh seed (goal: median < 2 ms)")
print(f"click (new seed) + all {int(moves['moves'])} moves: ours {moves['real_time']:.2f} ms vs OpenCV buildMap alone {cv_map:.2f} ms   RATIO {cv_map / moves['real_time']:5.2f}")
PYEOF
