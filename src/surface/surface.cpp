#include "surface/surface.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <mutex>
#include <unordered_set>

#include "features/features2d.h"
#include "graph/grid_graph.h"
#include "graph/shortest_path.h"
#include "util/error.h"
#include "util/parallel.h"

namespace vs {

std::string octantName(const OctantSigns& s) {
  std::string n;
  for (int a = 0; a < 3; ++a) n += std::string(s[a] > 0 ? "+" : "-") + "xyz"[a];
  return n;
}

OctantSigns parseOctant(const std::string& name) {
  OctantSigns s{0, 0, 0};
  bool ok = name.size() == 6;
  for (int a = 0; ok && a < 3; ++a) {
    const char sign = name[2 * a], axis = name[2 * a + 1];
    ok = (sign == '+' || sign == '-') && axis == "xyz"[a];
    if (ok) s[a] = sign == '+' ? 1 : -1;
  }
  if (!ok) throw UsageError("octant '" + name + "': expected signs for x, y, z such as +x+y+z or -x+y-z");
  return s;
}

std::string sideName(int planeAxis, int signFirst, int signSecond) {
  const int i = planeAxis == 0 ? 1 : 0, j = planeAxis == 2 ? 1 : 2;
  return std::string(1, "xyz"[planeAxis]) + (signFirst > 0 ? "+" : "-") + "xyz"[i] + (signSecond > 0 ? "+" : "-") +
         "xyz"[j];
}

namespace {

constexpr double kFoldAreaFraction = 0.05;
using Clock = std::chrono::steady_clock;
double secondsSince(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string halfLineName(int h) { return std::string(h % 2 ? "-" : "+") + "xyz"[h / 2]; }
std::string voxelText(const Index3& p) {
  return "(" + std::to_string(p[0]) + "," + std::to_string(p[1]) + "," + std::to_string(p[2]) + ")";
}
Vec3 toVec(const Index3& p) { return Vec3(double(p[0]), double(p[1]), double(p[2])); }

// The two in-plane axes of plane `k`, smaller first.
std::array<int, 2> planeAxes(int k) { return {k == 0 ? 1 : 0, k == 2 ? 1 : 2}; }
int sideId(int k, int si, int sj) { return 4 * k + 2 * (si < 0) + (sj < 0); }

struct Shared {
  const VolumeF32& vol;
  const SurfaceOptions& opt;
  Index3 center;
  double iso = 0;
  bool brightInside = true;  // the object (O's side of the iso-value) is brighter than the iso-value
  double finest = 1;         // finest spacing, mm
  Index3 costLo{0, 0, 0};    // the cost array covers the box costLo .. costLo + costDims - 1
  Index3 costDims{0, 0, 0};
  bool inside(double v) const { return brightInside ? v >= iso : v < iso; }
  double mmDistance(const Vec3& a, const Vec3& b) const { return (a - b).cwiseProduct(vol.geometry().spacing).norm(); }
};

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
  const std::string where = "half-line " + halfLineName(h) + " from the centre " + voxelText(s.center);
  if (outer == kMax)
    throw DataError("no surface crossing on the " + where + ": the object reaches the volume border at " +
                    voxelText(at(kMax)) + " (iso " + std::to_string(s.iso) + "); move the planes or give --corners");
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
    throw InvalidArgument("corner " + halfLineName(h) + " " + voxelText(c) + " is not on its half-line (" + line +
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
  std::map<int64_t, int64_t> pixelOf;  // voxel linear index -> pixel, for the corners and via points
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
      pixelOf[s.vol.geometry().linear(x[0], x[1], x[2])] = p;
    }
  std::vector<Index3> stops{from};
  stops.insert(stops.end(), via.begin(), via.end());
  stops.push_back(to);
  std::vector<int64_t> pix;
  for (const Index3& p : stops) {
    const auto it =
        s.vol.geometry().contains(p) ? pixelOf.find(s.vol.geometry().linear(p[0], p[1], p[2])) : pixelOf.end();
    if (it == pixelOf.end() || !mask[static_cast<size_t>(it->second)])
      throw InvalidArgument("side " + name + ": point " + voxelText(p) + " is not in its quadrant of plane " +
                            std::string(1, "xyz"[k]) + " = " + std::to_string(s.center[k]));
    pix.push_back(it->second);
  }
  SearchOptions so;
  so.mask = mask;
  ShortestPathSearch search(graph, GridCost::perEdge(edges), {pix[0]}, so);
  std::vector<Index3> out{from};
  for (size_t i = 1; i < pix.size(); ++i) {
    if (i > 1) search.restart({pix[i - 1]});
    const Path path = search.pathTo(pix[i]);
    if (path.empty())
      throw DataError("side " + name + ": no path from " + voxelText(stops[i - 1]) + " to " + voxelText(stops[i]) +
                      " inside its quadrant");
    for (size_t n = 1; n < path.voxels.size(); ++n) out.push_back(slice.voxelOf(path.voxels[n][0], path.voxels[n][1]));
  }
  if (out.size() < 2) throw DataError("side " + name + ": its corners coincide at " + voxelText(from));
  return out;
}

// ---- one octant's subdivision ------------------------------------------------------------------

struct Vertex {
  Vec3 pos;             // index space; voxel centre for path voxels, continuous for baseline blends
  bool onImage = true;  // from the image (contour or 3D path): refined onto the iso-surface
  int corner = -1;      // half-line id for a corner
  int side = -1;        // side id for a contour vertex
  int64_t sideIndex = -1;
};

struct Curve {
  int a = -1, b = -1;     // end vertices (pts.front() is a's position)
  std::vector<Vec3> pts;  // index space
  int side = -1;          // contour curves: side id and offset of pts[0] in that side
  int64_t sideOffset = 0;
  int child0 = -1, child1 = -1, mid = -1;  // the split, once done
  bool unsplittable = false;               // decided once: one step, or no free voxel to split at
};

struct Tri {
  std::array<int, 3> v;
  std::array<int, 3> e;  // e[i] joins v[i] and v[(i+1)%3]
};

class OctantBuilder {
 public:
  OctantBuilder(const Shared& s, const SurfaceCost& cost, const OctantSigns& sign) : s_(s), cost_(cost), sign_(sign) {}

