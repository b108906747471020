// One octant's deformed-triangle subdivision (the rules in surface.h; surface_detail.h).
#pragma once

#include "surface/fold_check.h"
#include "surface/surface_domain.h"

namespace vs::surface_detail {

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
        throw DataError("octant " + octantName(sign_) + ": no 3D path between " + indexText(roundIndex(pa)) + " and " +
                        indexText(roundIndex(pb)));
      for (const Index3& q : path) c.pts.push_back(toVec(q));
    }
    curves.push_back(std::move(c));
    return int(curves.size()) - 1;
  }
};

// The octant's mesh pieces (surface_finish.cpp): every vertex moved onto the iso-surface, in world
// mm, with its outward normal; with everyPathVoxel each triangle re-triangulated over its paths.
void finishOctant(const Shared& s, OctantBuilder& b);

}  // namespace vs::surface_detail
