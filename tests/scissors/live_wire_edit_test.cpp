// Anchor editing of the live-wire (scissors/live_wire.h insertAnchor, moveAnchor, removeAnchor,
// snapshot/restore): every edit must give the contour that clicking the new anchors in order
// gives from scratch, keep the segments that do not touch the edited anchor, and be undone
// exactly by restoring a snapshot. Noise images with fixed seeds (every path is a real choice).
#include <gtest/gtest.h>

#include <random>

#include "common/test_images.h"
#include "scissors/live_wire.h"
#include "util/error.h"

using namespace vs;

namespace {

VolumeF32 noise(int64_t w, int64_t h, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> d(0, 255);
  return test::makeImage(w, h, 1.0, 0.8, [&](int64_t, int64_t) { return d(rng); });
}

// The contour clicked through `anchors` in order (closed: then close()).
LiveWireContour clicked(const VolumeF32& img, const std::vector<PixelUV>& anchors, bool closed) {
  LiveWire lw = LiveWire::fromImage(AnyVolume(img));
  lw.setSeed(anchors.at(0));
  for (size_t k = 1; k < anchors.size(); ++k) lw.commit(anchors[k]);
  if (closed) lw.close();
  return lw.contour();
}

void expectSame(const LiveWireContour& a, const LiveWireContour& b, const std::string& what) {
  EXPECT_EQ(a.anchors, b.anchors) << what;
  EXPECT_EQ(a.pixels, b.pixels) << what;
  EXPECT_EQ(a.closed, b.closed) << what;
  EXPECT_NEAR(a.cost, b.cost, 1e-9 * std::max(1.0, b.cost)) << what;
  EXPECT_NEAR(a.lengthMm, b.lengthMm, 1e-9) << what;
}

}  // namespace

TEST(LiveWireEdit, EveryEditEqualsTheContourClickedThroughItsAnchors) {
  for (const unsigned seed : {11u, 12u, 13u}) {
    const VolumeF32 img = noise(48, 40, seed);
    const std::vector<PixelUV> start{{5, 5}, {40, 6}, {42, 34}, {6, 33}};
    for (const bool closed : {false, true}) {
      const std::string what = "seed " + std::to_string(seed) + (closed ? " closed" : " open");
      LiveWire lw = LiveWire::fromImage(AnyVolume(img));
      lw.setSeed(start[0]);
      for (size_t k = 1; k < start.size(); ++k) lw.commit(start[k]);
      if (closed) lw.close();
      const LiveWire::Snapshot original = lw.snapshot();
      const std::vector<LiveWireSegment> before = lw.segments();

      lw.insertAnchor(1, {30, 20});  // into segment 1 (anchors 1 -> 2)
      std::vector<PixelUV> anchors{{5, 5}, {40, 6}, {30, 20}, {42, 34}, {6, 33}};
      expectSame(lw.contour(), clicked(img, anchors, closed), what + " insert");
      // Only segment 1 was re-wired: the others are the same paths.
      EXPECT_EQ(lw.segments()[0].pixels, before[0].pixels) << what;
      EXPECT_EQ(lw.segments()[3].pixels, before[2].pixels) << what;

      lw.moveAnchor(3, {36, 28});
      anchors[3] = {36, 28};
      expectSame(lw.contour(), clicked(img, anchors, closed), what + " move");
      EXPECT_EQ(lw.segments()[0].pixels, before[0].pixels) << what;

      lw.moveAnchor(0, {8, 3});  // the first anchor (closed: the closing segment follows)
      anchors[0] = {8, 3};
      expectSame(lw.contour(), clicked(img, anchors, closed), what + " move first");

      lw.removeAnchor(1);  // a middle anchor: its neighbours joined
      anchors.erase(anchors.begin() + 1);
      expectSame(lw.contour(), clicked(img, anchors, closed), what + " remove middle");

      lw.removeAnchor(0);  // the first: open drops a segment, closed joins across the start
      anchors.erase(anchors.begin());
      expectSame(lw.contour(), clicked(img, anchors, closed), what + " remove first");

      if (!closed) {
        lw.moveAnchor(anchors.size() - 1, {20, 36});  // the open end: the seed follows
        anchors.back() = {20, 36};
        expectSame(lw.contour(), clicked(img, anchors, closed), what + " move end");
        EXPECT_EQ(lw.seed(), (PixelUV{20, 36}));
        EXPECT_EQ(lw.pathTo({2, 2}).front(), (PixelUV{20, 36})) << "the live path starts at the moved end";
        lw.removeAnchor(anchors.size() - 1);
        anchors.pop_back();
        expectSame(lw.contour(), clicked(img, anchors, closed), what + " remove end");
        EXPECT_EQ(lw.seed(), anchors.back());
      } else {
        EXPECT_THROW(lw.removeAnchor(0), InvalidArgument) << "a closed contour keeps 3 anchors";
      }
      // Undo of all of it: the snapshot puts the original contour back exactly.
      lw.restore(original);
      expectSame(lw.contour(), clicked(img, start, closed), what + " restored");
      if (!closed) {
        EXPECT_EQ(lw.pathTo({20, 20}).front(), start.back());
      }
    }
  }
}

