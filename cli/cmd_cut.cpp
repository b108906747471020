// `volscissors cut VOLUME --iso V --points "x,y,z;x,y,z;..." [--world] [--mesh iso|envmap] [--snap R] [--seed x,y,z]
//   --labels labels.nii.gz [--cut-surface cut.ply] [--contour contour.json] [--parts PREFIX] [--json report.json]
//   [--wg W] [--wc W] [--wp W] [--wd W] [--contour-wg W] [--contour-wn W] [--contour-wl W]`
// Volume cutting (thesis ch. 3, 5.1; issue 14): a closed live-wire contour through the points on
// the object's iso-surface, an internal cutting surface that follows the image, and the split.
// Labels: 0 background (< iso), 1 kept, 2 cut away (by default the smaller side; --seed keeps the
// side holding that voxel). Every output is written only after the whole cut succeeded.
// Exit status: 2 usage (bad option or coordinates), 1 data/IO (no surface at the iso-value, a
// point too far from the surface, a contour that separates nothing, a bad seed, unreadable file).
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "args.h"
#include "command.h"
#include "cutting/cut.h"
#include "io/mesh_io.h"
#include "io/volume_io.h"
#include "progress_line.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace {

const vs::CutOptions kDefaults;

struct Args {
  std::string volume, points, seed, labels, cutSurface, contour, parts, json, mesh = "iso";
  double iso = NAN, snap = kDefaults.snapRadiusMm;
  bool world = false;
  vs::CuttingSurfaceOptions surface = kDefaults.surface;
  vs::MeshCostOptions cost = kDefaults.cost;
};

