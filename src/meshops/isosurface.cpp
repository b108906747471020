#include "meshops/isosurface.h"

#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkFloatArray.h>
#include <vtkFlyingEdges3D.h>
#include <vtkIdList.h>
#include <vtkIdTypeArray.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataConnectivityFilter.h>
#include <vtkQuadricDecimation.h>
#include <vtkSmartPointer.h>
#include <vtkWindowedSincPolyDataFilter.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include "util/error.h"

namespace vs {
namespace {

template <class T>
using Ptr = vtkSmartPointer<T>;

// Wraps the volume's voxels without a copy (VTK only reads them), in index space.
Ptr<vtkImageData> wrapIndexSpace(const Volume<float>& volume) {
  auto scalars = Ptr<vtkFloatArray>::New();
  // save = 1: VTK must not free the buffer, which the Volume owns.
  scalars->SetArray(const_cast<float*>(volume.data()), volume.size(), 1);
  auto image = Ptr<vtkImageData>::New();
  const Index3& d = volume.dims();
  image->SetDimensions(static_cast<int>(d[0]), static_cast<int>(d[1]), static_cast<int>(d[2]));
  image->SetSpacing(1, 1, 1);
  image->SetOrigin(0, 0, 0);
  image->GetPointData()->SetScalars(scalars);
  return image;
}

// Points and triangles of a VTK poly data (index space here), dropping non-triangles.
TriMesh fromPolyData(vtkPolyData* poly) {
  TriMesh mesh;
  const vtkIdType n = poly->GetNumberOfPoints();
  mesh.positions.resize(static_cast<size_t>(n));
  for (vtkIdType i = 0; i < n; ++i) {
    double p[3];
    poly->GetPoint(i, p);
    mesh.positions[static_cast<size_t>(i)] = Vec3(p[0], p[1], p[2]);
  }
  vtkCellArray* polys = poly->GetPolys();
  auto ids = Ptr<vtkIdList>::New();
  polys->InitTraversal();
  while (polys->GetNextCell(ids))
    if (ids->GetNumberOfIds() == 3)
      mesh.triangles.push_back({static_cast<int32_t>(ids->GetId(0)), static_cast<int32_t>(ids->GetId(1)),
                                static_cast<int32_t>(ids->GetId(2))});
  return mesh;
}

// Drops vertices used by no triangle (decimation and component extraction leave them).
TriMesh compact(const TriMesh& mesh) {
  std::vector<int32_t> remap(mesh.positions.size(), -1);
  for (const auto& t : mesh.triangles)
    for (int32_t v : t) remap[static_cast<size_t>(v)] = 0;
  TriMesh out;
  for (size_t i = 0; i < remap.size(); ++i)
    if (remap[i] == 0) {
      remap[i] = static_cast<int32_t>(out.positions.size());
      out.positions.push_back(mesh.positions[i]);
      if (!mesh.normals.empty()) out.normals.push_back(mesh.normals[i]);
    }
  out.triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles)
    out.triangles.push_back(
        {remap[static_cast<size_t>(t[0])], remap[static_cast<size_t>(t[1])], remap[static_cast<size_t>(t[2])]});
  return out;
}

float sampleClamped(const Volume<float>& v, const Vec3& p) {
  const Index3& d = v.dims();
  double c[3];
  int64_t i0[3];
  for (int k = 0; k < 3; ++k) {
    c[k] = std::clamp(p[k], 0.0, static_cast<double>(d[k] - 1));
    i0[k] = std::min<int64_t>(static_cast<int64_t>(c[k]), std::max<int64_t>(d[k] - 2, 0));
    c[k] -= static_cast<double>(i0[k]);
  }
  double s = 0;
  for (int dz = 0; dz < 2; ++dz)
    for (int dy = 0; dy < 2; ++dy)
      for (int dx = 0; dx < 2; ++dx) {
        const int64_t x = std::min(i0[0] + dx, d[0] - 1), y = std::min(i0[1] + dy, d[1] - 1),
                      z = std::min(i0[2] + dz, d[2] - 1);
        const double w = (dx ? c[0] : 1 - c[0]) * (dy ? c[1] : 1 - c[1]) * (dz ? c[2] : 1 - c[2]);
        s += w * v(x, y, z);
      }
  return static_cast<float>(s);
}

// True when most triangles (by area) already face from bright to dark in index space: the face
// normal opposes the local intensity gradient. Decided once for the whole mesh, as VTK's winding
// is consistent.
bool facesOutward(const Volume<float>& volume, const TriMesh& indexMesh) {
  double vote = 0;
  const size_t step = std::max<size_t>(1, indexMesh.triangles.size() / 4096);
  for (size_t i = 0; i < indexMesh.triangles.size(); i += step) {
    const auto& t = indexMesh.triangles[i];
    const Vec3& a = indexMesh.positions[static_cast<size_t>(t[0])];
    const Vec3& b = indexMesh.positions[static_cast<size_t>(t[1])];
    const Vec3& c = indexMesh.positions[static_cast<size_t>(t[2])];
    const Vec3 n = (b - a).cross(c - a);
    const Vec3 m = (a + b + c) / 3.0;
    Vec3 g;
    for (int k = 0; k < 3; ++k) {
      Vec3 e = Vec3::Zero();
      e[k] = 0.5;
      g[k] = sampleClamped(volume, m + e) - sampleClamped(volume, m - e);
    }
    vote += n.dot(g) < 0 ? n.norm() : -n.norm();
  }
  return vote >= 0;
}

void flipAll(TriMesh& mesh) {
  for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
}

}  // namespace

