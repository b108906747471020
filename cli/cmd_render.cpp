// `volscissors render VOLUME --out image.png`: volume rendering (thesis 1.1, ch. 5 display
// modes) on the CPU, no GPU or display needed. The core (src/render) renders into an
// RgbaImage; this file only parses, loads files (volume, TF JSON, overlays, labels) and saves.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "args.h"
#include "command.h"
#include "io/overlay_io.h"
#include "io/png_io.h"
#include "io/volume_io.h"
#include "io/zarr_io.h"
#include "progress_line.h"
#include "render/colour_legend.h"
#include "render/renderer.h"
#include "render/slice_render.h"
#include "render/view_defaults.h"
#include "util/atomic_file.h"
#include "util/error.h"
#include "util/parallel.h"
#include "volume/slice.h"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); }

std::string frameName(const std::string& out, int i) {
  const std::string ext = vs::fileExtension(out);
  const std::string stem = out.substr(0, out.size() - ext.size());
  char buf[16];
  std::snprintf(buf, sizeof buf, "_%03d", i);
  return stem + buf + (ext.empty() ? ".png" : ext);
}

nlohmann::json rgb255(const std::array<float, 3>& c) {
  return {std::lround(c[0] * 255), std::lround(c[1] * 255), std::lround(c[2] * 255)};
}

vs::Overlay loadOverlay(const std::string& path, const vs::Geometry& g) {
  vs::Overlay o = vs::readOverlay(path, g);
  if (o.empty()) throw vs::DataError("overlay " + path + " is empty (nothing to draw)");
  if (o.pointsOutside > 0)
    vs::cli::warn("overlay " + path + ": " + std::to_string(o.pointsOutside) + " of " + std::to_string(o.points) +
                  " points lie outside the volume bounds (another coordinate frame? overlays are world mm, "
                  "JSON paths/contours voxel index)");
  return o;
}

std::string num(double v) {
  std::ostringstream os;
  os << v;
  return os.str();
}

struct Opts {
  std::string colorBy = "none";
  std::string volume, mode = "full", tf = "auto", view, box, planes, plane, window, labels, size = "512x512", out, json,
                      camera, lighting, orientation;
  std::vector<std::string> overlays;
  double zoom = 1.0, step = 0.5, overlayRadius = 0, fov = 30;
  bool perspective = false, noShading = false, noSkip = false, world = false, mipTf = false;
  bool voxelPixels = false, ticks = false, letters = false;
  int turntable = 0, repeat = 0;
};

