// Tests for tracking/terminal_end.cpp (issue 21): an automatic terminal's end on its vessel's lumen, not on a voxel
// of a masked volume's zero background that the smoothed cost took into the lumen region beside a vessel's end.
#include "tracking/terminal_end.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

#include "tracking/path_support.h"
#include "tracking/trace_run.h"

using namespace vs;

namespace {

// A vessel-only (masked) volume, 1 mm voxels: 150 within radius 1.5 of the segment y = z = 10, x = 4..x1, else 0.
VolumeF32 maskedTube(int64_t x1) {
  Geometry g;
  g.dims = {32, 21, 21};
  g.spacing = Vec3(1, 1, 1);
  VolumeF32 v(g, 0.0f);
  for (int64_t z = 0; z < 21; ++z)
    for (int64_t y = 0; y < 21; ++y)
      for (int64_t x = 4; x <= x1; ++x)
        if (std::hypot(static_cast<double>(y - 10), static_cast<double>(z - 10)) <= 1.5) v(x, y, z) = 150.0f;
  return v;
}

// The chain from x = from back to x = 4 along the tube's axis.
std::vector<Index3> chainFrom(int64_t from) {
  std::vector<Index3> c;
  for (int64_t x = from; x >= 4; --x) c.push_back({x, 10, 10});
  return c;
}

}  // namespace

TEST(TerminalEnd, AnEndOnTheBackgroundPastTheVesselsEndMovesBackOntoIt) {
  const VolumeF32 v = maskedTube(20);
  EXPECT_EQ(endOnLumen(v, chainFrom(22), 1.5), 2u);  // x = 22, 21 are 0: the end at x = 20
  EXPECT_EQ(endOnLumen(v, chainFrom(20), 1.5), 0u);  // on the lumen: kept
}

TEST(TerminalEnd, AStubJoinedThroughABackgroundVoxelIsNoEnd) {
  VolumeF32 v = maskedTube(20);
  v(22, 10, 10) = 150.0f;  // a stub beyond a zero voxel at x = 21
  EXPECT_EQ(endOnLumen(v, chainFrom(22), 1.5), 2u);
}

TEST(TerminalEnd, ATaperingEndRoundTheHalfMaximumIsKept) {
  VolumeF32 v = maskedTube(20);
  v(21, 10, 10) = 60.0f, v(22, 10, 10) = 50.0f;  // a third of the contrast: a faint tip, not background
  EXPECT_EQ(endOnLumen(v, chainFrom(22), 1.5), 0u);
}

// End to end: a masked tree traced with defaults; every automatic terminal lies on a vessel voxel.
TEST(TerminalEnd, AutomaticTerminalsOfAMaskedTreeLieOnItsVessels) {
  Geometry g;
  g.dims = {64, 64, 40};
  g.spacing = Vec3(0.55, 0.55, 1.0);
  VolumeF32 v(g, 0.0f);
  const Vec3 a(32, 8, 20), b(32, 36, 20), c1(12, 58, 14), c2(54, 56, 27);
  auto seg = [](const Vec3& p, const Vec3& s0, const Vec3& s1) {
    const Vec3 d = s1 - s0;
    const double t = std::clamp((p - s0).dot(d) / d.squaredNorm(), 0.0, 1.0);
    return (p - (s0 + t * d)).cwiseProduct(Vec3(0.55, 0.55, 1.0)).norm();
  };
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        const Vec3 p(static_cast<double>(x), static_cast<double>(y), static_cast<double>(z));
        const double d = std::min({seg(p, a, b) - 1.6, seg(p, b, c1) - 0.9, seg(p, b, c2) - 0.9});
        if (d <= 0) v(x, y, z) = static_cast<float>(150 - 30 * std::max(0.0, p[1] - 40) / 20);
      }
  TraceRequest rq;
  rq.root = {32, 10, 20};
  rq.autoTerminals = 2;
  const TraceResult r = runTrace(v, rq);
  ASSERT_EQ(r.paths.size(), 2u);
  for (const TracedPath& p : r.paths)
    EXPECT_GT(v(p.target[0], p.target[1], p.target[2]), 0.0f)
        << p.target[0] << "," << p.target[1] << "," << p.target[2];
}

