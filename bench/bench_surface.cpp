// Surface extraction benchmarks and accuracy (thesis 4.3.1, Table 1; issue 15). Not tests.
//   bench_surface table1 [HEAD]     Table 1 re-measured: the head resampled so that one octant is
//                                   32^3, 64x32x32, 64x64x32, 64^3; levels 1-4, 18-connected; nodes,
//                                   edges, triangles, seconds beside the thesis's SGI Octane figures.
//   bench_surface accuracy VOLUME ISO PLANES OCTANT [LEVELS]
//                                   per level, distances mesh -> reference and reference -> mesh in
//                                   voxels of the finest spacing, image-driven vs the geometry-only
//                                   baseline. Reference: vtkFlyingEdges3D of the same iso-value
//                                   (meshops), its vertices in the octant that are the outermost
//                                   crossing along their ray from the centre (the surface a patch
//                                   bounded by the three contours describes; inner surfaces such as
//                                   sinuses, and overhangs, are not scored). Last columns: the
//                                   finer mesh over every path voxel (SurfaceOptions::everyPathVoxel).
//   bench_surface timing VOLUME ISO PLANES LEVEL [closed] [edit]
//                                   one run, seconds per stage and CPU seconds; `edit`: then a
//                                   stylus edit of one side of plane z and its undo (editSide).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>

#include "io/volume_io.h"
#include "meshops/isosurface.h"
#include "surface/mesh_quality.h"
#include "surface/surface.h"
#include "surface/surface_cost.h"

