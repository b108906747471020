// Volume cutting (issue 14): robustness campaign and speed figures. Not tests.
//   bench_cut robustness VOLUME ISO LOOPS SEED
//       LOOPS random closed loops on the outer skin of the object's largest surface component (a
//       vertex whose outward ray leaves the volume without meeting the object): a random centre
//       vertex, a radius of 8-40 mm, 3-12 skin points at that distance in angular order around the
//       centre's normal, each moved up to 1 mm as a hand would. Each loop must give
//       a valid split (both parts non-empty, every object voxel labelled) or a clear error
//       (vs::DataError / InvalidArgument with a message); anything else - a silent empty or
//       whole-object part, another exception - is a failure. One JSON line per loop, then a
//       summary line; exit 1 when any loop failed.
//   bench_cut speed VOLUME ISO "x,y,z;x,y,z;..." OUTDIR
//       mesh extraction (vtkFlyingEdges3D through meshops, every component) and features+graph;
//       contour updates while placing the points: for each segment the search is seeded at one
//       point and the cursor moves along the segment's final path vertex by vertex, one
//       MeshLiveWire::pathTo per step (seconds each); the whole cut after the last point
//       (cutting surface + split). Writes OUTDIR/mesh.ply, OUTDIR/queries.txt (seed target per
//       line, for the same searches in VTK), OUTDIR/volume.f32 (raw float32, x fastest) and prints
//       one JSON line. bench/cut_vs_vtk.py runs VTK's peers on the same files in the same run.
//   bench_cut phantom SIZE
//       the whole cut after the last point on the project's head phantom at SIZE^3 (1 mm), the
//       demo's nose points scaled to the size: one JSON line.
//   bench_cut family SEED SCALE [wg wc wp wd]
//       one head of the randomised family (src/phantom/head_family.h): the nose, the ear and a
//       forehead patch cut with the truth's loops; per cut the part removed / taken from the
//       rest, the forehead surface's mean distance to the skull, the energy's shares, seconds.
//       One JSON line; bench/cut_head_family.py sweeps seeds. With DUMPDIR: volume.i16, truth.u8
//       and <cut>_cut.u8 there (raw, x fastest, dims in the JSON line) for looking at slices.
#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <map>
#include <random>
#include <string>

#include "cutting/cut.h"
#include "cutting/cut_contour_session.h"
#include "io/mesh_io.h"
#include "io/volume_io.h"
#include "meshops/isosurface.h"
#include "phantom/head_family.h"
#include "phantom/phantom.h"
#include "util/error.h"

namespace {

using Clock = std::chrono::steady_clock;
using vs::Vec3;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }
// CPU seconds of this process (all threads): on the shared, overloaded machine wall time mostly
// measures the other processes; the speed figures are CPU time, wall time is reported beside.
double cpuNow() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

// The whole cut after the last point, step by step: contour (the closing segment included),
// cutting surface, split; CPU seconds each.
struct AfterLastPoint {
  double contour = 0, surface = 0, split = 0;
  int64_t cutVoxels = 0;
};
AfterLastPoint cutAfterLastPoint(const vs::VolumeF32& v, const vs::CutMesh& mesh, const vs::CutOptions& o) {
  AfterLastPoint a;
  double c0 = cpuNow();
  std::vector<int64_t> anchors;
  for (const Vec3& p : o.pointsIndex)
    anchors.push_back(
        vs::snapToMesh(mesh.mesh, mesh.features, v.geometry().indexToWorld(p), o.snapRadiusMm, "point").vertex);
  const vs::MeshContour contour = vs::closedContour(mesh.graph, anchors);
  std::vector<Vec3> contourMm;
  for (int64_t k : contour.vertices) contourMm.push_back(mesh.mesh.positions[size_t(k)]);
  a.contour = cpuNow() - c0;
  c0 = cpuNow();
  const vs::CuttingSurface surface = vs::buildCuttingSurface(v, o.iso, contourMm, o.surface);
  a.surface = cpuNow() - c0;
  c0 = cpuNow();
  a.cutVoxels = vs::splitVolume(v, o.iso, surface).cutVoxels;
  a.split = cpuNow() - c0;
  return a;
}