  std::vector<Vertex> vertices;
  std::vector<Curve> curves;
  std::vector<Tri> tris;
  std::vector<SurfaceLevelStats> levels;

  void start(const std::array<Index3, 6>& corners, const std::vector<std::vector<Index3>>& sides) {
    int v[3];
    for (int a = 0; a < 3; ++a) {
      const int h = 2 * a + (sign_[a] < 0);
      Vertex vx;
      vx.pos = toVec(corners[static_cast<size_t>(h)]);
      vx.corner = h;
      vertices.push_back(vx);
      v[a] = a;
    }
    // Sides: AB in plane z (x, y), BC in plane x (y, z), CA stored A -> C in plane y (x, z).
    auto addSide = [&](int k, int va, int vb) {
      const auto [i, j] = planeAxes(k);
      const int id = sideId(k, sign_[i], sign_[j]);
      Curve c;
      c.a = va;
      c.b = vb;
      for (const Index3& p : sides[static_cast<size_t>(id)]) c.pts.push_back(toVec(p));
      c.side = id;
      curves.push_back(std::move(c));
      return int(curves.size()) - 1;
    };
    const int ab = addSide(2, v[0], v[1]), bc = addSide(0, v[1], v[2]), ac = addSide(1, v[0], v[2]);
    tris.push_back({{v[0], v[1], v[2]}, {ab, bc, ac}});
    // Every contour vertex up to the requested level is known now (contour splits depend on the
    // contour alone); interior vertices must never take their voxels.
    for (const Vertex& vx : vertices) taken_.insert(key(vx.pos));
    for (int c : {ab, bc, ac})
      reserveContourMidpoints(curves[static_cast<size_t>(c)].pts, 0, curves[static_cast<size_t>(c)].pts.size() - 1,
                              s_.opt.level);
    if (s_.opt.geometryOnly || s_.opt.level == 0) return;
    // The octant's box (planes included) is the 3D search domain.
    const Index3& d = s_.vol.dims();
    for (int a = 0; a < 3; ++a) {
      lo_[a] = sign_[a] > 0 ? s_.center[a] : 0;
      const int64_t hi = sign_[a] > 0 ? d[a] - 1 : s_.center[a];
      box_[a] = hi - lo_[a] + 1;
    }
    graph_ = GridGraph(box_, {s_.vol.geometry().spacing[0], s_.vol.geometry().spacing[1], s_.vol.geometry().spacing[2]},
                       s_.opt.connectivity);
    boxCost_.resize(static_cast<size_t>(box_[0] * box_[1] * box_[2]));
    for (int64_t z = 0; z < box_[2]; ++z)
      for (int64_t y = 0; y < box_[1]; ++y) {
        const int64_t cx = lo_[0] - s_.costLo[0], cy = lo_[1] + y - s_.costLo[1], cz = lo_[2] + z - s_.costLo[2];
        const float* src = cost_.node.data() + cx + s_.costDims[0] * (cy + s_.costDims[1] * cz);
        std::copy(src, src + box_[0], boxCost_.data() + box_[0] * (y + box_[1] * z));
      }
    // The search band: voxels within two voxels of an iso crossing. Paths on the surface never
    // leave it, so searching inside it only saves the exploration of the volume around the
    // surface; a path the band cannot hold (a gap) is searched again on the whole box.
    std::vector<uint8_t> side(boxCost_.size());
    for (int64_t z = 0; z < box_[2]; ++z)
      for (int64_t y = 0; y < box_[1]; ++y)
        for (int64_t x = 0; x < box_[0]; ++x)
          side[static_cast<size_t>(graph_.node(x, y, z))] = s_.inside(s_.vol(lo_[0] + x, lo_[1] + y, lo_[2] + z));
    std::vector<uint8_t> crossing(boxCost_.size(), 0);
    for (int64_t n = 0; n < graph_.nodeCount(); ++n)
      for (int k = 0; k < graph_.directionCount() && !crossing[static_cast<size_t>(n)]; ++k) {
        const int64_t m = graph_.neighbor(n, k);
        if (m >= 0 && side[static_cast<size_t>(m)] != side[static_cast<size_t>(n)])
          crossing[static_cast<size_t>(n)] = 1;
      }
    band_.assign(boxCost_.size(), 0);
    for (int64_t n = 0; n < graph_.nodeCount(); ++n) {
      if (!crossing[static_cast<size_t>(n)]) continue;
      band_[static_cast<size_t>(n)] = 1;
      for (int k = 0; k < graph_.directionCount(); ++k) {
        const int64_t m = graph_.neighbor(n, k);
        if (m >= 0) band_[static_cast<size_t>(m)] = 1;
      }
    }
    SearchOptions so;
    so.mask = band_;
    const int64_t anyNode = std::find(band_.begin(), band_.end(), 1) - band_.begin();
    if (anyNode < graph_.nodeCount())
      band_[static_cast<size_t>(anyNode)] = 1;
    else
      band_[0] = 1;
    search_ = std::make_unique<ShortestPathSearch>(
        graph_, GridCost::nodes(boxCost_), std::vector<int64_t>{anyNode < graph_.nodeCount() ? anyNode : 0}, so);
  }

