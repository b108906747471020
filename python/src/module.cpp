// volscissors._core: the compiled part of `import volscissors` (exceptions, Volume, read/write;
// the tools are bound in livewire.cpp, trace.cpp, render.cpp). Conventions, as in the CLI:
// index and world points are (x, y, z); volume.array is the voxel buffer seen as [z, y, x].
#include <Eigen/LU>   // determinant()
#include <Eigen/SVD>  // orthonormalising a direction
#include <cmath>

#include "common.h"
#include "io/volume_io.h"
#include "tracking/trace_run.h"
#include "volume/slice.h"

namespace vspy {

namespace {

PyObject* g_cancelled = nullptr;
PyObject* g_dataError = nullptr;
PyObject* g_unreachable = nullptr;

template <class T>
py::array viewOf(const std::shared_ptr<vs::AnyVolume>& holder, vs::Volume<T>& v) {
  const auto& d = v.dims();
  const py::ssize_t item = sizeof(T);
  // The capsule owns one reference to the volume: the view stays valid after the Volume goes.
  auto* keep = new std::shared_ptr<vs::AnyVolume>(holder);
  py::capsule base(keep, [](void* p) { delete static_cast<std::shared_ptr<vs::AnyVolume>*>(p); });
  return py::array(py::dtype::of<T>(), {d[2], d[1], d[0]}, {item * d[0] * d[1], item * d[0], item}, v.data(), base);
}

py::array arrayOf(const PyVolume& vol) {
  return std::visit([&](auto& v) { return viewOf(vol.data, v); }, *vol.data);
}

py::tuple triple(const vs::Vec3& v) { return py::make_tuple(v.x(), v.y(), v.z()); }

vs::Vec3 vec3Arg(const py::handle& obj, const std::string& what) {
  const auto v = finiteNumbers(obj, 3, what);
  return {v[0], v[1], v[2]};
}

vs::Vec3 spacingArg(const py::handle& obj) {
  const vs::Vec3 s = vec3Arg(obj, "spacing");
  if (!(s.minCoeff() > 0))
    throw py::value_error("spacing must be > 0 mm on every axis, got " + py::repr(obj).cast<std::string>());
  return s;
}

vs::Mat3 directionArg(const py::handle& obj) {
  py::array_t<double, py::array::c_style | py::array::forcecast> a;
  try {
    a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(obj);
  } catch (const py::error_already_set&) {
  }
  if (!a || a.ndim() != 2 || a.shape(0) != 3 || a.shape(1) != 3)
    throw py::value_error("direction must be a 3x3 matrix (columns: world direction of the x, y, z index axes)");
  vs::Mat3 m;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) m(r, c) = a.at(r, c);
  if (!m.allFinite() || std::abs(m.determinant()) < 1e-6)
    throw py::value_error("direction must be finite and invertible");
  // Columns are unit directions at right angles (scale belongs in spacing): a sheared or scaled
  // matrix would be written as a different geometry. float32 rounding (1e-4) is orthonormalised.
  const double dev = (m.transpose() * m - vs::Mat3::Identity()).cwiseAbs().maxCoeff();
  if (dev > 1e-3)
    throw py::value_error(
        "direction must be orthonormal (unit columns at right angles; put scale in spacing): "
        "|D^T D - I| is " +
        std::to_string(dev));
  if (dev > 0) {
    Eigen::JacobiSVD<vs::Mat3> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
    m = svd.matrixU() * svd.matrixV().transpose();
  }
  return m;
}

// Volume(array, spacing, origin, direction, dtype): one explicit copy into core-owned memory.
PyVolume makeVolume(const py::array& input, const py::object& spacing, const py::object& origin,
                    const py::object& direction, const py::object& dtype) {
  if (input.ndim() != 3 && input.ndim() != 2)
    throw py::value_error("Volume: expected a 3D array [z, y, x] (or a 2D image [y, x]), got " +
                          std::to_string(input.ndim()) + " dimensions");
  if (input.size() == 0) throw py::value_error("Volume: the array is empty");
  py::dtype target = dtype.is_none() ? input.dtype() : py::dtype::from_args(dtype);
  vs::VoxelType type;
  const char kind = target.kind();
  const size_t size = static_cast<size_t>(target.itemsize());
  if (kind == 'u' && size == 1)
    type = vs::VoxelType::UInt8;
  else if (kind == 'i' && size == 2)
    type = vs::VoxelType::Int16;
  else if (kind == 'u' && size == 2)
    type = vs::VoxelType::UInt16;
  else if (kind == 'f' && size == 4)
    type = vs::VoxelType::Float32;
  else
    throw py::type_error("Volume: voxel type " + py::str(target).cast<std::string>() +
                         " is not one of uint8, int16, uint16, float32; convert once with dtype='float32' "
                         "(or array.astype(...)) so no call converts it again");
  vs::Geometry g;
  const bool is2D = input.ndim() == 2;
  g.dims = {input.shape(is2D ? 1 : 2), input.shape(is2D ? 0 : 1), is2D ? 1 : input.shape(0)};
  g.spacing = spacingArg(spacing);
  g.origin = vec3Arg(origin, "origin");
  if (!direction.is_none()) g.direction = directionArg(direction);
  PyVolume out;
  switch (type) {
    case vs::VoxelType::UInt8:
      out.data = std::make_shared<vs::AnyVolume>(vs::VolumeU8(g));
      break;
    case vs::VoxelType::Int16:
      out.data = std::make_shared<vs::AnyVolume>(vs::VolumeI16(g));
      break;
    case vs::VoxelType::UInt16:
      out.data = std::make_shared<vs::AnyVolume>(vs::VolumeU16(g));
      break;
    case vs::VoxelType::Float32:
      out.data = std::make_shared<vs::AnyVolume>(vs::VolumeF32(g));
      break;
  }
  py::array view = arrayOf(out);
  py::object src = is2D ? input.attr("reshape")(py::make_tuple(1, input.shape(0), input.shape(1))) : py::object(input);
  // Same type: a plain copy; dtype= given: an explicit conversion (NumPy's casting rules).
  // An explicit conversion must not change values silently: NumPy wraps 70000 into int16 as
  // 4464 and casts NaN or -5 into uint8 as 0 or 251. Refuse values the target cannot hold.
  if (!dtype.is_none() && !target.is(input.dtype())) {
    py::module_ np = py::module_::import("numpy");
    const char from = input.dtype().kind();
    if ((from == 'f' || from == 'c') && kind != 'f') {
      if (!np.attr("isfinite")(input).attr("all")().cast<bool>())
        throw py::value_error("Volume: the array holds NaN or infinite values, which " +
                              py::str(target).cast<std::string>() + " cannot hold (replace them first)");
    }
    if (from == 'f' || from == 'i' || from == 'u' || from == 'b') {
      const double lo = np.attr("min")(input).cast<double>(), hi = np.attr("max")(input).cast<double>();
      py::object info = kind == 'f' ? np.attr("finfo")(target) : np.attr("iinfo")(target);
      const double tmin = info.attr("min").cast<double>(), tmax = info.attr("max").cast<double>();
      if (lo < tmin || hi > tmax)
        throw py::value_error("Volume: values " + std::to_string(lo) + ".." + std::to_string(hi) + " do not fit " +
                              py::str(target).cast<std::string>() + " (" + std::to_string(tmin) + ".." +
                              std::to_string(tmax) + "); rescale or clip them first");
    } else {
      throw py::type_error("Volume: cannot convert a " + py::str(input.dtype()).cast<std::string>() + " array to " +
                           py::str(target).cast<std::string>());
    }
  }
  py::module_::import("numpy").attr("copyto")(view, src, py::arg("casting") = dtype.is_none() ? "no" : "unsafe");
  return out;
}

std::string describe(const PyVolume& v) {
  return "<volscissors.Volume " + v.geometry().describe() + ", " + vs::voxelTypeName(vs::voxelType(v.any())) + ">";
}

}  // namespace