// The command line, with the core's defaults shown in --help.
void addOptions(CLI::App& sub, Opts& o) {
  const vs::OrbitView defaultView;
  const vs::RenderOptions defaults;
  o.view = num(defaultView.azimuthDeg) + "," + num(defaultView.elevationDeg);
  o.step = defaults.sampleStep;
  sub.add_option("volume", o.volume, "volume file or DICOM folder")->required();
  sub.add_option("--mode", o.mode, "full | cutbox | triplanar | monoplanar | mip | slice")->capture_default_str();
  sub.add_option("--tf", o.tf,
                 "transfer function: preset (auto, ct-skin, ct-bone, ct-lung, ct-angio, mri, vessels) or JSON file "
                 "{\"points\":[{\"value\":v,\"color\":[r,g,b],\"opacity\":a},...]}")
      ->capture_default_str();
  sub.add_option("--view", o.view,
                 "AZ,EL camera azimuth and elevation in degrees; 0,0 looks from anterior (-y) with superior up, AZ "
                 "turns towards the patient's left (+x), EL raises the eye")
      ->capture_default_str();
  sub.add_option("--zoom", o.zoom, "zoom factor, 1 fits the whole volume")->capture_default_str();
  sub.add_flag("--perspective", o.perspective, "perspective projection (default orthographic)");
  sub.add_option("--camera", o.camera, "explicit camera ex,ey,ez,tx,ty,tz,ux,uy,uz (eye, look-at, up; world mm)");
  sub.add_option("--fov", o.fov, "vertical field of view in degrees with --camera --perspective")
      ->capture_default_str();
  sub.add_option("--box", o.box,
                 "cutbox: x0,y0,z0,x1,y1,z1 (voxel index, or mm with --world; default the central half)");
  sub.add_option("--planes", o.planes, "triplanar: x,y,z plane positions (default the centre)");
  sub.add_option(
      "--plane", o.plane,
      "monoplanar/slice: AXIS=INDEX of an index axis, e.g. z=40 (default the central slice of the index axis "
      "that runs closest to superior-inferior, i.e. the axial one)");
  sub.add_flag("--world", o.world, "--box/--planes/--plane are world mm instead of voxel index");
  sub.add_option("--window", o.window,
                 "W,L grey window width and level for planes, faces, MIP and slices (default: 1st..99.5th percentile; "
                 "of the slice itself for an OME-Zarr slice)");
  sub.add_option("--overlay", o.overlays,
                 "overlay file (repeatable; colours cycle red, green, cyan, yellow, magenta, listed in the --json "
                 "legend): mesh .obj/.ply/.stl/.vtk/.vtp, tree .swc/.json, tracking report or live-wire contour .json");
  sub.add_option("--overlay-radius", o.overlayRadius,
                 "tube radius of line overlays in mm (default: file radii or 1.5 px)");
  sub.add_option("--color-by", o.colorBy,
                 "none | diameter: line overlays with radii (a measured tree: `measure --out`) coloured by diameter, "
                 "with a colour bar")
      ->capture_default_str()
      ->check(CLI::IsMember({"none", "diameter"}));
  sub.add_option("--labels", o.labels, "label volume (same dims), colours blended in");
  sub.add_option("--orientation", o.orientation,
                 "where the volume's axes point when its header does not say, e.g. LAS (x to patient left, y "
                 "anterior, z superior); default: the header's, else LPS with a warning")
      ->check([](const std::string& code) {
        try {
          vs::directionFromOrientationCode(code);
          return std::string();
        } catch (const vs::InvalidArgument& e) {
          return std::string(e.what());
        }
      });
  sub.add_option("--size", o.size, "WxH image size (slice: fit into this box keeping the aspect), at most 8192x8192")
      ->capture_default_str();
  sub.add_flag("--voxel-pixels", o.voxelPixels,
               "slice: one picture pixel per voxel (ignores --size), so a pixel's column and row are voxel indices "
               "(the mapping is in the --json report; `livewire --picture` takes these pixels)");
  sub.add_flag("--ticks", o.ticks, "slice: index ticks on the top and left edges every 10 voxels (longer every 50)");
  sub.add_flag("--letters", o.letters, "slice: anatomical orientation letters (R/L, A/P, S/I) at the edges");
  sub.add_option("--step", o.step, "sample distance in units of the smallest spacing")->capture_default_str();
  sub.add_flag("--no-shading", o.noShading, "no gradient shading");
  sub.add_option("--lighting", o.lighting,
                 "KA,KD,KS,POWER Blinn-Phong ambient, diffuse, specular coefficients (0..1) and specular power "
                 "(default " +
                     num(defaults.ambient) + "," + num(defaults.diffuse) + "," + num(defaults.specular) + "," +
                     num(defaults.specularPower) +
                     "; VTK's CPU ray caster with its default headlight acts as 0,KD,KS,POWER)");
  sub.add_flag("--no-skip", o.noSkip, "no empty-space skipping (for comparisons)");
  sub.add_flag("--mip-tf", o.mipTf,
               "mip: colour the maximum with the transfer function (colour x opacity, as VTK) instead of grey");
  sub.add_option("--turntable", o.turntable, "write N frames OUT_000.png... around the volume");
  sub.add_option("--repeat", o.repeat, "render the same frame N times after a warm-up and report timings");
  sub.add_option("--json", o.json, "report JSON: timings, overlay legend, and for slices the picture -> voxel mapping");
  sub.add_option("--out", o.out, "output picture (.png)");
}

