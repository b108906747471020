#include "meshops/polydata_file.h"

#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkDoubleArray.h>
#include <vtkIdList.h>
#include <vtkLogger.h>
#include <vtkOutputWindow.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataWriter.h>
#include <vtkSTLReader.h>
#include <vtkSTLWriter.h>
#include <vtkSmartPointer.h>
#include <vtkTriangleFilter.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>

#include <array>
#include <climits>
#include <cmath>
#include <filesystem>
#include <string>

#include "meshops/polydata_scan.h"
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
  void check(const std::string& path, const std::string& doing) const {
    if (!first.empty()) throw IoError(path + ": " + doing + message());
  }
};

// VTK's messages reach an object's observers only while the global warning display is on
// (turning it off silenced the observers too); what no observer takes (generic warnings of
// VTK's parsing helpers) is kept off the terminal instead.
void silenceVtkOutputWindow() {
  static const bool once = [] {
    vtkObject::GlobalWarningDisplayOn();
    vtkOutputWindow::GetInstance()->SetDisplayModeToNever();
    vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
    return true;
  }();
  (void)once;
}

// The file exists and is a regular file; noted as an input (outputs never replace it).
void checkInputFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw IoError(path + ": file not found");
  if (std::filesystem::is_directory(path, ec)) throw IoError(path + ": is a directory, expected a file");
  noteInputFile(path);
}

// Every id of every cell of `cells` must name a point (VTK's readers do not check them, and
// its filters would read past the points).
void checkIds(vtkCellArray* cells, vtkIdType points, const std::string& path, const char* what) {
  if (!cells) return;
  auto ids = Ptr<vtkIdList>::New();
  for (vtkIdType c = 0; c < cells->GetNumberOfCells(); ++c) {
    cells->GetCellAtId(c, ids);
    for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k)
      if (ids->GetId(k) < 0 || ids->GetId(k) >= points)
        throw IoError(path + ": " + what + " refers to point " + std::to_string(ids->GetId(k)) + " of " +
                      std::to_string(points));
  }
}

// Polygons (any size, concave too) and strips become triangles; lines and vertices are not
// passed on (lines are read as line cells). Triangles keep their order and vertex order.
std::vector<std::array<int32_t, 3>> trianglesOf(vtkPolyData* pd, const std::string& path) {
  std::vector<std::array<int32_t, 3>> out;
  if (pd->GetNumberOfPolys() + pd->GetNumberOfStrips() == 0) return out;
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
  messages.check(path, "");
  vtkCellArray* polys = triangulate->GetOutput()->GetPolys();
  checkIds(polys, pd->GetNumberOfPoints(), path, "a triangle");
  auto ids = Ptr<vtkIdList>::New();
  for (vtkIdType c = 0; c < polys->GetNumberOfCells(); ++c) {
    polys->GetCellAtId(c, ids);
    if (ids->GetNumberOfIds() != 3) continue;
    out.push_back({static_cast<int32_t>(ids->GetId(0)), static_cast<int32_t>(ids->GetId(1)),
                   static_cast<int32_t>(ids->GetId(2))});
  }
  return out;
}

PolyDataCells cellsOf(vtkPolyData* pd, const std::string& path) {
  PolyDataCells c;
  const vtkIdType n = pd->GetNumberOfPoints();
  if (n > INT32_MAX) throw IoError(path + ": more than 2^31 - 1 points");
  checkIds(pd->GetPolys(), n, path, "a polygon");
  checkIds(pd->GetStrips(), n, path, "a triangle strip");
  checkIds(pd->GetLines(), n, path, "a line");
  c.mesh.positions.reserve(static_cast<size_t>(n));
  for (vtkIdType i = 0; i < n; ++i) {
    c.mesh.positions.push_back(Eigen::Vector3d(pd->GetPoint(i)));
    if (!c.mesh.positions.back().allFinite()) throw IoError(path + ": a point coordinate is not finite");
  }
  vtkPointData* data = pd->GetPointData();
  if (vtkDataArray* normals = data->GetNormals();
      normals && normals->GetNumberOfComponents() == 3 && normals->GetNumberOfTuples() == n)
    for (vtkIdType i = 0; i < n; ++i) c.mesh.normals.push_back(Eigen::Vector3d(normals->GetTuple3(i)));
  c.mesh.triangles = trianglesOf(pd, path);
  auto ids = Ptr<vtkIdList>::New();
  vtkCellArray* lines = pd->GetLines();
  for (vtkIdType l = 0; lines && l < lines->GetNumberOfCells(); ++l) {
    lines->GetCellAtId(l, ids);
    std::vector<int32_t> cell(static_cast<size_t>(ids->GetNumberOfIds()));
    for (size_t k = 0; k < cell.size(); ++k) cell[k] = static_cast<int32_t>(ids->GetId(static_cast<vtkIdType>(k)));
    c.lines.push_back(std::move(cell));
  }
  for (int a = 0; a < data->GetNumberOfArrays(); ++a) {
    vtkDataArray* array = data->GetArray(a);
    if (!array || !array->GetName() || array->GetNumberOfComponents() != 1 || array->GetNumberOfTuples() != n) continue;
    std::vector<double>& v = c.pointScalars[array->GetName()];
    v.resize(static_cast<size_t>(n));
    for (vtkIdType i = 0; i < n; ++i) v[static_cast<size_t>(i)] = array->GetComponent(i, 0);
  }
  return c;
}

