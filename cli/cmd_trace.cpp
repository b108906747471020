// `volscissors trace VOLUME --root x,y,z (--target x,y,z)... | --targets-file F | --auto-terminals N | --full`
// Vessel / airway tracking (thesis 4.3.2, 6.2): one search from the root, resumed for every
// target; the paths refined to sub-voxel lumen centrelines with radii; writes the tree of
// extracted paths (SWC / VTK / JSON report / label volume). The pipeline itself is the core's
// tracking/trace_run (shared with Python's volscissors.trace); this file parses, crops and writes.
// Coordinates: 0-based voxel index x,y,z of VOLUME (--world: world mm as the reader reports).
// Exit status: 2 usage (bad option, coordinates outside the volume/ROI, duplicate targets, empty
// ROI, window lo >= hi), 1 data/IO (unreadable file, NaN voxels, no contrast for the auto cost,
// root/target outside any lumen within --snap, unreachable target, no terminal found). On exit
// 1 or 2 nothing is written.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <nlohmann/json.hpp>
#include <optional>

#include "args.h"
#include "command.h"
#include "cost/cost3d.h"
#include "io/mapped_volume.h"
#include "io/mesh_io.h"
#include "io/report_io.h"
#include "io/targets_io.h"
#include "io/volume_io.h"
#include "io/zarr_io.h"
#include "measure_summary.h"
#include "progress_line.h"
#include "quantify/quantify.h"
#include "quantify/report.h"
#include "tracking/chunked_trace.h"
#include "tracking/trace_run.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "volume/crop.h"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

const vs::TraceOptions kDefaults;
const vs::Cost3DOptions kCostDefaults;

struct Args {
  std::string volume, root, targetsFile, roi, out, json, labels, vtk, window, scales, measure;
  std::vector<std::string> targets;
  int autoTerminals = -1;
  double minLengthMm = kDefaults.autoTerminals.minLengthMm;
  bool continueDim = kDefaults.autoTerminals.continueDimBranches;
  int connectivity = kDefaults.tracker.connectivity;
  std::string prune = kDefaults.tracker.prune == vs::PruneMode::IsoRegion ? "isoregion" : "none";
  std::string pruneOn = vs::isoRegionFieldName(kDefaults.tracker.isoRegion.field), cost = kDefaults.cost;
  std::string polarity = kCostDefaults.polarity == vs::TubePolarity::Dark ? "dark" : "bright";
  double threshold = NAN, tolerance = kDefaults.tracker.isoRegion.tolerance,
         costTolerance = kDefaults.tracker.isoRegion.costTolerance, smoothMm = NAN;
  double wg = kCostDefaults.wg, wz = kCostDefaults.wz, power = kDefaults.autoCost.power;
  double upperEdge = kDefaults.autoCost.upperFraction;
  double snapMm = kDefaults.snapMm;
  bool full = false, world = false, noRefine = false, noCrossing = false;
  // Given on the command line (options a cost does not use are a usage error).
  bool polarityGiven = false, scalesGiven = false, powerGiven = false, wgGiven = false, wzGiven = false;
  bool upperEdgeGiven = false;
  double chunkedAboveMiB = 1024;  // .zarr inputs above this (float32 voxels) are traced chunk by chunk
};
constexpr int64_t kChunkCacheBytes = int64_t(512) << 20;

// Options that only some costs use: naming one with another cost is a usage error (it would
// change nothing).
void requireCostUses(const Args& a) {
  auto check = [&](bool given, const char* option, std::initializer_list<const char*> costs, const char* names) {
    if (!given) return;
    for (const char* c : costs)
      if (a.cost == c) return;
    throw vs::UsageError(std::string(option) + " applies to --cost " + names + "; --cost " + a.cost +
                         (a.cost == "auto" ? " (the default) estimates its own lumen model and" : "") +
                         " does not use it");
  };
  check(a.polarityGiven, "--polarity", {"vesselness", "intensity"}, "vesselness or intensity");
  check(a.scalesGiven, "--scales", {"vesselness"}, "vesselness");
  check(a.powerGiven, "--power", {"auto", "vesselness", "intensity"}, "auto, vesselness or intensity");
  check(a.wgGiven, "--wg", {"gradient"}, "gradient");
  check(a.wzGiven, "--wz", {"gradient"}, "gradient");
  check(!a.window.empty(), "--window", {"intensity"}, "intensity");
  check(a.upperEdgeGiven, "--upper-edge", {"auto"}, "auto");
}

