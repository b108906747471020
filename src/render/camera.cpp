#include "render/camera.h"

#include <Eigen/Geometry>
#include <cmath>

#include "util/error.h"

namespace vs {

namespace {
constexpr double kPi = 3.14159265358979323846;
bool finite3(const Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }
}  // namespace

void Camera::validate() const {
  VS_REQUIRE(finite3(eye) && finite3(target) && finite3(up), "camera: eye, target and up must be finite");
  const Vec3 f = target - eye;
  VS_REQUIRE(f.norm() > 1e-9, "camera: eye and look-at point coincide");
  VS_REQUIRE(up.norm() > 1e-12 && f.normalized().cross(up.normalized()).norm() > 1e-6,
             "camera: up vector is zero or parallel to the view direction");
  if (perspective)
    VS_REQUIRE(std::isfinite(fovDeg) && fovDeg > 0 && fovDeg < 179,
               "camera: field of view must be in (0, 179) degrees");
  else
    VS_REQUIRE(std::isfinite(orthoHeight) && orthoHeight > 0, "camera: orthographic height must be > 0 mm");
}

Camera orbitCamera(const Geometry& g, double az, double el, double zoom, bool perspective) {
  VS_REQUIRE(std::isfinite(zoom) && zoom > 0, "camera: zoom must be > 0");
  VS_REQUIRE(std::isfinite(az) && std::isfinite(el), "camera: azimuth/elevation must be finite");
  // World bounding box of the 8 corner voxel centres.
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (int c = 0; c < 8; ++c) {
    const Vec3 idx((c & 1) ? double(g.dims[0] - 1) : 0.0, (c & 2) ? double(g.dims[1] - 1) : 0.0,
                   (c & 4) ? double(g.dims[2] - 1) : 0.0);
    const Vec3 w = g.indexToWorld(idx);
    lo = lo.cwiseMin(w);
    hi = hi.cwiseMax(w);
  }
  const Vec3 centre = 0.5 * (lo + hi);
  const double radius = std::max(0.5 * (hi - lo).norm(), 1e-3);
  const double a = az * kPi / 180.0, e = el * kPi / 180.0;
  const Vec3 toEye(std::sin(a) * std::cos(e), -std::cos(a) * std::cos(e), std::sin(e));
  Camera cam;
  cam.target = centre;
  cam.perspective = perspective;
  // Near the poles +z is (almost) parallel to the view direction: use the horizontal direction instead.
  cam.up = std::abs(std::cos(e)) > 1e-3 ? Vec3(0, 0, 1) : Vec3(-std::sin(a), std::cos(a), 0) * (e > 0 ? 1.0 : -1.0);
  if (perspective) {
    const double half = 15.0 * kPi / 180.0;
    cam.fovDeg = 2.0 * std::atan(std::tan(half) / zoom) * 180.0 / kPi;
    cam.eye = centre + toEye * (radius / std::sin(half));
  } else {
    cam.orthoHeight = 2.0 * radius / zoom;
    cam.eye = centre + toEye * (radius * 4.0);
  }
  return cam;
}

CameraFrame::CameraFrame(const Camera& cam, int width, int height) : cam_(cam), w_(width), h_(height) {
  cam.validate();
  VS_REQUIRE(width > 0 && height > 0, "camera: image size must be positive");
  f_ = (cam.target - cam.eye).normalized();
  r_ = f_.cross(cam.up).normalized();
  u_ = r_.cross(f_);
  aspect_ = double(width) / double(height);
  tanHalf_ = std::tan(cam.fovDeg * kPi / 360.0);
}

void CameraFrame::ray(double px, double py, Vec3& origin, Vec3& dir) const {
  const double x = 2.0 * (px + 0.5) / w_ - 1.0;
  const double y = 1.0 - 2.0 * (py + 0.5) / h_;
  if (cam_.perspective) {
    origin = cam_.eye;
    dir = (f_ + r_ * (x * tanHalf_ * aspect_) + u_ * (y * tanHalf_)).normalized();
  } else {
    const double hh = 0.5 * cam_.orthoHeight;
    origin = cam_.eye + r_ * (x * hh * aspect_) + u_ * (y * hh);
    dir = f_;
  }
}

bool CameraFrame::project(const Vec3& p, double& px, double& py, double& depth) const {
  const Vec3 d = p - cam_.eye;
  depth = d.dot(f_);
  double x, y;
  if (cam_.perspective) {
    if (depth <= 1e-6) return false;
    x = d.dot(r_) / (depth * tanHalf_ * aspect_);
    y = d.dot(u_) / (depth * tanHalf_);
  } else {
    const double hh = 0.5 * cam_.orthoHeight;
    x = d.dot(r_) / (hh * aspect_);
    y = d.dot(u_) / hh;
  }
  px = (x + 1.0) * 0.5 * w_;
  py = (1.0 - y) * 0.5 * h_;
  return true;
}

double CameraFrame::pixelSizeAt(double depth) const {
  if (cam_.perspective) return 2.0 * depth * tanHalf_ / h_;
  return cam_.orthoHeight / h_;
}

}  // namespace vs
