// volscissors.cost: the core's 3D node costs (cost/cost3d.h) of a Volume, as a float32 Volume
// of the same geometry. One home of the cost formulas for the CLI, the tracer and
// volscissors.pyramid (which calls this per Dask block, issue 25).
#include <cmath>

#include "common.h"
#include "cost/cost3d.h"
#include "features/features3d.h"
#include "features/vesselness.h"

namespace vspy {

namespace {
vs::VesselnessOptions vesselnessArgs(const py::object& scales, const std::string& polarity,
                                     const py::object& cPerScale) {
  vs::VesselnessOptions o;
  if (polarity != "bright" && polarity != "dark") throw py::value_error("polarity must be 'bright' or 'dark'");
  o.polarity = polarity == "dark" ? vs::TubePolarity::Dark : vs::TubePolarity::Bright;
  if (!scales.is_none()) o.scalesMm = scales.cast<std::vector<double>>();
  if (!cPerScale.is_none()) o.cPerScale = cPerScale.cast<std::vector<double>>();
  return o;
}
}  // namespace

void bindCost(py::module_& m) {
  m.def(
      "cost",
      [](const py::object& volume, const std::string& kind, const py::object& window, const std::string& polarity,
         double power, double epsilon, const py::object& scales) {
        const PyVolume& vol = volumeArg(volume, "cost volume");
        vs::Cost3DOptions o;
        o.kind = vs::costKindFromName(kind);
        if (!window.is_none()) {
          const auto w = finiteNumbers(window, 2, "window");
          if (!(w[1] > w[0])) throw py::value_error("window (lo, hi) needs lo < hi");
          o.windowLo = w[0];
          o.windowHi = w[1];
        }
        if (polarity != "bright" && polarity != "dark") throw py::value_error("polarity must be 'bright' or 'dark'");
        o.polarity = polarity == "dark" ? vs::TubePolarity::Dark : vs::TubePolarity::Bright;
        if (!(power > 0) || !std::isfinite(power)) throw py::value_error("power must be > 0");
        if (!(epsilon > 0) || !std::isfinite(epsilon)) throw py::value_error("epsilon must be > 0");
        o.power = power;
        o.epsilon = epsilon;
        if (!scales.is_none()) o.vesselness.scalesMm = scales.cast<std::vector<double>>();
        vs::NodeCost3D nc;
        {
          py::gil_scoped_release release;
          nc = withFloat(vol.any(), [&](const vs::VolumeF32& f) { return vs::computeNodeCost3D(f, o); });
        }
        vs::VolumeF32 out(nc.geometry);
        out.voxels() = std::move(nc.node);
        return PyVolume{std::make_shared<vs::AnyVolume>(std::move(out))};
      },
      py::arg("volume"), py::arg("kind") = "intensity", py::arg("window") = py::none(), py::arg("polarity") = "bright",
      py::arg("power") = vs::Cost3DOptions{}.power, py::arg("epsilon") = vs::Cost3DOptions{}.epsilon,
      py::arg("scales") = py::none(),
      R"doc(Node costs of a volume (float32 Volume, same geometry): kind 'intensity' (window (lo, hi):
default the 1st/99.9th percentiles), 'vesselness' (scales in mm), 'gradient' or 'given'; the formulas
of `volscissors trace --cost` (cost/cost3d.h). ValueError for bad options, DataError for NaN voxels.)doc");

