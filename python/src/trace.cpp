// volscissors.trace: vessel / airway tracking through the core's trace pipeline
// (tracking/trace_run.h), the one `volscissors trace` runs, with the same defaults (read from the
// core's option structs here, never copied). Returns a Tree of NumPy arrays.
#include <cmath>
#include <cstdio>
#include <initializer_list>
#include <limits>

#include "common.h"
#include "io/mesh_io.h"
#include "quantify/quantify.h"
#include "quantify/report.h"
#include "tracking/trace_run.h"

namespace vspy {

namespace {

const vs::TraceOptions kDefaults;
const vs::Cost3DOptions kCostDefaults;

struct Path {
  py::array voxels, points, pointsMm, radii;
  py::tuple target, requested;
  bool reached = false;
  double cost = 0, lengthMm = 0;
  int parent = -1;
  size_t junctionIndex = 0;
  py::object profile = py::none();  // set by Tree.measure
};

struct Tree {
  std::vector<Path> paths;
  py::array branchPoints, nodePoints, nodeParents, nodeRadii;
  py::tuple root, requestedRoot;
  std::string costDescription;
  py::object costEstimate = py::none();
  py::list notes;
  py::dict stats;
  bool refined = false;
  vs::Tree swc;  // for save()
};

std::string str(const vs::Index3& v) {
  return "(" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) + ")";
}

// (N, 3) array of rows of three numbers (Index3 or Vec3), mapped through `f`.
template <class T, class Row, class F>
py::array rows(const std::vector<Row>& v, F&& f) {
  py::array_t<T> a({static_cast<py::ssize_t>(v.size()), py::ssize_t(3)});
  auto m = a.template mutable_unchecked<2>();
  for (size_t i = 0; i < v.size(); ++i) {
    const auto r = f(v[i]);
    for (py::ssize_t c = 0; c < 3; ++c) m(static_cast<py::ssize_t>(i), c) = static_cast<T>(r[c]);
  }
  return a;
}

py::array indexArray(const std::vector<vs::Index3>& v) {
  return rows<int64_t>(v, [](const vs::Index3& x) { return x; });
}

template <class T>
py::array vectorArray(const std::vector<T>& v) {
  py::array_t<T> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::tuple tupleOf(const vs::Index3& v) { return py::make_tuple(v[0], v[1], v[2]); }

Tree toPython(vs::TraceResult&& r, const vs::Geometry& g) {
  Tree t;
  for (size_t i = 0; i < r.paths.size(); ++i) {
    const vs::TracedPath& p = r.paths[i];
    Path out;
    out.voxels = indexArray(p.voxels);
    std::vector<vs::Vec3> pts = r.points[i];
    if (!r.refined)  // the voxel centres
      for (const auto& v : p.voxels) pts.emplace_back(double(v[0]), double(v[1]), double(v[2]));
    out.points = rows<double>(pts, [](const vs::Vec3& x) { return x; });
    out.pointsMm = rows<double>(pts, [&](const vs::Vec3& x) { return g.indexToWorld(x); });
    out.radii = vectorArray(r.radiiMm[i]);
    out.target = tupleOf(p.target);
    out.requested = tupleOf(p.requested);
    out.reached = p.reached;
    out.cost = p.cost;
    out.lengthMm = p.lengthMm;
    out.parent = p.parentPath;
    out.junctionIndex = p.junctionIndex;
    t.paths.push_back(std::move(out));
  }
  t.branchPoints = indexArray(r.branchPoints);
  t.nodePoints = rows<double>(r.tree.points, [](const Eigen::Vector3d& x) { return x; });
  t.nodeParents = vectorArray(r.tree.parent);
  t.nodeRadii = vectorArray(r.tree.radii);
  t.root = tupleOf(r.root);
  t.requestedRoot = tupleOf(r.requestedRoot);
  t.costDescription = r.costDescription;
  if (r.estimate) {
    const vs::LumenEstimate& e = *r.estimate;
    py::dict d;
    d["polarity"] = e.polarity == vs::TubePolarity::Bright ? "bright" : "dark";
    d["lumen"] = e.lumen;
    d["spread"] = e.spread;
    d["surroundings"] = e.surround;
    d["window"] = py::make_tuple(e.windowLo, e.windowHi);
    d["smooth_mm"] = r.smoothMm;
    d["model"] = vs::LumenEstimate::model;
    d["local_contrast"] = py::make_tuple(e.localLo, e.localHi);
    d["local_block_mm"] = e.localBlockMm;
    d["local_percentile"] = e.localPercentile;
    d["local_fraction"] = e.localFraction;
    d["local_noise_floor"] = e.localNoiseFloor;
    d["ring_radii_mm"] = py::cast(e.ringRadiiMm);
    d["connected_voxels"] = e.connectedVoxels;
    d["window_cut_from"] = e.spillVoxels > 0 ? py::object(py::float_(e.spillFrom)) : py::object(py::none());
    d["upper_edge"] = e.hasUpperEdge() ? py::object(py::make_tuple(e.upperLo, e.upperHi)) : py::object(py::none());
    t.costEstimate = d;
  }
  for (const auto& n : r.notes) t.notes.append(n);
  t.refined = r.refined;
  t.stats["voxels"] = r.stats.voxels;
  t.stats["nodes"] = r.stats.nodes;
  t.stats["edges"] = r.stats.edges;
  t.stats["settled"] = r.stats.settled;
  t.stats["full_search"] = r.stats.fullSearch;
  t.stats["features_seconds"] = r.featureSeconds;
  t.stats["graph_seconds"] = r.stats.graphSeconds;
  t.stats["search_seconds"] = r.stats.searchSeconds;
  t.stats["refine_seconds"] = r.refineSeconds;
  py::list phases;  // (name, wall s, CPU s) in order: the cost's phases, search, terminals, refine
  for (const vs::PhaseTime& p : r.phases) phases.append(py::make_tuple(p.name, p.wall, p.cpu));
  t.stats["phases"] = phases;
  t.swc = std::move(r.tree);
  return t;
}

std::vector<double> numbersOrEmpty(const py::object& obj, const std::string& what) {
  if (obj.is_none()) return {};
  std::vector<double> out;
  try {
    for (const auto& x : py::iter(obj)) out.push_back(x.cast<double>());
  } catch (const std::exception&) {
    throw py::value_error(what + " must be a sequence of numbers, got " + py::repr(obj).cast<std::string>());
  }
  return out;
}

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

double nonNegative(double v, const std::string& what) {
  if (!(v >= 0) || !std::isfinite(v)) throw py::value_error(what + " must be a finite number >= 0");
  return v;
}

// A measured path as the dict of NumPy arrays Path.profile holds.
py::dict pathProfile(const vs::TreeMeasurement& tm, const vs::PathMeasure& path) {
  const size_t n = path.sections.size();
  py::array_t<double> arc(static_cast<py::ssize_t>(n)), area(static_cast<py::ssize_t>(n)),
      eq(static_cast<py::ssize_t>(n)), dmin(static_cast<py::ssize_t>(n)), dmax(static_cast<py::ssize_t>(n));
  py::array_t<double> centre({static_cast<py::ssize_t>(n), py::ssize_t(3)});
  py::array_t<uint32_t> flags(static_cast<py::ssize_t>(n));
  auto c = centre.mutable_unchecked<2>();
  for (size_t k = 0; k < n; ++k) {
    const vs::CrossSection& cs = tm.sections[static_cast<size_t>(path.sections[k])];
    const auto i = static_cast<py::ssize_t>(k);
    arc.mutable_at(i) = path.arcMm[k];
    area.mutable_at(i) = cs.areaMm2;
    eq.mutable_at(i) = cs.equivalentDiameterMm;
    dmin.mutable_at(i) = cs.minDiameterMm;
    dmax.mutable_at(i) = cs.maxDiameterMm;
    flags.mutable_at(i) = cs.flags;
    for (py::ssize_t a = 0; a < 3; ++a) c(i, a) = cs.centreMm[a];
  }
  py::dict d;
  d["arc_mm"] = arc;
  d["centre_mm"] = centre;
  d["area_mm2"] = area;
  d["diameter_mm"] = eq;
  d["min_diameter_mm"] = dmin;
  d["max_diameter_mm"] = dmax;
  d["flags"] = flags;
  return d;
}

// Tree.measure: the tree quantified in `volume`; each path's profile set; the summary dict.
py::object treeMeasure(Tree& t, const py::object& volume, double stepMm, int rays, const std::string& polarity,
                       const py::object& progress) {
  const PyVolume& vol = volumeArg(volume, "measure volume");
  vs::QuantifyOptions o;
  if (!(stepMm > 0) || !std::isfinite(stepMm)) throw py::value_error("step_mm must be > 0");
  if (rays < 8) throw py::value_error("rays must be >= 8");
  o.stepMm = stepMm;
  o.rays = rays;
  o.polarity = vs::lumenPolarityFromName(polarity);  // ValueError
  auto data = vol.data;
  const vs::TreeMeasurement tm = runReleased(progress, [&](vs::Progress& pr) {
    return withFloat(*data, [&](const vs::VolumeF32& f) { return vs::measureTree(f, t.swc, o, pr); });
  });
  // Each traced path's profile: the measured root->tip path ending at its last point.
  for (auto& p : t.paths) {
    const auto pts = p.pointsMm.cast<py::array_t<double>>().unchecked<2>();
    if (pts.shape(0) == 0) continue;
    const vs::Vec3 last(pts(pts.shape(0) - 1, 0), pts(pts.shape(0) - 1, 1), pts(pts.shape(0) - 1, 2));
    const vs::PathMeasure* best = nullptr;
    double bestD = 1e300;
    for (const auto& mp : tm.paths) {
      const double d = (tm.tree.points[static_cast<size_t>(mp.tipNode)] - last).norm();
      if (d < bestD) bestD = d, best = &mp;
    }
    if (best) p.profile = pathProfile(tm, *best);
  }
  py::module_ json = py::module_::import("json");
  return json.attr("loads")(vs::measurementToJson(tm, o).dump());
}

// volscissors.trace: the arguments checked as the CLI checks them, then the core's runTrace.
Tree trace(const py::object& volume, const py::object& root, const py::object& targets, const py::object& autoTerminals,
           double minLengthMm, const std::string& cost, const py::object& polarity, const py::object& window,
           const py::object& smoothMm, const py::object& scales, const py::object& powerArg, const py::object& wgArg,
           const py::object& wzArg, double snapMm, bool refine, int connectivity, const std::string& prune, bool full,
           bool world, const py::object& progress, const py::object& continueDim) {
  const PyVolume& vol = volumeArg(volume, "trace volume");
  const vs::Geometry& g = vol.geometry();
  auto toVoxel = [&](const py::handle& p, const std::string& what) {
    if (!world) return voxelIndex(p, g, what);
    const auto w = finiteNumbers(p, 3, what);
    const vs::Index3 v = vs::roundIndex(g.worldToIndex(vs::Vec3(w[0], w[1], w[2])));
    if (!g.contains(v))
      throw py::value_error(what + " " + py::repr(p).cast<std::string>() + " mm is outside the volume " + g.describe());
    return v;
  };
  vs::TraceRequest rq;
  rq.root = toVoxel(root, "root");
  if (!targets.is_none()) {
    size_t k = 0;
    for (const auto& t : py::iter(targets)) {
      const std::string what = "targets[" + std::to_string(k++) + "]";
      const vs::Index3 v = toVoxel(t, what);
      if (v == rq.root) throw py::value_error(what + " " + str(v) + " is the root");
      for (const auto& q : rq.targets)
        if (q == v) throw py::value_error(what + " " + str(v) + " is given twice");
      rq.targets.push_back(v);
    }
  }
  if (!autoTerminals.is_none()) {
    // Range-checked in Python's own integers: 2**40 is a ValueError, not pybind11's cast error.
    if (!py::isinstance<py::int_>(autoTerminals) || py::isinstance<py::bool_>(autoTerminals))
      throw py::type_error("auto_terminals must be an integer");
    const py::object value = autoTerminals;
    int overflow = 0;
    const long long n = PyLong_AsLongLongAndOverflow(value.ptr(), &overflow);
    if (overflow != 0 || n < 0 || n > std::numeric_limits<int>::max())
      throw py::value_error("auto_terminals must be in 0.." + std::to_string(std::numeric_limits<int>::max()) +
                            " (0: as many as min_length_mm allows), got " + std::string(py::repr(value)));
    rq.autoTerminals = static_cast<int>(n);
  }
  if (rq.targets.empty() && rq.autoTerminals < 0) throw py::value_error("give targets or auto_terminals");
  if (!(minLengthMm > 0) || !std::isfinite(minLengthMm)) throw py::value_error("min_length_mm must be > 0");
  vs::TraceOptions& o = rq.options;
  o.autoTerminals.minLengthMm = minLengthMm;
  if (!continueDim.is_none()) {  // None: the default (off)
    if (rq.autoTerminals < 0) throw py::value_error("continue_dim applies to auto_terminals only");
    o.autoTerminals.continueDimBranches = continueDim.cast<bool>();
  }
  o.cost = cost;
  if (cost != "auto") rq.cost.kind = vs::costKindFromName(cost);  // ValueError listing the kinds
  o.snapMm = nonNegative(snapMm, "snap_mm");
  o.refine = refine;
  rq.full = full;
  // Arguments the chosen cost does not use are an error (they would change nothing).
  auto usedBy = [&](const py::object& arg, const char* name, std::initializer_list<const char*> costs,
                    const char* names) {
    if (arg.is_none()) return;
    for (const char* c : costs)
      if (cost == c) return;
    throw py::value_error(std::string(name) + " applies to cost=" + names + "; cost='" + cost + "'" +
                          (cost == "auto" ? " (the default) estimates its own lumen model and" : "") +
                          " does not use it");
  };
  usedBy(polarity, "polarity", {"vesselness", "intensity"}, "'vesselness' or 'intensity'");
  usedBy(window, "window", {"intensity"}, "'intensity'");
  usedBy(scales, "scales", {"vesselness"}, "'vesselness'");
  usedBy(powerArg, "power", {"auto", "vesselness", "intensity"}, "'auto', 'vesselness' or 'intensity'");
  usedBy(wgArg, "wg", {"gradient"}, "'gradient'");
  usedBy(wzArg, "wz", {"gradient"}, "'gradient'");
  if (!polarity.is_none()) {
    const auto pol = polarity.cast<std::string>();
    if (pol != "bright" && pol != "dark") throw py::value_error("polarity must be 'bright' or 'dark'");
    rq.cost.polarity = pol == "dark" ? vs::TubePolarity::Dark : vs::TubePolarity::Bright;
  }
  if (!window.is_none()) {
    const auto w = finiteNumbers(window, 2, "window (lo, hi)");
    if (!(w[1] > w[0])) throw py::value_error("window (lo, hi) needs lo < hi");
    rq.cost.windowLo = w[0], rq.cost.windowHi = w[1];
  }
  if (!smoothMm.is_none()) rq.smoothMm = nonNegative(smoothMm.cast<double>(), "smooth_mm");
  const auto sc = numbersOrEmpty(scales, "scales");
  if (!sc.empty()) rq.cost.vesselness.scalesMm = sc;
  const double power = powerArg.is_none() ? kCostDefaults.power : powerArg.cast<double>();
  if (!(power > 0) || !std::isfinite(power)) throw py::value_error("power must be > 0");
  rq.cost.power = o.autoCost.power = power;
  if (!wgArg.is_none()) rq.cost.wg = nonNegative(wgArg.cast<double>(), "wg");
  if (!wzArg.is_none()) rq.cost.wz = nonNegative(wzArg.cast<double>(), "wz");
  if (connectivity != 6 && connectivity != 18 && connectivity != 26)
    throw py::value_error("connectivity must be 6, 18 or 26");
  o.tracker.connectivity = connectivity;
  if (prune != "none" && prune != "isoregion") throw py::value_error("prune must be 'none' or 'isoregion'");
  o.tracker.prune = prune == "isoregion" ? vs::PruneMode::IsoRegion : vs::PruneMode::None;
  auto data = vol.data;
  vs::TraceResult r = runReleased(progress, [&](vs::Progress& pr) {
    return withFloat(*data, [&](const vs::VolumeF32& f) { return vs::runTrace(f, rq, pr); });
  });
  return toPython(std::move(r), g);
}

}  // namespace

void bindTrace(py::module_& m) {
  py::class_<Path>(m, "Path", "One extracted path root -> target of a Tree.")
      .def_readonly("voxels", &Path::voxels, "(N, 3) int64 voxel indices (x, y, z), root -> target, 26-connected")
      .def_readonly("points", &Path::points,
                    "(N, 3) refined sub-voxel centreline, continuous voxel index (x, y, z), one per voxel "
                    "(the CLI report's \"points\"; refine=False: the voxels)")
      .def_readonly("points_mm", &Path::pointsMm, "(N, 3) the points in world mm (x, y, z), LPS")
      .def_readonly("radii", &Path::radii,
                    "(N,) lumen radius at each point, mm (refined; refine=False: estimated at the voxels)")
      .def_readonly("target", &Path::target, "node reached (x, y, z): after snapping into the lumen / onto the graph")
      .def_readonly("requested", &Path::requested, "target as given (x, y, z); automatic terminals: the node chosen")
      .def_readonly("reached", &Path::reached)
      .def_readonly("cost", &Path::cost, "path cost (sum of edge costs)")
      .def_readonly("length_mm", &Path::lengthMm, "physical length of the voxel chain")
      .def_readonly("parent", &Path::parent, "index of the path it branches off (-1: from the root)")
      .def_readonly("profile", &Path::profile,
                    "after Tree.measure(volume): dict of NumPy arrays along the path (arc_mm, centre_mm, area_mm2, "
                    "diameter_mm, min_diameter_mm, max_diameter_mm, flags); None before")
      .def_readonly("junction_index", &Path::junctionIndex,
                    "index into voxels of the last voxel shared with earlier paths")
      .def("__repr__", [](const Path& p) {
        return "<volscissors.Path " + std::to_string(p.voxels.shape(0)) + " voxels, " + std::to_string(p.lengthMm) +
               " mm, cost " + std::to_string(p.cost) + ">";
      });

  py::class_<Tree>(m, "Tree", "The tree of paths extracted by volscissors.trace.")
      .def_readonly("paths", &Tree::paths, "list of Path, in extraction order (given targets, then automatic ones)")
      .def_readonly("branch_points", &Tree::branchPoints, "(M, 3) int64 voxels with >= 2 extracted children")
      .def_readonly("root", &Tree::root, "root voxel used (x, y, z): snapped into the lumen / onto the graph")
      .def_readonly("requested_root", &Tree::requestedRoot, "root as given (x, y, z)")
      .def_readonly("cost", &Tree::costDescription, "the node cost used, with its parameters")
      .def_readonly("cost_estimate", &Tree::costEstimate,
                    "cost='auto': dict of what it estimated at the root (polarity, lumen, spread, surroundings, "
                    "window (lo, hi), smooth_mm); else None")
      .def_readonly("notes", &Tree::notes, "what was moved or found (snapped root/targets, automatic terminals)")
      .def_readonly("refined", &Tree::refined, "points and radii are the refined sub-voxel centreline")
      .def_readonly("stats", &Tree::stats, "graph and search figures (nodes, edges, settled, seconds per stage)")
      .def_readonly("node_points", &Tree::nodePoints, "(K, 3) SWC nodes, world mm")
      .def_readonly("node_parents", &Tree::nodeParents, "(K,) SWC parent node index (-1: root)")
      .def_readonly("node_radii", &Tree::nodeRadii, "(K,) SWC radii, mm")
      .def(
          "save",
          [](const Tree& t, const std::string& path) {
            py::gil_scoped_release nogil;
            vs::writeTree(t.swc, path);
          },
          py::arg("path"), "write the tree as `volscissors trace --out` does: .swc, .vtk or .json, world mm; atomic")
      .def("measure", &treeMeasure, py::arg("volume"), py::arg("step_mm") = vs::QuantifyOptions{}.stepMm,
           py::arg("rays") = vs::QuantifyOptions{}.rays,
           py::arg("polarity") = vs::lumenPolarityName(vs::QuantifyOptions{}.polarity),
           py::arg("progress") = py::none(),
           "quantify the tree in `volume` (as `volscissors measure`): lumen cross-sections every step_mm along the "
           "centrelines; sets each path's `profile` (dict of NumPy arrays: arc_mm from the root, centre_mm (N, 3), "
           "area_mm2, diameter_mm (equivalent), min_diameter_mm, max_diameter_mm (NaN where flagged), flags (1 leaves "
           "the volume, 2 meets a branch, 4 no boundary)) and returns the summary dict (segments, paths, branch "
           "points, stenosis, tortuosity, angles). polarity: auto | bright | dark. DataError for a tree of another "
           "volume.")
      .def("__len__", [](const Tree& t) { return t.paths.size(); })
      .def("__repr__", [](const Tree& t) {
        return "<volscissors.Tree " + std::to_string(t.paths.size()) + " paths, " +
               std::to_string(t.branchPoints.shape(0)) + " branch points>";
      });

  m.def("trace", &trace, py::arg("volume"), py::arg("root"), py::arg("targets") = py::none(),
        py::arg("auto_terminals") = py::none(), py::arg("min_length_mm") = kDefaults.autoTerminals.minLengthMm,
        py::arg("cost") = kDefaults.cost, py::arg("polarity") = py::none(), py::arg("window") = py::none(),
        py::arg("smooth_mm") = py::none(), py::arg("scales") = py::none(), py::arg("power") = py::none(),
        py::arg("wg") = py::none(), py::arg("wz") = py::none(), py::arg("snap_mm") = kDefaults.snapMm,
        py::arg("refine") = kDefaults.refine, py::arg("connectivity") = kDefaults.tracker.connectivity,
        py::arg("prune") = "none", py::arg("full") = false, py::arg("world") = false, py::arg("progress") = py::none(),
        py::arg("continue_dim") = py::none(),
        (R"doc(
Vessel / airway tracking: one search from `root`, resumed for every target; the same pipeline and
defaults as `volscissors trace` (the CLI's JSON report and --out tree are what Tree holds and saves).

root, targets: voxel indices (x, y, z), 0-based (world=True: world mm, LPS). auto_terminals:
  None (off) or N: propose up to N terminals (0: as many as min_length_mm allows), each adding at
  least min_length_mm of new path.
continue_dim: with auto_terminals, continue the lumen region along branches that dim below its level
  where they stay a compact, resolved tube (None: the default, off; True: on; False: off).
cost: "auto" (default: intensity cost with its polarity and window estimated at the root, see
  Tree.cost_estimate), "intensity" (window (lo, hi), default 1st..99.9th percentile; polarity),
  "vesselness" (scales in mm; polarity), "gradient" (eq. 19-22; wg, wz) or "given" (voxels are
  costs, +inf = impassable). polarity: "bright" (CTA vessels, default) or "dark" (airways), for
  intensity/vesselness only. smooth_mm: Gaussian sigma of the auto/intensity cost and of the
  refinement (default )doc" +
         number(kDefaults.autoCost.smoothMm) + " auto, " + number(kDefaults.intensitySmoothMm) +
         R"doc( intensity). power: cost exponent of auto/intensity/vesselness
  (None: )doc" +
         number(kCostDefaults.power) + R"doc(). wg, wz: gradient weights (None: )doc" + number(kCostDefaults.wg) +
         ", " + number(kCostDefaults.wz) + R"doc(). An argument the chosen cost does not use (polarity, window,
  scales, power, wg, wz) is a ValueError naming the cost that uses it.
snap_mm: a root or target outside the lumen moves to the nearest lumen voxel within this radius
  (auto/intensity/vesselness costs; 0: off). refine: sub-voxel centring and radii (Path.points,
  Path.radii). connectivity 6/18/26; prune "none" or "isoregion". full=True completes the whole
  search first.
Runs without the GIL. progress(fraction, stage) is called from this thread; an exception raised
  by it, or Ctrl-C (KeyboardInterrupt), cancels the search and propagates.
Raises UnreachableError for a target in a separate component, DataError for an impassable root,
  a point outside any lumen within snap_mm, NaN voxels or no terminal found, ValueError for bad
  arguments (points outside the volume, duplicates).)doc")
            .c_str());
}

}  // namespace vspy
