// `volscissors trace VOLUME --root x,y,z (--target x,y,z)... | --targets-file F | --auto-terminals N`
// Vessel / airway tracking (thesis 4.3.2, 6.2): one search from the root, resumed for every
// target; writes the tree of extracted paths (SWC / VTK / JSON report / label volume).
// Coordinates: 0-based voxel index x,y,z of VOLUME (--world: world mm as the reader reports).
// Exit status: 2 usage (bad option, coordinates outside the volume/ROI, duplicate targets, empty
// ROI), 1 data/IO (unreadable file, unreachable target, threshold removing everything).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "command.h"
#include "cost/cost3d.h"
#include "io/mesh_io.h"
#include "io/volume_io.h"
#include "tracking/tracker.h"
#include "util/atomic_file.h"
#include "util/error.h"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

struct Args {
  std::string volume, root, targetsFile, roi, out, json, labels, vtk, window, scales;
  std::vector<std::string> targets;
  int autoTerminals = -1;
  double minLengthMm = 10;
  int connectivity = 26;
  std::string prune = "none", pruneOn = "cost", cost = "gradient", polarity = "bright";
  double threshold = NAN, tolerance = 0, costTolerance = 0, smoothMm = NAN, wg = 0.7, wz = 0.3, power = 4;
  bool full = false, world = false;
};

std::string str(const vs::Index3& v) {
  return "(" + std::to_string(v[0]) + "," + std::to_string(v[1]) + "," + std::to_string(v[2]) + ")";
}

std::vector<double> parseList(const std::string& text, const std::string& what, size_t n) {
  std::string t = text;
  std::replace(t.begin(), t.end(), ',', ' ');
  std::istringstream in(t);
  std::vector<double> v;
  double x;
  while (in >> x) v.push_back(x);
  if (!in.eof() || (n && v.size() != n) || v.empty())
    throw vs::UsageError(what + ": expected " + (n ? std::to_string(n) + " comma-separated numbers" : "numbers") +
                         ", got '" + text + "'");
  return v;
}

// Reads targets (and optionally a root) from a text file (one "x y z" or "x,y,z" per line, '#'
// comments) or a JSON file: [[x,y,z],...] or {"terminals"|"targets": [[x,y,z] | {"voxel": [x,y,z]}],
// "root"|"root_voxel": [x,y,z]} (the phantom truth and the peers' sidecars both work).
std::vector<vs::Vec3> readTargets(const std::string& path, std::optional<vs::Vec3>& root) {
  std::ifstream f(path);
  if (!f) throw vs::IoError("--targets-file '" + path + "': cannot open");
  std::stringstream ss;
  ss << f.rdbuf();
  const std::string text = ss.str();
  std::vector<vs::Vec3> out;
  const auto first = text.find_first_not_of(" \t\r\n");
  if (first != std::string::npos && (text[first] == '{' || text[first] == '[')) {
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(text);
    } catch (const std::exception& e) {
      throw vs::IoError("--targets-file '" + path + "': invalid JSON: " + e.what());
    }
    auto point = [&](const nlohmann::json& p) {
      const nlohmann::json& q = p.is_object() && p.contains("voxel") ? p["voxel"] : p;
      if (!q.is_array() || q.size() != 3) throw vs::IoError("--targets-file '" + path + "': a target is not [x,y,z]");
      return vs::Vec3(q[0].get<double>(), q[1].get<double>(), q[2].get<double>());
    };
    const nlohmann::json* list = &j;
    if (j.is_object()) {
      for (const char* k : {"root", "root_voxel"})
        if (j.contains(k)) root = point(j[k]);
      list = j.contains("terminals") ? &j["terminals"] : (j.contains("targets") ? &j["targets"] : nullptr);
      if (!list) throw vs::IoError("--targets-file '" + path + "': no \"terminals\" or \"targets\" array");
    }
    for (const auto& p : *list) out.push_back(point(p));
  } else {
    std::istringstream in(text);
    std::string line;
    int n = 0;
    while (std::getline(in, line)) {
      ++n;
      const auto hash = line.find('#');
      if (hash != std::string::npos) line.resize(hash);
      if (line.find_first_not_of(" \t\r,") == std::string::npos) continue;
      out.push_back(vs::parseTriple(line, "--targets-file '" + path + "' line " + std::to_string(n)));
    }
  }
  if (out.empty()) throw vs::UsageError("--targets-file '" + path + "' holds no target");
  return out;
}