std::string str(const vs::Index3& v) {
  return "(" + std::to_string(v[0]) + "," + std::to_string(v[1]) + "," + std::to_string(v[2]) + ")";
}

// An OME-Zarr volume (or a memory-mapped NIfTI/NRRD) larger than --chunked-above: block-wise costs and a block-sparse
// exact search (tracking/chunked_trace.h); only point-to-point paths, intensity or given costs, --json.
int runChunked(const Args& a, vs::ChunkedVolume cv, const vs::Vec3& rootGiven, const std::vector<vs::Vec3>& rawTargets,
               vs::Progress& progress) {
  const auto t0 = Clock::now();
  if (a.autoTerminals >= 0 || a.full || !a.out.empty() || !a.vtk.empty() || !a.labels.empty() || !a.roi.empty() ||
      !a.measure.empty() || a.prune != Args{}.prune)
    throw vs::UsageError(a.volume +
                         " is traced chunk by chunk (larger than --chunked-above): only --target/--targets-file, "
                         "--cost intensity|given, --window, --polarity, --power, --world, --smooth (of the "
                         "refinement only), --no-refine and --json apply");
  if (rawTargets.empty()) throw vs::UsageError("give --target or --targets-file");
  vs::ChunkedTraceOptions o;
  if (a.cost == "intensity" || a.cost == "auto") {
    o.cost.kind = vs::CostKind3D::Intensity;
    if (a.cost == "auto")
      vs::cli::note("note: chunked volume: the auto cost is the intensity cost (no whole-volume estimate)");
  } else if (a.cost == "given") {
    o.cost.kind = vs::CostKind3D::Given;
  } else {
    throw vs::UsageError("--cost " + a.cost + " needs the whole volume; chunked volumes take intensity or given");
  }
  if (!a.window.empty()) {
    const auto window = vs::cli::parseNumbers(a.window, "--window", 2);
    if (!(window[1] > window[0])) throw vs::UsageError("--window lo,hi needs lo < hi, got '" + a.window + "'");
    o.cost.windowLo = window[0], o.cost.windowHi = window[1];
  }
  o.cost.power = a.power;
  o.refine = !a.noRefine;
  // The cost is not smoothed (pointwise, no halo); the refinement's intensities are, as in memory.
  o.refineSmoothMm = std::isnan(a.smoothMm) ? (o.cost.kind == vs::CostKind3D::Intensity ? kDefaults.intensitySmoothMm
                                                                                        : kDefaults.autoCost.smoothMm)
                                            : a.smoothMm;
  if (o.refineSmoothMm < 0) throw vs::UsageError("--smooth must be >= 0 mm");
  o.centreline = kDefaults.centreline;
  o.cost.polarity = a.polarity == "dark" ? vs::TubePolarity::Dark : vs::TubePolarity::Bright;
  const vs::Geometry G = cv.geometry;
  auto toVoxel = [&](const vs::Vec3& p, const std::string& what) {
    const vs::Vec3 idx = a.world ? G.worldToIndex(p) : p;
    const vs::Index3 v = vs::roundIndex(idx);
    if (!G.contains(v)) throw vs::UsageError(what + " " + str(v) + " is outside the volume " + G.describe());
    return v;
  };
  const vs::Index3 root = toVoxel(rootGiven, "root");
  std::vector<vs::Index3> targets;
  for (size_t i = 0; i < rawTargets.size(); ++i)
    targets.push_back(toVoxel(rawTargets[i], "target #" + std::to_string(i + 1)));
  vs::ChunkCache cache(std::move(cv), kChunkCacheBytes);
  const vs::ChunkedTraceResult r = vs::traceChunked(cache, root, targets, o, progress);
  vs::cli::clearProgressLine();
  std::printf("cost: %s (chunked, window %.6g..%.6g)\n", r.costDescription.c_str(), r.windowLo, r.windowHi);
  vs::TraceReport rep;
  rep.volume = a.volume;
  rep.root = root;
  rep.requestedRoot = root;
  rep.cost = r.costDescription;
  std::printf("%-5s %-18s %8s %10s %12s\n", "path", "target", "voxels", "length_mm", "cost");
  for (size_t i = 0; i < r.paths.size(); ++i) {
    const vs::Path& p = r.paths[i];
    if (p.empty())
      throw vs::DataError("target #" + std::to_string(i + 1) + " " + str(targets[i]) + " is unreachable from the root");
    vs::TraceReportPath jp;
    jp.target = targets[i];
    jp.requested = targets[i];
    jp.reached = true;
    jp.cost = p.cost;
    jp.lengthMm = p.lengthMm;
    jp.voxels = p.voxels;
    if (o.refine) {
      jp.points = r.points[i];
      jp.radiiMm = r.radiiMm[i];
    }
    std::printf("%-5zu %-18s %8zu %10.2f %12.6g\n", i, str(targets[i]).c_str(), p.voxels.size(), p.lengthMm, p.cost);
    rep.paths.push_back(std::move(jp));
  }
  const double secs = since(t0);
  std::printf(
      "search: %lld nodes settled, %lld blocks (%.1f MiB of search state), %lld chunks read (cache peak "
      "%.1f MiB), %.3f s\n",
      static_cast<long long>(r.search.settled), static_cast<long long>(r.search.blocksTouched),
      double(r.search.blockBytes) / 1048576.0, static_cast<long long>(r.cache.loads),
      double(r.cache.peakBytes) / 1048576.0, secs);
  if (o.refine)
    std::printf("refine: %.3f s, largest region %lld voxels (smoothing %g mm)\n", r.refineSeconds,
                static_cast<long long>(r.refineRegionVoxels), o.refineSmoothMm);
  rep.graph = {{"chunked", true},
               {"settled", r.search.settled},
               {"blocks", r.search.blocksTouched},
               {"block_bytes", r.search.blockBytes},
               {"chunks_read", r.cache.loads},
               {"cache_peak_bytes", r.cache.peakBytes},
               {"connectivity", 26}};
  rep.seconds = {{"total", secs}};
  if (o.refine) rep.seconds["refine"] = r.refineSeconds;
  vs::OutputSet outputs;
  if (!a.json.empty()) outputs.write(a.json, [&](const std::string& t) { vs::writeTraceReport(rep, t); });
  outputs.commit();
  return 0;
}