// --plane as (axis, index); index -1: the default (central) slice of `defaultAxis`.
std::pair<int, double> planeOption(const Opts& o, const vs::Geometry& g, int defaultAxis) {
  std::pair<int, double> plane{defaultAxis, -1};
  if (o.plane.empty()) return plane;
  const auto spec = vs::parseSliceSpec(o.plane);
  plane = {spec.first, double(spec.second)};
  if (o.world) {
    vs::Vec3 c =
        g.indexToWorld(vs::Vec3(double(g.dims[0] - 1) / 2, double(g.dims[1] - 1) / 2, double(g.dims[2] - 1) / 2));
    c[plane.first] = plane.second;
    plane.second = std::round(g.worldToIndex(c)[plane.first]);
  }
  // An explicit plane must exist (a negative one would read as "the default").
  const int64_t n = g.dims[static_cast<size_t>(plane.first)];
  if (!(plane.second >= 0 && plane.second <= double(n - 1)))
    throw vs::UsageError("--plane " + o.plane + (o.world ? " (world mm, index " + num(plane.second) + ")" : "") +
                         " is outside the volume (" + std::string(1, "xyz"[plane.first]) + " 0.." +
                         std::to_string(n - 1) + ")");
  return plane;
}

// The overlays with their legend; with --color-by diameter, every line overlay split into pieces
// coloured by the tree's diameter.
struct Overlays {
  std::vector<vs::Overlay> list;
  nlohmann::json legend = nlohmann::json::array();
  std::optional<vs::ColouredPieces> byDiameter;
  void addLegend(vs::RgbaImage& img) const {
    if (byDiameter) vs::drawColourLegend(img, byDiameter->loMm, byDiameter->hiMm);
  }
};

Overlays loadOverlays(const Opts& o, const vs::Geometry& g) {
  Overlays ov;
  for (size_t i = 0; i < o.overlays.size(); ++i) {
    ov.list.push_back(loadOverlay(o.overlays[i], g));
    ov.legend.push_back({{"file", o.overlays[i]}, {"color", rgb255(vs::overlayPaletteColor(i))}});
  }
  if (o.colorBy == "diameter") {
    std::vector<vs::Polyline> all;
    for (auto& one : ov.list) {
      all.insert(all.end(), one.lines.begin(), one.lines.end());
      one.lines.clear();
    }
    if (all.empty()) throw vs::UsageError("--color-by diameter needs a line overlay (a tree with radii)");
    try {
      ov.byDiameter = vs::colourByDiameter(all);
    } catch (const vs::InvalidArgument& e) {
      throw vs::DataError(e.what());
    }
  }
  return ov;
}

// The --json report: what every mode reports, plus each mode's own figures.
struct Report {
  const Opts& o;
  const vs::Geometry& g;
  nlohmann::json common;
  void write(const nlohmann::json& extra, vs::OutputSet* with = nullptr) const {
    if (o.json.empty()) return;
    nlohmann::json r = common;
    r.update(extra);
    r["mode"] = o.mode;
    r["volume"] = o.volume;
    r["dims"] = {g.dims[0], g.dims[1], g.dims[2]};
    r["orientation"] = vs::orientationCode(g);
    if (with)  // in the same all-or-nothing set as the frames
      with->writeBytes(o.json, r.dump(2) + "\n");
    else
      vs::writeFileAtomically(o.json, r.dump(2) + "\n");
  }
};

