// A flat lumen against two tubes fused at a contact, read from the section's shape (issue 21, flat lumens): an
// ellipse has no waist, two touching discs have one, and the probe that prints the reading on the family's
// flat / wide / kissing / parallel sections (VS_SHAPE_SEEDS, the classifier's separation table).
#include "tracking/section_shape.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>

#include "phantom/phantom.h"
#include "supersampled_slices.h"
#include "volume/volume.h"

namespace vs {
namespace {

using test_slices::supersampled;

TEST(SectionShape, AnEllipseHasNoWaist) {
  const double cx = 32.2, cy = 31.7, a = 12, b = 5, th = 0.5;
  const VolumeF32 v = supersampled({64, 64, 6}, 200, 20, [&](double x, double y) {
    const double u = (x - cx) * std::cos(th) + (y - cy) * std::sin(th),
                 w = -(x - cx) * std::sin(th) + (y - cy) * std::cos(th);
    return (u / a) * (u / a) + (w / b) * (w / b) <= 1;
  });
  TrilinearSampler s(v);
  SectionScratch sc;
  const Vec3 c(cx + 6 * std::cos(th), cy + 6 * std::sin(th), 3);  // half way to the end of the wide axis
  const SectionShape r = sectionShape(s, Vec3(1, 1, 1), c, Vec3(0, 0, 1), s.at(c), 20, 30, sc);
  ASSERT_TRUE(r.ok);
  EXPECT_NEAR(r.aspect, a / b, 0.25);
  EXPECT_GT(r.waist, 0.95);
  EXPECT_GT(r.massWaist, 0.95);
}

TEST(SectionShape, TwoTouchingDiscsHaveAWaist) {
  const double r = 5, gap = 0.3, cy = 31.6, ax = 26.4, bx = ax + 2 * r + gap;
  const VolumeF32 v = supersampled({64, 64, 6}, 200, 20, [&](double x, double y) {
    return std::hypot(x - ax, y - cy) <= r || std::hypot(x - bx, y - cy) <= r;
  });
  TrilinearSampler s(v);
  SectionScratch sc;
  const Vec3 c(ax, cy, 3);
  const SectionShape sh = sectionShape(s, Vec3(1, 1, 1), c, Vec3(0, 0, 1), s.at(c), 20, 30, sc);
  ASSERT_TRUE(sh.ok);
  EXPECT_GT(sh.aspect, 1.7);
  EXPECT_LT(sh.waist, 0.6);
  EXPECT_LT(sh.massWaist, 0.7);
}

// The separation table: VS_SHAPE_SEEDS=A-B[,C-D...] and VS_SHAPE_VARIANT=flat | given | blind (blind: the
// blocks' order, b01-b03 thin, b04-b06 wide, b07-b09 kissing, b10-b12 parallel). One "[sec]" line per truth
// point: seed, variant, label, aspect, waist, massWaist, length / width mm, clipped. Labels: flat / wide trunk
// ("-junction" within three daughter radii + two voxels of a daughter's origin), kissing / parallel "contact"
// (A and B within their radii + the gap + half a voxel, past the fork's reach), "fork", "apart", "trunk"; thin.
std::vector<uint64_t> parseSeeds(const char* env) {
  std::vector<uint64_t> out;
  std::string s = env;
  size_t p = 0;
  while (p < s.size()) {
    size_t q = s.find(',', p);
    if (q == std::string::npos) q = s.size();
    const std::string part = s.substr(p, q - p);
    const size_t dash = part.find('-');
    const uint64_t a = std::strtoull(part.c_str(), nullptr, 10),
                   b = dash == std::string::npos ? a : std::strtoull(part.c_str() + dash + 1, nullptr, 10);
    for (uint64_t k = a; k <= b; ++k) out.push_back(k);
    p = q + 1;
  }
  return out;
}

TEST(SectionShapeProbe, SeparationTable) {
  const char* env = std::getenv("VS_SHAPE_SEEDS");
  if (!env) GTEST_SKIP() << "VS_SHAPE_SEEDS not set";
  const std::string mode = std::getenv("VS_SHAPE_VARIANT") ? std::getenv("VS_SHAPE_VARIANT") : "given";
  const double halfMm = std::getenv("VS_SHAPE_HALF") ? std::atof(std::getenv("VS_SHAPE_HALF")) : 30.0;
  for (const uint64_t seed : parseSeeds(env)) {
    VesselFamilyCase fc;
    if (mode == "flat") {
      fc = makeVesselFamilyCase(seed, VesselFamilyVariant::Flat);
    } else if (mode == "blind") {
      const VesselFamilyVariant v[4] = {VesselFamilyVariant::Thin, VesselFamilyVariant::WideLumen,
                                        VesselFamilyVariant::Kissing, VesselFamilyVariant::Parallel};
      fc = makeVesselFamilyCase(seed, v[((seed % 100) - 1) / 3 % 4]);
    } else {
      fc = makeVesselFamilyCase(seed);
    }
    const VesselTruth& t = fc.truth;
    const Vec3 sp = t.spacing;
    const double vox = sp.minCoeff();
    const TrilinearSampler sample(fc.volume);
    SectionScratch sc;
    const double surroundings = fc.dark ? t.foreground : t.background;
    const std::string var = vesselFamilyVariantName(fc.variant);
    double rMax = 0;
    for (const auto& b : t.branches) rMax = std::max(rMax, b.radiiMm.front());
    auto mm = [&](const Vec3& p) { return Vec3(p.cwiseProduct(sp)); };
    for (size_t bi = 0; bi < t.branches.size(); ++bi) {
      const VesselBranch& br = t.branches[bi];
      const bool trunk = br.radiiMm.front() >= 0.9 * rMax;
      // Every voxel along the polyline (a straight trunk's branch has its two ends only).
      for (size_t seg = 0; seg + 1 < br.points.size(); ++seg) {
        const Vec3 pa = mm(br.points[seg]), pb = mm(br.points[seg + 1]);
        const double len = (pb - pa).norm();
        if (!(len > 0)) continue;
        const Vec3 tan = (pb - pa) / len;
        for (double a = seg == 0 ? vox : 0; a < len; a += vox) {
          const Vec3 c = pa + a * tan;
          const double rad = br.radiiMm[seg] + (br.radiiMm[seg + 1] - br.radiiMm[seg]) * a / len;
          std::string label = var;
          if (fc.variant == VesselFamilyVariant::Flat || fc.variant == VesselFamilyVariant::WideLumen) {
            if (!trunk) continue;  // the daughters are round
            label += "-trunk";
            for (const auto& o : t.branches)
              if (o.radiiMm.front() < 0.9 * rMax && o.parent >= 0 &&
                  (mm(o.points.front()) - c).norm() < 3 * o.radiiMm.front() + 2 * vox + rMax)
                label = var + "-junction";
          } else if (fc.variant == VesselFamilyVariant::Kissing || fc.variant == VesselFamilyVariant::Parallel) {
            if (bi == 0) {
              label += "-trunk";
            } else if (bi <= 2 && t.branches.size() > 2) {
              const VesselBranch& other = t.branches[bi == 1 ? 2 : 1];
              double d = 1e30;
              size_t at = 0;
              for (size_t q = 0; q < other.points.size(); ++q)
                if ((mm(other.points[q]) - c).norm() < d) d = (mm(other.points[q]) - c).norm(), at = q;
              const double fork = (mm(br.points.front()) - c).norm();
              const double touch = rad + other.radiiMm[at] + fc.gapVoxels * vox + 0.5 * vox;
              if (fork < 3 * t.branches[0].radiiMm.back() + 2 * vox)
                label += "-fork";
              else
                label += d <= touch ? "-contact" : "-apart";
            } else {
              continue;
            }
          } else {
            label += "-tree";
          }
          const Vec3 ci = c.cwiseQuotient(sp);
          if (!sample.inside(ci)) continue;
          const SectionShape s = sectionShape(sample, sp, c, tan, sample.at(ci), surroundings, halfMm, sc);
          std::printf("[sec] %llu %s %s %d %.3f %.3f %.3f %.2f %.2f %d %.2f %.3f %.2f %.2f\n",
                      static_cast<unsigned long long>(seed), var.c_str(), label.c_str(), s.ok ? 1 : 0, s.aspect,
                      s.waist, s.massWaist, s.lengthMm, s.widthMm, s.clipped ? 1 : 0, rad, s.plateau, vox,
                      sp.maxCoeff());
        }
      }
    }
  }
}

}  // namespace
}  // namespace vs
