// Tests for scissors/live_wire: brute-force reference (Bellman-Ford over the same edge costs),
// path validity, resumed vs fresh searches, the interaction model (commit/close/undo/snap/
// cooling), the contour fill, the shapes2d phantom (Hausdorff to the true boundary) and a real
// CT slice (area vs a threshold segmentation).
#include "scissors/live_wire.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <limits>
#include <numbers>
#include <random>

#include "common/test_images.h"
#include "graph/grid_graph.h"
#include "io/volume_io.h"
#include "phantom/phantom.h"

using namespace vs;

namespace {

VolumeF32 image(int64_t w, int64_t h, double su, double sv, const std::function<float(int64_t, int64_t)>& fn) {
  return test::makeImage(w, h, su, sv, fn);
}

VolumeF32 noise(int64_t w, int64_t h, double su, double sv, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> d(0, 255);
  return image(w, h, su, sv, [&](int64_t, int64_t) { return d(rng); });
}

// Bellman-Ford over the live-wire's own directed edge costs (engine direction order).
std::vector<double> bellmanFord(const LiveWire& lw, PixelUV src) {
  const int64_t w = lw.width(), h = lw.height(), n = w * h;
  const GridGraph g({w, h, 1}, {1, 1, 1}, lw.options().connectivity);
  const int K = g.directionCount();
  std::vector<double> d(static_cast<size_t>(n), std::numeric_limits<double>::infinity());
  d[static_cast<size_t>(src[0] + w * src[1])] = 0;
  for (int64_t iter = 0; iter < n; ++iter) {
    bool changed = false;
    for (int64_t p = 0; p < n; ++p) {
      if (std::isinf(d[static_cast<size_t>(p)])) continue;
      for (int k = 0; k < K; ++k) {
        const int64_t q = g.neighbor(p, k);
        if (q < 0) continue;
        const double c = d[static_cast<size_t>(p)] + lw.edgeCosts()[static_cast<size_t>(p * K + k)];
        if (c < d[static_cast<size_t>(q)] - 1e-12) {
          d[static_cast<size_t>(q)] = c;
          changed = true;
        }
      }
    }
    if (!changed) break;
  }
  return d;
}

// Sum of the edge costs along a pixel chain; fails the test if two pixels are not neighbours.
double chainCost(const LiveWire& lw, const std::vector<PixelUV>& px) {
  const GridGraph g({lw.width(), lw.height(), 1}, {1, 1, 1}, lw.options().connectivity);
  double c = 0;
  for (size_t i = 0; i + 1 < px.size(); ++i) {
    const int k = g.direction(static_cast<int>(px[i + 1][0] - px[i][0]), static_cast<int>(px[i + 1][1] - px[i][1]), 0);
    EXPECT_GE(k, 0) << "pixels " << i << " and " << i + 1 << " are not neighbours";
    if (k < 0) return std::numeric_limits<double>::quiet_NaN();
    c += lw.edgeCosts()[static_cast<size_t>((px[i][0] + lw.width() * px[i][1]) * g.directionCount() + k)];
  }
  return c;
}

void expectValidPath(const std::vector<PixelUV>& px, PixelUV from, PixelUV to) {
  ASSERT_FALSE(px.empty());
  EXPECT_EQ(px.front(), from);
  EXPECT_EQ(px.back(), to);
  for (size_t i = 0; i + 1 < px.size(); ++i) {
    const int64_t du = std::abs(px[i + 1][0] - px[i][0]), dv = std::abs(px[i + 1][1] - px[i][1]);
    EXPECT_TRUE(std::max(du, dv) == 1) << "step " << i << " is not an 8-neighbour step";
  }
}

}  // namespace