// The viewer's cut preview while the points are placed (issue 26): the core's CutContourSession as
// the viewer's cut tool calls it. Point k is clicked, then the cursor moves towards point k+1
// along the path a hand would follow on the surface (the vertices of the unmasked segment from
// k to k+1, given as continuous indices, so each is snapped as a stylus point is), one preview per
// position; CPU ms each. Every preview is checked against cutContour from scratch on the same
// points (outside the timing), which also gives the cost of the from-scratch preview per move.
struct HoverFigures {
  std::vector<double> open, closed, clicks, scratch;  // ms
  std::vector<double> byKind[5];                      // closed ones: read-out, retry, from scratch, same vertex, error
  int64_t mismatches = 0, errors = 0;
  vs::CutContourSessionStats stats;
};
HoverFigures previewHovers(const vs::Geometry& g, const vs::CutMesh& mesh, const std::vector<Vec3>& pts,
                           double snapMm) {
  HoverFigures f;
  vs::CutContourSession s(mesh, g, snapMm);
  std::vector<uint8_t> all(mesh.mesh.positions.size(), 1);
  std::vector<Vec3> placed;
  for (size_t k = 0; k < pts.size(); ++k) {
    double c0 = cpuNow();
    placed.push_back(pts[k]);
    s.setPoints(placed);
    try {
      s.preview(std::nullopt);
    } catch (const vs::Error&) {
    }
    f.clicks.push_back(1e3 * (cpuNow() - c0));
    if (k + 1 == pts.size()) break;
    const int64_t from = s.snapVertex(pts[k]), to = s.snapVertex(pts[k + 1]);
    if (from < 0 || to < 0) continue;
    const vs::Path way = vs::contourSegmentSearch(mesh.graph, from, all).pathTo(to);
    for (int64_t cursor : way.nodes) {
      if (cursor == from) continue;
      const Vec3 hover = g.worldToIndex(mesh.mesh.positions[size_t(cursor)]);
      std::optional<vs::CutContour> got;
      const vs::CutContourSessionStats before = s.stats();
      c0 = cpuNow();
      bool error = false;
      try {
        const vs::CutContourPreview p = s.preview(hover);
        if (p.closed) got = p.loop;
      } catch (const vs::Error&) {
        error = true;
      }
      const double ms = 1e3 * (cpuNow() - c0);
      (placed.size() >= 2 ? f.closed : f.open).push_back(ms);
      const vs::CutContourSessionStats& after = s.stats();
      const int kind = error                                          ? 4
                       : after.readOuts > before.readOuts             ? 0
                       : after.closingRetries > before.closingRetries ? 1
                       : after.fromScratch > before.fromScratch       ? 2
                                                                      : 3;
      f.errors += error;
      if (placed.size() >= 2) f.byKind[kind].push_back(ms);
      if (placed.size() < 2) continue;
      std::vector<Vec3> withHover = placed;
      withHover.push_back(hover);
      c0 = cpuNow();
      std::optional<vs::CutContour> want;
      try {
        want = vs::cutContour(mesh, g, withHover, snapMm);
      } catch (const vs::Error&) {
      }
      f.scratch.push_back(1e3 * (cpuNow() - c0));
      f.mismatches += got.has_value() != want.has_value() || (got && got->contour.vertices != want->contour.vertices);
    }
  }
  f.stats = s.stats();
  return f;
}

double percentile(std::vector<double> v, double p);

std::string hoverJson(const HoverFigures& f) {
  char kinds[512];
  const char* names[5] = {"read_out", "closing_retry", "from_scratch", "same_vertex", "error"};
  std::string byKind;
  for (int k = 0; k < 5; ++k) {
    std::snprintf(kinds, sizeof kinds, "%s\"%s\":[%zu,%.3f,%.3f]", k ? "," : "", names[k], f.byKind[k].size(),
                  percentile(f.byKind[k], 50), percentile(f.byKind[k], 100));
    byKind += kinds;
  }
  char buf[1536];
  const vs::CutContourSessionStats& st = f.stats;
  std::snprintf(
      buf, sizeof buf,
      "{\"closed_hovers\":%zu,\"cpu_ms_median\":%.3f,\"cpu_ms_p95\":%.3f,\"cpu_ms_max\":%.3f,"
      "\"open_hovers\":%zu,\"open_cpu_ms_median\":%.3f,\"open_cpu_ms_max\":%.3f,"
      "\"clicks\":%zu,\"click_cpu_ms_median\":%.3f,\"click_cpu_ms_max\":%.3f,"
      "\"from_scratch_cpu_ms_median\":%.3f,\"from_scratch_cpu_ms_p95\":%.3f,\"mismatches\":%lld,"
      "\"errors\":%lld,\"read_outs\":%lld,\"closing_retries\":%lld,\"from_scratch\":%lld,\"same_vertex\":%lld,"
      "\"by_kind_n_median_max\":{%s}}",
      f.closed.size(), percentile(f.closed, 50), percentile(f.closed, 95), percentile(f.closed, 100), f.open.size(),
      percentile(f.open, 50), percentile(f.open, 100), f.clicks.size(), percentile(f.clicks, 50),
      percentile(f.clicks, 100), percentile(f.scratch, 50), percentile(f.scratch, 95), (long long)f.mismatches,
      (long long)f.errors, (long long)st.readOuts, (long long)st.closingRetries, (long long)st.fromScratch,
      (long long)st.cached, byKind.c_str());
  return buf;
}

