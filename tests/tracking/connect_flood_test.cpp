// The root's connected lumen and structure (connectRootLumen, auto_cost_structure.cpp) against a plain
// reference on a random volume: the connected lumen is the 26-connected region around the root of the voxels whose
// step (of the window's h from L) is within the window's last step, the structure the same up to its own last step,
// its wall the voxels beside it, its deep part its voxels with a cube of radius structureDepth inside it.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "phantom/phantom.h"
#include "tracking/auto_cost.h"

namespace vs {
namespace {

// Blobs of lumen-like values, some joined, some not, in noisy tissue.
VolumeF32 blobs(uint64_t seed) {
  Geometry g;
  g.dims = {40, 34, 30};
  VolumeF32 v(g);
  PhantomRng rng(seed);
  struct Blob {
    double x, y, z, r, value;
  };
  std::vector<Blob> b;
  for (int k = 0; k < 14; ++k)
    b.push_back({rng.uniform(0, 40), rng.uniform(0, 34), rng.uniform(0, 30), rng.uniform(2, 7), rng.uniform(40, 100)});
  b.push_back({20, 17, 15, 5, 100});  // the root's
  for (int64_t z = 0; z < 30; ++z)
    for (int64_t y = 0; y < 34; ++y)
      for (int64_t x = 0; x < 40; ++x) {
        double s = 20;
        for (const Blob& o : b) {
          const double d = std::hypot(x - o.x, y - o.y, z - o.z);
          s = std::max(s, 20 + (o.value - 20) * std::clamp((o.r + 1.5 - d) / 3.0, 0.0, 1.0));
        }
        v(x, y, z) = static_cast<float>(s + rng.normal(0, 6));
      }
  return v;
}

// The voxels 26-connected to the root's 3x3x3 neighbourhood through voxels of step <= stop.
std::vector<uint8_t> region(const VolumeF32& v, const Index3& root, const std::vector<int>& step, int stop) {
  const Geometry& g = v.geometry();
  std::vector<uint8_t> in(static_cast<size_t>(g.voxelCount()), 0);
  std::vector<Index3> front;
  auto visit = [&](int64_t x, int64_t y, int64_t z) {
    if (!g.contains({x, y, z})) return;
    const auto i = static_cast<size_t>(g.linear(x, y, z));
    if (in[i] || step[i] > stop) return;
    in[i] = 1;
    front.push_back({x, y, z});
  };
  for (int64_t dz = -1; dz <= 1; ++dz)
    for (int64_t dy = -1; dy <= 1; ++dy)
      for (int64_t dx = -1; dx <= 1; ++dx) visit(root[0] + dx, root[1] + dy, root[2] + dz);
  while (!front.empty()) {
    const Index3 p = front.back();
    front.pop_back();
    for (int64_t dz = -1; dz <= 1; ++dz)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx) visit(p[0] + dx, p[1] + dy, p[2] + dz);
  }
  return in;
}

TEST(ConnectFlood, TheConnectedLumenAndTheStructureAreTheRegionsWithinTheirSteps) {
  for (const uint64_t seed : {3u, 8u, 21u}) {
    const VolumeF32 v = blobs(seed);
    const Geometry& g = v.geometry();
    const Index3 root{20, 17, 15};
    LumenEstimate e;
    e.polarity = TubePolarity::Bright;
    e.lumen = 100;
    e.spread = 2;
    e.windowLo = 70;
    e.windowHi = 100;
    e.surround = e.shellMedian = 20;
    AutoCostOptions o;
    o.spillShare = 1;  // no spill: the stops are the window's and the structure's own
    RootStructure s;
    const LumenEstimate before = e;
    const std::vector<uint8_t> in = connectRootLumen(v, root, e, o, &s);
    // The steps as the flood counts them.
    const double h = (before.lumen - before.windowLo) / o.connectSteps;
    const int last = static_cast<int>(std::ceil(o.structureFraction * (e.lumen - e.surround) / h - 1e-9));
    ASSERT_GT(last, o.connectSteps);
    std::vector<int> step(static_cast<size_t>(g.voxelCount()));
    for (size_t i = 0; i < step.size(); ++i) {
      const double d = e.lumen - v.data()[i];
      step[i] = d <= 0 ? 0 : static_cast<int>(std::ceil(d / h));
    }
    EXPECT_DOUBLE_EQ(e.windowLo, before.windowLo) << "no spill";
    EXPECT_DOUBLE_EQ(e.structureEdge, e.lumen - last * h);
    const std::vector<uint8_t> window = region(v, root, step, o.connectSteps), structure = region(v, root, step, last);
    ASSERT_EQ(in.size(), window.size());
    int64_t nWindow = 0, nStructure = 0, nWall = 0, nDeep = 0;
    for (size_t i = 0; i < in.size(); ++i) {
      ASSERT_EQ(in[i], window[i]) << "seed " << seed << " voxel " << i;
      ASSERT_EQ(s.mask[i] >= 2, structure[i] == 1) << "seed " << seed << " voxel " << i;
      nWindow += window[i];
      nStructure += structure[i];
    }
    EXPECT_EQ(e.connectedVoxels, nWindow);
    EXPECT_GT(nStructure, nWindow) << "the structure reaches beyond the window (seed " << seed << ")";
    // Its wall (1 voxel): outside it with a 26-neighbour in it; its deep part: a cube of radius 2 inside it.
    for (int64_t z = 0; z < g.dims[2]; ++z)
      for (int64_t y = 0; y < g.dims[1]; ++y)
        for (int64_t x = 0; x < g.dims[0]; ++x) {
          const auto i = static_cast<size_t>(g.linear(x, y, z));
          bool beside = false, deep = structure[i] == 1;
          for (int64_t dz = -2; dz <= 2; ++dz)
            for (int64_t dy = -2; dy <= 2; ++dy)
              for (int64_t dx = -2; dx <= 2; ++dx) {
                if (!g.contains({x + dx, y + dy, z + dz})) continue;
                const bool inIt = structure[static_cast<size_t>(g.linear(x + dx, y + dy, z + dz))] == 1;
                deep = deep && inIt;
                beside = beside || (inIt && std::abs(dx) <= 1 && std::abs(dy) <= 1 && std::abs(dz) <= 1);
              }
          const int want = structure[i] ? (deep ? 3 : 2) : beside ? 1 : 0;
          ASSERT_EQ(s.mask[i], want) << "seed " << seed << " at " << x << "," << y << "," << z;
          nWall += want == 1;
          nDeep += want == 3;
        }
    EXPECT_EQ(e.structureVoxels, nStructure + nWall);
    EXPECT_EQ(static_cast<int64_t>(s.deep.size()), nDeep);
    EXPECT_GT(nDeep, 0);
  }
}

}  // namespace
}  // namespace vs
