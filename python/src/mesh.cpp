// volscissors.Mesh and the tools that make meshes or cut volumes: isosurface (src/meshops, VTK),
// surface (three orthogonal contours, src/surface) and cut (src/cutting), as the CLI runs them.
#include <cmath>

#include "common.h"
#include "cutting/cut.h"
#include "io/mesh_io.h"
#include "meshops/isosurface.h"
#include "surface/surface.h"

namespace vspy {

namespace {

// The core's defaults, as the CLI's.
const vs::SurfaceOptions kSurfaceDefaults;
const vs::CutOptions kCutDefaults;

struct Mesh {
  vs::TriMesh mesh;
};

py::array vectors(const std::vector<Eigen::Vector3d>& v) {
  py::array_t<double> a({static_cast<py::ssize_t>(v.size()), py::ssize_t(3)});
  for (size_t i = 0; i < v.size(); ++i)
    for (int c = 0; c < 3; ++c) a.mutable_at(static_cast<py::ssize_t>(i), c) = v[i][c];
  return a;
}

double isoArg(const py::object& iso) {
  const double v = iso.cast<double>();
  if (!std::isfinite(v)) throw py::value_error("iso must be a finite value");
  return v;
}

}  // namespace

void bindMesh(py::module_& m) {
  py::class_<Mesh>(m, "Mesh", "A triangle mesh in world mm (LPS), outward normals, counter-clockwise from outside.")
      .def_property_readonly(
          "vertices", [](const Mesh& s) { return vectors(s.mesh.positions); }, "(N, 3) vertex positions (x, y, z), mm")
      .def_property_readonly(
          "triangles",
          [](const Mesh& s) {
            py::array_t<int32_t> a({static_cast<py::ssize_t>(s.mesh.triangles.size()), py::ssize_t(3)});
            for (size_t i = 0; i < s.mesh.triangles.size(); ++i)
              for (int c = 0; c < 3; ++c) a.mutable_at(static_cast<py::ssize_t>(i), c) = s.mesh.triangles[i][c];
            return a;
          },
          "(M, 3) int32 vertex indices per triangle")
      .def_property_readonly(
          "normals",
          [](const Mesh& s) -> py::object {
            if (s.mesh.normals.empty()) return py::none();
            return vectors(s.mesh.normals);
          },
          "(N, 3) unit vertex normals, or None")
      .def(
          "save",
          [](const Mesh& s, const std::string& path) {
            py::gil_scoped_release nogil;
            vs::writeTriMesh(s.mesh, path);
          },
          py::arg("path"), "write .ply, .obj, .stl or .vtk (atomic)")
      .def("__len__", [](const Mesh& s) { return s.mesh.triangles.size(); })
      .def("__repr__", [](const Mesh& s) {
        return "<volscissors.Mesh " + std::to_string(s.mesh.positions.size()) + " vertices, " +
               std::to_string(s.mesh.triangles.size()) + " triangles>";
      });

  m.def(
      "isosurface",
      [](const py::object& volume, const py::object& iso, bool largestComponent, int smoothIterations, double decimate,
         const py::object& progress) {
        const PyVolume& vol = volumeArg(volume, "isosurface volume");
        vs::IsoSurfaceOptions o;
        o.iso = isoArg(iso);
        o.largestComponentOnly = largestComponent;
        o.smoothIterations = smoothIterations;
        o.decimateReduction = decimate;
        auto data = vol.data;
        Mesh out;
        out.mesh = runReleased(progress, [&](vs::Progress& pr) {
          return withFloat(*data, [&](const vs::VolumeF32& f) { return vs::extractIsoSurface(f, o, pr); });
        });
        return out;
      },
      py::arg("volume"), py::arg("iso"), py::arg("largest_component") = true, py::arg("smooth_iterations") = 0,
      py::arg("decimate") = 0.0, py::arg("progress") = py::none(), R"doc(
Iso-surface (VTK flying edges) of a Volume at `iso` (the object is the brighter side) -> Mesh.
largest_component keeps the largest connected piece; smooth_iterations: windowed-sinc smoothing
(0 = off); decimate: target reduction in [0, 1) (0 = off). DataError when iso crosses no voxel.)doc");

  m.def(
      "surface",
      [](const py::object& volume, const py::object& planes, const py::object& iso, int level, bool closed,
         const std::string& octant, int connectivity, bool allowFolds, const py::object& progress) {
        const PyVolume& vol = volumeArg(volume, "surface volume");
        vs::SurfaceOptions o;
        o.planes = voxelIndex(planes, vol.geometry(), "planes (x0, y0, z0)");
        if (!iso.is_none()) o.iso = isoArg(iso);
        o.level = level;
        o.closed = closed;
        o.octant = vs::parseOctant(octant);
        o.connectivity = connectivity;
        o.allowFolds = allowFolds;  // the core's surface policy, as `volscissors surface`
        auto data = vol.data;
        Mesh out;
        vs::SurfaceResult r = runReleased(progress, [&](vs::Progress& pr) {
          return withFloat(*data, [&](const vs::VolumeF32& f) { return vs::extractSurface(f, o, pr); });
        });
        out.mesh = std::move(r.mesh);
        return out;
      },
      py::arg("volume"), py::arg("planes"), py::arg("iso") = py::none(), py::arg("level") = kSurfaceDefaults.level,
      py::arg("closed") = kSurfaceDefaults.closed, py::arg("octant") = vs::octantName(kSurfaceDefaults.octant),
      py::arg("connectivity") = kSurfaceDefaults.connectivity, py::arg("allow_folds") = kSurfaceDefaults.allowFolds,
      py::arg("progress") = py::none(), R"doc(
Surface from three orthogonal contours (thesis 4.3.1): the planes x0, y0, z0 (voxel indices) meet
at a point inside the object; each octant is one deformed triangle subdivided `level` times
(0..8) by 3D minimum-cost paths. iso: default the Otsu threshold. closed=True stitches all eight
octants watertight; else the one `octant` ("+x+y+z", "-x+y+z", ...). -> Mesh in world mm.
DataError for a mesh the core's surface policy refuses, as the CLI and the viewer (degenerate
triangles are repaired; then not manifold, closed and not watertight, or an octant folding back
over itself unless allow_folds=True).)doc");

