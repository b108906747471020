// Overlay rasterisation for the ray caster: meshes and polylines (tubes) in world mm are drawn
// into a view-depth buffer with a flat colour x shade; the ray caster then treats them as
// opaque geometry (each ray composites the volume up to the overlay's depth).
// Thread safety: pure function of its arguments.
#pragma once

#include <array>
#include <vector>

#include "mesh/tri_mesh.h"
#include "render/camera.h"

namespace vs {

struct MeshOverlay {
  TriMesh mesh;
  std::array<float, 3> color;
};

struct LineOverlay {
  std::vector<Polyline> lines;
  std::array<float, 3> color;
  double radius;  // mm; <= 0: the polylines' radii, else 1.5 pixels
};

struct OverlayBuffer {
  std::vector<float> depth;  // width * height view depths (mm), +inf = none
  std::vector<std::array<float, 3>> color;
};

// Draws every triangle (perspective-correct depth, vertex normals when present, shade
// 0.25 + 0.75 |n . forward|) and every polyline segment (a tube of the given radius, front
// surface depth, shade 0.4 .. 1 across the tube) into `ob`, keeping the nearest positive depth
// per pixel. `ob` must be sized width * height of the camera frame. O(covered pixels).
void rasteriseOverlays(const CameraFrame& cf, const std::vector<MeshOverlay>& meshes,
                       const std::vector<LineOverlay>& lineSets, OverlayBuffer& ob);

}  // namespace vs