std::vector<double> finiteNumbers(const py::handle& obj, size_t n, const std::string& what) {
  std::vector<double> out;
  if (py::isinstance<py::str>(obj))
    throw py::value_error(what + " must be " + std::to_string(n) + " numbers, not a string");
  try {
    for (const auto& item : py::iter(obj)) out.push_back(item.cast<double>());
  } catch (const py::error_already_set&) {
    throw py::value_error(what + " must be " + std::to_string(n) + " numbers, got " +
                          py::repr(obj).cast<std::string>());
  } catch (const py::cast_error&) {
    throw py::value_error(what + " must be " + std::to_string(n) + " numbers, got " +
                          py::repr(obj).cast<std::string>());
  }
  if (out.size() != n)
    throw py::value_error(what + " must have " + std::to_string(n) + " values (x, y, z), got " +
                          std::to_string(out.size()));
  for (double x : out)
    if (!std::isfinite(x)) throw py::value_error(what + " must be finite, got " + py::repr(obj).cast<std::string>());
  return out;
}

vs::Index3 voxelIndex(const py::handle& obj, const vs::Geometry& g, const std::string& what) {
  const auto v = finiteNumbers(obj, 3, what);
  vs::Index3 i;
  for (int c = 0; c < 3; ++c) {
    if (v[c] != std::floor(v[c]))
      throw py::value_error(what + " must be integer voxel indices (x, y, z), got " +
                            py::repr(obj).cast<std::string>());
    i[c] = static_cast<int64_t>(v[c]);
  }
  if (!g.contains(i))
    throw py::value_error(what + " (" + std::to_string(i[0]) + ", " + std::to_string(i[1]) + ", " +
                          std::to_string(i[2]) + ") is outside the volume " + g.describe());
  return i;
}

