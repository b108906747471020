// Speed of the shortest-path engine (issue 3). Single-threaded by design (Dijkstra is
// sequential): every figure below is one core.
//
//   bench_engine [google-benchmark flags]
//     Full single-source map on a 512x512 8-connected image; point-to-point queries (Dijkstra
//     early stop vs A*); settled nodes per second on a 256^3 26-connected grid with the default
//     bucket queue vs the radix heap and the binary-heap reference in the same run (prints RATIO
//     lines, CPU time); full single-source maps
//     on 128x64x64, 128^3 and 256^3 with node costs. Inputs are synthetic vessel-like cost
//     volumes made here (the peers' cost formula on a noisy background with bright tubes);
//     setup is outside the timed region.
//
//   bench_engine --synthetic NX NY NZ     one full 26-connected map, time and peak RSS per voxel
//   bench_engine --npy COST.npy --sidecar META.json [--repeat N] [--warmup N] [--queue bucket|radix|heap]
//                [--key-resolution Q] [--full-only 1] [--map-hash 1]
//     Peer mode for bench/engine_vs_peers.sh: reads a float32 C-order .npy node-cost volume
//     (numpy [i,j,k] = our (x=k, y=j, z=i)), runs the full 26-connected (8 in 2D) single-source
//     map from the sidecar's root, and prints one JSON line in the peers' format (median of
//     N timed runs after warm-up, file loading excluded) with the terminals' costs and peak RSS,
//     plus point-to-point findPath timings (root -> each terminal; root -> the node 100 voxels
//     along the first terminal's path, Dijkstra and A*).
#include <benchmark/benchmark.h>
#include <sys/resource.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "graph/shortest_path.h"
#include "util/parallel.h"

namespace {

// ---------- synthetic inputs ----------

// Vessel-like node costs: f = 1e-3 + (1 - I/255)^4 with I = 30 + N(0,10) background and a few
// bright (I ~ 200) tubes of radius 1-4 voxels, like the peers' phantom.
std::vector<float> vesselCosts(const std::array<int64_t, 3>& d, uint32_t seed = 1234) {
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0.f, 10.f);
  const int64_t n = d[0] * d[1] * d[2];
  std::vector<float> I(static_cast<size_t>(n));
  for (auto& v : I) v = 30.f + noise(rng);
  std::uniform_real_distribution<double> u(0.1, 0.9);
  const bool twoD = d[2] == 1;
  for (int t = 0; t < 12; ++t) {
    const double ax = u(rng) * d[0], ay = u(rng) * d[1], az = twoD ? 0 : u(rng) * d[2];
    const double bx = u(rng) * d[0], by = u(rng) * d[1], bz = twoD ? 0 : u(rng) * d[2];
    const double r = 1 + 3 * (t % 4) / 3.0;
    const int steps = int(4 * std::hypot(bx - ax, by - ay, bz - az)) + 1;
    for (int s = 0; s <= steps; ++s) {
      const double f = double(s) / steps;
      const double cx = ax + f * (bx - ax), cy = ay + f * (by - ay), cz = az + f * (bz - az);
      const int R = int(std::ceil(r));
      for (int dz = twoD ? 0 : -R; dz <= (twoD ? 0 : R); ++dz)
        for (int dy = -R; dy <= R; ++dy)
          for (int dx = -R; dx <= R; ++dx) {
            const int64_t x = int64_t(cx) + dx, y = int64_t(cy) + dy, z = int64_t(cz) + dz;
            if (x < 0 || y < 0 || z < 0 || x >= d[0] || y >= d[1] || z >= d[2]) continue;
            if (dx * dx + dy * dy + dz * dz > r * r) continue;
            I[size_t(x + d[0] * (y + d[1] * z))] = 200.f;
          }
    }
  }
  std::vector<float> c(static_cast<size_t>(n));
  for (int64_t i = 0; i < n; ++i) {
    const float s = std::clamp(I[size_t(i)] / 255.f, 0.f, 1.f);
    c[size_t(i)] = 1e-3f + std::pow(1.f - s, 4.f);
  }
  return c;
}

