// The live-wire's anchor editing with real input events (xdotool into the test's own Xvfb,
// Mesa's software OpenGL): Ctrl+click on the contour inserts an anchor, a drag moves one, a
// right-click deletes one, `z` undoes, Delete removes another. The state after the events must be
// the one the GL-free tool gives for the same edits (anchors in the session), and the screenshot
// must show that contour: its pixels drawn in the contour's yellow, the old path gone.
#ifdef VS_HAVE_VIEWER
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "app/script.h"
#include "app/slice_layout.h"
#include "app/viewer_app.h"
#include "input_fixture.h"
#include "io/png_io.h"

using namespace vs;
using namespace vs::viewer;
namespace vt = vs::viewer::testing;

namespace {

class ViewerLiveWireEditTest : public vt::InputFixture {};

}  // namespace

TEST_F(ViewerLiveWireEditTest, InsertDragDeleteAndUndoWithTheMouseAndKeys) {
  const std::string points = "tool livewire\nslice z=64\npoint 30,64\npoint 64,20\npoint 98,64\nclose\n";
  // The same contour and edits without a window (the default volume: the 128^3 head phantom).
  ViewerApp ref;
  ref.loadHeadPhantom(128);
  std::istringstream in(points);
  runScript(ref, in, nullptr, "reference");
  LiveWireTool& lw = ref.liveWire();
  const LiveWireContour before = lw.contour();
  const auto& px = before.pixels;
  const auto i1 = std::find(px.begin(), px.end(), PixelUV{64, 20}) - px.begin();
  const auto i2 = std::find(px.begin(), px.end(), PixelUV{98, 64}) - px.begin();
  ASSERT_LT(i1, i2);
  const PixelUV mid = px[size_t((i1 + i2) / 2)];  // on the segment from anchor 1 to anchor 2
  lw.insertAnchor(1, mid);
  lw.moveAnchor(1, {64, 30});
  lw.removeAnchor(3);
  ASSERT_TRUE(lw.undo());
  lw.removeAnchor(2);
  const std::vector<PixelUV> anchors = lw.clicks();
  ASSERT_EQ(anchors, (std::vector<PixelUV>{{30, 64}, {64, 30}, {98, 64}}));
  const LiveWireContour after = lw.contour();

  start(points + "screenshot " + path("before.png") + "\ninteract F12\nsession-save " + path("after.json") +
        "\nscreenshot " + path("after.png") + "\nquit\n");
  ASSERT_TRUE(waitFor(path("before.png"))) << err();
  const vt::AxialScreen at(ref.geometry(), 64);
  ASSERT_EQ(xdo("windowfocus --sync %1" + at.move(mid) + " keydown ctrl click 1 keyup ctrl"), 0);  // insert
  std::string drag = at.move({64, 20}) + " mousedown 1";  // drag anchor 1 ten pixels down
  for (int64_t v = 22; v <= 30; v += 2) drag += at.move({64, v});
  ASSERT_EQ(xdo(drag + " mouseup 1"), 0);
  ASSERT_EQ(xdo(at.move({98, 64}) + " click 3"), 0);  // right-click: delete anchor 3
  ASSERT_EQ(xdo(at.move({90, 90}) + " key z"), 0);    // undo the delete
  ASSERT_EQ(xdo(at.move(mid) + " key Delete F12"), 0);
  ASSERT_EQ(waitExit(), 0) << err();

  const nlohmann::json s = session(path("after.json"));
  std::vector<PixelUV> got;
  for (const auto& c : s["livewire"]["clicks"]) got.push_back({c[0].get<int64_t>(), c[1].get<int64_t>()});
  EXPECT_EQ(got, anchors) << s["livewire"];
  EXPECT_TRUE(s["livewire"]["closed"].get<bool>());

  // The picture: the edited contour drawn, the old path near the moved anchor gone.
  const RgbaImage shot = readPng(path("after.png")), old = readPng(path("before.png"));
  const std::array<int, 3> yellow{255, 220, 0}, orange{255, 140, 0};
  auto drawnFraction = [&](const RgbaImage& im, const std::vector<PixelUV>& pixels) {
    int n = 0;
    for (const PixelUV& p : pixels) n += colourNear(im, at(p), 2, yellow, 30) ? 1 : 0;
    return pixels.empty() ? 0.0 : double(n) / double(pixels.size());
  };
  std::vector<PixelUV> gone;  // pixels of the old contour 4 or more pixels from the new one
  for (const PixelUV& p : before.pixels) {
    bool far = true;
    for (const PixelUV& q : after.pixels) far = far && std::hypot(double(p[0] - q[0]), double(p[1] - q[1])) >= 4;
    if (far) gone.push_back(p);
  }
  ASSERT_GE(gone.size(), 10u) << "the move changed the contour";
  const double drawn = drawnFraction(shot, after.pixels), oldDrawn = drawnFraction(old, gone),
               ghost = drawnFraction(shot, gone);
  EXPECT_GE(drawn, 0.9) << "the edited contour on the axial view";
  EXPECT_GE(oldDrawn, 0.9) << "the test's screen mapping (the contour before the edits)";
  EXPECT_LE(ghost, 0.1) << "the old path near the moved anchor is gone";
  for (const PixelUV& a : anchors) EXPECT_TRUE(colourNear(shot, at(a), 1, orange, 20)) << a[0] << "," << a[1];
  EXPECT_FALSE(colourNear(shot, at({64, 20}), 1, orange, 20)) << "no anchor left where the dragged one was";
  std::cout << "[ measured ] edited contour drawn " << drawn << ", old path drawn before " << oldDrawn << " after "
            << ghost << " (" << gone.size() << " px)\n";
}
#endif
