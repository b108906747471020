// Surface extraction from three orthogonal contours (issue 15): mesh validity, the subdivision
// rules, accuracy against analytic surfaces and against the geometry-only baseline, bad input.
#include "surface/surface.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <set>

#include "shapes.h"
#include "surface/mesh_quality.h"
#include "util/error.h"

namespace vs {
namespace {

using test::cube;

// Reference points of `ref` inside octant `o` around the centre (index space of g), and the mesh
// points, compared both ways. Distances in voxels of the finest spacing.
struct TwoWay {
  DistanceSummary toReference, fromReference;
};
TwoWay compare(const TriMesh& mesh, const TriMesh& ref, const Geometry& g, const Vec3& centerIndex,
               const std::vector<OctantSigns>& octants) {
  const double h = g.spacing.minCoeff();
  TwoWay r;
  MeshDistance toRef(ref), toMesh(mesh);
  std::vector<double> d = toRef.distances(sampleMesh(mesh, h / 2));
  for (double& x : d) x /= h;
  r.toReference = summarize(d);
  std::vector<Vec3> pts;
  for (const Vec3& p : ref.positions) {
    const Vec3 rel = g.worldToIndex(p) - centerIndex;
    for (const auto& o : octants)
      if (rel[0] * o[0] >= 0 && rel[1] * o[1] >= 0 && rel[2] * o[2] >= 0) {
        pts.push_back(p);
        break;
      }
  }
  d = toMesh.distances(pts);
  for (double& x : d) x /= h;
  r.fromReference = summarize(d);
  return r;
}

TEST(SurfaceNames, OctantsAndSides) {
  EXPECT_EQ(octantName({1, -1, 1}), "+x-y+z");
  EXPECT_EQ(parseOctant("-x+y-z"), (OctantSigns{-1, 1, -1}));
  EXPECT_THROW(parseOctant("+y+x+z"), InvalidArgument);
  EXPECT_THROW(parseOctant("x"), InvalidArgument);
  EXPECT_EQ(sideName(2, 1, -1), "z+x-y");
  EXPECT_EQ(sideName(0, -1, 1), "x-y+z");
}

// A sphere: 4^n triangles while every side keeps two steps, valid disc topology at every level,
// boundary made of the three contours.
TEST(SurfacePatch, SphereLevelsAreValidDiscs) {
  const Geometry g = cube(64);
  const Vec3 c(30, 31, 29);
  const VolumeF32 v = test::makeStarVolume(g, c, [](const Vec3&) { return 26.0; });
  for (int level = 0; level <= 4; ++level) {
    SurfaceOptions o;
    o.planes = {30, 31, 29};
    o.iso = 500;
    o.level = level;
    const SurfaceResult r = extractSurface(v, o);
    const MeshTopology t = analyzeTopology(r.mesh, 1e-9);
    SCOPED_TRACE("level " + std::to_string(level));
    if (level <= 3) {
      EXPECT_EQ(t.faces, int64_t(1) << (2 * level));
    }
    EXPECT_LE(t.faces, int64_t(1) << (2 * level));
    EXPECT_TRUE(t.valid()) << "nonmanifold " << t.nonManifoldEdges << " misoriented " << t.misorientedEdges
                           << " degenerate " << t.degenerateTriangles << " duplicate " << t.duplicateTriangles;
    EXPECT_EQ(t.eulerCharacteristic(), 1);
    EXPECT_EQ(t.boundaryLoops, 1);
    EXPECT_EQ(t.components, 1);
    // The boundary is the three contours: every boundary vertex lies in one of the planes.
    ASSERT_EQ(r.vertexVoxels.size(), r.mesh.positions.size());
    std::map<std::pair<int32_t, int32_t>, int> uses;
    for (const auto& tri : r.mesh.triangles)
      for (int i = 0; i < 3; ++i) uses[{std::min(tri[i], tri[(i + 1) % 3]), std::max(tri[i], tri[(i + 1) % 3])}]++;
    for (const auto& [e, n] : uses)
      if (n == 1)
        for (int32_t vtx : {e.first, e.second}) {
          const Index3 p = r.vertexVoxels[static_cast<size_t>(vtx)];
          EXPECT_TRUE(p[0] == 30 || p[1] == 31 || p[2] == 29);
        }
    // Outward: normals point away from the centre, triangles counter-clockwise from outside.
    for (size_t i = 0; i < r.mesh.positions.size(); ++i)
      EXPECT_GT(r.mesh.normals[i].dot(r.mesh.positions[i] - c), 0.9 * (r.mesh.positions[i] - c).norm());
    // Down to triangles a few voxels wide every triangle faces outward; at level 4 (sides of about
    // two voxel steps) a few slivers of nearly collinear voxels may flip, well under the fold limit.
    int64_t backFacing = 0;
    for (const auto& tri : r.mesh.triangles) {
      const Vec3 a = r.mesh.positions[static_cast<size_t>(tri[0])], b = r.mesh.positions[static_cast<size_t>(tri[1])],
                 cc = r.mesh.positions[static_cast<size_t>(tri[2])];
      backFacing += (b - a).cross(cc - a).dot((a + b + cc) / 3 - c) <= 0;
    }
    ASSERT_EQ(r.octants.size(), 1u);
    EXPECT_EQ(r.octants[0].backFacingTriangles, backFacing);
    if (level <= 3) {
      EXPECT_EQ(backFacing, 0);
    }
    EXPECT_LT(r.octants[0].backFacingAreaFraction, 0.02);
    EXPECT_FALSE(r.octants[0].folded);
    ASSERT_EQ(static_cast<int>(r.levels.size()), level);
  }
}

// Vertices lie on the iso-surface: sub-voxel positions after refinement.
TEST(SurfacePatch, VerticesOnTheSphere) {
  const Geometry g = cube(48);
  const Vec3 c(23.3, 24.1, 22.7);
  const VolumeF32 v = test::makeStarVolume(g, c, [](const Vec3&) { return 17.5; });
  SurfaceOptions o;
  o.planes = {23, 24, 23};
  o.iso = 500;
  o.level = 3;
  o.octant = {-1, 1, -1};
  const SurfaceResult r = extractSurface(v, o);
  for (const Vec3& p : r.mesh.positions) EXPECT_NEAR((p - c).norm(), 17.5, 0.1);
}

// A small object: sides reach one step, the rules for 1, 2 and 3 unsplit sides apply; the mesh
// stays a valid disc with fewer than 4^n triangles, and a level with nothing left to split fails.
TEST(SurfacePatch, ShortSidesKeepTheMeshValid) {
  const Geometry g = cube(24);
  const Vec3 c(11, 12, 11);
  const VolumeF32 v = test::makeStarVolume(g, c, [](const Vec3& d) { return 5.0 + 1.5 * d[0]; });
  int64_t previous = 0;
  int level = 0;
  for (;; ++level) {
    SurfaceOptions o;
    o.planes = {11, 12, 11};
    o.iso = 500;
    o.level = level;
    SurfaceResult r;
    try {
      r = extractSurface(v, o);
    } catch (const DataError& e) {
      EXPECT_NE(std::string(e.what()).find("octant +x+y+z: level " + std::to_string(level) + " is too deep"),
                std::string::npos)
          << e.what();
      break;
    }
    const MeshTopology t = analyzeTopology(r.mesh, 1e-9);
    SCOPED_TRACE("level " + std::to_string(level));
    EXPECT_TRUE(t.valid());
    EXPECT_EQ(t.eulerCharacteristic(), 1);
    EXPECT_EQ(t.boundaryLoops, 1);
    EXPECT_GT(t.faces, previous);
    previous = t.faces;
    ASSERT_LT(level, 8);
  }
  EXPECT_GE(level, 3);
  EXPECT_LT(previous, int64_t(1) << (2 * (level - 1)));  // some triangle met a one-step side
}

// A noisy star-shaped object with anisotropic spacing and a rotated direction matrix: mean
// <= 0.5 voxel and 95th percentile <= 1 voxel at level 4, both ways, and at least 5x better than
// interpolating the same three contours without the image.
TEST(SurfaceAccuracy, NoisyRotatedStarBeatsGeometryOnly) {
  Geometry g;
  g.dims = {72, 72, 40};
  g.spacing = Vec3(0.8, 0.8, 1.4);
  g.direction = Eigen::AngleAxisd(0.35, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  g.origin = Vec3(-20, 10, 5);
  const Vec3 centerIndex(36, 35, 20);
  const Vec3 c = g.indexToWorld(Vec3(35.6, 35.3, 19.8));
  const test::RadialFunction star = [&g](const Vec3& d) {
    const Vec3 l = g.direction.transpose() * d;  // in the volume's axes
    return 20.0 + 3.0 * std::sin(3 * std::atan2(l[1], l[0])) * (1 - l[2] * l[2]) + 2.0 * l[2] * l[0];
  };
  const VolumeF32 v = test::makeStarVolume(g, c, star, 1.2, 40.0, 7);
  const TriMesh ref = test::makeStarMesh(c, star, 240);
  for (const OctantSigns& oct : {OctantSigns{1, 1, 1}, OctantSigns{-1, 1, -1}}) {
    SurfaceOptions o;
    o.planes = {36, 35, 20};
    o.iso = 500;
    o.level = 4;
    o.octant = oct;
    const SurfaceResult image = extractSurface(v, o);
    o.geometryOnly = true;
    const SurfaceResult base = extractSurface(v, o);
    const TwoWay ei = compare(image.mesh, ref, g, centerIndex, {oct}),
                 eb = compare(base.mesh, ref, g, centerIndex, {oct});
    SCOPED_TRACE(octantName(oct));
    EXPECT_TRUE(analyzeTopology(image.mesh, 1e-9).valid());
    EXPECT_LE(ei.toReference.mean, 0.5);
    EXPECT_LE(ei.toReference.p95, 1.0);
    EXPECT_LE(ei.fromReference.mean, 0.5);
    EXPECT_LE(ei.fromReference.p95, 1.0);
    EXPECT_GE(eb.toReference.mean + eb.fromReference.mean, 5 * (ei.toReference.mean + ei.fromReference.mean))
        << "image " << ei.toReference.mean << "/" << ei.fromReference.mean << " baseline " << eb.toReference.mean << "/"
        << eb.fromReference.mean;
  }
}

// Eight octants stitched: watertight, Euler characteristic 2, outward orientation, accurate.
TEST(SurfaceClosed, SphereIsWatertight) {
  const Geometry g = cube(56, Vec3(1.0, 0.9, 1.2));
  const Vec3 c = g.indexToWorld(Vec3(27.4, 28.2, 26.6));
  const test::RadialFunction r = [](const Vec3& d) { return 19.0 + 2.0 * d[2]; };
  const VolumeF32 v = test::makeStarVolume(g, c, r);
  SurfaceOptions o;
  o.planes = {27, 28, 27};
  o.iso = 500;
  o.level = 3;
  o.closed = true;
  const SurfaceResult res = extractSurface(v, o);
  const MeshTopology t = analyzeTopology(res.mesh, 1e-9);
  EXPECT_TRUE(t.watertight());
  EXPECT_EQ(t.eulerCharacteristic(), 2);
  EXPECT_EQ(t.components, 1);
  EXPECT_EQ(t.faces, 8 * 64);
  EXPECT_EQ(res.octants.size(), 8u);
  for (const OctantReport& rep : res.octants) EXPECT_FALSE(rep.folded) << octantName(rep.octant);
  double signedVolume = 0;
  for (const auto& tri : res.mesh.triangles)
    signedVolume +=
        res.mesh.positions[static_cast<size_t>(tri[0])].dot(
            res.mesh.positions[static_cast<size_t>(tri[1])].cross(res.mesh.positions[static_cast<size_t>(tri[2])])) /
        6;
  EXPECT_GT(signedVolume, 0);
  const TwoWay e =
      compare(res.mesh, test::makeStarMesh(c, r), g, Vec3(27, 28, 27),
              {{1, 1, 1}, {1, 1, -1}, {1, -1, 1}, {1, -1, -1}, {-1, 1, 1}, {-1, 1, -1}, {-1, -1, 1}, {-1, -1, -1}});
  EXPECT_LE(e.fromReference.mean, 1.0);  // level 3: 64 triangles per octant on a 20 mm sphere
}

// The finer mesh: every path voxel is a vertex; closed it stays watertight with Euler
// characteristic 2, a patch stays a disc whose boundary runs through every contour voxel, and it
// lies at least as close to the true surface as the coarse mesh.
TEST(SurfaceFine, EveryPathVoxelIsAVertex) {
  const Geometry g = cube(48, Vec3(1.0, 0.9, 1.2));
  const Vec3 c = g.indexToWorld(Vec3(23.4, 24.2, 22.6));
  const test::RadialFunction radius = [](const Vec3& d) { return 17.0 + 2.0 * d[2] + 1.5 * d[0] * d[1]; };
  const VolumeF32 v = test::makeStarVolume(g, c, radius);
  const TriMesh truth = test::makeStarMesh(c, radius);
  for (const bool closed : {true, false}) {
    SCOPED_TRACE(closed ? "closed" : "octant");
    SurfaceOptions o;
    o.planes = {23, 24, 23};
    o.iso = 500;
    o.level = 3;
    o.closed = closed;
    o.octant = {1, -1, 1};
    const SurfaceResult coarse = extractSurface(v, o);
    o.everyPathVoxel = true;
    const SurfaceResult fine = extractSurface(v, o);
    const MeshTopology t = analyzeTopology(fine.mesh, 1e-9);
    EXPECT_TRUE(t.valid()) << "nonmanifold " << t.nonManifoldEdges << " misoriented " << t.misorientedEdges
                           << " degenerate " << t.degenerateTriangles << " duplicate " << t.duplicateTriangles;
    EXPECT_EQ(t.components, 1);
    EXPECT_GT(fine.mesh.positions.size(), 3 * coarse.mesh.positions.size());
    std::set<Index3> vertexVoxels(fine.vertexVoxels.begin(), fine.vertexVoxels.end());
    int64_t contourVoxels = 0;
    for (const auto& [name, pts] : fine.sides) {
      contourVoxels += static_cast<int64_t>(pts.size()) - 1;
      for (const Index3& p : pts) EXPECT_TRUE(vertexVoxels.count(p)) << name;
    }
    if (closed) {
      EXPECT_TRUE(t.watertight());
      EXPECT_EQ(t.eulerCharacteristic(), 2);
    } else {
      EXPECT_EQ(t.eulerCharacteristic(), 1);
      EXPECT_EQ(t.boundaryLoops, 1);
      EXPECT_EQ(t.boundaryEdges, contourVoxels);  // the boundary is the three contours, voxel by voxel
    }
    for (const OctantReport& rep : fine.octants)
      EXPECT_FALSE(rep.folded) << octantName(rep.octant) << " " << rep.backFacingAreaFraction;
    std::vector<OctantSigns> octs;
    for (const OctantReport& rep : fine.octants) octs.push_back(rep.octant);
    const TwoWay ef = compare(fine.mesh, truth, g, Vec3(23, 24, 23), octs),
                 ec = compare(coarse.mesh, truth, g, Vec3(23, 24, 23), octs);
    EXPECT_LE(ef.toReference.mean, 0.5);
    EXPECT_LE(ef.toReference.p95, 1.0);
    EXPECT_LE(ef.fromReference.mean, ec.fromReference.mean);
    EXPECT_LE(ef.toReference.mean, ec.toReference.mean);
  }
}

// The triangles of each octant (in the mesh's order) as world-position triples.
std::vector<std::vector<std::array<Vec3, 3>>> trianglesByOctant(const SurfaceResult& r) {
  std::vector<std::vector<std::array<Vec3, 3>>> out;
  size_t t = 0;
  for (const OctantReport& rep : r.octants) {
    out.emplace_back();
    for (int64_t i = 0; i < rep.triangles; ++i, ++t) {
      const auto& tri = r.mesh.triangles[t];
      out.back().push_back({r.mesh.positions[static_cast<size_t>(tri[0])],
                            r.mesh.positions[static_cast<size_t>(tri[1])],
                            r.mesh.positions[static_cast<size_t>(tri[2])]});
    }
  }
  return out;
}

// Stylus editing of one side of a closed surface: only the two octants sharing it change, the
// side passes through the given point, the mesh stays watertight, and the result equals a fresh
// extraction with the point as the side's via. A bad edit leaves the surface as it was.
TEST(SurfaceEdit, OneSideReSubdividesOnlyItsTwoOctants) {
  const Geometry g = cube(48, Vec3(1.0, 0.9, 1.2));
  const Vec3 c = g.indexToWorld(Vec3(23.4, 24.2, 22.6));
  const test::RadialFunction radius = [](const Vec3& d) { return 17.0 + 2.0 * d[2] + 1.5 * d[0] * d[1]; };
  const VolumeF32 v = test::makeStarVolume(g, c, radius);
  SurfaceOptions o;
  o.planes = {23, 24, 23};
  o.iso = 500;
  o.level = 3;
  o.closed = true;
  SurfaceExtraction extraction(v, o);
  const SurfaceResult before = extraction.result();
  // A point of plane z = 23 in quadrant x+, y+, three voxels inside the surface along the diagonal.
  Index3 via{0, 0, 23};
  for (int64_t k = 1;; ++k)
    if (v(23 + k, 24 + k, 23) < 500) {
      via = {23 + k - 3, 24 + k - 3, 23};
      break;
    }
  const SurfaceEditReport rep = extraction.editSide("z+x+y", {via});
  const SurfaceResult& after = extraction.result();
  ASSERT_EQ(rep.octants.size(), 2u);
  EXPECT_EQ(rep.octants[0], (OctantSigns{1, 1, 1}));
  EXPECT_EQ(rep.octants[1], (OctantSigns{1, 1, -1}));
  EXPECT_GT(rep.paths, 0);
  const auto side =
      std::find_if(after.sides.begin(), after.sides.end(), [](const auto& sd) { return sd.first == "z+x+y"; });
  ASSERT_NE(side, after.sides.end());
  EXPECT_NE(std::find(side->second.begin(), side->second.end(), via), side->second.end());
  const auto old = trianglesByOctant(before), now = trianglesByOctant(after);
  ASSERT_EQ(now.size(), 8u);
  for (size_t n = 0; n < 8; ++n) {
    const bool edited = after.octants[n].octant == rep.octants[0] || after.octants[n].octant == rep.octants[1];
    SCOPED_TRACE(octantName(after.octants[n].octant));
    if (edited)
      EXPECT_NE(now[n], old[n]);
    else
      EXPECT_EQ(now[n], old[n]);  // bit for bit
  }
  const MeshTopology t = analyzeTopology(after.mesh, 1e-9);
  EXPECT_TRUE(t.watertight());
  EXPECT_EQ(t.eulerCharacteristic(), 2);
  // The same as extracting with the point from the start.
  SurfaceOptions withVia = o;
  withVia.via = {{"z+x+y", {via}}};
  const SurfaceResult fresh = extractSurface(v, withVia);
  EXPECT_EQ(fresh.mesh.positions, after.mesh.positions);
  EXPECT_EQ(fresh.mesh.triangles, after.mesh.triangles);
  // Bad edits throw and change nothing.
  EXPECT_THROW(extraction.editSide("z+x+q", {via}), InvalidArgument);
  EXPECT_THROW(extraction.editSide("z-x+y", {Index3{30, 30, 23}}), InvalidArgument);  // not in quadrant x-
  EXPECT_EQ(extraction.result().mesh.positions, after.mesh.positions);
  EXPECT_EQ(extraction.result().mesh.triangles, after.mesh.triangles);
  // Removing the points restores the original surface.
  extraction.editSide("z+x+y", {});
  EXPECT_EQ(extraction.result().mesh.positions, before.mesh.positions);
  EXPECT_EQ(extraction.result().mesh.triangles, before.mesh.triangles);
}

TEST(SurfaceBadInput, ClearErrors) {
  const Geometry g = cube(32);
  const VolumeF32 v = test::makeStarVolume(g, Vec3(15, 15, 15), [](const Vec3&) { return 9.0; });
  SurfaceOptions o;
  o.planes = {15, 15, 15};
  o.iso = 500;
  o.level = 1;
  auto message = [&](const SurfaceOptions& opt) {
    try {
      extractSurface(v, opt);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  SurfaceOptions bad = o;
  bad.planes = {15, 40, 15};
  EXPECT_THROW(extractSurface(v, bad), InvalidArgument);
  bad = o;
  bad.corners[2] = Index3{16, 25, 15};  // +y corner off its line
  EXPECT_NE(message(bad).find("corner +y (16,25,15) is not on its half-line"), std::string::npos) << message(bad);
  EXPECT_THROW(extractSurface(v, bad), InvalidArgument);
  bad = o;
  bad.iso = 2000;  // nothing reaches it: the centre is "outside" and so is everything
  EXPECT_THROW(extractSurface(v, bad), DataError);
  const VolumeF32 full = test::makeStarVolume(g, Vec3(15, 15, 15), [](const Vec3&) { return 100.0; });
  try {
    extractSurface(full, o);
    FAIL() << "no error";
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find("half-line +x"), std::string::npos) << e.what();
  }
  bad = o;
  bad.via = {{"z+x+y", {Index3{3, 3, 15}}}};  // not in the quadrant
  EXPECT_NE(message(bad).find("side z+x+y: point (3,3,15) is not in its quadrant"), std::string::npos) << message(bad);
}

TEST(SurfaceCostTest, FloorAndIsoTerm) {
  const Geometry g = cube(32);
  const VolumeF32 v = test::makeStarVolume(g, Vec3(15, 15, 15), [](const Vec3&) { return 9.0; });
  const SurfaceCost c = computeSurfaceCost(v, 500);
  float lo = 1e9f, hi = 0;
  for (float x : c.node) lo = std::min(lo, x), hi = std::max(hi, x);
  EXPECT_GE(lo, 0.05f);
  EXPECT_LE(hi, 0.05f + 0.3f + 1.0f + 1e-5f);
  // On the surface (r = 9) cheap, at the centre and far outside the full iso penalty.
  EXPECT_LT(c.node[static_cast<size_t>(g.linear(24, 15, 15))], 0.2f);
  EXPECT_GT(c.node[static_cast<size_t>(g.linear(15, 15, 15))], 1.3f);
  EXPECT_GT(c.node[static_cast<size_t>(g.linear(1, 1, 1))], 1.3f);
  EXPECT_NEAR(otsuThreshold(v), 500, 60);
  SurfaceCostOptions bad;
  bad.floor = 0;
  EXPECT_THROW(computeSurfaceCost(v, 500, bad), InvalidArgument);
}

}  // namespace
}  // namespace vs
