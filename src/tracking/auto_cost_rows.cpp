// The local background's rows and points (auto_cost.h: BlockGrid's and LocalBackground's readers): the interpolation
// between the block centres, the own-block clamp, the fold over the scales and the wide lumen's wall against the
// former background. Moved out of auto_cost.cpp unchanged (session 48 speed4: that file was at the size limit).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "tracking/auto_cost.h"

namespace vs {

namespace {
// Block index and weight of voxel coordinate p along axis a of a block grid.
void blockAxis(const BlockGrid& g, int64_t p, int a, int64_t& k0, int64_t& k1, double& f) {
  const double u = (static_cast<double>(p) + 0.5) / static_cast<double>(g.blockVoxels[a]) - 0.5;
  const double uc = std::clamp(u, 0.0, static_cast<double>(g.blocks[a] - 1));
  k0 = static_cast<int64_t>(std::floor(uc));
  k1 = std::min(k0 + 1, g.blocks[a] - 1);
  f = uc - static_cast<double>(k0);
}
}  // namespace

double BlockGrid::at(const std::vector<float>& field, int64_t x, int64_t y, int64_t z) const {
  const int64_t p[3] = {x, y, z};
  int64_t k0[3], k1[3];
  double f[3];
  for (int a = 0; a < 3; ++a) blockAxis(*this, p[a], a, k0[a], k1[a], f[a]);
  auto v = [&](int64_t i, int64_t j, int64_t k) {
    return static_cast<double>(field[static_cast<size_t>((k * blocks[1] + j) * blocks[0] + i)]);
  };
  double r = 0;
  for (int c = 0; c < 8; ++c) {
    const double w = ((c & 1) ? f[0] : 1 - f[0]) * ((c & 2) ? f[1] : 1 - f[1]) * ((c & 4) ? f[2] : 1 - f[2]);
    if (w > 0) r += w * v((c & 1) ? k1[0] : k0[0], (c & 2) ? k1[1] : k0[1], (c & 4) ? k1[2] : k0[2]);
  }
  return r;
}

void BlockGrid::prepareRows(int64_t nx) {
  rowI0.resize(static_cast<size_t>(nx));
  rowI1.resize(rowI0.size());
  rowOwn.resize(rowI0.size());
  rowF.resize(rowI0.size());
  for (int64_t x = 0; x < nx; ++x) {
    int64_t i0, i1;
    blockAxis(*this, x, 0, i0, i1, rowF[static_cast<size_t>(x)]);
    rowI0[static_cast<size_t>(x)] = static_cast<int32_t>(i0);
    rowI1[static_cast<size_t>(x)] = static_cast<int32_t>(i1);
    rowOwn[static_cast<size_t>(x)] = static_cast<int32_t>(std::min(x / blockVoxels[0], blocks[0] - 1));
  }
}

namespace {
// The row (y, z)'s values at the block centres along x: linear in y and z between the four block rows around it.
const std::vector<double>& blockCentreLine(const BlockGrid& g, const std::vector<float>& field, int64_t y, int64_t z) {
  int64_t j0, j1, k0, k1;
  double fy, fz;
  blockAxis(g, y, 1, j0, j1, fy);
  blockAxis(g, z, 2, k0, k1, fz);
  thread_local std::vector<double> line;
  line.resize(static_cast<size_t>(g.blocks[0]));
  for (int64_t i = 0; i < g.blocks[0]; ++i) {
    auto v = [&](int64_t j, int64_t k) {
      return static_cast<double>(field[static_cast<size_t>((k * g.blocks[1] + j) * g.blocks[0] + i)]);
    };
    line[static_cast<size_t>(i)] =
        (1 - fz) * ((1 - fy) * v(j0, k0) + fy * v(j1, k0)) + fz * ((1 - fy) * v(j0, k1) + fy * v(j1, k1));
  }
  return line;
}

// rowNotBeyondOwn on prepared rows, with backgroundRow's fold over the scales (Fold) and the first scale's spread
// (WithSpread) in the same pass (session 47 speed3: one pass, not four; the same operations on the same values).
template <bool Bright, bool Fold, bool WithSpread = false>
void preparedRowNotBeyondOwn(const BlockGrid& g, const std::vector<double>& line, const float* plane,
                             std::vector<double>& out, const double* sl = nullptr, double* so = nullptr) {
  const double* f = g.rowF.data();
  const int32_t *i0 = g.rowI0.data(), *i1 = g.rowI1.data(), *own = g.rowOwn.data();
  double* o = out.data();
  const double* l = line.data();
  for (size_t x = 0; x < out.size(); ++x) {
    const double t = (1 - f[x]) * l[i0[x]] + f[x] * l[i1[x]];
    if constexpr (WithSpread) so[x] = (1 - f[x]) * sl[i0[x]] + f[x] * sl[i1[x]];
    const double b = static_cast<double>(plane[own[x]]);
    const double v = Bright ? std::max(t, b) : std::min(t, b);
    if constexpr (Fold)
      o[x] = Bright ? std::min(o[x], v) : std::max(o[x], v);
    else
      o[x] = v;
  }
}
}  // namespace

void BlockGrid::row(const std::vector<float>& field, int64_t y, int64_t z, std::vector<double>& out) const {
  // The row's values at the block centres along x, then linear between them.
  const std::vector<double>& line = blockCentreLine(*this, field, y, z);
  if (rowF.size() == out.size()) {
    for (size_t x = 0; x < out.size(); ++x)
      out[x] = (1 - rowF[x]) * line[static_cast<size_t>(rowI0[x])] + rowF[x] * line[static_cast<size_t>(rowI1[x])];
    return;
  }
  for (size_t x = 0; x < out.size(); ++x) {
    int64_t i0, i1;
    double fx;
    blockAxis(*this, static_cast<int64_t>(x), 0, i0, i1, fx);
    out[x] = (1 - fx) * line[static_cast<size_t>(i0)] + fx * line[static_cast<size_t>(i1)];
  }
}

void BlockGrid::rowNotBeyondOwn(const std::vector<float>& field, int64_t y, int64_t z, bool bright,
                                std::vector<double>& out, bool fold) const {
  if (rowOwn.size() == out.size() && rowF.size() == out.size()) {
    const std::vector<double>& line = blockCentreLine(*this, field, y, z);
    const int64_t j = std::min(y / blockVoxels[1], blocks[1] - 1), k = std::min(z / blockVoxels[2], blocks[2] - 1);
    const float* plane = field.data() + (k * blocks[1] + j) * blocks[0];
    const auto pass = fold ? (bright ? preparedRowNotBeyondOwn<true, true> : preparedRowNotBeyondOwn<false, true>)
                           : (bright ? preparedRowNotBeyondOwn<true, false> : preparedRowNotBeyondOwn<false, false>);
    pass(*this, line, plane, out, nullptr, nullptr);
    return;
  }
  thread_local std::vector<double> clamped;
  std::vector<double>& r = fold ? clamped : out;
  r.resize(out.size());
  row(field, y, z, r);
  for (size_t x = 0; x < out.size(); ++x) {
    const double b = this->own(field, static_cast<int64_t>(x), y, z);
    r[x] = bright ? std::max(r[x], b) : std::min(r[x], b);
  }
  if (fold)
    for (size_t x = 0; x < out.size(); ++x) out[x] = bright ? std::min(out[x], r[x]) : std::max(out[x], r[x]);
}

double BlockGrid::own(const std::vector<float>& field, int64_t x, int64_t y, int64_t z) const {
  const int64_t i = std::min(x / blockVoxels[0], blocks[0] - 1), j = std::min(y / blockVoxels[1], blocks[1] - 1),
                k = std::min(z / blockVoxels[2], blocks[2] - 1);
  return static_cast<double>(field[static_cast<size_t>((k * blocks[1] + j) * blocks[0] + i)]);
}

namespace {
double backgroundAt(const std::vector<BlockGrid>& scales, bool bright, int64_t x, int64_t y, int64_t z) {
  double best = bright ? std::numeric_limits<double>::infinity() : -std::numeric_limits<double>::infinity();
  for (const BlockGrid& s : scales) {
    // Interpolated, but never more lumen-like than the voxel's own block: across a step between
    // two backgrounds the interpolation undershoots on the brighter side by up to half a block.
    const double t = s.at(s.value, x, y, z), b = s.own(s.value, x, y, z);
    const double v = bright ? std::max(t, b) : std::min(t, b);
    best = bright ? std::min(best, v) : std::max(best, v);
  }
  return best;
}

void backgroundRow(const std::vector<BlockGrid>& scales, bool bright, int64_t y, int64_t z, std::vector<double>& out) {
  // Never more lumen-like than the own block (see backgroundAt); the scales after the first folded into out.
  for (size_t k = 0; k < scales.size(); ++k) scales[k].rowNotBeyondOwn(scales[k].value, y, z, bright, out, k > 0);
}
}  // namespace

double LocalBackground::at(int64_t x, int64_t y, int64_t z) const {
  return backgroundAt(scales, polarity == TubePolarity::Bright, x, y, z);
}

bool LocalBackground::isWall(int64_t x, int64_t y, int64_t z, double v, double b) const {
  if (structure.empty()) return false;
  const uint8_t zone = structure[static_cast<size_t>((z * dims[1] + y) * dims[0] + x)];
  if (zone != 1) return zone != 0;  // 2: the root's window region and its wall
  // Beside the wide lumen's deep part beyond the window, or in the deep part's core: its wall if on the background's
  // side of the half-maximum between its level and the background b.
  const double level = scales.front().own(scales.front().lumenLevel, x, y, z);
  if (std::isnan(level)) return true;
  return polarity == TubePolarity::Bright ? v < 0.5 * (level + b) : v > 0.5 * (level + b);
}

bool LocalBackground::formerDiffers(int64_t x, int64_t y, int64_t z) const {
  for (const BlockGrid& s : structureScales) {
    const int64_t i = std::min(x / s.blockVoxels[0], s.blocks[0] - 1),
                  j = std::min(y / s.blockVoxels[1], s.blocks[1] - 1),
                  k = std::min(z / s.blockVoxels[2], s.blocks[2] - 1);
    if (s.differs[static_cast<size_t>((k * s.blocks[1] + j) * s.blocks[0] + i)]) return true;
  }
  return false;
}

double LocalBackground::at(int64_t x, int64_t y, int64_t z, double v) const {
  const double b = at(x, y, z);
  if (formerDiffers(x, y, z) && isWall(x, y, z, v, b))
    return backgroundAt(structureScales, polarity == TubePolarity::Bright, x, y, z);
  return b;
}

double LocalBackground::spreadAt(int64_t x, int64_t y, int64_t z) const {
  return scales.empty() ? 0.0 : scales.front().at(scales.front().spread, x, y, z);
}

void LocalBackground::row(int64_t y, int64_t z, std::vector<double>& out) const {
  backgroundRow(scales, polarity == TubePolarity::Bright, y, z, out);
}

void LocalBackground::rowWithSpread(int64_t y, int64_t z, std::vector<double>& out, std::vector<double>& spread) const {
  const BlockGrid& s = scales.front();
  if (s.rowOwn.size() != out.size() || s.rowF.size() != out.size() || spread.size() != out.size()) {
    row(y, z, out);
    s.row(s.spread, y, z, spread);
    return;
  }
  thread_local std::vector<double> spreadLine;
  spreadLine = blockCentreLine(s, s.spread, y, z);
  const std::vector<double>& line = blockCentreLine(s, s.value, y, z);
  const int64_t j = std::min(y / s.blockVoxels[1], s.blocks[1] - 1),
                k = std::min(z / s.blockVoxels[2], s.blocks[2] - 1);
  const float* plane = s.value.data() + (k * s.blocks[1] + j) * s.blocks[0];
  const bool bright = polarity == TubePolarity::Bright;
  (bright ? preparedRowNotBeyondOwn<true, false, true>
          : preparedRowNotBeyondOwn<false, false, true>)(s, line, plane, out, spreadLine.data(), spread.data());
  for (size_t m = 1; m < scales.size(); ++m) scales[m].rowNotBeyondOwn(scales[m].value, y, z, bright, out, true);
}

void LocalBackground::wallRow(int64_t y, int64_t z, const float* v, std::vector<double>& out) const {
  if (structure.empty()) return;
  const size_t base = static_cast<size_t>((z * dims[1] + y) * dims[0]);
  // Whether the row holds any of the zone: ORed whole (a branch-free pass; most rows hold none).
  uint8_t any = 0;
  for (size_t x = 0; x < out.size(); ++x) any |= structure[base + x];
  if (!any) return;
  const bool bright = polarity == TubePolarity::Bright;
  for (size_t x = 0; x < out.size(); ++x)
    if (structure[base + x] && formerDiffers(static_cast<int64_t>(x), y, z) &&
        isWall(static_cast<int64_t>(x), y, z, v[x], out[x]))
      out[x] = backgroundAt(structureScales, bright, static_cast<int64_t>(x), y, z);
}

}  // namespace vs