TEST(LiveWireEdit, RejectsWhatDoesNotExist) {
  LiveWire lw = LiveWire::fromImage(AnyVolume(noise(20, 16, 3)));
  EXPECT_THROW(lw.moveAnchor(0, {1, 1}), InvalidArgument) << "no anchors yet";
  lw.setSeed({2, 2});
  lw.commit({15, 3});
  lw.commit({15, 12});
  EXPECT_THROW(lw.insertAnchor(2, {8, 8}), InvalidArgument) << "segment 2 of 2";
  EXPECT_THROW(lw.insertAnchor(0, {2, 2}), InvalidArgument) << "on its own end";
  EXPECT_THROW(lw.moveAnchor(3, {8, 8}), InvalidArgument) << "anchor 3 of 3";
  EXPECT_THROW(lw.moveAnchor(1, {2, 2}), InvalidArgument) << "onto its neighbour";
  EXPECT_THROW(lw.moveAnchor(1, {20, 2}), InvalidArgument) << "outside the slice";
  EXPECT_THROW(lw.removeAnchor(5), InvalidArgument);
  const LiveWireContour unchanged = lw.contour();
  EXPECT_EQ(unchanged.anchors.size(), 3u);
  // Removing down to nothing: the seed alone, then no seed.
  lw.removeAnchor(2);
  lw.removeAnchor(0);
  EXPECT_EQ(lw.contour().anchors, (std::vector<PixelUV>{{15, 3}}));
  lw.removeAnchor(0);
  EXPECT_FALSE(lw.hasSeed());
}

TEST(LiveWireEdit, CoolingSwitchedOnAndOffOnALiveWire) {
  // A vertical edge at u = 10: paths from the seed to points further down follow it, so their
  // beginnings agree over the moves and cooling freezes them.
  const VolumeF32 img = test::makeImage(24, 60, 1, 1, [](int64_t u, int64_t) { return u < 10 ? 0.0f : 200.0f; });
  LiveWire lw = LiveWire::fromImage(AnyVolume(img));
  lw.setSeed({10, 2});
  for (int64_t v = 20; v < 50; v += 2) lw.pathTo({10, v});
  EXPECT_TRUE(lw.segments().empty()) << "cooling is off by default";
  lw.setCoolingMoves(3);
  for (int64_t v = 20; v < 50; v += 2) lw.pathTo({10, v});
  ASSERT_FALSE(lw.segments().empty()) << "cooling on: a stable part froze";
  EXPECT_TRUE(lw.segments().front().cooled);
  const size_t frozen = lw.segments().size();
  lw.setCoolingMoves(0);
  for (int64_t v = 50; v < 58; ++v) lw.pathTo({10, v});
  EXPECT_EQ(lw.segments().size(), frozen) << "off again: nothing more froze";
  EXPECT_THROW(lw.setCoolingMoves(-1), InvalidArgument);
}
