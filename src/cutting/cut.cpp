#include "cutting/cut.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "cutting/cut_contour.h"
#include "cutting/envmap.h"
#include "meshops/isosurface.h"
#include "util/error.h"

namespace vs {
namespace {
using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
}  // namespace

void checkCutWeights(const CutOptions& o) {
  auto nonNegative = [](double w) { return std::isfinite(w) && w >= 0; };
  VS_REQUIRE(nonNegative(o.surface.wg), "cut: the image weight w_g must be a finite number >= 0");
  VS_REQUIRE(std::isfinite(o.surface.wc) && o.surface.wc > 0, "cut: the continuity weight w_c must be > 0");
  VS_REQUIRE(nonNegative(o.surface.wp), "cut: the part weight w_p must be a finite number >= 0");
  VS_REQUIRE(o.surface.wd >= 0 && o.surface.wd <= 1, "cut: the direction share w_d must be in [0, 1]");
  VS_REQUIRE(nonNegative(o.cost.wg) && nonNegative(o.cost.wn),
             "cut: the contour's weights w_g and w_n must be finite numbers >= 0");
  VS_REQUIRE(std::isfinite(o.cost.wl) && o.cost.wl > 0, "cut: the contour's length weight w_l must be > 0");
}

CutMesh prepareCutMesh(const VolumeF32& volume, TriMesh mesh, const MeshCostOptions& cost) {
  CutMesh m;
  m.features = sampleVertexFeatures(volume, mesh, cost.robustMaxPercentile);
  m.graph = buildMeshGraph(mesh, m.features, cost);
  m.mesh = std::move(mesh);
  return m;
}

CutResult cutVolume(const VolumeF32& volume, const CutOptions& o, Progress& progress) {
  VS_REQUIRE(o.pointsIndex.size() >= 3,
             "a cut needs at least 3 points around the part, got " + std::to_string(o.pointsIndex.size()));
  checkCutWeights(o);
  const Geometry& g = volume.geometry();
  std::vector<Vec3> pointsMm;
  for (const Vec3& p : o.pointsIndex) pointsMm.push_back(g.indexToWorld(p));
  auto t0 = Clock::now();
  TriMesh mesh;
  if (o.meshKind == CutMeshKind::EnvMap) {
    EnvMapOptions env;
    env.iso = o.iso;
    mesh = envMapMesh(volume, env);
  } else {
    IsoSurfaceOptions iso;
    iso.iso = o.iso;
    iso.largestComponentOnly = false;
    mesh = keepComponentNearest(extractIsoSurface(volume, iso, progress), pointsMm);
  }
  const double meshSeconds = since(t0);
  t0 = Clock::now();
  const CutMesh prepared = prepareCutMesh(volume, std::move(mesh), o.cost);
  const double prepareSeconds = since(t0);
  CutResult r = cutOnMesh(volume, prepared, o, progress);
  r.seconds[0] = meshSeconds;
  r.seconds[1] += prepareSeconds;
  return r;
}

CutResult cutOnMesh(const VolumeF32& volume, const CutMesh& m, const CutOptions& o, Progress& progress) {
  VS_REQUIRE(o.pointsIndex.size() >= 3,
             "a cut needs at least 3 points around the part, got " + std::to_string(o.pointsIndex.size()));
  checkCutWeights(o);
  const Geometry& g = volume.geometry();
  CutResult r;
  r.mesh = m.mesh;
  auto t0 = Clock::now();
  CutContour contour = cutContour(m, g, o.pointsIndex, o.snapRadiusMm, progress);  // the viewer previews this one
  r.contour = std::move(contour.contour);
  r.contourMm = std::move(contour.contourMm);
  r.snapDistanceMm = std::move(contour.snapDistanceMm);
  r.seconds[1] = since(t0);

  t0 = Clock::now();
  r.surface = buildCuttingSurface(volume, o.iso, r.contourMm, o.surface, progress);
  r.seconds[2] = since(t0);

  t0 = Clock::now();
  SplitOptions so;
  so.keepSeed = o.keepSeed;
  r.split = splitVolume(volume, o.iso, r.surface, so, progress);
  r.seconds[3] = since(t0);
  return r;
}

}  // namespace vs