std::vector<Eigen::Vector3d> vertexNormals(const TriMesh& mesh) {
  std::vector<Vec3> normals(mesh.positions.size(), Vec3::Zero());
  for (const auto& t : mesh.triangles) {
    const Vec3& a = mesh.positions[static_cast<size_t>(t[0])];
    const Vec3& b = mesh.positions[static_cast<size_t>(t[1])];
    const Vec3& c = mesh.positions[static_cast<size_t>(t[2])];
    const Vec3 n = (b - a).cross(c - a);  // length = twice the area: area weighting
    for (int32_t v : t) normals[static_cast<size_t>(v)] += n;
  }
  for (auto& n : normals) {
    const double len = n.norm();
    n = len > 0 ? Vec3(n / len) : Vec3::Zero();
  }
  return normals;
}

TriMesh extractIsoSurface(const Volume<float>& volume, const IsoSurfaceOptions& options, Progress& progress) {
  VS_REQUIRE(!volume.empty(), "extractIsoSurface: empty volume");
  VS_REQUIRE(std::isfinite(options.iso), "extractIsoSurface: the iso-value must be finite");
  VS_REQUIRE(options.smoothIterations >= 0, "extractIsoSurface: smoothing iterations must be >= 0");
  VS_REQUIRE(options.decimateReduction >= 0 && options.decimateReduction < 1,
             "extractIsoSurface: decimation reduction must be in [0, 1)");
  progress.report(0.0, "iso-surface");

  Ptr<vtkImageData> image = wrapIndexSpace(volume);
  auto flyingEdges = Ptr<vtkFlyingEdges3D>::New();
  flyingEdges->SetInputData(image);
  flyingEdges->SetValue(0, options.iso);
  flyingEdges->ComputeNormalsOff();
  flyingEdges->ComputeGradientsOff();
  flyingEdges->ComputeScalarsOff();
  flyingEdges->Update();
  Ptr<vtkPolyData> poly = flyingEdges->GetOutput();
  if (poly->GetNumberOfPolys() == 0) {
    const auto [lo, hi] = std::minmax_element(volume.voxels().begin(), volume.voxels().end());
    std::ostringstream msg;
    msg << "iso-value " << options.iso << " gives no surface: the volume's values lie in [" << *lo << ", " << *hi
        << "]";
    throw DataError(msg.str());
  }
  progress.report(0.4, "iso-surface");

  if (options.largestComponentOnly) {
    auto connectivity = Ptr<vtkPolyDataConnectivityFilter>::New();
    connectivity->SetInputData(poly);
    connectivity->SetExtractionModeToLargestRegion();
    connectivity->Update();
    poly = connectivity->GetOutput();
    progress.report(0.55, "iso-surface");
  }
  if (options.decimateReduction > 0) {
    auto decimate = Ptr<vtkQuadricDecimation>::New();
    decimate->SetInputData(poly);
    decimate->SetTargetReduction(options.decimateReduction);
    decimate->Update();
    poly = decimate->GetOutput();
    progress.report(0.75, "iso-surface");
  }
  if (options.smoothIterations > 0) {
    auto smooth = Ptr<vtkWindowedSincPolyDataFilter>::New();
    smooth->SetInputData(poly);
    smooth->SetNumberOfIterations(options.smoothIterations);
    smooth->SetPassBand(0.1);
    smooth->NormalizeCoordinatesOn();  // pass band independent of the mesh's size
    smooth->BoundarySmoothingOff();    // keep the rim where the object leaves the volume
    smooth->FeatureEdgeSmoothingOff();
    smooth->Update();
    poly = smooth->GetOutput();
    progress.report(0.9, "iso-surface");
  }

  TriMesh mesh = compact(fromPolyData(poly));
  if (mesh.triangles.empty()) throw DataError("iso-value " + std::to_string(options.iso) + " gives no surface");
  if (!facesOutward(volume, mesh)) flipAll(mesh);

  const Geometry& g = volume.geometry();
  for (Vec3& p : mesh.positions) p = g.indexToWorld(p);
  // A mirroring index->world map (negative determinant) reverses the winding.
  if ((g.direction * g.spacing.asDiagonal()).determinant() < 0) flipAll(mesh);
  mesh.normals = vertexNormals(mesh);
  progress.report(1.0, "iso-surface");
  return mesh;
}

