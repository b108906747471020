// Where the refined centreline of the vessel family misses (issue 21, docs/notes/tracking.md
// session 13 thin4): every refined point more than 1 voxel from the true centreline (the thin
// sweep's measure: any branch) is put in one class, the first that fits:
//   past   a point the discrete tree shares between two paths beyond their true junction (the
//          discrete branch point lies past the fork);
//   merged a point within 0.25 voxel of another path's refined point that is not the same tree
//          point (two discrete paths side by side, centred onto one line, e.g. past a junction);
//   fork   within 2 parent radii + 2 voxels of a true branch point;
//   end    within 3 voxels of its path's end (the terminal);
//   thin   true radius under 1 voxel;
//   other.
// Per true branch point also the discrete branch point's offset (voxels; along the parent's axis,
// positive past the junction). A sweep only: VS_FAMILY_DIAG=FIRST-LAST (thin) and
// VS_FAMILY_DIAG_VARIANTS=FIRST-LAST (as drawn, thin and parallel ones only); none in CI.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "family_seeds.h"
#include "phantom/phantom.h"
#include "tracking/auto_cost.h"
#include "tracking/trace_run.h"
#include "tracking/tracker.h"
#include "tracking/valley_cost.h"

namespace vs {
namespace {

std::vector<uint64_t> seedsFrom(const char* name) { return familySeedsFromEnv(name); }

// Branch a is b or an ancestor of b.
bool ancestorOf(const VesselTruth& t, int a, int b) {
  for (; b >= 0; b = t.branches[size_t(b)].parent)
    if (a == b) return true;
  return false;
}

// The trace of a family case with defaults and every terminal given; false, with a line naming
// the refusal, when it is refused.
bool traceEveryTerminal(const VesselFamilyCase& c, const char* tag, TraceResult& r) {
  TraceRequest rq;
  rq.root = c.truth.rootVoxel;
  rq.targets = c.truth.terminalVoxels;
  try {
    r = runTrace(c.volume, rq);
  } catch (const std::exception& e) {
    std::printf("[%s %s] refused: %s\n", tag, c.describe().c_str(), e.what());
    return false;
  }
  return true;
}

void diagnose(const VesselFamilyCase& c) {
  const VesselTruth& t = c.truth;
  TraceResult r;
  if (!traceEveryTerminal(c, "diag", r)) return;
  const double vox = t.spacing.minCoeff();
  const size_t np = r.paths.size();
  const bool ownOnly = std::getenv("VS_FAMILY_DIAG_OWN") != nullptr;
  if (const char* dir = std::getenv("VS_FAMILY_DIAG_DUMP")) {  // "kind id x y z" (mm): truth and paths
    if (FILE* fp = std::fopen((std::string(dir) + "/diag_" + std::to_string(t.seed) + ".txt").c_str(), "w")) {
      for (size_t b = 0; b < t.branches.size(); ++b)
        for (const Vec3& p : t.branches[b].points) {
          const Vec3 m = p.cwiseProduct(t.spacing);
          std::fprintf(fp, "t %zu %.3f %.3f %.3f\n", b, m[0], m[1], m[2]);
        }
      for (size_t i = 0; i < np; ++i)
        for (size_t k = 0; k < r.points[i].size(); ++k) {
          const Vec3 m = r.points[i][k].cwiseProduct(t.spacing);
          const Index3& v = r.paths[i].voxels[k];
          std::fprintf(fp, "p %zu %.3f %.3f %.3f %.3f %.3f %.3f\n", i, m[0], m[1], m[2], double(v[0]) * t.spacing[0],
                       double(v[1]) * t.spacing[1], double(v[2]) * t.spacing[2]);
        }
      std::fclose(fp);
    }
  }
  enum { kPast, kMerged, kFork, kEnd, kThin, kOther, kClasses };
  const char* names[kClasses] = {"past", "merged", "fork", "end", "thin", "other"};
  size_t count[kClasses] = {0, 0, 0, 0, 0, 0}, n = 0, far = 0;
  auto key = [](const Index3& v) { return (uint64_t(v[0]) << 42) | (uint64_t(v[1]) << 21) | uint64_t(v[2]); };
  for (size_t i = 0; i < np; ++i) {
    const auto& vi = r.paths[i].voxels;
    // Thin: any branch (the thin sweep's measure); the other variants and VS_FAMILY_DIAG_OWN (a given
    // thin case, its line's measure): the path's own branches.
    VesselTruth own = t;
    if (c.variant != VesselFamilyVariant::Thin || ownOnly) {
      own.branches.clear();
      for (size_t b = 0; b < t.branches.size(); ++b)
        if (ancestorOf(t, int(b), t.terminalBranches[i])) own.branches.push_back(t.branches[b]);
    }
    for (size_t k = 0; k < r.points[i].size(); ++k) {
      ++n;
      const Vec3& p = r.points[i][k];
      CenterlineDistance d = distanceToCenterline(own, p);
      if (d.distanceMm <= vox) continue;
      const double ownMm = d.distanceMm;
      d = distanceToCenterline(t, p);  // branch ids of the whole tree
      if (d.distanceMm <= vox && !ownOnly) continue;
      ++far;
      int cls = kOther;
      // Shared with another path j beyond the true junction of i's and j's terminals.
      for (size_t j = 0; j < np && cls == kOther; ++j) {
        if (j == i || k >= r.paths[j].voxels.size() || key(r.paths[j].voxels[k]) != key(vi[k])) continue;
        int a = t.terminalBranches[i], b = t.terminalBranches[j];
        while (!ancestorOf(t, a, b)) a = t.branches[size_t(a)].parent;  // deepest common branch
        if (!ancestorOf(t, d.branch, a)) cls = kPast;
      }
      // On another path's refined point (within 0.25 voxel) that is not the same tree point: two
      // discrete paths side by side, centred onto one line.
      for (size_t j = 0; j < np && cls == kOther; ++j)
        for (size_t m = 0; m < r.points[j].size() && cls == kOther && j != i; ++m)
          if ((r.points[j][m] - p).cwiseProduct(t.spacing).norm() < 0.25 * vox &&
              (m != k || key(r.paths[j].voxels[m]) != key(vi[k])))
            cls = kMerged;
      double junction = 1e9, parentR = 0;
      for (const VesselBranchPoint& bp : t.branchPoints) {
        const double dj = (p - bp.position).cwiseProduct(t.spacing).norm();
        if (dj < junction) junction = dj, parentR = t.branches[size_t(bp.parent)].radiiMm.back();
      }
      if (cls == kOther && junction <= 2 * parentR + 2 * vox) cls = kFork;
      if (cls == kOther && r.points[i].size() - k <= 4) cls = kEnd;
      if (cls == kOther && d.radiusMm < vox) cls = kThin;
      ++count[cls];
      if (std::getenv("VS_FAMILY_DIAG_POINTS"))
        std::printf(
            "  far %s: path %zu point %zu/%zu dist %.2f, true r %.2f, refined r %.2f, branch %d, junction %.1f\n",
            names[cls], i, k, r.points[i].size(), ownMm / vox, d.radiusMm / vox, r.radiiMm[i][k] / vox, d.branch,
            junction / vox);
    }
  }
  std::printf("[diag %s] %zu points, %zu far (%.1f%% within 1):", c.describe().c_str(), n, far,
              n ? 100.0 * double(n - far) / double(n) : 0.0);
  for (int k = 0; k < kClasses; ++k) std::printf(" %s %zu", names[k], count[k]);
  std::printf("\n");
  // Discrete branch points against the true ones: per true branch point, the paths to one terminal
  // below each of two children; where they part.
  for (size_t b = 0; b < t.branchPoints.size(); ++b) {
    const VesselBranchPoint& bp = t.branchPoints[b];
    if (bp.children.size() < 2) continue;
    // The pair of paths (one below each child) that share the most voxels.
    size_t s = 0, pa = np;
    for (size_t i = 0; i < np; ++i)
      for (size_t j = 0; j < np; ++j) {
        if (!ancestorOf(t, bp.children[0], t.terminalBranches[i]) ||
            !ancestorOf(t, bp.children[1], t.terminalBranches[j]))
          continue;
        const auto &a = r.paths[i].voxels, &bb = r.paths[j].voxels;
        size_t k = 0;
        while (k + 1 < a.size() && k + 1 < bb.size() && key(a[k + 1]) == key(bb[k + 1])) ++k;
        if (pa == np || k > s) s = k, pa = i;
      }
    if (pa == np) continue;
    const auto& a = r.paths[pa].voxels;
    const Vec3 dv(double(a[s][0]), double(a[s][1]), double(a[s][2]));
    const VesselBranch& par = t.branches[size_t(bp.parent)];
    const Vec3 axis = (par.points.back() - par.points[par.points.size() - 2]).cwiseProduct(t.spacing).normalized();
    const Vec3 off = (dv - bp.position).cwiseProduct(t.spacing);
    const Vec3 c0 = (t.branches[size_t(bp.children[0])].points[1] - bp.position).cwiseProduct(t.spacing).normalized();
    const Vec3 c1 = (t.branches[size_t(bp.children[1])].points[1] - bp.position).cwiseProduct(t.spacing).normalized();
    std::printf(
        "  fork %zu: parent r %.2f vox, children %.0f deg apart, discrete branch point %.1f vox off (%.1f along)\n", b,
        par.radiiMm.back() / vox, std::acos(std::clamp(c0.dot(c1), -1.0, 1.0)) * 180 / M_PI, off.norm() / vox,
        off.dot(axis) / vox);
  }
}

class FamilyDiagnosis : public ::testing::TestWithParam<uint64_t> {};
TEST_P(FamilyDiagnosis, Thin) { diagnose(makeVesselFamilyCase(GetParam(), VesselFamilyVariant::Thin)); }
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(FamilyDiagnosis);
INSTANTIATE_TEST_SUITE_P(Sweep, FamilyDiagnosis, ::testing::ValuesIn(seedsFrom("VS_FAMILY_DIAG")),
                         [](const auto& p) { return "seed" + std::to_string(p.param); });

class FamilyDiagnosisVariants : public ::testing::TestWithParam<uint64_t> {};
TEST_P(FamilyDiagnosisVariants, ThinAndParallel) {
  const VesselFamilyVariant v = vesselFamilyVariantOf(GetParam());
  if (v == VesselFamilyVariant::Thin || v == VesselFamilyVariant::Parallel) diagnose(makeVesselFamilyCase(GetParam()));
}
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(FamilyDiagnosisVariants);
INSTANTIATE_TEST_SUITE_P(Sweep, FamilyDiagnosisVariants, ::testing::ValuesIn(seedsFrom("VS_FAMILY_DIAG_VARIANTS")),
                         [](const auto& p) { return "seed" + std::to_string(p.param); });

// A seed as the blind blocks and family_scan.sh's given lines draw it (01-03 thin, 04-06 wide, 07-09
// kissing, 10-12 parallel), VS_FAMILY_DIAG_ANY=FIRST-LAST (session 49 held18; with VS_FAMILY_DIAG_OWN
// for a thin one's given line).
class FamilyDiagnosisAny : public ::testing::TestWithParam<uint64_t> {};
TEST_P(FamilyDiagnosisAny, AsGiven) {
  const VesselFamilyVariant v[4] = {VesselFamilyVariant::Thin, VesselFamilyVariant::WideLumen,
                                    VesselFamilyVariant::Kissing, VesselFamilyVariant::Parallel};
  diagnose(makeVesselFamilyCase(GetParam(), v[((GetParam() % 100) - 1) / 3 % 4]));
}
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(FamilyDiagnosisAny);
INSTANTIATE_TEST_SUITE_P(Sweep, FamilyDiagnosisAny, ::testing::ValuesIn(seedsFrom("VS_FAMILY_DIAG_ANY")),
                         [](const auto& p) { return "seed" + std::to_string(p.param); });

// Kissing and parallel variants (session 14, kiss4): where a far refined point (more than 1 voxel
// from its own tubes) comes from. Per far point, the first class that fits:
//   cross  its discrete (raw) path voxel lies outside its own tubes and inside another tube: the
//          path crossed to the neighbour (the cost);
//   pulled its raw voxel lies inside its own tubes: the refinement moved it out (the rays see the
//          two touching tubes as one cross-section);
//   other  neither (the raw voxel in the background between them).
// Also the points whose raw voxel crossed but whose refined point is back within 1 voxel ("cross
// fixed"), and the radius error (true radius >= 1 voxel) of the points within 1 voxel and of the
// points whose raw voxel is inside both tubes' surfaces + 1 voxel ("contact"). A sweep only:
// VS_FAMILY_DIAG_KISS=FIRST-LAST (kissing and parallel seeds as drawn; with VS_FAMILY_DIAG_KISS_GIVEN
// set, kissing given); none in CI.
// Session 16 (kiss6): each change of tube on a raw path (a run of raw voxels nearer the other tube's
// axis than the own one's, and inside it) classified by its transition: q = dOwn / (dOwn + dOther)
// goes from <= 0.25 to >= 0.75; "step" when that takes <= 3 voxels of path, else "drift"; where:
// "join" (the tubes' surface gap > 1 voxel 5 points before, <= 1 after), "depart" (the reverse),
// "contact" (<= 1 both), "apart" (> 1 both). Per seed the far points (> 1 voxel from the own
// tubes) of each class, and the far points whose raw voxel is in the own tube ("pulled").
void classifyCrossings(const VesselTruth& t, const TraceResult& r) {
  const double vox = t.spacing.minCoeff();
  std::string line;
  size_t farIn[2][4] = {{0, 0, 0, 0}, {0, 0, 0, 0}};
  const char* where[4] = {"join", "depart", "contact", "apart"};
  for (size_t i = 0; i < r.paths.size(); ++i) {
    VesselTruth own = t, oth = t;
    own.branches.clear(), oth.branches.clear();
    for (size_t b = 0; b < t.branches.size(); ++b)
      (ancestorOf(t, int(b), t.terminalBranches[i]) ? own : oth).branches.push_back(t.branches[b]);
    const auto& vx = r.paths[i].voxels;
    const size_t n = vx.size();
    std::vector<double> q(n), gap(n);
    std::vector<int> other(n), far(n);
    for (size_t k = 0; k < n; ++k) {
      const Vec3 raw{double(vx[k][0]), double(vx[k][1]), double(vx[k][2])};
      const CenterlineDistance a = distanceToCenterline(own, raw), b = distanceToCenterline(oth, raw);
      q[k] = a.distanceMm / std::max(1e-9, a.distanceMm + b.distanceMm);
      gap[k] = ((a.closest - b.closest).cwiseProduct(t.spacing).norm() - a.radiusMm - b.radiusMm) / vox;
      other[k] = b.distanceMm < a.distanceMm && b.distanceMm <= b.radiusMm;
      far[k] = distanceToCenterline(own, r.points[i][k]).distanceMm > vox;
    }
    for (size_t k = 0; k < n;) {
      if (!other[k]) {
        ++k;
        continue;
      }
      size_t e = k;
      while (e + 1 < n && other[e + 1]) ++e;
      // The transition that lies at the contact: into the run (k) and out of it (e + 1).
      int best = -1, bestWhere = 3;
      double bestWidth = 0;
      for (const size_t at : {k, e + 1}) {
        if (at == 0 || at >= n) continue;
        const bool in = at == k;  // into the other tube: q rises
        size_t lo = at, hi = at;
        while (lo > 0 && (in ? q[lo] > 0.25 : q[lo] < 0.75)) --lo;
        while (hi + 1 < n && (in ? q[hi] < 0.75 : q[hi] > 0.25)) ++hi;
        double width = 0;
        for (size_t j = lo + 1; j <= hi; ++j) {
          const Vec3 d{double(vx[j][0] - vx[j - 1][0]), double(vx[j][1] - vx[j - 1][1]),
                       double(vx[j][2] - vx[j - 1][2])};
          width += d.cwiseProduct(t.spacing).norm() / vox;
        }
        const double gb = gap[at >= 5 ? at - 5 : 0], ga = gap[std::min(n - 1, at + 5)];
        const int w = gb > 1 && ga <= 1 ? 0 : gb <= 1 && ga > 1 ? 1 : gb <= 1 && ga <= 1 ? 2 : 3;
        if (best < 0 || w < bestWhere) best = int(at), bestWhere = w, bestWidth = width;
      }
      size_t nf = 0;
      for (size_t j = k; j <= e; ++j) nf += far[j];
      if (best >= 0 && e - k + 1 >= 3) {
        const int kind = bestWidth <= 3 ? 0 : 1;
        farIn[kind][bestWhere] += nf;
        char buf[160];
        std::snprintf(buf, sizeof buf, " [path %zu, %zu-%zu of %zu: %s at %s, width %.1f, %zu far]", i, k, e, n,
                      kind ? "drift" : "step", where[bestWhere], bestWidth, nf);
        line += buf;
      }
      k = e + 1;
    }
  }
  size_t pulled = 0;
  for (size_t i = 0; i < r.paths.size(); ++i) {
    VesselTruth own = t;
    own.branches.clear();
    for (size_t b = 0; b < t.branches.size(); ++b)
      if (ancestorOf(t, int(b), t.terminalBranches[i])) own.branches.push_back(t.branches[b]);
    for (size_t k = 0; k < r.points[i].size(); ++k) {
      const Index3& v = r.paths[i].voxels[k];
      const CenterlineDistance dr = distanceToCenterline(own, Vec3(double(v[0]), double(v[1]), double(v[2])));
      pulled += dr.distanceMm <= dr.radiusMm && distanceToCenterline(own, r.points[i][k]).distanceMm > vox;
    }
  }
  std::printf(
      "[kissclass seed %llu] far: step join/depart/contact/apart %zu/%zu/%zu/%zu, drift %zu/%zu/%zu/%zu, "
      "pulled %zu;%s\n",
      static_cast<unsigned long long>(t.seed), farIn[0][0], farIn[0][1], farIn[0][2], farIn[0][3], farIn[1][0],
      farIn[1][1], farIn[1][2], farIn[1][3], pulled, line.c_str());
}

void diagnoseKissing(const VesselFamilyCase& c) {
  const VesselTruth& t = c.truth;
  TraceResult r;
  if (!traceEveryTerminal(c, "kiss", r)) return;
  const double vox = t.spacing.minCoeff();
  size_t n = 0, cross = 0, pulled = 0, other = 0, crossFixed = 0, contact = 0;
  double radErr = 0, radErrContact = 0;
  size_t nRad = 0, nRadContact = 0;
  for (size_t i = 0; i < r.paths.size(); ++i) {
    VesselTruth own = t, oth = t;
    own.branches.clear(), oth.branches.clear();
    for (size_t b = 0; b < t.branches.size(); ++b)
      (ancestorOf(t, int(b), t.terminalBranches[i]) ? own : oth).branches.push_back(t.branches[b]);
    for (size_t k = 0; k < r.points[i].size(); ++k) {
      ++n;
      const Index3& v = r.paths[i].voxels[k];
      const Vec3 raw{double(v[0]), double(v[1]), double(v[2])};
      const CenterlineDistance dr = distanceToCenterline(own, raw), dp = distanceToCenterline(own, r.points[i][k]);
      const CenterlineDistance orw = distanceToCenterline(oth, raw);
      const bool rawOwn = dr.distanceMm <= dr.radiusMm, rawOther = orw.distanceMm <= orw.radiusMm;
      const bool far = dp.distanceMm > vox;
      if (rawOther && !rawOwn) (far ? cross : crossFixed) += 1;
      if (far && rawOwn) ++pulled;
      if (far && !rawOwn && !rawOther) ++other;
      const bool atContact = dr.distanceMm <= dr.radiusMm + vox && orw.distanceMm <= orw.radiusMm + vox;
      contact += atContact;
      if (dp.radiusMm >= vox && !far) {
        const double e = std::abs(r.radiiMm[i][k] - dp.radiusMm) / vox;
        radErr += e, ++nRad;
        if (atContact) radErrContact += e, ++nRadContact;
      }
      if (std::getenv("VS_FAMILY_DIAG_POINTS") && (far || (rawOther && !rawOwn)))
        std::printf(
            "  path %zu point %zu/%zu: refined %.2f vox off, raw %.2f (own r %.2f), raw to other %.2f (r %.2f)\n", i, k,
            r.points[i].size(), dp.distanceMm / vox, dr.distanceMm / vox, dr.radiusMm / vox, orw.distanceMm / vox,
            orw.radiusMm / vox);
    }
  }
  classifyCrossings(t, r);
  if (std::getenv("VS_FAMILY_DIAG_COST")) {  // node cost integrals: own truth centreline against the path
    const AutoCost ac = computeAutoCost(c.volume, t.rootVoxel, AutoCostOptions{}, Progress::none());
    const Geometry& g = ac.cost.geometry;
    auto at = [&](const Vec3& p) {
      Index3 v;
      for (int a = 0; a < 3; ++a) v[a] = std::clamp<int64_t>(std::llround(p[a]), 0, g.dims[a] - 1);
      return double(ac.cost.node[size_t(g.linear(v[0], v[1], v[2]))]);
    };
    for (size_t i = 0; i < r.paths.size(); ++i) {
      double truthSum = 0, pathSum = 0, worst = 0;
      for (int b = t.terminalBranches[i]; b >= 0; b = t.branches[size_t(b)].parent) {
        const auto& pts = t.branches[size_t(b)].points;
        for (size_t k = 1; k < pts.size(); ++k) {
          const double len = (pts[k] - pts[k - 1]).cwiseProduct(t.spacing).norm();
          const double cst = at(pts[k]);
          truthSum += len * cst;
          worst = std::max(worst, cst);
        }
      }
      const auto& vx = r.paths[i].voxels;
      std::string prof;
      for (size_t k = 1; k < vx.size(); ++k) {
        const Vec3 a{double(vx[k][0]), double(vx[k][1]), double(vx[k][2])},
            b0{double(vx[k - 1][0]), double(vx[k - 1][1]), double(vx[k - 1][2])};
        const double cst = at(a);
        pathSum += (a - b0).cwiseProduct(t.spacing).norm() * cst;
        if (cst > 0.01) {
          char buf[48];
          std::snprintf(buf, sizeof buf, " %zu:%.3f", k, cst);
          prof += buf;
        }
        if (std::getenv("VS_FAMILY_DIAG_DEPTH")) {
          const bool bright = !c.dark;
          const double du = valleyDepth(c.volume, ac.background.valleys, vx[k][0], vx[k][1], vx[k][2], bright, 1e30);
          const double ds = valleyDepth(ac.smoothed, ac.background.valleys, vx[k][0], vx[k][1], vx[k][2], bright, 1e30);
          const CenterlineDistance own = distanceToCenterline(t, a);
          std::printf("    %zu: v %.1f sm %.1f depth raw %.1f smoothed %.1f cost %.4f (to truth %.2f vox, branch %d)\n",
                      k, double(c.volume(vx[k][0], vx[k][1], vx[k][2])),
                      double(ac.smoothed(vx[k][0], vx[k][1], vx[k][2])), du, ds, cst, own.distanceMm / vox, own.branch);
        }
      }
      if (std::getenv("VS_FAMILY_DIAG_TRUTH")) {  // session 17 (par1): the lumen model along the own truth
        for (int b = t.terminalBranches[i]; b >= 0; b = t.branches[size_t(b)].parent) {
          const auto& pts = t.branches[size_t(b)].points;
          for (size_t k = 0; k < pts.size(); k += 2) {
            Index3 v;
            for (int a = 0; a < 3; ++a) v[a] = std::clamp<int64_t>(std::llround(pts[k][a]), 0, g.dims[a] - 1);
            const LocalContrast lc = localContrastAt(ac.smoothed, ac.background, ac.estimate, v);
            const double ds = valleyDepth(ac.smoothed, ac.background.valleys, v[0], v[1], v[2], !c.dark, 1e30);
            const double du = valleyDepth(c.volume, ac.background.valleys, v[0], v[1], v[2], !c.dark, 1e30);
            const size_t lin = size_t(g.linear(v[0], v[1], v[2]));
            std::printf(
                "    truth b%d %zu (%lld %lld %lld) r %.2f: sm %.1f bg %.1f (t %.1f..%.1f) struct %d valley raw %.1f "
                "sm %.1f cost %.4f\n",
                b, k, (long long)v[0], (long long)v[1], (long long)v[2], t.branches[size_t(b)].radiiMm[k],
                double(ac.smoothed(v[0], v[1], v[2])), lc.background, lc.lo, lc.hi,
                ac.background.structure.empty() ? -1 : int(ac.background.structure[lin]), du, ds,
                double(ac.cost.node[lin]));
          }
        }
        std::printf("  estimate: %s\n", ac.estimate.describe().c_str());
        if (const char* atEnv = std::getenv("VS_FAMILY_DIAG_AT")) {  // "x y z": the smoothed slab around it
          long long ax = 0, ay = 0, az = 0;
          if (std::sscanf(atEnv, "%lld %lld %lld", &ax, &ay, &az) == 3 && std::getenv("VS_FAMILY_DIAG_BLOCKS")) {
            // session 20 (par3): the 27 blocks whose most lumen-like value is the background here
            const BlockGrid bgr = blockGrid(g, AutoCostOptions{}.localBlockMm);
            const int64_t bi = ax / bgr.blockVoxels[0], bj = ay / bgr.blockVoxels[1], bk = az / bgr.blockVoxels[2];
            BlockSamples smp;
            for (int64_t k = std::max<int64_t>(0, bk - 1); k <= std::min(bgr.blocks[2] - 1, bk + 1); ++k)
              for (int64_t j = std::max<int64_t>(0, bj - 1); j <= std::min(bgr.blocks[1] - 1, bj + 1); ++j)
                for (int64_t bx = std::max<int64_t>(0, bi - 1); bx <= std::min(bgr.blocks[0] - 1, bi + 1); ++bx) {
                  const int64_t b = (k * bgr.blocks[1] + j) * bgr.blocks[0] + bx;
                  const PlainBlock pb = plainBlock(ac.smoothed, bgr, b, true, float(ac.estimate.windowLo), nullptr, 0,
                                                   25, 5, 5 * ac.estimate.spread, smp);
                  std::vector<float> vv = smp.vals;
                  std::sort(vv.begin(), vv.end());
                  const auto pc = [&](double f) { return vv.empty() ? 0.f : vv[size_t(f * double(vv.size() - 1))]; };
                  std::printf(
                      "   block %lld %lld %lld: raw %.1f uncapped %.1f spread %.2f p5 %.1f p25 %.1f p50 %.1f "
                      "p75 %.1f n %zu (voxels %lld %lld %lld)\n",
                      (long long)bx, (long long)j, (long long)k, pb.raw, pb.uncapped, pb.spread, pc(0.05), pc(0.25),
                      pc(0.5), pc(0.75), vv.size(), (long long)bgr.blockVoxels[0], (long long)bgr.blockVoxels[1],
                      (long long)bgr.blockVoxels[2]);
                }
          } else if (std::sscanf(atEnv, "%lld %lld %lld", &ax, &ay, &az) == 3)
            for (int64_t z = std::max<int64_t>(0, az - 2); z <= std::min<int64_t>(g.dims[2] - 1, az + 2); ++z) {
              std::printf("   z %lld:\n", (long long)z);
              for (int64_t x = 0; x < g.dims[0]; ++x) {
                std::printf("   ");
                for (int64_t y = std::max<int64_t>(0, ay - 1); y <= std::min<int64_t>(g.dims[1] - 1, ay + 1); ++y)
                  std::printf(" %5.0f", double(ac.smoothed(x, y, z)));
                std::printf("\n");
              }
            }
        }
      }
      std::printf("  noise %.1f, background %.1f, foreground %.1f\n", t.noiseSigma, t.background, t.foreground);
      std::printf("  cost path %zu: truth %.3f (worst voxel %.3f), path %.3f; path voxels > 0.01:%s\n", i, truthSum,
                  worst, pathSum, prof.c_str());
    }
  }
  // The contact's direction: from A's centreline to B's at B's middle point, in voxels of each axis;
  // the gap as the sampling sees it (the gap's mm over the spacing along that direction).
  if (t.branches.size() >= 3) {
    const VesselBranch& B = t.branches[2];
    const Vec3 pb = B.points[B.points.size() / 2];
    VesselTruth a = t;
    a.branches = {t.branches[1]};
    const CenterlineDistance da = distanceToCenterline(a, pb);
    const Vec3 dmm = (pb - da.closest).cwiseProduct(t.spacing).normalized();
    const double along = 1.0 / dmm.cwiseQuotient(t.spacing).norm();  // mm per voxel step along dmm
    std::printf("  contact direction %.2f %.2f %.2f (mm), spacing along it %.2f mm, gap %.2f of those\n", dmm[0],
                dmm[1], dmm[2], along, c.gapVoxels * vox / along);
  }
  std::printf(
      "[kiss %s] %zu points, far: cross %zu pulled %zu other %zu; cross fixed %zu; contact %zu; radius error %.3f "
      "(contact %.3f, %zu)\n",
      c.describe().c_str(), n, cross, pulled, other, crossFixed, contact, nRad ? radErr / double(nRad) : 0.0,
      nRadContact ? radErrContact / double(nRadContact) : 0.0, nRadContact);
}

class FamilyDiagnosisKissing : public ::testing::TestWithParam<uint64_t> {};
TEST_P(FamilyDiagnosisKissing, KissingAndParallel) {
  if (const char* given = std::getenv("VS_FAMILY_DIAG_KISS_GIVEN")) {  // the variant given (13's 9707-9709)
    const bool parallel = std::string(given) == "parallel";            // session 17 (par1): 10010-10012
    diagnoseKissing(
        makeVesselFamilyCase(GetParam(), parallel ? VesselFamilyVariant::Parallel : VesselFamilyVariant::Kissing));
    return;
  }
  const VesselFamilyVariant v = vesselFamilyVariantOf(GetParam());
  if (v == VesselFamilyVariant::Kissing || v == VesselFamilyVariant::Parallel)
    diagnoseKissing(makeVesselFamilyCase(GetParam()));
}
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(FamilyDiagnosisKissing);
INSTANTIATE_TEST_SUITE_P(Sweep, FamilyDiagnosisKissing, ::testing::ValuesIn(seedsFrom("VS_FAMILY_DIAG_KISS")),
                         [](const auto& p) { return "seed" + std::to_string(p.param); });

// Wide lumens (session 16, wide6): the lumen model across the trunk. Per trunk point (every 8th of
// the branches whose radius is >= 5 voxels) the node cost and the smoothed value at 0, 0.25, 0.5,
// 0.75, 0.9 and 1.1 of the radius from the axis (two directions across it), and the confine level
// (half the lumen cost). A sweep only: VS_FAMILY_DIAG_WIDE=FIRST-LAST (wide given); none in CI.
void diagnoseWide(const VesselFamilyCase& c) {
  const VesselTruth& t = c.truth;
  const AutoCost ac = computeAutoCost(c.volume, t.rootVoxel, AutoCostOptions{}, Progress::none());
  const Geometry& g = ac.cost.geometry;
  const double vox = t.spacing.minCoeff(), level = 0.5 * lumenCostThreshold(ac.cost);
  std::printf("[wide %s] R %.1f vox, %s, confine level %.3f\n", c.describe().c_str(), c.lumenRadiusVoxels,
              ac.estimate.describe().c_str(), level);
  auto at = [&](const Vec3& p, bool cost) {
    Index3 v;
    for (int a = 0; a < 3; ++a) v[a] = std::clamp<int64_t>(std::llround(p[a]), 0, g.dims[a] - 1);
    const size_t i = size_t(g.linear(v[0], v[1], v[2]));
    return cost ? double(ac.cost.nodeWeight * ac.cost.node[i]) : double(ac.smoothed.data()[i]);
  };
  for (size_t b = 0; b < t.branches.size(); ++b) {
    const VesselBranch& br = t.branches[b];
    std::printf("  branch %zu: %zu points, radius %.2f vox\n", b, br.points.size(), br.radiiMm.front() / vox);
    if (br.radiiMm.front() < 5 * vox || br.points.size() < 2) continue;
    for (double a : {0.2, 0.5, 0.8}) {
      const Vec3 e = (br.points.back() - br.points.front()).cwiseProduct(t.spacing).normalized();
      const Vec3 o = br.points.front() + a * (br.points.back() - br.points.front());
      Vec3 u = e.cross(Vec3(0, 0, 1));
      if (u.norm() < 0.3) u = e.cross(Vec3(1, 0, 0));
      u.normalize();
      const Vec3 w = e.cross(u);
      const double R = br.radiiMm.front();
      std::printf("  branch %zu at %.1f:", b, a);
      for (const Vec3& d : {u, w, Vec3(-u), Vec3(-w)}) {
        std::printf(" |");
        for (double f : {0.0, 0.25, 0.5, 0.75, 0.9, 1.1}) {
          const Vec3 p = o + (f * R * d).cwiseQuotient(t.spacing);
          std::printf(" %.2f/%.0f", at(p, true), at(p, false));
        }
      }
      std::printf("\n");
    }
  }
}
class FamilyDiagnosisWide : public ::testing::TestWithParam<uint64_t> {};
TEST_P(FamilyDiagnosisWide, WideLumen) {
  diagnoseWide(makeVesselFamilyCase(GetParam(), VesselFamilyVariant::WideLumen));
}
GTEST_ALLOW_UNINSTANTIATED_PARAMETERIZED_TEST(FamilyDiagnosisWide);
INSTANTIATE_TEST_SUITE_P(Sweep, FamilyDiagnosisWide, ::testing::ValuesIn(seedsFrom("VS_FAMILY_DIAG_WIDE")),
                         [](const auto& p) { return "seed" + std::to_string(p.param); });

}  // namespace
}  // namespace vs