  // One level; returns the number of triangles added.
  int64_t subdivide(int level, Progress& progress) {
    const auto t0 = Clock::now();
    SurfaceLevelStats st;
    st.level = level;
    const std::vector<Tri> old = std::move(tris);
    tris.clear();
    for (const Tri& t : old) {
      progress.check();
      std::array<bool, 3> split{};
      int n = 0;
      for (int i = 0; i < 3; ++i) n += split[i] = splitCurve(t.e[i]);
      if (n == 0) {
        tris.push_back(t);
      } else if (n == 3) {
        const int m0 = curves[t.e[0]].mid, m1 = curves[t.e[1]].mid, m2 = curves[t.e[2]].mid;
        const int n01 = connect(m0, m1, st), n12 = connect(m1, m2, st), n20 = connect(m2, m0, st);
        const auto& [v0, v1, v2] = t.v;
        add(v0, m0, m2, half(t.e[0], v0), n20, half(t.e[2], v0));
        add(m0, v1, m1, half(t.e[0], v1), half(t.e[1], v1), n01);
        add(m2, m1, v2, n12, half(t.e[1], v2), half(t.e[2], v2));
        add(m0, m1, m2, n01, n12, n20);
      } else if (n == 2) {
        const int u = !split[0] ? 0 : !split[1] ? 1 : 2;  // the unsplit side becomes e1
        const Tri r = rotate(t, (u + 2) % 3);
        const auto& [v0, v1, v2] = r.v;
        const int m0 = curves[r.e[0]].mid, m2 = curves[r.e[2]].mid;
        const int n02 = connect(m0, m2, st);
        add(v0, m0, m2, half(r.e[0], v0), n02, half(r.e[2], v0));
        if (dist(m0, v2) <= dist(v1, m2)) {
          const int d = connect(m0, v2, st);
          add(m0, v1, v2, half(r.e[0], v1), r.e[1], d);
          add(m0, v2, m2, d, half(r.e[2], v2), n02);
        } else {
          const int d = connect(v1, m2, st);
          add(m0, v1, m2, half(r.e[0], v1), d, n02);
          add(v1, v2, m2, r.e[1], half(r.e[2], v2), d);
        }
      } else {
        const int sIdx = split[0] ? 0 : split[1] ? 1 : 2;  // the split side becomes e0
        const Tri r = rotate(t, sIdx);
        const auto& [v0, v1, v2] = r.v;
        const int m0 = curves[r.e[0]].mid;
        const int d = connect(m0, v2, st);
        add(v0, m0, v2, half(r.e[0], v0), d, r.e[2]);
        add(m0, v1, v2, half(r.e[0], v1), r.e[1], d);
      }
    }
    st.triangles = static_cast<int64_t>(tris.size());
    st.seconds = secondsSince(t0);
    levels.push_back(st);
    return static_cast<int64_t>(tris.size() - old.size());
  }