Ptr<vtkPolyData> toVtk(const PolyDataCells& c) {
  auto points = Ptr<vtkPoints>::New();
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(c.mesh.positions.size()));
  for (size_t i = 0; i < c.mesh.positions.size(); ++i)
    points->SetPoint(static_cast<vtkIdType>(i), c.mesh.positions[i].data());
  auto polys = Ptr<vtkCellArray>::New();
  for (const auto& t : c.mesh.triangles) {
    const vtkIdType ids[3] = {t[0], t[1], t[2]};
    polys->InsertNextCell(3, ids);
  }
  auto lines = Ptr<vtkCellArray>::New();
  for (const auto& l : c.lines) {
    const std::vector<vtkIdType> ids(l.begin(), l.end());
    lines->InsertNextCell(static_cast<vtkIdType>(ids.size()), ids.data());
  }
  auto pd = Ptr<vtkPolyData>::New();
  pd->SetPoints(points);
  pd->SetPolys(polys);  // empty cell arrays are not written
  pd->SetLines(lines);
  auto array = [](const std::string& name, const std::vector<double>& values, int components) {
    auto a = Ptr<vtkDoubleArray>::New();
    a->SetName(name.c_str());
    a->SetNumberOfComponents(components);
    a->SetNumberOfTuples(static_cast<vtkIdType>(values.size() / static_cast<size_t>(components)));
    for (size_t i = 0; i < values.size(); ++i) a->SetValue(static_cast<vtkIdType>(i), values[i]);
    return a;
  };
  if (!c.mesh.normals.empty()) {
    std::vector<double> v;
    for (const auto& n : c.mesh.normals) v.insert(v.end(), {n.x(), n.y(), n.z()});
    pd->GetPointData()->SetNormals(array("normals", v, 3));
  }
  for (const auto& [name, values] : c.pointScalars) pd->GetPointData()->AddArray(array(name, values, 1));
  return pd;
}

Ptr<vtkPolyData> loadXml(const std::string& path) {
  checkInputFile(path);
  auto reader = Ptr<vtkXMLPolyDataReader>::New();
  if (!reader->CanReadFile(path.c_str()))
    throw IoError(path + ": not a readable VTK XML PolyData file (not <VTKFile type=\"PolyData\">)");
  VtkMessages messages(reader);
  reader->SetFileName(path.c_str());
  reader->Update();
  messages.check(path, "");
  return reader->GetOutput();
}

Ptr<vtkPolyData> loadStl(const std::string& path) {
  polydata_detail::checkStlSize(path, readTextFile(path));
  auto reader = Ptr<vtkSTLReader>::New();
  VtkMessages messages(reader);
  reader->SetFileName(path.c_str());
  reader->MergingOn();  // one point per distinct position, as the triangles share them
  reader->Update();
  messages.check(path, "");
  return reader->GetOutput();
}

void requirePolyDataExtension(const std::string& path, const std::string& ext) {
  if (ext != ".vtp" && ext != ".vtk" && ext != ".stl")
    throw InvalidArgument(path + ": VTK polygonal data must be .vtp, .vtk or .stl, not '" + ext + "'");
}

}  // namespace

