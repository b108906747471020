// Tracking benchmarks (thesis 4.3.2, Table 2). Not tests: timings only.
//  * Point-to-point on a 256^3 cost volume, ~100-voxel paths along the vessels: A* vs plain
//    Dijkstra early exit (graph/shortest_path.h findPath), median over pairs and repetitions.
//  * One root, 16 terminals, one resumed search (VesselTracker) vs 16 independent searches.
//  * Pruned IsoRegion graph build on a 128x64x64 phantom.
//  * Issue 12: a tree of 10 paths (root to the first 10 terminals) searched by a fresh tracker,
//    and the sub-voxel refinement of that tree (centreline.h), in one process: the search's
//    state pages are recycled between iterations here, i.e. this is the search at its fastest.
// Input: VS_BENCH_COST = a *_cost.nii.gz of the peers (make_volumes.py) and VS_BENCH_TARGETS =
// its JSON sidecar (root, terminals); without them a 256^3 vessel phantom with the peers' cost
// formula (1e-3 + (1 - I/255)^4) is generated in memory.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>

#include "cost/cost3d.h"
#include "graph/shortest_path.h"
#include "io/volume_io.h"
#include "phantom/phantom.h"
#include "tracking/centreline.h"
#include "tracking/pruned_graph.h"
#include "tracking/tracker.h"