std::vector<int32_t> meshComponents(const TriMesh& mesh, int32_t* componentCount) {
  std::vector<int32_t> component(mesh.positions.size(), -1);
  if (componentCount) *componentCount = 0;
  if (mesh.triangles.empty()) return component;
  // Triangles sharing a vertex are connected (what vtkPolyDataConnectivityFilter does, without
  // copying the mesh into VTK: a union-find over the vertices, ~20x faster on a head's skin).
  std::vector<int32_t> parent(mesh.positions.size());
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int32_t v) {
    while (parent[size_t(v)] != v) v = parent[size_t(v)] = parent[size_t(parent[size_t(v)])];
    return v;
  };
  for (const auto& t : mesh.triangles) {
    VS_REQUIRE(t[0] >= 0 && t[1] >= 0 && t[2] >= 0 && size_t(std::max({t[0], t[1], t[2]})) < parent.size(),
               "meshComponents: a triangle refers to a missing vertex");
    for (int k = 1; k < 3; ++k) {
      const int32_t a = find(t[0]), b = find(t[size_t(k)]);
      if (a != b) parent[size_t(std::max(a, b))] = std::min(a, b);
    }
  }
  // Regions numbered in the order their first triangle appears (VTK's traversal order).
  std::vector<int32_t> regionOfRoot(mesh.positions.size(), -1);
  int32_t count = 0;
  for (const auto& t : mesh.triangles) {
    int32_t& r = regionOfRoot[size_t(find(t[0]))];
    if (r < 0) r = count++;
  }
  std::vector<int64_t> size(static_cast<size_t>(count), 0);
  for (const auto& t : mesh.triangles)
    for (int32_t v : t)
      if (component[size_t(v)] < 0) {
        component[size_t(v)] = regionOfRoot[size_t(find(v))];
        ++size[size_t(component[size_t(v)])];
      }
  // Renumber by decreasing size (ties by VTK's order) so 0 is always the largest.
  std::vector<int32_t> order(static_cast<size_t>(count));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int32_t a, int32_t b) { return size[size_t(a)] > size[size_t(b)]; });
  std::vector<int32_t> rank(static_cast<size_t>(count));
  for (int32_t r = 0; r < count; ++r) rank[static_cast<size_t>(order[static_cast<size_t>(r)])] = r;
  for (auto& c : component)
    if (c >= 0) c = rank[static_cast<size_t>(c)];
  if (componentCount) *componentCount = count;
  return component;
}

TriMesh keepComponent(const TriMesh& mesh, const std::vector<int32_t>& componentOfVertex, int32_t component) {
  VS_REQUIRE(componentOfVertex.size() == mesh.positions.size(), "keepComponent: one component id per vertex");
  TriMesh part;
  part.positions = mesh.positions;
  part.normals = mesh.normals;
  for (const auto& t : mesh.triangles)
    if (componentOfVertex[static_cast<size_t>(t[0])] == component) part.triangles.push_back(t);
  return compact(part);
}

TriMesh keepComponentNearest(const TriMesh& mesh, const std::vector<Vec3>& pointsMm) {
  VS_REQUIRE(!mesh.empty(), "keepComponentNearest: empty mesh");
  VS_REQUIRE(!pointsMm.empty(), "keepComponentNearest: no points");
  int32_t count = 0;
  const std::vector<int32_t> component = meshComponents(mesh, &count);
  std::vector<int> votes(static_cast<size_t>(count), 0);
  for (const Vec3& p : pointsMm) {
    double best = std::numeric_limits<double>::infinity();
    int32_t bestComponent = -1;
    for (size_t i = 0; i < mesh.positions.size(); ++i)
      if (component[i] >= 0) {
        const double d = (mesh.positions[i] - p).squaredNorm();
        if (d < best) best = d, bestComponent = component[i];
      }
    if (bestComponent >= 0) ++votes[static_cast<size_t>(bestComponent)];
  }
  // Components are numbered largest first, so max_element's first maximum breaks ties by size.
  const int32_t chosen = static_cast<int32_t>(std::max_element(votes.begin(), votes.end()) - votes.begin());
  return keepComponent(mesh, component, chosen);
}

}  // namespace vs
