#include "app/stereo.h"

#include <Eigen/Dense>

namespace vs::viewer {

std::vector<StereoEye> stereoEyes(const ViewerApp& app, StereoMode mode, int w, int h) {
  VS_REQUIRE(w > 0 && h > 0, "stereo: the 3D view's size must be positive");
  const ViewSettings& v = app.view();
  const Camera cam = app.camera();
  const double dist = (cam.target - cam.eye).norm() * v.convergence, sep = v.eyeSeparation * dist;
  auto make = [&](int eye, int x0, int width) {
    StereoEye e;
    e.eye = eye;
    e.x0 = x0;
    e.width = width;
    e.height = h;
    e.view = eye == 0 ? eyeView(cam, double(width) / h) : eyeView(cam, double(width) / h, eye, sep, dist);
    return e;
  };
  if (mode == StereoMode::Off) return {make(0, 0, w)};
  if (mode == StereoMode::SideBySide) {
    const int half = w / 2;
    return {make(-1, 0, half), make(+1, half, w - half)};
  }
  return {make(-1, 0, w), make(+1, 0, w)};
}

bool projectToEye(const StereoEye& e, const Vec3& world, double& px, double& py, double& depth) {
  const Eigen::Vector4d viewPt = e.view.view * Eigen::Vector4d(world.x(), world.y(), world.z(), 1);
  depth = -viewPt.z();
  const Eigen::Vector4d clip = e.view.projection * viewPt;
  if (clip.w() <= 1e-9) return false;
  px = (clip.x() / clip.w() + 1) * 0.5 * e.width;
  py = (1 - clip.y() / clip.w()) * 0.5 * e.height;
  return true;
}

void eyeRay(const StereoEye& e, double px, double py, Vec3& origin, Vec3& dir) {
  const Eigen::Matrix4d inv = (e.view.projection * e.view.view).inverse();
  const double nx = 2 * px / e.width - 1, ny = 1 - 2 * py / e.height;
  auto unproject = [&](double nz) {
    const Eigen::Vector4d p = inv * Eigen::Vector4d(nx, ny, nz, 1);
    return Vec3(p.x() / p.w(), p.y() / p.w(), p.z() / p.w());
  };
  origin = unproject(-1);  // on the near plane (1 mm in front of the eye)
  dir = (unproject(0.5) - origin).normalized();
}

const StereoEye& eyeAt(const std::vector<StereoEye>& eyes, double px) {
  for (const StereoEye& e : eyes)
    if (px >= e.x0 && px < e.x0 + e.width) return e;
  return eyes.front();
}

}  // namespace vs::viewer
