// The box searches of the path re-searches (crossing_retrace.h, neck_retrace.h): a box of the volume
// round the stretch searched again, and Dijkstra inside it with voxels blocked.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "cost/cost3d.h"

namespace vs::retrace {

inline Vec3 mmOf(const Geometry& g, const Index3& v) {
  return Vec3(double(v[0]) * g.spacing[0], double(v[1]) * g.spacing[1], double(v[2]) * g.spacing[2]);
}

// The chain's voxels lo..hi (hi clamped to its end) in mm.
inline std::vector<Vec3> mmOfChain(const Geometry& g, const std::vector<Index3>& chain, size_t lo, size_t hi) {
  std::vector<Vec3> out;
  for (size_t j = lo; j <= hi && j < chain.size(); ++j) out.push_back(mmOf(g, chain[j]));
  return out;
}

// A box of the volume (the original path's, with a margin) and the search inside it.
struct Box {
  Index3 lo{0, 0, 0}, n{0, 0, 0};
  int64_t size() const { return n[0] * n[1] * n[2]; }
  bool in(const Index3& v) const {
    for (size_t a = 0; a < 3; ++a)
      if (v[a] < lo[a] || v[a] >= lo[a] + n[a]) return false;
    return true;
  }
  int64_t index(const Index3& v) const { return (v[0] - lo[0]) + n[0] * ((v[1] - lo[1]) + n[1] * (v[2] - lo[2])); }
  Index3 voxel(int64_t i) const { return {lo[0] + i % n[0], lo[1] + (i / n[0]) % n[1], lo[2] + i / (n[0] * n[1])}; }
};

struct Step {
  Index3 d;
  double lengthMm;
};

std::vector<Step> stepsFor(const Geometry& g, int connectivity);

// The box round path[lo..hi] with a margin of `margin` smallest spacings, cut to the volume.
Box boxAround(const Geometry& g, const std::vector<Index3>& path, size_t lo, size_t hi, double margin = 12);

// The largest distance (mm) from a voxel of `route` to the nearest voxel of `old`.
double farthestFrom(const Geometry& g, const std::vector<Index3>& route, const std::vector<Index3>& old);

// full's points lo..hi (inclusive).
std::vector<Index3> stretch(const std::vector<Index3>& full, size_t lo, size_t hi);

// full with its points lo..hi replaced by `part`.
std::vector<Index3> spliced(const std::vector<Index3>& full, size_t lo, size_t hi, const std::vector<Index3>& part);

// A re-search's result taking its new route: the path becomes `voxels`, its cost the old one with
// the replaced part's cost `oldPart` swapped for the new part's `newPart`.
template <class Result>
Result accepted(Result r, double oldPart, double newPart, std::vector<Index3> voxels) {
  r.changed = true;
  r.newCost = r.oldCost - oldPart + newPart;
  r.voxels = std::move(voxels);
  return r;
}

// The physical length of a voxel chain (mm).
double chainLength(const Geometry& g, const std::vector<Index3>& path);

// What a box search did (session 39 cache702; tests and timing): voxels settled, step costs read, heap entries.
struct BoxSearchStats {
  int64_t settled = 0, costsRead = 0, entries = 0;
};

// Dijkstra from `from` to `to` inside the box, blocked voxels never entered; empty when the target
// is not reached at a cost <= cap. Voxels are settled in (distance, box index) order, each once.
std::vector<Index3> boxPath(const NodeCost3D& cost, const Box& b, const std::vector<uint8_t>& blocked,
                            const std::vector<Step>& steps, const Index3& from, const Index3& to, double cap,
                            double* outCost, BoxSearchStats* stats = nullptr);

// The smoothed intensity at v, signed so that the lumen is bright (sign -1: a dark lumen).
double signedAt(const VolumeF32& sm, const Index3& v, double sign);

// The background round voxel v: the median of the signed smoothed intensity `radiusMm` away along
// the 26 directions (samples outside the volume left out; NaN where none is inside).
double shellMedian(const VolumeF32& sm, const Index3& v, double radiusMm, double sign);

// The widest route's bottleneck in the box from `from` to `to`: the highest level at which they are
// joined by voxels at or above it (a maximin search; blocked voxels never entered).
double bottleneck(const VolumeF32& sm, double sign, const Box& b, const std::vector<Step>& steps, const Index3& from,
                  const Index3& to, const std::vector<uint8_t>& blocked);

}  // namespace vs::retrace