struct Volume3 {
  vs::GridGraph g;
  std::vector<float> c;
};

const Volume3& input(int64_t nx, int64_t ny, int64_t nz, int conn) {
  static std::map<std::array<int64_t, 4>, Volume3> cache;
  const std::array<int64_t, 4> key{nx, ny, nz, conn};
  auto it = cache.find(key);
  if (it == cache.end()) {
    Volume3 v{vs::GridGraph({nx, ny, nz}, {1, 1, 1}, conn), vesselCosts({nx, ny, nz})};
    it = cache.emplace(key, std::move(v)).first;
  }
  return it->second;
}

std::map<std::string, double> g_rates;  // settled nodes per second, for the printed ratios

// Full single-source map (construction + runToCompletion).
void fullMap(benchmark::State& st, const char* name, int64_t nx, int64_t ny, int64_t nz, int conn, vs::QueueKind q) {
  const Volume3& in = input(nx, ny, nz, conn);
  vs::SearchOptions opt;
  opt.queue = q;
  const int64_t src = in.g.node(nx / 2, ny / 2, nz / 2);
  int64_t settled = 0;
  double secs = 0;
  auto cpuNow = [] {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
  };
  for (auto _ : st) {
    const double t0 = cpuNow();  // CPU time: the ratio must not depend on other load on the machine
    vs::ShortestPathSearch s(in.g, vs::GridCost::nodes(in.c), {src}, opt);
    s.runToCompletion();
    secs += cpuNow() - t0;
    settled += s.settledCount();
    benchmark::DoNotOptimize(s.totalCosts().data());
  }
  st.counters["settled_per_s"] = benchmark::Counter(double(settled), benchmark::Counter::kIsRate);
  st.counters["nodes"] = double(in.g.nodeCount());
  g_rates[name] = double(settled) / secs;
}

void BM_Full2D_512_8conn(benchmark::State& st) {
  fullMap(st, "BM_Full2D_512_8conn", 512, 512, 1, 8, vs::QueueKind::Bucket);
}
void BM_Full2D_512_8conn_heap(benchmark::State& st) {
  fullMap(st, "BM_Full2D_512_8conn_heap", 512, 512, 1, 8, vs::QueueKind::BinaryHeap);
}
void BM_Full3D_128x64x64_26conn(benchmark::State& st) {
  fullMap(st, "BM_Full3D_128x64x64_26conn", 128, 64, 64, 26, vs::QueueKind::Bucket);
}
void BM_Full3D_128_26conn(benchmark::State& st) {
  fullMap(st, "BM_Full3D_128_26conn", 128, 128, 128, 26, vs::QueueKind::Bucket);
}
void BM_Full3D_256_26conn(benchmark::State& st) {
  fullMap(st, "BM_Full3D_256_26conn", 256, 256, 256, 26, vs::QueueKind::Bucket);
}
void BM_Full3D_256_26conn_radix(benchmark::State& st) {
  fullMap(st, "BM_Full3D_256_26conn_radix", 256, 256, 256, 26, vs::QueueKind::Radix);
}
void BM_Full2D_512_8conn_radix(benchmark::State& st) {
  fullMap(st, "BM_Full2D_512_8conn_radix", 512, 512, 1, 8, vs::QueueKind::Radix);
}
void BM_Full3D_128_26conn_radix(benchmark::State& st) {
  fullMap(st, "BM_Full3D_128_26conn_radix", 128, 128, 128, 26, vs::QueueKind::Radix);
}
void BM_Full3D_256_26conn_heap(benchmark::State& st) {
  fullMap(st, "BM_Full3D_256_26conn_heap", 256, 256, 256, 26, vs::QueueKind::BinaryHeap);
}
void BM_Full3D_128_6conn(benchmark::State& st) {
  fullMap(st, "BM_Full3D_128_6conn", 128, 128, 128, 6, vs::QueueKind::Bucket);
}

