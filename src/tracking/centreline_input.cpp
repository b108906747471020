#include <cmath>

#include "features/features3d.h"
#include "features/vesselness.h"
#include "tracking/centreline.h"

// The refinement's input image and the mapping of a search chain onto the refined tree: what the
// trace's front ends call around refineCentreline (centreline.cpp holds the refinement itself).
namespace vs {

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

}  // namespace vs
