// Interaction latencies of the viewer that do not depend on the GPU (issue 16):
//   live-wire update per mouse move on a 256^2 slice (goal: median < 5 ms),
//   stylus pick of the 3D view (goal: < 2 ms), the cut's live contour on the surface per mouse move,
//   first frame after loading a 256^3 volume (goal: < 1 s; the GPU part on Mesa's llvmpipe here),
//   the UI thread's longest frame while a trace runs in the background (its GL-free work),
//   the CPU 3D view (the fallback without OpenGL 3.3): the UI thread's cost per frame during a
//   drag, the pictures it got, and the time to the full-resolution frame after the drag.
// Usage: bench_viewer [VOLUME] [--cpu-view|--cut]   (default: the head phantom, 256^3; --cpu-view: only
// the CPU 3D view rows). Prints one table.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "app/cpu_view.h"
#include "app/slice_layout.h"
#include "app/viewer_app.h"
#ifdef VS_HAVE_VIEWER
#include "gl/egl_context.h"
#include "gl/raycaster.h"
#endif

using namespace vs;
using namespace vs::viewer;
using Clock = std::chrono::steady_clock;

namespace {

double ms(Clock::time_point a, Clock::time_point b) { return std::chrono::duration<double, std::milli>(b - a).count(); }

struct Stats {
  double median = 0, p95 = 0, max = 0;
  size_t n = 0;
};

Stats stats(std::vector<double> v) {
  Stats s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.n = v.size();
  s.median = v[v.size() / 2];
  s.p95 = v[std::min(v.size() - 1, v.size() * 95 / 100)];
  s.max = v.back();
  return s;
}

void row(const char* what, const Stats& s, const char* goal) {
  std::printf("%-44s %6zu %9.3f %9.3f %9.3f   %s\n", what, s.n, s.median, s.p95, s.max, goal);
}

}  // namespace