namespace {

// 1 mm voxels, background 100: a tube (radius 1.5, 1000) along y = z = 10 from x = 4 to x = 35, then a thread of
// `dim` voxels on the axis from x = 36 to x = 35 + dimLength (session 39 end71: the renal artery and the tissue past
// its end).
VolumeF32 tubeThenThread(float dim, int64_t dimLength) {
  Geometry g;
  g.dims = {64, 21, 21};
  g.spacing = Vec3(1, 1, 1);
  VolumeF32 v(g, 100.0f);
  for (int64_t z = 0; z < 21; ++z)
    for (int64_t y = 0; y < 21; ++y)
      for (int64_t x = 4; x <= 35; ++x)
        if (std::hypot(static_cast<double>(y - 10), static_cast<double>(z - 10)) <= 1.5) v(x, y, z) = 1000.0f;
  for (int64_t x = 36; x <= 35 + dimLength; ++x) v(x, 10, 10) = dim;
  return v;
}

const std::function<double(const Index3&)> kRadius = [](const Index3&) { return 1.5; };

// The renal hook's shape (session 40 hook): the tube's chain to x = 35, then a dim thread on to x = 50 (y = 10) that
// turns (up to y = 16) and runs back beside its own way out to x = 30, behind where it fell; the chain end first, back
// to x = 4.
std::vector<Index3> hookChain(VolumeF32& v, float dim) {
  std::vector<Index3> out;  // from the tube outward
  for (int64_t x = 4; x <= 50; ++x) out.push_back({x, 10, 10});
  for (int64_t y = 11; y <= 16; ++y) out.push_back({50, y, 10});
  for (int64_t x = 49; x >= 30; --x) out.push_back({x, 16, 10});
  for (const Index3& c : out)
    if (c[0] >= 36 || c[1] != 10) v(c[0], c[1], c[2]) = dim;
  return {out.rbegin(), out.rend()};
}

}  // namespace

TEST(TerminalEnd, ADimStretchPastTheFeedingTubeThatTurnsBackIsCutWhereItFell) {
  VolumeF32 v = tubeThenThread(400.0f, 0);
  const std::vector<Index3> c = hookChain(v, 400.0f);  // below the half-maximum 550, its end behind the fall
  const FadedStretch f = fadedStretch(v, c, c.size(), kRadius);
  ASSERT_TRUE(f.found);
  EXPECT_EQ(c[f.first], (Index3{36, 10, 10}));
  EXPECT_DOUBLE_EQ(f.level, 1000.0);
  EXPECT_DOUBLE_EQ(f.background, 100.0);
  // endOnLumen judges the end by its own first 5 mm (the thread's 400): it keeps it.
  EXPECT_EQ(endOnLumen(v, c, 1.5), 0u);
}

TEST(TerminalEnd, ALongDimStretchThatKeepsGoingIsKept) {
  // A thin vessel's dim continuation falls as far (session 39 end71's head CTA ends) but keeps going: not cut.
  const VolumeF32 v = tubeThenThread(400.0f, 20);
  const std::vector<Index3> c = chainFrom(55);
  EXPECT_FALSE(fadedStretch(v, c, c.size(), kRadius).found);
  // The same thread turned aside (its end 90 degrees or less off the tube's way at the fall) goes on too.
  VolumeF32 w = tubeThenThread(400.0f, 0);
  std::vector<Index3> side;
  for (int64_t y = 18; y > 10; --y) side.push_back({48, y, 10}), w(48, y, 10) = 400.0f;
  for (int64_t x = 48; x >= 4; --x) side.push_back({x, 10, 10});
  for (int64_t x = 36; x <= 48; ++x) w(x, 10, 10) = 400.0f;
  EXPECT_FALSE(fadedStretch(w, side, side.size(), kRadius).found);
}

TEST(TerminalEnd, AStretchAboveTheHalfMaximumOrShorterThanARunIsKept) {
  VolumeF32 bright = tubeThenThread(600.0f, 0);
  const std::vector<Index3> h = hookChain(bright, 600.0f);
  EXPECT_FALSE(fadedStretch(bright, h, h.size(), kRadius).found);  // above 550
  const std::vector<Index3> shortTip = chainFrom(38);              // 3 mm below it: a tip in noise, not a run (5 mm)
  EXPECT_FALSE(fadedStretch(tubeThenThread(400.0f, 3), shortTip, shortTip.size(), kRadius).found);
  // Less than 5 mm of the branch's own tube before the fall (the rest on the paths so far): no level to judge by.
  VolumeF32 dim = tubeThenThread(400.0f, 0);
  const std::vector<Index3> c = hookChain(dim, 400.0f);
  EXPECT_FALSE(fadedStretch(dim, c, 44, kRadius).found);
}

TEST(TerminalEnd, AGradualFadeAlongTheTubeIsKept) {
  VolumeF32 v = tubeThenThread(400.0f, 0);
  for (int64_t x = 4; x <= 55; ++x) v(x, 10, 10) = static_cast<float>(1000.0 - 14.0 * static_cast<double>(x - 4));
  const std::vector<Index3> c = chainFrom(55);
  EXPECT_FALSE(fadedStretch(v, c, c.size(), kRadius).found);  // 5 mm before any voxel it is at most 70 brighter
}

