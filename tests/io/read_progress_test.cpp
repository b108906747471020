// readVolume's progress and cancel: the stages reach the callback, a cancelled Progress stops
// the read with Cancelled before any voxel is read.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "io/io_test_util.h"
#include "io/volume_io.h"
#include "util/error.h"

namespace vs {
namespace {

TEST(ReadVolumeProgress, ReportsTheReadStageAndHonoursCancel) {
  test::TempDir dir("read_progress");
  Geometry g;
  g.dims = {4, 3, 2};
  VolumeF32 v(g, 1.5f);
  const std::string path = dir.file("v.nrrd");
  writeVolume(AnyVolume(v), path);

  std::vector<double> fractions;
  Progress watched([&](double f, const std::string& stage) {
    EXPECT_EQ(stage, "read");
    fractions.push_back(f);
  });
  const AnyVolume back = readVolume(path, {}, nullptr, watched);
  EXPECT_EQ(geometryOf(back).dims, g.dims);
  EXPECT_EQ(fractions, (std::vector<double>{0.0, 1.0}));

  Progress cancelled;
  cancelled.cancel();
  EXPECT_THROW(readVolume(path, {}, nullptr, cancelled), Cancelled);
}

}  // namespace
}  // namespace vs