TEST(LiveWire, MatchesBellmanFordOnTinyImages) {
  for (const auto& [cost, conn, su, sv] : std::vector<std::tuple<LiveWireCostKind, int, double, double>>{
           {LiveWireCostKind::MortensenBarrett, 8, 1.0, 1.0},
           {LiveWireCostKind::MortensenBarrett, 8, 0.5, 1.5},
           {LiveWireCostKind::Gradient, 8, 1.0, 2.0},
           {LiveWireCostKind::MortensenBarrett, 4, 1.0, 1.0}}) {
    for (unsigned seed = 1; seed <= 3; ++seed) {
      LiveWireOptions o;
      o.cost.kind = cost;
      o.connectivity = conn;
      LiveWire lw = LiveWire::fromImage(noise(9, 7, su, sv, seed), o);
      const PixelUV src{static_cast<int64_t>(seed) % 9, 3};
      const auto ref = bellmanFord(lw, src);
      lw.setSeed(src);
      for (int64_t v = 0; v < 7; ++v)
        for (int64_t u = 0; u < 9; ++u) {
          const auto& px = lw.pathTo({u, v});
          expectValidPath(px, src, {u, v});
          const double c = chainCost(lw, px);
          EXPECT_NEAR(c, ref[static_cast<size_t>(u + 9 * v)], 1e-4 * (1 + c)) << "target " << u << "," << v;
          if (conn == 4) {
            for (size_t i = 0; i + 1 < px.size(); ++i)
              EXPECT_EQ(std::abs(px[i + 1][0] - px[i][0]) + std::abs(px[i + 1][1] - px[i][1]), 1);
          }
        }
      EXPECT_EQ(lw.searchStarts(), 1) << "the seed's search must be resumed, not restarted";
      // A committed segment reports the same cost.
      const auto& seg = lw.commit({8 - src[0], 6});
      EXPECT_NEAR(seg.cost, ref[static_cast<size_t>(8 - src[0] + 9 * 6)], 1e-4 * (1 + seg.cost));
    }
  }
}

TEST(LiveWire, ResumedQueriesEqualFreshOnes) {
  const auto img = noise(40, 30, 1.0, 1.0, 11);
  LiveWire resumed = LiveWire::fromImage(img);
  resumed.setSeed({5, 5});
  std::mt19937 rng(3);
  for (int i = 0; i < 25; ++i) {
    const PixelUV t{static_cast<int64_t>(rng() % 40), static_cast<int64_t>(rng() % 30)};
    const std::vector<PixelUV> a = resumed.pathTo(t);
    LiveWire fresh = LiveWire::fromImage(img);
    fresh.setSeed({5, 5});
    const std::vector<PixelUV> b = fresh.pathTo(t);
    EXPECT_NEAR(chainCost(resumed, a), chainCost(fresh, b), 1e-6);
    EXPECT_EQ(a, b) << "target " << t[0] << "," << t[1];
  }
  EXPECT_EQ(resumed.searchStarts(), 1);
}

TEST(LiveWire, CancelledMapResumesToTheSamePaths) {
  const auto img = noise(600, 600, 1.0, 1.0, 5);  // 360000 pixels: several progress chunks
  LiveWire lw = LiveWire::fromImage(img);
  lw.setSeed({10, 10});
  std::vector<double> fractions;
  Progress cancelling([&](double f, const std::string& stage) {
    EXPECT_EQ(stage, "search");
    fractions.push_back(f);
  });
  cancelling.cancel();
  EXPECT_THROW(lw.buildMap(cancelling), Cancelled);
  Progress counting([&](double f, const std::string&) { fractions.push_back(f); });
  lw.buildMap(counting);
  EXPECT_EQ(lw.settledCount(), 600 * 600);
  ASSERT_FALSE(fractions.empty());
  EXPECT_GT(fractions.back(), 0.5);
  LiveWire fresh = LiveWire::fromImage(img);
  fresh.setSeed({10, 10});
  const PixelUV t{590, 580};
  EXPECT_EQ(lw.pathTo(t), fresh.pathTo(t));
  EXPECT_EQ(lw.searchStarts(), 1);
}

TEST(LiveWire, FlatImageGivesValidStraightPaths) {
  LiveWire lw = LiveWire::fromImage(image(20, 10, 1.0, 1.0, [](int64_t, int64_t) { return 5.0f; }));
  lw.setSeed({2, 2});
  const auto& px = lw.pathTo({12, 2});
  expectValidPath(px, {2, 2}, {12, 2});
  EXPECT_EQ(px.size(), 11u);  // straight: diagonals are not favoured (costs proportional to length)
  const auto& diag = lw.pathTo({9, 9});
  expectValidPath(diag, {2, 2}, {9, 9});
  EXPECT_EQ(diag.size(), 8u);
}

