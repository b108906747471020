// volscissors.LiveWire (the interactive pattern: one search per seed, resumed per cursor move)
// and volscissors.livewire (a contour through clicked points, as `volscissors livewire`).
// Slice pixels are (u, v), 0-based: axial z=K: (x, y); coronal y=K: (x, z); sagittal x=K: (y, z).
#include <cmath>

#include "common.h"
#include "features/features2d.h"
#include "scissors/live_wire.h"
#include "scissors/live_wire_document.h"
#include "volume/slice.h"

namespace vspy {

namespace {

struct Contour {
  py::array pixels, index, world, anchors;
  py::object mask = py::none();  // closed contours only
  bool closed = false;
  double lengthMm = 0, cost = 0;
  py::object areaPixels = py::none(), areaMm2 = py::none();
  std::string slice;
};

const vs::LiveWireOptions kWireDefaults;  // the core's defaults, as the CLI's

py::tuple defaultWeights() {
  const auto& c = kWireDefaults.cost;
  return py::make_tuple(c.weightZ, c.weightG, c.weightD);
}

struct PyLiveWire {
  std::unique_ptr<vs::LiveWire> wire;
  std::mutex busy;  // the core object is not thread-safe; calls run without the GIL
  vs::Geometry geometry;
  int axis = 2;
  int64_t index = 0;
};

vs::PixelUV pixelArg(const py::handle& obj, const PyLiveWire& lw, const std::string& what) {
  const auto v = finiteNumbers(obj, 2, what);
  if (v[0] != std::floor(v[0]) || v[1] != std::floor(v[1]))
    throw py::value_error(what + " must be integer slice pixels (u, v), got " + py::repr(obj).cast<std::string>());
  const vs::PixelUV p{static_cast<int64_t>(v[0]), static_cast<int64_t>(v[1])};
  if (!lw.wire->contains(p))
    throw py::value_error(what + " (" + std::to_string(p[0]) + ", " + std::to_string(p[1]) + ") is outside the " +
                          std::to_string(lw.wire->width()) + "x" + std::to_string(lw.wire->height()) + " " +
                          vs::describeSlice(lw.axis, lw.index));
  return p;
}

py::array uvArray(const std::vector<vs::PixelUV>& px) {
  py::array_t<int64_t> a({static_cast<py::ssize_t>(px.size()), py::ssize_t(2)});
  for (size_t i = 0; i < px.size(); ++i) {
    a.mutable_at(static_cast<py::ssize_t>(i), 0) = px[i][0];
    a.mutable_at(static_cast<py::ssize_t>(i), 1) = px[i][1];
  }
  return a;
}

// From the core's contour document (scissors/live_wire_document.h), as `volscissors livewire`.
Contour makeContour(const PyLiveWire& lw) {
  const vs::ContourDocument doc = vs::contourDocument(*lw.wire, lw.geometry, lw.axis, lw.index);
  Contour out;
  out.closed = doc.closed;
  out.lengthMm = doc.lengthMm;
  out.cost = doc.cost;
  out.slice = vs::sliceName(lw.axis, lw.index);
  out.pixels = uvArray(doc.points);
  out.anchors = uvArray(lw.wire->contour().anchors);
  const auto n = static_cast<py::ssize_t>(doc.points.size());
  py::array_t<int64_t> idx({n, py::ssize_t(3)});
  py::array_t<double> world({n, py::ssize_t(3)});
  for (py::ssize_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) {
      idx.mutable_at(i, k) = doc.pointsIndex[static_cast<size_t>(i)][k];
      world.mutable_at(i, k) = doc.pointsWorld[static_cast<size_t>(i)][k];
    }
  out.index = idx;
  out.world = world;
  if (doc.closed) {
    const int64_t W = lw.wire->width(), H = lw.wire->height();
    const std::vector<uint8_t> m = vs::fillContour(doc.points, W, H);
    py::array_t<uint8_t> mask({static_cast<py::ssize_t>(H), static_cast<py::ssize_t>(W)});
    std::copy(m.begin(), m.end(), mask.mutable_data());
    out.mask = mask;
    out.areaPixels = py::int_(*doc.areaPixels);
    out.areaMm2 = py::float_(*doc.areaMm2);
  }
  return out;
}

vs::LiveWireOptions wireOptions(const std::string& cost, const py::object& weights, double smoothMm, int connectivity) {
  vs::LiveWireOptions o;
  o.cost.kind = vs::parseLiveWireCostKind(cost);
  const auto w = finiteNumbers(weights, 3, "weights (wZ, wG, wD)");
  o.cost.weightZ = w[0], o.cost.weightG = w[1], o.cost.weightD = w[2];
  if (!(smoothMm >= 0) || !std::isfinite(smoothMm)) throw py::value_error("smooth_mm must be a sigma >= 0 mm");
  o.features.smoothSigmaMm = smoothMm;
  if (connectivity != 4 && connectivity != 8) throw py::value_error("connectivity must be 4 or 8");
  o.connectivity = connectivity;
  return o;
}

// Picks the slice ("z=40", default the middle axial one); the features are computed later by
// buildWire, without the GIL.
std::unique_ptr<PyLiveWire> sliceOf(const PyVolume& vol, const py::object& slice) {
  auto lw = std::make_unique<PyLiveWire>();
  lw->geometry = vol.geometry();
  lw->axis = 2;
  lw->index = lw->geometry.dims[2] / 2;
  if (!slice.is_none()) std::tie(lw->axis, lw->index) = vs::parseSliceSpec(slice.cast<std::string>());
  if (lw->index < 0 || lw->index >= lw->geometry.dims[lw->axis])
    throw py::value_error("slice " + vs::sliceName(lw->axis, lw->index) + ": index outside 0.." +
                          std::to_string(lw->geometry.dims[lw->axis] - 1));
  return lw;
}

// Features and edge costs of the chosen slice (call without the GIL; `data` keeps the voxels alive).
void buildWire(PyLiveWire& lw, const std::shared_ptr<vs::AnyVolume>& data, const vs::LiveWireOptions& o) {
  lw.wire = std::make_unique<vs::LiveWire>(vs::liveWireOnSlice(*data, lw.axis, lw.index, o));
}

// A search step of one LiveWire, run without the GIL, with progress and cancel (runReleased).
template <class Step>
auto searchStep(PyLiveWire& lw, const py::object& progress, Step&& step) {
  return runReleased(progress, [&](vs::Progress& pr) {
    std::lock_guard<std::mutex> lock(lw.busy);
    return step(*lw.wire, pr);
  });
}

void bindContourClass(py::module_& m) {
  py::class_<Contour>(m, "Contour", "A live-wire contour on one slice (see volscissors.livewire).")
      .def_readonly("pixels", &Contour::pixels, "(N, 2) int64 slice pixels (u, v); closed: first not repeated")
      .def_readonly("index", &Contour::index, "(N, 3) int64 voxel indices (x, y, z) of the pixels")
      .def_readonly("world", &Contour::world, "(N, 3) world points (x, y, z) in mm, LPS")
      .def_readonly("anchors", &Contour::anchors, "(K, 2) the seed points (clicks after snapping)")
      .def_readonly("closed", &Contour::closed)
      .def_readonly("length_mm", &Contour::lengthMm, "physical length (closed: with the closing step)")
      .def_readonly("cost", &Contour::cost, "sum of edge costs (cost per mm integrated along the path)")
      .def_readonly("area_pixels", &Contour::areaPixels, "closed: pixels inside (boundary included), else None")
      .def_readonly("area_mm2", &Contour::areaMm2, "closed: area in mm^2, else None")
      .def_readonly("mask", &Contour::mask, "closed: uint8 [v, u] (height, width) filled mask, else None")
      .def_readonly("slice", &Contour::slice, "the slice, e.g. 'z=40'")
      .def("__len__", [](const Contour& c) { return c.pixels.shape(0); })
      .def("__repr__", [](const Contour& c) {
        return "<volscissors.Contour " + c.slice + ", " + std::to_string(c.pixels.shape(0)) + " pixels" +
               (c.closed ? ", closed" : "") + ", " + std::to_string(c.lengthMm) + " mm>";
      });
}

void bindLiveWireClass(py::module_& m) {
  py::class_<PyLiveWire>(m, "LiveWire", R"doc(
Interactive 2D live-wire (Intelligent Scissors) on one slice of a Volume.

slice: "z=K" (axial), "y=K" (coronal), "x=K" (sagittal); default the middle axial slice (a 2D
  image is its only slice). Points are slice pixels (u, v), 0-based: axial (x, y), coronal (x, z),
  sagittal (y, z). cost: "mb" (Mortensen-Barrett, weights wZ, wG, wD) or "gradient"
  (Stalling-Hege). smooth_mm: Gaussian pre-smoothing sigma in mm. Features and edge costs are
  computed once here; set_seed starts one search that path_to resumes (never restarts).
Searches (path_to, commit, close, build_map) run without the GIL and take progress=callable
  (fraction, stage); an exception raised by it, or Ctrl-C, cancels the search (it stays valid and
  resumes on the next call). One LiveWire serves one thread at a time.)doc")
      .def(py::init([](const py::object& image, const py::object& slice, const std::string& cost,
                       const py::object& weights, double smoothMm, int connectivity) {
             const PyVolume& vol = volumeArg(image, "LiveWire image");
             auto lw = sliceOf(vol, slice);
             const vs::LiveWireOptions o = wireOptions(cost, weights, smoothMm, connectivity);
             auto data = vol.data;
             py::gil_scoped_release nogil;
             buildWire(*lw, data, o);
             return lw;
           }),
           py::arg("volume"), py::arg("slice") = py::none(),
           py::arg("cost") = vs::liveWireCostKindName(kWireDefaults.cost.kind), py::arg("weights") = defaultWeights(),
           py::arg("smooth_mm") = kWireDefaults.features.smoothSigmaMm,
           py::arg("connectivity") = kWireDefaults.connectivity)
      .def(
          "set_seed",
          [](PyLiveWire& lw, const py::object& p) {
            const vs::PixelUV uv = pixelArg(p, lw, "seed");
            std::lock_guard<std::mutex> lock(lw.busy);
            lw.wire->setSeed(uv);
          },
          py::arg("point"), "start a new contour at slice pixel (u, v)")
      .def(
          "path_to",
          [](PyLiveWire& lw, const py::object& p, const py::object& progress) {
            const vs::PixelUV uv = pixelArg(p, lw, "point");
            return uvArray(
                searchStep(lw, progress, [&](vs::LiveWire& w, vs::Progress& pr) { return w.pathTo(uv, pr); }));
          },
          py::arg("point"), py::arg("progress") = py::none(),
          "(N, 2) live path seed -> point, both included (resumes the seed's search)")
      .def(
          "commit",
          [](PyLiveWire& lw, const py::object& p, const py::object& progress) {
            const vs::PixelUV uv = pixelArg(p, lw, "point");
            return uvArray(
                searchStep(lw, progress, [&](vs::LiveWire& w, vs::Progress& pr) { return w.commit(uv, pr).pixels; }));
          },
          py::arg("point"), py::arg("progress") = py::none(),
          "commit the path seed -> point as a segment; point becomes the seed")
      .def(
          "close",
          [](PyLiveWire& lw, const py::object& progress) {
            searchStep(lw, progress, [](vs::LiveWire& w, vs::Progress& pr) { w.close(pr); });
          },
          py::arg("progress") = py::none(), "commit the path back to the first point (needs one committed segment)")
      .def(
          "undo", [](PyLiveWire& lw) { return lw.wire->undo(); }, "drop the last segment; False if none")
      .def(
          "snap",
          [](PyLiveWire& lw, const py::object& p, double radius) {
            if (!(radius >= 0) || !std::isfinite(radius)) throw py::value_error("radius must be >= 0 pixels");
            const vs::PixelUV s = lw.wire->snap(pixelArg(p, lw, "point"), radius);
            return py::make_tuple(s[0], s[1]);
          },
          py::arg("point"), py::arg("radius"), "strongest-gradient pixel within radius (pixels) of point")
      .def(
          "build_map",
          [](PyLiveWire& lw, const py::object& progress) {
            searchStep(lw, progress, [](vs::LiveWire& w, vs::Progress& pr) { w.buildMap(pr); });
          },
          py::arg("progress") = py::none(),
          "settle every pixel from the seed (the full map); later path_to calls are O(path)")
      .def("contour", &makeContour, "the committed contour so far")
      .def_property_readonly("seed",
                             [](const PyLiveWire& lw) -> py::object {
                               if (!lw.wire->hasSeed()) return py::none();
                               return py::make_tuple(lw.wire->seed()[0], lw.wire->seed()[1]);
                             })
      .def_property_readonly("width", [](const PyLiveWire& lw) { return lw.wire->width(); })
      .def_property_readonly("height", [](const PyLiveWire& lw) { return lw.wire->height(); })
      .def_property_readonly("slice", [](const PyLiveWire& lw) { return vs::sliceName(lw.axis, lw.index); })
      .def_property_readonly(
          "settled", [](const PyLiveWire& lw) { return lw.wire->settledCount(); },
          "pixels settled by the current seed's search");
}

void bindLivewireFunction(py::module_& m) {
  m.def(
      "livewire",
      [](const py::object& volume, const py::object& points, const py::object& slice, bool closed,
         const std::string& cost, const py::object& weights, double smoothMm, double snap, bool world,
         const py::object& progress) {
        const PyVolume& vol = volumeArg(volume, "livewire volume");
        const vs::Geometry& g = vol.geometry();
        if (!(snap >= 0) || !std::isfinite(snap)) throw py::value_error("snap must be a radius >= 0 pixels");
        std::unique_ptr<PyLiveWire> lw;
        std::vector<vs::PixelUV> input;
        if (world) {
          // As `volscissors livewire --world`: the points must lie on the slice (default: the
          // axial slice through the first point); the in-plane axes come from volume/slice.
          const auto pts = pointList(points, "points");
          if (pts.empty()) throw py::value_error("points: need at least 2 points, got 0");
          std::vector<vs::Vec3> index;
          for (const auto& p : pts) index.push_back(g.worldToIndex(p));
          lw = sliceOf(vol, slice.is_none() ? py::str(vs::sliceName(2, vs::roundIndex(index[0])[2])) : slice);
          const auto [ua, va] = vs::sliceInPlaneAxes(lw->axis);
          for (size_t i = 0; i < index.size(); ++i) {
            const vs::Vec3& c = index[i];
            if (std::abs(c[lw->axis] - static_cast<double>(lw->index)) > 0.5 + 1e-6)
              throw py::value_error("points[" + std::to_string(i) + "] lies at " + "xyz"[lw->axis] + "=" +
                                    std::to_string(c[lw->axis]) + ", not on slice " +
                                    vs::sliceName(lw->axis, lw->index));
            const vs::Index3 r = vs::roundIndex(c);
            input.push_back({r[static_cast<size_t>(ua)], r[static_cast<size_t>(va)]});
          }
        } else {
          lw = sliceOf(vol, slice);
          if (py::isinstance<py::str>(points)) throw py::value_error("points must be a list of (u, v) pixels");
          size_t k = 0;
          for (const auto& p : py::iter(points)) {
            const std::string what = "points[" + std::to_string(k++) + "]";
            const auto v = finiteNumbers(p, 2, what);
            if (v[0] != std::floor(v[0]) || v[1] != std::floor(v[1]))
              throw py::value_error(what + " must be integer slice pixels (u, v), got " +
                                    py::repr(p).cast<std::string>());
            input.push_back({static_cast<int64_t>(v[0]), static_cast<int64_t>(v[1])});
          }
        }
        const auto [ua, va] = vs::sliceInPlaneAxes(lw->axis);
        for (size_t i = 0; i < input.size(); ++i)
          if (input[i][0] < 0 || input[i][1] < 0 || input[i][0] >= g.dims[ua] || input[i][1] >= g.dims[va])
            throw py::value_error("points[" + std::to_string(i) + "] (" + std::to_string(input[i][0]) + ", " +
                                  std::to_string(input[i][1]) + ") is outside the " + std::to_string(g.dims[ua]) + "x" +
                                  std::to_string(g.dims[va]) + " " + vs::describeSlice(lw->axis, lw->index));
        if (input.size() < 2)
          throw py::value_error("points: need at least 2 points, got " + std::to_string(input.size()));
        if (closed && input.size() < 3) throw py::value_error("closed=True needs at least 3 points");
        const vs::LiveWireOptions o = wireOptions(cost, weights, smoothMm, kWireDefaults.connectivity);
        auto data = vol.data;
        // Features, snapping and the searches: one call without the GIL, cancellable.
        runReleased(progress, [&](vs::Progress& pr) {
          buildWire(*lw, data, o);
          std::vector<vs::PixelUV> c;
          for (const auto& p : input) c.push_back(snap > 0 ? lw->wire->snap(p, snap) : p);
          for (size_t i = 1; i < c.size(); ++i)
            if (c[i] == c[i - 1])
              throw vs::InvalidArgument("points " + std::to_string(i - 1) + " and " + std::to_string(i) +
                                        " are the same pixel (" + std::to_string(c[i][0]) + ", " +
                                        std::to_string(c[i][1]) + ")" + (snap > 0 ? " after snapping" : ""));
          if (closed && c.back() == c.front()) c.pop_back();  // "closed" already says it
          if (closed && c.size() < 3) throw vs::InvalidArgument("closed=True needs at least 3 distinct points");
          lw->wire->setSeed(c.front());
          for (size_t i = 1; i < c.size(); ++i) lw->wire->commit(c[i], pr);
          if (closed) lw->wire->close(pr);
        });
        return makeContour(*lw);
      },
      py::arg("volume"), py::arg("points"), py::arg("slice") = py::none(), py::arg("closed") = false,
      py::arg("cost") = vs::liveWireCostKindName(kWireDefaults.cost.kind), py::arg("weights") = defaultWeights(),
      py::arg("smooth_mm") = kWireDefaults.features.smoothSigmaMm, py::arg("snap") = 0.0, py::arg("world") = false,
      py::arg("progress") = py::none(), R"doc(
Live-wire contour through clicked points on one slice (the same result as `volscissors livewire`).

points: slice pixels (u, v) (axial z=K: (x, y); coronal y=K: (x, z); sagittal x=K: (y, z)), or
  with world=True world points (x, y, z) in mm that must lie on the slice (default slice: the
  axial one through the first point). slice: "z=K" / "y=K" / "x=K", default the middle axial.
closed: back to the first point (>= 3 points). snap: move each point to the strongest edge
  within this radius in pixels first. Returns a Contour (pixels, index, world, length_mm,
  cost, area and mask when closed). ValueError for points outside the slice or duplicates.
Runs without the GIL; progress(fraction, stage) and Ctrl-C as in trace.)doc");
}

}  // namespace

void bindLiveWire(py::module_& m) {
  bindContourClass(m);
  bindLiveWireClass(m);
  bindLivewireFunction(m);
}

}  // namespace vspy
