// Progress: reports reach the callback, cancel() makes report()/check() throw Cancelled, and the
// shared Progress::none() cannot be cancelled by anyone.
#include "util/progress.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "util/error.h"

namespace vs {
namespace {

TEST(Progress, ReportsReachTheCallbackUntilCancelled) {
  std::vector<std::string> stages;
  Progress p([&](double, const std::string& stage) { stages.push_back(stage); });
  p.report(0.5, "features");
  EXPECT_EQ(stages, std::vector<std::string>{"features"});
  p.cancel();
  EXPECT_TRUE(p.cancelled());
  EXPECT_THROW(p.report(0.6, "search"), Cancelled);
  EXPECT_THROW(p.check(), Cancelled);
  EXPECT_EQ(stages.size(), 1u);
}

TEST(Progress, NoneIgnoresCancel) {
  Progress::none().cancel();
  EXPECT_FALSE(Progress::none().cancelled());
  EXPECT_NO_THROW(Progress::none().report(1.0, "search"));
  EXPECT_NO_THROW(Progress::none().check());
}

}  // namespace
}  // namespace vs