namespace {

using Clock = std::chrono::steady_clock;

vs::Index3 parseIndex(const std::string& s) {
  vs::Index3 p{0, 0, 0};
  if (std::sscanf(s.c_str(), "%ld,%ld,%ld", &p[0], &p[1], &p[2]) != 3) throw vs::UsageError("expected x,y,z: " + s);
  return p;
}

// Trilinear resampling to new dims over the same physical extent.
vs::VolumeF32 resample(const vs::VolumeF32& v, const vs::Index3& dims) {
  vs::Geometry g = v.geometry();
  g.dims = dims;
  for (int a = 0; a < 3; ++a) g.spacing[a] = v.geometry().spacing[a] * double(v.dims()[a] - 1) / double(dims[a] - 1);
  vs::VolumeF32 out(g);
  for (int64_t z = 0; z < dims[2]; ++z)
    for (int64_t y = 0; y < dims[1]; ++y)
      for (int64_t x = 0; x < dims[0]; ++x) {
        const vs::Vec3 p(double(x) * double(v.dims()[0] - 1) / double(dims[0] - 1),
                         double(y) * double(v.dims()[1] - 1) / double(dims[1] - 1),
                         double(z) * double(v.dims()[2] - 1) / double(dims[2] - 1));
        out(x, y, z) = static_cast<float>(vs::sampleTrilinear(v, p));
      }
  return out;
}

int accuracy(const std::string& path, double iso, const vs::Index3& planes, const std::string& octant, int maxLevel) {
  const vs::VolumeF32 v = vs::toFloat(vs::readVolume(path));
  const double h = v.geometry().spacing.minCoeff();
  vs::IsoSurfaceOptions io;
  io.iso = iso;
  io.largestComponentOnly = false;
  const vs::TriMesh ref = vs::extractIsoSurface(v, io);
  const vs::OctantSigns s = vs::parseOctant(octant);
  const vs::Vec3 o{double(planes[0]), double(planes[1]), double(planes[2])};
  const std::vector<vs::Vec3> refPts = vs::outermostInOctant(ref, v, iso, o, s);
  const vs::MeshDistance toRef(ref);
  std::printf(
      "%s, iso %g, planes %ld,%ld,%ld, octant %s: reference %zu triangles, %zu scored vertices; voxels of %.3g mm\n",
      path.c_str(), iso, planes[0], planes[1], planes[2], octant.c_str(), ref.triangles.size(), refPts.size(), h);
  std::printf(
      "| level | triangles | mesh->ref mean | p95 | ref->mesh mean | p95 | baseline mesh->ref mean | p95 | baseline "
      "ref->mesh mean | p95 | ratio of means | every-voxel triangles | mesh->ref mean | p95 | ref->mesh mean | p95 "
      "|\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (int level = 1; level <= maxLevel; ++level) {
    vs::DistanceSummary d[3][2];  // image-driven, geometry-only baseline, every path voxel
    int64_t tris[3] = {0, 0, 0};
    for (int base = 0; base < 3; ++base) {
      vs::SurfaceOptions opt;
      opt.planes = planes;
      opt.iso = iso;
      opt.level = level;
      opt.octant = s;
      opt.geometryOnly = base == 1;
      opt.everyPathVoxel = base == 2;
      const vs::SurfaceResult r = vs::extractSurface(v, opt);
      tris[base] = static_cast<int64_t>(r.mesh.triangles.size());
      std::vector<double> a = toRef.distances(vs::sampleMesh(r.mesh, h / 2));
      for (double& x : a) x /= h;
      std::vector<double> b = vs::MeshDistance(r.mesh).distances(refPts);
      for (double& x : b) x /= h;
      d[base][0] = vs::summarize(a);
      d[base][1] = vs::summarize(b);
    }
    std::printf(
        "| %d | %ld | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.3f | %.1fx | %ld | %.3f | %.3f | %.3f | %.3f "
        "|\n",
        level, tris[0], d[0][0].mean, d[0][0].p95, d[0][1].mean, d[0][1].p95, d[1][0].mean, d[1][0].p95, d[1][1].mean,
        d[1][1].p95, (d[1][0].mean + d[1][1].mean) / (d[0][0].mean + d[0][1].mean), tris[2], d[2][0].mean, d[2][0].p95,
        d[2][1].mean, d[2][1].p95);
  }
  return 0;
}

// CPU seconds of the whole process, all threads: on a loaded shared machine the wall time
// measures the other users, while an idle machine needs at most this long (less on two cores).
double cpuSeconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

int table1(const std::string& path) {
  const vs::VolumeF32 head = vs::toFloat(vs::readVolume(path));
  const double iso = vs::otsuThreshold(head);
  struct Row {
    vs::Index3 octant;
    double thesis[4];
    int thesisTris[4];
  };
  const Row rows[] = {{{32, 32, 32}, {0.07, 0.27, 0.85, 2.68}, {4, 16, 58, 202}},
                      {{64, 32, 32}, {0.68, 2.08, 4.32, 9.31}, {4, 16, 64, 250}},
                      {{64, 64, 32}, {3.03, 7.48, 12.51, 22.95}, {4, 16, 64, 256}},
                      {{64, 64, 64}, {7.12, 16.86, 28.16, 47.97}, {4, 16, 64, 256}}};
  std::printf(
      "%s resampled so that the +x+y+z octant from the centre has the Table 1 size; iso %g (Otsu); 18-connected\n",
      path.c_str(), iso);
  std::printf(
      "| octant | level | triangles (thesis) | 3D paths | nodes settled | edges scanned | seconds subdivision | "
      "seconds total | CPU seconds | thesis seconds | speed-up |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const Row& row : rows) {
    const vs::Index3 dims{2 * row.octant[0], 2 * row.octant[1], 2 * row.octant[2]};
    const vs::VolumeF32 v = resample(head, dims);
    for (int level = 1; level <= 4; ++level) {
      vs::SurfaceOptions opt;
      opt.planes = {row.octant[0] - 1, row.octant[1] - 1, row.octant[2] - 1};
      opt.iso = iso;
      opt.level = level;
      opt.connectivity = 18;
      const auto t0 = Clock::now();
      const double cpu0 = cpuSeconds();
      const vs::SurfaceResult r = vs::extractSurface(v, opt);
      const double total = std::chrono::duration<double>(Clock::now() - t0).count(), cpu = cpuSeconds() - cpu0;
      int64_t paths = 0, nodes = 0, edges = 0;
      double sub = 0;
      for (const auto& l : r.levels)
        paths += l.paths, nodes += l.nodesSettled, edges += l.edgesScanned, sub += l.seconds;
      std::printf("| %ldx%ldx%ld | %d | %zu (%d) | %ld | %ld | %ld | %.3f | %.3f | %.3f | %.2f | %.0fx |\n",
                  row.octant[0], row.octant[1], row.octant[2], level, r.mesh.triangles.size(),
                  row.thesisTris[level - 1], paths, nodes, edges, sub, total, cpu, row.thesis[level - 1],
                  row.thesis[level - 1] / total);
    }
  }
  return 0;
}

int timing(const std::string& path, double iso, const vs::Index3& planes, int level, bool closed, bool edit) {
  const vs::VolumeF32 v = vs::toFloat(vs::readVolume(path));
  vs::SurfaceOptions opt;
  opt.planes = planes;
  opt.iso = iso;
  opt.level = level;
  opt.closed = closed;
  const double cpu0 = cpuSeconds();
  vs::SurfaceExtraction extraction(v, opt);
  const double cpu = cpuSeconds() - cpu0;
  const vs::SurfaceResult& r = extraction.result();
  double sub = 0;
  for (const auto& l : r.levels) sub += l.seconds;
  std::printf(
      "%s %s level %d: %zu triangles; wall seconds: cost %.3f, sides %.3f, subdivision (sum over octants) %.3f, "
      "total %.3f; CPU seconds (all threads) %.3f\n",
      path.c_str(), closed ? "closed" : "octant", level, r.mesh.triangles.size(), r.secondsCost, r.secondsSides, sub,
      r.secondsTotal, cpu);
  for (const vs::OctantReport& o : r.octants)
    std::printf(
        "  octant %s: fold check %ld of %ld rays (%.1f%%)%s, %ld meet another object; back-facing area %.1f%%\n",
        vs::octantName(o.octant).c_str(), o.foldedRays, o.foldCheckRays, 100 * o.foldedRayFraction,
        o.folded ? ", FOLDED" : "", o.otherObjectRays, 100 * o.backFacingAreaFraction);
  if (edit) {  // stylus edit of side z+x+y: through the voxel of its path nearest its middle, moved one
               // voxel towards the centre (a different path), then back
    const auto side =
        std::find_if(r.sides.begin(), r.sides.end(), [](const auto& s) { return s.first.rfind("z", 0) == 0; });
    vs::Index3 p = side->second[side->second.size() / 2];
    for (int a = 0; a < 2; ++a) p[a] += p[a] > planes[a] ? -1 : p[a] < planes[a] ? 1 : 0;
    for (int round = 0; round < 2; ++round) {
      const double c0 = cpuSeconds();
      const vs::SurfaceEditReport e =
          extraction.editSide(side->first, round == 0 ? std::vector<vs::Index3>{p} : std::vector<vs::Index3>{});
      std::printf("edit %s %s: %zu octants re-subdivided, %ld paths, %.3f s wall, %.3f s CPU\n", side->first.c_str(),
                  round == 0 ? "through one point" : "back to the plain live-wire", e.octants.size(), e.paths,
                  e.seconds, cpuSeconds() - c0);
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "table1" && argc >= 3) return table1(argv[2]);
    if (mode == "accuracy" && argc >= 6)
      return accuracy(argv[2], std::atof(argv[3]), parseIndex(argv[4]), argv[5], argc > 6 ? std::atoi(argv[6]) : 5);
    if (mode == "timing" && argc >= 6) {
      bool closed = false, edit = false;
      for (int i = 6; i < argc; ++i) (std::string(argv[i]) == "closed" ? closed : edit) |= true;
      return timing(argv[2], std::atof(argv[3]), parseIndex(argv[4]), std::atoi(argv[5]), closed, edit);
    }
    std::fprintf(stderr,
                 "usage: bench_surface table1 HEAD | accuracy VOLUME ISO X,Y,Z OCTANT [LEVELS] | timing VOLUME ISO "
                 "X,Y,Z LEVEL [closed] [edit]\n");
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_surface: %s\n", e.what());
    return 1;
  }
}
