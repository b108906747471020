// The live-wire tool's anchor editing and path cooling (app/livewire_edit.cpp), GL-free: each
// edit is one undo step, undo/redo give back the contours exactly, the edited contour equals the
// one clicked through its anchors (which is what the session stores, so it reopens the same),
// the script commands do the same, and path cooling is an option of the tool, script and session.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/script.h"
#include "app/viewer_app.h"
#include "util/error.h"

namespace fs = std::filesystem;
using namespace vs;
using namespace vs::viewer;

namespace {

void script(ViewerApp& app, const std::string& s) {
  std::istringstream in(s);
  runScript(app, in, nullptr, "test");
}

// A fresh app on the same phantom slice with `anchors` clicked in order (and closed).
LiveWireContour clickedThrough(const std::vector<PixelUV>& anchors, bool closed) {
  ViewerApp b;
  b.loadHeadPhantom(64);
  b.setTool(ToolKind::LiveWire);
  b.setLiveWireSlice(2, 32);
  for (const PixelUV& p : anchors) b.point2(p);
  if (closed) b.closeContour();
  return b.liveWire().contour();
}

}  // namespace

TEST(LiveWireEditTool, InsertMoveDeleteAreUndoStepsAndRewireBetweenNeighbours) {
  ViewerApp app;
  app.loadHeadPhantom(64);
  app.setTool(ToolKind::LiveWire);
  app.setLiveWireSlice(2, 32);
  for (const PixelUV& p : std::vector<PixelUV>{{14, 32}, {32, 10}, {50, 32}}) app.point2(p);
  app.closeContour();
  LiveWireTool& lw = app.liveWire();
  const LiveWireContour closed3 = lw.contour();
  ASSERT_EQ(lw.clicks().size(), 3u);

  // Insert near the contour between anchors 1 and 2: the tool finds that segment.
  const PixelUV onSegment = closed3.pixels[closed3.pixels.size() * 1 / 2];
  ASSERT_EQ(lw.segmentNear(onSegment, 2), std::optional<size_t>(1));
  lw.insertAnchor(PixelUV{onSegment[0] + 3, onSegment[1] + 3});
  ASSERT_EQ(lw.clicks().size(), 4u);
  EXPECT_EQ(lw.clicks()[2], (PixelUV{onSegment[0] + 3, onSegment[1] + 3}));
  const LiveWireContour inserted = lw.contour();
  EXPECT_EQ(inserted.pixels, clickedThrough(lw.clicks(), true).pixels);
  EXPECT_NE(inserted.pixels, closed3.pixels);

  // Move anchor 1 (found under the mouse within a radius) and delete anchor 3.
  ASSERT_EQ(lw.anchorNear({33, 11}, 3), std::optional<size_t>(1));
  EXPECT_FALSE(lw.anchorNear({33, 20}, 3).has_value());
  lw.moveAnchor(1, {30, 14});
  EXPECT_EQ(lw.clicks()[1], (PixelUV{30, 14}));
  const LiveWireContour moved = lw.contour();
  EXPECT_EQ(moved.pixels, clickedThrough(lw.clicks(), true).pixels);
  lw.removeAnchor(3);
  const LiveWireContour deleted = lw.contour();
  EXPECT_EQ(lw.clicks().size(), 3u);
  EXPECT_EQ(deleted.pixels, clickedThrough(lw.clicks(), true).pixels);
  EXPECT_THROW(lw.removeAnchor(0), InvalidArgument) << "a closed contour keeps 3 anchors";
  EXPECT_THROW(lw.moveAnchor(7, {1, 1}), InvalidArgument);

  // Undo walks back through every edit exactly, redo forward again; a new click would need the
  // close undone (the contour stays closed through the edits).
  EXPECT_EQ(lw.undoSteps(), 7u);  // 3 clicks, close, insert, move, delete
  ASSERT_TRUE(app.undo());
  EXPECT_EQ(lw.contour().pixels, moved.pixels);
  ASSERT_TRUE(app.undo());
  EXPECT_EQ(lw.contour().pixels, inserted.pixels);
  ASSERT_TRUE(app.undo());
  EXPECT_EQ(lw.contour().pixels, closed3.pixels);
  EXPECT_EQ(lw.clicks().size(), 3u);
  ASSERT_TRUE(app.undo());  // the close
  EXPECT_FALSE(lw.contour().closed);
  ASSERT_TRUE(app.redo());
  ASSERT_TRUE(app.redo());
  ASSERT_TRUE(app.redo());
  ASSERT_TRUE(app.redo());
  EXPECT_EQ(lw.contour().pixels, deleted.pixels);
  EXPECT_FALSE(app.redo());

  // The session stores the anchors: it reopens to the edited contour.
  const fs::path file = fs::temp_directory_path() / ("vs_lw_edit_" + std::to_string(::getpid()) + ".json");
  app.saveSession(file.string());
  ViewerApp b;
  b.loadSession(file.string());
  fs::remove(file);
  EXPECT_EQ(b.liveWire().contour().pixels, deleted.pixels);
  EXPECT_EQ(b.liveWire().clicks(), lw.clicks());
}

