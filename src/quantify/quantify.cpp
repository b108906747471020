#include "quantify/quantify.h"

#include <Eigen/Dense>
#include <algorithm>
#include <atomic>
#include <cmath>

#include "quantify/section.h"
#include "util/error.h"
#include "util/parallel.h"

namespace vs {

std::string lumenPolarityName(LumenPolarity p) {
  switch (p) {
    case LumenPolarity::Auto:
      return "auto";
    case LumenPolarity::Bright:
      return "bright";
    case LumenPolarity::Dark:
      return "dark";
  }
  return "auto";
}

LumenPolarity lumenPolarityFromName(const std::string& name) {
  if (name == "auto") return LumenPolarity::Auto;
  if (name == "bright") return LumenPolarity::Bright;
  if (name == "dark") return LumenPolarity::Dark;
  throw InvalidArgument("lumen polarity must be auto, bright or dark, got '" + name + "'");
}

std::string crossSectionFlagsText(uint32_t flags) {
  std::string s;
  auto add = [&](uint32_t bit, const char* name) {
    if (!(flags & bit)) return;
    if (!s.empty()) s += '|';
    s += name;
  };
  add(kSectionLeavesVolume, "leaves_volume");
  add(kSectionMeetsBranch, "meets_branch");
  add(kSectionNoBoundary, "no_boundary");
  return s;
}

int TreeMeasurement::measuredSections() const {
  return static_cast<int>(std::count_if(sections.begin(), sections.end(), [](const auto& s) { return s.measured(); }));
}

namespace {

using namespace quantify_detail;

// Robust stenosis of one segment's profile (see QuantifyOptions::healthyFraction).
// minLengthMm, significance: the noise guard (QuantifyOptions::stenosisMinLengthVoxels, stenosisSignificance).
void segmentStenosis(const std::vector<double>& s, const std::vector<double>& d, double healthy, double minLengthMm,
                     double significance, double maxLengthDiameters, SegmentMeasure& m, double& slope) {
  const size_t n = d.size();
  if (n < 3) return;
  // The raw profile: a running median would cut the tip off a short stenosis (a 5 mm notch loses
  // ~20 % of its minimum diameter to a median of 3 sections 0.5 mm apart); one section's
  // equivalent diameter already averages `rays` boundary points.
  const std::vector<double>& sm = d;
  const size_t iMin = static_cast<size_t>(std::min_element(sm.begin(), sm.end()) - sm.begin());
  std::vector<bool> keep(n, true);
  double a = 0, b = 0;
  for (int it = 0; it < 8; ++it) {
    double S = 0, Ss = 0, Sd = 0, Sss = 0, Ssd = 0;
    for (size_t i = 0; i < n; ++i)
      if (keep[i]) S += 1, Ss += s[i], Sd += sm[i], Sss += s[i] * s[i], Ssd += s[i] * sm[i];
    const double det = S * Sss - Ss * Ss;
    if (S >= 3 && det > 1e-9 * S * S) {
      b = (S * Ssd - Ss * Sd) / det;
      a = (Sd - b * Ss) / S;
    } else {
      std::vector<double> kept;
      for (size_t i = 0; i < n; ++i)
        if (keep[i]) kept.push_back(sm[i]);
      a = kept.empty() ? median(sm) : median(kept);
      b = 0;
    }
    bool changed = false;
    for (size_t i = 0; i < n; ++i) {
      const bool k = sm[i] >= healthy * (a + b * s[i]);
      changed |= k != keep[i];
      keep[i] = k;
    }
    if (!changed) break;
  }
  m.minDiameterMm = sm[iMin];
  m.minArcMm = s[iMin];
  m.referenceDiameterMm = a + b * s[iMin];
  slope = b;
  // NASCET-like: the reference needs healthy lumen on both sides of the narrowing (two sections
  // each); a minimum at a segment's end (a taper into the periphery, a cut-off) is no stenosis.
  int before = 0, after = 0;
  for (size_t i = 0; i < n; ++i)
    if (keep[i]) (s[i] < s[iMin] ? before : after) += s[i] != s[iMin];
  if (before < 2 || after < 2) return;
  // Noise guard: the narrowed run (sections below the healthy band, contiguous with the minimum)
  // from the midpoints to its healthy neighbours, and the narrowing against the healthy scatter.
  size_t lo = iMin, hi = iMin;
  while (lo > 0 && !keep[lo - 1]) --lo;
  while (hi + 1 < n && !keep[hi + 1]) ++hi;
  double length = 0;
  if (!keep[iMin]) {
    const double from = lo > 0 ? 0.5 * (s[lo - 1] + s[lo]) : s[lo];
    const double to = hi + 1 < n ? 0.5 * (s[hi] + s[hi + 1]) : s[hi];
    length = to - from;
  }
  m.stenosisLengthMm = length;
  std::vector<double> residual;
  for (size_t i = 0; i < n; ++i)
    if (keep[i]) residual.push_back(std::abs(sm[i] - (a + b * s[i])));
  const double scatter = 1.4826 * median(residual);
  if (length < minLengthMm || m.referenceDiameterMm - sm[iMin] < significance * scatter) return;
  if (length > maxLengthDiameters * m.referenceDiameterMm) return;  // a taper or diffuse narrowing
  m.stenosis = m.referenceDiameterMm > 0 ? std::max(0.0, 1 - sm[iMin] / m.referenceDiameterMm) : kNaN;
}

// Segments (root or branch point -> branch point or tip), branch points, generations and
// Strahler orders of m.tree.
void buildSegments(TreeMeasurement& m) {
  const Tree& tree = m.tree;
  const size_t N = tree.size();
  std::vector<std::vector<int32_t>> children(N);
  for (size_t i = 0; i < N; ++i)
    if (tree.parent[i] >= 0) children[static_cast<size_t>(tree.parent[i])].push_back(static_cast<int32_t>(i));
  struct Pending {
    int32_t start, next;
    int parent;
  };
  std::vector<Pending> todo;
  for (size_t i = 0; i < N; ++i) {
    if (tree.parent[i] >= 0) continue;
    if (children[i].size() >= 2) {
      BranchPointMeasure bp;
      bp.node = static_cast<int32_t>(i);
      bp.positionMm = tree.points[i];
      m.branchPoints.push_back(bp);
    }
    for (int32_t c : children[i]) todo.push_back({static_cast<int32_t>(i), c, -1});
  }
  for (size_t t = 0; t < todo.size(); ++t) {
    const Pending pd = todo[t];
    SegmentMeasure seg;
    seg.parent = pd.parent;
    seg.nodes = {pd.start};
    int32_t cur = pd.next;
    while (true) {
      seg.nodes.push_back(cur);
      if (children[static_cast<size_t>(cur)].size() != 1) break;
      cur = children[static_cast<size_t>(cur)][0];
    }
    const int id = static_cast<int>(m.segments.size());
    if (seg.parent >= 0) {
      seg.generation = m.segments[static_cast<size_t>(seg.parent)].generation + 1;
      m.segments[static_cast<size_t>(seg.parent)].children.push_back(id);
    }
    const auto& ch = children[static_cast<size_t>(cur)];
    if (ch.size() >= 2) {
      BranchPointMeasure bp;
      bp.node = cur;
      bp.positionMm = tree.points[static_cast<size_t>(cur)];
      bp.parentSegment = id;
      m.branchPoints.push_back(bp);
      for (int32_t c : ch) todo.push_back({cur, c, id});
    }
    m.segments.push_back(std::move(seg));
  }
  for (auto& bp : m.branchPoints)
    for (size_t s = 0; s < m.segments.size(); ++s)
      if (m.segments[s].nodes.front() == bp.node) bp.childSegments.push_back(static_cast<int>(s));
  // Strahler orders (children come after their parent in m.segments).
  for (size_t s = m.segments.size(); s-- > 0;) {
    auto& seg = m.segments[s];
    if (seg.children.empty()) continue;
    int best = 0, count = 0;
    for (int c : seg.children) {
      const int o2 = m.segments[static_cast<size_t>(c)].strahler;
      if (o2 > best)
        best = o2, count = 1;
      else if (o2 == best)
        ++count;
    }
    seg.strahler = count >= 2 ? best + 1 : best;
  }
}

// The section rule: b's lumen (radius rb) crosses a's plane within a's own boundary.
bool meetsLumen(const CrossSection& a, const CrossSection& b, double rb) {
  const Vec3 d = b.centreMm - a.centreMm;
  const double along = a.tangent.dot(d);
  if (std::abs(along) > rb) return false;
  return (d - along * a.tangent).norm() <= a.outerRadiusMm + rb;
}

// Flags the sections another segment's lumen crosses (lumenRadius: per section, its equivalent
// radius when measured, else its hint radius).
void flagMeetingSections(TreeMeasurement& m, const std::vector<double>& lumenRadius, const QuantifyOptions& o) {
  // Sections another segment's lumen crosses.
  struct Box {
    Vec3 lo, hi;
  };
  std::vector<Box> boxes(m.segments.size());
  double maxOuter = 0;
  for (const auto& cs : m.sections) maxOuter = std::max(maxOuter, cs.outerRadiusMm);
  for (size_t si = 0; si < m.segments.size(); ++si) {
    Box b{Vec3::Constant(1e300), Vec3::Constant(-1e300)};
    for (int i : m.segments[si].sections) {
      b.lo = b.lo.cwiseMin(m.sections[static_cast<size_t>(i)].centreMm);
      b.hi = b.hi.cwiseMax(m.sections[static_cast<size_t>(i)].centreMm);
    }
    boxes[si] = b;
  }
  std::vector<uint8_t> meets(m.sections.size(), 0);
  for (size_t si = 0; si < m.segments.size(); ++si)
    for (size_t sj = 0; sj < m.segments.size(); ++sj) {
      if (si == sj) continue;
      const double margin = 2 * maxOuter + o.stepMm;
      if ((boxes[si].lo.array() - margin > boxes[sj].hi.array()).any() ||
          (boxes[sj].lo.array() - margin > boxes[si].hi.array()).any())
        continue;
      for (int i : m.segments[si].sections) {
        const CrossSection& a = m.sections[static_cast<size_t>(i)];
        for (int j : m.segments[sj].sections) {
          if (!meetsLumen(a, m.sections[static_cast<size_t>(j)], lumenRadius[static_cast<size_t>(j)])) continue;
          meets[static_cast<size_t>(i)] = 1;
          break;
        }
      }
    }
  for (size_t i = 0; i < m.sections.size(); ++i)
    if (meets[i]) m.sections[i].flags |= kSectionMeetsBranch;
}

// No numbers (and no boundary) for a flagged section.
void clearFlagged(TreeMeasurement& m) {
  for (auto& cs : m.sections)
    if (!cs.measured()) {
      cs.areaMm2 = cs.equivalentDiameterMm = cs.minDiameterMm = cs.maxDiameterMm = kNaN;
      cs.minDirection = cs.maxDirection = Vec3::Zero();
      cs.boundaryMm.clear();
    }
}

// Whether any section of another segment than a's meets a (the rule of flagMeetingSections).
bool meetsAnotherSegment(const TreeMeasurement& m, const CrossSection& a, const std::vector<double>& lumenRadius) {
  for (size_t j = 0; j < m.sections.size(); ++j) {
    const CrossSection& b = m.sections[j];
    if (b.segment != a.segment && meetsLumen(a, b, lumenRadius[j])) return true;
  }
  return false;
}

// The branch point's neighbour on one of its segments (see BranchPointMeasure): the measured
// section nearest the branch point that no other branch meets. Between the last flagged and the
// first measured regular station (from the branch point), sections every step/8 are tried in
// order; the first that is measured and clear is added to the segment. -1 when the segment has no
// measured section.
int branchNeighbour(TreeMeasurement& m, const std::vector<Curve>& curves, const SectionContext& ctx, double sign,
                    std::vector<double>& lumenRadius, int si, bool atEnd, int bpIndex) {
  SegmentMeasure& seg = m.segments[static_cast<size_t>(si)];
  const Curve& c = curves[static_cast<size_t>(si)];
  auto dist = [&](double arc) { return atEnd ? c.length() - arc : arc; };
  std::vector<int> order = seg.sections;  // by distance from the branch point
  if (atEnd) std::reverse(order.begin(), order.end());
  size_t q = 0;
  while (q < order.size() && !m.sections[static_cast<size_t>(order[q])].measured()) ++q;
  if (q == order.size()) return -1;
  int found = order[q];
  if (q > 0) {
    const double d0 = dist(m.sections[static_cast<size_t>(order[q - 1])].arcMm);
    const double d1 = dist(m.sections[static_cast<size_t>(order[q])].arcMm);
    for (int k = 1; k < 8; ++k) {
      const double d = d0 + (d1 - d0) * k / 8, arc = atEnd ? c.length() - d : d;
      CrossSection cs = placeSection(c, si, arc);
      measureSection(ctx, sign, c.radius(arc), cs);
      if (!cs.measured() || meetsAnotherSegment(m, cs, lumenRadius)) continue;
      found = static_cast<int>(m.sections.size());
      m.sections.push_back(std::move(cs));
      lumenRadius.push_back(0.5 * m.sections.back().equivalentDiameterMm);
      auto pos = std::lower_bound(seg.sections.begin(), seg.sections.end(), arc,
                                  [&](int i, double s) { return m.sections[static_cast<size_t>(i)].arcMm < s; });
      seg.sections.insert(pos, found);
      break;
    }
  }
  m.sections[static_cast<size_t>(found)].branchPoint = bpIndex;
  return found;
}

void branchNeighbours(TreeMeasurement& m, const std::vector<Curve>& curves, const SectionContext& ctx, double sign,
                      std::vector<double>& lumenRadius) {
  for (size_t b = 0; b < m.branchPoints.size(); ++b) {
    BranchPointMeasure& bp = m.branchPoints[b];
    const int bi = static_cast<int>(b);
    if (bp.parentSegment >= 0)
      bp.parentSection = branchNeighbour(m, curves, ctx, sign, lumenRadius, bp.parentSegment, true, bi);
    for (int cseg : bp.childSegments)
      bp.childSections.push_back(branchNeighbour(m, curves, ctx, sign, lumenRadius, cseg, false, bi));
  }
}

// Per segment: diameters and stenosis (the narrowest point refined by sections every step/8).
void segmentMeasures(TreeMeasurement& m, const std::vector<Curve>& curves, const SectionContext& ctx, double sign,
                     const QuantifyOptions& o) {
  const double spacing = ctx.volume.geometry().spacing.maxCoeff();  // the largest: the resolution along any axis
  for (auto& seg : m.segments) {
    std::vector<double> s, d;
    for (int i : seg.sections) {
      const CrossSection& cs = m.sections[static_cast<size_t>(i)];
      if (!cs.measured()) continue;
      s.push_back(cs.arcMm);
      d.push_back(cs.equivalentDiameterMm);
    }
    seg.measuredSections = static_cast<int>(d.size());
    if (d.empty()) continue;
    double sum = 0;
    for (double x : d) sum += x;
    seg.meanDiameterMm = sum / static_cast<double>(d.size());
    const size_t k = static_cast<size_t>(std::min_element(d.begin(), d.end()) - d.begin());
    seg.minDiameterMm = d[k];
    seg.minArcMm = s[k];
    double slope = 0;
    segmentStenosis(s, d, o.healthyFraction, o.stenosisMinLengthVoxels * spacing, o.stenosisSignificance,
                    o.stenosisMaxLengthDiameters, seg, slope);
    if (std::isnan(seg.stenosis)) continue;
    // The narrowest point between two stations: sections every step/8 around the smallest one
    // (not in the profile), against the same reference line.
    const int si = static_cast<int>(&seg - m.segments.data());
    const Curve& c = curves[static_cast<size_t>(si)];
    double best = seg.minDiameterMm, bestS = seg.minArcMm;
    for (int q = -3; q <= 3; ++q) {
      const double sk = seg.minArcMm + q * o.stepMm / 8;
      if (q == 0 || sk < 0 || sk > c.length()) continue;
      CrossSection extra = placeSection(c, si, sk);
      measureSection(ctx, sign, c.radius(sk), extra);
      if (extra.measured() && extra.equivalentDiameterMm < best) best = extra.equivalentDiameterMm, bestS = sk;
    }
    if (bestS != seg.minArcMm) {
      seg.referenceDiameterMm += slope * (bestS - seg.minArcMm);
      seg.minDiameterMm = best;
      seg.minArcMm = bestS;
      seg.stenosis = std::max(0.0, 1 - best / seg.referenceDiameterMm);
    }
  }
}

// Branch angles: chords of the segments near each branch point (QuantifyOptions).
void branchAngles(TreeMeasurement& m, const std::vector<Curve>& curves, const QuantifyOptions& o) {
  auto radiusNearEnd = [&](int si, bool atEnd) {
    const auto& seg = m.segments[static_cast<size_t>(si)];
    const Curve& c = curves[static_cast<size_t>(si)];
    std::vector<double> d;
    for (int i : seg.sections) {
      const CrossSection& cs = m.sections[static_cast<size_t>(i)];
      const double dist = atEnd ? c.length() - cs.arcMm : cs.arcMm;
      if (cs.measured() && dist <= 5 + 4 * c.radius(atEnd ? c.length() : 0)) d.push_back(0.5 * cs.equivalentDiameterMm);
    }
    return d.empty() ? c.radius(atEnd ? c.length() : 0) : median(d);
  };
  for (auto& bp : m.branchPoints) {
    const double r =
        bp.parentSegment >= 0 ? radiusNearEnd(bp.parentSegment, true) : radiusNearEnd(bp.childSegments[0], false);
    const double a1 = o.directionStartRadii * r;
    const double a2 = a1 + std::max(o.directionMinLengthMm, o.directionLengthRadii * r);
    auto window = [&](double L, double& w1, double& w2) {
      w2 = std::min(a2, L);
      w1 = std::min(a1, w2 / 3);
    };
    Vec3 dp = Vec3::Zero();
    if (bp.parentSegment >= 0) {
      const Curve& c = curves[static_cast<size_t>(bp.parentSegment)];
      double w1, w2;
      window(c.length(), w1, w2);
      dp = c.at(c.length() - w1) - c.at(c.length() - w2);
    }
    std::vector<Vec3> dc;
    for (int cseg : bp.childSegments) {
      const Curve& c = curves[static_cast<size_t>(cseg)];
      double w1, w2;
      window(c.length(), w1, w2);
      dc.push_back(c.at(w2) - c.at(w1));
      const double ang = bp.parentSegment >= 0 ? angleDeg(dp, dc.back()) : kNaN;
      bp.childAnglesDeg.push_back(ang);
      m.segments[static_cast<size_t>(cseg)].branchAngleDeg = ang;
    }
    for (size_t i = 0; i < dc.size(); ++i)
      for (size_t j = i + 1; j < dc.size(); ++j) bp.pairAnglesDeg.push_back(angleDeg(dc[i], dc[j]));
  }
}

// Paths root -> tip: the profile (sections by arc from the root) and the path's measures.
void pathMeasures(TreeMeasurement& m, const std::vector<Curve>& curves) {
  for (size_t si = 0; si < m.segments.size(); ++si) {
    if (!m.segments[si].children.empty()) continue;
    PathMeasure p;
    for (int s = static_cast<int>(si); s >= 0; s = m.segments[static_cast<size_t>(s)].parent) p.segments.push_back(s);
    std::reverse(p.segments.begin(), p.segments.end());
    p.tipNode = m.segments[si].nodes.back();
    double offset = 0, sumD = 0;
    int nD = 0;
    Curve whole;
    for (size_t k = 0; k < p.segments.size(); ++k) {
      const auto& seg = m.segments[static_cast<size_t>(p.segments[k])];
      const Curve& c = curves[static_cast<size_t>(p.segments[k])];
      for (size_t q = 0; q < c.p.size(); ++q) {
        if (k > 0 && q == 0) continue;
        whole.s.push_back(whole.p.empty() ? 0 : whole.s.back() + (c.p[q] - whole.p.back()).norm());
        whole.p.push_back(c.p[q]);
        whole.r.push_back(c.r[q]);
      }
      for (size_t q = 0; q < seg.sections.size(); ++q) {
        if (k > 0 && q == 0) continue;
        const int i = seg.sections[q];
        const CrossSection& cs = m.sections[static_cast<size_t>(i)];
        p.sections.push_back(i);
        p.arcMm.push_back(offset + cs.arcMm);
        if (cs.measured()) {
          sumD += cs.equivalentDiameterMm;
          ++nD;
          if (std::isnan(p.minDiameterMm) || cs.equivalentDiameterMm < p.minDiameterMm) {
            p.minDiameterMm = cs.equivalentDiameterMm;
            p.minArcMm = p.arcMm.back();
          }
        }
      }
      if (!std::isnan(seg.stenosis) && (std::isnan(p.stenosis) || seg.stenosis > p.stenosis)) {
        p.stenosis = seg.stenosis;
        p.stenosisArcMm = offset + seg.minArcMm;
      }
      offset += seg.lengthMm;
    }
    p.lengthMm = offset;
    p.chordMm = whole.p.empty() ? 0 : (whole.p.back() - whole.p.front()).norm();
    p.distanceMetric = p.chordMm > 0 ? p.lengthMm / p.chordMm : kNaN;
    p.sumOfAnglesRadPerCm = sumOfAngles(whole);
    if (nD > 0) p.meanDiameterMm = sumD / nD;
    m.paths.push_back(std::move(p));
  }
}

}  // namespace

TreeMeasurement measureTree(const VolumeF32& volume, const Tree& input, const QuantifyOptions& o, Progress& progress) {
  VS_REQUIRE(o.stepMm > 0 && std::isfinite(o.stepMm), "quantify: stepMm must be > 0");
  VS_REQUIRE(o.rays >= 8, "quantify: at least 8 rays");
  VS_REQUIRE(o.sampleStepVoxels > 0 && o.sampleStepVoxels <= 1, "quantify: sampleStepVoxels in (0, 1]");
  VS_REQUIRE(o.maxRadiusMm > 0, "quantify: maxRadiusMm must be > 0");
  VS_REQUIRE(o.healthyFraction > 0 && o.healthyFraction < 1, "quantify: healthyFraction in (0, 1)");
  VS_REQUIRE(o.stenosisMinLengthVoxels >= 0 && o.stenosisSignificance >= 0 && o.stenosisMaxLengthDiameters > 0,
             "quantify: stenosis rule parameters >= 0");
  VS_REQUIRE(!volume.empty(), "quantify: empty volume");
  checkTreeInVolume(volume.geometry(), input);
  const double vox = volume.geometry().spacing.minCoeff();

  TreeMeasurement m;
  m.tree = mergeCoincidentBranches(input, &m.mergedBranches);
  buildSegments(m);
  // Curves and regular stations.
  std::vector<Curve> curves;
  for (auto& seg : m.segments) {
    curves.push_back(makeCurve(m.tree, seg.nodes, vox));
    const Curve& c = curves.back();
    seg.lengthMm = c.length();
    seg.chordMm = (c.p.back() - c.p.front()).norm();
    seg.distanceMetric = seg.chordMm > 0 ? seg.lengthMm / seg.chordMm : kNaN;
    seg.sumOfAnglesRadPerCm = sumOfAngles(c);
  }
  std::vector<double> hints;
  for (size_t si = 0; si < m.segments.size(); ++si) {
    const Curve& c = curves[si];
    if (c.p.size() < 2) continue;
    for (double s : stations(c.length(), o.stepMm)) {
      m.segments[si].sections.push_back(static_cast<int>(m.sections.size()));
      m.sections.push_back(placeSection(c, static_cast<int>(si), s));
      hints.push_back(c.radius(s));
    }
  }
  const SectionContext ctx(volume, o);
  // Polarity: the sign of the median lumen contrast.
  double sign = o.polarity == LumenPolarity::Dark ? -1.0 : 1.0;
  if (o.polarity == LumenPolarity::Auto) {
    std::vector<double> contrast;
    const size_t stride = std::max<size_t>(1, m.sections.size() / 200);
    for (size_t i = 0; i < m.sections.size(); i += stride) {
      const double c = sectionContrast(ctx, m.sections[i].centreMm, m.sections[i].tangent, std::max(hints[i], vox));
      if (!std::isnan(c)) contrast.push_back(c);
    }
    if (contrast.empty())
      throw DataError(
          "quantify: cannot tell a bright from a dark lumen (every section's surroundings leave the "
          "volume): give the polarity");
    sign = median(contrast) >= 0 ? 1.0 : -1.0;
  }
  m.polarity = sign > 0 ? LumenPolarity::Bright : LumenPolarity::Dark;
  const int64_t S = static_cast<int64_t>(m.sections.size());
  std::atomic<int64_t> done{0};
  parallelFor(
      0, S,
      [&](int64_t b, int64_t e) {
        for (int64_t i = b; i < e; ++i) {
          if ((i & 63) == 0) progress.check();
          measureSection(ctx, sign, hints[static_cast<size_t>(i)], m.sections[static_cast<size_t>(i)]);
        }
        const int64_t d = done += e - b;
        progress.report(static_cast<double>(d) / static_cast<double>(std::max<int64_t>(1, S)), "cross-sections");
      },
      std::max<int64_t>(1, o.sectionsPerThread));
  progress.check();

  std::vector<double> lumenRadius(m.sections.size());
  for (size_t i = 0; i < m.sections.size(); ++i)
    lumenRadius[i] = m.sections[i].measured() ? 0.5 * m.sections[i].equivalentDiameterMm : hints[i];
  flagMeetingSections(m, lumenRadius, o);
  clearFlagged(m);
  branchNeighbours(m, curves, ctx, sign, lumenRadius);
  segmentMeasures(m, curves, ctx, sign, o);
  branchAngles(m, curves, o);
  pathMeasures(m, curves);
  return m;
}

}  // namespace vs
