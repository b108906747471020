// volscissors.render: the CPU ray caster (full, cutbox, triplanar, monoplanar, mip) into a NumPy
// RGBA image, with the defaults of `volscissors render`.
#include <cmath>

#include "common.h"
#include "render/renderer.h"
#include "render/view_defaults.h"

namespace vspy {

namespace {

vs::TransferFunction transferFunction(const std::string& tf, const vs::AnyVolume& vol) {
  if (tf.size() > 5 && tf.substr(tf.size() - 5) == ".json") return vs::TransferFunction::fromFile(tf);
  return vs::TransferFunction::preset(tf, vs::valueRange(vol));
}

}  // namespace

void bindRender(py::module_& m) {
  m.def(
      "render",
      [](const py::object& volume, const std::string& mode, const std::string& tf, const py::object& view, double zoom,
         const py::object& size, bool perspective, const py::object& window, bool shading, double step,
         const py::object& box, const py::object& planes, const py::object& plane, const py::object& labels,
         const py::object& progress) {
        const PyVolume& vol = volumeArg(volume, "render volume");
        const vs::Geometry& g = vol.geometry();
        // The CLI's defaults for every mode (view, cut box, plane, MIP window): render/view_defaults.h.
        vs::RenderOptions ro = vs::defaultRenderOptions(*vol.data, vs::renderModeFromName(mode));
        const vs::OrbitView orbit;
        const auto v = view.is_none() ? std::vector<double>{orbit.azimuthDeg, orbit.elevationDeg}
                                      : finiteNumbers(view, 2, "view (azimuth, elevation)");
        if (!(zoom > 0) || !std::isfinite(zoom)) throw py::value_error("zoom must be > 0");
        const auto wh = finiteNumbers(size, 2, "size (width, height)");
        const int W = static_cast<int>(wh[0]), H = static_cast<int>(wh[1]);
        if (W != wh[0] || H != wh[1] || W < 1 || H < 1 || W > vs::Renderer::kMaxImageSide ||
            H > vs::Renderer::kMaxImageSide)
          throw py::value_error("size: width and height must be integers in 1.." +
                                std::to_string(vs::Renderer::kMaxImageSide));
        if (!window.is_none()) {
          const auto wl = finiteNumbers(window, 2, "window (width, level)");
          if (!(wl[0] > 0)) throw py::value_error("window: width must be > 0");
          ro.window = {wl[0], wl[1]};
        }
        ro.shading = shading;
        ro.sampleStep = step;
        if (!box.is_none()) {
          const auto b = finiteNumbers(box, 6, "box (x0, y0, z0, x1, y1, z1)");
          ro.box = {b[0], b[1], b[2], b[3], b[4], b[5]};
        }
        if (!planes.is_none()) {
          const auto p = finiteNumbers(planes, 3, "planes (x, y, z)");
          ro.planes = vs::Vec3(p[0], p[1], p[2]);
        }
        if (!plane.is_none()) {
          const auto spec = vs::parseSliceSpec(plane.cast<std::string>());
          ro.planeAxis = spec.first;
          ro.planeIndex = double(spec.second);
        }
        std::shared_ptr<vs::AnyVolume> labelData;
        if (!labels.is_none()) labelData = volumeArg(labels, "labels").data;
        auto data = vol.data;
        vs::RgbaImage img = runReleased(progress, [&](vs::Progress& pr) {
          vs::Renderer ren(*data, pr);
          ren.setOptions(ro);
          ren.setTransferFunction(transferFunction(tf, *data));
          if (labelData) ren.setLabels(*labelData);
          return ren.render(vs::orbitCamera(g, v[0], v[1], zoom, perspective), W, H, pr).image;
        });
        py::array_t<uint8_t> out(
            {static_cast<py::ssize_t>(img.height), static_cast<py::ssize_t>(img.width), py::ssize_t(4)});
        std::copy(img.pixels.begin(), img.pixels.end(), out.mutable_data());
        return out;
      },
      py::arg("volume"), py::arg("mode") = "full", py::arg("tf") = "auto", py::arg("view") = py::none(),
      py::arg("zoom") = 1.0, py::arg("size") = py::make_tuple(512, 512), py::arg("perspective") = false,
      py::arg("window") = py::none(), py::arg("shading") = true, py::arg("step") = 0.5, py::arg("box") = py::none(),
      py::arg("planes") = py::none(), py::arg("plane") = py::none(), py::arg("labels") = py::none(),
      py::arg("progress") = py::none(), R"doc(
Volume rendering on the CPU (as `volscissors render`); returns an (height, width, 4) uint8 RGBA array.

mode: "full", "cutbox", "triplanar", "monoplanar" or "mip". tf: a preset (auto, ct-skin, ct-bone,
ct-lung, ct-angio, mri, vessels) or a transfer-function .json file. view: (azimuth, elevation) in
degrees; (0, 0) looks from anterior (-y, LPS) with +z up; default (30, 30), as the CLI. zoom 1 fits the volume. size: (width,
height). window: (width, level) for planes, faces and MIP (default: 1st..99.5th percentile).
step: ray sample distance in units of the smallest spacing. box: cutbox (x0, y0, z0, x1, y1, z1)
voxel index (default the central half). planes: triplanar (x, y, z) index (default the centre).
plane: monoplanar "z=40". labels: a label Volume of the same dims, blended in colour.
Runs without the GIL; progress(fraction, stage) and Ctrl-C as in trace.)doc");
}

}  // namespace vspy