TEST(LiveWire, CommitCloseUndo) {
  // A bright square on dark ground: clicks on the four corners, closed along the square's edges.
  // (With only three corners the way back along the other two sides costs exactly as much as
  // retracing, so the closing path may retrace: live-wire needs a click on each side.)
  LiveWire lw = LiveWire::fromImage(image(40, 40, 1.0, 1.0, [](int64_t u, int64_t v) {
    return (u >= 10 && u <= 29 && v >= 10 && v <= 29) ? 200.0f : 20.0f;
  }));
  EXPECT_FALSE(lw.hasSeed());
  EXPECT_THROW(lw.pathTo({1, 1}), InvalidArgument);
  lw.setSeed({10, 10});
  lw.commit({29, 10});
  lw.commit({29, 29});
  lw.commit({10, 29});
  EXPECT_EQ(lw.segments().size(), 3u);
  EXPECT_EQ(lw.seed(), (PixelUV{10, 29}));
  lw.close();
  EXPECT_TRUE(lw.closed());
  EXPECT_THROW(lw.commit({5, 5}), InvalidArgument);
  EXPECT_THROW(lw.close(), InvalidArgument);
  const LiveWireContour c = lw.contour();
  EXPECT_TRUE(c.closed);
  EXPECT_EQ(c.anchors.size(), 4u);
  // The contour follows the square's edge (the pixel rings just inside or just outside it).
  for (const auto& p : c.pixels) {
    const int64_t d =
        std::max(std::abs(2 * p[0] - 39), std::abs(2 * p[1] - 39));  // 2 x Chebyshev distance to the centre
    EXPECT_TRUE(d == 19 || d == 21) << p[0] << "," << p[1];
  }
  EXPECT_GE(c.lengthMm, 76.0 - 1e-9);
  EXPECT_LE(c.lengthMm, 84.0 + 1e-9);
  EXPECT_NEAR(c.lengthMm, contourLengthMm(c.pixels, true, 1, 1), 1e-9);
  for (size_t i = 0; i < c.pixels.size(); ++i) {
    const auto& a = c.pixels[i];
    const auto& b = c.pixels[(i + 1) % c.pixels.size()];
    EXPECT_EQ(std::max(std::abs(a[0] - b[0]), std::abs(a[1] - b[1])), 1);
  }
  const auto mask = fillContour(c.pixels, 40, 40);
  int64_t area = 0;
  for (auto m : mask) area += m;
  EXPECT_GE(area, 400);  // the whole 20x20 square, boundary included
  EXPECT_LE(area, 484);

  // undo: reopen, then remove segments one by one, then the seed.
  EXPECT_TRUE(lw.undo());
  EXPECT_FALSE(lw.closed());
  EXPECT_EQ(lw.segments().size(), 3u);
  EXPECT_TRUE(lw.undo());
  EXPECT_EQ(lw.seed(), (PixelUV{29, 29}));
  EXPECT_TRUE(lw.undo());
  EXPECT_EQ(lw.segments().size(), 1u);
  EXPECT_EQ(lw.seed(), (PixelUV{29, 10}));
  expectValidPath(lw.pathTo({29, 29}), {29, 10}, {29, 29});
  EXPECT_TRUE(lw.undo());
  EXPECT_EQ(lw.seed(), (PixelUV{10, 10}));
  EXPECT_TRUE(lw.undo());
  EXPECT_FALSE(lw.hasSeed());
  EXPECT_FALSE(lw.undo());
}

TEST(LiveWire, CloseWhenTheLastClickIsTheFirstPoint) {
  LiveWire lw = LiveWire::fromImage(noise(16, 16, 1, 1, 5));
  lw.setSeed({2, 2});
  lw.commit({12, 3});
  lw.commit({8, 12});
  lw.commit({2, 2});
  lw.close();
  EXPECT_EQ(lw.segments().size(), 3u);
  const auto c = lw.contour();
  EXPECT_NE(c.pixels.back(), c.pixels.front());
  EXPECT_TRUE(lw.undo());  // only reopens
  EXPECT_EQ(lw.segments().size(), 3u);
  EXPECT_FALSE(lw.closed());
}