namespace {

struct Data {
  vs::VolumeF32 volume;
  vs::NodeCost3D cost;
  vs::Index3 root{0, 0, 0};
  std::vector<vs::Index3> terminals;
  std::vector<std::pair<int64_t, int64_t>> pairs;  // ~100-voxel point-to-point queries
};

const Data& data() {
  static std::unique_ptr<Data> instance = [] {
    auto d = std::make_unique<Data>();
    const char* costPath = std::getenv("VS_BENCH_COST");
    const char* targetsPath = std::getenv("VS_BENCH_TARGETS");
    vs::Cost3DOptions co;
    if (costPath && targetsPath) {
      d->volume = vs::toFloat(vs::readVolume(costPath));
      co.kind = vs::CostKind3D::Given;
      std::ifstream f(targetsPath);
      const nlohmann::json j = nlohmann::json::parse(f);
      auto idx = [](const nlohmann::json& p) {
        return vs::Index3{p[0].get<int64_t>(), p[1].get<int64_t>(), p[2].get<int64_t>()};
      };
      d->root = idx(j["root"]);
      for (const auto& t : j["terminals"]) d->terminals.push_back(idx(t));
    } else {
      vs::VesselPhantomOptions o;
      o.dims = {256, 256, 256};
      o.minTerminals = o.maxTerminals = 16;
      const vs::VesselPhantom ph = vs::makeVesselPhantom(o);
      d->volume = vs::toFloat(vs::AnyVolume(ph.volume));
      d->root = ph.truth.rootVoxel;
      d->terminals = ph.truth.terminalVoxels;
      co.kind = vs::CostKind3D::Intensity;
      co.windowLo = 0, co.windowHi = 255;
    }
    d->cost = vs::computeNodeCost3D(d->volume, co);
    const vs::Geometry& g = d->volume.geometry();
    const vs::GridGraph grid(g.dims, {g.spacing[0], g.spacing[1], g.spacing[2]}, 26);
    const vs::GridCost gc = d->cost.gridCost();
    vs::ShortestPathSearch s(grid, gc, {g.linear(d->root[0], d->root[1], d->root[2])});
    for (const auto& t : d->terminals) {
      const vs::Path p = s.pathTo(g.linear(t[0], t[1], t[2]));
      if (p.size() >= 110) d->pairs.push_back({p.nodes[5], p.nodes[104]});
    }
    return d;
  }();
  return *instance;
}

void pointToPoint(benchmark::State& state, bool astar) {
  const Data& d = data();
  const vs::Geometry& g = d.volume.geometry();
  const vs::GridGraph grid(g.dims, {g.spacing[0], g.spacing[1], g.spacing[2]}, 26);
  const vs::GridCost gc = d.cost.gridCost();
  vs::SearchOptions opt;
  opt.useAStar = astar;
  size_t i = 0;
  for (auto _ : state) {
    const auto& pr = d.pairs[i++ % d.pairs.size()];
    const vs::Path p = vs::findPath(grid, gc, pr.first, pr.second, opt);
    benchmark::DoNotOptimize(p.cost);
  }
  state.counters["pairs"] = static_cast<double>(d.pairs.size());
}
void BM_PointToPoint256_AStar(benchmark::State& s) { pointToPoint(s, true); }
void BM_PointToPoint256_Dijkstra(benchmark::State& s) { pointToPoint(s, false); }

void BM_Tracker16Terminals_Resumed(benchmark::State& state) {
  const Data& d = data();
  for (auto _ : state) {
    vs::VesselTracker tr(d.volume, d.cost, d.root);
    for (const auto& t : d.terminals) benchmark::DoNotOptimize(tr.addTarget(t).cost);
  }
}

void BM_Tracker16Terminals_Restarted(benchmark::State& state) {
  const Data& d = data();
  for (auto _ : state)
    for (const auto& t : d.terminals) {
      vs::VesselTracker tr(d.volume, d.cost, d.root);
      benchmark::DoNotOptimize(tr.addTarget(t).cost);
    }
}

constexpr size_t kTreePaths = 10;

void BM_Tracker10Paths_Search(benchmark::State& state) {
  const Data& d = data();
  for (auto _ : state) {
    vs::VesselTracker tr(d.volume, d.cost, d.root);
    for (size_t i = 0; i < std::min(kTreePaths, d.terminals.size()); ++i)
      benchmark::DoNotOptimize(tr.addTarget(d.terminals[i]).cost);
  }
}

void BM_Tracker10Paths_Refine(benchmark::State& state) {
  const Data& d = data();
  vs::VesselTracker tr(d.volume, d.cost, d.root);
  for (size_t i = 0; i < std::min(kTreePaths, d.terminals.size()); ++i) tr.addTarget(d.terminals[i]);
  const vs::CentrelineTree tree = tr.centrelineTree();
  for (auto _ : state) benchmark::DoNotOptimize(vs::refineCentreline(d.volume, tree).points.data());
  state.counters["points"] = static_cast<double>(tree.points.size());
}

void BM_PrunedGraphBuild_128x64x64(benchmark::State& state) {
  vs::VesselPhantomOptions o;
  o.dims = {128, 64, 64};
  o.minTerminals = 4, o.maxTerminals = 8;
  const vs::VesselPhantom ph = vs::makeVesselPhantom(o);
  const vs::VolumeF32 v = vs::toFloat(vs::AnyVolume(ph.volume));
  const vs::NodeCost3D cost = vs::computeNodeCost3D(v, vs::Cost3DOptions{});
  vs::IsoRegionOptions io;
  io.field = vs::IsoRegionField::Intensity;  // the thesis's literal rule: threshold on intensities
  io.threshold = 100;
  int64_t nodes = 0, edges = 0;
  for (auto _ : state) {
    const vs::PrunedGraph pg = vs::buildPrunedGraph(v, cost, 26, io);
    nodes = pg.nodes, edges = pg.edges;
  }
  state.counters["nodes"] = static_cast<double>(nodes);
  state.counters["edges"] = static_cast<double>(edges);
}

}  // namespace

BENCHMARK(BM_PointToPoint256_AStar)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(BM_PointToPoint256_Dijkstra)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(BM_Tracker16Terminals_Resumed)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Tracker16Terminals_Restarted)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_Tracker10Paths_Search)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(BM_Tracker10Paths_Refine)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(BM_PrunedGraphBuild_128x64x64)->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK_MAIN();