 private:
  const Shared& s_;
  const SurfaceCost& cost_;
  OctantSigns sign_;
  Index3 lo_{0, 0, 0}, box_{1, 1, 1};
  GridGraph graph_;
  std::vector<float> boxCost_;
  std::unique_ptr<ShortestPathSearch> search_, fullSearch_;
  std::vector<uint8_t> band_;          // search mask: within two voxels of an iso crossing
  std::unordered_set<int64_t> taken_;  // voxels of existing and future contour vertices, interior vertices

  int64_t key(const Vec3& p) const {
    const Index3 i = roundIndex(p);
    return s_.vol.geometry().linear(i[0], i[1], i[2]);
  }
  // Index of the point of p[first..last] nearest half the physical length, strictly inside.
  size_t middle(const std::vector<Vec3>& p, size_t first, size_t last) const {
    std::vector<double> arc(last - first + 1, 0.0);
    for (size_t i = first + 1; i <= last; ++i) arc[i - first] = arc[i - first - 1] + s_.mmDistance(p[i - 1], p[i]);
    size_t m = first + 1;
    for (size_t i = first + 1; i < last; ++i)
      if (std::abs(arc[i - first] - arc.back() / 2) < std::abs(arc[m - first] - arc.back() / 2)) m = i;
    return m;
  }
  void reserveContourMidpoints(const std::vector<Vec3>& p, size_t first, size_t last, int depth) {
    if (depth <= 0 || last - first < 2) return;
    const size_t m = middle(p, first, last);
    taken_.insert(key(p[m]));
    reserveContourMidpoints(p, first, m, depth - 1);
    reserveContourMidpoints(p, m, last, depth - 1);
  }

  static Tri rotate(const Tri& t, int r) {
    Tri o;
    for (int i = 0; i < 3; ++i) o.v[i] = t.v[(i + r) % 3], o.e[i] = t.e[(i + r) % 3];
    return o;
  }
  double dist(int a, int b) const { return s_.mmDistance(vertices[a].pos, vertices[b].pos); }
  void add(int a, int b, int c, int eab, int ebc, int eca) { tris.push_back({{a, b, c}, {eab, ebc, eca}}); }
  // The half of a split curve that touches vertex v.
  int half(int c, int v) const { return curves[c].a == v ? curves[c].child0 : curves[c].child1; }

  // Splits curve c once (cached). Contours split at the point nearest half their length (the same
  // in every octant that shares them); interior curves at the free voxel nearest their middle, so
  // no two vertices share a voxel. False if the curve has one step or no free voxel.
  bool splitCurve(int c) {
    Curve& cv = curves[static_cast<size_t>(c)];
    if (cv.mid >= 0) return true;
    if (cv.unsplittable) return false;
    const std::vector<Vec3>& p = cv.pts;
    if (p.size() < 3) {
      cv.unsplittable = true;
      return false;
    }
    size_t m = middle(p, 0, p.size() - 1);
    if (cv.side < 0) {
      std::vector<double> arc(p.size(), 0.0);
      for (size_t i = 1; i < p.size(); ++i) arc[i] = arc[i - 1] + s_.mmDistance(p[i - 1], p[i]);
      std::vector<size_t> order;  // the middle half only: a split far off-centre skews the triangles
      for (size_t i = 1; i + 1 < p.size(); ++i)
        if (std::abs(arc[i] - arc.back() / 2) <= arc.back() / 4 + 1e-9) order.push_back(i);
      std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
        return std::abs(arc[a] - arc.back() / 2) < std::abs(arc[b] - arc.back() / 2);
      });
      const auto free = std::find_if(order.begin(), order.end(), [&](size_t i) { return !taken_.count(key(p[i])); });
      if (free == order.end()) {
        cv.unsplittable = true;
        return false;
      }
      m = *free;
      taken_.insert(key(p[m]));
    }
    Vertex mv;
    mv.pos = p[m];
    mv.onImage = !s_.opt.geometryOnly || cv.side >= 0;
    if (cv.side >= 0) {
      mv.side = cv.side;
      mv.sideIndex = cv.sideOffset + static_cast<int64_t>(m);
    }
    vertices.push_back(mv);
    const int mid = int(vertices.size()) - 1;
    Curve h0, h1;
    h0.a = cv.a, h0.b = mid, h1.a = mid, h1.b = cv.b;
    h0.pts.assign(p.begin(), p.begin() + static_cast<std::ptrdiff_t>(m) + 1);
    h1.pts.assign(p.begin() + static_cast<std::ptrdiff_t>(m), p.end());
    h0.side = h1.side = cv.side;
    h0.sideOffset = cv.sideOffset;
    h1.sideOffset = cv.sideOffset + static_cast<int64_t>(m);
    curves[static_cast<size_t>(c)].mid = mid;  // before the pushes: they may move cv
    curves.push_back(std::move(h0));
    curves.push_back(std::move(h1));
    curves[static_cast<size_t>(c)].child0 = int(curves.size()) - 2;
    curves[static_cast<size_t>(c)].child1 = int(curves.size()) - 1;
    return true;
  }

