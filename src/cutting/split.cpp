#include "cutting/split.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "util/error.h"

namespace vs {
namespace {

enum : uint8_t { kFree = 0, kBlocked = 1, kSideA = 2, kSideB = 3, kOutside = 4 };

// Marks every voxel whose centre lies within `radius` (index units) of a sample of the surface's
// triangles, sampled at <= 1/4 voxel. radius = sqrt(3)/2 + 1/8 covers every voxel cube the surface
// touches (its supercover), and a 26-connected step between two voxel centres on opposite sides
// crosses the surface inside one of the two cubes, so no 26-connected path gets through.
int64_t voxelise(const TriMesh& mesh, const Geometry& g, std::vector<uint8_t>& state) {
  const double radius = std::sqrt(3.0) / 2 + 0.125 + 1e-6, r2 = radius * radius;
  int64_t blocked = 0;
  std::vector<Vec3> idx(mesh.positions.size());
  for (size_t i = 0; i < idx.size(); ++i) idx[i] = g.worldToIndex(mesh.positions[i]);
  for (const auto& t : mesh.triangles) {
    const Vec3 &a = idx[size_t(t[0])], &b = idx[size_t(t[1])], &c = idx[size_t(t[2])];
    const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
    const int m = std::max(1, int(std::ceil(longest / 0.25)));
    for (int i = 0; i <= m; ++i)
      for (int j = 0; j <= m - i; ++j) {
        const Vec3 p = a + (b - a) * (double(i) / m) + (c - a) * (double(j) / m);
        for (int64_t z = int64_t(std::ceil(p.z() - radius)); z <= int64_t(std::floor(p.z() + radius)); ++z)
          for (int64_t y = int64_t(std::ceil(p.y() - radius)); y <= int64_t(std::floor(p.y() + radius)); ++y)
            for (int64_t x = int64_t(std::ceil(p.x() - radius)); x <= int64_t(std::floor(p.x() + radius)); ++x) {
              if (!g.contains(x, y, z)) continue;
              if ((Vec3(double(x), double(y), double(z)) - p).squaredNorm() > r2) continue;
              uint8_t& s = state[size_t(g.linear(x, y, z))];
              if (s == kFree) s = kBlocked, ++blocked;
            }
      }
  }
  return blocked;
}

std::array<int64_t, 26> neighbourOffsets(const Geometry& g) {
  std::array<int64_t, 26> o{};
  int k = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        if (dx || dy || dz) o[size_t(k++)] = dx + g.dims[0] * (dy + g.dims[1] * dz);
  return o;
}

// Breadth-first region growth over free object voxels, 26-connected; the voxels must not lie on
// the volume's border (the state array gives the border a kOutside frame, see splitVolume).
struct Growth {
  std::vector<int64_t> queue;
  size_t head = 0;
  uint8_t side;
  int64_t size = 0;
  bool done() const { return head == queue.size(); }
};

}  // namespace

namespace {

// Seeds over the disc's interior: on each face of the surface the first free object voxel along
// the projection line (a: along +normal, b: along -normal).
void placeSeeds(const Geometry& g, const CuttingSurface& surface, std::vector<uint8_t>& state, Growth& a, Growth& b) {
  const double reach = 3.0 * g.spacing.maxCoeff(), step = 0.25 * g.spacing.minCoeff();
  for (int64_t y = 0; y < surface.height; ++y)
    for (int64_t x = 0; x < surface.width; ++x) {
      if (surface.ring[size_t(y * surface.width + x)] < 2) continue;
      const Vec3 p = surface.point(x, y);
      for (Growth* side : {&a, &b}) {
        for (double along = step; along <= reach; along += step) {
          const Index3 v = roundIndex(g.worldToIndex(p + (side == &a ? along : -along) * surface.normal));
          if (!g.contains(v)) break;
          uint8_t& st = state[size_t(g.linear(v[0], v[1], v[2]))];
          if (st == kBlocked) continue;
          if (st == kFree) {  // taken voxels (this side's or, where the surface folds, the other's) are no seeds
            st = side->side;
            side->queue.push_back(g.linear(v[0], v[1], v[2]));
          }
          break;
        }
      }
    }
}

// Every blocked (surface) object voxel given a side: by where its centre lies against the surface
// over the disc's interior, else the side it touches first (breadth-first through the shell).
void assignSurfaceVoxels(const VolumeF32& volume, double iso, const CuttingSurface& surface,
                         const std::array<int64_t, 26>& offsets, uint8_t plusSide, std::vector<uint8_t>& state) {
  const Geometry& g = volume.geometry();
  for (int64_t i = 0; i < g.voxelCount(); ++i) {
    if (state[size_t(i)] != kBlocked || volume.data()[i] < iso) continue;
    const Index3 v = g.unlinear(i);
    const Vec3 w = g.indexToWorld(Vec3(double(v[0]), double(v[1]), double(v[2]))) - surface.center;
    const double fx = (w.dot(surface.axisU) - surface.u0) / surface.pixelMm;
    const double fy = (w.dot(surface.axisV) - surface.v0) / surface.pixelMm;
    const int64_t x = int64_t(std::floor(fx)), y = int64_t(std::floor(fy));
    double depth = 0, weight = 0;
    bool interior = true;
    for (int dy = 0; dy < 2 && interior; ++dy)
      for (int dx = 0; dx < 2 && interior; ++dx) {
        if (!surface.inDomain(x + dx, y + dy)) {
          interior = false;
          break;
        }
        const double wgt = (dx ? fx - double(x) : 1 - (fx - double(x))) * (dy ? fy - double(y) : 1 - (fy - double(y)));
        depth += wgt * surface.depth[size_t((y + dy) * surface.width + x + dx)];
        weight += wgt;
      }
    if (!interior || weight <= 0) continue;
    const bool plus = w.dot(surface.normal) > depth / weight;
    state[size_t(i)] = plus ? plusSide : uint8_t(kSideA + kSideB - plusSide);
  }
  std::vector<int64_t> frontier;
  for (int64_t i = 0; i < g.voxelCount(); ++i)
    if (state[size_t(i)] == kSideA || state[size_t(i)] == kSideB) {
      for (int64_t o : offsets) {
        const int64_t j = i + o;
        if (j >= 0 && j < g.voxelCount() && state[size_t(j)] == kBlocked) {
          frontier.push_back(i);
          break;
        }
      }
    }
  while (!frontier.empty()) {
    std::vector<int64_t> next;
    for (int64_t i : frontier)
      for (int64_t o : offsets) {
        const int64_t j = i + o;
        if (j >= 0 && j < g.voxelCount() && state[size_t(j)] == kBlocked && volume.data()[j] >= iso) {
          state[size_t(j)] = state[size_t(i)];
          next.push_back(j);
        }
      }
    frontier = std::move(next);
  }
}

// Object voxels on the volume's border (the growth's kOutside frame) take the side of the object
// voxels inside next to them (the majority, ties to the kept side), then border voxels reached only
// along the border take their neighbour's side. Before, all of them stayed on the kept side: a part
// that the field of view crops (an ear touching the first slice of an MR) lost its outermost layer.
void assignBorderVoxels(const VolumeF32& volume, double iso, uint8_t cutSide, std::vector<uint8_t>& state) {
  const Geometry& g = volume.geometry();
  const Index3& d = g.dims;
  const uint8_t kept = kOutside + 1, pending = kOutside + 2;
  auto onBorder = [&](int64_t x, int64_t y, int64_t z) {
    return x == 0 || y == 0 || z == 0 || x + 1 == d[0] || y + 1 == d[1] || z + 1 == d[2];
  };
  std::vector<int64_t> border;
  for (int64_t z = 0; z < d[2]; ++z)
    for (int64_t y = 0; y < d[1]; ++y)
      for (int64_t x = 0; x < d[0]; ++x) {
        if (!onBorder(x, y, z)) {
          if (x == 1 && x + 1 < d[0] - 1) x = d[0] - 2;  // skip the interior of the row
          continue;
        }
        const int64_t i = g.linear(x, y, z);
        if (volume.data()[i] >= iso) state[size_t(i)] = pending, border.push_back(i);
      }
  // Visits the in-volume 26-neighbours of voxel i.
  auto forNeighbours = [&](int64_t i, auto&& f) {
    const Index3 v = g.unlinear(i);
    for (int64_t dz = -1; dz <= 1; ++dz)
      for (int64_t dy = -1; dy <= 1; ++dy)
        for (int64_t dx = -1; dx <= 1; ++dx) {
          const int64_t x = v[0] + dx, y = v[1] + dy, z = v[2] + dz;
          if ((dx || dy || dz) && x >= 0 && y >= 0 && z >= 0 && x < d[0] && y < d[1] && z < d[2])
            f(g.linear(x, y, z), onBorder(x, y, z));
        }
  };
  std::vector<int64_t> queue;
  std::vector<uint8_t> side(border.size(), pending);
  for (size_t k = 0; k < border.size(); ++k) {
    int cut = 0, rest = 0;
    forNeighbours(border[k], [&](int64_t j, bool jOnBorder) {
      if (jOnBorder || volume.data()[j] < iso) return;
      (state[size_t(j)] == cutSide ? cut : rest)++;
    });
    if (cut + rest > 0) side[k] = cut > rest ? cutSide : kept;
  }
  for (size_t k = 0; k < border.size(); ++k)
    if (side[k] != pending) state[size_t(border[k])] = side[k], queue.push_back(border[k]);
  for (size_t head = 0; head < queue.size(); ++head) {
    const uint8_t s = state[size_t(queue[head])];
    forNeighbours(queue[head], [&](int64_t j, bool jOnBorder) {
      if (jOnBorder && state[size_t(j)] == pending) state[size_t(j)] = s, queue.push_back(j);
    });
  }
}

}  // namespace

SplitResult splitVolume(const VolumeF32& volume, double iso, const CuttingSurface& surface, const SplitOptions& options,
                        Progress& progress) {
  const Geometry& g = volume.geometry();
  const Index3& d = g.dims;
  VS_REQUIRE(surface.width > 0 && surface.height > 0, "split: empty cutting surface");
  progress.report(0.0, "split");
  // Object voxels start free; background and the one-voxel border frame are "outside" (the frame
  // lets the growth skip bounds checks; object voxels on the border take their neighbours' side below).
  std::vector<uint8_t> state(size_t(g.voxelCount()), kOutside);
  for (int64_t z = 1; z + 1 < d[2]; ++z)
    for (int64_t y = 1; y + 1 < d[1]; ++y)
      for (int64_t x = 1; x + 1 < d[0]; ++x) {
        const int64_t i = g.linear(x, y, z);
        if (volume.data()[i] >= iso) state[size_t(i)] = kFree;
      }
  SplitResult result;
  const TriMesh mesh = surface.mesh();
  result.surfaceVoxels = voxelise(mesh, g, state);
  progress.report(0.2, "split");

  // Seeds: over the disc's interior, on each face of the surface the first free object voxel
  // along the projection line, before the line leaves the object (a thin cap of a flat scalp still
  // has its layer of voxels beyond the blocked shell). A free voxel is more than the shell's
  // half-thickness from the surface, so it lies on the side of the line's point that found it.
  Growth a{{}, 0, kSideA}, b{{}, 0, kSideB};
  placeSeeds(g, surface, state, a, b);
  if (a.queue.empty() || b.queue.empty())
    throw DataError(
        "the contour separates nothing: the cutting surface leaves no object voxel on one of its sides (it runs "
        "within a voxel of the object's surface; draw the loop around a part that stands out)");

  // Grow both sides in turns of equal work; the first to finish is the smaller part. Meeting the
  // other side means the two are joined around the surface: the contour encloses no part.
  const std::array<int64_t, 26> offsets = neighbourOffsets(g);
  auto grow = [&](Growth& s, int64_t budget) {
    while (budget-- > 0 && !s.done()) {
      const int64_t i = s.queue[s.head++];
      ++s.size;
      for (int64_t o : offsets) {
        uint8_t& n = state[size_t(i + o)];
        if (n == kFree) {
          n = s.side;
          s.queue.push_back(i + o);
        } else if (n == kSideA + kSideB - s.side) {
          throw DataError(
              "the contour separates nothing: the two sides of the cutting surface are joined inside the object "
              "(does the contour go all the way around the part?)");
        }
      }
    }
  };
  const int64_t chunk = 1 << 16;
  int64_t grown = 0;
  while (!a.done() && !b.done()) {
    grow(a, chunk);
    grow(b, chunk);
    grown += 2 * chunk;
    progress.report(0.2 + 0.6 * std::min(1.0, double(grown) / double(g.voxelCount())), "split");
  }
  // With a seed, both sides must be known exactly to tell which one holds it.
  if (options.keepSeed) {
    while (!a.done() || !b.done()) {
      grow(a, chunk);
      grow(b, chunk);
      progress.check();
    }
  }
  const Growth& small = a.done() && (!b.done() || a.size <= b.size) ? a : b;
  const Growth& large = &small == &a ? b : a;
  uint8_t cutSide = small.side;
  if (options.keepSeed) {
    const Index3& s = *options.keepSeed;
    if (!g.contains(s)) throw InvalidArgument("--seed is outside the volume");
    const float value = volume(s[0], s[1], s[2]);
    const uint8_t st = state[size_t(g.linear(s[0], s[1], s[2]))];
    if (value < iso) throw DataError("--seed lies outside the object (value " + std::to_string(value) + " < iso)");
    if (st == kBlocked) throw DataError("--seed lies on the cutting surface; choose a voxel farther from the cut");
    if (st != kSideA && st != kSideB)
      throw DataError("--seed is on neither side of the cut (another part of the object)");
    cutSide = st == small.side ? large.side : small.side;
  }

  // Surface voxels over the disc, its rim beyond the contour included, go to the side of the
  // surface their centre lies on (so an edge the surface follows splits where the image does, and
  // the face's top voxels beside a nose stay with the face: the rim lies on the object's outer
  // surface); only those whose cell leaves the disc go to the side they touch first (a
  // breadth-first pass from both sides through the blocked shell). Every object voxel gets a label.
  assignSurfaceVoxels(volume, iso, surface, offsets, a.side, state);  // a's seeds were placed along +normal
  assignBorderVoxels(volume, iso, cutSide, state);
  progress.report(0.9, "split");

  result.labels = VolumeU8(g, 0);
  uint8_t* labels = result.labels.data();
  const float* v = volume.data();
  for (int64_t i = 0; i < g.voxelCount(); ++i) {
    if (v[i] < iso) continue;
    if (state[size_t(i)] == cutSide) {
      labels[i] = 2;
      ++result.cutVoxels;
    } else {
      labels[i] = 1;
      ++result.keptVoxels;
    }
  }
  progress.report(1.0, "split");
  return result;
}

template <class T>
Volume<T> splitPart(const Volume<T>& volume, const VolumeU8& labels, uint8_t label) {
  if (volume.geometry().dims != labels.geometry().dims)
    throw InvalidArgument("splitPart: the label volume's dimensions differ from the volume's");
  Volume<T> out = volume;
  if (volume.size() == 0) return out;
  const T floor = *std::min_element(volume.voxels().begin(), volume.voxels().end());
  for (int64_t i = 0; i < volume.size(); ++i)
    if (labels.data()[i] != label) out.data()[i] = floor;
  return out;
}

template Volume<uint8_t> splitPart(const Volume<uint8_t>&, const VolumeU8&, uint8_t);
template Volume<int16_t> splitPart(const Volume<int16_t>&, const VolumeU8&, uint8_t);
template Volume<uint16_t> splitPart(const Volume<uint16_t>&, const VolumeU8&, uint8_t);
template Volume<float> splitPart(const Volume<float>&, const VolumeU8&, uint8_t);

}  // namespace vs