  m.def(
      "cut",
      [](const py::object& volume, const py::object& iso, const py::object& points, const py::object& keep,
         double snapRadiusMm, double wg, double wc, double wp, double wd, double contourWg, double contourWn,
         double contourWl, const py::object& progress) {
        const PyVolume& vol = volumeArg(volume, "cut volume");
        vs::CutOptions o;
        o.surface.wg = wg;
        o.surface.wc = wc;
        o.surface.wp = wp;
        o.surface.wd = wd;
        o.cost.wg = contourWg;
        o.cost.wn = contourWn;
        o.cost.wl = contourWl;
        o.iso = isoArg(iso);
        o.pointsIndex = pointList(points, "points");
        if (o.pointsIndex.size() < 3) throw py::value_error("points: need at least 3 points around the part");
        for (size_t i = 0; i < o.pointsIndex.size(); ++i)
          if (!vol.geometry().containsContinuous(o.pointsIndex[i]))
            throw py::value_error("points[" + std::to_string(i) + "] is outside the volume " +
                                  vol.geometry().describe());
        if (!keep.is_none()) o.keepSeed = voxelIndex(keep, vol.geometry(), "keep");
        if (!(snapRadiusMm > 0) || !std::isfinite(snapRadiusMm)) throw py::value_error("snap_radius_mm must be > 0");
        o.snapRadiusMm = snapRadiusMm;
        auto data = vol.data;
        PyVolume labels;
        labels.data = std::make_shared<vs::AnyVolume>(runReleased(progress, [&](vs::Progress& pr) {
          return withFloat(*data, [&](const vs::VolumeF32& f) { return vs::cutVolume(f, o, pr).split.labels; });
        }));
        return labels;
      },
      py::arg("volume"), py::arg("iso"), py::arg("points"), py::arg("keep") = py::none(),
      py::arg("snap_radius_mm") = kCutDefaults.snapRadiusMm, py::arg("wg") = kCutDefaults.surface.wg,
      py::arg("wc") = kCutDefaults.surface.wc, py::arg("wp") = kCutDefaults.surface.wp,
      py::arg("wd") = kCutDefaults.surface.wd, py::arg("contour_wg") = kCutDefaults.cost.wg,
      py::arg("contour_wn") = kCutDefaults.cost.wn, py::arg("contour_wl") = kCutDefaults.cost.wl,
      py::arg("progress") = py::none(), R"doc(
Volume cutting (thesis ch. 3): the object is the voxels >= iso; `points` (continuous voxel indices
(x, y, z), in loop order) go around the part to cut off; they snap to the object's surface within
snap_radius_mm. A closed live-wire on the surface, an internal cutting surface and region growing
split the object. -> uint8 label Volume: 0 background, 1 kept, 2 cut away. keep: a voxel whose
side is kept (default: cut away the smaller side). DataError when the contour separates nothing.
Cutting surface weights (eq. 15-18): wg image term (edge strength x direction), wc continuity, wp
cost per pixel of depth below the surrounding surface's continuation where the part stands out
(a nose), wd the direction-consistency share of the image term (0..1). Contour live-wire on the
mesh (eq. 13): contour_wg gradient, contour_wn normal change, contour_wl length (> 0). ValueError
for a weight out of range.)doc");
}

}  // namespace vspy
