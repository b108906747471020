// Target lists (trace --targets-file): text and JSON layouts, the root, and what is refused.
#include "io/targets_io.h"

#include <gtest/gtest.h>

#include "io_test_util.h"
#include "util/error.h"

using namespace vs;

namespace {

TEST(TargetsIo, TextLinesWithCommentsCommasAndSpaces) {
  const TargetList t = parseTargetList("# header\n1 2 3\n\n 4.5,5,-6  # tail\r\n7, 8 ,9\n", "t.txt");
  ASSERT_EQ(t.targets.size(), 3u);
  EXPECT_EQ(t.targets[0], Vec3(1, 2, 3));
  EXPECT_EQ(t.targets[1], Vec3(4.5, 5, -6));
  EXPECT_EQ(t.targets[2], Vec3(7, 8, 9));
  EXPECT_FALSE(t.root);
}

TEST(TargetsIo, JsonListsTruthFilesAndSidecars) {
  EXPECT_EQ(parseTargetList("[[1,2,3],[4,5,6]]", "a.json").targets.size(), 2u);
  const TargetList truth = parseTargetList(R"({"root_voxel": [9,8,7], "terminals": [[1,2,3]]})", "b.json");
  ASSERT_TRUE(truth.root);
  EXPECT_EQ(*truth.root, Vec3(9, 8, 7));
  const TargetList side = parseTargetList(R"({"root": {"voxel": [1,1,1]}, "targets": [{"voxel": [2,3,4]}]})", "c.json");
  EXPECT_EQ(*side.root, Vec3(1, 1, 1));
  EXPECT_EQ(side.targets.at(0), Vec3(2, 3, 4));
}

TEST(TargetsIo, BadContentIsAnIoErrorNamingTheFileAndTheProblem) {
  const std::pair<std::string, std::string> cases[] = {
      {"1 2 3\n4 5\n", "line 2"},
      {"1 2 3 4\n", "line 1"},
      {"nan 1 2\n", "line 1"},
      {"1e999 1 2\n", "line 1"},
      {"", "holds no target"},
      {"{\"terminals\": []}", "holds no target"},
      {"[[1,2,\"3\"]]", "target #1"},
      {"{\"terminals\": 5}", "not an array"},
      {"{\"x\": 1}", "no \"terminals\""},
      {"[[1,2,3]", "invalid JSON"},
      {"[[1e400,2,3]]", "invalid JSON"},
  };
  for (const auto& [text, message] : cases) {
    try {
      parseTargetList(text, "f.txt");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const IoError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("targets file 'f.txt'"), std::string::npos) << what;
      EXPECT_NE(what.find(message), std::string::npos) << text << " -> " << what;
    }
  }
  EXPECT_THROW(readTargetList("/nonexistent/targets.txt"), IoError);
}

TEST(TargetsIo, ReadsAFile) {
  test::TempDir d("targets");
  test::writeBytes(d.file("t.txt"), "1 2 3\n");
  EXPECT_EQ(readTargetList(d.file("t.txt")).targets.size(), 1u);
}

}  // namespace