std::vector<vs::Vec3> pointList(const py::handle& obj, const std::string& what) {
  std::vector<vs::Vec3> out;
  if (py::isinstance<py::str>(obj)) throw py::value_error(what + " must be a list of (x, y, z) points, not a string");
  size_t k = 0;
  try {
    for (const auto& p : py::iter(obj)) {
      const auto v = finiteNumbers(p, 3, what + "[" + std::to_string(k++) + "]");
      out.emplace_back(v[0], v[1], v[2]);
    }
  } catch (const py::error_already_set&) {
    throw py::value_error(what + " must be a list of (x, y, z) points, got " + py::repr(obj).cast<std::string>());
  }
  return out;
}

const PyVolume& volumeArg(const py::handle& obj, const std::string& what) {
  if (!py::isinstance<PyVolume>(obj)) {
    if (py::isinstance<py::array>(obj))
      throw py::type_error(what +
                           ": wrap the NumPy array once as volscissors.Volume(array, spacing=(sx, sy, sz)) "
                           "(voxel spacing in mm decides path lengths and costs; it is never guessed)");
    throw py::type_error(what + " must be a volscissors.Volume, got " + py::str(obj.get_type()).cast<std::string>());
  }
  return obj.cast<const PyVolume&>();
}

void bindVolume(py::module_& m) {
  py::class_<PyVolume>(m, "Volume", R"doc(
A 3D image with its geometry (world = origin + direction @ diag(spacing) @ index, LPS mm).

Volume(array, spacing=(1, 1, 1), origin=(0, 0, 0), direction=None, dtype=None)

array: NumPy array in [z, y, x] order (SimpleITK convention; a 2D [y, x] image is one slice),
  of uint8, int16, uint16 or float32. It is copied ONCE into volscissors-owned memory (other
  voxel types only with an explicit dtype=, converted once); every later call uses that memory.
spacing, origin: (x, y, z) in mm; direction: 3x3, columns = world directions of the x, y, z
  index axes (identity by default).
volume.array is a writable zero-copy NumPy view [z, y, x] of the voxels: edits are seen by
every later call, and the view keeps the voxels alive.)doc")
      .def(py::init(&makeVolume), py::arg("array"), py::arg("spacing") = py::make_tuple(1.0, 1.0, 1.0),
           py::arg("origin") = py::make_tuple(0.0, 0.0, 0.0), py::arg("direction") = py::none(),
           py::arg("dtype") = py::none())
      .def_property_readonly("array", &arrayOf, "zero-copy writable NumPy view of the voxels, [z, y, x]")
      .def_property_readonly(
          "dtype", [](const PyVolume& v) { return vs::voxelTypeName(vs::voxelType(v.any())); },
          "voxel type name: uint8, int16, uint16 or float32")
      .def_property_readonly(
          "dims",
          [](const PyVolume& v) {
            const auto& d = v.geometry().dims;
            return py::make_tuple(d[0], d[1], d[2]);
          },
          "voxel counts (x, y, z)")
      .def_property_readonly(
          "shape",
          [](const PyVolume& v) {
            const auto& d = v.geometry().dims;
            return py::make_tuple(d[2], d[1], d[0]);
          },
          "array shape (z, y, x)")
      .def_property(
          "spacing", [](const PyVolume& v) { return triple(v.geometry().spacing); },
          [](PyVolume& v, const py::object& s) {
            std::visit([&](auto& vol) { vol.geometry().spacing = spacingArg(s); }, *v.data);
          },
          "voxel spacing (x, y, z) in mm")
      .def_property(
          "origin", [](const PyVolume& v) { return triple(v.geometry().origin); },
          [](PyVolume& v, const py::object& o) {
            std::visit([&](auto& vol) { vol.geometry().origin = vec3Arg(o, "origin"); }, *v.data);
          },
          "world position (x, y, z) of voxel (0, 0, 0), mm (LPS)")
      .def_property(
          "direction",
          [](const PyVolume& v) {
            py::array_t<double> a({3, 3});
            for (int r = 0; r < 3; ++r)
              for (int c = 0; c < 3; ++c) a.mutable_at(r, c) = v.geometry().direction(r, c);
            return a;
          },
          [](PyVolume& v, const py::object& d) {
            std::visit([&](auto& vol) { vol.geometry().direction = directionArg(d); }, *v.data);
          },
          "3x3 direction matrix; column j = world direction of index axis j (x, y, z)")
      .def(
          "index_to_world",
          [](const PyVolume& v, const py::object& pts) {
            const auto p = pointList(py::module_::import("numpy").attr("atleast_2d")(pts), "points");
            py::array_t<double> out({static_cast<py::ssize_t>(p.size()), py::ssize_t(3)});
            for (size_t i = 0; i < p.size(); ++i) {
              const vs::Vec3 w = v.geometry().indexToWorld(p[i]);
              for (int c = 0; c < 3; ++c) out.mutable_at(static_cast<py::ssize_t>(i), c) = w[c];
            }
            return out;
          },
          py::arg("points"), "(N, 3) continuous indices (x, y, z) -> (N, 3) world mm")
      .def(
          "world_to_index",
          [](const PyVolume& v, const py::object& pts) {
            const auto p = pointList(py::module_::import("numpy").attr("atleast_2d")(pts), "points");
            py::array_t<double> out({static_cast<py::ssize_t>(p.size()), py::ssize_t(3)});
            for (size_t i = 0; i < p.size(); ++i) {
              const vs::Vec3 w = v.geometry().worldToIndex(p[i]);
              for (int c = 0; c < 3; ++c) out.mutable_at(static_cast<py::ssize_t>(i), c) = w[c];
            }
            return out;
          },
          py::arg("points"), "(N, 3) world mm -> (N, 3) continuous indices (x, y, z)")
      .def("__repr__", &describe);

  m.def(
      "read",
      [](const std::string& path, const std::string& orientation) {
        if (!orientation.empty()) vs::directionFromOrientationCode(orientation);  // ValueError before reading
        PyVolume out;
        vs::ReadInfo info;
        {
          py::gil_scoped_release nogil;
          out.data = std::make_shared<vs::AnyVolume>(vs::readVolume(path, {}, &info));
          if (!orientation.empty()) vs::setOrientation(*out.data, orientation);
        }
        if (orientation.empty() && !info.orientationInHeader)
          py::module_::import("warnings")
              .attr("warn")(path +
                            " states no orientation: LPS assumed, the anatomy may be wrong (state it with "
                            "orientation='LAS' or the code that applies)");
        return out;
      },
      py::arg("path"), py::arg("orientation") = "", R"doc(
Reads a volume: NIfTI, NRRD, MetaImage, VTK (.vtk, .vti), a DICOM folder, PNG/TIFF (2D).
Intensity scaling (NIfTI slope, DICOM rescale) is applied; voxel types other than uint8, int16,
uint16, float32 are converted as the CLI does. OSError for a missing or unreadable file.
orientation: where the axes point when the header does not say (e.g. "LAS": x to patient left,
y anterior, z superior); default "": the header's, else LPS with a UserWarning.)doc");

  m.def(
      "write",
      [](const py::object& volume, const std::string& path) {
        const PyVolume& v = volumeArg(volume, "write");
        py::gil_scoped_release nogil;
        vs::writeVolume(v.any(), path);
      },
      py::arg("volume"), py::arg("path"), R"doc(
Writes a volume by extension (.nii, .nii.gz, .nrrd, .nhdr, .mha, .mhd), keeping voxel type,
spacing, origin and direction. Atomic: never a partial file. OSError on failure.)doc");
}

}  // namespace vspy

