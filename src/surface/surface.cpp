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
#include "surface/surface_policy.h"
#include "surface/surface_subdivision.h"
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

using namespace surface_detail;

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
    throw InvalidArgument("planes " + indexText(opt.planes) + " are outside the volume " + g.describe());
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