// Point-to-point queries on the 512x512 image: 16 fixed pairs, Dijkstra with early stop vs A*.
void pointToPoint(benchmark::State& st, bool astar) {
  const Volume3& in = input(512, 512, 1, 8);
  std::mt19937 rng(5);
  std::vector<std::pair<int64_t, int64_t>> pairs;
  for (int i = 0; i < 16; ++i) pairs.push_back({int64_t(rng() % 262144u), int64_t(rng() % 262144u)});
  vs::SearchOptions opt;
  opt.useAStar = astar;
  double total = 0;
  for (auto _ : st)
    for (const auto& [s, t] : pairs) total += vs::findPath(in.g, vs::GridCost::nodes(in.c), s, t, opt).cost;
  benchmark::DoNotOptimize(total);
  st.counters["queries_per_s"] = benchmark::Counter(double(st.iterations() * 16), benchmark::Counter::kIsRate);
}
void BM_PointToPoint2D_512_dijkstra(benchmark::State& st) { pointToPoint(st, false); }
void BM_PointToPoint2D_512_astar(benchmark::State& st) { pointToPoint(st, true); }

// Resumed search: one source, 16 targets one after the other (the tracking pattern).
void BM_Resume3D_128_16targets(benchmark::State& st) {
  const Volume3& in = input(128, 128, 128, 26);
  std::mt19937 rng(8);
  std::vector<int64_t> targets;
  for (int i = 0; i < 16; ++i) targets.push_back(int64_t(rng() % uint32_t(in.g.nodeCount())));
  for (auto _ : st) {
    vs::ShortestPathSearch s(in.g, vs::GridCost::nodes(in.c), {in.g.node(64, 64, 64)});
    for (int64_t t : targets) benchmark::DoNotOptimize(s.pathTo(t).cost);
  }
}

BENCHMARK(BM_Full2D_512_8conn)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Full2D_512_8conn_radix)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Full2D_512_8conn_heap)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointToPoint2D_512_dijkstra)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PointToPoint2D_512_astar)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Full3D_128x64x64_26conn)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Full3D_128_26conn)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Full3D_128_26conn_radix)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Full3D_128_6conn)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Resume3D_128_16targets)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Full3D_256_26conn)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_Full3D_256_26conn_radix)->Unit(benchmark::kMillisecond)->Iterations(2);
BENCHMARK(BM_Full3D_256_26conn_heap)->Unit(benchmark::kMillisecond)->Iterations(1);

// ---------- peer mode ----------

std::vector<float> readNpyFloat32(const std::string& path, std::vector<int64_t>& shape) {
  std::ifstream f(path, std::ios::binary);
  if (!f) throw std::runtime_error("cannot open " + path);
  char magic[6];
  f.read(magic, 6);
  if (std::memcmp(magic, "\x93NUMPY", 6) != 0) throw std::runtime_error(path + ": not a .npy file");
  unsigned char ver[2];
  f.read(reinterpret_cast<char*>(ver), 2);
  uint32_t hlen = 0;
  if (ver[0] == 1) {
    unsigned char b[2];
    f.read(reinterpret_cast<char*>(b), 2);
    hlen = b[0] | (b[1] << 8);
  } else {
    unsigned char b[4];
    f.read(reinterpret_cast<char*>(b), 4);
    hlen = b[0] | (b[1] << 8) | (b[2] << 16) | (uint32_t(b[3]) << 24);
  }
  std::string h(hlen, '\0');
  f.read(h.data(), hlen);
  if (h.find("'descr': '<f4'") == std::string::npos) throw std::runtime_error(path + ": dtype must be <f4: " + h);
  if (h.find("'fortran_order': False") == std::string::npos) throw std::runtime_error(path + ": must be C order");
  const auto a = h.find("'shape': (");
  const auto b = h.find(')', a);
  std::stringstream ss(h.substr(a + 10, b - a - 10));
  std::string item;
  int64_t n = 1;
  shape.clear();
  while (std::getline(ss, item, ','))
    if (item.find_first_not_of(' ') != std::string::npos) {
      shape.push_back(std::stoll(item));
      n *= shape.back();
    }
  std::vector<float> data(static_cast<size_t>(n));
  f.read(reinterpret_cast<char*>(data.data()), std::streamsize(n * 4));
  if (!f) throw std::runtime_error(path + ": truncated");
  return data;
}