PYBIND11_MODULE(_core, m) {
  m.doc() = "volscissors core bindings (use `import volscissors`)";
  m.attr("__version__") = VS_VERSION;
  using namespace vspy;
  g_cancelled = PyErr_NewExceptionWithDoc("volscissors.Cancelled",
                                          "A long call was cancelled (progress callback or a core cancel).",
                                          PyExc_Exception, nullptr);
  g_dataError = PyErr_NewExceptionWithDoc("volscissors.DataError",
                                          "Well-formed input whose content is unusable (NaN voxels, impassable root).",
                                          PyExc_ValueError, nullptr);
  g_unreachable =
      PyErr_NewExceptionWithDoc("volscissors.UnreachableError",
                                "A target cannot be reached from the root (separate component).", g_dataError, nullptr);
  m.attr("Cancelled") = py::handle(g_cancelled);
  m.attr("DataError") = py::handle(g_dataError);
  m.attr("UnreachableError") = py::handle(g_unreachable);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const vs::Cancelled& e) {
      PyErr_SetString(g_cancelled, e.what());
    } catch (const vs::UnreachableTarget& e) {
      PyErr_SetString(g_unreachable, e.what());
    } catch (const vs::IoError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    } catch (const vs::DataError& e) {
      PyErr_SetString(g_dataError, e.what());
    } catch (const vs::InvalidArgument& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const vs::Error& e) {
      PyErr_SetString(PyExc_RuntimeError, e.what());
    }
  });
  bindVolume(m);
  bindLiveWire(m);
  bindTrace(m);
  bindCost(m);
  bindRender(m);
  bindMesh(m);
}
