#!/usr/bin/env bash
# Live-wire speed next to OpenCV's IntelligentScissorsMB (peer) on the same 512x512 image,
# in the same run: features/costs vs applyImage, full single-source map vs buildMap, and our
# cursor-move (resumed search) median. Prints wall and process-CPU times and RATIO lines
# (> 1: we are faster), one block per round (ours and OpenCV alternate; the machine is shared).
#   [ROUNDS=2] bench/livewire_vs_opencv.sh [BUILD_DIR]   (default build; needs target bench_livewire)
# Needs /usr/bin/python3 with numpy, scipy, scikit-image, opencv, nibabel (Debian packages
# python3-numpy python3-scipy python3-skimage python3-opencv python3-nibabel).
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${1:-build}
case "$BUILD" in /*) ;; *) BUILD="$ROOT/$BUILD" ;; esac
PEERS=${VS_PEERS_DIR:-$ROOT/../shared/peers}
PY=/usr/bin/python3
BENCH_BIN=${BENCH_BIN:-$BUILD/bench_livewire}
[ -x "$BENCH_BIN" ] || { echo "missing $BUILD/bench_livewire (cmake --build $BUILD --target bench_livewire)" >&2; exit 1; }
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

# ROUNDS alternating runs (ours, then OpenCV) so both see the same machine load; OpenCV is
# timed here with the peer's settings (livewire_opencv.py: weights 0.43/0.43/0.14, gradient
# max 150, zero-crossing mode) for both wall (perf_counter) and process CPU time.
ROUNDS=${ROUNDS:-2}
for r in $(seq 1 "$ROUNDS"); do
  # Features+costs and the searches run as separate processes, so a failing search still
  # leaves the features+costs figures.
  for part in FeaturesAndCosts 'FullMap|CursorMoves'; do
    VS_BENCH_IMAGE="$IMG" VS_BENCH_SEED="$SEED" VS_BENCH_TARGETS="$TARGETS" \
      "$BENCH_BIN" --benchmark_repetitions=5 --benchmark_report_aggregates_only=true \
      --benchmark_filter="$part" --benchmark_format=json > "$TMP/ours$r-${part%%|*}.json" 2>/dev/null ||
      echo "bench_livewire --benchmark_filter='$part' failed (exit $?)" >&2
  done
  "$PY" - "$IMG" "$SEED" > "$TMP/opencv$r.json" <<'PYEOF'
import json, statistics, sys, time
import cv2
img = cv2.imread(sys.argv[1], cv2.IMREAD_GRAYSCALE)
seed = tuple(int(x) for x in sys.argv[2].split(","))
tool = cv2.segmentation.IntelligentScissorsMB()
tool.setWeights(0.43, 0.43, 0.14)
tool.setGradientMagnitudeMaxLimit(150.0)
tool.setEdgeFeatureZeroCrossingParameters(2.0)
def bench(fn, repeat=9):
    fn()
    wall, cpu = [], []
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.process_time()
        fn()
        cpu.append(time.process_time() - c0)
        wall.append(time.perf_counter() - w0)
    return {"wall_ms": statistics.median(wall) * 1e3, "cpu_ms": statistics.median(cpu) * 1e3}
out = {"version": cv2.__version__, "threads": cv2.getNumThreads(), "shape": list(img.shape),
       "applyImage": bench(lambda: tool.applyImage(img))}
out["buildMap"] = bench(lambda: tool.buildMap(seed))
print(json.dumps(out))
PYEOF
done

"$PY" - "$TMP" "$ROUNDS" "$IMG" "$SEED" <<'PYEOF'
import json, sys
tmp, rounds, img, seed = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
for r in range(1, rounds + 1):
    ours = {}
    for part in ("FeaturesAndCosts", "FullMap"):
        try:
            ours.update({b["name"]: b for b in json.load(open(f"{tmp}/ours{r}-{part}.json"))["benchmarks"]})
        except (OSError, ValueError, KeyError):
            pass
    cv = json.load(open(f"{tmp}/opencv{r}.json"))
    def med(name):
        for key in (f"{name}/process_time/real_time_median", f"{name}/real_time_median"):
            if key in ours:
                assert ours[key]["time_unit"] == "ms"
                return ours[key]
        return None
    feat, fmap, moves = med("BM_FeaturesAndCosts"), med("BM_FullMap"), med("BM_CursorMoves")
    a, m = cv["applyImage"], cv["buildMap"]
    if r == 1:
        print(f"image {img} {cv['shape'][1]}x{cv['shape'][0]}, seed {seed}, OpenCV {cv['version']} "
              f"(zero-crossing mode, {cv['threads']} threads); medians, wall / process CPU")
    print(f"round {r}:")
    if feat is None:
        print("  features+costs  ours: no result (bench_livewire failed)")
    else:
      print(f"  features+costs  ours {feat['real_time']:7.2f} / {feat['cpu_time']:7.2f} ms   OpenCV applyImage "
          f"{a['wall_ms']:7.2f} / {a['cpu_ms']:7.2f} ms   RATIO wall {a['wall_ms'] / feat['real_time']:5.2f}  cpu {a['cpu_ms'] / feat['cpu_time']:5.2f}  (goal >= 1)")
    if fmap is None or moves is None:
        print("  full map / cursor moves: no result (bench_livewire failed)")
        continue
    print(f"  full map        ours {fmap['real_time']:7.2f} / {fmap['cpu_time']:7.2f} ms   OpenCV buildMap   "
          f"{m['wall_ms']:7.2f} / {m['cpu_ms']:7.2f} ms   RATIO wall {m['wall_ms'] / fmap['real_time']:5.2f}  cpu {m['cpu_ms'] / fmap['cpu_time']:5.2f}  (goal >= 3)")
    print(f"  cursor move     ours median {moves['move_median_ms']:.4f} ms, p95 {moves['move_p95_ms']:.3f} ms, max {moves['move_max_ms']:.2f} ms "
          f"over {int(moves['moves'])} moves from a fresh seed (goal: median < 2 ms)")
    print(f"  click + all {int(moves['moves'])} moves: ours {moves['real_time']:.2f} ms vs OpenCV buildMap alone {m['wall_ms']:.2f} ms   RATIO {m['wall_ms'] / moves['real_time']:5.2f}")
PYEOF