vs::VolumeF32 load(const std::string& path) { return vs::toFloat(vs::readVolume(path)); }

std::string jsonEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    out += c >= 0 && c < 32 ? ' ' : c;
  }
  return out;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(p / 100.0 * double(v.size() - 1) + 0.5))];
}

// True when the ray from vertex i along its outward normal leaves the volume without meeting the
// object again: the vertex is on the outer skin, not on an inner surface (sinus, ventricle, sulcus).
bool onOuterSkin(const vs::VolumeF32& v, double iso, const vs::TriMesh& mesh,
                 const std::vector<Eigen::Vector3d>& normals, int64_t i) {
  const vs::Geometry& g = v.geometry();
  const double step = g.spacing.minCoeff();
  for (double d = 2 * step;; d += step) {
    const Vec3 c = g.worldToIndex(mesh.positions[size_t(i)] + d * normals[size_t(i)]);
    const vs::Index3 k = vs::roundIndex(c);
    if (!g.contains(k)) return true;
    if (v(k[0], k[1], k[2]) >= iso) return false;
  }
}

// Points on the outer skin at about `radius` mm from vertex `centre`, in angular order around the
// mean normal near the centre; empty when the band holds too few such vertices.
std::vector<Vec3> loopAround(const vs::VolumeF32& v, double iso, const vs::TriMesh& mesh,
                             const std::vector<Eigen::Vector3d>& normals, int64_t centre, double radius, int count,
                             std::mt19937_64& rng) {
  if (!onOuterSkin(v, iso, mesh, normals, centre)) return {};
  const Vec3 c = mesh.positions[size_t(centre)];
  Vec3 normalSum = Vec3::Zero();
  std::vector<int64_t> band;
  for (size_t i = 0; i < mesh.positions.size(); ++i) {
    const double d = (mesh.positions[i] - c).norm();
    if (d < 0.5 * radius) normalSum += normals[i];
    if (std::abs(d - radius) < 0.75 && onOuterSkin(v, iso, mesh, normals, int64_t(i))) band.push_back(int64_t(i));
  }
  if (band.size() < size_t(3 * count) || normalSum.norm() == 0) return {};
  const Vec3 n = normalSum.normalized(), u = n.unitOrthogonal(), w = n.cross(u);
  std::uniform_real_distribution<double> unit(0, 1);
  const double phase = 2 * M_PI * unit(rng);
  std::vector<Vec3> points;
  for (int k = 0; k < count; ++k) {
    const double target = phase + 2 * M_PI * (k + 0.3 * (unit(rng) - 0.5)) / count;
    int64_t best = -1;
    double bestGap = 1e300;
    for (int64_t i : band) {
      const Vec3 r = mesh.positions[size_t(i)] - c;
      const double gap = std::abs(std::remainder(std::atan2(r.dot(w), r.dot(u)) - target, 2 * M_PI));
      if (gap < bestGap) bestGap = gap, best = i;
    }
    Vec3 jitter(unit(rng) - 0.5, unit(rng) - 0.5, unit(rng) - 0.5);
    points.push_back(mesh.positions[size_t(best)] + 2.0 / std::sqrt(3.0) * jitter);  // <= 1 mm
  }
  return points;
}

