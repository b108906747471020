// `volscissors render VOLUME --out image.png`: volume rendering (thesis 1.1, ch. 5 display
// modes) on the CPU, no GPU or display needed. The core (src/render) renders into an
// RgbaImage; this file only parses, loads files (volume, TF JSON, overlays, labels) and saves.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "command.h"
#include "io/mesh_io.h"
#include "io/png_io.h"
#include "io/volume_io.h"
#include "render/renderer.h"
#include "render/slice_render.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/parallel.h"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::vector<double> parseNumbers(const std::string& s, const std::string& what, size_t n1, size_t n2 = 0) {
  std::vector<double> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t used = 0;
      const double v = std::stod(item, &used);
      if (used != item.size() || !std::isfinite(v)) throw std::invalid_argument(item);
      out.push_back(v);
    } catch (const std::exception&) {
      throw vs::UsageError(what + ": '" + s + "' is not a comma-separated list of numbers");
    }
  }
  if (out.size() != n1 && (n2 == 0 || out.size() != n2))
    throw vs::UsageError(what + ": expected " + std::to_string(n1) + (n2 ? " or " + std::to_string(n2) : "") +
                         " comma-separated numbers, got '" + s + "'");
  return out;
}

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw vs::IoError(path + ": cannot open file");
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

std::string frameName(const std::string& out, int i) {
  const std::string ext = vs::fileExtension(out);
  const std::string stem = out.substr(0, out.size() - ext.size());
  char buf[16];
  std::snprintf(buf, sizeof buf, "_%03d", i);
  return stem + buf + (ext.empty() ? ".png" : ext);
}

const std::array<float, 3> kOverlayColors[] = {
    {1.0f, 0.25f, 0.2f}, {0.2f, 1.0f, 0.3f}, {0.2f, 0.8f, 1.0f}, {1.0f, 0.9f, 0.2f}, {1.0f, 0.4f, 1.0f}};

struct LoadedOverlay {
  vs::TriMesh mesh;
  std::vector<vs::Polyline> lines;
};

vs::Polyline indexPolyline(const nlohmann::json& pts, const vs::Geometry& g, const std::string& where, bool closed) {
  vs::Polyline pl;
  pl.closed = closed;
  if (!pts.is_array()) throw vs::IoError(where + ": expected an array of [x,y,z] points");
  for (const auto& p : pts) {
    if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() || !p[2].is_number())
      throw vs::IoError(where + ": expected [x,y,z] voxel index points");
    pl.points.push_back(g.indexToWorld(vs::Vec3(p[0].get<double>(), p[1].get<double>(), p[2].get<double>())));
  }
  return pl;
}