TEST(LiveWire, RejectsBadPoints) {
  LiveWire lw = LiveWire::fromImage(noise(10, 8, 1, 1, 2));
  EXPECT_THROW(lw.setSeed({10, 0}), InvalidArgument);
  EXPECT_THROW(lw.setSeed({0, -1}), InvalidArgument);
  lw.setSeed({3, 3});
  EXPECT_THROW(lw.pathTo({0, 8}), InvalidArgument);
  EXPECT_THROW(lw.commit({3, 3}), InvalidArgument);  // seed equal to the target
  EXPECT_THROW(lw.close(), InvalidArgument);         // needs two points
  EXPECT_THROW(lw.snap({-1, 0}, 2), InvalidArgument);
  EXPECT_THROW(lw.snap({1, 1}, -2), InvalidArgument);
  LiveWireOptions bad;
  bad.connectivity = 6;
  EXPECT_THROW(LiveWire::fromImage(noise(4, 4, 1, 1, 1), bad), InvalidArgument);
  // A seed path to itself is the single pixel.
  EXPECT_EQ(lw.pathTo({3, 3}).size(), 1u);
}

TEST(LiveWire, SnapMovesToTheStrongestEdgeWithinTheRadius) {
  // Vertical step at u = 14/15 (strongest gradient there).
  LiveWire lw = LiveWire::fromImage(image(30, 20, 1, 1, [](int64_t u, int64_t) { return u < 15 ? 0.0f : 100.0f; }));
  const PixelUV s = lw.snap({11, 7}, 4.0);
  EXPECT_EQ(s[1], 7);
  EXPECT_TRUE(s[0] == 14 || s[0] == 15);
  EXPECT_EQ(s, (PixelUV{14, 7}));                      // tie between 14 and 15: the nearer one
  EXPECT_EQ(lw.snap({11, 7}, 2.0), (PixelUV{11, 7}));  // edge out of reach: unchanged (all gradients 0 there)
  EXPECT_EQ(lw.snap({11, 7}, 0.0), (PixelUV{11, 7}));
}

TEST(LiveWire, PathCoolingFreezesTheStablePart) {
  // A bright disc: the cursor jitters near the far side; the common part of the live paths freezes.
  LiveWireOptions o;
  o.coolingMoves = 3;
  o.coolingMinPixels = 5;
  LiveWire lw = LiveWire::fromImage(
      image(64, 64, 1, 1, [](int64_t u, int64_t v) { return std::hypot(u - 32.0, v - 32.0) < 20 ? 200.0f : 30.0f; }),
      o);
  lw.setSeed({12, 32});
  const std::vector<PixelUV> cursor = {{46, 46}, {46, 47}, {47, 46}, {46, 45}};  // bottom right: no tie between ways
  std::vector<PixelUV> last;
  for (const auto& p : cursor) last = lw.pathTo(p);
  ASSERT_FALSE(lw.segments().empty()) << "nothing was cooled";
  EXPECT_TRUE(lw.segments().front().cooled);
  EXPECT_EQ(lw.segments().front().from, (PixelUV{12, 32}));
  EXPECT_EQ(lw.seed(), lw.segments().back().to);
  expectValidPath(last, lw.seed(), cursor.back());
  // Contour so far + live path is still one connected chain from the first point.
  const auto c = lw.contour();
  expectValidPath(c.pixels, {12, 32}, lw.seed());
  EXPECT_GE(lw.searchStarts(), 2);
  // Without cooling nothing is committed.
  LiveWire plain = LiveWire::fromImage(image(8, 8, 1, 1, [](int64_t u, int64_t) { return float(u); }));
  plain.setSeed({0, 0});
  for (int i = 0; i < 5; ++i) plain.pathTo({7, 7});
  EXPECT_TRUE(plain.segments().empty());
}

TEST(ContourFill, FillsPolygonInteriorWithBoundary) {
  // Diamond |u - 10| + |v - 10| <= 5 traced as an 8-connected ring.
  std::vector<PixelUV> ring;
  for (int i = 0; i < 5; ++i) ring.push_back({10 + i, 5 + i});
  for (int i = 0; i < 5; ++i) ring.push_back({15 - i, 10 + i});
  for (int i = 0; i < 5; ++i) ring.push_back({10 - i, 15 - i});
  for (int i = 0; i < 5; ++i) ring.push_back({5 + i, 10 - i});
  const auto m = fillContour(ring, 21, 21);
  for (int64_t v = 0; v < 21; ++v)
    for (int64_t u = 0; u < 21; ++u)
      EXPECT_EQ(m[static_cast<size_t>(u + 21 * v)], (std::abs(u - 10) + std::abs(v - 10) <= 5) ? 1 : 0)
          << u << "," << v;
  EXPECT_THROW(fillContour({{0, 0}, {30, 0}}, 21, 21), InvalidArgument);
  EXPECT_EQ(sliceToVolumeIndex(0, 7, {1, 2}), (Index3{7, 1, 2}));
  EXPECT_EQ(sliceToVolumeIndex(1, 7, {1, 2}), (Index3{1, 7, 2}));
  EXPECT_EQ(sliceToVolumeIndex(2, 7, {1, 2}), (Index3{1, 2, 7}));
}