int robustness(const std::string& path, double iso, int loops, uint64_t seed) {
  const vs::VolumeF32 v = load(path);
  const vs::Geometry& g = v.geometry();
  vs::IsoSurfaceOptions io;
  io.iso = iso;
  io.largestComponentOnly = true;
  auto t0 = Clock::now();
  const vs::CutMesh mesh = vs::prepareCutMesh(v, vs::extractIsoSurface(v, io));
  std::printf("{\"volume\":\"%s\",\"iso\":%g,\"vertices\":%zu,\"triangles\":%zu,\"mesh_seconds\":%.2f}\n",
              jsonEscape(path).c_str(), iso, mesh.mesh.positions.size(), mesh.mesh.triangles.size(), since(t0));
  int64_t objectVoxels = 0;
  for (int64_t i = 0; i < g.voxelCount(); ++i) objectVoxels += v.data()[i] >= iso;
  const std::vector<Eigen::Vector3d> normals = vs::vertexNormals(mesh.mesh);
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<int64_t> vertex(0, int64_t(mesh.mesh.positions.size()) - 1);
  std::uniform_real_distribution<double> radius(8, 40);
  std::uniform_int_distribution<int> count(3, 12);
  int valid = 0, errors = 0, failures = 0;
  std::map<std::string, int> errorKinds;
  std::vector<double> seconds;
  for (int loop = 0; loop < loops; ++loop) {
    std::vector<Vec3> pts;
    double r = 0;
    while (pts.empty()) pts = loopAround(v, iso, mesh.mesh, normals, vertex(rng), r = radius(rng), count(rng), rng);
    vs::CutOptions o;
    o.iso = iso;
    for (const Vec3& p : pts) o.pointsIndex.push_back(g.worldToIndex(p));
    std::string outcome, message;
    t0 = Clock::now();
    try {
      const vs::CutResult res = vs::cutOnMesh(v, mesh, o);
      const bool partition = res.split.cutVoxels + res.split.keptVoxels == objectVoxels;
      if (res.split.cutVoxels > 0 && res.split.keptVoxels > 0 && partition) {
        outcome = "valid";
        ++valid;
        message = "cut " + std::to_string(res.split.cutVoxels) + " voxels, contour " +
                  std::to_string(res.contour.vertices.size()) + " vertices";
      } else {
        outcome = "failure";
        ++failures;
        message = "cut " + std::to_string(res.split.cutVoxels) + ", kept " + std::to_string(res.split.keptVoxels) +
                  (partition ? "" : ", labels do not cover the object");
      }
    } catch (const vs::DataError& e) {
      outcome = "error", message = e.what(), ++errors;
    } catch (const vs::InvalidArgument& e) {
      outcome = "error", message = e.what(), ++errors;
    } catch (const std::exception& e) {
      outcome = "failure", message = std::string("unexpected exception: ") + e.what(), ++failures;
    }
    seconds.push_back(since(t0));
    if (outcome == "error") ++errorKinds[message.substr(0, std::min<size_t>(message.size(), 48))];
    std::printf(
        "{\"loop\":%d,\"points\":%zu,\"radius_mm\":%.1f,\"outcome\":\"%s\",\"message\":\"%s\",\"seconds\":%.2f}\n",
        loop, pts.size(), r, outcome.c_str(), jsonEscape(message).c_str(), seconds.back());
    std::fflush(stdout);
  }
  std::printf(
      "{\"summary\":true,\"loops\":%d,\"valid\":%d,\"clear_errors\":%d,\"failures\":%d,\"median_seconds\":%.2f,"
      "\"error_kinds\":{",
      loops, valid, errors, failures, percentile(seconds, 50));
  bool first = true;
  for (const auto& [k, n] : errorKinds) {
    std::printf("%s\"%s\":%d", first ? "" : ",", jsonEscape(k).c_str(), n);
    first = false;
  }
  std::printf("}}\n");
  return failures > 0 ? 1 : 0;
}

std::vector<Vec3> parsePoints(const std::string& s) {
  std::vector<Vec3> out;
  size_t start = 0;
  while (start < s.size()) {
    const size_t end = s.find(';', start);
    const std::string item = s.substr(start, end == std::string::npos ? std::string::npos : end - start);
    Vec3 p;
    if (std::sscanf(item.c_str(), "%lf,%lf,%lf", &p.x(), &p.y(), &p.z()) != 3)
      throw vs::InvalidArgument("bad point '" + item + "'");
    out.push_back(p);
    if (end == std::string::npos) break;
    start = end + 1;
  }
  return out;
}

