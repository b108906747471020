#include "surface/surface.h"

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <unordered_set>

#include "features/features2d.h"
#include "graph/grid_graph.h"
#include "graph/shortest_path.h"
#include "mesh/mesh_repair.h"
#include "surface/fold_check.h"
#include "surface/surface_policy.h"
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
  if (!ok) throw InvalidArgument("octant '" + name + "': expected signs for x, y, z such as +x+y+z or -x+y-z");
  return s;
}

std::string sideName(int planeAxis, int signFirst, int signSecond) {
  const int i = planeAxis == 0 ? 1 : 0, j = planeAxis == 2 ? 1 : 2;
  return std::string(1, "xyz"[planeAxis]) + (signFirst > 0 ? "+" : "-") + "xyz"[i] + (signSecond > 0 ? "+" : "-") +
         "xyz"[j];
}

namespace {

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
      throw InvalidArgument("side " + name + ": point " + voxelText(p) + " is not in its quadrant of plane " +
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

// The 3D search domain of one octant: its box (planes included), the node costs there and the
// search band. It depends on the cost and the octant only, so an edited side reuses it.
struct OctantDomain {
  Index3 lo{0, 0, 0}, box{1, 1, 1};
  GridGraph graph;
  std::vector<float> cost;
  std::vector<uint8_t> band;  // search mask: within two voxels of an iso crossing

  OctantDomain(const Shared& s, const SurfaceCost& sc, const OctantSigns& sign) {
    const Index3& d = s.vol.dims();
    for (int a = 0; a < 3; ++a) {
      lo[a] = sign[a] > 0 ? s.center[a] : 0;
      const int64_t hi = sign[a] > 0 ? d[a] - 1 : s.center[a];
      box[a] = hi - lo[a] + 1;
    }
    const Vec3& sp = s.vol.geometry().spacing;
    graph = GridGraph(box, {sp[0], sp[1], sp[2]}, s.opt.connectivity);
    cost.resize(static_cast<size_t>(graph.nodeCount()));
    for (int64_t z = 0; z < box[2]; ++z)
      for (int64_t y = 0; y < box[1]; ++y) {
        const int64_t cx = lo[0] - s.costLo[0], cy = lo[1] + y - s.costLo[1], cz = lo[2] + z - s.costLo[2];
        const float* src = sc.node.data() + cx + s.costDims[0] * (cy + s.costDims[1] * cz);
        std::copy(src, src + box[0], cost.data() + box[0] * (y + box[1] * z));
      }
    // The search band: voxels within two voxels of an iso crossing. Paths on the surface never
    // leave it, so searching inside it only saves the exploration of the volume around the
    // surface; a path the band cannot hold (a gap) is searched again on the whole box.
    std::vector<uint8_t> side(cost.size());
    parallelFor(0, box[2], [&](int64_t z0, int64_t z1) {
      for (int64_t z = z0; z < z1; ++z)
        for (int64_t y = 0; y < box[1]; ++y)
          for (int64_t x = 0; x < box[0]; ++x)
            side[static_cast<size_t>(graph.node(x, y, z))] = s.inside(s.vol(lo[0] + x, lo[1] + y, lo[2] + z));
    });
    std::vector<uint8_t> crossing(cost.size(), 0);
    forEachVoxel([&](int64_t n, auto&& anyNeighbor) {
      crossing[static_cast<size_t>(n)] =
          anyNeighbor([&](int64_t m) { return side[static_cast<size_t>(m)] != side[static_cast<size_t>(n)]; });
    });
    band.assign(cost.size(), 0);
    forEachVoxel([&](int64_t n, auto&& anyNeighbor) {
      band[static_cast<size_t>(n)] = crossing[static_cast<size_t>(n)] ||
                                     anyNeighbor([&](int64_t m) { return crossing[static_cast<size_t>(m)] != 0; });
    });
  }

  // Calls f(node, anyNeighbor) for every voxel of the box, slices in parallel; anyNeighbor(pred)
  // tells whether pred holds for one of the node's in-box neighbours.
  template <class F>
  void forEachVoxel(F&& f) const {
    const int K = graph.directionCount();
    parallelFor(0, box[2], [&](int64_t z0, int64_t z1) {
      for (int64_t z = z0; z < z1; ++z)
        for (int64_t y = 0; y < box[1]; ++y)
          for (int64_t x = 0; x < box[0]; ++x) {
            const int64_t n = graph.node(x, y, z);
            const bool interior = x > 0 && y > 0 && z > 0 && x + 1 < box[0] && y + 1 < box[1] && z + 1 < box[2];
            f(n, [&](auto&& pred) {
              for (int k = 0; k < K; ++k) {
                if (!interior) {
                  const auto& o = graph.offset(k);
                  if (!graph.contains(x + o[0], y + o[1], z + o[2])) continue;
                }
                if (pred(n + graph.linearOffset(k))) return true;
              }
              return false;
            });
          }
    });
  }

  // The minimum-cost path a -> b (voxel positions) inside the band of the sub-box regionLo..regionHi
  // (box coordinates, inclusive; the ends always take part); if the band has a gap there, inside
  // the band of the whole box, then inside the whole box. Voxel indices of the volume; empty if
  // there is no path at all.
  std::vector<Index3> path(const Vec3& a, const Vec3& b, const Index3& regionLo, const Index3& regionHi,
                           SurfaceLevelStats& st) {
    st.paths += 1;
    useRegion(regionLo, regionHi);
    Path p = search(local_, localNode(a), localNode(b), st);
    Index3 offset = local_.lo;
    if (p.empty()) {
      useRegion({0, 0, 0}, {box[0] - 1, box[1] - 1, box[2] - 1});
      p = search(local_, localNode(a), localNode(b), st);
      offset = {0, 0, 0};
    }
    if (p.empty()) {
      const int64_t src = graph.node(int64_t(a[0]) - lo[0], int64_t(a[1]) - lo[1], int64_t(a[2]) - lo[2]);
      const int64_t dst = graph.node(int64_t(b[0]) - lo[0], int64_t(b[1]) - lo[1], int64_t(b[2]) - lo[2]);
      ShortestPathSearch full(graph, GridCost::nodes(cost), {src});
      p = full.pathTo(dst);
      st.nodesSettled += full.settledCount();
      st.edgesScanned += full.settledCount() * graph.directionCount();
    }
    std::vector<Index3> out;
    out.reserve(p.voxels.size());
    for (const auto& q : p.voxels)
      out.push_back({q[0] + offset[0] + lo[0], q[1] + offset[1] + lo[1], q[2] + offset[2] + lo[2]});
    return out;
  }

 private:
  // The search inside one sub-box (its own small graph, costs and band), reused while the sub-box
  // stays the same: a search over the whole box would initialise its records in chunks of whole
  // slices for every short path.
  struct Local {
    Index3 lo{0, 0, 0}, hi{-1, -1, -1};
    GridGraph graph;
    std::vector<float> cost;
    std::vector<uint8_t> band;
    std::unique_ptr<ShortestPathSearch> search;
  } local_;

  void useRegion(const Index3& rlo, const Index3& rhi) {
    if (local_.search && rlo == local_.lo && rhi == local_.hi) return;
    local_.search.reset();  // it references the graph and arrays replaced below
    local_.lo = rlo;
    local_.hi = rhi;
    const Index3 d{rhi[0] - rlo[0] + 1, rhi[1] - rlo[1] + 1, rhi[2] - rlo[2] + 1};
    local_.graph = GridGraph(d, graph.spacing(), graph.connectivity());
    local_.cost.resize(static_cast<size_t>(local_.graph.nodeCount()));
    local_.band.resize(local_.cost.size());
    for (int64_t z = 0; z < d[2]; ++z)
      for (int64_t y = 0; y < d[1]; ++y) {
        const size_t from = static_cast<size_t>(graph.node(rlo[0], rlo[1] + y, rlo[2] + z));
        const size_t to = static_cast<size_t>(local_.graph.node(0, y, z));
        std::copy_n(cost.begin() + static_cast<std::ptrdiff_t>(from), d[0],
                    local_.cost.begin() + static_cast<std::ptrdiff_t>(to));
        std::copy_n(band.begin() + static_cast<std::ptrdiff_t>(from), d[0],
                    local_.band.begin() + static_cast<std::ptrdiff_t>(to));
      }
  }
  int64_t localNode(const Vec3& p) const {
    return local_.graph.node(int64_t(p[0]) - lo[0] - local_.lo[0], int64_t(p[1]) - lo[1] - local_.lo[1],
                             int64_t(p[2]) - lo[2] - local_.lo[2]);
  }
  static Path search(Local& l, int64_t src, int64_t dst, SurfaceLevelStats& st) {
    uint8_t& bs = l.band[static_cast<size_t>(src)];
    uint8_t& bd = l.band[static_cast<size_t>(dst)];
    const uint8_t bandSrc = bs, bandDst = bd;
    bs = bd = 1;
    if (!l.search) {
      SearchOptions so;
      so.mask = l.band;
      l.search = std::make_unique<ShortestPathSearch>(l.graph, GridCost::nodes(l.cost), std::vector<int64_t>{src}, so);
    } else {
      l.search->restart({src});
    }
    Path p = l.search->pathTo(dst);
    bs = bandSrc;  // restored: the next search sees the same band
    bd = bandDst;
    st.nodesSettled += l.search->settledCount();
    st.edgesScanned += l.search->settledCount() * l.graph.directionCount();
    return p;
  }
};

class OctantBuilder {
 public:
  // `domain`: the octant's 3D search domain (null for level 0 and the geometry-only baseline).
  OctantBuilder(const Shared& s, std::shared_ptr<OctantDomain> domain, const OctantSigns& sign)
      : s_(s), domain_(std::move(domain)), sign_(sign) {}

  std::vector<Vertex> vertices;
  std::vector<Curve> curves;
  std::vector<Tri> tris;
  std::vector<SurfaceLevelStats> levels;
  // The patch as mesh pieces (finishOctant): vertices on the iso-surface with their stitching keys,
  // triangles in local vertex ids.
  struct OutVertex {
    Vec3 world, normal;
    Index3 voxel;
    std::pair<int64_t, int64_t> key{-1, 0};  // shared across octants: (0, half-line), (1 + side, index)
  };
  std::vector<OutVertex> outVertices;
  std::vector<std::array<int32_t, 3>> outTris;
  FoldCheck fold;  // of the finished patch (fold_check.h)

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
      if (n > 0 && domain_) setRegion(t);
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
  std::shared_ptr<OctantDomain> domain_;
  OctantSigns sign_;
  Index3 regionLo_{0, 0, 0}, regionHi_{0, 0, 0};  // where the new curves of a triangle are searched
  std::unordered_set<int64_t> taken_;             // voxels of existing and future contour vertices, interior vertices

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

  // The new curves inside triangle t are searched in the bounding box of its three curves, widened
  // by an eighth of its largest extent (at least three voxels), within the octant's box (box
  // coordinates): they join points of its sides across the patch the sides enclose.
  void setRegion(const Tri& t) {
    Vec3 lo = vertices[static_cast<size_t>(t.v[0])].pos, hi = lo;
    for (int e : t.e)
      for (const Vec3& p : curves[static_cast<size_t>(e)].pts) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const double margin = std::max(3.0, (hi - lo).maxCoeff() / 8);
    for (int a = 0; a < 3; ++a) {
      regionLo_[a] = std::max<int64_t>(0, int64_t(std::floor(lo[a] - margin)) - domain_->lo[a]);
      regionHi_[a] = std::min<int64_t>(domain_->box[a] - 1, int64_t(std::ceil(hi[a] + margin)) - domain_->lo[a]);
    }
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
      const std::vector<Index3> path = domain_->path(pa, pb, regionLo_, regionHi_, st);
      if (path.empty())
        throw DataError("octant " + octantName(sign_) + ": no 3D path between " + voxelText(roundIndex(pa)) + " and " +
                        voxelText(roundIndex(pb)));
      for (const Index3& q : path) c.pts.push_back(toVec(q));
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

// Triangulates a simple loop of path voxels (outVertices ids, counter-clockwise seen along
// `normal`) by ear clipping in the plane normal to it, best-shaped ear first. A diagonal never
// joins two points of one curve (`curvesOf`): the patch on the other side of that curve could then
// use the same diagonal, and the mesh would pinch. False (nothing added) if no admissible ear
// remains.
bool clipEars(OctantBuilder& b, std::vector<int32_t> loop, const Vec3& normal,
              const std::vector<std::vector<int>>& curvesOf) {
  auto world = [&](int32_t v) { return b.outVertices[static_cast<size_t>(v)].world; };
  if (!(normal.norm() > 0)) return false;
  const Vec3 p0 = world(loop[0]), axis = normal.normalized();
  const Vec3 e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  auto flat = [&](int32_t v) {
    const Vec3 d = world(v) - p0;
    return Eigen::Vector2d(d.dot(e1), d.dot(e2));
  };
  auto cross2 = [](const Eigen::Vector2d& a, const Eigen::Vector2d& c) { return a[0] * c[1] - a[1] * c[0]; };
  auto shareCurve = [&](int32_t p, int32_t q) {
    for (int cp : curvesOf[static_cast<size_t>(p)])
      for (int cq : curvesOf[static_cast<size_t>(q)])
        if (cp == cq) return true;
    return false;
  };
  std::vector<std::array<int32_t, 3>> tris;
  while (loop.size() > 3) {
    const size_t n = loop.size();
    double bestQuality = -1;
    size_t best = n;
    for (size_t i = 0; i < n; ++i) {
      const size_t prev = (i + n - 1) % n, next = (i + 1) % n;
      if (shareCurve(loop[prev], loop[next])) continue;
      const Eigen::Vector2d a = flat(loop[prev]), c = flat(loop[i]), d = flat(loop[next]);
      const double area2 = cross2(c - a, d - a);
      if (!(area2 > 0)) continue;  // reflex or flat
      bool empty = true;           // no other loop point inside the ear
      for (size_t j = 0; j < n && empty; ++j) {
        if (j == prev || j == i || j == next) continue;
        const Eigen::Vector2d q = flat(loop[j]);
        empty = !(cross2(c - a, q - a) >= 0 && cross2(d - c, q - c) >= 0 && cross2(a - d, q - d) >= 0);
      }
      if (!empty) continue;
      const double quality = area2 / ((c - a).squaredNorm() + (d - c).squaredNorm() + (a - d).squaredNorm());
      if (quality > bestQuality) bestQuality = quality, best = i;
    }
    if (best == n) return false;
    tris.push_back({loop[(best + n - 1) % n], loop[best], loop[(best + 1) % n]});
    loop.erase(loop.begin() + static_cast<std::ptrdiff_t>(best));
  }
  const Eigen::Vector2d a = flat(loop[0]), c = flat(loop[1]), d = flat(loop[2]);
  if (!(cross2(c - a, d - a) > 0)) return false;
  tris.push_back({loop[0], loop[1], loop[2]});
  b.outTris.insert(b.outTris.end(), tris.begin(), tris.end());
  return true;
}

// Removes back-and-forth steps (x, y, x -> x) from a closed loop of vertex ids: two paths of one
// triangle that run along the same voxels enclose no surface there, and the patches on their far
// sides meet directly. Then splits the loop at any vertex it visits twice into simple loops.
std::vector<std::vector<int32_t>> simpleLoops(std::vector<int32_t> loop) {
  bool changed = true;
  while (changed && loop.size() >= 3) {
    changed = false;
    for (size_t i = 0; i < loop.size() && loop.size() >= 3; ++i) {
      const size_t n = loop.size(), next = (i + 1) % n, next2 = (i + 2) % n;
      if (loop[i] == loop[next]) {
        loop.erase(loop.begin() + static_cast<std::ptrdiff_t>(next));
        changed = true;
      } else if (loop[i] == loop[next2]) {  // i, next, i: drop next and the repeated i
        const size_t hi = std::max(next, next2), lo = std::min(next, next2);
        loop.erase(loop.begin() + static_cast<std::ptrdiff_t>(hi));
        loop.erase(loop.begin() + static_cast<std::ptrdiff_t>(lo));
        changed = true;
      }
    }
  }
  if (loop.size() < 3) return {};
  for (size_t i = 0; i < loop.size(); ++i)
    for (size_t j = i + 1; j < loop.size(); ++j)
      if (loop[i] == loop[j]) {  // a figure eight: two loops through the repeated vertex
        std::vector<std::vector<int32_t>> out =
            simpleLoops({loop.begin() + static_cast<std::ptrdiff_t>(i), loop.begin() + static_cast<std::ptrdiff_t>(j)});
        std::vector<int32_t> second(loop.begin() + static_cast<std::ptrdiff_t>(j), loop.end());
        second.insert(second.end(), loop.begin(), loop.begin() + static_cast<std::ptrdiff_t>(i));
        for (auto& part : simpleLoops(second)) out.push_back(std::move(part));
        return out;
      }
  return {loop};
}

// The octant's mesh pieces: every vertex moved onto the iso-surface, in world mm, with its outward
// normal. `everyPathVoxel`: each final triangle becomes a fan around its centre over all the
// voxels of its three curves (a curve's voxels are shared by the two triangles using it, and a
// contour's by the two octants, so the finer mesh stays crack-free).
void finishOctant(const Shared& s, OctantBuilder& b) {
  const Geometry& g = s.vol.geometry();
  const Mat3 gradToWorld = g.direction.inverse().transpose();
  const Vec3 centerWorld = g.indexToWorld(toVec(s.center));
  auto addVertex = [&](const Vec3& pos, bool onImage, std::pair<int64_t, int64_t> key) {
    const Vec3 p = onImage ? refineOntoIso(s, pos) : pos;
    OctantBuilder::OutVertex o;
    o.world = g.indexToWorld(p);
    Vec3 n = gradToWorld * sampleGradient(s.vol, p);
    if (s.brightInside) n = -n;
    o.normal = n.norm() > 0 ? Vec3(n.normalized()) : Vec3((o.world - centerWorld).normalized());
    o.voxel = roundIndex(pos);
    o.key = key;
    b.outVertices.push_back(o);
    return static_cast<int32_t>(b.outVertices.size() - 1);
  };
  b.outVertices.clear();
  b.outTris.clear();
  for (const Vertex& vx : b.vertices)
    addVertex(vx.pos, vx.onImage,
              vx.corner >= 0 ? std::pair<int64_t, int64_t>{0, vx.corner}
              : vx.side >= 0 ? std::pair<int64_t, int64_t>{1 + vx.side, vx.sideIndex}
                             : std::pair<int64_t, int64_t>{-1, 0});
  if (!s.opt.everyPathVoxel) {
    for (const Tri& t : b.tris) b.outTris.push_back({t.v[0], t.v[1], t.v[2]});
    return;
  }
  // Every path voxel is one vertex (paths that share voxels share vertices); contour voxels are
  // keyed by (side, index) for stitching, corners by half-line.
  auto voxelKey = [&](const Vec3& p) {
    const Index3 i = roundIndex(p);
    return g.linear(i[0], i[1], i[2]);
  };
  std::unordered_map<int64_t, int32_t> vertexAt;  // voxel -> vertex
  std::unordered_map<int64_t, std::pair<int64_t, int64_t>> contourKey;
  for (const Curve& c : b.curves)
    if (c.side >= 0 && c.mid < 0)
      for (size_t k = 0; k < c.pts.size(); ++k)
        contourKey[voxelKey(c.pts[k])] = {1 + c.side, c.sideOffset + int64_t(k)};
  for (size_t v = 0; v < b.vertices.size(); ++v) vertexAt[voxelKey(b.vertices[v].pos)] = static_cast<int32_t>(v);
  std::vector<std::vector<int>> curvesOf(b.vertices.size());
  auto pointId = [&](const Vec3& p, int curve) {
    const int64_t k = voxelKey(p);
    auto [it, fresh] = vertexAt.try_emplace(k, -1);
    if (fresh) {
      const auto ck = contourKey.find(k);
      it->second = addVertex(p, true, ck != contourKey.end() ? ck->second : std::pair<int64_t, int64_t>{-1, 0});
      curvesOf.emplace_back();
    }
    auto& on = curvesOf[static_cast<size_t>(it->second)];
    if (std::find(on.begin(), on.end(), curve) == on.end()) on.push_back(curve);
    return it->second;
  };
  auto world = [&](int32_t v) { return b.outVertices[static_cast<size_t>(v)].world; };
  for (const Tri& t : b.tris) {
    std::vector<int32_t> loop;
    for (int i = 0; i < 3; ++i) {
      const Curve& c = b.curves[static_cast<size_t>(t.e[i])];
      const size_t last = c.pts.size() - 1;
      const bool forward = c.a == t.v[i];
      for (size_t j = 0; j <= last; ++j) {
        const int32_t id = pointId(c.pts[forward ? j : last - j], t.e[i]);
        if (j < last) loop.push_back(id);
      }
    }
    const Vec3 normal = (world(t.v[1]) - world(t.v[0])).cross(world(t.v[2]) - world(t.v[0]));
    for (const std::vector<int32_t>& part : simpleLoops(loop)) {
      if (clipEars(b, part, normal, curvesOf)) continue;
      Vec3 sum(0, 0, 0);  // no admissible ear: a fan around the part's centre
      for (int32_t v : part) sum += g.worldToIndex(world(v));
      const int32_t centre = addVertex(sum / double(part.size()), true, {-1, 0});
      curvesOf.emplace_back();
      for (size_t i = 0; i < part.size(); ++i) b.outTris.push_back({part[i], part[(i + 1) % part.size()], centre});
    }
  }
  // Two loops that reduce to the same three vertices in opposite order enclose nothing: drop both.
  std::map<std::array<int32_t, 3>, std::array<std::vector<size_t>, 2>> byVertices;  // by orientation
  for (size_t i = 0; i < b.outTris.size(); ++i) {
    const auto& t = b.outTris[i];
    const size_t first = size_t(std::min_element(t.begin(), t.end()) - t.begin());
    const std::array<int32_t, 3> rotated{t[first], t[(first + 1) % 3], t[(first + 2) % 3]};
    const bool reversed = rotated[1] > rotated[2];
    byVertices[reversed ? std::array<int32_t, 3>{rotated[0], rotated[2], rotated[1]} : rotated][reversed].push_back(i);
  }
  std::vector<bool> drop(b.outTris.size(), false);
  for (const auto& [verts, uses] : byVertices)
    for (size_t k = 0; k < std::min(uses[0].size(), uses[1].size()); ++k) drop[uses[0][k]] = drop[uses[1][k]] = true;
  size_t kept = 0;
  for (size_t i = 0; i < b.outTris.size(); ++i)
    if (!drop[i]) b.outTris[kept++] = b.outTris[i];
  b.outTris.resize(kept);
}

}  // namespace

struct SurfaceExtraction::State {
  const VolumeF32& vol;
  SurfaceOptions opt;
  Shared s;
  std::vector<OctantSigns> octants;
  std::array<Index3, 6> corners{};
  std::vector<std::vector<Index3>> sides = std::vector<std::vector<Index3>>(12);
  std::vector<int> sideList;  // the sides the octants use, each once
  SurfaceCost cost;
  std::vector<std::shared_ptr<OctantDomain>> domains;  // per octant; null without 3D searches
  std::vector<std::unique_ptr<OctantBuilder>> builders;
  SurfaceResult result;

  State(const VolumeF32& v, const SurfaceOptions& o) : vol(v), opt(o), s{vol, opt, opt.planes} {}

  std::string sideNameOf(int id) const { return sideName(id / 4, (id & 2) ? -1 : 1, (id & 1) ? -1 : 1); }
  bool usesSide(const OctantSigns& o, int id) const {
    const auto [i, j] = planeAxes(id / 4);
    return sideId(id / 4, o[i], o[j]) == id;
  }
  std::vector<Index3> viaOf(int id) const {
    std::vector<Index3> via;
    for (const auto& [name, pts] : opt.via)
      if (name == sideNameOf(id)) via.insert(via.end(), pts.begin(), pts.end());
    return via;
  }
  std::vector<Index3> computeSideById(int id, const std::vector<Index3>& via) const {
    const int k = id / 4, si = (id & 2) ? -1 : 1, sj = (id & 1) ? -1 : 1;
    const auto [i, j] = planeAxes(k);
    return computeSide(s, k, si, sj, corners[static_cast<size_t>(2 * i + (si < 0))],
                       corners[static_cast<size_t>(2 * j + (sj < 0))], via);
  }

  // Subdivides the octants `which` from `sideSet` in parallel; throws DataError (too deep, no
  // path) without touching the state.
  std::vector<std::unique_ptr<OctantBuilder>> buildOctants(const std::vector<size_t>& which,
                                                           const std::vector<std::vector<Index3>>& sideSet,
                                                           Progress& progress) {
    std::vector<std::unique_ptr<OctantBuilder>> built(which.size());
    std::vector<std::string> tooDeep(which.size());
    std::mutex progressMutex;
    int64_t done = 0;
    const int64_t work = static_cast<int64_t>(which.size()) * std::max(opt.level, 1);
    parallelFor(0, static_cast<int64_t>(which.size()), [&](int64_t b, int64_t e) {
      for (int64_t m = b; m < e; ++m) {
        const size_t n = which[static_cast<size_t>(m)];
        auto builder = std::make_unique<OctantBuilder>(s, domains[n], octants[n]);
        builder->start(corners, sideSet);
        for (int level = 1; level <= opt.level; ++level) {
          if (builder->subdivide(level, progress) == 0) {
            tooDeep[static_cast<size_t>(m)] = "octant " + octantName(octants[n]) + ": level " + std::to_string(level) +
                                              " is too deep for the object: every side is one voxel step after level " +
                                              std::to_string(level - 1);
            break;
          }
          std::lock_guard<std::mutex> lock(progressMutex);
          progress.report(0.1 + 0.85 * double(++done) / double(work), "subdivision");
        }
        finishOctant(s, *builder);
        std::vector<Vec3> world(builder->outVertices.size());
        for (size_t v = 0; v < world.size(); ++v) world[v] = builder->outVertices[v].world;
        builder->fold = checkFold(vol, s.iso, s.brightInside, s.center, octants[n], world, builder->outTris);
        built[static_cast<size_t>(m)] = std::move(builder);
      }
    });
    for (const std::string& message : tooDeep)
      if (!message.empty()) throw DataError(message);
    return built;
  }

  // The mesh from the octants' patches. Contour vertices are keyed by (side, index along it),
  // corners by half-line, so octants sharing a contour share its vertices.
  void assemble() {
    const Geometry& g = vol.geometry();
    SurfaceResult& res = result;
    res.mesh = TriMesh();
    res.vertexVoxels.clear();
    res.levels.clear();
    res.octants.clear();
    res.sides.clear();
    for (int id : sideList) res.sides.emplace_back(sideNameOf(id), sides[static_cast<size_t>(id)]);
    std::map<std::pair<int64_t, int64_t>, int32_t> sharedVertex;
    TriMesh& mesh = res.mesh;
    const double det = g.direction.determinant();
    const Vec3 centerWorld = g.indexToWorld(res.centerIndex);
    for (size_t n = 0; n < builders.size(); ++n) {
      const OctantBuilder& ob = *builders[n];
      const OctantSigns& o = octants[n];
      std::vector<int32_t> id(ob.outVertices.size(), -1);
      for (size_t v = 0; v < id.size(); ++v) {
        const OctantBuilder::OutVertex& ov = ob.outVertices[v];
        if (ov.key.first >= 0) {
          const auto it = sharedVertex.find(ov.key);
          if (it != sharedVertex.end()) {
            id[v] = it->second;
            continue;
          }
        }
        id[v] = static_cast<int32_t>(mesh.positions.size());
        mesh.positions.push_back(ov.world);
        mesh.normals.push_back(ov.normal);
        res.vertexVoxels.push_back(ov.voxel);
        if (ov.key.first >= 0) sharedVertex[ov.key] = id[v];
      }
      const bool flip = double(o[0] * o[1] * o[2]) * det < 0;
      OctantReport rep;
      rep.octant = o;
      rep.triangles = static_cast<int64_t>(ob.outTris.size());
      // Triangles that face the centre O, for information: slivers of nearly collinear voxels at
      // the finest levels flip a little area without any fold; folds are the image's (fold_check.h).
      double area = 0, back = 0;
      for (const auto& t : ob.outTris) {
        std::array<int32_t, 3> tri{id[static_cast<size_t>(t[0])], id[static_cast<size_t>(t[1])],
                                   id[static_cast<size_t>(t[2])]};
        if (flip) std::swap(tri[1], tri[2]);
        mesh.triangles.push_back(tri);
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
      rep.foldCheckRays = ob.fold.rays;
      rep.foldedRays = ob.fold.foldedRays;
      rep.foldedRayFraction = ob.fold.fraction();
      rep.otherObjectRays = ob.fold.otherObjectRays;
      rep.firstFold = ob.fold.firstFold;
      rep.folded = ob.fold.folded();
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
    }
    // The policy's first step: a sliver is repaired, not fatal (surface_policy.h).
    const MeshRepair repair = repairDegenerateTriangles(mesh);
    res.repairedTriangles = repair.removedTriangles;
    if (!repair.newIndex.empty()) {
      std::vector<Index3> voxels(mesh.positions.size());
      for (size_t v = 0; v < repair.newIndex.size(); ++v)
        if (repair.newIndex[v] >= 0 && v < res.vertexVoxels.size())
          voxels[static_cast<size_t>(repair.newIndex[v])] = res.vertexVoxels[v];
      res.vertexVoxels = std::move(voxels);
    }
    res.topology = analyzeTopology(mesh);
  }
};

SurfaceExtraction::SurfaceExtraction(const VolumeF32& vol, const SurfaceOptions& opt, Progress& progress) {
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
  VS_REQUIRE(!(opt.everyPathVoxel && opt.geometryOnly),
             "the geometry-only baseline has no path voxels for a finer mesh");

  state_ = std::make_unique<State>(vol, opt);
  State& st = *state_;
  Shared& s = st.s;
  SurfaceResult& res = st.result;
  s.iso = opt.iso ? *opt.iso : otsuThreshold(vol);
  VS_REQUIRE(std::isfinite(s.iso), "the iso-value must be finite");
  s.brightInside = vol(s.center[0], s.center[1], s.center[2]) >= s.iso;
  s.finest = std::min({g.spacing[0], g.spacing[1], g.spacing[2]});
  res.iso = s.iso;
  res.centerIndex = toVec(s.center);

  if (opt.closed) {
    for (int z : {1, -1})
      for (int y : {1, -1})
        for (int x : {1, -1}) st.octants.push_back({x, y, z});
  } else {
    st.octants.push_back(opt.octant);
  }
  // Corners of the half-lines used.
  std::array<bool, 6> used{};
  for (const auto& o : st.octants)
    for (int a = 0; a < 3; ++a) used[static_cast<size_t>(2 * a + (o[a] < 0))] = true;
  for (int h = 0; h < 6; ++h) {
    if (opt.corners[static_cast<size_t>(h)] && !used[static_cast<size_t>(h)])
      throw InvalidArgument("corner " + halfLineName(h) + " is given but no octant uses that half-line");
    if (!used[static_cast<size_t>(h)]) continue;
    if (opt.corners[static_cast<size_t>(h)]) {
      checkCorner(s, h, *opt.corners[static_cast<size_t>(h)]);
      st.corners[static_cast<size_t>(h)] = *opt.corners[static_cast<size_t>(h)];
    } else {
      st.corners[static_cast<size_t>(h)] = findCorner(s, h);
    }
    res.corners[static_cast<size_t>(h)] = st.corners[static_cast<size_t>(h)];
  }
  progress.report(0.02, "corners");

  // Sides (the quadrant contours), each computed once.
  auto tSides = Clock::now();
  for (const auto& o : st.octants)
    for (int k = 0; k < 3; ++k) {
      const auto [i, j] = planeAxes(k);
      const int id = sideId(k, o[i], o[j]);
      if (std::find(st.sideList.begin(), st.sideList.end(), id) == st.sideList.end()) st.sideList.push_back(id);
    }
  for (const auto& [name, pts] : opt.via) {
    bool known = false;
    for (int id : st.sideList) known |= st.sideNameOf(id) == name;
    if (!known) throw InvalidArgument("via points for side '" + name + "', which no extracted octant uses");
  }
  parallelFor(0, static_cast<int64_t>(st.sideList.size()), [&](int64_t b, int64_t e) {
    for (int64_t n = b; n < e; ++n) {
      const int id = st.sideList[static_cast<size_t>(n)];
      st.sides[static_cast<size_t>(id)] = st.computeSideById(id, st.viaOf(id));
    }
  });
  res.secondsSides = secondsSince(tSides);
  progress.report(0.05, "sides");

  auto tCost = Clock::now();
  const bool searches = !opt.geometryOnly && opt.level > 0;  // level 0 is the contours alone
  if (searches) {
    // Only the octants' boxes need costs: crop to their union plus one voxel, so the central
    // differences at the box faces see their true neighbours.
    for (int a = 0; a < 3; ++a) {
      bool plus = false, minus = false;
      for (const auto& o : st.octants) (o[a] > 0 ? plus : minus) = true;
      s.costLo[a] = minus ? 0 : std::max<int64_t>(0, s.center[a] - 1);
      const int64_t hi = plus ? g.dims[a] - 1 : std::min(g.dims[a] - 1, s.center[a] + 1);
      s.costDims[a] = hi - s.costLo[a] + 1;
    }
    if (s.costDims == g.dims) {  // closed: every voxel
      st.cost = computeSurfaceCost(vol, s.iso, opt.cost, progress);
    } else {
      Geometry cg = g;
      cg.dims = s.costDims;
      cg.origin = g.indexToWorld(toVec(s.costLo));
      VolumeF32 crop(cg);
      for (int64_t z = 0; z < cg.dims[2]; ++z)
        for (int64_t y = 0; y < cg.dims[1]; ++y) {
          const float* src = vol.data() + g.linear(s.costLo[0], s.costLo[1] + y, s.costLo[2] + z);
          std::copy(src, src + cg.dims[0], crop.data() + cg.linear(0, y, z));
        }
      st.cost = computeSurfaceCost(crop, s.iso, opt.cost, progress);
    }
  }
  res.costDescription = opt.geometryOnly ? "geometry only (radial blend of the contours)"
                        : searches       ? st.cost.description
                                         : "none (level 0: the contours alone)";
  res.secondsCost = secondsSince(tCost);

  // The octants, in parallel.
  st.domains.resize(st.octants.size());
  if (searches)
    parallelFor(0, static_cast<int64_t>(st.octants.size()), [&](int64_t b, int64_t e) {
      for (int64_t n = b; n < e; ++n)
        st.domains[static_cast<size_t>(n)] =
            std::make_shared<OctantDomain>(s, st.cost, st.octants[static_cast<size_t>(n)]);
    });
  std::vector<size_t> all(st.octants.size());
  for (size_t n = 0; n < all.size(); ++n) all[n] = n;
  st.builders = st.buildOctants(all, st.sides, progress);
  st.assemble();
  checkSurfacePolicy(res, opt);
  res.secondsTotal = secondsSince(tStart);
  progress.report(1.0, "surface");
}

SurfaceExtraction::~SurfaceExtraction() = default;

const SurfaceResult& SurfaceExtraction::result() const { return state_->result; }

SurfaceEditReport SurfaceExtraction::editSide(const std::string& side, const std::vector<Index3>& points,
                                              Progress& progress) {
  const auto t0 = Clock::now();
  State& st = *state_;
  int id = -1;
  for (int candidate : st.sideList)
    if (st.sideNameOf(candidate) == side) id = candidate;
  if (id < 0) throw InvalidArgument("edit of side '" + side + "', which no extracted octant uses");
  std::vector<std::vector<Index3>> sides = st.sides;
  sides[static_cast<size_t>(id)] = st.computeSideById(id, points);
  SurfaceEditReport rep;
  rep.side = side;
  std::vector<size_t> which;
  for (size_t n = 0; n < st.octants.size(); ++n)
    if (st.usesSide(st.octants[n], id)) which.push_back(n), rep.octants.push_back(st.octants[n]);
  std::vector<std::unique_ptr<OctantBuilder>> rebuilt = st.buildOctants(which, sides, progress);
  // Commit (nothing above changed the state), undone if the surface policy refuses the result.
  std::vector<std::vector<Index3>> oldSides = std::move(st.sides);
  const auto oldVia = st.opt.via;
  SurfaceResult oldResult = st.result;
  st.sides = std::move(sides);
  std::erase_if(st.opt.via, [&](const auto& v) { return v.first == side; });
  if (!points.empty()) st.opt.via.emplace_back(side, points);
  for (size_t m = 0; m < which.size(); ++m) {
    for (const SurfaceLevelStats& l : rebuilt[m]->levels) rep.paths += l.paths, rep.nodesSettled += l.nodesSettled;
    std::swap(st.builders[which[m]], rebuilt[m]);  // rebuilt[m] now holds the old octant
  }
  st.assemble();
  try {
    checkSurfacePolicy(st.result, st.opt);
  } catch (...) {
    st.sides = std::move(oldSides);
    st.opt.via = oldVia;
    for (size_t m = 0; m < which.size(); ++m) std::swap(st.builders[which[m]], rebuilt[m]);
    st.result = std::move(oldResult);
    throw;
  }
  rep.seconds = secondsSince(t0);
  progress.report(1.0, "edit");
  return rep;
}

SurfaceResult extractSurface(const VolumeF32& vol, const SurfaceOptions& opt, Progress& progress) {
  return SurfaceExtraction(vol, opt, progress).result();
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