namespace {

// Session 40's fadedStretch as merged (every shell measured where it is placed): the reference the lazy shell must
// match field by field.
FadedStretch eagerFaded(const VolumeF32& vol, const std::vector<Index3>& chain, size_t free,
                        const std::function<double(const Index3&)>& radiusMm,
                        const std::function<double(const Index3&)>& background) {
  const Geometry& g = vol.geometry();
  const double runMm =
      std::max(PathSupportOptions{}.minLengthMm, PathSupportOptions{}.minSpacings * g.spacing.maxCoeff());
  free = std::min(free, chain.size());
  std::vector<double> arc(chain.size(), 0.0), value(chain.size());
  for (size_t i = 0; i < chain.size(); ++i) {
    if (i > 0) arc[i] = arc[i - 1] + mmBetween(g, chain[i], chain[i - 1]);
    value[i] = vol(chain[i][0], chain[i][1], chain[i][2]);
  }
  double shell = std::numeric_limits<double>::quiet_NaN();
  Index3 shellAt{0, 0, 0};
  for (size_t k = free; k-- > 0;) {
    if (arc[k] < runMm) break;
    std::vector<double> lumen;
    size_t j = k + 1;
    for (; j < free && arc[j] - arc[k + 1] <= 5.0; ++j) lumen.push_back(value[j]);
    if (j == free || lumen.empty()) continue;
    const double r = radiusMm(chain[k]);
    if (std::isnan(shell) || mmBetween(g, chain[k], shellAt) > r)
      shell = shellMedian(vol, chain[k], 2 * r + 2, 2 * r + 6), shellAt = chain[k];
    const double level = medianOf(lumen), local = background ? background(chain[k]) : shell;
    const double bg = std::abs(local - level) > std::abs(shell - level) ? local : shell;
    if (std::isnan(bg)) continue;
    for (double& x : lumen) x = std::abs(x - level);
    if (!(std::abs(level - bg) > 3 * medianOf(std::move(lumen)))) continue;
    const double half = bg + 0.5 * (level - bg), sign = level > bg ? 1.0 : -1.0;
    if (sign * (value[k] - half) >= 0) continue;
    const double med = medianOf(std::vector<double>(value.begin(), value.begin() + static_cast<std::ptrdiff_t>(k + 1)));
    if (!(sign * (med - half) < 0)) continue;
    const Vec3 in = mmStep(g, chain[j - 1], chain[k]), net = mmStep(g, chain[k], chain[0]);
    double reach = 0;
    for (size_t i = 0; i <= k; ++i) reach = std::max(reach, mmStep(g, chain[k], chain[i]).norm());
    FadedStretch out;
    if (in.dot(net) < 0 && reach - net.norm() >= runMm)
      out.found = true, out.first = k, out.level = level, out.background = bg, out.medianValue = med,
      out.lengthMm = arc[k];
    return out;
  }
  return {};
}

}  // namespace

TEST(TerminalEnd, TheFallsShellIsMeasuredOnlyWhereItsTestNeedsIt) {
  // With the auto cost's local background, the tube's voxels (at the level, the background 900 below it) pass without
  // a shell: the hook's scan measures one, at the fall (session 40's code measured one every lumen radius, 20 here).
  VolumeF32 v = tubeThenThread(400.0f, 0);
  const std::vector<Index3> c = hookChain(v, 400.0f);
  const std::function<double(const Index3&)> blocks = [](const Index3&) { return 100.0; };
  const FadedStretch f = fadedStretch(v, c, c.size(), kRadius, blocks);
  ASSERT_TRUE(f.found);
  EXPECT_EQ(c[f.first], (Index3{36, 10, 10}));
  EXPECT_EQ(f.shellsRead, 1u);
  // The same as every shell measured, field by field: backgrounds on either side of the level, none (the shell
  // alone), NaN, equal to the level; radii that leave the shell empty (placed again at the next voxel) or are NaN.
  const std::function<double(const Index3&)> noBlocks;
  const std::vector<std::function<double(const Index3&)>> backgrounds{
      blocks,
      noBlocks,
      [](const Index3&) { return std::numeric_limits<double>::quiet_NaN(); },
      [](const Index3&) { return 1000.0; },
      [](const Index3&) { return 1900.0; },
      [](const Index3& x) { return 60.0 + 20.0 * static_cast<double>(x[0] % 7); }};
  const std::vector<std::function<double(const Index3&)>> radii{
      kRadius, [](const Index3& x) { return x[0] % 5 == 0 ? 100.0 : 1.5; },
      [](const Index3& x) { return x[0] % 3 == 0 ? std::numeric_limits<double>::quiet_NaN() : 0.8 + 0.1 * x[0]; }};
  for (const float dim : {400.0f, 600.0f, 150.0f, 1500.0f})
    for (size_t b = 0; b < backgrounds.size(); ++b)
      for (size_t q = 0; q < radii.size(); ++q) {
        VolumeF32 w = tubeThenThread(dim, 0);
        const std::vector<Index3> h = hookChain(w, dim);
        for (const size_t free : {h.size(), size_t{44}, size_t{60}}) {
          const FadedStretch lazy = fadedStretch(w, h, free, radii[q], backgrounds[b]);
          const FadedStretch eager = eagerFaded(w, h, free, radii[q], backgrounds[b]);
          SCOPED_TRACE(testing::Message()
                       << "dim " << dim << " background " << b << " radius " << q << " free " << free);
          EXPECT_EQ(lazy.found, eager.found);
          EXPECT_EQ(lazy.first, eager.first);
          EXPECT_EQ(lazy.level, eager.level);
          EXPECT_EQ(lazy.background, eager.background);
          EXPECT_EQ(lazy.medianValue, eager.medianValue);
          EXPECT_EQ(lazy.lengthMm, eager.lengthMm);
        }
      }
}