int speed(const std::string& path, double iso, const std::string& points, const std::string& outDir) {
  const vs::VolumeF32 v = load(path);
  const vs::Geometry& g = v.geometry();
  vs::IsoSurfaceOptions io;
  io.iso = iso;
  io.largestComponentOnly = false;
  auto t0 = Clock::now();
  double c0 = cpuNow();
  vs::TriMesh all = vs::extractIsoSurface(v, io);
  const double extractSeconds = since(t0), extractCpu = cpuNow() - c0;
  vs::CutOptions o;
  o.iso = iso;
  o.pointsIndex = parsePoints(points);
  std::vector<Vec3> pointsMm;
  for (const Vec3& p : o.pointsIndex) pointsMm.push_back(g.indexToWorld(p));
  c0 = cpuNow();
  vs::TriMesh skin = vs::keepComponentNearest(all, pointsMm);
  const double componentSeconds = cpuNow() - c0;
  c0 = cpuNow();
  const vs::CutMesh mesh = vs::prepareCutMesh(v, std::move(skin), o.cost);
  const double prepareSeconds = cpuNow() - c0;

  // Placing the points: the search restarts at each point (a click), then follows the cursor.
  std::vector<int64_t> anchors;
  for (size_t i = 0; i < pointsMm.size(); ++i)
    anchors.push_back(vs::snapToMesh(mesh.mesh, mesh.features, pointsMm[i], o.snapRadiusMm, "point").vertex);
  vs::MeshLiveWire wire(mesh.graph);
  std::vector<double> updates, segmentMm;
  std::ofstream queries(outDir + "/queries.txt");
  for (size_t i = 0; i < anchors.size(); ++i) {
    const int64_t from = anchors[i], to = anchors[(i + 1) % anchors.size()];
    wire.setSeed(from);
    const vs::Path final = wire.pathTo(to);
    segmentMm.push_back(final.lengthMm);
    wire.setSeed(from);
    for (int64_t cursor : final.nodes) {
      if (cursor == from) continue;
      c0 = cpuNow();
      const vs::Path p = wire.pathTo(cursor);
      updates.push_back(cpuNow() - c0);
      queries << from << ' ' << cursor << '\n';
    }
  }
  queries.close();
  vs::writeTriMesh(mesh.mesh, outDir + "/mesh.ply");
  {
    std::ofstream raw(outDir + "/volume.f32", std::ios::binary);
    raw.write(reinterpret_cast<const char*>(v.data()), std::streamsize(sizeof(float) * size_t(g.voxelCount())));
  }
  const AfterLastPoint cut = cutAfterLastPoint(v, mesh, o);
  const HoverFigures hovers = previewHovers(g, mesh, o.pointsIndex, o.snapRadiusMm);
  std::printf(
      "{\"preview\":%s,\"volume\":\"%s\",\"dims\":[%lld,%lld,%lld],\"spacing\":[%g,%g,%g],\"iso\":%g,\"all_triangles\":"
      "%zu,"
      "\"skin_vertices\":%zu,\"skin_triangles\":%zu,\"extract_cpu_seconds\":%.3f,\"extract_wall_seconds\":%.3f,"
      "\"component_cpu_seconds\":%.3f,\"features_graph_cpu_seconds\":%.3f,\"segments\":%zu,\"segment_mm_median\":%.1f,"
      "\"updates\":%zu,\"update_cpu_ms_median\":%.3f,\"update_cpu_ms_p95\":%.3f,\"update_cpu_ms_max\":%.3f,"
      "\"contour_cpu_seconds\":%.3f,\"surface_cpu_seconds\":%.3f,\"split_cpu_seconds\":%.3f,"
      "\"after_last_point_cpu_seconds\":%.3f,\"cut_voxels\":%lld}\n",
      hoverJson(hovers).c_str(), jsonEscape(path).c_str(), (long long)g.dims[0], (long long)g.dims[1],
      (long long)g.dims[2], g.spacing.x(), g.spacing.y(), g.spacing.z(), iso, all.triangles.size(),
      mesh.mesh.positions.size(), mesh.mesh.triangles.size(), extractCpu, extractSeconds, componentSeconds,
      prepareSeconds, segmentMm.size(), percentile(segmentMm, 50), updates.size(), 1e3 * percentile(updates, 50),
      1e3 * percentile(updates, 95), 1e3 * percentile(updates, 100), cut.contour, cut.surface, cut.split,
      cut.surface + cut.split, (long long)cut.cutVoxels);
  return 0;
}