// Anonymous memory backed by transparent huge pages right now, in KiB (Linux; -1 elsewhere):
// the search's record array asks for them (madvise), and a run that did not get them is slower.
long anonHugeKiB() {
  std::ifstream f("/proc/self/smaps_rollup");
  std::string line;
  while (std::getline(f, line))
    if (line.rfind("AnonHugePages:", 0) == 0) return std::stol(line.substr(14));
  return -1;
}

// FNV-1a over every node's total (its bits) and state byte (back direction, settled): two
// engine builds give the same map, tree included, exactly when the hashes agree.
std::string fullMapHash(const vs::ShortestPathSearch& s) {
  uint64_t h = 1469598103934665603ull;
  auto mix = [&h](const void* p, size_t n) {
    const auto* b = static_cast<const unsigned char*>(p);
    for (size_t i = 0; i < n; ++i) h = (h ^ b[i]) * 1099511628211ull;
  };
  const auto t = s.totalCosts();
  const auto st = s.nodeState();
  mix(t.data(), t.size() * sizeof(double));
  mix(st.data(), st.size());
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

int peerMode(int argc, char** argv) {
  std::string npy, sidecar, queue = "bucket";
  int repeat = 3, warmup = 1, threads = 0;
  bool fullOnly = false;  // --full-only 1: only the full maps (for perf stat / perf record)
  bool mapHash = false;   // --map-hash 1: a hash of the last full map's totals and states
  double keyRes = 0;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string k = argv[i], v = argv[i + 1];
    if (k == "--npy")
      npy = v;
    else if (k == "--sidecar")
      sidecar = v;
    else if (k == "--repeat")
      repeat = std::stoi(v);
    else if (k == "--warmup")
      warmup = std::stoi(v);
    else if (k == "--queue")
      queue = v;
    else if (k == "--key-resolution")
      keyRes = std::stod(v);
    else if (k == "--threads")
      threads = std::stoi(v);
    else if (k == "--full-only")
      fullOnly = v == "1";
    else if (k == "--map-hash")
      mapHash = v == "1";
    else {
      std::cerr << "unknown option " << k << "\n";
      return 2;
    }
  }
  std::vector<int64_t> shape;
  const std::vector<float> cost = readNpyFloat32(npy, shape);
  nlohmann::json meta;
  std::ifstream(sidecar) >> meta;
  std::array<int64_t, 3> dims{1, 1, 1};
  const bool twoD = shape.size() == 2;
  if (twoD)
    dims = {shape[1], shape[0], 1};
  else
    dims = {shape[2], shape[1], shape[0]};
  auto toNode = [&](const nlohmann::json& p) {
    return twoD ? int64_t(p[1]) + dims[0] * int64_t(p[0])
                : int64_t(p[2]) + dims[0] * (int64_t(p[1]) + dims[1] * int64_t(p[0]));
  };
  vs::GridGraph g(dims, {1, 1, 1}, twoD ? 8 : 26);
  const int64_t root = toNode(meta["root"]);
  std::vector<int64_t> terms;
  for (const auto& t : meta["terminals"]) terms.push_back(toNode(t));
  vs::SearchOptions opt;
  opt.keyResolution = keyRes;
  opt.queue = queue == "heap"    ? vs::QueueKind::BinaryHeap
              : queue == "radix" ? vs::QueueKind::Radix
                                 : vs::QueueKind::Bucket;
  opt.threads = threads;
  std::vector<int> fullThreads;  // per full map: automatic mode decides per map (an idle second core)
  auto cpuNow = [] {             // the whole process: both search threads when the full map runs on two
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
  };
  std::vector<double> times, cpuTimes, termCosts, earlyTimes;
  std::vector<long> hugeKiB;  // per full map, warm-up included
  std::vector<size_t> pathVoxels;
  int64_t settledEarly = 0;
  int64_t mid = -1;  // the node ~100 voxels along the root -> first terminal path
  std::string hash;  // --map-hash
  for (int i = 0; i < warmup + repeat; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    const double c0 = cpuNow();
    vs::ShortestPathSearch s(g, vs::GridCost::nodes(cost), {root}, opt);
    s.runToCompletion();
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    hugeKiB.push_back(anonHugeKiB());
    if (i >= warmup) fullThreads.push_back(s.lastRunThreads());
    if (i >= warmup) {
      times.push_back(dt);
      cpuTimes.push_back(cpuNow() - c0);
    }
    if (mapHash && i + 1 == warmup + repeat) hash = fullMapHash(s);
    termCosts.clear();
    pathVoxels.clear();
    for (int64_t t : terms) {
      termCosts.push_back(s.totalCost(t));
      const vs::Path p = s.settledPath(t);
      pathVoxels.push_back(p.size());
      if (mid < 0 && !p.empty()) mid = p.nodes[std::min<size_t>(99, p.size() - 1)];
    }
  }
  for (int i = 0; i < (fullOnly ? 0 : warmup + repeat); ++i) {  // early exit: stop once all terminals are settled
    const auto t0 = std::chrono::steady_clock::now();
    vs::ShortestPathSearch s(g, vs::GridCost::nodes(cost), {root}, opt);
    s.settleUntilAll(terms);
    const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (i >= warmup) earlyTimes.push_back(dt);
    settledEarly = s.settledCount();
  }
  // Point to point (findPath: validation, init and search, like skimage's route_through_array):
  // root -> each terminal (Dijkstra early stop), and root -> the node ~100 voxels along the
  // first terminal's path (Dijkstra and A*), each repeated.
  std::vector<double> routeTimes, p100Times, p100AstarTimes;
  size_t p100Voxels = 0;
  for (int i = 0; i < (fullOnly ? 0 : warmup + repeat); ++i)
    for (int64_t t : terms) {
      const auto t0 = std::chrono::steady_clock::now();
      vs::SearchOptions dijkstra = opt;
      dijkstra.useAStar = false;
      const vs::Path p = vs::findPath(g, vs::GridCost::nodes(cost), root, t, dijkstra);
      const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (i >= warmup) routeTimes.push_back(dt);
      benchmark::DoNotOptimize(p.cost);
    }
  for (int i = 0; i < 2 + std::max(5, repeat) && mid >= 0 && !fullOnly; ++i)
    for (bool astar : {false, true}) {
      const auto t0 = std::chrono::steady_clock::now();
      vs::SearchOptions query = opt;
      query.useAStar = astar;
      const vs::Path p = vs::findPath(g, vs::GridCost::nodes(cost), root, mid, query);
      const double dt = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      if (i >= 2) (astar ? p100AstarTimes : p100Times).push_back(dt);
      p100Voxels = p.size();
    }
  auto median = [](std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
  };
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  nlohmann::json out;
  out["peer"] = "project";
  out["huge_pages_kib_per_full_map"] = hugeKiB;
  out["version"] = "volscissors graph engine";
  out["task"] = "sssp";
  out["input"] = npy;
  out["shape"] = shape;
  out["nodes"] = g.nodeCount();
  out["connectivity"] = g.connectivity();
  // Of the full maps (automatic mode decides per map); early exits and point to point use 1.
  out["threads"] = fullThreads.empty() ? 1 : *std::max_element(fullThreads.begin(), fullThreads.end());
  out["threads_per_map"] = fullThreads;
  out["queue"] = queue;
  out["timings"]["full_total"] = {
      {"median_s", median(times)}, {"runs_s", times}, {"cpu_median_s", median(cpuTimes)}, {"cpu_runs_s", cpuTimes}};
  out["timings"]["early_exit_all_terminals"] = {
      {"median_s", median(earlyTimes)}, {"runs_s", earlyTimes}, {"settled_nodes", settledEarly}};
  out["timings"]["point_to_point_terminals"] = {{"median_s", median(routeTimes)}, {"runs", routeTimes.size()}};
  out["timings"]["point_to_point_100"] = {
      {"median_s", median(p100Times)}, {"astar_median_s", median(p100AstarTimes)}, {"path_voxels", p100Voxels}};
  out["terminal_costs"] = termCosts;
  if (mapHash) out["full_map_hash"] = hash;
  out["path_voxels"] = pathVoxels;
  out["peak_rss_bytes"] = int64_t(ru.ru_maxrss) * 1024;
  out["peak_rss_bytes_per_voxel"] = double(ru.ru_maxrss) * 1024.0 / double(g.nodeCount());
  std::cout << out.dump() << std::endl;
  return 0;
}

