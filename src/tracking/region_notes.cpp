#include "tracking/region_notes.h"

#include <algorithm>
#include <cstdio>

namespace vs {

// The terminal scan's region for the note: its size and depth, and a warning when it has leaked.
std::string describeRegion(const Geometry& g, size_t regionVoxels, const std::vector<float>& depth) {
  float deepest = 0;
  for (float d : depth) deepest = std::max(deepest, d);
  char buf[256];
  std::snprintf(buf, sizeof buf, "lumen region %zu voxels (%.1f ml) connected to the root, deepest %.1f mm",
                regionVoxels, static_cast<double>(regionVoxels) * g.spacing.prod() / 1000.0,
                static_cast<double>(deepest));
  std::string text = buf;
  // A vessel or airway tree fills a few percent of a scan (0.4-2.2 % on the shared volumes); a
  // region of a fifth or more has leaked into tissue of the lumen's values (non-contrast CT's
  // pulmonary vessels into the mediastinum and body wall): say so rather than return its far ends
  // as branch ends without a word.
  const double share = static_cast<double>(regionVoxels) / static_cast<double>(g.voxelCount());
  if (share >= kLeakedRegionShare) {
    std::snprintf(buf, sizeof buf,
                  "; warning: it fills %.0f %% of the volume, more than a vessel or airway tree does: the terminals "
                  "may lie outside the tree (give targets, or choose a cost and window)",
                  100.0 * share);
    text += buf;
  }
  return text;
}

// What the region's continuation along dim branches and its fronts' spills changed, for the note.
std::string describeRegionChanges(const Geometry& g, const RegionChanges& r) {
  std::string text;
  if (r.continuedVoxels > 0) {
    char buf[200];
    std::snprintf(buf, sizeof buf, "; continued along %d dim branch piece(s) below the lumen level (%zu voxels)",
                  r.continuedPieces, r.continuedVoxels);
    text += buf;
  } else if (r.continuationAsked) {  // the option asked for found nothing: said, not silent
    text += "; no dim branch continued below the lumen level (none stays a compact tube for the branch length)";
  }
  if (r.spilledVoxels > 0) {
    char buf[300];
    std::snprintf(buf, sizeof buf,
                  "; %zu voxels (%.1f ml) left out where its fronts stopped being a tube's cross-section (the first "
                  "at (%lld,%lld,%lld), %.0f mm from the root)",
                  r.spilledVoxels, static_cast<double>(r.spilledVoxels) * g.spacing.prod() / 1000.0,
                  static_cast<long long>(r.spillAt[0]), static_cast<long long>(r.spillAt[1]),
                  static_cast<long long>(r.spillAt[2]), r.spillMm);
    text += buf;
  }
  return text;
}

}  // namespace vs
