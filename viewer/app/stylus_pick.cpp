// The stylus: the first visible point under a pixel of the 3D view, as the display mode shows
// it (a plane, the cut box's face, the MIP's maximum, the composited ray reaching opacity 0.5),
// snapped to the strongest gradient within the snap radius. The ray is clipped by the renderer's
// own ray/box clip (render/block_walk.h) and sampled by the core's trilinear sampler.
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "app/stereo.h"
#include "app/viewer_app.h"
#include "features/features3d.h"
#include "render/block_walk.h"
#include "volume/sample.h"

namespace vs::viewer {

namespace {

// The part of the ray o + t d (t >= 0, in front of the eye) inside the box [lo, hi].
bool clipRay(const Vec3& o, const Vec3& d, const Vec3& lo, const Vec3& hi, double& t0, double& t1) {
  if (!intersectBox(o.data(), d.data(), lo.data(), hi.data(), t0, t1)) return false;
  t0 = std::max(t0, 0.0);
  return t1 >= t0;
}

}  // namespace

StylusPick ViewerApp::stylusPick(double px, double py, int width, int height) const {
  VS_REQUIRE(hasVolume(), "no volume loaded");
  VS_REQUIRE(width > 0 && height > 0, "stylus: the 3D view's size must be positive");
  VS_REQUIRE(px >= 0 && py >= 0 && px < width && py < height,
             "stylus: pixel " + std::to_string(px) + "," + std::to_string(py) + " is outside the 3D view (" +
                 std::to_string(width) + "x" + std::to_string(height) + ")");
  Vec3 o, d;
  if (view_.stereo == StereoMode::SideBySide) {  // the camera of the eye whose half is under the mouse
    const std::vector<StereoEye> eyes = stereoEyes(*this, view_.stereo, width, height);
    const StereoEye& e = eyeAt(eyes, px);
    eyeRay(e, px - e.x0, py, o, d);
    return pick(o, d);
  }
  const CameraFrame cf(camera(), width, height);  // mono; anaglyph: the cyclopean eye between both
  cf.ray(px - 0.5, py - 0.5, o, d);
  return pick(o, d);
}

Vec3 ViewerApp::stylusTarget(const StylusPick& p) const {
  if (tool_ == ToolKind::Cut) return p.surface;  // the cut snaps it onto its mesh itself
  return Vec3(double(p.voxel[0]), double(p.voxel[1]), double(p.voxel[2]));
}

StylusPick ViewerApp::stylusClick(double px, double py, int width, int height) {
  VS_REQUIRE(tool_ == ToolKind::Cut || tool_ == ToolKind::Trace || tool_ == ToolKind::Surface,
             "stylus: the " + toolName(tool_) + " tool takes no 3D points (use trace, surface or cut)");
  const StylusPick p = stylusPick(px, py, width, height);
  VS_REQUIRE(p.hit, "stylus: nothing visible under pixel " + std::to_string(px) + "," + std::to_string(py));
  if (tool_ == ToolKind::Cut)
    cutPoint(stylusTarget(p));
  else
    point3(p.voxel);  // == stylusTarget(p)
  return p;
}

StylusPick ViewerApp::pick(const Vec3& originWorld, const Vec3& dirWorld) const {
  StylusPick res;
  const Geometry& g = geometry();
  const Eigen::Matrix3d Minv = (g.direction * g.spacing.asDiagonal()).inverse();
  const Vec3 o = Minv * (originWorld - g.origin), d = Minv * dirWorld.normalized();  // index per mm
  const Vec3 lo(0, 0, 0), hi(double(g.dims[0] - 1), double(g.dims[1] - 1), double(g.dims[2] - 1));
  double t0 = 0, t1 = 0;
  if (!clipRay(o, d, lo, hi, t0, t1)) return res;
  auto finish = [&](const Vec3& c) {
    res.hit = true;
    res.surface = c;
    res.voxel = strongestGradientVoxel(*floatVolume_, roundIndex(c), snap_);  // features/features3d.h
    return res;
  };
  const RenderMode mode = view_.mode;
  if (mode == RenderMode::Triplanar || mode == RenderMode::Monoplanar) {
    double best = 1e300;
    for (int a = 0; a < 3; ++a) {
      if (mode == RenderMode::Monoplanar && a != view_.monoAxis) continue;
      if (std::abs(d[a]) < 1e-15) continue;
      const double t = (double(view_.cursor[static_cast<size_t>(a)]) - o[a]) / d[a];
      if (t <= 0 || t >= best) continue;
      const Vec3 q = o + t * d;
      bool inside = true;
      for (int b = 0; b < 3; ++b) inside = inside && q[b] >= lo[b] - 1e-6 && q[b] <= hi[b] + 1e-6;
      if (inside) best = t;
    }
    if (best < 1e300) return finish(o + best * d);
    return res;
  }
  if (mode == RenderMode::CutBox) {
    const auto b = cutBox();
    if (!clipRay(o, d, Vec3(b[0], b[1], b[2]), Vec3(b[3], b[4], b[5]), t0, t1)) return res;
    return finish(o + t0 * d);  // the box's entry face is shown opaque
  }
  const double dt = 0.5 * g.spacing.minCoeff();
  const TrilinearSampler sampler(*floatVolume_);  // the core's sampler (volume/sample.h)
  if (mode == RenderMode::Mip) {
    float vmax = -1e30f;
    double tmax = t0;
    for (double t = t0; t <= t1; t += dt) {
      const Vec3 q = o + t * d;
      const float v = static_cast<float>(sampler.at(q));
      if (v > vmax) vmax = v, tmax = t;
    }
    return finish(o + tmax * d);
  }
  const TfTable table(tf_, range_.min, range_.max, dt);
  double A = 0;
  for (double t = t0; t <= t1; t += dt) {
    const Vec3 q = o + t * d;
    const float a = table(static_cast<float>(sampler.at(q))).a;
    A += (1 - A) * a;
    if (A >= 0.5) return finish(q);
  }
  return res;
}

}  // namespace vs::viewer