// Overlays by extension; JSON by content: tracking report {"paths":[{"voxels":[[x,y,z]..]}]}
// and live-wire contours {"points_index":[[x,y,z]..]} or {"points":[[u,v]..], "slice": "z=40" |
// {"axis":2,"index":40}} are in voxel index coordinates; tree {"nodes"} and {"polylines"} files
// are world mm (read by the I/O module).
LoadedOverlay loadOverlay(const std::string& path, const vs::Geometry& g) {
  LoadedOverlay o;
  const std::string ext = vs::fileExtension(path);
  if (ext == ".obj" || ext == ".ply" || ext == ".stl") {
    o.mesh = vs::readTriMesh(path);
  } else if (ext == ".swc") {
    o.lines = vs::readTree(path).toPolylines();
  } else if (ext == ".vtk") {
    o.mesh = vs::readTriMesh(path);
    if (o.mesh.empty()) o.lines = vs::readPolylines(path);
  } else if (ext == ".json") {
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(readText(path));
    } catch (const nlohmann::json::exception& e) {
      throw vs::IoError(path + ": malformed JSON: " + e.what());
    }
    if (j.contains("paths")) {
      if (!j["paths"].is_array()) throw vs::IoError(path + ": \"paths\" must be an array");
      size_t i = 0;
      for (const auto& p : j["paths"]) {
        const std::string where = path + ": paths[" + std::to_string(i++) + "]";
        if (!p.is_object() || !p.contains("voxels")) throw vs::IoError(where + ": needs \"voxels\"");
        o.lines.push_back(indexPolyline(p["voxels"], g, where, false));
      }
    } else if (j.contains("points_index")) {
      o.lines.push_back(indexPolyline(j["points_index"], g, path, j.value("closed", true)));
    } else if (j.contains("points") && j.contains("slice")) {
      int axis = 2;
      int64_t index = 0;
      if (j["slice"].is_string()) {
        std::tie(axis, index) = vs::parseSliceSpec(j["slice"].get<std::string>());
      } else if (j["slice"].is_object() && j["slice"].contains("axis") && j["slice"].contains("index")) {
        axis = j["slice"]["axis"].get<int>();
        index = j["slice"]["index"].get<int64_t>();
      } else {
        throw vs::IoError(path + ": \"slice\" must be \"z=40\" or {\"axis\": 2, \"index\": 40}");
      }
      if (axis < 0 || axis > 2) throw vs::IoError(path + ": slice axis must be 0, 1 or 2");
      const int ua = axis == 0 ? 1 : 0, va = axis == 2 ? 1 : 2;  // SliceView convention
      nlohmann::json pts = nlohmann::json::array();
      for (const auto& p : j["points"]) {
        if (!p.is_array() || p.size() < 2) throw vs::IoError(path + ": \"points\" must be [u,v] pairs");
        if (p.size() == 3) {
          pts.push_back(p);
          continue;
        }
        double c[3];
        c[axis] = double(index);
        c[ua] = p[0].get<double>();
        c[va] = p[1].get<double>();
        pts.push_back({c[0], c[1], c[2]});
      }
      o.lines.push_back(indexPolyline(pts, g, path, j.value("closed", true)));
    } else if (j.contains("nodes")) {
      o.lines = vs::readTree(path).toPolylines();
    } else if (j.contains("polylines")) {
      o.lines = vs::readPolylines(path);
    } else {
      throw vs::IoError(path + ": unknown overlay JSON (expected \"paths\", \"points_index\", \"points\"+\"slice\", "
                                "\"nodes\" or \"polylines\")");
    }
  } else {
    throw vs::UsageError("--overlay " + path + ": unsupported file type '" + ext +
                         "' (use .obj .ply .stl .vtk meshes, .swc trees, or .json paths/contours/trees)");
  }
  // Warn when the overlay is not where the volume is (another coordinate frame?).
  int64_t total = 0, outside = 0;
  auto test = [&](const vs::Vec3& w) {
    const vs::Vec3 i = g.worldToIndex(w);
    ++total;
    for (int a = 0; a < 3; ++a)
      if (i[a] < -1 || i[a] > double(g.dims[static_cast<size_t>(a)])) {
        ++outside;
        break;
      }
  };
  for (const auto& p : o.mesh.positions) test(p);
  for (const auto& l : o.lines)
    for (const auto& p : l.points) test(p);
  if (total == 0) std::cerr << "volscissors: warning: overlay " << path << " is empty\n";
  else if (outside > 0)
    std::cerr << "volscissors: warning: overlay " << path << ": " << outside << " of " << total
              << " points lie outside the volume bounds (another coordinate frame? overlays are world mm, "
                 "JSON paths/contours voxel index)\n";
  return o;
}

