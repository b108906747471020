// The surface tool's corner handles with real input events (xdotool into the test's own Xvfb):
// the +x corner dragged along its half-line on the axial view starts a new extraction with that
// corner. The saved mesh must equal the core's extraction with the corner there, the session must
// hold the corner, and the screenshot must show the handle where it was dropped, not where it was.
#ifdef VS_HAVE_VIEWER
#include <gtest/gtest.h>

#include <cmath>

#include "app/viewer_app.h"
#include "input_fixture.h"
#include "io/mesh_io.h"
#include "io/png_io.h"
#include "surface/surface.h"

using namespace vs;
using namespace vs::viewer;
namespace vt = vs::viewer::testing;

namespace {

class ViewerSurfaceHandleTest : public vt::InputFixture {};

}  // namespace

TEST_F(ViewerSurfaceHandleTest, DraggedCornerReExtractsWithIt) {
  ViewerApp ref;
  ref.loadHeadPhantom(64);
  SurfaceOptions o;
  o.planes = {32, 32, 32};
  o.level = 1;
  const SurfaceResult first = extractSurface(ref.floatVolume(), o);
  ASSERT_TRUE(first.corners[0].has_value());
  const Index3 from = *first.corners[0];
  Index3 to = from;
  to[0] -= 4;  // four voxels in along +x
  o.corners[0] = to;
  const SurfaceResult moved = extractSurface(ref.floatVolume(), o);

  start("load phantom:head:64\ntool surface\nsurface-level 1\nplanes 32,32,32\nrun\nscreenshot " + path("before.png") +
        "\ninteract F12\nwait\nsession-save " + path("after.json") + "\nsave " + path("after.obj") + "\nscreenshot " +
        path("after.png") + "\nquit\n");
  ASSERT_TRUE(waitFor(path("before.png"))) << err();
  const vt::AxialScreen at(ref.geometry(), 32);
  std::string drag = "windowfocus --sync %1" + at.move({from[0], from[1]}) + " mousedown 1";
  for (int64_t x = from[0] - 1; x >= to[0]; --x) drag += at.move({x, from[1]});
  ASSERT_EQ(xdo(drag + " mouseup 1" + at.move({10, 60}) + " key F12"), 0);
  ASSERT_EQ(waitExit(), 0) << err();

  const nlohmann::json s = session(path("after.json"));
  EXPECT_EQ(s["surface"]["corners"][0], nlohmann::json(to)) << s["surface"];
  const TriMesh saved = readTriMesh(path("after.obj"));
  ASSERT_EQ(saved.triangles.size(), moved.mesh.triangles.size());
  double worst = 0;
  for (size_t i = 0; i < saved.positions.size() && i < moved.mesh.positions.size(); ++i)
    worst = std::max(worst, (saved.positions[i] - moved.mesh.positions[i]).norm());
  EXPECT_LT(worst, 1e-3) << "the mesh is the core's extraction with the dragged corner (mm, as written)";
  const RgbaImage before = readPng(path("before.png")), after = readPng(path("after.png"));
  const std::array<int, 3> magenta{255, 80, 200};
  EXPECT_TRUE(colourNear(before, at({from[0], from[1]}), 2, magenta, 20)) << "the handle before the drag";
  EXPECT_TRUE(colourNear(after, at({to[0], to[1]}), 2, magenta, 20)) << "the handle where it was dropped";
  EXPECT_FALSE(colourNear(after, at({from[0], from[1]}), 1, magenta, 20)) << "no handle left where it was";
  std::cout << "[ measured ] corner +x " << from[0] << " -> " << to[0] << ": " << saved.triangles.size()
            << " triangles, largest vertex difference to the core's mesh " << worst << " mm\n";
}
#endif