int phantom(int64_t size) {
  vs::HeadPhantomOptions ho;
  ho.dims = {size, size, size};
  const vs::HeadPhantom ph = vs::makeHeadPhantom(ho);
  const vs::HeadTruth& t = ph.truth;
  const vs::VolumeF32 v = vs::toFloat(vs::AnyVolume(ph.volume));
  // The eight points around the nose of scripts/demo.d/50_cut.sh (128^3 phantom), scaled: the
  // phantom's proportions follow its size.
  vs::CutOptions o;
  o.iso = t.isoSkin;
  for (const Vec3& p : parsePoints("72,21,58;69,20,68;64,20,73;58,20,68;55,21,58;58,23,47;64,24,42;69,23,47"))
    o.pointsIndex.push_back(p * (double(size) / 128));
  vs::IsoSurfaceOptions io;
  io.iso = o.iso;
  const vs::CutMesh mesh = vs::prepareCutMesh(v, vs::extractIsoSurface(v, io));
  const AfterLastPoint cut = cutAfterLastPoint(v, mesh, o);
  const HoverFigures hovers = previewHovers(v.geometry(), mesh, o.pointsIndex, o.snapRadiusMm);
  std::printf(
      "{\"preview\":%s,\"phantom_size\":%lld,\"contour_cpu_seconds\":%.3f,\"surface_cpu_seconds\":%.3f,"
      "\"split_cpu_seconds\":%.3f,\"after_last_point_cpu_seconds\":%.3f,\"cut_voxels\":%lld}\n",
      hoverJson(hovers).c_str(), (long long)size, cut.contour, cut.surface, cut.split, cut.surface + cut.split,
      (long long)cut.cutVoxels);
  return 0;
}

std::string energyJson(const vs::CuttingSurfaceEnergy& e) {
  char buf[256];
  std::snprintf(buf, sizeof buf,
                "{\"image\":%.2f,\"continuity\":%.2f,\"part\":%.2f,\"share_image\":%.3f,\"share_continuity\":%.3f,"
                "\"share_part\":%.3f,\"edge_fraction\":%.3f}",
                e.image, e.continuity, e.part, e.share(e.image), e.share(e.continuity), e.share(e.part),
                e.edgeFraction);
  return buf;
}

// Raw uint8 / int16 dumps for looking at slices (x fastest; dims and spacing in the JSON line).
template <class T>
void dumpRaw(const std::string& path, const vs::Volume<T>& v) {
  std::ofstream f(path, std::ios::binary);
  f.write(reinterpret_cast<const char*>(v.data()), std::streamsize(v.size() * int64_t(sizeof(T))));
}