  m.def(
      "vesselness",
      [](const py::object& volume, const py::object& scales, const std::string& polarity, const py::object& cPerScale) {
        const PyVolume& vol = volumeArg(volume, "vesselness volume");
        const vs::VesselnessOptions o = vesselnessArgs(scales, polarity, cPerScale);
        std::vector<float> v;
        vs::Geometry g;
        {
          py::gil_scoped_release release;
          v = withFloat(vol.any(), [&](const vs::VolumeF32& f) {
            g = f.geometry();
            return vs::computeVesselness(f, o);
          });
        }
        vs::VolumeF32 out(g);
        out.voxels() = std::move(v);
        return PyVolume{std::make_shared<vs::AnyVolume>(std::move(out))};
      },
      py::arg("volume"), py::arg("scales") = py::none(), py::arg("polarity") = "bright",
      py::arg("c_per_scale") = py::none(),
      R"doc(Frangi vesselness in [0, 1] (float32 Volume, same geometry): the response `vesselness` costs are
made of (features/vesselness.h). scales in mm (default 1, 2, 3 x the smallest spacing); c_per_scale:
Frangi's c per scale (default: half the largest Hessian norm of this volume at each scale).)doc");
  m.def(
      "vesselness_halo",
      [](const std::array<int64_t, 3>& dims, const std::array<double, 3>& spacing, const py::object& scales) {
        vs::Geometry g;
        g.dims = {dims[0], dims[1], dims[2]};
        g.spacing = vs::Vec3(spacing[0], spacing[1], spacing[2]);
        return vs::vesselnessHaloVoxels(g, vesselnessArgs(scales, "bright", py::none()));
      },
      py::arg("dims"), py::arg("spacing"), py::arg("scales") = py::none(),
      "Voxels of context a block needs on each side for its vesselness to equal the whole volume's.");
  m.def(
      "vesselness_structure_scale",
      [](const py::object& volume, const py::object& scales, const std::array<int64_t, 3>& lo,
         const std::array<int64_t, 3>& hi) {
        const PyVolume& vol = volumeArg(volume, "vesselness volume");
        const vs::VesselnessOptions o = vesselnessArgs(scales, "bright", py::none());
        py::gil_scoped_release release;
        return withFloat(vol.any(), [&](const vs::VolumeF32& f) {
          return vs::vesselnessStructureScale(f, o, {lo[0], lo[1], lo[2]}, {hi[0], hi[1], hi[2]});
        });
      },
      py::arg("volume"), py::arg("scales") = py::none(), py::arg("lo") = std::array<int64_t, 3>{0, 0, 0},
      py::arg("hi") = std::array<int64_t, 3>{0, 0, 0},
      "Frangi's c per scale over the voxel box [lo, hi) (x, y, z; hi (0,0,0): the whole volume).");
  m.def(
      "vesselness_cost",
      [](const py::object& response, double maxV, double power, double epsilon) {
        const PyVolume& vol = volumeArg(response, "vesselness response");
        return withFloat(vol.any(), [&](const vs::VolumeF32& f) {
          vs::VolumeF32 out(f.geometry());
          out.voxels() = vs::vesselnessCostOf(f.voxels(), maxV, epsilon, power);
          return PyVolume{std::make_shared<vs::AnyVolume>(std::move(out))};
        });
      },
      py::arg("response"), py::arg("max_response"), py::arg("power") = vs::Cost3DOptions{}.power,
      py::arg("epsilon") = vs::Cost3DOptions{}.epsilon,
      "The vesselness cost eps + (1 - V/max_response)^power of a response volume (cost/cost3d.h).");
  m.def(
      "percentile",
      [](py::array_t<float, py::array::c_style | py::array::forcecast> values, double p, bool positiveOnly) {
        std::vector<float> v(values.data(), values.data() + values.size());
        return vs::percentileOf(v, p, positiveOnly);
      },
      py::arg("values"), py::arg("p"), py::arg("positive_only") = false,
      "The core's robust percentile (features3d.h: percentileOf; over 4M values subsampled).");
  m.attr("VESSELNESS_MAX_PERCENTILE") = vs::Cost3DOptions{}.robustMaxPercentile;
  m.def(
      "percentile_sample_stride", [](int64_t n) { return vs::percentileSampleStride(static_cast<size_t>(n)); },
      py::arg("n"), "The stride percentile() subsamples n values with.");
}

}  // namespace vspy
