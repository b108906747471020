// Tests for tracking/trace_session: the resumable trace the viewer keeps gives runTrace's tree for
// the same points, resumes the search for an added target (the earlier paths kept as they were),
// restarts it for a removed target, and refuses as runTrace does.
#include "tracking/trace_session.h"

#include <gtest/gtest.h>

#include "phantom/phantom.h"

using namespace vs;

namespace {

const VesselPhantom& phantom() {
  static const VesselPhantom p = [] {
    VesselPhantomOptions o;
    o.seed = 5;
    o.dims = {56, 56, 56};
    o.spacing = {0.9, 0.8, 1.0};
    o.minTerminals = 3;
    o.maxTerminals = 6;
    return makeVesselPhantom(o);
  }();
  return p;
}

const VolumeF32& volume() {
  static const VolumeF32 v = toFloat(AnyVolume(phantom().volume));
  return v;
}

void expectSameTree(const Tree& a, const Tree& b) {
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 0u);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a.parent[i], b.parent[i]) << i;
    EXPECT_LT((a.points[i] - b.points[i]).norm(), 1e-9) << i;
    EXPECT_NEAR(a.radii[i], b.radii[i], 1e-9) << i;
  }
}

}  // namespace

TEST(TraceSession, ResumedTargetsGiveRunTracesTree) {
  const VesselTruth& t = phantom().truth;
  ASSERT_GE(t.terminalVoxels.size(), 2u);
  TraceRequest rq;
  rq.root = t.rootVoxel;
  rq.targets = {t.terminalVoxels[0], t.terminalVoxels[1]};
  const TraceResult once = runTrace(volume(), rq);

  TraceSession s(volume(), TraceRequest{});
  int calls = 0;
  const auto first = s.resume(rq.root, {rq.targets[0]}, -1, Progress::none(), [&](const auto&) { ++calls; });
  ASSERT_EQ(first.paths.size(), 1u);
  EXPECT_GE(calls, 2);  // the kept paths (none), then the new one
  const std::vector<Index3> firstVoxels = first.paths[0].voxels;
  const VesselTracker* tracker = s.tracker();
  const auto both = s.resume(rq.root, rq.targets, -1, Progress::none());
  EXPECT_EQ(s.tracker(), tracker) << "an added target resumes the same search";
  ASSERT_EQ(both.paths.size(), 2u);
  EXPECT_EQ(both.paths[0].voxels, firstVoxels);
  EXPECT_EQ(both.used.size(), 3u);
  EXPECT_EQ(both.used[0], once.root);
  expectSameTree(both.tree, once.tree);

  // A removed target: a fresh search with one path, the tree runTrace gives for that target alone.
  const auto fewer = s.resume(rq.root, {rq.targets[1]}, -1, Progress::none());
  ASSERT_EQ(fewer.paths.size(), 1u);
  TraceRequest one = rq;
  one.targets = {rq.targets[1]};
  expectSameTree(fewer.tree, runTrace(volume(), one).tree);
}

TEST(TraceSession, RefusesAsRunTrace) {
  const VesselTruth& t = phantom().truth;
  TraceSession s(volume(), TraceRequest{});
  EXPECT_THROW(s.resume(t.rootVoxel, {t.rootVoxel}, -1, Progress::none()), DataError);  // onto the root
  EXPECT_THROW(s.resume(t.rootVoxel, {{999, 0, 0}}, -1, Progress::none()), InvalidArgument);
  EXPECT_THROW(s.resume({-1, 0, 0}, {t.terminalVoxels[0]}, -1, Progress::none()), InvalidArgument);
  TraceRequest bad;
  bad.smoothMm = -1;
  EXPECT_THROW(TraceSession(volume(), bad), InvalidArgument);
  // After a refusal the session still traces.
  const auto ok = s.resume(t.rootVoxel, {t.terminalVoxels[0]}, -1, Progress::none());
  EXPECT_EQ(ok.paths.size(), 1u);
  EXPECT_TRUE(ok.paths[0].reached);
}
