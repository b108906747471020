// Corners on the half-lines and the quadrant contours of the surface extraction (surface_detail.h).
#include "surface/surface_detail.h"

namespace vs::surface_detail {

// Outermost crossing of the iso-value on half-line h: the voxel nearest the iso-value among the
// outermost object voxel and its outer neighbour.
Index3 findCorner(const Shared& s, int h) {
  const int axis = h / 2, sign = h % 2 ? -1 : 1;
  const Index3& d = s.vol.dims();
  auto at = [&](int64_t k) {
    Index3 p = s.center;
    p[axis] += sign * k;
    return p;
  };
  const int64_t kMax = sign > 0 ? d[axis] - 1 - s.center[axis] : s.center[axis];
  int64_t outer = -1;
  for (int64_t k = kMax; k >= 0; --k) {
    const Index3 p = at(k);
    if (s.inside(s.vol(p[0], p[1], p[2]))) {
      outer = k;
      break;
    }
  }
  const std::string where = "half-line " + halfLineName(h) + " from the centre " + indexText(s.center);
  if (outer == kMax)
    throw DataError("no surface crossing on the " + where + ": the object reaches the volume border at " +
                    indexText(at(kMax)) + " (iso " + std::to_string(s.iso) + "); move the planes or give --corners");
  if (outer <= 0)
    throw DataError("no surface crossing on the " + where + ": the centre is the only object voxel (iso " +
                    std::to_string(s.iso) + "); move the planes or give --corners");
  const Index3 in = at(outer), out = at(outer + 1);
  const double dIn = std::abs(s.vol(in[0], in[1], in[2]) - s.iso),
               dOut = std::abs(s.vol(out[0], out[1], out[2]) - s.iso);
  return dOut < dIn ? out : in;
}

void checkCorner(const Shared& s, int h, const Index3& c) {
  const int axis = h / 2, sign = h % 2 ? -1 : 1;
  bool ok = s.vol.geometry().contains(c) && sign * (c[axis] - s.center[axis]) > 0;
  for (int a = 0; a < 3; ++a)
    if (a != axis && c[a] != s.center[a]) ok = false;
  if (!ok) {
    std::string line;
    for (int a = 0; a < 3; ++a)
      if (a != axis) line += std::string(line.empty() ? "" : ", ") + "xyz"[a] + " = " + std::to_string(s.center[a]);
    throw InvalidArgument("corner " + halfLineName(h) + " " + indexText(c) + " is not on its half-line (" + line +
                          ", " + "xyz"[axis] + (sign > 0 ? " > " : " < ") + std::to_string(s.center[axis]) +
                          ", inside the volume)");
  }
}

// One quadrant contour: 2D live-wire in plane k = center[k] from corner `from` to corner `to`
// through the via points, restricted to the quadrant (signs si, sj of the in-plane axes).
std::vector<Index3> computeSide(const Shared& s, int k, int si, int sj, const Index3& from, const Index3& to,
                                const std::vector<Index3>& via) {
  const std::string name = sideName(k, si, sj);
  const SliceView<float> slice = sliceView(s.vol, k, s.center[k]);
  const Features2D f =
      computeFeatures2D(slice, {}, "plane " + std::string(1, "xyz"[k]) + "=" + std::to_string(s.center[k]));
  const GridGraph graph({slice.width, slice.height, 1}, {slice.spacingU, slice.spacingV, 1.0}, 8);
  const int K = graph.directionCount();
  std::vector<std::array<int, 2>> steps;
  for (int d = 0; d < K; ++d) steps.push_back({graph.offset(d)[0], graph.offset(d)[1]});
  std::vector<float> edges = liveWireEdgeCosts(f, s.opt.sideCost, steps);
  // The iso term keeps the contour on the chosen iso-surface rather than the strongest edge.
  const double tiny = 1e-6 * std::max<double>(f.maxMagnitude, 1e-30);
  const auto [ai, aj] = planeAxes(k);
  std::vector<uint8_t> mask(static_cast<size_t>(f.pixelCount()), 0);
  for (int64_t v = 0; v < f.height; ++v)
    for (int64_t u = 0; u < f.width; ++u) {
      const int64_t p = f.index(u, v);
      const Index3 x = slice.voxelOf(u, v);
      mask[static_cast<size_t>(p)] = si * (x[ai] - s.center[ai]) >= 0 && sj * (x[aj] - s.center[aj]) >= 0;
      const double d = std::abs(f.smoothed[static_cast<size_t>(p)] - s.iso) /
                       std::max<double>(f.magnitude[static_cast<size_t>(p)], tiny);
      const double isoTerm = s.opt.cost.weightIso * std::min(d / s.finest, 1.0);
      // Edges entering pixel p: from p - offset(d) in direction d.
      for (int dir = 0; dir < K; ++dir) {
        const auto& o = graph.offset(dir);
        const int64_t pu = u - o[0], pv = v - o[1];
        if (f.contains(pu, pv))
          edges[static_cast<size_t>(f.index(pu, pv) * K + dir)] += float(graph.length(dir) * isoTerm);
      }
    }
  std::vector<Index3> stops{from};
  stops.insert(stops.end(), via.begin(), via.end());
  stops.push_back(to);
  std::vector<int64_t> pix;
  for (const Index3& p : stops) {
    // Pixel (u, v) of the slice is the voxel with p[ai] = u, p[aj] = v (volume.h).
    const bool inPlane = s.vol.geometry().contains(p) && p[k] == s.center[k];
    const int64_t pixel = inPlane ? f.index(p[ai], p[aj]) : -1;
    if (!inPlane || !mask[static_cast<size_t>(pixel)])
      throw InvalidArgument("side " + name + ": point " + indexText(p) + " is not in its quadrant of plane " +
                            std::string(1, "xyz"[k]) + " = " + std::to_string(s.center[k]));
    pix.push_back(pixel);
  }
  SearchOptions so;
  so.mask = mask;
  ShortestPathSearch search(graph, GridCost::perEdge(edges), {pix[0]}, so);
  std::vector<Index3> out{from};
  for (size_t i = 1; i < pix.size(); ++i) {
    if (i > 1) search.restart({pix[i - 1]});
    const Path path = search.pathTo(pix[i]);
    if (path.empty())
      throw DataError("side " + name + ": no path from " + indexText(stops[i - 1]) + " to " + indexText(stops[i]) +
                      " inside its quadrant");
    for (size_t n = 1; n < path.voxels.size(); ++n) out.push_back(slice.voxelOf(path.voxels[n][0], path.voxels[n][1]));
  }
  if (out.size() < 2) throw DataError("side " + name + ": its corners coincide at " + indexText(from));
  return out;
}

}  // namespace vs::surface_detail