// Root and targets as written (checked against the volume later): bad text fails before loading.
void givenEndpoints(const Args& a, vs::Vec3& rootGiven, std::vector<vs::Vec3>& rawTargets) {
  std::optional<vs::Vec3> fileRoot;
  for (const auto& t : a.targets) rawTargets.push_back(vs::cli::parseVec3(t, "--target"));
  if (!a.targetsFile.empty()) {
    vs::TargetList file = vs::readTargetList(a.targetsFile);
    fileRoot = file.root;
    rawTargets.insert(rawTargets.end(), file.targets.begin(), file.targets.end());
  }
  if (a.root.empty() && !fileRoot) throw vs::UsageError("--root x,y,z is required");
  rootGiven = a.root.empty() ? *fileRoot : vs::cli::parseVec3(a.root, "--root");
}

// A given point (voxel index, or world mm with --world) as a voxel of the volume.
vs::Index3 toVoxel(const Args& a, const vs::Geometry& G, const vs::Vec3& p, const std::string& what) {
  const vs::Vec3 idx = a.world ? G.worldToIndex(p) : p;
  if (!a.world)
    for (int c = 0; c < 3; ++c)
      if (p[c] != std::floor(p[c]))
        throw vs::UsageError(what + ": voxel coordinates must be integers (or use --world)");
  const vs::Index3 v = vs::roundIndex(idx);
  if (!G.contains(v)) throw vs::UsageError(what + " " + str(v) + " is outside the volume " + G.describe());
  return v;
}

// The targets as voxels: inside the volume, neither a duplicate nor the root.
std::vector<vs::Index3> targetVoxels(const Args& a, const vs::Geometry& G, const std::vector<vs::Vec3>& rawTargets,
                                     const vs::Index3& root) {
  std::vector<vs::Index3> targets;
  for (size_t i = 0; i < rawTargets.size(); ++i) {
    const vs::Index3 t = toVoxel(a, G, rawTargets[i], "target #" + std::to_string(i + 1));
    for (size_t k = 0; k < targets.size(); ++k)
      if (targets[k] == t)
        throw vs::UsageError("target #" + std::to_string(i + 1) + " " + str(t) + " duplicates target #" +
                             std::to_string(k + 1));
    if (t == root) throw vs::UsageError("target #" + std::to_string(i + 1) + " " + str(t) + " is the root");
    targets.push_back(t);
  }
  return targets;
}