// --mode slice: one slice as a picture, its picture -> voxel mapping in the report.
// slabIndex >= 0: `vol` is that one slice of the volume (readBox), rendered as its slice 0.
int renderSlicePicture(const Opts& o, const vs::AnyVolume& vol, const vs::AnyVolume* labels,
                       std::pair<int, double> plane, const Overlays& ov, const vs::WindowLevel& window, int W, int H,
                       const Report& report, int64_t slabIndex = -1) {
  const vs::Geometry& g = vs::geometryOf(vol);
  const int axis = plane.first;
  const int64_t n = g.dims[static_cast<size_t>(axis)];
  const int64_t index = slabIndex >= 0 ? 0 : plane.second < 0 ? (n - 1) / 2 : int64_t(plane.second);
  const int64_t shown = slabIndex >= 0 ? slabIndex : index;
  vs::SliceImageOptions so;
  so.window = window;
  so.fitWidth = W;
  so.fitHeight = H;
  so.pixelPerVoxel = o.voxelPixels;
  so.indexTicks = o.ticks;
  so.orientationLetters = o.letters;
  std::vector<vs::Polyline> lines;
  for (size_t i = 0; i < ov.list.size(); ++i) {
    lines.insert(lines.end(), ov.list[i].lines.begin(), ov.list[i].lines.end());
    so.polylineColors.resize(lines.size(), vs::overlayPaletteColor(i));
  }
  if (ov.byDiameter) {
    lines.insert(lines.end(), ov.byDiameter->pieces.begin(), ov.byDiameter->pieces.end());
    so.polylineColors.insert(so.polylineColors.end(), ov.byDiameter->colours.begin(), ov.byDiameter->colours.end());
  }
  for (size_t i = 0; i < ov.list.size(); ++i) {
    if (!ov.list[i].mesh.empty())
      vs::cli::warn("overlay " + o.overlays[i] + " is a surface mesh: slice pictures draw line overlays only");
  }
  vs::SlicePicture pic = vs::slicePicture(g, axis, index, so);
  pic.indexAtOrigin[axis] += double(shown - index);
  vs::RgbaImage img = vs::renderSlice(vol, axis, index, so, labels, lines.empty() ? nullptr : &lines);
  ov.addLegend(img);
  if (!o.out.empty()) vs::writePng(img, o.out);
  const vs::SliceFrame& f = pic.frame;
  auto vec = [](const vs::Vec3& v) { return nlohmann::json{v.x(), v.y(), v.z()}; };
  report.write(
      {{"image", {img.width, img.height}},
       {"slice",
        {{"axis", std::string(1, "xyz"[axis])}, {"index", shown}, {"plane", vs::anatomicalPlaneName(f.plane)}}},
       {"edges",
        {{"left", std::string(1, f.edgeLetters[0])},
         {"right", std::string(1, f.edgeLetters[1])},
         {"top", std::string(1, f.edgeLetters[2])},
         {"bottom", std::string(1, f.edgeLetters[3])}}},
       {"pixel_to_index",
        {{"about",
          "voxel index (x,y,z) of the centre of picture pixel (col,row), 0-based: "
          "origin + col * per_column + row * per_row"},
         {"origin", vec(pic.indexAtOrigin)},
         {"per_column", vec(pic.indexPerColumn)},
         {"per_row", vec(pic.indexPerRow)}}}});
  vs::cli::note("render: " + vs::anatomicalPlaneName(f.plane) + " slice " + vs::sliceName(axis, shown) + " -> " +
                o.out + " (" + std::to_string(img.width) + "x" + std::to_string(img.height) + ", left " +
                f.edgeLetters[0] + ", top " + f.edgeLetters[2] + ")");
  return 0;
}

// The render options of the command line (step, shading, lighting, skipping, box, planes, plane).
void setRenderOptions(const Opts& o, const vs::Geometry& g, std::pair<int, double> plane, vs::RenderOptions& ro) {
  auto toIndex = [&](const vs::Vec3& p) { return o.world ? g.worldToIndex(p) : p; };
  ro.sampleStep = o.step;
  ro.shading = !o.noShading;
  if (!o.lighting.empty()) {
    const auto l = vs::cli::parseNumbers(o.lighting, "--lighting", 4);
    ro.ambient = l[0], ro.diffuse = l[1], ro.specular = l[2], ro.specularPower = l[3];
  }
  ro.emptySpaceSkipping = !o.noSkip;
  ro.mipTransferFunction = o.mipTf;
  if (!o.box.empty()) {
    const auto b = vs::cli::parseNumbers(o.box, "--box", 6);
    const vs::Vec3 a = toIndex(vs::Vec3(b[0], b[1], b[2])), c = toIndex(vs::Vec3(b[3], b[4], b[5]));
    ro.box = {std::min(a.x(), c.x()), std::min(a.y(), c.y()), std::min(a.z(), c.z()),
              std::max(a.x(), c.x()), std::max(a.y(), c.y()), std::max(a.z(), c.z())};
    if (!o.world) ro.box = {b[0], b[1], b[2], b[3], b[4], b[5]};
  }
  if (!o.planes.empty()) ro.planes = toIndex(vs::cli::parseVec3(o.planes, "--planes"));
  ro.planeAxis = plane.first;
  ro.planeIndex = plane.second;
}