namespace {
// Symmetric Hausdorff distance (pixels) between a pixel contour and a dense boundary polygon.
double hausdorff(const std::vector<PixelUV>& contour, const std::vector<Vec2>& boundary) {
  double h = 0;
  for (const auto& p : contour) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& b : boundary) best = std::min(best, std::hypot(b.x() - p[0], b.y() - p[1]));
    h = std::max(h, best);
  }
  for (const auto& b : boundary) {
    double best = std::numeric_limits<double>::infinity();
    for (const auto& p : contour) best = std::min(best, std::hypot(b.x() - p[0], b.y() - p[1]));
    h = std::max(h, best);
  }
  return h;
}
}  // namespace

TEST(LiveWire, ShapesPhantomContoursLieOnTheTrueBoundary) {
  Shapes2DOptions po;
  po.width = po.height = 256;
  const Shapes2DPhantom ph = makeShapes2DPhantom(po);
  ASSERT_EQ(ph.truth.shapes.size(), 4u);
  LiveWireOptions o;
  o.features.smoothSigmaMm = 1.0;
  LiveWire lw = LiveWire::fromImage(AnyVolume(ph.image), o);
  for (const Shape2D& shape : ph.truth.shapes) {
    const int clicks = shape.kind == ShapeKind::Star ? 6 : shape.kind == ShapeKind::RoundedRect ? 5 : 4;
    const size_t nb = shape.boundary.size();
    std::vector<PixelUV> pts;
    for (int i = 0; i < clicks; ++i) {
      const Vec2& b = shape.boundary[nb * static_cast<size_t>(i) / static_cast<size_t>(clicks)];
      pts.push_back({std::llround(b.x()), std::llround(b.y())});
    }
    lw.setSeed(pts[0]);
    for (size_t i = 1; i < pts.size(); ++i) lw.commit(pts[i]);
    lw.close();
    const auto c = lw.contour();
    const double h = hausdorff(c.pixels, shape.boundary);
    std::cout << "[ shapes2d ] " << shapeKindName(shape.kind) << ": " << clicks << " clicks, " << c.pixels.size()
              << " contour pixels, Hausdorff " << h << " px\n";
    EXPECT_LE(h, 1.5) << shapeKindName(shape.kind);
    // Area of the filled mask vs the label image.
    const auto mask = fillContour(c.pixels, ph.image.dims()[0], ph.image.dims()[1]);
    int64_t inter = 0, a = 0, b = 0;
    for (size_t i = 0; i < mask.size(); ++i) {
      const bool l = ph.labels.voxels()[i] == shape.label;
      a += mask[i];
      b += l;
      inter += (mask[i] && l);
    }
    EXPECT_GT(2.0 * inter / static_cast<double>(a + b), 0.95) << shapeKindName(shape.kind);
  }
}