// The trace options, the IsoRegion pruning and the cost's parameters from the command line.
void setTraceOptions(const Args& a, vs::TraceRequest& rq) {
  vs::TraceOptions& opt = rq.options;
  opt.cost = a.cost;
  opt.refine = !a.noRefine;
  opt.snapMm = a.snapMm;
  opt.tracker.crossing.enabled = !a.noCrossing;
  opt.autoTerminals.minLengthMm = a.minLengthMm;
  // An option that would change nothing is an error, not ignored.
  if (a.continueDim && a.autoTerminals < 0) throw vs::UsageError("--continue-dim applies to --auto-terminals only");
  opt.autoTerminals.continueDimBranches = a.continueDim;
  opt.autoCost.power = a.power;
  opt.autoCost.upperFraction = a.upperEdge;
  vs::TrackerOptions& to = opt.tracker;
  to.connectivity = a.connectivity;
  to.prune = a.prune == "isoregion" ? vs::PruneMode::IsoRegion : vs::PruneMode::None;
  if (to.prune == vs::PruneMode::None && (!std::isnan(a.threshold) || a.tolerance != 0 || a.costTolerance != 0))
    vs::cli::note(
        "note: --threshold/--tolerance/--cost-tolerance only shape the IsoRegion map; they have no effect without "
        "--prune isoregion");
  to.isoRegion.field = vs::isoRegionFieldFromName(a.pruneOn);
  if (to.prune == vs::PruneMode::IsoRegion && to.isoRegion.field == vs::IsoRegionField::Cost &&
      (!std::isnan(a.threshold) || a.tolerance != 0))
    throw vs::UsageError(
        "--threshold/--tolerance shape the intensity IsoRegion map: add --prune-on intensity "
        "(the default --prune-on cost takes --cost-tolerance)");
  if (to.prune == vs::PruneMode::IsoRegion && to.isoRegion.field == vs::IsoRegionField::Intensity &&
      a.costTolerance != 0)
    throw vs::UsageError("--cost-tolerance applies to --prune-on cost, not intensity (use --tolerance)");
  if (to.prune == vs::PruneMode::IsoRegion) {
    if (to.isoRegion.field == vs::IsoRegionField::Intensity) {
      to.isoRegion.tolerance = a.tolerance;
      if (!std::isnan(a.threshold)) to.isoRegion.threshold = a.threshold;
    } else {
      to.isoRegion.costTolerance = a.costTolerance;
    }
  }
  if (!a.window.empty()) {
    const auto window = vs::cli::parseNumbers(a.window, "--window", 2);
    if (!(window[1] > window[0])) throw vs::UsageError("--window lo,hi needs lo < hi, got '" + a.window + "'");
    rq.cost.windowLo = window[0], rq.cost.windowHi = window[1];
  }
  if (!std::isnan(a.smoothMm) && a.smoothMm < 0) throw vs::UsageError("--smooth must be >= 0 mm");
  rq.smoothMm = a.smoothMm;
  rq.cost.wg = a.wg, rq.cost.wz = a.wz, rq.cost.power = a.power;
  rq.cost.polarity = a.polarity == "dark" ? vs::TubePolarity::Dark : vs::TubePolarity::Bright;
  if (!a.scales.empty()) rq.cost.vesselness.scalesMm = vs::cli::parseNumbers(a.scales, "--scales", 0);
}

// Region of interest (inclusive voxel box; the whole volume without --roi): root and targets inside.
vs::VoxelBox roiBox(const Args& a, const vs::Geometry& G, const vs::Index3& root,
                    const std::vector<vs::Index3>& targets) {
  vs::VoxelBox box = vs::wholeBox(G);
  if (a.roi.empty()) return box;
  const auto r = vs::cli::parseNumbers(a.roi, "--roi", 6);
  try {
    box = vs::clampBox(G, vs::Vec3(r[0], r[1], r[2]), vs::Vec3(r[3], r[4], r[5]));
  } catch (const vs::InvalidArgument& e) {
    throw vs::UsageError(std::string("--roi: ") + e.what());
  }
  if (!box.contains(root)) throw vs::UsageError("root " + str(root) + " is outside the --roi");
  for (size_t i = 0; i < targets.size(); ++i)
    if (!box.contains(targets[i]))
      throw vs::UsageError("target #" + std::to_string(i + 1) + " " + str(targets[i]) + " is outside the --roi");
  return box;
}