// bench_engine --synthetic NX NY NZ: one full 26-connected map on a synthetic vessel cost volume;
// prints time and peak RSS per voxel (the memory check for 512^3).
int syntheticMode(int argc, char** argv) {
  if (argc < 5) {
    std::cerr << "usage: bench_engine --synthetic NX NY NZ\n";
    return 2;
  }
  const std::array<int64_t, 3> d{std::stoll(argv[2]), std::stoll(argv[3]), std::stoll(argv[4])};
  const std::vector<float> c = vesselCosts(d);
  vs::GridGraph g(d, {1, 1, 1}, 26);
  timespec c0{}, c1{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c0);
  const auto t0 = std::chrono::steady_clock::now();
  vs::ShortestPathSearch s(g, vs::GridCost::nodes(c), {g.node(d[0] / 2, d[1] / 2, d[2] / 2)});
  s.runToCompletion();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c1);
  rusage ru{};
  getrusage(RUSAGE_SELF, &ru);
  std::printf(
      "synthetic %lldx%lldx%lld 26-connected full map: %.2f s wall, %.2f s cpu (1 thread), settled %lld, "
      "peak RSS %.2f GB = %.1f B/voxel (incl. the float cost volume)\n",
      (long long)d[0], (long long)d[1], (long long)d[2], wall,
      double(c1.tv_sec - c0.tv_sec) + 1e-9 * double(c1.tv_nsec - c0.tv_nsec), (long long)s.settledCount(),
      double(ru.ru_maxrss) / 1048576.0, double(ru.ru_maxrss) * 1024.0 / double(g.nodeCount()));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == "--synthetic") return syntheticMode(argc, argv);
  if (argc > 1 && std::string(argv[1]) == "--npy") {
    try {
      return peerMode(argc, argv);
    } catch (const std::exception& e) {
      std::cerr << "bench_engine: " << e.what() << "\n";
      return 1;
    }
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  auto ratio = [](const char* fast, const char* ref) {
    const auto a = g_rates.find(fast), b = g_rates.find(ref);
    if (a != g_rates.end() && b != g_rates.end())
      std::printf("RATIO settled nodes per CPU second %s / %s = %.2f  (%.1f M/s vs %.1f M/s, 1 thread)\n", fast, ref,
                  a->second / b->second, a->second / 1e6, b->second / 1e6);
  };
  ratio("BM_Full3D_256_26conn", "BM_Full3D_256_26conn_heap");
  ratio("BM_Full3D_256_26conn", "BM_Full3D_256_26conn_radix");
  ratio("BM_Full3D_128_26conn", "BM_Full3D_128_26conn_radix");
  ratio("BM_Full2D_512_8conn", "BM_Full2D_512_8conn_heap");
  ratio("BM_Full2D_512_8conn", "BM_Full2D_512_8conn_radix");
  return 0;
}
