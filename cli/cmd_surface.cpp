// `volscissors surface VOLUME --planes x0,y0,z0 [--world] [--iso V] [--corners "x,y,z;x,y,z;x,y,z"]
//   [--octant +x+y+z] [--level N] [--connectivity 18|26|6] [--closed] [--via SIDE:x,y,z;...]
//   [--edit SIDE:x,y,z;...] [--every-voxel]
//   --out mesh.ply|.obj|.stl|.vtk [--json report.json]`
// Surface extraction from three orthogonal contours (thesis 4.3.1, src/surface/surface.h): one
// octant's patch, or with --closed the eight patches stitched into a watertight surface.
// Exit 2: bad syntax, planes or corners outside the volume or off their half-lines; exit 1:
// unreadable file, no surface crossing, a side without path, a level too deep, and what the core's
// surface policy refuses (surface/surface_policy.h: a mesh invalid after the repair of degenerate
// triangles, a fold unless --allow-folds). No output file on any failure.
#include <cmath>
#include <nlohmann/json.hpp>

#include "args.h"
#include "command.h"
#include "io/mesh_io.h"
#include "io/volume_io.h"
#include "progress_line.h"
#include "surface/surface.h"
#include "surface/surface_policy.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/text.h"

namespace {

const vs::SurfaceOptions kDefaults;

struct Args {
  std::string volume, planes, corners, octant = vs::octantName(kDefaults.octant), out, json;
  std::vector<std::string> via, edits;
  double iso = 0;
  bool isoGiven = false;  // --iso on the command line (else the core's Otsu default)
  int level = kDefaults.level, connectivity = kDefaults.connectivity;
  bool world = false, closed = kDefaults.closed, allowFolds = kDefaults.allowFolds,
       geometryOnly = kDefaults.geometryOnly, everyPathVoxel = kDefaults.everyPathVoxel;
};

int run(const Args& a) {
  vs::cli::requireExtension(a.out, "--out", {".ply", ".obj", ".stl", ".vtk"});
  if (a.isoGiven && !std::isfinite(a.iso))
    throw vs::UsageError("--iso must be a finite value (leave it out for the Otsu threshold)");
  if (a.planes.empty()) throw vs::UsageError("--planes x0,y0,z0 is required");
  const vs::Vec3 planes = vs::cli::parseVec3(a.planes, "--planes");
  const std::vector<vs::Vec3> corners = vs::cli::parseVec3List(a.corners, "--corners");
  // SIDE:x,y,z;x,y,z items of --via and --edit.
  using SidePoints = std::vector<std::pair<std::string, std::vector<vs::Vec3>>>;
  auto sidePoints = [](const std::vector<std::string>& items, const std::string& option) {
    SidePoints out;
    for (const std::string& v : items) {
      auto [side, points] = vs::cli::splitLabel(v, option, "z+x+y:40,52,30;44,50,30");
      out.emplace_back(side, vs::cli::parseVec3List(points, option));
    }
    return out;
  };
  const SidePoints via = sidePoints(a.via, "--via"), edits = sidePoints(a.edits, "--edit");
  vs::OutputSet outputs;  // mesh and report together or nothing
  outputs.add(a.out);
  if (!a.json.empty()) outputs.add(a.json);

  vs::cli::ProgressLine progressLine("surface");
  vs::Progress& progress = progressLine.progress();
  const vs::VolumeF32 vol = vs::toFloat(vs::readVolume(a.volume, {}, nullptr, progress));
  vs::requireFinite(vs::AnyVolume(vol), a.volume);
  const vs::Geometry& G = vol.geometry();
  auto toVoxel = [&](const vs::Vec3& p, const std::string& what) {
    if (!a.world)
      for (int c = 0; c < 3; ++c)
        if (p[c] != std::floor(p[c]))
          throw vs::UsageError(what + ": voxel coordinates must be integers (or use --world)");
    const vs::Index3 v = vs::roundIndex(a.world ? G.worldToIndex(p) : p);
    if (!G.contains(v)) throw vs::UsageError(what + " " + vs::indexText(v) + " is outside the volume " + G.describe());
    return v;
  };

  vs::SurfaceOptions o = kDefaults;
  o.planes = toVoxel(planes, "--planes");
  if (a.isoGiven) o.iso = a.iso;
  o.level = a.level;
  o.connectivity = a.connectivity;
  o.closed = a.closed;
  o.octant = vs::parseOctant(a.octant);
  o.geometryOnly = a.geometryOnly;
  o.everyPathVoxel = a.everyPathVoxel;
  o.allowFolds = a.allowFolds;
  if (!corners.empty()) {
    if (!a.closed && corners.size() == 3) {
      for (int axis = 0; axis < 3; ++axis)
        o.corners[static_cast<size_t>(2 * axis + (o.octant[axis] < 0))] =
            toVoxel(corners[static_cast<size_t>(axis)], "--corners item " + std::to_string(axis + 1));
    } else if (a.closed && corners.size() == 6) {
      for (size_t h = 0; h < 6; ++h) o.corners[h] = toVoxel(corners[h], "--corners item " + std::to_string(h + 1));
    } else {
      throw vs::UsageError(
          "--corners: give 3 corners (x, y, z half-lines of the octant) or, with --closed, 6 "
          "(+x;-x;+y;-y;+z;-z); got " +
          std::to_string(corners.size()));
    }
  }
  auto sideVoxels = [&](const SidePoints& items, const std::string& what) {
    std::vector<std::pair<std::string, std::vector<vs::Index3>>> out;
    for (const auto& [side, points] : items) {
      std::vector<vs::Index3> voxels;
      for (const vs::Vec3& p : points) voxels.push_back(toVoxel(p, what));
      out.emplace_back(side, std::move(voxels));
    }
    return out;
  };
  o.via = sideVoxels(via, "--via point");
  const auto editVoxels = sideVoxels(edits, "--edit point");

  vs::SurfaceExtraction extraction(vol, o, progress);
  std::vector<vs::SurfaceEditReport> editReports;
  for (const auto& [side, voxels] : editVoxels) editReports.push_back(extraction.editSide(side, voxels, progress));
  const vs::SurfaceResult& r = extraction.result();  // checked by the core's surface policy
  const vs::MeshTopology& topo = r.topology;
  const std::string folded = vs::foldedOctantsText(r);

  auto arr = [](const auto& v) { return nlohmann::json::array({v[0], v[1], v[2]}); };
  nlohmann::json rep;
  rep["volume"] = a.volume;
  rep["iso"] = r.iso;
  rep["cost"] = r.costDescription;
  rep["connectivity"] = a.connectivity;
  rep["planes"] = arr(o.planes);
  rep["center_world"] = arr(G.indexToWorld(r.centerIndex));
  rep["closed"] = a.closed;
  rep["corners"] = nlohmann::json::object();
  const char* names[6] = {"+x", "-x", "+y", "-y", "+z", "-z"};
  for (size_t h = 0; h < 6; ++h)
    if (r.corners[h])
      rep["corners"][names[h]] = {
          {"voxel", arr(*r.corners[h])},
          {"world", arr(G.indexToWorld(vs::Vec3(double((*r.corners[h])[0]), double((*r.corners[h])[1]),
                                                double((*r.corners[h])[2]))))}};
  rep["sides"] = nlohmann::json::object();
  for (const auto& [name, pts] : r.sides) rep["sides"][name] = {{"voxels", pts.size()}};
  rep["levels"] = nlohmann::json::array();
  for (const auto& l : r.levels)
    rep["levels"].push_back({{"level", l.level},
                             {"triangles", l.triangles},
                             {"paths", l.paths},
                             {"nodes_settled", l.nodesSettled},
                             {"edges_scanned", l.edgesScanned},
                             {"seconds", l.seconds}});
  rep["octants"] = nlohmann::json::array();
  for (const auto& oc : r.octants)
    rep["octants"].push_back(
        {{"octant", vs::octantName(oc.octant)},
         {"triangles", oc.triangles},
         {"back_facing_triangles", oc.backFacingTriangles},
         {"back_facing_area_fraction", oc.backFacingAreaFraction},
         {"fold_check_rays", oc.foldCheckRays},
         {"folded_rays", oc.foldedRays},
         {"folded_ray_fraction", oc.foldedRayFraction},
         {"rays_meeting_other_objects", oc.otherObjectRays},
         {"first_fold_voxel", oc.firstFold ? arr(vs::roundIndex(*oc.firstFold)) : nlohmann::json(nullptr)},
         {"folded", oc.folded}});
  rep["mesh"] = {{"vertices", topo.vertices},
                 {"edges", topo.edges},
                 {"triangles", topo.faces},
                 {"euler_characteristic", topo.eulerCharacteristic()},
                 {"boundary_loops", topo.boundaryLoops},
                 {"watertight", topo.watertight()},
                 {"repaired_degenerate_triangles", r.repairedTriangles}};
  rep["seconds"] = {{"cost", r.secondsCost}, {"sides", r.secondsSides}, {"total", r.secondsTotal}};
  rep["edits"] = nlohmann::json::array();
  for (const auto& e : editReports) {
    nlohmann::json octants = nlohmann::json::array();
    for (const auto& oc : e.octants) octants.push_back(vs::octantName(oc));
    rep["edits"].push_back({{"side", e.side},
                            {"octants_recomputed", octants},
                            {"paths", e.paths},
                            {"nodes_settled", e.nodesSettled},
                            {"seconds", e.seconds}});
  }

  outputs.write(a.out, [&](const std::string& t) { vs::writeTriMesh(r.mesh, t); });
  if (!a.json.empty()) outputs.writeBytes(a.json, rep.dump(1) + "\n");
  outputs.commit();
  vs::cli::note("surface: " + std::to_string(topo.faces) + " triangles, " + std::to_string(topo.vertices) +
                " vertices, Euler characteristic " + std::to_string(topo.eulerCharacteristic()) + ", iso " +
                std::to_string(r.iso) + ", " + std::to_string(r.secondsTotal) + " s -> " + a.out);
  if (!folded.empty()) vs::cli::note("warning: folded octant " + folded);
  return 0;
}

const vs::cli::Registration reg{
    "surface", "surface of an object from three orthogonal contours (thesis 4.3.1): one octant or closed",
    [](CLI::App& sub) {
      auto a = std::make_shared<Args>();
      sub.add_option("volume", a->volume, "input volume (.nii.gz, .nrrd, .mha, .vtk, DICOM folder)")->required();
      sub.add_option("--planes", a->planes, "plane positions x0,y0,z0 (voxel indices; --world: mm)")->required();
      sub.add_flag("--world", a->world, "--planes, --corners and --via are world mm instead of voxel indices");
      CLI::Option* iso =
          sub.add_option("--iso", a->iso, "iso-value of the surface (default: Otsu threshold of the volume)");
      sub.add_option("--corners", a->corners,
                     "corners on the half-lines: \"x,y,z;x,y,z;x,y,z\" for the octant's x, y, z half-lines, or with "
                     "--closed six for +x;-x;+y;-y;+z;-z (default: outermost iso crossing on each)");
      sub.add_option("--octant", a->octant, "the octant to extract, signs of x, y, z")->capture_default_str();
      sub.add_option("--level", a->level, "subdivision levels, 4^N triangles per octant")
          ->capture_default_str()
          ->check(CLI::Range(0, 8));
      sub.add_option("--connectivity", a->connectivity, "3D path connectivity: 6, 18 (the thesis) or 26")
          ->capture_default_str()
          ->check(CLI::IsMember({6, 18, 26}));
      sub.add_flag("--closed", a->closed, "all eight octants stitched into one watertight surface");
      sub.add_option("--via", a->via,
                     "intermediate points of one side, SIDE:x,y,z;x,y,z (SIDE as z+x+y: plane z, quadrant x+ y+); "
                     "repeatable");
      sub.add_option("--edit", a->edits,
                     "after extracting, re-route one side through points as stylus editing does, SIDE:x,y,z;...: "
                     "only the octants sharing that side are re-subdivided (the report gives each edit's octants "
                     "and seconds); repeatable, applied in order");
      sub.add_flag("--allow-folds", a->allowFolds, "write the mesh even where an octant folds back (default: fail)");
      sub.add_flag("--every-voxel", a->everyPathVoxel,
                   "finer mesh: every voxel of every path is a vertex (each triangle re-triangulated over its three "
                   "paths' voxels; "
                   "default: path end points only, 4^N triangles per octant)");
      sub.add_flag("--geometry-only", a->geometryOnly,
                   "baseline: interior vertices interpolated from the three contours without the image");
      sub.add_option("--out", a->out, "mesh output: .ply, .obj, .stl or .vtk (world mm, outward normals)")->required();
      sub.add_option("--json", a->json,
                     "report: corners, sides, per-level triangles/paths/nodes/edges/seconds, octants, mesh");
      return [a, iso] {
        a->isoGiven = iso->count() > 0;
        return run(*a);
      };
    }};

}  // namespace
