// volscissors.trace: vessel / airway tracking (one root, many targets, one resumed search), with
// the defaults and checks of `volscissors trace`. Returns a Tree of NumPy arrays.
#include <cmath>

#include "common.h"
#include "cost/cost3d.h"
#include "io/mesh_io.h"
#include "tracking/tracker.h"

namespace vspy {

namespace {

struct Path {
  py::array voxels, points, radii;
  py::tuple target, requested;
  bool reached = false;
  double cost = 0, lengthMm = 0;
  int parent = -1;
  size_t junctionIndex = 0;
};

struct Tree {
  std::vector<Path> paths;
  py::array branchPoints, nodePoints, nodeParents, nodeRadii;
  py::tuple root;
  std::string costDescription;
  py::dict stats;
  vs::Tree swc;  // for save()
};

struct TraceParams {
  vs::Index3 root{};
  std::vector<vs::Index3> targets;
  int autoTerminals = -1;  // < 0: off
  double minLengthMm = 10;
  vs::Cost3DOptions cost;
  vs::TrackerOptions tracker;
  bool full = false;
};

struct RawPath {
  vs::TracedPath path;
  std::vector<double> radii;
};

struct TraceResult {
  std::vector<RawPath> paths;
  std::vector<vs::Index3> branchPoints;
  vs::Tree swc;
  vs::Index3 root{};
  vs::Geometry geometry;
  std::string costDescription;
  vs::TrackerStats stats;
};

std::string str(const vs::Index3& v) {
  return "(" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) + ")";
}

TraceResult runTrace(const vs::AnyVolume& input, const TraceParams& p, vs::Progress& progress) {
  const vs::VolumeF32 vol = vs::toFloat(input);
  // Given costs may hold +inf (impassable voxels); computeNodeCost3D rejects NaN and negatives.
  if (p.cost.kind != vs::CostKind3D::Given) vs::requireFinite(vs::AnyVolume(vol), "trace volume");
  const vs::NodeCost3D cost = vs::computeNodeCost3D(vol, p.cost, nullptr, progress);
  const auto& g = vol.geometry();
  if (!std::isfinite(cost.node[static_cast<size_t>(g.linear(p.root[0], p.root[1], p.root[2]))]))
    throw vs::DataError("root " + str(p.root) + " lies in an impassable voxel (cost inf)");
  vs::VesselTracker tr(vol, cost, p.root, p.tracker, progress);
  for (size_t i = 0; i < p.targets.size(); ++i) {
    const vs::TracedPath& path = tr.addTarget(p.targets[i], progress);
    if (!path.reached)
      throw Unreachable("target #" + std::to_string(i + 1) + " " + str(p.targets[i]) +
                        " is not reachable from the root " + str(p.root) +
                        " (separate component: impassable costs or outside the region)");
  }
  if (p.autoTerminals >= 0) {
    vs::AutoTerminalOptions ao;
    ao.count = p.autoTerminals;
    ao.minLengthMm = p.minLengthMm;
    tr.autoTerminals(ao, progress);
  }
  if (p.full) tr.runToCompletion(progress);
  TraceResult r;
  for (const auto& path : tr.paths()) {
    RawPath rp{path, {}};
    for (const auto& v : path.voxels) rp.radii.push_back(tr.radiusAt(v));
    r.paths.push_back(std::move(rp));
  }
  if (r.paths.empty()) throw vs::DataError("trace found no path (no target given and no automatic terminal found)");
  r.branchPoints = tr.branchPoints();
  r.swc = tr.toTree();
  r.root = tr.root();
  r.geometry = g;
  r.costDescription = cost.description;
  r.stats = tr.stats();
  return r;
}

py::array indexArray(const std::vector<vs::Index3>& v) {
  py::array_t<int64_t> a({static_cast<py::ssize_t>(v.size()), py::ssize_t(3)});
  for (size_t i = 0; i < v.size(); ++i)
    for (int c = 0; c < 3; ++c) a.mutable_at(static_cast<py::ssize_t>(i), c) = v[i][c];
  return a;
}

py::array worldArray(const std::vector<Eigen::Vector3d>& v) {
  py::array_t<double> a({static_cast<py::ssize_t>(v.size()), py::ssize_t(3)});
  for (size_t i = 0; i < v.size(); ++i)
    for (int c = 0; c < 3; ++c) a.mutable_at(static_cast<py::ssize_t>(i), c) = v[i][c];
  return a;
}

template <class T>
py::array vectorArray(const std::vector<T>& v) {
  py::array_t<T> a(static_cast<py::ssize_t>(v.size()));
  std::copy(v.begin(), v.end(), a.mutable_data());
  return a;
}

py::tuple tupleOf(const vs::Index3& v) { return py::make_tuple(v[0], v[1], v[2]); }

Tree toPython(TraceResult&& r) {
  Tree t;
  for (const auto& rp : r.paths) {
    const vs::TracedPath& p = rp.path;
    Path out;
    out.voxels = indexArray(p.voxels);
    std::vector<Eigen::Vector3d> world;
    for (const auto& v : p.voxels)
      world.push_back(r.geometry.indexToWorld(vs::Vec3(double(v[0]), double(v[1]), double(v[2]))));
    out.points = worldArray(world);
    out.radii = vectorArray(rp.radii);
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
  t.nodePoints = worldArray(r.swc.points);
  t.nodeParents = vectorArray(r.swc.parent);
  t.nodeRadii = vectorArray(r.swc.radii);
  t.root = tupleOf(r.root);
  t.costDescription = r.costDescription;
  t.stats["nodes"] = r.stats.nodes;
  t.stats["edges"] = r.stats.edges;
  t.stats["settled"] = r.stats.settled;
  t.stats["graph_seconds"] = r.stats.graphSeconds;
  t.stats["search_seconds"] = r.stats.searchSeconds;
  t.swc = std::move(r.swc);
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

}  // namespace

void bindTrace(py::module_& m) {
  py::class_<Path>(m, "Path", "One extracted path root -> target of a Tree.")
      .def_readonly("voxels", &Path::voxels, "(N, 3) int64 voxel indices (x, y, z), root -> target, 26-connected")
      .def_readonly("points", &Path::points, "(N, 3) world points (x, y, z) in mm of the voxels")
      .def_readonly("radii", &Path::radii, "(N,) local lumen radius estimate at each voxel, mm")
      .def_readonly("target", &Path::target, "graph node reached (x, y, z)")
      .def_readonly("requested", &Path::requested, "target as given (x, y, z)")
      .def_readonly("reached", &Path::reached)
      .def_readonly("cost", &Path::cost, "path cost (sum of edge costs)")
      .def_readonly("length_mm", &Path::lengthMm, "physical length of the voxel chain")
      .def_readonly("parent", &Path::parent, "index of the path it branches off (-1: from the root)")
      .def_readonly("junction_index", &Path::junctionIndex,
                    "index into voxels of the last voxel shared with earlier paths")
      .def("__repr__", [](const Path& p) {
        return "<volscissors.Path " + std::to_string(p.voxels.shape(0)) + " voxels, " + std::to_string(p.lengthMm) +
               " mm, cost " + std::to_string(p.cost) + ">";
      });

  py::class_<Tree>(m, "Tree", "The tree of paths extracted by volscissors.trace.")
      .def_readonly("paths", &Tree::paths, "list of Path, in extraction order")
      .def_readonly("branch_points", &Tree::branchPoints, "(M, 3) int64 voxels with >= 2 extracted children")
      .def_readonly("root", &Tree::root, "root voxel (x, y, z)")
      .def_readonly("cost", &Tree::costDescription, "the node cost used, with its parameters")
      .def_readonly("stats", &Tree::stats, "graph and search figures (nodes, edges, settled, seconds)")
      .def_readonly("node_points", &Tree::nodePoints, "(K, 3) SWC nodes, world mm")
      .def_readonly("node_parents", &Tree::nodeParents, "(K,) SWC parent node index (-1: root)")
      .def_readonly("node_radii", &Tree::nodeRadii, "(K,) SWC radii, mm")
      .def(
          "save",
          [](const Tree& t, const std::string& path) {
            py::gil_scoped_release nogil;
            vs::writeTree(t.swc, path);
          },
          py::arg("path"), "write the tree: .swc, .vtk (polylines) or .json, world mm; atomic")
      .def("__len__", [](const Tree& t) { return t.paths.size(); })
      .def("__repr__", [](const Tree& t) {
        return "<volscissors.Tree " + std::to_string(t.paths.size()) + " paths, " +
               std::to_string(t.branchPoints.shape(0)) + " branch points>";
      });

  m.def(
      "trace",
      [](const py::object& volume, const py::object& root, const py::object& targets, const py::object& autoTerminals,
         double minLengthMm, const std::string& cost, const std::string& polarity, const py::object& window,
         const py::object& smoothMm, const py::object& scales, double power, double wg, double wz, int connectivity,
         const std::string& prune, bool full, bool world, const py::object& progress) {
        const PyVolume& vol = volumeArg(volume, "trace volume");
        const vs::Geometry& g = vol.geometry();
        auto toVoxel = [&](const py::handle& p, const std::string& what) {
          if (!world) return voxelIndex(p, g, what);
          const auto w = finiteNumbers(p, 3, what);
          const vs::Index3 v = vs::roundIndex(g.worldToIndex(vs::Vec3(w[0], w[1], w[2])));
          if (!g.contains(v))
            throw py::value_error(what + " " + py::repr(p).cast<std::string>() + " mm is outside the volume " +
                                  g.describe());
          return v;
        };
        TraceParams p;
        p.root = toVoxel(root, "root");
        if (!targets.is_none()) {
          size_t k = 0;
          for (const auto& t : py::iter(targets)) {
            const std::string what = "targets[" + std::to_string(k++) + "]";
            const vs::Index3 v = toVoxel(t, what);
            if (v == p.root) throw py::value_error(what + " " + str(v) + " is the root");
            for (const auto& q : p.targets)
              if (q == v) throw py::value_error(what + " " + str(v) + " is given twice");
            p.targets.push_back(v);
          }
        }
        if (!autoTerminals.is_none()) {
          p.autoTerminals = autoTerminals.cast<int>();
          if (p.autoTerminals < 0)
            throw py::value_error("auto_terminals must be >= 0 (0: as many as min_length_mm allows)");
        }
        if (p.targets.empty() && p.autoTerminals < 0) throw py::value_error("give targets or auto_terminals");
        if (!(minLengthMm >= 0) || !std::isfinite(minLengthMm)) throw py::value_error("min_length_mm must be >= 0");
        p.minLengthMm = minLengthMm;
        p.full = full;
        p.cost.kind = vs::costKindFromName(cost);
        if (polarity != "bright" && polarity != "dark") throw py::value_error("polarity must be 'bright' or 'dark'");
        p.cost.polarity = polarity == "dark" ? vs::TubePolarity::Dark : vs::TubePolarity::Bright;
        if (!window.is_none()) {
          const auto w = finiteNumbers(window, 2, "window (lo, hi)");
          p.cost.windowLo = w[0], p.cost.windowHi = w[1];
        }
        if (smoothMm.is_none())
          p.cost.smoothMm = p.cost.kind == vs::CostKind3D::Intensity ? 1.0 : 0.0;
        else
          p.cost.smoothMm = smoothMm.cast<double>();
        const auto sc = numbersOrEmpty(scales, "scales");
        if (!sc.empty()) p.cost.vesselness.scalesMm = sc;
        p.cost.power = power, p.cost.wg = wg, p.cost.wz = wz;
        if (connectivity != 6 && connectivity != 18 && connectivity != 26)
          throw py::value_error("connectivity must be 6, 18 or 26");
        p.tracker.connectivity = connectivity;
        if (prune != "none" && prune != "isoregion") throw py::value_error("prune must be 'none' or 'isoregion'");
        p.tracker.prune = prune == "isoregion" ? vs::PruneMode::IsoRegion : vs::PruneMode::None;
        auto data = vol.data;
        TraceResult r = runReleased(progress, [&](vs::Progress& pr) { return runTrace(*data, p, pr); });
        return toPython(std::move(r));
      },
      py::arg("volume"), py::arg("root"), py::arg("targets") = py::none(), py::arg("auto_terminals") = py::none(),
      py::arg("min_length_mm") = 10.0, py::arg("cost") = "gradient", py::arg("polarity") = "bright",
      py::arg("window") = py::none(), py::arg("smooth_mm") = py::none(), py::arg("scales") = py::none(),
      py::arg("power") = 4.0, py::arg("wg") = 0.7, py::arg("wz") = 0.3, py::arg("connectivity") = 26,
      py::arg("prune") = "none", py::arg("full") = false, py::arg("world") = false, py::arg("progress") = py::none(),
      R"doc(
Vessel / airway tracking: one search from `root`, resumed for every target (as `volscissors trace`).

root, targets: voxel indices (x, y, z), 0-based (world=True: world mm, LPS). auto_terminals:
  None (off) or N: propose up to N terminals (0: as many as min_length_mm allows), each adding at
  least min_length_mm of new path. cost: "gradient" (eq. 19-22; wg, wz), "vesselness" (scales in
  mm, power), "intensity" (window (lo, hi), smooth_mm, default 1 mm; power) or "given" (voxels
  are costs, +inf = impassable); polarity "bright" (CTA vessels) or "dark" (airways). connectivity 6/18/26; prune
  "none" or "isoregion". full=True completes the whole search.
Runs without the GIL. progress(fraction, stage) is called from this thread; an exception raised
  by it, or Ctrl-C (KeyboardInterrupt), cancels the search and propagates.
Raises UnreachableError for a target in a separate component, DataError for an impassable root
  or NaN voxels, ValueError for bad arguments (points outside the volume, duplicates).)doc");
}

}  // namespace vspy