PolyDataCells readPolyDataCells(const std::string& path) {
  silenceVtkOutputWindow();
  const std::string ext = fileExtension(path);
  requirePolyDataExtension(path, ext);
  try {
    if (ext == ".vtk") return polydata_detail::readLegacyVtk(path, readTextFile(path));
    const Ptr<vtkPolyData> pd = ext == ".vtp" ? loadXml(path) : loadStl(path);
    if (!pd || !pd->GetPoints()) {
      if (pd && pd->GetNumberOfCells() == 0) return {};  // a file with no point and no cell
      throw IoError(path + ": VTK read no polygonal data");
    }
    return cellsOf(pd, path);
  } catch (const std::logic_error& e) {  // std::stoll & co. on a malformed legacy header field
    throw IoError(path + ": malformed file (" + std::string(e.what()) + ")");
  } catch (const std::bad_alloc&) {
    throw IoError(path + ": out of memory while reading");
  }
}

void writePolyDataCells(const PolyDataCells& cells, const std::string& path, const PolyDataWriteOptions& options) {
  silenceVtkOutputWindow();
  const std::string ext = fileExtension(path);
  requirePolyDataExtension(path, ext);
  const Ptr<vtkPolyData> pd = toVtk(cells);
  std::string bytes;
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
    messages.check(path, "VTK could not write the file: ");
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
    messages.check(path, "VTK could not write the file: ");
    bytes.assign(writer->GetOutputString(), static_cast<size_t>(writer->GetOutputStringLength()));
  } else {  // .stl: VTK's writer writes a file only, so into the atomic write's temporary
    writeAtomically(path, [&](const std::string& tmp) {
      auto writer = Ptr<vtkSTLWriter>::New();
      VtkMessages messages(writer);
      writer->SetInputData(pd);
      writer->SetFileName(tmp.c_str());
      writer->SetHeader("volscissors STL (world mm)");
      if (options.binary)
        writer->SetFileTypeToBinary();
      else
        writer->SetFileTypeToASCII();
      writer->Write();
      messages.check(path, "VTK could not write the file: ");
    });
    return;
  }
  if (bytes.empty()) throw IoError(path + ": VTK could not write the file");
  writeFileAtomically(path, bytes);
}

void appendPolylineCells(const std::vector<Polyline>& lines, PolyDataCells& cells) {
  bool allRadii = !lines.empty();
  for (const auto& l : lines) allRadii = allRadii && !l.points.empty() && l.radii.size() == l.points.size();
  std::vector<double>* radius = nullptr;
  if (allRadii) {
    radius = &cells.pointScalars["radius"];
    radius->resize(cells.mesh.positions.size(), 0.0);
  }
  for (const auto& l : lines) {
    std::vector<int32_t> ids;
    for (size_t k = 0; k < l.points.size(); ++k) {
      ids.push_back(static_cast<int32_t>(cells.mesh.positions.size()));
      cells.mesh.positions.push_back(l.points[k]);
      if (radius) radius->push_back(l.radii[k]);
    }
    if (l.closed && ids.size() > 2) ids.push_back(ids.front());
    cells.lines.push_back(std::move(ids));
  }
  if (!cells.mesh.normals.empty()) cells.mesh.normals.resize(cells.mesh.positions.size(), Eigen::Vector3d::Zero());
}

PolyDataContent readPolyDataFile(const std::string& path) {
  PolyDataCells cells = readPolyDataCells(path);
  PolyDataContent c;
  const auto radius = cells.pointScalars.find("radius");
  for (const auto& ids : cells.lines) {
    Polyline line;
    for (int32_t id : ids) {
      line.points.push_back(cells.mesh.positions[static_cast<size_t>(id)]);
      if (radius != cells.pointScalars.end()) line.radii.push_back(radius->second[static_cast<size_t>(id)]);
    }
    // A loop stored with its first point repeated at the end is a closed polyline.
    if (ids.size() > 3 && ids.front() == ids.back()) {
      line.closed = true;
      line.points.pop_back();
      if (!line.radii.empty()) line.radii.pop_back();
    }
    c.lines.push_back(std::move(line));
  }
  if (!cells.mesh.triangles.empty()) c.mesh = std::move(cells.mesh);  // else: the points of the lines only
  return c;
}

void writePolyDataFile(const PolyDataContent& content, const std::string& path, const PolyDataWriteOptions& options) {
  PolyDataCells cells;
  cells.mesh = content.mesh;
  appendPolylineCells(content.lines, cells);
  writePolyDataCells(cells, path, options);
}

}  // namespace vs
