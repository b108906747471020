#include "args.h"

#include <gtest/gtest.h>

#include "progress_line.h"
#include "util/error.h"

using namespace vs;
using namespace vs::cli;

namespace {
// The UsageError message of f(), or "" when it does not throw.
template <class F>
std::string usageMessage(F&& f) {
  try {
    f();
  } catch (const UsageError& e) {
    return e.what();
  }
  return {};
}
}  // namespace

TEST(Args, Numbers) {
  EXPECT_EQ(parseNumbers("1,2.5,-3", "--x", 3), (std::vector<double>{1, 2.5, -3}));
  EXPECT_EQ(parseNumbers(" 1, +2", "--x", 2), (std::vector<double>{1, 2}));
  EXPECT_EQ(parseNumbers("4,5", "--x", 3, 2).size(), 2u);
  EXPECT_EQ(parseNumbers("4,5,6,7", "--x", 0).size(), 4u);
  for (const char* bad : {"", "1,", ",1", "1,,2", "1,2x", "nan,1", "inf,2", "1;2", "0x10,1"})
    EXPECT_NE(usageMessage([&] { parseNumbers(bad, "--view", 2); }).find("--view"), std::string::npos) << bad;
  EXPECT_NE(usageMessage([] { parseNumbers("1,2,3", "--view", 2); }).find("expected 2"), std::string::npos);
}

TEST(Args, TriplesSizesAndDims) {
  EXPECT_EQ(parseVec3("1.5,2,-3", "--root"), Vec3(1.5, 2, -3));
  EXPECT_EQ(parseIndex3("4,5,6", "--root"), (Index3{4, 5, 6}));
  EXPECT_THROW(parseIndex3("4,5.5,6", "--root"), UsageError);
  EXPECT_THROW(parseIndex3("4,5", "--root"), UsageError);
  EXPECT_EQ(parseImageSize("640x480", "--size", 8192), (std::array<int, 2>{640, 480}));
  for (const char* bad : {"640", "640x", "x480", "0x10", "10x9000", "10x10x10", "axb", "10.5x10"})
    EXPECT_THROW(parseImageSize(bad, "--size", 8192), UsageError) << bad;
  EXPECT_EQ(parseDims("3,4,5", "--size", 100, false), (Index3{3, 4, 5}));
  EXPECT_EQ(parseDims("3,4", "--size", 100, true), (Index3{3, 4, 1}));
  EXPECT_THROW(parseDims("3,4", "--size", 100, false), UsageError);
  EXPECT_THROW(parseDims("3,4,0", "--size", 100, false), UsageError);
  EXPECT_THROW(parseDims("3,4,101", "--size", 100, false), UsageError);
}

TEST(Args, PointLists) {
  const auto p = parsePointList("1,2; 3,4 ;;5,6,7", "--points", {2, 3}, true);
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p[1], (std::vector<double>{3, 4}));
  EXPECT_EQ(p[2].size(), 3u);
  EXPECT_TRUE(parsePointList(" ; ", "--points", {2}, true).empty());
  // The error names the bad item.
  const std::string m = usageMessage([] { parsePointList("1,2;3,x;5,6", "--points", {2}, true); });
  EXPECT_NE(m.find("'3,x'"), std::string::npos) << m;
  EXPECT_THROW(parsePointList("1.5,2", "--points", {2}, true), UsageError);
  EXPECT_EQ(parsePointList("1.5,2,3", "--points", {3}, false)[0][0], 1.5);
  EXPECT_THROW(parsePointList("1,2,3,4", "--points", {2, 3}, false), UsageError);
}

TEST(Progress, TimeLeftText) {
  EXPECT_EQ(timeLeftText(3.2), "~3 s left");
  EXPECT_EQ(timeLeftText(0.1), "~1 s left");
  EXPECT_EQ(timeLeftText(150), "~3 min left");
  EXPECT_EQ(timeLeftText(-1), "");
}

TEST(Progress, ActiveProgressIsTheInnermostLine) {
  EXPECT_EQ(activeProgress(), nullptr);
  {
    ProgressLine line("test");
    EXPECT_EQ(activeProgress(), &line.progress());
    // Cancelling the active progress stops the operation at its next report.
    activeProgress()->cancel();
    EXPECT_THROW(line.progress().report(0.5, "stage"), Cancelled);
  }
  EXPECT_EQ(activeProgress(), nullptr);
}