int run(const Args& a) {
  const auto tLoad = Clock::now();
  nlohmann::json seconds;
  vs::AnyVolume any = vs::readVolume(a.volume);
  vs::VolumeF32 full = vs::toFloat(any);
  any = vs::AnyVolume(vs::VolumeU8());
  vs::requireFinite(vs::AnyVolume(full), a.volume);
  seconds["load"] = since(tLoad);
  const vs::Geometry& G = full.geometry();

  auto toVoxel = [&](const vs::Vec3& p, const std::string& what) {
    const vs::Vec3 idx = a.world ? G.worldToIndex(p) : p;
    if (!a.world)
      for (int c = 0; c < 3; ++c)
        if (p[c] != std::floor(p[c])) throw vs::UsageError(what + ": voxel coordinates must be integers (or use --world)");
    const vs::Index3 v = vs::roundIndex(idx);
    if (!G.contains(v))
      throw vs::UsageError(what + " " + str(v) + " is outside the volume " + G.describe());
    return v;
  };

  // Root and targets.
  std::optional<vs::Vec3> fileRoot;
  std::vector<vs::Vec3> rawTargets;
  for (const auto& t : a.targets) rawTargets.push_back(vs::parseTriple(t, "--target"));
  if (!a.targetsFile.empty()) {
    const auto more = readTargets(a.targetsFile, fileRoot);
    rawTargets.insert(rawTargets.end(), more.begin(), more.end());
  }
  if (a.root.empty() && !fileRoot) throw vs::UsageError("--root x,y,z is required");
  const vs::Index3 root = toVoxel(a.root.empty() ? *fileRoot : vs::parseTriple(a.root, "--root"), "root");
  if (rawTargets.empty() && a.autoTerminals < 0)
    throw vs::UsageError("give --target, --targets-file or --auto-terminals N");
  std::vector<vs::Index3> targets;
  for (size_t i = 0; i < rawTargets.size(); ++i) {
    const vs::Index3 t = toVoxel(rawTargets[i], "target #" + std::to_string(i + 1));
    for (size_t k = 0; k < targets.size(); ++k)
      if (targets[k] == t)
        throw vs::UsageError("target #" + std::to_string(i + 1) + " " + str(t) + " duplicates target #" + std::to_string(k + 1));
    if (t == root) throw vs::UsageError("target #" + std::to_string(i + 1) + " " + str(t) + " is the root");
    targets.push_back(t);
  }

  // Region of interest (inclusive voxel box): the volume is cropped to it.
  vs::Index3 lo{0, 0, 0}, hi{G.dims[0] - 1, G.dims[1] - 1, G.dims[2] - 1};
  if (!a.roi.empty()) {
    const auto r = parseList(a.roi, "--roi", 6);
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::max<int64_t>(0, static_cast<int64_t>(std::ceil(r[c])));
      hi[c] = std::min<int64_t>(G.dims[c] - 1, static_cast<int64_t>(std::floor(r[c + 3])));
      if (hi[c] < lo[c])
        throw vs::UsageError("--roi '" + a.roi + "' is empty inside the volume " + G.describe());
    }
    auto inside = [&](const vs::Index3& v) {
      for (int c = 0; c < 3; ++c)
        if (v[c] < lo[c] || v[c] > hi[c]) return false;
      return true;
    };
    if (!inside(root)) throw vs::UsageError("root " + str(root) + " is outside the --roi");
    for (size_t i = 0; i < targets.size(); ++i)
      if (!inside(targets[i])) throw vs::UsageError("target #" + std::to_string(i + 1) + " " + str(targets[i]) + " is outside the --roi");
  }
  vs::VolumeF32 vol;
  if (a.roi.empty()) {
    vol = std::move(full);
  } else {
    vs::Geometry g = G;
    g.dims = {hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1};
    g.origin = G.indexToWorld(vs::Vec3(static_cast<double>(lo[0]), static_cast<double>(lo[1]), static_cast<double>(lo[2])));
    vol = vs::VolumeF32(g);
    for (int64_t z = 0; z < g.dims[2]; ++z)
      for (int64_t y = 0; y < g.dims[1]; ++y)
        for (int64_t x = 0; x < g.dims[0]; ++x) vol(x, y, z) = full(x + lo[0], y + lo[1], z + lo[2]);
    full = vs::VolumeF32();
  }
  auto local = [&](const vs::Index3& v) { return vs::Index3{v[0] - lo[0], v[1] - lo[1], v[2] - lo[2]}; };
  auto global = [&](const vs::Index3& v) { return vs::Index3{v[0] + lo[0], v[1] + lo[1], v[2] + lo[2]}; };

  const auto range = std::minmax_element(vol.voxels().begin(), vol.voxels().end());
  if (!std::isnan(a.threshold) && a.threshold > *range.second)
    throw vs::DataError("--threshold " + std::to_string(a.threshold) + " removes every voxel (largest value " +
                        std::to_string(*range.second) + ")");

  // Costs.
  const auto tFeat = Clock::now();
  vs::Cost3DOptions co;
  co.kind = vs::costKindFromName(a.cost);
  co.wg = a.wg, co.wz = a.wz, co.power = a.power;
  if (a.polarity != "bright" && a.polarity != "dark") throw vs::UsageError("--polarity must be bright or dark");
  co.polarity = a.polarity == "dark" ? vs::TubePolarity::Dark : vs::TubePolarity::Bright;
  if (!a.window.empty()) {
    const auto w = parseList(a.window, "--window", 2);
    co.windowLo = w[0], co.windowHi = w[1];
  }
  co.smoothMm = std::isnan(a.smoothMm) ? (co.kind == vs::CostKind3D::Intensity ? 1.0 : 0.0) : a.smoothMm;
  if (!a.scales.empty()) co.vesselness.scalesMm = parseList(a.scales, "--scales", 0);
  const vs::NodeCost3D cost = vs::computeNodeCost3D(vol, co);
  seconds["features"] = since(tFeat);
  if (!std::isfinite(cost.node[static_cast<size_t>(vol.geometry().linear(local(root)[0], local(root)[1], local(root)[2]))]))
    throw vs::DataError("root " + str(root) + " lies in an impassable voxel (cost inf)");

  vs::TrackerOptions to;
  to.connectivity = a.connectivity;
  if (a.prune != "none" && a.prune != "isoregion") throw vs::UsageError("--prune must be none or isoregion");
  to.prune = a.prune == "isoregion" ? vs::PruneMode::IsoRegion : vs::PruneMode::None;
  if (to.prune == vs::PruneMode::None && (!std::isnan(a.threshold) || a.tolerance != 0 || a.costTolerance != 0))
    vs::cli::note("note: --threshold/--tolerance/--cost-tolerance only shape the IsoRegion map; they have no effect without --prune isoregion");
  to.isoRegion.field = vs::isoRegionFieldFromName(a.pruneOn);
  if (to.prune == vs::PruneMode::IsoRegion && to.isoRegion.field == vs::IsoRegionField::Cost &&
      (!std::isnan(a.threshold) || a.tolerance != 0))
    throw vs::UsageError("--threshold/--tolerance shape the intensity IsoRegion map: add --prune-on intensity "
                         "(the default --prune-on cost takes --cost-tolerance)");
  if (to.prune == vs::PruneMode::IsoRegion && to.isoRegion.field == vs::IsoRegionField::Intensity && a.costTolerance != 0)
    throw vs::UsageError("--cost-tolerance applies to --prune-on cost, not intensity (use --tolerance)");
  if (to.prune == vs::PruneMode::IsoRegion) {
    if (to.isoRegion.field == vs::IsoRegionField::Intensity) {
      to.isoRegion.tolerance = a.tolerance;
      if (!std::isnan(a.threshold)) to.isoRegion.threshold = a.threshold;
    } else {
      to.isoRegion.costTolerance = a.costTolerance;
    }
  }
  vs::VesselTracker tr(vol, cost, local(root), to);
  if (tr.root() != local(root))
    vs::cli::note("root " + str(root) + " was pruned; snapped to the nearest graph node " + str(global(tr.root())));
  for (size_t i = 0; i < targets.size(); ++i) {
    const vs::TracedPath& p = tr.addTarget(local(targets[i]));
    if (!p.reached)
      throw vs::DataError("target #" + std::to_string(i + 1) + " " + str(targets[i]) +
                          " is not reachable from the root " + str(root) +
                          " (separate component: impassable costs or outside the region)");
    if (p.target != local(targets[i]))
      vs::cli::note("target #" + std::to_string(i + 1) + " " + str(targets[i]) + " was pruned; snapped to " + str(global(p.target)));
  }
  if (a.autoTerminals >= 0) {
    vs::AutoTerminalOptions ao;
    ao.count = a.autoTerminals;
    ao.minLengthMm = a.minLengthMm;
    const auto added = tr.autoTerminals(ao);
    vs::cli::note("automatic terminals: " + std::to_string(added.size()) + " found");
  }
  if (a.full) tr.runToCompletion();
  const vs::TrackerStats st = tr.stats();
  seconds["graph"] = st.graphSeconds;
  seconds["search"] = st.searchSeconds;

  // Outputs.
  const auto tOut = Clock::now();
  const vs::Tree tree = tr.toTree();
  vs::OutputSet outputs;  // all or nothing: committed after the report below
  if (!a.out.empty()) outputs.write(a.out, [&](const std::string& t) { vs::writeTree(tree, t); });
  if (!a.vtk.empty()) outputs.write(a.vtk, [&](const std::string& t) { vs::writePolylines(tree.toPolylines(), t); });
  if (!a.labels.empty()) {
    const vs::VolumeU16 labLocal = tr.labelVolume();
    vs::VolumeU16 lab(G, 0);
    for (int64_t z = 0; z < labLocal.dims()[2]; ++z)
      for (int64_t y = 0; y < labLocal.dims()[1]; ++y)
        for (int64_t x = 0; x < labLocal.dims()[0]; ++x) lab(x + lo[0], y + lo[1], z + lo[2]) = labLocal(x, y, z);
    outputs.write(a.labels, [&](const std::string& t) { vs::writeVolume(vs::AnyVolume(std::move(lab)), t); });
  }
  seconds["output"] = since(tOut);

  auto arr = [](const vs::Index3& v) { return nlohmann::json::array({v[0], v[1], v[2]}); };
  nlohmann::json rep;
  rep["volume"] = a.volume;
  rep["root"] = arr(global(tr.root()));
  rep["cost"] = cost.description;
  rep["paths"] = nlohmann::json::array();
  std::printf("%-5s %-18s %8s %10s %12s %10s %7s\n", "path", "target", "voxels", "length_mm", "cost", "cost/mm", "parent");
  for (size_t i = 0; i < tr.paths().size(); ++i) {
    const vs::TracedPath& p = tr.paths()[i];
    nlohmann::json jp;
    jp["target"] = arr(global(p.target));
    jp["requested"] = arr(global(p.requested));
    jp["reached"] = p.reached;
    jp["cost"] = p.cost;
    jp["length_mm"] = p.lengthMm;
    jp["length_voxels"] = p.voxels.size();
    jp["parent_path"] = p.parentPath;
    nlohmann::json vox = nlohmann::json::array();
    for (const auto& v : p.voxels) vox.push_back(arr(global(v)));
    jp["voxels"] = std::move(vox);
    rep["paths"].push_back(std::move(jp));
    const vs::Index3 t = global(p.target);
    char tb[64];
    std::snprintf(tb, sizeof tb, "%lld,%lld,%lld", static_cast<long long>(t[0]), static_cast<long long>(t[1]),
                  static_cast<long long>(t[2]));
    std::printf("%-5zu %-18s %8zu %10.2f %12.5g %10.4g %7d\n", i, tb, p.voxels.size(), p.lengthMm, p.cost,
                p.lengthMm > 0 ? p.cost / p.lengthMm : 0.0, p.parentPath);
  }
  rep["branch_points"] = nlohmann::json::array();
  for (const auto& b : tr.branchPoints()) rep["branch_points"].push_back(arr(global(b)));
  rep["graph"] = {{"voxels", st.voxels}, {"nodes", st.nodes}, {"edges", st.edges}, {"repair_edges", st.repairEdges},
                  {"connectivity", a.connectivity}, {"prune", a.prune}, {"settled", st.settled},
                  {"prune_on", a.prune == "none" ? "" : a.pruneOn},
                  {"cost_tolerance", a.prune == "none" || a.pruneOn != "cost" ? 0.0 : a.costTolerance},
                  {"full_search", a.full}};
  rep["seconds"] = seconds;
  const std::string pruneText = a.prune == "none" ? a.prune : a.prune + " on " + a.pruneOn;
  std::printf("graph: %lld voxels, %lld nodes, %lld edges (undirected%s), %d-connected, prune %s, build %.3f s\n",
              static_cast<long long>(st.voxels), static_cast<long long>(st.nodes), static_cast<long long>(st.edges),
              st.repairEdges ? (", " + std::to_string(st.repairEdges) + " repair").c_str() : "", a.connectivity,
              pruneText.c_str(), st.graphSeconds);
  std::printf("search: %lld nodes settled, %.3f s; features %.3f s; branch points %zu\n",
              static_cast<long long>(st.settled), st.searchSeconds, seconds["features"].get<double>(),
              tr.branchPoints().size());
  if (!a.json.empty()) outputs.writeBytes(a.json, rep.dump(1) + "\n");
  outputs.commit();
  return 0;
}