// The overlays (and the diameter-coloured pieces) drawn into the rendering.
void addOverlays(vs::Renderer& ren, const Overlays& ov, double radius) {
  for (size_t i = 0; i < ov.list.size(); ++i) {
    const auto col = vs::overlayPaletteColor(i);
    if (!ov.list[i].mesh.empty()) ren.addMesh(ov.list[i].mesh, col);
    if (!ov.list[i].lines.empty()) ren.addPolylines(ov.list[i].lines, col, radius);
  }
  if (ov.byDiameter)
    for (size_t k = 0; k < ov.byDiameter->pieces.size(); ++k)
      ren.addPolylines({ov.byDiameter->pieces[k]}, ov.byDiameter->colours[k], radius);
}

// --camera as given, or the orbit camera at azimuth az and elevation el.
vs::Camera makeCamera(const Opts& o, const vs::Geometry& g, double az, double el) {
  if (!o.camera.empty()) {
    const auto c = vs::cli::parseNumbers(o.camera, "--camera", 9);
    vs::Camera cam;
    cam.eye = vs::Vec3(c[0], c[1], c[2]);
    cam.target = vs::Vec3(c[3], c[4], c[5]);
    cam.up = vs::Vec3(c[6], c[7], c[8]);
    cam.perspective = o.perspective;
    cam.fovDeg = o.fov / o.zoom;
    if (!cam.perspective) {
      const vs::Camera fit = vs::orbitCamera(g, 0, 0, o.zoom, false);
      cam.orthoHeight = fit.orthoHeight;
    }
    cam.validate();
    return cam;
  }
  return vs::orbitCamera(g, az, el, o.zoom, o.perspective);
}

// --turntable N: N frames around the volume, all or none written.
void renderTurntable(const Opts& o, vs::Renderer& ren, const vs::Geometry& g, const std::vector<double>& view,
                     const Overlays& ov, int W, int H, const Report& report, vs::Progress& progress) {
  if (o.out.empty()) throw vs::UsageError("--turntable needs --out");
  vs::OutputSet frames;  // the whole turntable or no frame at all
  for (int i = 0; i < o.turntable; ++i) {
    progress.report(double(i) / o.turntable, "turntable");
    auto res = ren.render(makeCamera(o, g, view[0] + 360.0 * i / o.turntable, view[1]), W, H, progress);
    ov.addLegend(res.image);
    frames.write(frameName(o.out, i), [&](const std::string& t) { vs::writePng(res.image, t); });
  }
  report.write({{"image", {W, H}}, {"frames", o.turntable}}, &frames);
  frames.commit();
  vs::cli::note("render: " + std::to_string(o.turntable) + " frames -> " + frameName(o.out, 0) + " ...");
}

