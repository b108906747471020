// Finishing an octant of the surface extraction: vertices onto the iso-surface, normals, and the
// every-voxel re-triangulation (surface_detail.h).
#include "surface/surface_subdivision.h"

namespace vs::surface_detail {

namespace {

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

}  // namespace

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

}  // namespace vs::surface_detail
