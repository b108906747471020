#!/usr/bin/env bash
# `make bench`: every Google Benchmark target, then the side-by-side peer comparisons when
# ../shared/peers and the Debian peer packages (scripts/install-bench-deps.sh) are there.
# Benchmarks print RATIO lines against a reference measured in the same run.
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${1:-build}
for b in bench_engine bench_livewire bench_tracking bench_render; do
  [ -x "$BUILD/$b" ] || continue
  echo "== $b"
  "$BUILD/$b" --benchmark_min_time=0.2
done
# The viewer's interaction latencies (its own table; docs/notes/viewer.md).
if [ -x "$BUILD/bench_viewer" ]; then echo "== bench_viewer"; "$BUILD/bench_viewer"; fi
if [ -d ../shared/peers ] && /usr/bin/python3 -c "import numpy, scipy, skimage" 2>/dev/null; then
  echo "== peers (scikit-image, SciPy, OpenCV, VTK) on the same inputs"
  bench/engine_vs_peers.sh "$BUILD"
  bench/livewire_vs_opencv.sh "$BUILD"
  bench/trace_vs_peers.sh "$BUILD"
  bench/table2.sh "$BUILD"
  if /usr/bin/python3 -c "import vtk" 2>/dev/null && command -v xvfb-run >/dev/null; then
    /usr/bin/python3 bench/render_vs_vtk.py --build "$BUILD" || echo "render_vs_vtk failed"
  fi
else
  echo "(peer comparisons skipped: need ../shared/peers and scripts/install-bench-deps.sh)"
fi
