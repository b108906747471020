#include "meshops/polydata_file.h"

#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkIdList.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataReader.h>
#include <vtkPolyDataWriter.h>
#include <vtkSmartPointer.h>
#include <vtkTriangleFilter.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>

#include <array>
#include <cmath>
#include <string>

#include "util/atomic_file.h"
#include "util/error.h"

namespace vs {

namespace {

template <class T>
using Ptr = vtkSmartPointer<T>;

// VTK reports problems through vtkErrorMacro, which prints to the terminal by default; an
// observer on the algorithm collects them instead, so the caller gets one IoError.
struct VtkMessages {
  std::string first;
  Ptr<vtkCallbackCommand> command = Ptr<vtkCallbackCommand>::New();
  explicit VtkMessages(vtkObject* watched) {
    command->SetClientData(this);
    command->SetCallback([](vtkObject*, unsigned long, void* self, void* text) {
      auto* m = static_cast<VtkMessages*>(self);
      if (m->first.empty() && text) m->first = static_cast<const char*>(text);
    });
    watched->AddObserver(vtkCommand::ErrorEvent, command);
    watched->AddObserver(vtkCommand::WarningEvent, command);
  }
  // VTK's text is "ERROR: In file.cxx, line N\nvtkClass (0x...): message": keep the message.
  std::string message() const {
    const size_t colon = first.rfind("): ");
    std::string m = colon == std::string::npos ? first : first.substr(colon + 3);
    while (!m.empty() && (m.back() == '\n' || m.back() == ' ')) m.pop_back();
    return m;
  }
};

void silenceVtkOutputWindow() {
  static const bool once = [] {
    vtkObject::GlobalWarningDisplayOff();
    return true;
  }();
  (void)once;
}

std::vector<Polyline> linesOf(vtkPolyData* pd, const std::string& path) {
  std::vector<Polyline> out;
  vtkDataArray* radius = pd->GetPointData()->GetArray("radius");
  if (radius && radius->GetNumberOfComponents() != 1) radius = nullptr;
  auto ids = Ptr<vtkIdList>::New();
  vtkCellArray* cells = pd->GetLines();
  cells->InitTraversal();
  while (cells->GetNextCell(ids)) {
    Polyline line;
    const vtkIdType n = ids->GetNumberOfIds();
    for (vtkIdType k = 0; k < n; ++k) {
      const vtkIdType id = ids->GetId(k);
      if (id < 0 || id >= pd->GetNumberOfPoints()) throw IoError(path + ": a line refers to a missing point");
      line.points.push_back(Eigen::Vector3d(pd->GetPoint(id)));
      if (radius) line.radii.push_back(radius->GetComponent(id, 0));
    }
    // A loop stored with its first point repeated at the end is a closed polyline.
    if (n > 3 && ids->GetId(0) == ids->GetId(n - 1)) {
      line.closed = true;
      line.points.pop_back();
      if (radius) line.radii.pop_back();
    }
    if (line.points.size() >= 2) out.push_back(std::move(line));
  }
  return out;
}

TriMesh trianglesOf(vtkPolyData* pd, const std::string& path) {
  TriMesh mesh;
  const vtkIdType n = pd->GetNumberOfPoints();
  for (vtkIdType i = 0; i < n; ++i) mesh.positions.push_back(Eigen::Vector3d(pd->GetPoint(i)));
  if (vtkDataArray* normals = pd->GetPointData()->GetNormals();
      normals && normals->GetNumberOfComponents() == 3 && normals->GetNumberOfTuples() == n)
    for (vtkIdType i = 0; i < n; ++i) mesh.normals.push_back(Eigen::Vector3d(normals->GetTuple3(i)));
  if (pd->GetNumberOfPolys() + pd->GetNumberOfStrips() == 0) return mesh;
  // Polygons (any size, concave too) and strips become triangles; lines and vertices are not
  // passed on (lines are read as polylines, not as 2-point segments).
  auto surface = Ptr<vtkPolyData>::New();
  surface->SetPoints(pd->GetPoints());
  surface->SetPolys(pd->GetPolys());
  surface->SetStrips(pd->GetStrips());
  auto triangulate = Ptr<vtkTriangleFilter>::New();
  triangulate->SetInputData(surface);
  triangulate->PassVertsOff();
  triangulate->PassLinesOff();
  VtkMessages messages(triangulate);
  triangulate->Update();
  if (!messages.first.empty()) throw IoError(path + ": " + messages.message());
  vtkPolyData* tri = triangulate->GetOutput();
  auto ids = Ptr<vtkIdList>::New();
  vtkCellArray* polys = tri->GetPolys();
  polys->InitTraversal();
  while (polys->GetNextCell(ids)) {
    if (ids->GetNumberOfIds() != 3) continue;
    std::array<int32_t, 3> t{};
    for (int k = 0; k < 3; ++k) {
      const vtkIdType id = ids->GetId(k);
      if (id < 0 || id >= n) throw IoError(path + ": a polygon refers to a missing point");
      t[static_cast<size_t>(k)] = static_cast<int32_t>(id);
    }
    mesh.triangles.push_back(t);
  }
  return mesh;
}

Ptr<vtkPolyData> toVtk(const PolyDataContent& c) {
  auto points = Ptr<vtkPoints>::New();
  points->SetDataTypeToDouble();
  auto radius = Ptr<vtkDoubleArray>::New();
  radius->SetName("radius");
  bool anyRadius = false;
  for (const auto& p : c.mesh.positions) {
    points->InsertNextPoint(p.data());
    radius->InsertNextValue(0);
  }
  auto polys = Ptr<vtkCellArray>::New();
  for (const auto& t : c.mesh.triangles) {
    const vtkIdType ids[3] = {t[0], t[1], t[2]};
    polys->InsertNextCell(3, ids);
  }
  auto lines = Ptr<vtkCellArray>::New();
  for (const auto& l : c.lines) {
    std::vector<vtkIdType> ids;
    for (size_t k = 0; k < l.points.size(); ++k) {
      ids.push_back(points->InsertNextPoint(l.points[k].data()));
      radius->InsertNextValue(l.radii.empty() ? 0.0 : l.radii[k]);
      anyRadius = anyRadius || !l.radii.empty();
    }
    if (l.closed && !ids.empty()) ids.push_back(ids.front());
    lines->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
  }
  auto pd = Ptr<vtkPolyData>::New();
  pd->SetPoints(points);
  pd->SetPolys(polys);
  pd->SetLines(lines);
  if (anyRadius) pd->GetPointData()->AddArray(radius);
  return pd;
}

}  // namespace

PolyDataContent readPolyDataFile(const std::string& path) {
  silenceVtkOutputWindow();
  const std::string ext = fileExtension(path);
  if (ext != ".vtp" && ext != ".vtk")
    throw InvalidArgument(path + ": VTK polygonal data must be .vtp or .vtk, not '" + ext + "'");
  Ptr<vtkPolyData> pd;
  std::string complaint;
  if (ext == ".vtp") {
    auto reader = Ptr<vtkXMLPolyDataReader>::New();
    if (!reader->CanReadFile(path.c_str()))
      throw IoError(path + ": not a readable VTK XML PolyData file (missing, or not <VTKFile type=\"PolyData\">)");
    VtkMessages messages(reader);
    reader->SetFileName(path.c_str());
    reader->Update();
    complaint = messages.first.empty() ? "" : messages.message();
    pd = reader->GetOutput();
  } else {
    auto reader = Ptr<vtkPolyDataReader>::New();
    VtkMessages messages(reader);
    reader->SetFileName(path.c_str());
    if (!reader->IsFilePolyData()) throw IoError(path + ": not a readable legacy VTK POLYDATA file");
    reader->Update();
    complaint = messages.first.empty() ? "" : messages.message();
    pd = reader->GetOutput();
  }
  if (!complaint.empty()) throw IoError(path + ": " + complaint);
  if (!pd) throw IoError(path + ": VTK read no polygonal data");
  PolyDataContent c;
  c.mesh = trianglesOf(pd, path);
  c.lines = linesOf(pd, path);
  for (const auto& p : c.mesh.positions)
    if (!p.allFinite()) throw IoError(path + ": a point coordinate is not finite");
  if (c.mesh.triangles.empty()) c.mesh = TriMesh();  // points of the lines only
  return c;
}

void writePolyDataFile(const PolyDataContent& content, const std::string& path, const PolyDataWriteOptions& options) {
  silenceVtkOutputWindow();
  const std::string ext = fileExtension(path);
  const Ptr<vtkPolyData> pd = toVtk(content);
  std::string bytes, complaint;
  if (ext == ".vtp") {
    auto writer = Ptr<vtkXMLPolyDataWriter>::New();
    VtkMessages messages(writer);
    writer->SetInputData(pd);
    writer->SetWriteToOutputString(1);
    if (options.binary)
      writer->SetDataModeToAppended();
    else
      writer->SetDataModeToAscii();
    if (!options.compressed) writer->SetCompressorTypeToNone();
    writer->Write();
    complaint = messages.first.empty() ? "" : messages.message();
    bytes = writer->GetOutputString();
  } else if (ext == ".vtk") {
    auto writer = Ptr<vtkPolyDataWriter>::New();
    VtkMessages messages(writer);
    writer->SetInputData(pd);
    writer->WriteToOutputStringOn();
    if (options.binary)
      writer->SetFileTypeToBinary();
    else
      writer->SetFileTypeToASCII();
    writer->Write();
    complaint = messages.first.empty() ? "" : messages.message();
    bytes.assign(writer->GetOutputString(), static_cast<size_t>(writer->GetOutputStringLength()));
  } else {
    throw InvalidArgument(path + ": VTK polygonal data must be .vtp or .vtk, not '" + ext + "'");
  }
  if (!complaint.empty() || bytes.empty()) throw IoError(path + ": VTK could not write the file: " + complaint);
  writeFileAtomically(path, bytes);
}

}  // namespace vs
