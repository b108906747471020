#include "measure_summary.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "command.h"

namespace vs::cli {

namespace {
std::string fmt(double v, const char* f = "%.2f") {
  if (!std::isfinite(v)) return "-";
  char b[32];
  std::snprintf(b, sizeof b, f, v);
  return b;
}
}  // namespace

void printMeasurement(const TreeMeasurement& m, double seconds) {
  int leaves = 0, meets = 0, none = 0;
  for (const auto& cs : m.sections) {
    leaves += (cs.flags & kSectionLeavesVolume) != 0;
    meets += (cs.flags & kSectionMeetsBranch) != 0;
    none += (cs.flags & kSectionNoBoundary) != 0;
  }
  std::printf(
      "measure: %s lumen, %zu cross-sections, %d measured (flagged: %d meet a branch, %d leave the volume, "
      "%d no boundary), %zu segments, %zu branch points, %.3f s\n",
      lumenPolarityName(m.polarity).c_str(), m.sections.size(), m.measuredSections(), meets, leaves, none,
      m.segments.size(), m.branchPoints.size(), seconds);
  if (4 * m.measuredSections() < static_cast<int>(m.sections.size()))
    warn("fewer than a quarter of the cross-sections could be measured: is this the volume the tree was traced in?");
  if (m.mergedBranches > 0)
    std::printf(
        "measure: %d pair(s) of branches ran inside one lumen from their branch point: merged until they part\n",
        m.mergedBranches);
  std::printf("%-5s %8s %9s %9s %9s %9s %9s %7s\n", "path", "segments", "length_mm", "mean_d_mm", "min_d_mm", "at_mm",
              "stenosis", "DM");
  for (size_t i = 0; i < m.paths.size(); ++i) {
    const PathMeasure& p = m.paths[i];
    std::printf("%-5zu %8zu %9.2f %9s %9s %9s %9s %7s\n", i, p.segments.size(), p.lengthMm,
                fmt(p.meanDiameterMm).c_str(), fmt(p.minDiameterMm).c_str(), fmt(p.minArcMm, "%.1f").c_str(),
                std::isfinite(p.stenosis) ? (fmt(100 * p.stenosis, "%.0f") + "%").c_str() : "-",
                fmt(p.distanceMetric, "%.3f").c_str());
  }
}

}  // namespace vs::cli
