// The C++ side of bench/python_overhead.py: the core calls that volscissors.trace and
// LiveWire.build_map make, timed on inputs already in memory (what the Python calls get).
//   BM_Trace:   vs::runTrace with the CLI's defaults on $VS_BENCH_VOLUME (float32), root
//               $VS_BENCH_ROOT "x,y,z", targets $VS_BENCH_TARGETS "x,y,z;x,y,z;...".
//   BM_LiveWireMap: a new seed and the full single-source map on slice z=0 of $VS_BENCH_IMAGE
//               (seeds $VS_BENCH_SEED "u,v" and its right neighbour, alternately).
// Iterations per run: $VS_BENCH_CALLS (default 5). CPU time of the process is reported next to wall time (the shared
// machine's load moves wall time).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "io/volume_io.h"
#include "scissors/live_wire.h"
#include "tracking/trace_run.h"

namespace {

std::vector<std::vector<int64_t>> parseTuples(const char* text) {
  std::vector<std::vector<int64_t>> out;
  std::stringstream all(text ? text : "");
  std::string item;
  while (std::getline(all, item, ';')) {
    std::vector<int64_t> v;
    std::stringstream one(item);
    std::string n;
    while (std::getline(one, n, ',')) v.push_back(std::stoll(n));
    if (!v.empty()) out.push_back(v);
  }
  return out;
}

int64_t calls() {
  const char* c = std::getenv("VS_BENCH_CALLS");
  return c ? std::max<int64_t>(1, std::atoll(c)) : 5;
}

void BM_Trace(benchmark::State& state) {
  const char* path = std::getenv("VS_BENCH_VOLUME");
  if (!path) {
    state.SkipWithError("set VS_BENCH_VOLUME, VS_BENCH_ROOT, VS_BENCH_TARGETS");
    return;
  }
  const vs::VolumeF32 vol = vs::toFloat(vs::readVolume(path));
  vs::TraceRequest rq;
  const auto root = parseTuples(std::getenv("VS_BENCH_ROOT")).at(0);
  rq.root = {root.at(0), root.at(1), root.at(2)};
  for (const auto& t : parseTuples(std::getenv("VS_BENCH_TARGETS"))) rq.targets.push_back({t.at(0), t.at(1), t.at(2)});
  benchmark::DoNotOptimize(vs::runTrace(vol, rq).paths.data());  // warm-up, as the Python side has
  for (auto _ : state) {
    const vs::TraceResult r = vs::runTrace(vol, rq);
    benchmark::DoNotOptimize(r.paths.data());
  }
}
BENCHMARK(BM_Trace)->Iterations(calls())->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

// The live-wire of $VS_BENCH_IMAGE and the two seeds it alternates between; false (and the state
// marked skipped) when the environment does not name them.
struct LiveWireInput {
  std::optional<vs::LiveWire> lw;
  vs::PixelUV seeds[2];
};
bool loadLiveWire(benchmark::State& state, LiveWireInput& in) {
  const char* path = std::getenv("VS_BENCH_IMAGE");
  if (!path) {
    state.SkipWithError("set VS_BENCH_IMAGE and VS_BENCH_SEED");
    return false;
  }
  in.lw.emplace(vs::LiveWire::fromImage(vs::readVolume(path)));
  const auto s = parseTuples(std::getenv("VS_BENCH_SEED")).at(0);
  in.seeds[0] = {s.at(0), s.at(1)};
  in.seeds[1] = {s.at(0) + 1, s.at(1)};
  return true;
}

void BM_LiveWireMap(benchmark::State& state) {
  LiveWireInput in;
  if (!loadLiveWire(state, in)) return;
  vs::LiveWire& lw = *in.lw;
  lw.setSeed(in.seeds[1]);
  lw.buildMap();  // warm-up, as the Python side has
  int i = 0;
  for (auto _ : state) {
    lw.setSeed(in.seeds[i++ % 2]);  // a different seed: the search starts from scratch
    lw.buildMap();
    benchmark::DoNotOptimize(lw.settledCount());
  }
}
// The same, each map on a fresh thread (as a binding call that runs the core off the calling
// thread does): separates the cost of the thread and its cold caches from the binding's own.
void BM_LiveWireMapNewThread(benchmark::State& state) {
  LiveWireInput in;
  if (!loadLiveWire(state, in)) return;
  vs::LiveWire& lw = *in.lw;
  int i = 0;
  for (auto _ : state) {
    std::thread worker([&] {
      lw.setSeed(in.seeds[i++ % 2]);
      lw.buildMap();
    });
    worker.join();
    benchmark::DoNotOptimize(lw.settledCount());
  }
}
BENCHMARK(BM_LiveWireMapNewThread)
    ->Iterations(calls())
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->MeasureProcessCPUTime();

BENCHMARK(BM_LiveWireMap)->Iterations(calls())->Unit(benchmark::kMillisecond)->UseRealTime()->MeasureProcessCPUTime();

}  // namespace

BENCHMARK_MAIN();