int family(uint64_t seed, double scale, const vs::CuttingSurfaceOptions& surface, const std::string& dumpDir) {
  vs::HeadFamilyOptions fo;
  fo.seed = seed;
  fo.sizeScale = scale;
  const vs::HeadFamilyPhantom ph = vs::makeHeadFamilyPhantom(fo);
  const vs::HeadFamilyTruth& t = ph.truth;
  const vs::VolumeF32 v = vs::toFloat(vs::AnyVolume(ph.volume));
  const vs::Geometry& g = v.geometry();
  if (!dumpDir.empty()) {
    dumpRaw(dumpDir + "/volume.i16", ph.volume);
    dumpRaw(dumpDir + "/truth.u8", ph.labels);
  }
  auto cut = [&](const std::vector<Vec3>& loop, const char* name, uint8_t part) -> std::string {
    vs::CutOptions o;
    o.iso = t.iso;
    o.surface = surface;
    for (const Vec3& p : loop) o.pointsIndex.push_back(g.worldToIndex(p));
    char buf[1024];
    try {
      const vs::CutResult r = vs::cutVolume(v, o);
      if (!dumpDir.empty()) dumpRaw(dumpDir + "/" + name + "_cut.u8", r.split.labels);
      const double seconds = r.seconds[0] + r.seconds[1] + r.seconds[2] + r.seconds[3];
      if (part != 0) {
        const vs::PartCutScore s = vs::scorePartCut(ph, vs::HeadLabel(part), r.split.labels);
        // The cutting surface against the face's skin under the part (signed, mm, < 0 inside the face).
        const vs::CuttingSurface& cs = r.surface;
        double sd = 0;
        int64_t count = 0;
        for (int64_t y = 0; y < cs.height; ++y)
          for (int64_t x = 0; x < cs.width; ++x)
            if (cs.inDomain(x, y) && cs.ring[size_t(y * cs.width + x)] >= 1)
              sd += t.faceSignedDistance(cs.point(x, y)), ++count;
        std::snprintf(buf, sizeof buf,
                      "\"%s\":{\"removed\":%.4f,\"taken_rest\":%.4f,\"taken_by_centre\":%.4f,\"part_rim_cut\":%.4f,"
                      "\"surface_to_skin_mm\":%.2f,\"seconds\":%.2f,"
                      "\"energy\":%s}",
                      name, s.removed, s.takenRest, s.takenByCentre, s.partRimCut, count ? sd / double(count) : 0.0,
                      seconds, energyJson(r.surface.energy).c_str());
      } else {
        const vs::CuttingSurface& cs = r.surface;
        std::vector<Vec3> under;
        for (int64_t y = 0; y < cs.height; ++y)
          for (int64_t x = 0; x < cs.width; ++x)
            if (cs.inDomain(x, y) && double(cs.ring[size_t(y * cs.width + x)]) * cs.pixelMm >= 4)
              under.push_back(cs.point(x, y));
        std::snprintf(buf, sizeof buf,
                      "\"%s\":{\"bone_distance_mm\":%.3f,\"cut_mm3\":%.0f,\"seconds\":%.2f,\"energy\":%s}", name,
                      under.empty() ? -1.0 : vs::meanDistanceToBoneMm(t, under),
                      double(r.split.cutVoxels) * g.spacing.prod(), seconds, energyJson(r.surface.energy).c_str());
      }
    } catch (const vs::Error& e) {
      std::snprintf(buf, sizeof buf, "\"%s\":{\"error\":\"%s\"}", name, jsonEscape(e.what()).c_str());
    }
    return buf;
  };
  std::printf(
      "{\"seed\":%llu,\"scale\":%.2f,\"dims\":[%lld,%lld,%lld],\"spacing\":[%.2f,%.2f,%.2f],\"soft_mm\":%.1f,\"bone_"
      "mm\":%.1f,"
      "\"bone_hu\":%.0f,\"noise\":%.1f,%s,%s,%s,%s}\n",
      (unsigned long long)seed, scale, (long long)g.dims[0], (long long)g.dims[1], (long long)g.dims[2], g.spacing.x(),
      g.spacing.y(), g.spacing.z(), t.skinMm + t.fatMm + t.muscleMm, t.boneMm, t.bone, t.noiseSigma,
      cut(t.noseLoopMm(12), "nose", vs::kHeadNose).c_str(), cut(t.earLoopMm(12), "ear", vs::kHeadEar).c_str(),
      cut(t.foreheadLoopMm(12 * scale / 0.6, 12), "forehead", 0).c_str(),
      cut(t.cheekLoopMm(12 * scale / 0.6, 12), "cheek", 0).c_str());
  std::fflush(stdout);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string mode = argc > 1 ? argv[1] : "";
    if (mode == "robustness" && argc == 6)
      return robustness(argv[2], std::stod(argv[3]), std::stoi(argv[4]), std::stoull(argv[5]));
    if (mode == "speed" && argc == 6) return speed(argv[2], std::stod(argv[3]), argv[4], argv[5]);
    if (mode == "phantom" && argc == 3) return phantom(std::stoll(argv[2]));
    if (mode == "family" && argc >= 4 && argc <= 9 && argc != 6 && argc != 7) {
      vs::CuttingSurfaceOptions so;
      if (argc >= 8)
        so.wg = std::stod(argv[4]), so.wc = std::stod(argv[5]), so.wp = std::stod(argv[6]), so.wd = std::stod(argv[7]);
      const std::string dump = argc == 5 ? argv[4] : argc == 9 ? argv[8] : "";
      return family(std::stoull(argv[2]), std::stod(argv[3]), so, dump);
    }
    std::fprintf(stderr,
                 "usage: bench_cut robustness VOLUME ISO LOOPS SEED | speed VOLUME ISO POINTS OUTDIR | phantom SIZE | "
                 "family SEED SCALE [wg wc wp wd] [DUMPDIR]\n");
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_cut: %s\n", e.what());
    return 1;
  }
}