// The trace report in full-volume indices (paths, branch points, graph), the root and the path
// table printed.
vs::TraceReport traceReport(const Args& a, const vs::TraceResult& tr, const vs::VoxelBox& box, const vs::Index3& root) {
  auto global = [&](const vs::Index3& v) { return box.toGlobal(v); };
  const vs::TrackerStats& st = tr.stats;
  vs::TraceReport rep;
  rep.volume = a.volume;
  rep.root = global(tr.root);
  rep.requestedRoot = root;
  rep.cost = tr.costDescription;
  rep.notes = tr.notes;
  if (tr.estimate) {
    const vs::LumenEstimate& e = *tr.estimate;
    rep.costEstimate = {{"polarity", e.polarity == vs::TubePolarity::Bright ? "bright" : "dark"},
                        {"lumen", e.lumen},
                        {"spread", e.spread},
                        {"surroundings", e.surround},
                        {"window", {e.windowLo, e.windowHi}},
                        {"smooth_mm", tr.smoothMm},
                        {"model", vs::LumenEstimate::model},
                        {"local_contrast", {e.localLo, e.localHi}},
                        {"local_block_mm", e.localBlockMm},
                        {"local_percentile", e.localPercentile},
                        {"local_fraction", e.localFraction},
                        {"local_noise_floor", e.localNoiseFloor},
                        {"ring_radii_mm", e.ringRadiiMm},
                        {"connected_voxels", e.connectedVoxels}};
    // The upper edge (bright; dark: the lower edge): full lumen up to the first, none beyond the second (null: none).
    rep.costEstimate["upper_edge"] =
        e.hasUpperEdge() ? nlohmann::json::array({e.upperLo, e.upperHi}) : nlohmann::json();
    // The window's far edge before it was cut where the root's connected lumen spilled (null: no cut).
    rep.costEstimate["window_cut_from"] = e.spillVoxels > 0 ? nlohmann::json(e.spillFrom) : nlohmann::json();
  }
  std::printf("root: requested %s, used %s\n", str(root).c_str(), str(global(tr.root)).c_str());
  if (!tr.paths.empty())
    std::printf("%-5s %-18s %-18s %8s %10s %12s %10s %7s\n", "path", "requested", "target", "voxels", "length_mm",
                "cost", "cost/mm", "parent");
  for (size_t i = 0; i < tr.paths.size(); ++i) {
    const vs::TracedPath& p = tr.paths[i];
    vs::TraceReportPath jp;
    jp.target = global(p.target);
    jp.requested = global(p.requested);
    jp.reached = p.reached;
    jp.cost = p.cost;
    jp.lengthMm = p.lengthMm;
    jp.parentPath = p.parentPath;
    for (const auto& v : p.voxels) jp.voxels.push_back(global(v));
    if (tr.refined) {
      for (const auto& q : tr.points[i]) jp.points.push_back(box.toGlobal(q));
      jp.radiiMm = tr.radiiMm[i];
    }
    auto txt = [](const vs::Index3& t) {
      return std::to_string(t[0]) + "," + std::to_string(t[1]) + "," + std::to_string(t[2]);
    };
    std::printf("%-5zu %-18s %-18s %8zu %10.2f %12.5g %10.4g %7d\n", i, txt(jp.requested).c_str(),
                txt(jp.target).c_str(), p.voxels.size(), p.lengthMm, p.cost, p.lengthMm > 0 ? p.cost / p.lengthMm : 0.0,
                p.parentPath);
    rep.paths.push_back(std::move(jp));
  }
  for (const auto& b : tr.branchPoints) rep.branchPoints.push_back(global(b));
  rep.graph = {{"voxels", st.voxels},
               {"nodes", st.nodes},
               {"edges", st.edges},
               {"repair_edges", st.repairEdges},
               {"connectivity", a.connectivity},
               {"prune", a.prune},
               {"settled", st.settled},
               {"terminal_search_settled", st.terminalSearchSettled},
               {"prune_on", a.prune == "none" ? "" : a.pruneOn},
               {"cost_tolerance", a.prune == "none" || a.pruneOn != "cost" ? 0.0 : a.costTolerance},
               {"full_search", st.fullSearch}};
  return rep;
}

// The graph and search lines of the summary.
void printSearchSummary(const Args& a, const vs::TraceResult& tr, double featureSeconds) {
  const vs::TrackerStats& st = tr.stats;
  const std::string pruneText = a.prune == "none" ? a.prune : a.prune + " on " + a.pruneOn;
  std::printf("graph: %lld voxels, %lld nodes, %lld edges (undirected%s), %d-connected, prune %s, build %.3f s\n",
              static_cast<long long>(st.voxels), static_cast<long long>(st.nodes), static_cast<long long>(st.edges),
              st.repairEdges ? (", " + std::to_string(st.repairEdges) + " repair").c_str() : "", a.connectivity,
              pruneText.c_str(), st.graphSeconds);
  std::printf("search: %lld nodes settled%s%s, %.3f s; features %.3f s; refine %.3f s; branch points %zu\n",
              static_cast<long long>(st.settled), st.fullSearch ? " (all reachable)" : "",
              st.terminalSearchSettled
                  ? (" (terminal scan: " + std::to_string(st.terminalSearchSettled) + " lumen voxels)").c_str()
                  : "",
              st.searchSeconds, featureSeconds, tr.refined ? tr.refineSeconds : 0.0, tr.branchPoints.size());
}