// One frame (rendered 1 + --repeat times, the median frame time reported).
void renderFrame(const Opts& o, vs::Renderer& ren, const vs::Geometry& g, const std::vector<double>& view,
                 const Overlays& ov, int W, int H, const Report& report, vs::Progress& progress, double loadS,
                 double prepareS, vs::RenderMode mode) {
  const vs::Camera cam = makeCamera(o, g, view[0], view[1]);
  std::vector<double> frames;
  auto tf0 = Clock::now();
  vs::RenderResult res = ren.render(cam, W, H, progress);
  const double first = since(tf0);
  for (int i = 0; i < o.repeat; ++i) {
    progress.report(double(i) / o.repeat, "repeat");
    tf0 = Clock::now();
    res = ren.render(cam, W, H);
    frames.push_back(since(tf0));
  }
  ov.addLegend(res.image);
  if (!o.out.empty()) vs::writePng(res.image, o.out);
  std::vector<double> sorted = frames;
  std::sort(sorted.begin(), sorted.end());
  const double median = sorted.empty() ? first : sorted[sorted.size() / 2];
  nlohmann::json extra;
  extra["seconds"] = {
      {"load", loadS}, {"prepare", prepareS}, {"first_frame", first}, {"frame_median", median}, {"frames", frames}};
  extra["fps"] = median > 0 ? 1.0 / median : 0.0;
  extra["samples"] = res.samples;
  const double frac = ren.overlayFractionOutside();
  if (frac > 0) extra["overlay_fraction_outside"] = frac;
  extra["image"] = {W, H};
  extra["threads"] = vs::workerCount();
  extra["view"] = {{"azimuth_deg", view[0]}, {"elevation_deg", view[1]}};
  report.write(extra);
  vs::cli::note("render: " + renderModeName(mode) + " " + std::to_string(W) + "x" + std::to_string(H) +
                (o.out.empty() ? "" : " -> " + o.out) +
                (o.repeat > 0 ? ", median frame " + std::to_string(median * 1000) + " ms" : ""));
}

void warnNoOrientation(const Opts& o) {
  std::cerr << "volscissors: warning: " << o.volume
            << " states no orientation: LPS assumed, the picture's anatomy may be wrong (state it with "
               "--orientation CODE, e.g. LAS)\n";
}

Report makeReport(const Opts& o, const vs::Geometry& g, const Overlays& ov) {
  Report report{o, g, {}};
  if (!ov.legend.empty()) report.common["overlays"] = ov.legend;
  if (ov.byDiameter)
    report.common["color_by"] = {
        {"quantity", "diameter_mm"}, {"min", ov.byDiameter->loMm}, {"max", ov.byDiameter->hiMm}};
  return report;
}

// --mode slice of an OME-Zarr folder (issue 25): only the chunks holding the slice are read, so a
// slice of a volume larger than memory takes one slice's memory. The automatic window is then the
// slice's percentiles (the whole volume's would read every chunk).
int renderZarrSlice(const Opts& o, const vs::WindowLevel& window, int W, int H) {
  vs::ZarrInfo zi;
  vs::ChunkedVolume cv = vs::openZarr(o.volume, 0, &zi);
  if (!o.orientation.empty())
    vs::setOrientation(cv.geometry, o.orientation);
  else if (!zi.hasDirection)
    warnNoOrientation(o);
  const vs::Geometry g = cv.geometry;
  const std::pair<int, double> plane = planeOption(o, g, vs::axialIndexAxis(g));
  const Overlays ov = loadOverlays(o, g);
  const Report report = makeReport(o, g, ov);
  const int axis = plane.first;
  const int64_t index = plane.second < 0 ? (g.dims[size_t(axis)] - 1) / 2 : int64_t(plane.second);
  vs::Index3 origin{0, 0, 0}, size = g.dims;
  origin[size_t(axis)] = index;
  size[size_t(axis)] = 1;
  vs::ChunkCache cache(std::move(cv), int64_t(64) << 20);
  const vs::AnyVolume slab = cache.readBox(origin, size);
  if (window.window <= 0) vs::cli::note("render: OME-Zarr slice: automatic window from this slice");
  vs::cli::note("render: " + std::to_string(cache.stats().loads) + " chunks read");
  return renderSlicePicture(o, slab, nullptr, {axis, 0.0}, ov, window, W, H, report, index);
}

// The volume as read, with --orientation applied (a warning when neither states one).
vs::AnyVolume readOriented(const Opts& o) {
  vs::ReadInfo readInfo;
  vs::AnyVolume vol = vs::readVolume(o.volume, {}, &readInfo);
  if (!o.orientation.empty())
    vs::setOrientation(vol, o.orientation);
  else if (!readInfo.orientationInHeader)
    warnNoOrientation(o);
  return vol;
}