const vs::cli::Registration reg{
    "trace", "track vessels / airways: one root, many targets, one resumed search (thesis 4.3.2)",
    [](CLI::App& sub) -> vs::cli::Runner {
      auto a = std::make_shared<Args>();
      sub.add_option("volume", a->volume, "input volume (any format volscissors reads)")->required();
      sub.add_option("--root", a->root, "root voxel x,y,z (0-based index; --world: mm)");
      sub.add_option("--target", a->targets, "target voxel x,y,z (repeatable)");
      sub.add_option("--targets-file", a->targetsFile,
                     "targets: text lines 'x y z' or JSON ([[x,y,z],..] or {\"terminals\": .., \"root\": ..})");
      sub.add_option("--auto-terminals", a->autoTerminals,
                     "propose up to N terminals automatically (0: as many as --min-length allows)")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--min-length", a->minLengthMm, "automatic terminals: new branch length >= this (mm, default 10)");
      sub.add_option("--connectivity", a->connectivity, "6, 18 or 26 (default 26)")->check(CLI::IsMember({6, 18, 26}));
      sub.add_option("--prune", a->prune, "none | isoregion (thesis 4.1 pruned graph; field: --prune-on)")
          ->check(CLI::IsMember({"none", "isoregion"}));
      sub.add_option("--cost", a->cost, "gradient (eq. 19-22) | vesselness | intensity | given (voxels are costs)")
          ->check(CLI::IsMember({"gradient", "vesselness", "intensity", "given"}));
      sub.add_option("--polarity", a->polarity, "vesselness/intensity: bright (CTA vessels) | dark (airways)")
          ->check(CLI::IsMember({"bright", "dark"}));
      sub.add_option("--window", a->window, "intensity cost window lo,hi (default: 1st..99.9th percentile)");
      sub.add_option("--smooth", a->smoothMm, "intensity cost: Gaussian pre-smoothing sigma in mm (default 1)");
      sub.add_option("--scales", a->scales, "vesselness sigmas in mm, comma-separated (default 1,2,3 x spacing)");
      sub.add_option("--power", a->power, "vesselness/intensity cost exponent (default 4)");
      sub.add_option("--wg", a->wg, "gradient cost weight w_g (default 0.7)");
      sub.add_option("--wz", a->wz, "zero-crossing weight w_z (default 0.3)");
      sub.add_option("--prune-on", a->pruneOn,
                     "IsoRegion field: cost (default; the node costs the search sees) | intensity (thesis 4.1 literal)")
          ->check(CLI::IsMember({"cost", "intensity"}));
      sub.add_option("--cost-tolerance", a->costTolerance,
                     "--prune-on cost: costs within this relative difference count as equal (default 0 = exact)")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--threshold", a->threshold,
                     "--prune-on intensity: values below T are set to 0 first (thesis: 30)");
      sub.add_option("--tolerance", a->tolerance,
                     "--prune-on intensity: values within this (absolute) count as equal (default 0)");
      sub.add_option("--roi", a->roi, "region of interest x0,y0,z0,x1,y1,z1 (inclusive voxel box)");
      sub.add_flag("--world", a->world, "--root/--target(s) are world mm instead of voxel indices");
      sub.add_flag("--full", a->full, "complete the whole single-source search after the targets");
      sub.add_option("--out", a->out, "tree output: .swc, .vtk or .json (vs::writeTree)");
      sub.add_option("--json", a->json, "report: root, paths (voxels, cost, length_mm), branch points, graph, seconds");
      sub.add_option("--labels", a->labels, "label volume of the tree (.nii.gz, .nrrd, .mha): path index + 1");
      sub.add_option("--vtk", a->vtk, "legacy VTK polylines of the tree's branches");
      return [a] { return run(*a); };
    }};

}  // namespace
