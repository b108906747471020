// Cameras for the ray caster and the overlay rasteriser, in world (mm) coordinates.
// Pixel (px, py) of a W x H image (row 0 at the top) has its centre at normalised device
// coordinates x = 2 (px + 0.5) / W - 1 (right), y = 1 - 2 (py + 0.5) / H (up).
//   perspective:  ray from the eye through  forward + x tan(fov/2) aspect right + y tan(fov/2) up
//   orthographic: parallel rays along forward from  eye + x (h/2) aspect right + y (h/2) up
// fov is the vertical field of view, h (orthoHeight) the visible height in mm, aspect = W/H.
#pragma once

#include "volume/geometry.h"

namespace vs {

struct Camera {
  Vec3 eye{0, -100, 0};  // mm
  Vec3 target{0, 0, 0};  // look-at point, mm
  Vec3 up{0, 0, 1};      // need not be orthogonal to the view direction (not parallel to it)
  bool perspective = false;
  double fovDeg = 30.0;      // vertical field of view (perspective), degrees in (0, 180)
  double orthoHeight = 100;  // visible image height in mm (orthographic), > 0

  // Throws InvalidArgument for a degenerate camera (eye == target, up parallel to the view
  // direction, fov or height out of range, non-finite numbers).
  void validate() const;
};

// A camera orbiting the volume's centre so that its whole bounding box (voxel centres
// 0..dims-1) fits the view at zoom 1: the bounding sphere of radius R (mm) fills the image
// height (orthographic: orthoHeight = 2R / zoom; perspective: fov 30 deg / zoom and the eye
// at distance R / sin(15 deg), as VTK's ResetCamera). Azimuth turns about world +z (patient
// superior in LPS), elevation raises the eye towards +z. az = el = 0 looks from -y (anterior
// in LPS) towards +y with +z up; az = 90 looks from +x.
Camera orbitCamera(const Geometry& g, double azimuthDeg, double elevationDeg, double zoom, bool perspective);

// The default orbit of the 3D modes: from anterior, turned 30 degrees towards the patient's
// left and raised 30 degrees, so that no index plane or cut-box face is seen edge-on.
struct OrbitView {
  double azimuthDeg = 30;
  double elevationDeg = 30;
};

// Precomputed frame of a camera for one image size: ray generation and projection.
class CameraFrame {
 public:
  CameraFrame(const Camera& cam, int width, int height);

  int width() const { return w_; }
  int height() const { return h_; }
  const Camera& camera() const { return cam_; }
  const Vec3& forward() const { return f_; }
  const Vec3& right() const { return r_; }
  const Vec3& up() const { return u_; }

  // Ray through the centre of pixel (px, py): origin and unit direction.
  void ray(double px, double py, Vec3& origin, Vec3& dir) const;
  // Projects a world point: pixel coordinates (continuous; pixel centres at +0.5) and view
  // depth (distance along forward from the eye plane, mm). Returns false if the point is
  // behind the eye (perspective, depth <= 1e-6).
  bool project(const Vec3& world, double& px, double& py, double& depth) const;
  // Size in mm of one pixel at view depth `depth` (orthographic: constant).
  double pixelSizeAt(double depth) const;

 private:
  Camera cam_;
  int w_, h_;
  Vec3 f_, r_, u_;
  double tanHalf_ = 0, aspect_ = 1;
};

}  // namespace vs