int run(const Args& a) {
  vs::Vec3 rootGiven;
  std::vector<vs::Vec3> rawTargets;
  givenEndpoints(a, rootGiven, rawTargets);

  vs::cli::ProgressLine progressLine("trace");
  vs::Progress& progress = progressLine.progress();
  if (vs::isZarrPath(a.volume) || vs::isMappable(a.volume)) {  // OME-Zarr, or uncompressed NIfTI/NRRD mapped
    vs::ChunkedVolume cv = vs::isZarrPath(a.volume) ? vs::openZarr(a.volume) : vs::openMapped(a.volume);
    if (double(cv.geometry.voxelCount()) * 4.0 > a.chunkedAboveMiB * 1048576.0)
      return runChunked(a, std::move(cv), rootGiven, rawTargets, progress);
  }
  requireCostUses(a);  // (a chunked volume's auto cost is the intensity cost: its own rules above)
  const auto tLoad = Clock::now();
  nlohmann::json seconds;
  // Non-finite voxels are checked by runTrace (+inf is an impassable given cost).
  vs::VolumeF32 full = vs::toFloat(vs::readVolume(a.volume, {}, nullptr, progress));
  seconds["load"] = since(tLoad);
  const vs::Geometry& G = full.geometry();

  const vs::Index3 root = toVoxel(a, G, rootGiven, "root");
  const bool mapOnly = rawTargets.empty() && a.autoTerminals < 0;
  if (mapOnly && !a.full) throw vs::UsageError("give --target, --targets-file, --auto-terminals N or --full");
  if (mapOnly && (!a.out.empty() || !a.vtk.empty() || !a.labels.empty() || !a.measure.empty()))
    throw vs::UsageError(
        "--full without targets computes the map only: --out, --vtk, --labels and --measure need targets");
  const std::vector<vs::Index3> targets = targetVoxels(a, G, rawTargets, root);

  vs::TraceRequest rq;
  rq.volumeName = a.volume;
  setTraceOptions(a, rq);
  const vs::VoxelBox box = roiBox(a, G, root, targets);
  vs::VolumeF32 vol = a.roi.empty() ? std::move(full) : vs::cropVolume(full, box);
  const vs::Geometry fullGeometry = G;
  full = vs::VolumeF32();

  const auto range = std::minmax_element(vol.voxels().begin(), vol.voxels().end());
  if (!std::isnan(a.threshold) && a.threshold > *range.second)
    throw vs::DataError("--threshold " + std::to_string(a.threshold) + " removes every voxel (largest value " +
                        std::to_string(*range.second) + ")");

  rq.root = box.toLocal(root);
  for (const auto& t : targets) rq.targets.push_back(box.toLocal(t));
  rq.autoTerminals = a.autoTerminals;
  rq.full = a.full;
  rq.labels = !a.labels.empty();
  rq.messageOffset = box.lo;  // messages name full-volume indices
  vs::TraceResult tr = vs::runTrace(vol, rq, progress);
  seconds["features"] = tr.featureSeconds;
  vs::cli::clearProgressLine();
  std::printf("cost: %s\n", tr.costDescription.c_str());
  for (const auto& n : tr.notes) vs::cli::note(n);
  seconds["graph"] = tr.stats.graphSeconds;
  seconds["search"] = tr.stats.searchSeconds;
  seconds["search_cpu"] = tr.searchCpuSeconds;
  if (tr.refined) {
    seconds["refine"] = tr.refineSeconds;
    seconds["refine_cpu"] = tr.refineCpuSeconds;
  }
  if (tr.stats.terminalRegionSeconds > 0) seconds["terminal_region"] = tr.stats.terminalRegionSeconds;
  seconds["phases"] = nlohmann::json::array();  // in order: name, wall s, CPU s (all threads)
  for (const vs::PhaseTime& p : tr.phases) seconds["phases"].push_back({p.name, p.wall, p.cpu});

  // Quantification along the traced tree (issue 24): cross-sections in the (cropped) volume.
  std::optional<vs::TreeMeasurement> measured;
  if (!a.measure.empty()) {
    const auto tMeasure = Clock::now();
    measured = vs::measureTree(vol, tr.tree, {}, progress);
    seconds["measure"] = since(tMeasure);
    vs::cli::clearProgressLine();
    vs::cli::printMeasurement(*measured, seconds["measure"].get<double>());
  }

  // Outputs (all computed before the first is written).
  const auto tOut = Clock::now();
  vs::TraceReport rep = traceReport(a, tr, box, root);
  std::optional<vs::VolumeU16> labels;
  if (tr.labels) {
    if (a.roi.empty()) {
      labels = std::move(*tr.labels);
    } else {
      labels.emplace(fullGeometry, 0);
      vs::pasteVolume(*tr.labels, box, *labels);
    }
  }
  const vs::Tree tree = measured ? vs::treeWithMeasuredRadii(*measured) : tr.tree;
  vs::OutputSet outputs;  // all or nothing: committed after the report below
  if (!a.out.empty()) outputs.write(a.out, [&](const std::string& t) { vs::writeTree(tree, t); });
  if (!a.vtk.empty()) outputs.write(a.vtk, [&](const std::string& t) { vs::writePolylines(tree.toPolylines(), t); });
  if (labels)
    outputs.write(a.labels, [&](const std::string& t) { vs::writeVolume(vs::AnyVolume(std::move(*labels)), t); });
  seconds["output"] = since(tOut);
  rep.seconds = seconds;
  printSearchSummary(a, tr, seconds["features"].get<double>());
  if (measured) outputs.writeBytes(a.measure, vs::measurementCsv(*measured));
  if (!a.json.empty() && measured) {
    nlohmann::json j = vs::traceReportToJson(rep);
    j["measure"] = vs::measurementToJson(*measured, {});
    outputs.writeBytes(a.json, j.dump(1) + "\n");
  } else if (!a.json.empty()) {
    outputs.write(a.json, [&](const std::string& t) { vs::writeTraceReport(rep, t); });
  }
  outputs.commit();
  return 0;
}