TEST(LiveWireEditTool, ScriptCommandsEditAnchors) {
  ViewerApp app;
  app.loadHeadPhantom(64);
  script(app, "tool livewire\nslice z=32\npoint 14,32\npoint 32,10\npoint 50,32\npoint 32,54\n");
  const std::vector<PixelUV> four = app.liveWire().clicks();
  script(app, "anchor-insert 45,18\nanchor-move 0 12,30\nanchor-delete 4\n");
  // Inserted between anchors 1 and 2 (the segment from (32,10) to (50,32) passes nearest).
  const std::vector<PixelUV> expect{{12, 30}, {32, 10}, {45, 18}, {50, 32}};
  EXPECT_EQ(app.liveWire().clicks(), expect);
  EXPECT_EQ(app.liveWire().contour().pixels, clickedThrough(expect, false).pixels);
  script(app, "undo\nundo\nundo\n");
  EXPECT_EQ(app.liveWire().clicks(), four);
  EXPECT_THROW(script(app, "anchor-delete 9\n"), ScriptError);
  EXPECT_THROW(script(app, "anchor-move 1\n"), ScriptError);
  EXPECT_THROW(script(app, "anchor-move -1 3,3\n"), ScriptError);
  EXPECT_THROW(script(app, "tool trace\nanchor-delete 0\n"), ScriptError);
  EXPECT_NE(std::find(scriptCommands().begin(), scriptCommands().end(), "anchor-insert"), scriptCommands().end());
}

TEST(LiveWireEditTool, PathCoolingIsAToolScriptAndSessionOption) {
  // Hover down along the phantom's skin edge on the left of the head, as a user moving the mouse.
  auto hoverAlong = [](ViewerApp& app) {
    for (int64_t v = 20; v <= 44; ++v) app.liveWire().hover({12, v});
  };
  ViewerApp plain;
  plain.loadHeadPhantom(64);
  script(plain, "tool livewire\nslice z=32\npoint 14,16\n");
  hoverAlong(plain);
  EXPECT_EQ(plain.liveWire().clicks().size(), 1u) << "cooling off (the default): no anchor appears";

  ViewerApp app;
  app.loadHeadPhantom(64);
  script(app, "tool livewire\nlivewire-cooling 3\nslice z=32\npoint 14,16\n");
  EXPECT_EQ(app.liveWire().cooling(), 3);
  hoverAlong(app);
  const size_t anchors = app.liveWire().clicks().size();
  EXPECT_GT(anchors, 1u) << "the stable part of the live path froze into anchors";
  EXPECT_EQ(app.liveWire().undoSteps(), anchors) << "each frozen segment is one undo step";
  const LiveWireContour cooled = app.liveWire().contour();
  // The session keeps the option and the frozen anchors.
  const fs::path file = fs::temp_directory_path() / ("vs_lw_cool_" + std::to_string(::getpid()) + ".json");
  app.saveSession(file.string());
  EXPECT_EQ(app.sessionJson()["livewire"]["cooling"], 3);
  ViewerApp b;
  b.loadSession(file.string());
  fs::remove(file);
  EXPECT_EQ(b.liveWire().cooling(), 3);
  EXPECT_EQ(b.liveWire().contour().pixels, cooled.pixels);
  ASSERT_TRUE(app.undo());
  EXPECT_EQ(app.liveWire().clicks().size(), anchors - 1);
  EXPECT_THROW(script(app, "livewire-cooling -2\n"), ScriptError);
}