// The CPU 3D view at 640x400: the first frame after loading, then a drag (one request per UI
// frame every 16 ms for 2 s, turning the view 1 degree a frame) and the wait for the full frame.
void benchCpuView(ViewerApp& app) {
  const std::array<float, 3> background{0.08f, 0.08f, 0.1f};
  CpuView view;
  auto settle = [&] {
    while (!view.settled()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  };
  const auto t0 = Clock::now();
  view.request(cpuFrameRequest(app, 640, 400, background));
  settle();
  std::printf("%-44s %6d %9.1f\n", "CPU 3D view: first frame 640x400 (+ renderer)", 1, ms(t0, Clock::now()));
  std::vector<double> ui;
  int previews = 0, full = 0;
  std::shared_ptr<const CpuView::Frame> seen = view.newest();
  for (int i = 0; i < 125; ++i) {
    app.setOrbit(app.view().azimuthDeg + 1, app.view().elevationDeg);
    const auto u0 = Clock::now();
    view.request(cpuFrameRequest(app, 640, 400, background));
    const auto f = view.newest();
    ui.push_back(ms(u0, Clock::now()));
    if (f != seen) (f->preview ? previews : full) += 1, seen = f;
    std::this_thread::sleep_for(std::chrono::milliseconds(16));
  }
  const auto t1 = Clock::now();
  settle();
  row("CPU 3D view: UI thread per frame (request)", stats(ui), "never waits for a render");
  std::printf("%-44s %6d %9.1f\n", "CPU 3D view: full frame after the drag", 1, ms(t1, Clock::now()));
  std::printf("  (2 s drag: %d new pictures shown, %d previews at 1/%d resolution, %d full)\n", previews + full,
              previews, CpuView::kPreviewDivisor, full);
}

// Cut: the live contour on the surface mesh while the stylus moves (one resumed mesh search per
// move), after the mesh is built in the background and one point is placed.
void benchCut(ViewerApp& app) {
  app.setTransferFunction("ct-skin");  // the skin: the stylus' surface and the cut's iso-value
  app.setTool(ToolKind::Cut);
  const auto tMesh0 = Clock::now();
  app.prepareCutContour();
  app.job().wait();
  app.finishJob();
  const auto tMesh1 = Clock::now();
  const CameraFrame cf(app.camera(), 640, 400);
  std::vector<Vec3> surface;  // stylus points along a row across the face
  for (int px = 250; px < 390; px += 1) {
    Vec3 o, d;
    cf.ray(px, 200, o, d);
    const StylusPick pk = app.pick(o, d);
    if (pk.hit) surface.push_back(pk.surface);
  }
  std::vector<double> t;
  size_t drawn = 0;
  if (!surface.empty()) {
    app.cutPoint(surface.front());
    app.cut().liveContour(std::nullopt);  // the committed segments (none yet)
    for (size_t i = 1; i < surface.size(); ++i) {
      const auto t0 = Clock::now();
      drawn += app.cut().liveContour(surface[i]).path.empty() ? 0 : 1;
      t.push_back(ms(t0, Clock::now()));
    }
  }
  std::printf("%-44s %6d %9.1f\n", "cut: surface mesh + graph (background)", 1, ms(tMesh0, tMesh1));
  row("cut: live contour update per mouse move", stats(t), "median < 5 ms");
  std::printf("  (%zu of %zu moves drew a live segment; iso %.4g)\n", drawn, t.size(), app.cut().iso());
  // The previewed loop (issue 26 item 3: the core's cutContour through the points and the hovered
  // point, self-avoiding and closed): three points (the middle of the row, two on a row 40 px
  // lower), then the stylus along the first row's second quarter; each move whose hovered vertex changed recomputes the
  // whole loop.
  std::vector<Vec3> lower;
  for (int px = 250; px < 390; px += 1) {
    Vec3 o, d;
    cf.ray(px, 240, o, d);
    const StylusPick pk = app.pick(o, d);
    if (pk.hit) lower.push_back(pk.surface);
  }
  if (surface.size() > 20 && lower.size() > 20) {
    std::vector<double> tPoint, tLoop;
    size_t closed = 0;
    for (const Vec3& p : {surface.back(), lower.back(), lower.front()}) {
      app.cutPoint(p);
      const auto t0 = Clock::now();
      app.cut().liveContour(std::nullopt);  // a new point: the component (prepared once) and the loop
      tPoint.push_back(ms(t0, Clock::now()));
    }
    for (size_t i = 10; i + 10 < surface.size(); ++i) {
      const auto t0 = Clock::now();
      closed += app.cut().liveContour(surface[i]).closed ? 1 : 0;
      tLoop.push_back(ms(t0, Clock::now()));
    }
    row("cut: preview after a new point (first: mesh)", stats(tPoint), "");
    row("cut: previewed loop per mouse move (4 pts)", stats(tLoop), "median < 5 ms");
    std::printf("  (%zu of %zu moves previewed a closed loop%s%s)\n", closed, tLoop.size(),
                closed < tLoop.size() ? "; otherwise: " : "", app.cut().liveContour(std::nullopt).problem.c_str());
  }
}

int main(int argc, char** argv) {
  std::string volumePath;
  bool cpuViewOnly = false, cutOnly = false;
  for (int i = 1; i < argc; ++i)
    if (std::string(argv[i]) == "--cpu-view")
      cpuViewOnly = true;
    else if (std::string(argv[i]) == "--cut")
      cutOnly = true;
    else
      volumePath = argv[i];
  ViewerApp app;
  const auto tLoad0 = Clock::now();
  if (!volumePath.empty())
    app.load(volumePath);
  else
    app.loadHeadPhantom(256);
  const auto tLoad1 = Clock::now();
  const Geometry& g = app.geometry();
  std::printf("volume: %s, %s\n", app.source().c_str(), g.describe().c_str());
  std::printf("%-44s %6s %9s %9s %9s   %s\n", "measure (ms)", "n", "median", "p95", "max", "goal");
  if (cpuViewOnly) {
    benchCpuView(app);
    return 0;
  }
  if (cutOnly) {
    benchCut(app);
    return 0;
  }

  // Live-wire: the mouse circles the slice centre, one hover per move, after one click.
  {
    app.setTool(ToolKind::LiveWire);
    const int64_t z = g.dims[2] / 2;
    app.liveWire().setSlice(2, z);
    const double cx = double(g.dims[0]) / 2, cy = double(g.dims[1]) / 2,
                 r = 0.35 * double(std::min(g.dims[0], g.dims[1]));
    const auto tFeat0 = Clock::now();
    app.point2({std::lround(cx + r), std::lround(cy)});  // builds the slice's costs, seeds
    const auto tFeat1 = Clock::now();
    std::vector<double> t;
    for (int i = 1; i <= 400; ++i) {
      const double a = 2 * 3.14159265358979 * i / 400;
      const PixelUV p{std::lround(cx + r * std::cos(a)), std::lround(cy + r * std::sin(a))};
      const auto t0 = Clock::now();
      app.liveWire().hover(p);
      t.push_back(ms(t0, Clock::now()));
    }
    std::printf("%-44s %6d %9.3f\n", "live-wire: slice costs + first click", 1, ms(tFeat0, tFeat1));
    row("live-wire: update per mouse move", stats(t), "median < 5 ms");
  }

  // Stylus: rays through a 640x400 3D view's pixels on a grid over its central part (the head).
  {
    const Camera cam = app.camera();
    const CameraFrame cf(cam, 640, 400);
    std::vector<double> t;
    int hits = 0;
    for (int py = 110; py < 290; py += 12)
      for (int px = 230; px < 410; px += 12) {
        Vec3 o, d;
        cf.ray(px, py, o, d);
        const auto t0 = Clock::now();
        hits += app.pick(o, d).hit ? 1 : 0;
        t.push_back(ms(t0, Clock::now()));
      }
    row("stylus pick (full mode, snap 0)", stats(t), "< 2 ms");
    app.setSnap(3);
    t.clear();
    for (int py = 110; py < 290; py += 12)
      for (int px = 230; px < 410; px += 12) {
        Vec3 o, d;
        cf.ray(px, py, o, d);
        const auto t0 = Clock::now();
        app.pick(o, d);
        t.push_back(ms(t0, Clock::now()));
      }
    row("stylus pick + snap radius 3", stats(t), "< 2 ms");
    app.setSnap(0);
    std::printf("  (%d of %zu rays hit the volume)\n", hits, t.size());
  }

  benchCut(app);

  // First frame: load (above) + GPU upload + one 640x400 frame.
  {
    double upload = -1, frame = -1;
    std::string renderer = "no OpenGL";
#ifdef VS_HAVE_VIEWER
    try {
      EglContext gl;
      renderer = gl.renderer();
      GpuRayCaster rc;
      const auto t0 = Clock::now();
      rc.setVolume(app.volume());
      rc.setTransferFunction(app.transferFunction());
      const auto t1 = Clock::now();
      RayCastSettings s;
      s.window = app.view().window;
      rc.renderImage(eyeView(app.camera(), 640.0 / 400.0), 640, 400, s);
      const auto t2 = Clock::now();
      upload = ms(t0, t1);
      frame = ms(t1, t2);
    } catch (const std::exception& e) {
      renderer = e.what();
    }
#endif
    std::printf("%-44s %6d %9.1f\n", "load (read or generate + viewer state)", 1, ms(tLoad0, tLoad1));
    std::printf("%-44s %6d %9.1f\n", "GPU upload (3D texture + TF)", 1, upload);
    std::printf("%-44s %6d %9.1f   on %s\n", "first 3D frame 640x400", 1, frame, renderer.c_str());
  }

  benchCpuView(app);

  // UI thread while a trace runs: each frame's GL-free work (three slice images at the cursor, a
  // stylus pick, the tree snapshot) must not wait for the job.
  {
    app.setTool(ToolKind::Trace);
    app.trace().setCost("gradient", TubePolarity::Bright);  // the head phantom has no lumen for the auto cost
    const Index3 c = app.view().cursor;
    app.point3(c);
    app.point3({c[0] / 2, c[1], c[2]});
    app.point3({c[0], c[1] / 2, c[2] / 3});
    const Camera cam = app.camera();
    const CameraFrame cf(cam, 640, 400);
    std::vector<double> t;
    const auto tRun0 = Clock::now();
    app.run(/*wait=*/false);
    while (app.job().running()) {
      const auto t0 = Clock::now();
      for (int a = 0; a < 3; ++a)
        sliceImage(app.floatVolume(), a, app.view().cursor[static_cast<size_t>(a)], app.view().window);
      Vec3 o, d;
      cf.ray(320, 200, o, d);
      app.pick(o, d);
      (void)app.trace().paths();
      t.push_back(ms(t0, Clock::now()));
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    const double runMs = ms(tRun0, Clock::now());
    app.finishJob();
    row("UI frame (GL-free work) while a trace runs", stats(t), "never waits for the job");
    std::printf("  (trace with 2 targets: %.0f ms in the background, %zu paths)\n", runMs, app.trace().paths().size());
  }
  return 0;
}