std::string fmtDefault(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

const vs::cli::Registration reg{
    "trace",
    "track vessels / airways: one root, many targets, one resumed search, sub-voxel centrelines (thesis 4.3.2)",
    [](CLI::App& sub) -> vs::cli::Runner {
      auto a = std::make_shared<Args>();
      const vs::TraceOptions& d = kDefaults;
      sub.add_option("volume", a->volume, "input volume (any format volscissors reads)")->required();
      sub.add_option("--root", a->root, "root voxel x,y,z (0-based index; --world: mm)");
      sub.add_option("--target", a->targets, "target voxel x,y,z (repeatable)");
      sub.add_option("--targets-file", a->targetsFile,
                     "targets: text lines 'x y z' or JSON ([[x,y,z],..] or {\"terminals\": .., \"root\": ..})");
      sub.add_option("--auto-terminals", a->autoTerminals,
                     "propose up to N terminals automatically (0: as many as --min-length allows)")
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--min-length", a->minLengthMm, "automatic terminals: new branch length >= this (mm)")
          ->capture_default_str()
          ->check(CLI::PositiveNumber);
      sub.add_flag("--continue-dim", a->continueDim,
                   "automatic terminals: continue the lumen region along branches that dim below its level where they "
                   "stay a resolved tube (off by default)");
      sub.add_option("--connectivity", a->connectivity, "6, 18 or 26")
          ->capture_default_str()
          ->check(CLI::IsMember({6, 18, 26}));
      sub.add_option("--prune", a->prune, "none | isoregion (thesis 4.1 pruned graph; field: --prune-on)")
          ->capture_default_str()
          ->check(CLI::IsMember({"none", "isoregion"}));
      sub.add_option(
             "--cost", a->cost,
             "auto (intensity cost, polarity and window estimated at the root) | intensity | "
             "vesselness | gradient (thesis eq. 19-22, follows walls) | given (voxels are costs, +inf impassable)")
          ->capture_default_str()
          ->check(CLI::IsMember({"auto", "gradient", "vesselness", "intensity", "given"}));
      auto* polarity =
          sub.add_option("--polarity", a->polarity, "vesselness/intensity: bright (CTA vessels) | dark (airways)")
              ->capture_default_str()
              ->check(CLI::IsMember({"bright", "dark"}));
      sub.add_option("--window", a->window, "intensity cost window lo,hi (default: 1st..99.9th percentile)");
      sub.add_option("--smooth", a->smoothMm,
                     "auto/intensity cost: Gaussian pre-smoothing sigma in mm (default " +
                         fmtDefault(d.autoCost.smoothMm) + " auto, " + fmtDefault(d.intensitySmoothMm) + " intensity)");
      sub.add_option("--snap", a->snapMm,
                     "root/targets outside the lumen move to the nearest lumen voxel within R mm (0: off)")
          ->capture_default_str()
          ->check(CLI::NonNegativeNumber);
      sub.add_flag("--no-refine", a->noRefine, "keep the voxel paths (no sub-voxel centring, radii from the voxels)");
      sub.add_flag("--no-crossing-retrace", a->noCrossing,
                   "keep a target's path that steps or drifts sideways into a touching tube as the search found it");
      auto* scales =
          sub.add_option("--scales", a->scales, "vesselness sigmas in mm, comma-separated (default 1,2,3 x spacing)");
      auto* power = sub.add_option("--power", a->power, "auto/vesselness/intensity cost exponent")
                        ->capture_default_str()
                        ->check(CLI::PositiveNumber);
      auto* upper = sub.add_option("--upper-edge", a->upperEdge,
                                   "auto cost: values beyond the root's lumen by more than this many lumen contrasts "
                                   "(lumen - surroundings) are less and less lumen, none from 1.5 x as many (bright: "
                                   "bone, calcium, metal; dark: mirrored); 0: no edge")
                        ->capture_default_str()
                        ->check(CLI::NonNegativeNumber);
      auto* wg = sub.add_option("--wg", a->wg, "gradient cost weight w_g")->capture_default_str();
      auto* wz = sub.add_option("--wz", a->wz, "gradient cost: zero-crossing weight w_z")->capture_default_str();
      sub.add_option("--prune-on", a->pruneOn,
                     "IsoRegion field: cost (the node costs the search sees) | intensity (thesis 4.1 literal)")
          ->capture_default_str()
          ->check(CLI::IsMember({"cost", "intensity"}));
      sub.add_option("--cost-tolerance", a->costTolerance,
                     "--prune-on cost: costs within this relative difference count as equal (0 = exact)")
          ->capture_default_str()
          ->check(CLI::NonNegativeNumber);
      sub.add_option("--threshold", a->threshold,
                     "--prune-on intensity: values below T are set to 0 first (thesis: 30)");
      sub.add_option("--tolerance", a->tolerance, "--prune-on intensity: values within this (absolute) count as equal")
          ->capture_default_str();
      sub.add_option("--roi", a->roi,
                     "region of interest x0,y0,z0,x1,y1,z1 (inclusive voxel box; default: whole volume)");
      sub.add_flag("--world", a->world, "--root/--target(s) are world mm instead of voxel indices");
      sub.add_option("--chunked-above", a->chunkedAboveMiB,
                     "MiB: a .zarr volume, or an uncompressed .nii/.nrrd/.nhdr (memory-mapped), whose float32 "
                     "voxels exceed this is traced chunk by chunk (block-wise "
                     "costs, exact search over the blocks it reaches, chunk cache 512 MiB; --cost intensity|given, "
                     "--json only)")
          ->capture_default_str();
      sub.add_flag("--full", a->full, "complete the whole single-source map first (alone: the map only)");
      sub.add_option("--out", a->out, "tree output: .swc, .vtk or .json (refined world positions and radii)");
      sub.add_option("--json", a->json,
                     "report: root (requested, used), cost and its estimate, paths (voxels, refined points, radii), "
                     "branch points, graph, seconds");
      sub.add_option("--labels", a->labels, "label volume of the tree (.nii.gz, .nrrd, .mha): path index + 1");
      sub.add_option("--vtk", a->vtk, "legacy VTK polylines of the tree's branches");
      sub.add_option("--measure", a->measure,
                     "quantify the tree (as `measure`): cross-sections CSV here, summary in --json, --out radii "
                     "from the measured cross-sections");
      return [a, polarity, scales, power, wg, wz, upper] {
        a->polarityGiven = polarity->count() > 0, a->scalesGiven = scales->count() > 0;
        a->upperEdgeGiven = upper->count() > 0;
        a->powerGiven = power->count() > 0, a->wgGiven = wg->count() > 0, a->wzGiven = wz->count() > 0;
        return run(*a);
      };
    }};

}  // namespace