int run(const Args& a) {
  if (!std::isfinite(a.iso)) throw vs::UsageError("--iso must be a finite number");
  if (!(a.snap > 0)) throw vs::UsageError("--snap must be > 0 mm");
  for (const auto& [name, w] : {std::pair<const char*, double>{"--wg", a.surface.wg},
                                {"--wp", a.surface.wp},
                                {"--contour-wg", a.cost.wg},
                                {"--contour-wn", a.cost.wn}})
    if (!(w >= 0) || !std::isfinite(w)) throw vs::UsageError(std::string(name) + " must be a finite number >= 0");
  if (!(a.surface.wc > 0) || !std::isfinite(a.surface.wc)) throw vs::UsageError("--wc must be > 0");
  if (!(a.cost.wl > 0) || !std::isfinite(a.cost.wl)) throw vs::UsageError("--contour-wl must be > 0");
  if (!(a.surface.wd >= 0 && a.surface.wd <= 1)) throw vs::UsageError("--wd must be in [0, 1]");
  const std::vector<vs::Vec3> points = vs::cli::parseVec3List(a.points, "--points");
  if (points.size() < 3)
    throw vs::UsageError("--points: a cut needs at least 3 points around the part, got " +
                         std::to_string(points.size()));
  std::vector<vs::Vec3> seed;
  if (!a.seed.empty()) {
    seed = vs::cli::parseVec3List(a.seed, "--seed");
    if (seed.size() != 1) throw vs::UsageError("--seed: expected one point x,y,z");
  }
  vs::cli::requireExtension(a.labels, "--labels", vs::cli::volumeOutputExtensions());
  if (!a.cutSurface.empty()) vs::cli::requireExtension(a.cutSurface, "--cut-surface", {".ply", ".obj", ".stl", ".vtk"});
  if (!a.contour.empty()) vs::cli::requireExtension(a.contour, "--contour", {".json", ".vtk"});
  vs::OutputSet outputs;  // all or nothing, paths checked before any work
  for (const std::string* out : {&a.labels, &a.cutSurface, &a.contour, &a.json})
    if (!out->empty()) outputs.add(*out);
  const std::string keptPath = a.parts + "_kept.nii.gz", cutPath = a.parts + "_cut.nii.gz";
  if (!a.parts.empty()) {
    outputs.add(keptPath);
    outputs.add(cutPath);
  }

  vs::cli::ProgressLine progressLine("cut");
  vs::Progress& progress = progressLine.progress();
  const auto t0 = std::chrono::steady_clock::now();
  const vs::AnyVolume any = vs::readVolume(a.volume, {}, nullptr, progress);
  vs::requireFinite(any, a.volume);
  const vs::VolumeF32 volume = vs::toFloat(any);
  const double loadSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const vs::Geometry& g = volume.geometry();

  vs::CutOptions o = kDefaults;
  o.iso = a.iso;
  o.snapRadiusMm = a.snap;
  o.meshKind = a.mesh == "envmap" ? vs::CutMeshKind::EnvMap : vs::CutMeshKind::Iso;
  o.surface = a.surface;
  o.cost = a.cost;
  for (const vs::Vec3& p : points) {
    const vs::Vec3 idx = a.world ? g.worldToIndex(p) : p;
    if (!g.containsContinuous(idx)) {
      std::ostringstream msg;
      msg << "--points: (" << p.x() << "," << p.y() << "," << p.z() << ") is outside the volume " << g.describe()
          << (a.world ? " (world mm)" : " (voxel index; use --world for mm)");
      throw vs::UsageError(msg.str());
    }
    o.pointsIndex.push_back(idx);
  }
  if (!seed.empty()) {
    const vs::Index3 v = vs::roundIndex(a.world ? g.worldToIndex(seed[0]) : seed[0]);
    if (!g.contains(v)) throw vs::UsageError("--seed is outside the volume " + g.describe());
    o.keepSeed = v;
  }

  const vs::CutResult r = vs::cutVolume(volume, o, progress);

  const double voxelMm3 = g.spacing.prod();
  const vs::CuttingSurfaceEnergy& e = r.surface.energy;
  nlohmann::json report;
  report["volume"] = a.volume;
  report["iso"] = a.iso;
  report["mesh"] = {{"kind", a.mesh}, {"vertices", r.mesh.positions.size()}, {"triangles", r.mesh.triangles.size()}};
  nlohmann::json snapped = nlohmann::json::array();
  for (size_t i = 0; i < r.contour.anchors.size(); ++i) {
    const vs::Vec3& w = r.mesh.positions[size_t(r.contour.anchors[i])];
    const vs::Vec3 idx = g.worldToIndex(w);
    snapped.push_back({{"index", {idx.x(), idx.y(), idx.z()}},
                       {"world_mm", {w.x(), w.y(), w.z()}},
                       {"snap_distance_mm", r.snapDistanceMm[i]}});
  }
  report["points"] = snapped;
  report["contour"] = {{"vertices", r.contour.vertices.size()}, {"length_mm", r.contour.lengthMm}};
  report["cutting_surface"] = {
      {"projected_area_mm2", r.surface.projectedAreaMm2},
      {"normal", {r.surface.normal.x(), r.surface.normal.y(), r.surface.normal.z()}},
      {"blocked_voxels", r.split.surfaceVoxels},
      {"weights", {{"wg", a.surface.wg}, {"wc", a.surface.wc}, {"wp", a.surface.wp}, {"wd", a.surface.wd}}},
      // the minimised energy's terms at the optimum and their shares
      {"energy",
       {{"image", e.image},
        {"continuity", e.continuity},
        {"part", e.part},
        {"share_image", e.share(e.image)},
        {"share_continuity", e.share(e.continuity)},
        {"share_part", e.share(e.part)},
        {"pixels", e.pixels},
        {"edge_fraction", e.edgeFraction},
        {"standing_out", e.standingOut},
        {"edge_within_reach", e.edgeWithinReach}}}};
  report["contour"]["weights"] = {{"wg", a.cost.wg}, {"wn", a.cost.wn}, {"wl", a.cost.wl}};
  report["parts"] = {
      {"kept", {{"label", 1}, {"voxels", r.split.keptVoxels}, {"mm3", double(r.split.keptVoxels) * voxelMm3}}},
      {"cut", {{"label", 2}, {"voxels", r.split.cutVoxels}, {"mm3", double(r.split.cutVoxels) * voxelMm3}}}};
  report["seconds"] = {{"load", loadSeconds},
                       {"mesh", r.seconds[0]},
                       {"contour", r.seconds[1]},
                       {"cutting_surface", r.seconds[2]},
                       {"split", r.seconds[3]}};

  progress.report(1.0, "writing");
  outputs.write(a.labels, [&](const std::string& t) { vs::writeVolume(vs::AnyVolume(r.split.labels), t); });
  if (!a.cutSurface.empty())
    outputs.write(a.cutSurface, [&](const std::string& t) { vs::writeTriMesh(r.surface.mesh(), t); });
  if (!a.contour.empty()) {
    vs::Polyline loop;
    loop.points = r.contourMm;
    loop.closed = true;
    outputs.write(a.contour, [&](const std::string& t) { vs::writePolylines({loop}, t); });
  }
  if (!a.parts.empty())
    std::visit(
        [&](const auto& v) {
          outputs.write(keptPath, [&](const std::string& t) {
            vs::writeVolume(vs::AnyVolume(vs::splitPart(v, r.split.labels, 1)), t);
          });
          outputs.write(cutPath, [&](const std::string& t) {
            vs::writeVolume(vs::AnyVolume(vs::splitPart(v, r.split.labels, 2)), t);
          });
        },
        any);
  if (!a.json.empty()) outputs.writeBytes(a.json, report.dump(2) + "\n");
  outputs.commit();

  std::ostringstream msg;
  msg.precision(4);
  msg << "mesh " << r.mesh.positions.size() << " vertices; contour " << r.contour.vertices.size() << " vertices, "
      << r.contour.lengthMm << " mm; cut away " << r.split.cutVoxels << " voxels ("
      << double(r.split.cutVoxels) * voxelMm3 << " mm3), kept " << r.split.keptVoxels << "; "
      << r.seconds[0] + r.seconds[1] + r.seconds[2] + r.seconds[3] << " s; energy: image " << e.image << " (share "
      << e.share(e.image) << "), continuity " << e.continuity << " (" << e.share(e.continuity) << "), part " << e.part
      << " (" << e.share(e.part) << "); " << int64_t(std::lround(e.edgeFraction * double(e.pixels))) << " of "
      << e.pixels << " pixels on an edge (edges within reach: " << e.edgeWithinReach << " pixels' worth)";
  vs::cli::note(msg.str());
  return 0;
}

