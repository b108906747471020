// volscissors.cost: the core's 3D node costs (cost/cost3d.h) of a Volume, as a float32 Volume
// of the same geometry. One home of the cost formulas for the CLI, the tracer and
// volscissors.pyramid (which calls this per Dask block, issue 25).
#include <cmath>

#include "common.h"
#include "cost/cost3d.h"

namespace vspy {

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
}

}  // namespace vspy