int run(const Opts& o) {
  if (o.out.empty() && o.repeat <= 0) throw vs::UsageError("--out is required (except with --repeat)");
  if (!o.out.empty()) vs::cli::requireExtension(o.out, "--out", {".png"});  // no PNG bytes in a .jpg
  if (o.turntable < 0 || o.turntable > 3600) throw vs::UsageError("--turntable must be in 0..3600");
  if (o.repeat < 0 || o.repeat > 10000) throw vs::UsageError("--repeat must be in 0..10000");
  const auto [W, H] = vs::cli::parseImageSize(o.size, "--size", vs::Renderer::kMaxImageSide);
  const bool sliceMode = o.mode == "slice";
  const vs::RenderMode mode = sliceMode ? vs::RenderMode::Full : vs::renderModeFromName(o.mode);
  if (!sliceMode && (o.voxelPixels || o.ticks || o.letters))
    throw vs::UsageError("--voxel-pixels, --ticks and --letters apply to --mode slice only");
  if (!o.out.empty()) vs::checkOutputPath(o.out);
  if (!o.json.empty()) vs::checkOutputPath(o.json);
  const auto view = vs::cli::parseNumbers(o.view, "--view", 2);
  vs::WindowLevel window;
  if (!o.window.empty()) {
    const auto wl = vs::cli::parseNumbers(o.window, "--window", 2);
    if (!(wl[0] > 0)) throw vs::UsageError("--window: width must be > 0");
    window = {wl[0], wl[1]};
  }

  vs::cli::ProgressLine progressLine("render");
  vs::Progress& progress = progressLine.progress();
  const auto t0 = Clock::now();
  if (sliceMode && o.labels.empty() && vs::isZarrPath(o.volume)) return renderZarrSlice(o, window, W, H);
  progress.report(0, "reading " + o.volume);
  const vs::AnyVolume vol = readOriented(o);
  const vs::Geometry& g = vs::geometryOf(vol);
  std::unique_ptr<vs::AnyVolume> labels;
  if (!o.labels.empty()) labels = std::make_unique<vs::AnyVolume>(vs::readVolume(o.labels));

  vs::RenderOptions ro = vs::defaultRenderOptions(vol, mode);
  if (window.window > 0) ro.window = window;
  const std::pair<int, double> plane = planeOption(o, g, ro.planeAxis);  // default: the central axial slice
  const Overlays ov = loadOverlays(o, g);
  const Report report = makeReport(o, g, ov);
  if (sliceMode) return renderSlicePicture(o, vol, labels.get(), plane, ov, window, W, H, report);

  const vs::TransferFunction tf = vs::fileExtension(o.tf) == ".json"
                                      ? vs::TransferFunction::fromFile(o.tf)
                                      : vs::TransferFunction::preset(o.tf, vs::valueRange(vol));
  vs::Renderer ren(vol, progress);
  const double loadS = since(t0);
  setRenderOptions(o, g, plane, ro);
  ren.setOptions(ro);
  ren.setTransferFunction(tf);
  if (labels) ren.setLabels(*labels);
  addOverlays(ren, ov, o.overlayRadius);

  const auto tp = Clock::now();
  ren.prepare(progress);
  const double prepareS = since(tp);
  if (o.turntable > 0)
    renderTurntable(o, ren, g, view, ov, W, H, report, progress);
  else
    renderFrame(o, ren, g, view, ov, W, H, report, progress, loadS, prepareS, ro.mode);
  return 0;
}

vs::cli::Runner setup(CLI::App& sub) {
  auto o = std::make_shared<Opts>();
  addOptions(sub, *o);
  return [o] { return run(*o); };
}

const vs::cli::Registration reg{"render", "volume rendering to PNG (full, cutbox, triplanar, monoplanar, MIP, slice)",
                                setup};

}  // namespace