TEST(LiveWire, SkullOutlineOnRealCtMatchesThresholdArea) {
  // Axial slice z = 90 of the InVesalius head CT: the skull is a closed bone ring there. Truth:
  // threshold segmentation bone > 300 HU with its holes filled (everything inside the outer
  // skull boundary). The live-wire gets 8 points on that boundary (outermost mask pixel on rays
  // at 45 degree steps from the centroid) and is closed.
  // Tolerance: the live-wire follows the Laplacian zero crossing of the bone/soft tissue edge
  // (about half way, ~500 HU) while the threshold sits at 300 HU, so the two outlines may be
  // up to one pixel apart all around: |area difference| <= perimeter (in pixels) x 1 pixel.
  const std::string path = std::string(VS_SHARED_DATA_DIR) + "/head_ct_cranium_invesalius/cranium.nhdr";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data missing: " << path;
  const AnyVolume vol = readVolume(path);
  const auto& ct = std::get<VolumeI16>(vol);
  const int64_t z = 90;
  ASSERT_GT(ct.dims()[2], z);
  const int64_t w = ct.dims()[0], h = ct.dims()[1];
  // Threshold + fill holes (flood the non-bone pixels from the image border, 4-connected).
  std::vector<uint8_t> outside(static_cast<size_t>(w * h), 0);
  std::vector<int64_t> stack;
  auto push = [&](int64_t u, int64_t v) {
    if (u < 0 || v < 0 || u >= w || v >= h) return;
    const auto i = static_cast<size_t>(u + w * v);
    if (outside[i] || ct(u, v, z) > 300) return;
    outside[i] = 1;
    stack.push_back(u + w * v);
  };
  for (int64_t u = 0; u < w; ++u) push(u, 0), push(u, h - 1);
  for (int64_t v = 0; v < h; ++v) push(0, v), push(w - 1, v);
  while (!stack.empty()) {
    const int64_t i = stack.back();
    stack.pop_back();
    const int64_t u = i % w, v = i / w;
    push(u - 1, v), push(u + 1, v), push(u, v - 1), push(u, v + 1);
  }
  // Keep the component of the filled mask at the image centre (the head; drops the headrest arc).
  std::vector<uint8_t> head(static_cast<size_t>(w * h), 0);
  auto grow = [&](int64_t u, int64_t v) {
    if (u < 0 || v < 0 || u >= w || v >= h) return;
    const auto i = static_cast<size_t>(u + w * v);
    if (head[i] || outside[i]) return;
    head[i] = 1;
    stack.push_back(u + w * v);
  };
  grow(w / 2, h / 2);
  while (!stack.empty()) {
    const int64_t i = stack.back();
    stack.pop_back();
    const int64_t u = i % w, v = i / w;
    grow(u - 1, v), grow(u + 1, v), grow(u, v - 1), grow(u, v + 1);
  }
  int64_t areaThr = 0, perimeter = 0;
  double cu = 0, cv = 0;
  auto inside = [&](int64_t u, int64_t v) {
    return u >= 0 && v >= 0 && u < w && v < h && head[static_cast<size_t>(u + w * v)];
  };
  for (int64_t v = 0; v < h; ++v)
    for (int64_t u = 0; u < w; ++u)
      if (inside(u, v)) {
        ++areaThr, cu += double(u), cv += double(v);
        if (!inside(u - 1, v) || !inside(u + 1, v) || !inside(u, v - 1) || !inside(u, v + 1)) ++perimeter;
      }
  ASSERT_GT(areaThr, 5000) << "unexpected threshold segmentation";
  cu /= double(areaThr), cv /= double(areaThr);
  std::vector<PixelUV> pts;
  for (int k = 0; k < 8; ++k) {
    const double a = k * std::numbers::pi / 4;
    PixelUV last{std::llround(cu), std::llround(cv)};
    for (double r = 0; r < double(w + h); r += 0.25) {
      const PixelUV p{std::llround(cu + r * std::cos(a)), std::llround(cv + r * std::sin(a))};
      if (inside(p[0], p[1])) last = p;
    }
    pts.push_back(last);
  }
  std::cout << "[ cranium z=90 ] points";
  for (const auto& p : pts) std::cout << ' ' << p[0] << ',' << p[1];
  std::cout << '\n';
  LiveWire lw = LiveWire::fromSlice(sliceView(ct, 2, z));
  lw.setSeed(pts[0]);
  for (size_t i = 1; i < pts.size(); ++i) lw.commit(pts[i]);
  lw.close();
  const auto c = lw.contour();
  const auto mask = fillContour(c.pixels, w, h);
  int64_t areaLw = 0, inter = 0;
  for (int64_t i = 0; i < w * h; ++i) {
    areaLw += mask[static_cast<size_t>(i)];
    inter += mask[static_cast<size_t>(i)] && head[static_cast<size_t>(i)];
  }
  const double dice = 2.0 * double(inter) / double(areaLw + areaThr);
  std::cout << "[ cranium z=90 ] threshold area " << areaThr << " px, live-wire area " << areaLw << " px ("
            << 100.0 * double(areaLw - areaThr) / double(areaThr) << " %), perimeter " << perimeter << " px, Dice "
            << dice << ", contour " << c.pixels.size() << " px, " << c.lengthMm << " mm\n";
  EXPECT_LE(std::abs(areaLw - areaThr), perimeter);
  EXPECT_GT(dice, 0.97);
}
