#include "volume/crop.h"

#include <cmath>

namespace vs {

std::string VoxelBox::describe() const {
  std::string s;
  const char* axis[] = {"x", "y", "z"};
  for (int a = 0; a < 3; ++a)
    s += std::string(a ? ", " : "") + axis[a] + " " + std::to_string(lo[a]) + ".." + std::to_string(hi[a]);
  return s;
}

VoxelBox wholeBox(const Geometry& g) { return {{0, 0, 0}, {g.dims[0] - 1, g.dims[1] - 1, g.dims[2] - 1}}; }

VoxelBox clampBox(const Geometry& g, const Vec3& lo, const Vec3& hi) {
  VoxelBox b;
  for (int a = 0; a < 3; ++a) {
    VS_REQUIRE(std::isfinite(lo[a]) && std::isfinite(hi[a]), "box corners must be finite");
    b.lo[a] = std::max<int64_t>(0, static_cast<int64_t>(std::ceil(lo[a])));
    b.hi[a] = std::min<int64_t>(g.dims[a] - 1, static_cast<int64_t>(std::floor(hi[a])));
  }
  if (b.empty())
    throw InvalidArgument("the box " + std::to_string(lo[0]) + "," + std::to_string(lo[1]) + "," +
                          std::to_string(lo[2]) + " .. " + std::to_string(hi[0]) + "," + std::to_string(hi[1]) + "," +
                          std::to_string(hi[2]) + " is empty inside the volume " + g.describe());
  return b;
}

Geometry cropGeometry(const Geometry& g, const VoxelBox& box) {
  Geometry c = g;
  c.dims = box.dims();
  c.origin = g.indexToWorld(
      Vec3(static_cast<double>(box.lo[0]), static_cast<double>(box.lo[1]), static_cast<double>(box.lo[2])));
  return c;
}

namespace {
void requireInside(const Geometry& g, const VoxelBox& box) {
  VS_REQUIRE(!box.empty() && g.contains(box.lo) && g.contains(box.hi),
             "crop box " + box.describe() + " is empty or not inside the volume " + g.describe());
}
}  // namespace

template <class T>
Volume<T> cropVolume(const Volume<T>& v, const VoxelBox& box) {
  requireInside(v.geometry(), box);
  Volume<T> out(cropGeometry(v.geometry(), box));
  const Index3 d = box.dims();
  for (int64_t z = 0; z < d[2]; ++z)
    for (int64_t y = 0; y < d[1]; ++y) {
      const T* src = &v(box.lo[0], y + box.lo[1], z + box.lo[2]);
      std::copy(src, src + d[0], &out(0, y, z));
    }
  return out;
}

template <class T>
void pasteVolume(const Volume<T>& part, const VoxelBox& box, Volume<T>& whole) {
  requireInside(whole.geometry(), box);
  VS_REQUIRE(part.dims() == box.dims(), "pasteVolume: the part's size differs from its box " + box.describe());
  const Index3 d = box.dims();
  for (int64_t z = 0; z < d[2]; ++z)
    for (int64_t y = 0; y < d[1]; ++y) {
      const T* src = &part(0, y, z);
      std::copy(src, src + d[0], &whole(box.lo[0], y + box.lo[1], z + box.lo[2]));
    }
}

template Volume<uint8_t> cropVolume(const Volume<uint8_t>&, const VoxelBox&);
template Volume<int16_t> cropVolume(const Volume<int16_t>&, const VoxelBox&);
template Volume<uint16_t> cropVolume(const Volume<uint16_t>&, const VoxelBox&);
template Volume<float> cropVolume(const Volume<float>&, const VoxelBox&);
template void pasteVolume(const Volume<uint8_t>&, const VoxelBox&, Volume<uint8_t>&);
template void pasteVolume(const Volume<int16_t>&, const VoxelBox&, Volume<int16_t>&);
template void pasteVolume(const Volume<uint16_t>&, const VoxelBox&, Volume<uint16_t>&);
template void pasteVolume(const Volume<float>&, const VoxelBox&, Volume<float>&);

}  // namespace vs
