#include "app/profile.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "app/viewer_app.h"
#include "util/error.h"

namespace vs::viewer {

void ProfileView::measure(const VolumeF32& volume, const Tree& tree) {
  TreeMeasurement m = measureTree(volume, tree);
  if (m.paths.empty()) throw DataError("measure: the tree has no path from its root to a tip");
  m_ = std::move(m);
  input_ = tree;
  has_ = true;
  coloured_ = false;
  try {
    pieces_ = vs::colourByDiameter(treeWithMeasuredRadii(m_, /*flaggedAsNaN=*/true).toPolylines());
    coloured_ = true;
  } catch (const InvalidArgument&) {  // no section measured: nothing to colour by
    pieces_ = ColouredPieces{};
  }
  path_ = 0;
  section_ = -1;
}

void ProfileView::clear() {
  has_ = false;
  m_ = TreeMeasurement{};
  input_ = Tree{};
  pieces_ = ColouredPieces{};
  coloured_ = false;
  path_ = 0;
  section_ = -1;
}

bool ProfileView::measuredFrom(const Tree& tree) const {
  return has_ && tree.points == input_.points && tree.parent == input_.parent && tree.radii == input_.radii;
}

void ProfileView::selectPath(int path) {
  if (!has_) throw InvalidArgument("no measured tree: run `measure` after the trace");
  if (path < 0 || path >= static_cast<int>(m_.paths.size()))
    throw InvalidArgument("path " + std::to_string(path) + " outside 0.." + std::to_string(m_.paths.size() - 1));
  if (path != path_) section_ = -1;
  path_ = path;
}

void ProfileView::selectSection(int profileIndex) {
  if (!has_) throw InvalidArgument("no measured tree: run `measure` after the trace");
  const auto& p = m_.paths[static_cast<size_t>(path_)];
  if (profileIndex < -1 || profileIndex >= static_cast<int>(p.sections.size()))
    throw InvalidArgument("section " + std::to_string(profileIndex) + " outside the profile");
  section_ = profileIndex;
}

void ProfileView::selectArc(double arcMm) {
  if (!has_) throw InvalidArgument("no measured tree: run `measure` after the trace");
  if (!std::isfinite(arcMm)) throw InvalidArgument("arc length must be a number of mm");
  const auto& arc = m_.paths[static_cast<size_t>(path_)].arcMm;
  int best = -1;
  for (size_t k = 0; k < arc.size(); ++k)
    if (best < 0 || std::abs(arc[k] - arcMm) < std::abs(arc[static_cast<size_t>(best)] - arcMm))
      best = static_cast<int>(k);
  section_ = best;
}

bool ProfileView::selectNear(const Vec3& w, double maxDistanceMm) {
  if (!has_) return false;
  int bestPath = -1, bestK = -1;
  double bestD = maxDistanceMm;
  for (size_t q = 0; q < m_.paths.size(); ++q) {
    // The selected path first: a trunk's sections belong to every path through it.
    const size_t p = (q + static_cast<size_t>(path_)) % m_.paths.size();
    const auto& secs = m_.paths[p].sections;
    for (size_t k = 0; k < secs.size(); ++k) {
      const double d = (m_.sections[static_cast<size_t>(secs[k])].centreMm - w).norm();
      if (d < bestD) bestD = d, bestPath = static_cast<int>(p), bestK = static_cast<int>(k);
    }
  }
  if (bestPath < 0) return false;
  path_ = bestPath;
  section_ = bestK;
  return true;
}

const CrossSection* ProfileView::selected() const {
  if (!has_ || section_ < 0) return nullptr;
  const auto& p = m_.paths[static_cast<size_t>(path_)];
  return &m_.sections[static_cast<size_t>(p.sections[static_cast<size_t>(section_)])];
}

double ProfileView::selectedArcMm() const {
  if (!has_ || section_ < 0) return std::numeric_limits<double>::quiet_NaN();
  return m_.paths[static_cast<size_t>(path_)].arcMm[static_cast<size_t>(section_)];
}

void ProfileView::setColourByDiameter(bool on) {
  if (on && !has_) throw InvalidArgument("color-by diameter: no measured tree (run `measure` after the trace)");
  if (on && !coloured_) throw DataError("color-by diameter: no cross-section of the tree could be measured");
  colourBy_ = on;
}

void ProfileView::plotData(std::vector<double>& arcMm, std::vector<double>& diameterMm) const {
  arcMm.clear();
  diameterMm.clear();
  if (!has_) return;
  const auto& p = m_.paths[static_cast<size_t>(path_)];
  arcMm = p.arcMm;
  for (int i : p.sections) diameterMm.push_back(m_.sections[static_cast<size_t>(i)].equivalentDiameterMm);
}

void measureTraceProfile(ViewerApp& app) {
  if (!app.hasVolume()) throw InvalidArgument("measure: no volume");
  const Tree tree = app.trace().tree();
  if (tree.size() == 0) throw InvalidArgument("measure: no traced tree (run the trace tool first)");
  app.profile().measure(app.floatVolume(), tree);
}

void selectProfileArc(ViewerApp& app, double arcMm) {
  ProfileView& p = app.profile();
  p.selectArc(arcMm);
  if (const CrossSection* cs = p.selected()) {
    const Vec3 i = app.geometry().worldToIndex(cs->centreMm);
    const Index3 d = app.geometry().dims;
    Index3 v;
    for (int a = 0; a < 3; ++a) v[a] = std::clamp<int64_t>(std::llround(i[a]), 0, d[a] - 1);
    app.setCursor(v);
  }
}

void setTreeColouring(ViewerApp& app, const std::string& by) {
  if (by != "diameter" && by != "none") throw UsageError("color-by takes diameter or none, got '" + by + "'");
  app.profile().setColourByDiameter(by == "diameter");
}

}  // namespace vs::viewer