  // A new interior curve a -> b: the 3D minimum-cost path inside the octant, or for the baseline
  // the radial blend of the two end points around the centre.
  int connect(int a, int b, SurfaceLevelStats& st) {
    Curve c;
    c.a = a;
    c.b = b;
    const Vec3 pa = vertices[a].pos, pb = vertices[b].pos;
    if (s_.opt.geometryOnly) {
      const Vec3 sp = s_.vol.geometry().spacing, o = toVec(s_.center);
      const Vec3 ra = (pa - o).cwiseProduct(sp), rb = (pb - o).cwiseProduct(sp);
      const int steps = std::max(1, int(std::ceil(s_.mmDistance(pa, pb) / s_.finest)));
      for (int i = 0; i <= steps; ++i) {
        const double t = double(i) / steps;
        const double r = (1 - t) * ra.norm() + t * rb.norm();
        const Vec3 dir = ((1 - t) * ra.normalized() + t * rb.normalized()).normalized();
        c.pts.push_back(o + (r * dir).cwiseQuotient(sp));
      }
      c.pts.front() = pa;
      c.pts.back() = pb;
    } else {
      auto boxNode = [&](const Vec3& p) {
        return graph_.node(int64_t(p[0]) - lo_[0], int64_t(p[1]) - lo_[1], int64_t(p[2]) - lo_[2]);
      };
      const int64_t src = boxNode(pa), dst = boxNode(pb);
      band_[static_cast<size_t>(src)] = band_[static_cast<size_t>(dst)] = 1;  // the ends always take part
      search_->restart({src});
      Path path = search_->pathTo(dst);
      st.paths += 1;
      st.nodesSettled += search_->settledCount();
      st.edgesScanned += search_->settledCount() * graph_.directionCount();
      if (path.empty()) {  // the band has a gap between the two: the whole box
        if (!fullSearch_)
          fullSearch_ =
              std::make_unique<ShortestPathSearch>(graph_, GridCost::nodes(boxCost_), std::vector<int64_t>{src});
        else
          fullSearch_->restart({src});
        path = fullSearch_->pathTo(dst);
        st.nodesSettled += fullSearch_->settledCount();
        st.edgesScanned += fullSearch_->settledCount() * graph_.directionCount();
      }
      if (path.empty())
        throw DataError("octant " + octantName(sign_) + ": no 3D path between " + voxelText(roundIndex(pa)) + " and " +
                        voxelText(roundIndex(pb)));
      for (const auto& q : path.voxels)
        c.pts.push_back(Vec3(double(q[0] + lo_[0]), double(q[1] + lo_[1]), double(q[2] + lo_[2])));
    }
    curves.push_back(std::move(c));
    return int(curves.size()) - 1;
  }
};

// Newton steps along the trilinear gradient onto the iso-surface, at most one voxel per axis.
Vec3 refineOntoIso(const Shared& s, const Vec3& start) {
  const Vec3& sp = s.vol.geometry().spacing;
  Vec3 p = start;
  for (int it = 0; it < 8; ++it) {
    const double f = sampleTrilinear(s.vol, p) - s.iso;
    const Vec3 g = sampleGradient(s.vol, p);
    const double gg = g.squaredNorm();
    if (!(gg > 0)) break;
    const Vec3 step = (-f / gg * g).cwiseQuotient(sp);
    Vec3 next = p + step;
    for (int a = 0; a < 3; ++a) {
      next[a] = std::clamp(next[a], start[a] - 1.0, start[a] + 1.0);
      next[a] = std::clamp(next[a], 0.0, double(s.vol.dims()[a] - 1));
    }
    const bool small = (next - p).norm() < 1e-4;
    p = next;
    if (small) break;
  }
  return p;
}

}  // namespace

