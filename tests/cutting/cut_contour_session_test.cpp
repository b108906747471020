// The viewer's incremental cut contour (CutContourSession) is cutContour from scratch: after any
// sequence of hovers, clicks and undos on the head phantom's face, every preview equals
// cutContour(points + hover) vertex for vertex (or throws the same message), and most previews
// are path read-outs (so the test would see a wrong shortcut). MeshSnapper snaps as snapToMesh.
#include "cutting/cut_contour_session.h"

#include <gtest/gtest.h>

#include <optional>
#include <random>
#include <set>

#include "meshops/isosurface.h"
#include "phantom/phantom.h"
#include "util/error.h"

namespace {

using vs::Vec3;

struct Face {
  vs::VolumeF32 volume;
  vs::CutMesh mesh;
  std::vector<Vec3> nose;  // the loop around the nose's base, continuous indices
};

const Face& face() {
  static const Face f = [] {
    vs::HeadPhantomOptions ho;
    ho.seed = 1;
    ho.dims = {128, 128, 64};
    ho.spacing = Vec3(1, 1, 2);
    ho.noiseSigma = 10;
    const vs::HeadPhantom ph = vs::makeHeadPhantom(ho);
    Face out{vs::toFloat(vs::AnyVolume(ph.volume)), {}, {}};
    const vs::Geometry& g = out.volume.geometry();
    std::vector<Vec3> mm = vs::noseBaseLoopMm(ph.truth);
    for (const Vec3& q : mm) out.nose.push_back(g.worldToIndex(q));
    vs::IsoSurfaceOptions io;
    io.iso = ph.truth.isoSkin;
    io.largestComponentOnly = false;
    out.mesh = vs::prepareCutMesh(out.volume, vs::keepComponentNearest(vs::extractIsoSurface(out.volume, io), mm));
    return out;
  }();
  return f;
}

// The session's preview and cutContour from scratch for the same points: the same loop, or the same error.
void expectSameAsFromScratch(vs::CutContourSession& s, const std::optional<Vec3>& hover, const std::string& what) {
  SCOPED_TRACE(what);
  const Face& f = face();
  std::vector<Vec3> pts = s.points();
  if (hover) pts.push_back(*hover);
  if (pts.size() < 3) return;
  std::optional<vs::CutContour> a, b;
  std::string errA, errB;
  try {
    const vs::CutContourPreview p = s.preview(hover);
    EXPECT_TRUE(p.closed);
    EXPECT_EQ(p.withHover, hover.has_value());
    a = p.loop;
  } catch (const vs::Error& e) {
    errA = e.what();
  }
  try {
    b = vs::cutContour(f.mesh, f.volume.geometry(), pts, 3.0);
  } catch (const vs::Error& e) {
    errB = e.what();
  }
  ASSERT_EQ(a.has_value(), b.has_value()) << "session: " << errA << " / from scratch: " << errB;
  EXPECT_EQ(errA, errB);
  if (!a) return;
  EXPECT_EQ(a->contour.vertices, b->contour.vertices);
  EXPECT_EQ(a->contour.anchors, b->contour.anchors);
  EXPECT_EQ(a->contourMm, b->contourMm);
  EXPECT_EQ(a->snapDistanceMm, b->snapDistanceMm);
  EXPECT_EQ(a->contour.lengthMm, b->contour.lengthMm);
  EXPECT_EQ(a->contour.cost, b->contour.cost);
  const std::set<int64_t> distinct(a->contour.vertices.begin(), a->contour.vertices.end());
  EXPECT_EQ(distinct.size(), a->contour.vertices.size()) << "the loop touches itself";
}

TEST(CutContourSession, EveryPreviewIsCutContourFromScratch) {
  const Face& f = face();
  const vs::Geometry& g = f.volume.geometry();
  ASSERT_EQ(f.nose.size(), 10u);
  vs::CutContourSession s(f.mesh, g, 3.0);
  std::mt19937 rng(20261202);
  std::uniform_real_distribution<double> jitter(-1.5, 1.5), unit(0, 1);
  // Hover candidates: vertices within 35 mm of the nose loop's centre (the face around the nose).
  Vec3 centre = Vec3::Zero();
  for (const Vec3& p : f.nose) centre += g.indexToWorld(p) / double(f.nose.size());
  std::vector<int64_t> nearFace;
  for (size_t v = 0; v < f.mesh.mesh.positions.size(); ++v)
    if ((f.mesh.mesh.positions[v] - centre).norm() < 35) nearFace.push_back(int64_t(v));
  ASSERT_GT(nearFace.size(), 1000u);
  std::uniform_int_distribution<size_t> pick(0, nearFace.size() - 1);
  auto index = [&](int64_t v) { return g.worldToIndex(f.mesh.mesh.positions[size_t(v)]); };

  std::vector<Vec3> placed;
  int steps = 0;
  for (size_t next = 0; next < f.nose.size() && steps < 400; ++steps) {
    const std::string at = "step " + std::to_string(steps) + ", " + std::to_string(placed.size()) + " points";
    const double r = unit(rng);
    if (r < 0.05 && placed.size() >= 2) {  // undo
      placed.pop_back();
      --next;
      s.setPoints(placed);
      expectSameAsFromScratch(s, std::nullopt, at + ", undone");
      continue;
    }
    if (r < 0.15) {  // click the next point of the loop
      placed.push_back(f.nose[next++]);
      s.setPoints(placed);
      expectSameAsFromScratch(s, std::nullopt, at + ", clicked");
      continue;
    }
    // Hover: mostly along the way to the next point (a hand moving there), else anywhere near the
    // face, on the contour drawn so far, or near the first point (where the loop closes).
    std::optional<Vec3> hover;
    const Vec3 to = f.nose[next];
    if (r < 0.7 && !placed.empty()) {
      const double t = unit(rng);
      hover = placed.back() * (1 - t) + to * t + Vec3(jitter(rng), jitter(rng), 0.5 * jitter(rng));
    } else if (r < 0.8 || placed.size() < 2) {
      hover = index(nearFace[pick(rng)]);
    } else if (r < 0.9) {
      try {
        const vs::CutContour c = vs::cutContour(f.mesh, g, placed, 3.0);
        hover = index(c.contour.vertices[size_t(unit(rng) * double(c.contour.vertices.size() - 1))]);
      } catch (const vs::Error&) {
        hover = index(nearFace[pick(rng)]);
      }
    } else {
      hover = placed.front() + Vec3(2 * jitter(rng), 2 * jitter(rng), jitter(rng));
    }
    if (s.snapVertex(*hover) < 0) hover = placed.empty() ? to : placed.back();  // the viewer drops those
    expectSameAsFromScratch(s, hover, at + ", hovered");
    if (unit(rng) < 0.3) expectSameAsFromScratch(s, hover, at + ", hovered again");
  }
  const vs::CutContourSessionStats& st = s.stats();
  std::printf("previews %lld: read-outs %lld, closing searched again %lld, from scratch %lld, same vertex %lld\n",
              (long long)st.previews, (long long)st.readOuts, (long long)st.closingRetries, (long long)st.fromScratch,
              (long long)st.cached);
  EXPECT_GT(st.readOuts, st.previews / 2) << "the previews are not incremental";
  EXPECT_GT(st.closingRetries, 0) << "no closing path touched the hovered segment: that way is not tested";
  EXPECT_GT(st.fromScratch, 0) << "no hover on the drawn contour: that way is not tested";
}

TEST(CutContourSession, TwoPointsGiveTheOpenSegmentAndFewerNothing) {
  const Face& f = face();
  vs::CutContourSession s(f.mesh, f.volume.geometry(), 3.0);
  EXPECT_TRUE(s.preview(f.nose[0]).loop.contour.vertices.empty());
  s.setPoints({f.nose[0]});
  EXPECT_TRUE(s.preview(std::nullopt).loop.contour.vertices.empty());
  const vs::CutContourPreview hovered = s.preview(f.nose[1]);
  s.setPoints({f.nose[0], f.nose[1]});
  const vs::CutContourPreview clicked = s.preview(std::nullopt);
  EXPECT_FALSE(hovered.closed);
  EXPECT_TRUE(hovered.withHover);
  ASSERT_GE(clicked.loop.contour.vertices.size(), 2u);
  EXPECT_EQ(hovered.loop.contour.vertices, clicked.loop.contour.vertices);
  // It is the first segment of the loop once a third point is placed.
  const vs::CutContour loop = vs::cutContour(f.mesh, f.volume.geometry(), {f.nose[0], f.nose[1], f.nose[2]}, 3.0);
  const auto& v = clicked.loop.contour.vertices;
  EXPECT_TRUE(std::equal(v.begin(), v.end() - 1, loop.contour.vertices.begin()));
}

TEST(MeshSnapper, SnapsAsSnapToMesh) {
  const Face& f = face();
  const vs::TriMesh& m = f.mesh.mesh;
  for (double radius : {3.0, 0.25}) {  // (0.25: cells wider than the radius, fewer than the vertices)
    SCOPED_TRACE("snap radius " + std::to_string(radius));
    const vs::MeshSnapper snapper(m, f.mesh.features, radius);
    std::mt19937 rng(7);
    std::uniform_int_distribution<size_t> pick(0, m.positions.size() - 1);
    std::uniform_real_distribution<double> off(-4 * radius / 3, 4 * radius / 3);
    int far = 0;
    for (int i = 0; i < 2000; ++i) {
      const Vec3 p = m.positions[pick(rng)] + Vec3(off(rng), off(rng), off(rng)) * (i % 10 == 0 ? 3 : 1);
      std::string errA, errB;
      vs::MeshSnap a, b;
      try {
        a = snapper.snap(p, "point 4");
      } catch (const vs::DataError& e) {
        errA = e.what();
      }
      try {
        b = vs::snapToMesh(m, f.mesh.features, p, radius, "point 4");
      } catch (const vs::DataError& e) {
        errB = e.what();
      }
      EXPECT_EQ(errA, errB);
      far += !errB.empty();
      if (!errB.empty()) continue;
      EXPECT_EQ(a.vertex, b.vertex) << "point " << p.transpose();
      EXPECT_EQ(a.distanceMm, b.distanceMm);
    }
    EXPECT_GT(far, 20) << "no point beyond the snap radius: the error is not tested";
  }
}

}  // namespace
