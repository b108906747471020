// Live-wire speed on a 512x512 image (issue 3): features + costs once per slice, the full
// single-source map per click, and cursor moves (resumed search) per mouse event.
// Input: $VS_BENCH_IMAGE (a 2D image, e.g. the peers' shapes_512.png) with $VS_BENCH_SEED "u,v"
// and $VS_BENCH_TARGETS "u,v;u,v;..." (the cursor walks seed -> targets in 2-pixel steps);
// default: the project's shapes2d phantom 512x512, seed and targets on shape 0's boundary.
// bench/livewire_vs_opencv.sh runs this next to OpenCV's IntelligentScissorsMB and prints ratios.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "graph/grid_graph.h"
#include "io/volume_io.h"
#include "phantom/phantom.h"
#include "scissors/live_wire.h"

namespace {

struct Input {
  vs::AnyVolume image;
  vs::PixelUV seed{};
  std::vector<vs::PixelUV> targets;
  std::vector<vs::PixelUV> cursor;  // the mouse trajectory
};

std::vector<vs::PixelUV> parsePts(const std::string& s) {
  std::vector<vs::PixelUV> out;
  std::stringstream all(s);
  std::string item;
  while (std::getline(all, item, ';')) {
    long long u = 0, v = 0;
    char c = 0;
    std::stringstream one(item);
    if (one >> u >> c >> v) out.push_back({u, v});
  }
  return out;
}

const Input& input() {
  static const Input in = [] {
    Input r;
    if (const char* path = std::getenv("VS_BENCH_IMAGE")) {
      r.image = vs::readVolume(path);
      r.seed = parsePts(std::getenv("VS_BENCH_SEED") ? std::getenv("VS_BENCH_SEED") : "0,0").at(0);
      r.targets = parsePts(std::getenv("VS_BENCH_TARGETS") ? std::getenv("VS_BENCH_TARGETS") : "");
    } else {
      vs::Shapes2DOptions o;
      o.width = o.height = 512;
      o.noiseSigma = 12;
      const vs::Shapes2DPhantom ph = vs::makeShapes2DPhantom(o);
      r.image = ph.image;
      const auto& b = ph.truth.shapes.at(0).boundary;
      auto at = [&](double f) {
        const auto& p = b[static_cast<size_t>(f * static_cast<double>(b.size())) % b.size()];
        return vs::PixelUV{std::llround(p.x()), std::llround(p.y())};
      };
      r.seed = at(0);
      r.targets = {at(0.25), at(0.5), at(0.75)};
    }
    vs::PixelUV cur = r.seed;
    for (const auto& t : r.targets) {
      const double d = std::hypot(double(t[0] - cur[0]), double(t[1] - cur[1]));
      const int steps = std::max(1, static_cast<int>(d / 2));
      for (int i = 1; i <= steps; ++i)
        r.cursor.push_back({cur[0] + std::llround(double(t[0] - cur[0]) * i / steps),
                            cur[1] + std::llround(double(t[1] - cur[1]) * i / steps)});
      cur = t;
    }
    return r;
  }();
  return in;
}

void BM_FeaturesAndCosts(benchmark::State& state) {
  const Input& in = input();
  for (auto _ : state) {
    vs::LiveWire lw = vs::LiveWire::fromImage(in.image);
    benchmark::DoNotOptimize(lw.edgeCosts().data());
  }
  state.SetLabel(vs::geometryOf(in.image).describe());
}
BENCHMARK(BM_FeaturesAndCosts)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

// The two parts of the above separately: features only, and costs from given features.
void BM_FeaturesOnly(benchmark::State& state) {
  const Input& in = input();
  for (auto _ : state) {
    const vs::Features2D f = vs::computeFeatures2D(in.image);
    benchmark::DoNotOptimize(f.zeroCrossing.data());
  }
}
BENCHMARK(BM_FeaturesOnly)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

void BM_CostsOnly(benchmark::State& state) {
  const Input& in = input();
  const vs::Features2D f = vs::computeFeatures2D(in.image);
  const vs::GridGraph g({f.width, f.height, 1}, {f.spacingU, f.spacingV, 1.0}, 8);
  std::vector<std::array<int, 2>> steps;
  for (int k = 0; k < g.directionCount(); ++k) steps.push_back({g.offset(k)[0], g.offset(k)[1]});
  for (auto _ : state) {
    const std::vector<float> c = vs::liveWireEdgeCosts(f, {}, steps);
    benchmark::DoNotOptimize(c.data());
  }
}
BENCHMARK(BM_CostsOnly)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

void BM_FullMap(benchmark::State& state) {
  const Input& in = input();
  vs::LiveWire lw = vs::LiveWire::fromImage(in.image);
  const vs::PixelUV seeds[2] = {in.seed, {in.seed[0] + 1, in.seed[1]}};
  int i = 0;
  for (auto _ : state) {
    lw.setSeed(seeds[i++ % 2]);  // a different seed: the search restarts from scratch
    lw.buildMap();
    benchmark::DoNotOptimize(lw.settledCount());
  }
  state.counters["nodes"] = static_cast<double>(lw.settledCount());
}
BENCHMARK(BM_FullMap)->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

// One iteration = a new seed, then every cursor position of the trajectory (the search grows
// as the cursor moves away and is resumed, never restarted). Counters: per-move median/p95/max.
void BM_CursorMoves(benchmark::State& state) {
  const Input& in = input();
  vs::LiveWire lw = vs::LiveWire::fromImage(in.image);
  std::vector<double> ms;
  const vs::PixelUV seeds[2] = {in.seed, {in.seed[0] + 1, in.seed[1]}};
  int it = 0;
  for (auto _ : state) {
    lw.setSeed(seeds[it++ % 2]);
    for (const auto& p : in.cursor) {
      const auto t0 = std::chrono::steady_clock::now();
      benchmark::DoNotOptimize(lw.pathTo(p).size());
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    }
  }
  std::sort(ms.begin(), ms.end());
  state.counters["moves"] = static_cast<double>(in.cursor.size());
  state.counters["move_median_ms"] = ms[ms.size() / 2];
  state.counters["move_p95_ms"] = ms[ms.size() * 95 / 100];
  state.counters["move_max_ms"] = ms.back();
}
BENCHMARK(BM_CursorMoves)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