SurfaceResult extractSurface(const VolumeF32& vol, const SurfaceOptions& opt, Progress& progress) {
  const auto tStart = Clock::now();
  VS_REQUIRE(!vol.empty(), "surface: empty volume");
  requireFinite(AnyVolume(vol), "surface input");
  const Geometry& g = vol.geometry();
  if (!g.contains(opt.planes))
    throw InvalidArgument("planes " + voxelText(opt.planes) + " are outside the volume " + g.describe());
  for (int a = 0; a < 3; ++a)
    if (opt.planes[a] == 0 || opt.planes[a] == g.dims[a] - 1)
      throw InvalidArgument(std::string("plane ") + "xyz"[a] + " = " + std::to_string(opt.planes[a]) +
                            " lies on the volume border: the octants on one side would be empty");
  VS_REQUIRE(opt.level >= 0 && opt.level <= 8, "level must be in 0..8 (4^8 = 65536 triangles per octant)");
  VS_REQUIRE(opt.connectivity == 6 || opt.connectivity == 18 || opt.connectivity == 26,
             "connectivity must be 6, 18 or 26");
  for (int a = 0; a < 3; ++a) VS_REQUIRE(std::abs(opt.octant[a]) == 1, "octant signs must be +1 or -1");

  SurfaceResult res;
  Shared s{vol, opt, opt.planes};
  s.iso = opt.iso ? *opt.iso : otsuThreshold(vol);
  VS_REQUIRE(std::isfinite(s.iso), "the iso-value must be finite");
  s.brightInside = vol(s.center[0], s.center[1], s.center[2]) >= s.iso;
  s.finest = std::min({g.spacing[0], g.spacing[1], g.spacing[2]});
  res.iso = s.iso;
  res.centerIndex = toVec(s.center);

  std::vector<OctantSigns> octants;
  if (opt.closed) {
    for (int z : {1, -1})
      for (int y : {1, -1})
        for (int x : {1, -1}) octants.push_back({x, y, z});
  } else {
    octants.push_back(opt.octant);
  }
  // Corners of the half-lines used.
  std::array<Index3, 6> corners{};
  std::array<bool, 6> used{};
  for (const auto& o : octants)
    for (int a = 0; a < 3; ++a) used[static_cast<size_t>(2 * a + (o[a] < 0))] = true;
  for (int h = 0; h < 6; ++h) {
    if (opt.corners[static_cast<size_t>(h)] && !used[static_cast<size_t>(h)])
      throw InvalidArgument("corner " + halfLineName(h) + " is given but no octant uses that half-line");
    if (!used[static_cast<size_t>(h)]) continue;
    if (opt.corners[static_cast<size_t>(h)]) {
      checkCorner(s, h, *opt.corners[static_cast<size_t>(h)]);
      corners[static_cast<size_t>(h)] = *opt.corners[static_cast<size_t>(h)];
    } else {
      corners[static_cast<size_t>(h)] = findCorner(s, h);
    }
    res.corners[static_cast<size_t>(h)] = corners[static_cast<size_t>(h)];
  }
  progress.report(0.02, "corners");

  // Sides (the quadrant contours), each computed once.
  auto tSides = Clock::now();
  std::vector<std::vector<Index3>> sides(12);
  std::vector<int> sideList;
  for (const auto& o : octants)
    for (int k = 0; k < 3; ++k) {
      const auto [i, j] = planeAxes(k);
      const int id = sideId(k, o[i], o[j]);
      if (std::find(sideList.begin(), sideList.end(), id) == sideList.end()) sideList.push_back(id);
    }
  for (const auto& [name, pts] : opt.via) {
    bool known = false;
    for (int id : sideList) known |= sideName(id / 4, (id & 2) ? -1 : 1, (id & 1) ? -1 : 1) == name;
    if (!known) throw InvalidArgument("via points for side '" + name + "', which no extracted octant uses");
  }
  parallelFor(0, static_cast<int64_t>(sideList.size()), [&](int64_t b, int64_t e) {
    for (int64_t n = b; n < e; ++n) {
      const int id = sideList[static_cast<size_t>(n)];
      const int k = id / 4, si = (id & 2) ? -1 : 1, sj = (id & 1) ? -1 : 1;
      const auto [i, j] = planeAxes(k);
      std::vector<Index3> via;
      for (const auto& [name, pts] : opt.via)
        if (name == sideName(k, si, sj)) via.insert(via.end(), pts.begin(), pts.end());
      sides[static_cast<size_t>(id)] = computeSide(s, k, si, sj, corners[static_cast<size_t>(2 * i + (si < 0))],
                                                   corners[static_cast<size_t>(2 * j + (sj < 0))], via);
    }
  });
  res.secondsSides = secondsSince(tSides);
  for (int id : sideList) {
    std::vector<Index3> pts = sides[static_cast<size_t>(id)];
    res.sides.emplace_back(sideName(id / 4, (id & 2) ? -1 : 1, (id & 1) ? -1 : 1), std::move(pts));
  }
  progress.report(0.05, "sides");

  auto tCost = Clock::now();
  SurfaceCost cost;
  const bool searches = !opt.geometryOnly && opt.level > 0;  // level 0 is the contours alone
  if (searches) {
    // Only the octants' boxes need costs: crop to their union plus one voxel, so the central
    // differences at the box faces see their true neighbours.
    for (int a = 0; a < 3; ++a) {
      bool plus = false, minus = false;
      for (const auto& o : octants) (o[a] > 0 ? plus : minus) = true;
      s.costLo[a] = minus ? 0 : std::max<int64_t>(0, s.center[a] - 1);
      const int64_t hi = plus ? g.dims[a] - 1 : std::min(g.dims[a] - 1, s.center[a] + 1);
      s.costDims[a] = hi - s.costLo[a] + 1;
    }
    Geometry cg = g;
    cg.dims = s.costDims;
    cg.origin = g.indexToWorld(toVec(s.costLo));
    VolumeF32 crop(cg);
    for (int64_t z = 0; z < cg.dims[2]; ++z)
      for (int64_t y = 0; y < cg.dims[1]; ++y) {
        const float* src = vol.data() + g.linear(s.costLo[0], s.costLo[1] + y, s.costLo[2] + z);
        std::copy(src, src + cg.dims[0], crop.data() + cg.linear(0, y, z));
      }
    cost = computeSurfaceCost(crop, s.iso, opt.cost, progress);
  }
  res.costDescription = opt.geometryOnly ? "geometry only (radial blend of the contours)"
                        : searches       ? cost.description
                                         : "none (level 0: the contours alone)";
  res.secondsCost = secondsSince(tCost);

  // The octants, in parallel.
  std::vector<std::unique_ptr<OctantBuilder>> builders(octants.size());
  std::vector<std::string> tooDeep(octants.size());
  std::mutex progressMutex;
  int64_t done = 0;
  const int64_t work = static_cast<int64_t>(octants.size()) * std::max(opt.level, 1);
  parallelFor(0, static_cast<int64_t>(octants.size()), [&](int64_t b, int64_t e) {
    for (int64_t n = b; n < e; ++n) {
      auto builder = std::make_unique<OctantBuilder>(s, cost, octants[static_cast<size_t>(n)]);
      builder->start(corners, sides);
      for (int level = 1; level <= opt.level; ++level) {
        if (builder->subdivide(level, progress) == 0) {
          tooDeep[static_cast<size_t>(n)] =
              "octant " + octantName(octants[static_cast<size_t>(n)]) + ": level " + std::to_string(level) +
              " is too deep for the object: every side is one voxel step after level " + std::to_string(level - 1);
          break;
        }
        std::lock_guard<std::mutex> lock(progressMutex);
        progress.report(0.1 + 0.85 * double(++done) / double(work), "subdivision");
      }
      builders[static_cast<size_t>(n)] = std::move(builder);
    }
  });
  for (const std::string& m : tooDeep)
    if (!m.empty()) throw DataError(m);

  // Stitch: contour vertices are keyed by (side, index along it), corners by half-line, so
  // octants sharing a contour share its vertices.
  std::map<std::pair<int64_t, int64_t>, int32_t> sharedVertex;
  std::vector<Vec3> voxelPos;
  std::vector<bool> onImage;
  TriMesh& mesh = res.mesh;
  const double det = g.direction.determinant();
  const Vec3 centerWorld = g.indexToWorld(res.centerIndex);
  for (size_t n = 0; n < builders.size(); ++n) {
    const OctantBuilder& ob = *builders[n];
    const OctantSigns& o = octants[n];
    std::vector<int32_t> id(ob.vertices.size(), -1);
    auto globalId = [&](int v) {
      if (id[static_cast<size_t>(v)] >= 0) return id[static_cast<size_t>(v)];
      const Vertex& vx = ob.vertices[static_cast<size_t>(v)];
      std::pair<int64_t, int64_t> key{-1, 0};
      if (vx.corner >= 0)
        key = {0, vx.corner};
      else if (vx.side >= 0)
        key = {1 + vx.side, vx.sideIndex};
      if (key.first >= 0) {
        const auto it = sharedVertex.find(key);
        if (it != sharedVertex.end()) return id[static_cast<size_t>(v)] = it->second;
      }
      const int32_t gid = static_cast<int32_t>(voxelPos.size());
      voxelPos.push_back(vx.pos);
      onImage.push_back(vx.onImage);
      if (key.first >= 0) sharedVertex[key] = gid;
      return id[static_cast<size_t>(v)] = gid;
    };
    const bool flip = double(o[0] * o[1] * o[2]) * det < 0;
    OctantReport rep;
    rep.octant = o;
    const size_t firstTri = mesh.triangles.size();
    for (const Tri& t : ob.tris) {
      std::array<int32_t, 3> tri{globalId(t.v[0]), globalId(t.v[1]), globalId(t.v[2])};
      if (flip) std::swap(tri[1], tri[2]);
      mesh.triangles.push_back(tri);
    }
    rep.triangles = static_cast<int64_t>(ob.tris.size());
    res.octants.push_back(rep);
    for (size_t l = 0; l < ob.levels.size(); ++l) {
      if (res.levels.size() <= l) res.levels.push_back({ob.levels[l].level});
      SurfaceLevelStats& agg = res.levels[l];
      agg.triangles += ob.levels[l].triangles;
      agg.paths += ob.levels[l].paths;
      agg.nodesSettled += ob.levels[l].nodesSettled;
      agg.edgesScanned += ob.levels[l].edgesScanned;
      agg.seconds += ob.levels[l].seconds;
    }
    (void)firstTri;
  }

  // Vertex positions on the iso-surface and outward normals.
  const Mat3 gradToWorld = g.direction.inverse().transpose();
  mesh.positions.resize(voxelPos.size());
  mesh.normals.resize(voxelPos.size());
  res.vertexVoxels.resize(voxelPos.size());
  parallelFor(
      0, static_cast<int64_t>(voxelPos.size()),
      [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) {
          const size_t k = static_cast<size_t>(i);
          const Vec3 p = onImage[k] ? refineOntoIso(s, voxelPos[k]) : voxelPos[k];
          res.vertexVoxels[k] = roundIndex(voxelPos[k]);
          mesh.positions[k] = g.indexToWorld(p);
          Vec3 n = gradToWorld * sampleGradient(vol, p);
          if (s.brightInside) n = -n;
          mesh.normals[k] = n.norm() > 0 ? Vec3(n.normalized()) : Vec3((mesh.positions[k] - centerWorld).normalized());
        }
      },
      256);

  // Folds: triangles that face the centre O (the surface turns back along rays from O). Slivers of
  // nearly collinear voxels at the finest levels flip a little area (about 1% on a sphere at two-step
  // sides); an ear or an overhang turns far more.
  size_t t0 = 0;
  for (OctantReport& rep : res.octants) {
    double area = 0, back = 0;
    for (size_t t = t0; t < t0 + static_cast<size_t>(rep.triangles); ++t) {
      const auto& tri = mesh.triangles[t];
      const Vec3 a = mesh.positions[static_cast<size_t>(tri[0])], b = mesh.positions[static_cast<size_t>(tri[1])],
                 c = mesh.positions[static_cast<size_t>(tri[2])];
      const Vec3 nrm = (b - a).cross(c - a);
      area += nrm.norm() / 2;
      if (nrm.dot((a + b + c) / 3 - centerWorld) < 0) {
        rep.backFacingTriangles += 1;
        back += nrm.norm() / 2;
      }
    }
    rep.backFacingAreaFraction = area > 0 ? back / area : 0;
    rep.folded = rep.backFacingAreaFraction > kFoldAreaFraction;
    t0 += static_cast<size_t>(rep.triangles);
  }
  res.secondsTotal = secondsSince(tStart);
  progress.report(1.0, "surface");
  return res;
}

std::vector<Vec3> outermostInOctant(const TriMesh& ref, const VolumeF32& v, double iso, const Vec3& o,
                                    const OctantSigns& s) {
  const Geometry& g = v.geometry();
  const Index3 c = roundIndex(o);
  VS_REQUIRE(g.contains(c), "outermostInOctant: the centre is outside the volume");
  const bool bright = v(c[0], c[1], c[2]) >= iso;
  std::vector<Vec3> pts;
  for (const Vec3& w : ref.positions) {
    const Vec3 p = g.worldToIndex(w), rel = p - o;
    if (rel[0] * s[0] < 0 || rel[1] * s[1] < 0 || rel[2] * s[2] < 0 || rel.norm() < 1) continue;
    const Vec3 dir = rel.normalized();
    bool outer = true;
    for (double t = 1.5; outer; t += 0.5) {  // from 1.5 voxels beyond the vertex outwards
      const Vec3 q = p + t * dir;
      if (!g.containsContinuous(q)) break;
      const double val = sampleTrilinear(v, q);
      if (bright ? val >= iso : val < iso) outer = false;
    }
    if (outer) pts.push_back(w);
  }
  return pts;
}

}  // namespace vs
