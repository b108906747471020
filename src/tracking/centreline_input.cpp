#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "features/features3d.h"
#include "features/vesselness.h"
#include "tracking/centreline.h"
#include "tracking/centreline_junctions.h"
#include "util/error.h"

// The refinement's input image and the mapping of a search chain onto the refined tree: what the
// trace's front ends call around refineCentreline (centreline.cpp holds the refinement itself); and two
// of its helpers (centreline_junctions.h), kept here for centreline.cpp's size.
namespace vs {

std::vector<int32_t> ownPathVoxels(const RefinedCentreline& refined, size_t inputCount) {
  const size_t n = refined.points.size();
  std::vector<int32_t> own(n);
  const bool copies = refined.source.size() == n && refined.parent.size() == n && n > inputCount;
  for (size_t i = 0; i < n; ++i) own[i] = copies ? refined.source[i] : static_cast<int32_t>(i);
  if (!copies) return own;
  std::vector<uint8_t> shared(inputCount, 0);
  for (size_t i = inputCount; i < n; ++i) shared[static_cast<size_t>(refined.source[i])] = 1;
  std::vector<int32_t> child(n, -1);  // the only child; -2: several
  for (size_t i = 1; i < n; ++i) {
    int32_t& c = child[static_cast<size_t>(refined.parent[i])];
    c = c == -1 ? static_cast<int32_t>(i) : -2;
  }
  for (size_t i = 0; i < n; ++i) {
    if (!shared[static_cast<size_t>(own[i])]) continue;
    for (int32_t k = child[i]; k >= 0; k = child[static_cast<size_t>(k)])
      if (!shared[static_cast<size_t>(refined.source[static_cast<size_t>(k)])]) {
        own[i] = refined.source[static_cast<size_t>(k)];
        break;
      }
  }
  return own;
}

VolumeF32 refinementIntensity(const VolumeF32& volume, double smoothMm, bool costsGiven, Progress& progress) {
  if (!costsGiven) return smoothMm > 0 ? gaussianSmooth3D(volume, smoothMm, progress) : volume;
  VolumeF32 lumen = volume;
  const float hi = percentileOf(lumen.voxels(), 99.9);
  for (float& v : lumen.voxels())
    if (!std::isfinite(v)) v = hi;
  return smoothMm > 0 ? gaussianSmooth3D(lumen, smoothMm, progress) : lumen;
}

std::vector<int32_t> refinedChain(const RefinedCentreline& refined, const std::vector<int32_t>& inputChain) {
  const size_t m = inputChain.size();
  if (m == 0 || refined.parent.size() != refined.points.size() || refined.source.size() != refined.points.size())
    return inputChain;
  std::vector<int32_t> chain(m);
  int32_t k = inputChain.back();
  for (size_t i = m; i-- > 0;) {
    if (k < 0 || static_cast<size_t>(k) >= refined.parent.size() ||
        refined.source[static_cast<size_t>(k)] != inputChain[i])
      return inputChain;
    chain[i] = k;
    k = refined.parent[static_cast<size_t>(k)];
  }
  return k < 0 ? chain : inputChain;
}

namespace centreline_detail {

// refineCentreline's preconditions (throws InvalidArgument naming the first that fails).
void validateRefineInput(const VolumeF32& vol, const CentrelineTree& tree, const CentrelineOptions& o) {
  const size_t n = tree.points.size();
  VS_REQUIRE(tree.parent.size() == n, "refineCentreline: points and parents differ in size");
  VS_REQUIRE(o.iterations >= 0 && o.rays >= 4 && o.maxRadiusMm > 0 && o.smoothWeight >= 0 && o.smoothWeight < 1 &&
                 o.maxStepMm > 0 && o.maxStepRadii >= 0 && o.growContrast >= 0 && o.sectionContrast >= 0 &&
                 o.settleVoxels >= 0 && o.pointsPerThread >= 1 && o.coarseRounds >= 0 && o.saddleContrast >= 0 &&
                 o.lobeValley >= 0 && o.lobeLongRay >= 0 && o.lobeForkRadii >= 0,
             "refineCentreline: iterations >= 0, rays >= 4, max radius > 0, smooth weight in [0,1), max step > 0, "
             "settle >= 0, points per thread >= 1, coarse rounds >= 0, saddle contrast >= 0, lobe valley, long ray and "
             "fork radii >= 0");
  const Geometry& g = vol.geometry();
  for (size_t i = 0; i < n; ++i) {
    VS_REQUIRE(g.containsContinuous(tree.points[i]), "refineCentreline: point outside the volume");
    VS_REQUIRE(tree.parent[i] < static_cast<int32_t>(i) && (i == 0) == (tree.parent[i] < 0),
               "refineCentreline: parents must precede their children and only point 0 is the root");
  }
}

void smoothSteps(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                 const std::vector<uint8_t>& frozen, double weight, const std::vector<Vec3>& step,
                 std::vector<Vec3>& out) {
  out = step;
  for (size_t i = 1; i < step.size(); ++i) {
    if (children[i].empty() || frozen[i]) continue;  // ends and placed points keep their step, as smoothTree
    Vec3 m = Vec3::Zero();
    int count = 0;
    const auto add = [&](int32_t j) {
      if (j > 0 && !frozen[static_cast<size_t>(j)]) m += step[static_cast<size_t>(j)], ++count;
    };
    add(parent[i]);
    for (int32_t c : children[i]) add(c);
    // Only a step against its neighbours' (zig-zag) is averaged: one they share corrects the whole stretch (e.g.
    // the points that the rounds' smoothing pulled towards a root clicked off the axis) and stays.
    if (count > 0 && step[i].dot(m) < 0) out[i] = (1 - weight) * step[i] + weight * m / count;
  }
}

std::vector<Vec3> smoothFinalStep(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                                  const std::vector<uint8_t>& frozen, double weight, const std::vector<Vec3>& rested,
                                  std::vector<Vec3>& q) {
  // The last step averaged with its neighbours' where it runs against them (apart in an uneven lumen, they zig-zag;
  // session 25 zig1).
  std::vector<Vec3> step(q.size()), smoothed;
  for (size_t k = 0; k < q.size(); ++k) step[k] = q[k] - rested[k];
  smoothSteps(parent, children, frozen, weight, step, smoothed);
  for (size_t k = 0; k < q.size(); ++k) q[k] += smoothed[k] - step[k];  // as before: rested + smoothed, rounded alike
  return q;
}

void balanceFreeForks(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                      const std::vector<uint8_t>& frozen, std::vector<Vec3>& q) {
  for (size_t k = 1; k < q.size(); ++k) {
    if (children[k].size() < 2 || frozen[k] || parent[k] < 0) continue;
    const Vec3& p = q[static_cast<size_t>(parent[k])];
    Vec3 m = Vec3::Zero();
    for (int32_t c : children[k]) m += q[static_cast<size_t>(c)];
    const double nc = static_cast<double>(children[k].size());
    q[k] += 0.5 * (p + m / nc) - (p + m) / (nc + 1);
  }
}

std::vector<uint8_t> nearRootPoints(const CentrelineTree& tree, const std::vector<Vec3>& q, double reachMm) {
  std::vector<uint8_t> near(q.size(), 1);
  std::vector<double> along(q.size(), 0.0);
  for (size_t k = 1; k < q.size(); ++k) {
    const size_t p = static_cast<size_t>(tree.parent[k]);
    along[k] = along[p] + (q[k] - q[p]).norm();
    near[k] = along[k] <= reachMm;
  }
  return near;
}

void finishRefined(const std::vector<Vec3>& q, const Vec3& spacing, std::vector<int32_t>& parent,
                   std::vector<int32_t>& source, RefinedCentreline& out) {
  const double minR = 0.5 * spacing.minCoeff();
  out.points.resize(q.size());
  for (size_t k = 0; k < q.size(); ++k) {
    out.radiiMm[k] = std::max(minR, out.radiiMm[k]);
    out.points[k] = q[k].cwiseQuotient(spacing);
  }
  out.parent = std::move(parent);
  out.source = std::move(source);
}

}  // namespace centreline_detail

}  // namespace vs