vs::cli::Runner setup(CLI::App& sub) {
  struct Opts {
    std::string volume, mode = "full", tf = "auto", view = "0,0", box, planes, plane, window, labels, size = "512x512",
                out, json, camera, lighting;
    std::vector<std::string> overlays;
    double zoom = 1.0, step = 0.5, overlayRadius = 0, fov = 30;
    bool perspective = false, noShading = false, noSkip = false, world = false, mipTf = false;
    int turntable = 0, repeat = 0;
  };
  auto o = std::make_shared<Opts>();
  sub.add_option("volume", o->volume, "volume file or DICOM folder")->required();
  sub.add_option("--mode", o->mode, "full | cutbox | triplanar | monoplanar | mip | slice (default full)");
  sub.add_option("--tf", o->tf,
                 "transfer function: preset (auto, ct-skin, ct-bone, ct-lung, ct-angio, mri, vessels) or JSON file "
                 "{\"points\":[{\"value\":v,\"color\":[r,g,b],\"opacity\":a},...]} (default auto)");
  sub.add_option("--view", o->view, "AZ,EL camera azimuth and elevation in degrees (default 0,0: from anterior, -y)");
  sub.add_option("--zoom", o->zoom, "zoom factor, 1 fits the whole volume (default 1)");
  sub.add_flag("--perspective", o->perspective, "perspective projection (default orthographic)");
  sub.add_option("--camera", o->camera, "explicit camera ex,ey,ez,tx,ty,tz,ux,uy,uz (eye, look-at, up; world mm)");
  sub.add_option("--fov", o->fov, "vertical field of view in degrees with --camera --perspective (default 30)");
  sub.add_option("--box", o->box, "cutbox: x0,y0,z0,x1,y1,z1 (voxel index, or mm with --world)");
  sub.add_option("--planes", o->planes, "triplanar: x,y,z plane positions (default the centre)");
  sub.add_option("--plane", o->plane, "monoplanar/slice: axis=index, e.g. z=40 (default the central axial slice)");
  sub.add_flag("--world", o->world, "--box/--planes/--plane are world mm instead of voxel index");
  sub.add_option("--window", o->window, "W,L grey window width and level for planes, faces, MIP and slices");
  sub.add_option("--overlay", o->overlays,
                 "overlay file (repeatable): mesh .obj/.ply/.stl/.vtk, tree .swc/.json, tracking report or "
                 "live-wire contour .json");
  sub.add_option("--overlay-radius", o->overlayRadius, "tube radius of line overlays in mm (default: file radii or 1.5 px)");
  sub.add_option("--labels", o->labels, "label volume (same dims), colours blended in");
  sub.add_option("--size", o->size, "WxH image size (default 512x512; slice: fit into this box), at most 8192x8192");
  sub.add_option("--step", o->step, "sample distance in units of the smallest spacing (default 0.5)");
  sub.add_flag("--no-shading", o->noShading, "no gradient shading");
  sub.add_option("--lighting", o->lighting,
                 "KA,KD,KS,POWER Blinn-Phong ambient, diffuse, specular coefficients (0..1) and specular power "
                 "(default 0.3,0.8,0.2,10; VTK's CPU ray caster with its default headlight acts as 0,KD,KS,POWER)");
  sub.add_flag("--no-skip", o->noSkip, "no empty-space skipping (for comparisons)");
  sub.add_flag("--mip-tf", o->mipTf, "mip: colour the maximum with the transfer function (colour x opacity, as VTK) instead of grey");
  sub.add_option("--turntable", o->turntable, "write N frames OUT_000.png... around the volume");
  sub.add_option("--repeat", o->repeat, "render the same frame N times after a warm-up and report timings");
  sub.add_option("--json", o->json, "timing/report JSON file");
  sub.add_option("--out", o->out, "output PNG");

  return [o] {
    if (o->out.empty() && o->repeat <= 0) throw vs::UsageError("--out is required (except with --repeat)");
    if (o->turntable < 0 || o->turntable > 3600) throw vs::UsageError("--turntable must be in 0..3600");
    if (o->repeat < 0 || o->repeat > 10000) throw vs::UsageError("--repeat must be in 0..10000");
    int W = 0, H = 0;
    {
      const auto x = o->size.find('x');
      try {
        if (x == std::string::npos) throw std::invalid_argument("x");
        size_t u1 = 0, u2 = 0;
        const std::string a = o->size.substr(0, x), b = o->size.substr(x + 1);
        W = std::stoi(a, &u1);
        H = std::stoi(b, &u2);
        if (u1 != a.size() || u2 != b.size()) throw std::invalid_argument("x");
      } catch (const std::exception&) {
        throw vs::UsageError("--size: expected WxH, e.g. 512x512, got '" + o->size + "'");
      }
      if (W < 1 || H < 1 || W > vs::Renderer::kMaxImageSide || H > vs::Renderer::kMaxImageSide)
        throw vs::UsageError("--size " + o->size + ": each side must be 1.." + std::to_string(vs::Renderer::kMaxImageSide));
    }
    const bool sliceMode = o->mode == "slice";
    vs::RenderOptions ro;
    if (!sliceMode) ro.mode = vs::renderModeFromName(o->mode);
    if (!o->out.empty()) vs::checkOutputPath(o->out);
    if (!o->json.empty()) vs::checkOutputPath(o->json);
    const auto view = parseNumbers(o->view, "--view", 2);
    if (!o->window.empty()) {
      const auto wl = parseNumbers(o->window, "--window", 2);
      if (!(wl[0] > 0)) throw vs::UsageError("--window: width must be > 0");
      ro.window = {wl[0], wl[1]};
    }

    const auto t0 = Clock::now();
    const vs::AnyVolume vol = vs::readVolume(o->volume);
    const vs::Geometry& g = vs::geometryOf(vol);
    std::unique_ptr<vs::AnyVolume> labels;
    if (!o->labels.empty()) labels = std::make_unique<vs::AnyVolume>(vs::readVolume(o->labels));

    auto toIndex = [&](const vs::Vec3& p) { return o->world ? g.worldToIndex(p) : p; };
    std::pair<int, double> plane{2, -1};
    if (!o->plane.empty()) {
      const auto spec = vs::parseSliceSpec(o->plane);
      plane = {spec.first, double(spec.second)};
      if (o->world) {
        vs::Vec3 c = g.indexToWorld(vs::Vec3(double(g.dims[0] - 1) / 2, double(g.dims[1] - 1) / 2, double(g.dims[2] - 1) / 2));
        c[plane.first] = plane.second;
        plane.second = std::round(g.worldToIndex(c)[plane.first]);
      }
    }

    std::vector<LoadedOverlay> overlays;
    for (const auto& f : o->overlays) overlays.push_back(loadOverlay(f, g));

    if (sliceMode) {
      const int axis = plane.first;
      const int64_t index = plane.second < 0 ? (g.dims[static_cast<size_t>(axis)] - 1) / 2 : int64_t(plane.second);
      if (index < 0 || index >= g.dims[static_cast<size_t>(axis)])
        throw vs::UsageError("--plane: " + std::string(1, "xyz"[axis]) + "=" + std::to_string(index) +
                             " is outside the volume (0.." + std::to_string(g.dims[static_cast<size_t>(axis)] - 1) + ")");
      vs::SliceImageOptions so;
      so.window = ro.window;
      so.fitWidth = W;
      so.fitHeight = H;
      std::vector<vs::Polyline> lines;
      for (const auto& ov : overlays) lines.insert(lines.end(), ov.lines.begin(), ov.lines.end());
      const vs::RgbaImage img = vs::renderSlice(vol, axis, index, so, labels.get(), lines.empty() ? nullptr : &lines);
      if (!o->out.empty()) vs::writePng(img, o->out);
      vs::cli::note("render: slice " + std::string(1, "xyz"[axis]) + "=" + std::to_string(index) + " -> " + o->out +
                    " (" + std::to_string(img.width) + "x" + std::to_string(img.height) + ")");
      return 0;
    }

    vs::TransferFunction tf;
    {
      const std::string ext = vs::fileExtension(o->tf);
      if (ext == ".json") tf = vs::TransferFunction::fromJson(readText(o->tf), o->tf);
      else tf = vs::TransferFunction::preset(o->tf, vs::valueRange(vol));
    }
    vs::Renderer ren(vol);
    const double loadS = since(t0);

    ro.sampleStep = o->step;
    ro.shading = !o->noShading;
    if (!o->lighting.empty()) {
      const auto l = parseNumbers(o->lighting, "--lighting", 4);
      ro.ambient = l[0], ro.diffuse = l[1], ro.specular = l[2], ro.specularPower = l[3];
    }
    ro.emptySpaceSkipping = !o->noSkip;
    ro.mipTransferFunction = o->mipTf;
    if (!o->box.empty()) {
      const auto b = parseNumbers(o->box, "--box", 6);
      const vs::Vec3 a = toIndex(vs::Vec3(b[0], b[1], b[2])), c = toIndex(vs::Vec3(b[3], b[4], b[5]));
      ro.box = {std::min(a.x(), c.x()), std::min(a.y(), c.y()), std::min(a.z(), c.z()),
                std::max(a.x(), c.x()), std::max(a.y(), c.y()), std::max(a.z(), c.z())};
      if (!o->world) ro.box = {b[0], b[1], b[2], b[3], b[4], b[5]};
    } else if (ro.mode == vs::RenderMode::CutBox) {
      // Default cut box: the central half of the volume.
      for (int a = 0; a < 3; ++a) {
        const double n = double(g.dims[static_cast<size_t>(a)] - 1);
        ro.box[static_cast<size_t>(a)] = std::round(n * 0.25);
        ro.box[static_cast<size_t>(a) + 3] = std::round(n * 0.75);
      }
    }
    if (!o->planes.empty()) {
      const auto p = parseNumbers(o->planes, "--planes", 3);
      ro.planes = toIndex(vs::Vec3(p[0], p[1], p[2]));
    }
    ro.planeAxis = plane.first;
    ro.planeIndex = plane.second;
    ren.setOptions(ro);
    ren.setTransferFunction(tf);
    if (labels) ren.setLabels(*labels);
    for (size_t i = 0; i < overlays.size(); ++i) {
      const auto& col = kOverlayColors[i % 5];
      if (!overlays[i].mesh.empty()) ren.addMesh(overlays[i].mesh, col);
      if (!overlays[i].lines.empty()) ren.addPolylines(overlays[i].lines, col, o->overlayRadius);
    }

    auto makeCamera = [&](double az) {
      if (!o->camera.empty()) {
        const auto c = parseNumbers(o->camera, "--camera", 9);
        vs::Camera cam;
        cam.eye = vs::Vec3(c[0], c[1], c[2]);
        cam.target = vs::Vec3(c[3], c[4], c[5]);
        cam.up = vs::Vec3(c[6], c[7], c[8]);
        cam.perspective = o->perspective;
        cam.fovDeg = o->fov / o->zoom;
        if (!cam.perspective) {
          const vs::Camera fit = vs::orbitCamera(g, 0, 0, o->zoom, false);
          cam.orthoHeight = fit.orthoHeight;
        }
        cam.validate();
        return cam;
      }
      return vs::orbitCamera(g, az, view[1], o->zoom, o->perspective);
    };

    const auto tp = Clock::now();
    ren.prepare();
    const double prepareS = since(tp);

    nlohmann::json report;
    if (o->turntable > 0) {
      if (o->out.empty()) throw vs::UsageError("--turntable needs --out");
      vs::OutputSet frames;  // the whole turntable or no frame at all
      for (int i = 0; i < o->turntable; ++i) {
        const auto res = ren.render(makeCamera(view[0] + 360.0 * i / o->turntable), W, H);
        frames.write(frameName(o->out, i), [&](const std::string& t) { vs::writePng(res.image, t); });
      }
      frames.commit();
      vs::cli::note("render: " + std::to_string(o->turntable) + " frames -> " + frameName(o->out, 0) + " ...");
    } else {
      const vs::Camera cam = makeCamera(view[0]);
      std::vector<double> frames;
      auto tf0 = Clock::now();
      vs::RenderResult res = ren.render(cam, W, H);
      const double first = since(tf0);
      for (int i = 0; i < o->repeat; ++i) {
        tf0 = Clock::now();
        res = ren.render(cam, W, H);
        frames.push_back(since(tf0));
      }
      if (!o->out.empty()) vs::writePng(res.image, o->out);
      std::vector<double> sorted = frames;
      std::sort(sorted.begin(), sorted.end());
      const double median = sorted.empty() ? first : sorted[sorted.size() / 2];
      report["seconds"] = {{"load", loadS}, {"prepare", prepareS}, {"first_frame", first}, {"frame_median", median},
                           {"frames", frames}};
      report["fps"] = median > 0 ? 1.0 / median : 0.0;
      report["samples"] = res.samples;
      const double frac = ren.overlayFractionOutside();
      if (frac > 0) report["overlay_fraction_outside"] = frac;
      vs::cli::note("render: " + renderModeName(ro.mode) + " " + std::to_string(W) + "x" + std::to_string(H) +
                    (o->out.empty() ? "" : " -> " + o->out) +
                    (o->repeat > 0 ? ", median frame " + std::to_string(median * 1000) + " ms" : ""));
    }
    if (!o->json.empty()) {
      report["image"] = {W, H};
      report["threads"] = vs::workerCount();
      report["mode"] = o->mode;
      report["volume"] = o->volume;
      report["dims"] = {g.dims[0], g.dims[1], g.dims[2]};
      vs::writeFileAtomically(o->json, report.dump(2) + "\n");
    }
    return 0;
  };
}

const vs::cli::Registration reg{"render", "volume rendering to PNG (full, cutbox, triplanar, monoplanar, MIP, slice)", setup};

}  // namespace