const vs::cli::Registration reg{
    "cut", "cut a volume in two along a closed live-wire contour drawn on the object's surface (thesis ch. 3)",
    [](CLI::App& sub) -> vs::cli::Runner {
      auto a = std::make_shared<Args>();
      sub.add_option("volume", a->volume, "input volume")->required();
      sub.add_option("--iso", a->iso, "iso-value of the object's surface (the object is the voxels >= iso)")
          ->required();
      sub.add_option("--points", a->points,
                     "points near the surface around the part, in loop order: \"x,y,z;x,y,z;...\" (0-based voxel "
                     "index; mm with --world); at least 3")
          ->required();
      sub.add_flag("--world", a->world, "--points and --seed are world coordinates (mm, LPS)");
      sub.add_option("--mesh", a->mesh,
                     "surface mesh: iso (iso-surface) or envmap (the thesis's environment map from the object's "
                     "centroid; star-shaped objects only)")
          ->check(CLI::IsMember({"iso", "envmap"}))
          ->capture_default_str();
      sub.add_option("--snap", a->snap,
                     "3D snap radius (mm): each point moves to a strong-gradient surface vertex "
                     "within it; points farther from the surface are refused")
          ->capture_default_str();
      sub.add_option("--seed", a->seed, "a voxel x,y,z whose side is kept (default: cut away the smaller side)");
      sub.add_option("--labels", a->labels, "output label volume: 0 background, 1 kept, 2 cut away")->required();
      sub.add_option("--cut-surface", a->cutSurface, "output cutting surface mesh (.ply .obj .stl .vtk)");
      sub.add_option("--contour", a->contour, "output closed contour (.json .vtk)");
      sub.add_option("--parts", a->parts,
                     "write PREFIX_kept.nii.gz and PREFIX_cut.nii.gz (the volume masked per part)");
      sub.add_option("--json", a->json, "report: mesh, contour length, voxels and mm3 per part, seconds per step");
      sub.add_option("--wg", a->surface.wg,
                     "cutting surface: weight of the image term (eq. 15; edge strength x direction), >= 0")
          ->capture_default_str();
      sub.add_option("--wc", a->surface.wc, "cutting surface: weight of continuity (eq. 15-18), > 0")
          ->capture_default_str();
      sub.add_option("--wp", a->surface.wp,
                     "cutting surface: cost per pixel of depth below the continuation of the surface around "
                     "the contour, where the part stands out of it (a nose: the whole protrusion, not the "
                     "face under it); 0 lets the cut follow deeper edges, >= 0")
          ->capture_default_str();
      sub.add_option("--wd", a->surface.wd,
                     "cutting surface: share of the image term that asks the edge to face the projection "
                     "direction (direction consistency), 0..1")
          ->capture_default_str();
      sub.add_option("--contour-wg", a->cost.wg, "contour live-wire on the mesh: gradient weight w_g (eq. 13)")
          ->capture_default_str();
      sub.add_option("--contour-wn", a->cost.wn, "contour live-wire on the mesh: normal-change weight w_n (eq. 13)")
          ->capture_default_str();
      sub.add_option("--contour-wl", a->cost.wl, "contour live-wire on the mesh: length weight w_l (> 0)")
          ->capture_default_str();
      return [a] { return run(*a); };
    }};

}  // namespace
