#include "quantify/quantify.h"

#include <atomic>

#include "quantify/quantify_detail.h"
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
    if (flags & bit) s += (s.empty() ? "" : "|") + std::string(name);
  };
  add(kSectionLeavesVolume, "leaves_volume");
  add(kSectionMeetsBranch, "meets_branch");
  add(kSectionNoBoundary, "no_boundary");
  return s;
}

int TreeMeasurement::measuredSections() const {
  return static_cast<int>(std::count_if(sections.begin(), sections.end(), [](const auto& s) { return s.measured(); }));
}

using namespace quantify_detail;

namespace {

Curve makeCurve(const Tree& tree, const std::vector<int32_t>& nodes, double fallbackRadius) {
  Curve c;
  for (int32_t i : nodes) {
    const Vec3& q = tree.points[static_cast<size_t>(i)];
    if (!c.p.empty() && (q - c.p.back()).norm() < 1e-9) continue;  // duplicate point
    c.s.push_back(c.p.empty() ? 0 : c.s.back() + (q - c.p.back()).norm());
    c.p.push_back(q);
    const double r = tree.radii.empty() ? 0 : tree.radii[static_cast<size_t>(i)];
    c.r.push_back(std::isfinite(r) && r > 0 ? r : fallbackRadius);
  }
  return c;
}
// Robust stenosis of one segment's profile (see QuantifyOptions::healthyFraction).
void segmentStenosis(const std::vector<double>& s, const std::vector<double>& d, double healthy, SegmentMeasure& m,
                     double& slope) {
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
  m.stenosis = m.referenceDiameterMm > 0 ? std::max(0.0, 1 - sm[iMin] / m.referenceDiameterMm) : kNaN;
}

}  // namespace

Tree mergeCoincidentBranches(const Tree& input, int* merged) {
  Tree tree = input;
  if (merged) *merged = 0;
  auto radius = [&](int32_t i) { return tree.radii.empty() ? 0.0 : tree.radii[static_cast<size_t>(i)]; };
  for (bool changed = true; changed;) {
    changed = false;
    const size_t n = tree.size();
    std::vector<std::vector<int32_t>> children(n);
    for (size_t i = 0; i < n; ++i)
      if (tree.parent[i] >= 0) children[static_cast<size_t>(tree.parent[i])].push_back(static_cast<int32_t>(i));
    auto chain = [&](int32_t c) {
      std::vector<int32_t> out{c};
      while (children[static_cast<size_t>(out.back())].size() == 1)
        out.push_back(children[static_cast<size_t>(out.back())][0]);
      return out;
    };
    std::vector<char> drop(n, 0);
    for (size_t b = 0; b < n && !changed; ++b) {
      const auto& ch = children[b];
      for (size_t i = 0; i < ch.size() && !changed; ++i)
        for (size_t j = 0; j < ch.size() && !changed; ++j) {
          if (i == j) continue;
          std::vector<int32_t> A = chain(ch[i]), B = chain(ch[j]);
          if (A.size() < B.size() || (A.size() == B.size() && i > j)) continue;  // B: the shorter chain
          A.insert(A.begin(), static_cast<int32_t>(b));
          auto nearest = [&](int32_t q) {
            int32_t best = A[0];
            double bd = 1e300;
            for (int32_t a : A) {
              const double d = (tree.points[static_cast<size_t>(a)] - tree.points[static_cast<size_t>(q)]).norm();
              if (d < bd) bd = d, best = a;
            }
            return std::pair<int32_t, double>(best, bd);
          };
          size_t K = 0;
          while (K < B.size()) {
            const auto [a, d] = nearest(B[K]);
            if (!(d < 0.5 * radius(a))) break;
            ++K;
          }
          if (K < 2) continue;
          // B[0..K-1] run inside A's lumen: drop them, hang the rest of B (or B's children) on A.
          for (size_t k = 0; k < K; ++k) drop[static_cast<size_t>(B[k])] = 1;
          if (K < B.size()) {
            tree.parent[static_cast<size_t>(B[K])] = nearest(B[K]).first;
          } else {
            for (int32_t c : children[static_cast<size_t>(B.back())])
              tree.parent[static_cast<size_t>(c)] = nearest(c).first;
          }
          changed = true;
        }
    }
    if (!changed) break;
    if (merged) ++*merged;
    std::vector<int32_t> map(n, -1);
    Tree out;
    for (size_t i = 0; i < n; ++i) {
      if (drop[i]) continue;
      map[i] = static_cast<int32_t>(out.points.size());
      out.points.push_back(tree.points[i]);
      out.parent.push_back(tree.parent[i]);
      if (!tree.radii.empty()) out.radii.push_back(tree.radii[i]);
      if (!tree.types.empty()) out.types.push_back(tree.types[i]);
    }
    for (auto& p : out.parent)
      if (p >= 0) p = map[static_cast<size_t>(p)];
    tree = std::move(out);
  }
  return tree;
}

void checkTreeInVolume(const Geometry& g, const Tree& tree, const std::string& treeName) {
  tree.validate();
  if (tree.size() == 0) throw DataError(treeName + " has no points");
  size_t outside = 0, first = 0;
  for (size_t i = 0; i < tree.size(); ++i)
    if (!g.nearVolume(tree.points[i])) {
      if (outside++ == 0) first = i;
    }
  if (outside > 0) {
    const Vec3& p = tree.points[first];
    const Vec3 idx = g.worldToIndex(p);
    char buf[256];
    std::snprintf(buf, sizeof buf,
                  "%zu of %zu points of %s lie outside the volume (%s), e.g. point %zu at "
                  "(%.1f, %.1f, %.1f) mm = voxel (%.1f, %.1f, %.1f): the tree does not belong to this volume "
                  "(another image or geometry)",
                  outside, tree.size(), treeName.c_str(), g.describe().c_str(), first, p[0], p[1], p[2], idx[0], idx[1],
                  idx[2]);
    throw DataError(buf);
  }
}

namespace {

// The tree split into segments (node chains between the root, branch points and tips; a parent
// before its children) and its branch points with their parent and child segments.
void splitIntoSegments(TreeMeasurement& m) {
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
}

// Strahler orders (children come after their parent in m.segments).
void strahlerOrders(TreeMeasurement& m) {
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

// Each segment's centreline curve, with its length, chord, distance metric and sum of angles.
std::vector<Curve> segmentCurves(TreeMeasurement& m, double vox) {
  std::vector<Curve> curves;
  for (auto& seg : m.segments) {
    curves.push_back(makeCurve(m.tree, seg.nodes, vox));
    const Curve& c = curves.back();
    seg.lengthMm = c.length();
    seg.chordMm = (c.p.back() - c.p.front()).norm();
    seg.distanceMetric = seg.chordMm > 0 ? seg.lengthMm / seg.chordMm : kNaN;
    seg.sumOfAnglesRadPerCm = sumOfAngles(c);
  }
  return curves;
}

// A section of curve c at arc s, its plane normal to the chord over one hint radius either side.
CrossSection placeSection(const Curve& c, int segment, double s) {
  CrossSection cs;
  cs.segment = segment;
  cs.arcMm = s;
  cs.centreMm = c.at(s);
  const double h = std::max(1.0, c.radius(s));
  Vec3 t = c.at(std::min(c.length(), s + h)) - c.at(std::max(0.0, s - h));
  if (t.norm() <= 0) t = c.p.back() - c.p.front();
  cs.tangent = t.normalized();
  return cs;
}

// Sections every stepMm along each segment; returns each section's hint radius.
std::vector<double> placeSections(TreeMeasurement& m, const std::vector<Curve>& curves, double stepMm) {
  std::vector<double> hints;
  for (size_t si = 0; si < m.segments.size(); ++si) {
    const Curve& c = curves[si];
    if (c.p.size() < 2) continue;
    for (double s : stations(c.length(), stepMm)) {
      m.segments[si].sections.push_back(static_cast<int>(m.sections.size()));
      m.sections.push_back(placeSection(c, static_cast<int>(si), s));
      hints.push_back(c.radius(s));
    }
  }
  return hints;
}

// Polarity: +1 bright lumen, -1 dark; with Auto, the sign of the median lumen contrast.
double lumenSign(const SectionContext& ctx, const TreeMeasurement& m, const std::vector<double>& hints, double vox) {
  const QuantifyOptions& o = ctx.o;
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
  return sign;
}

// Every section measured, in parallel.
void measureSections(const SectionContext& ctx, double sign, const std::vector<double>& hints, TreeMeasurement& m,
                     Progress& progress) {
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
      std::max<int64_t>(1, ctx.o.sectionsPerThread));
  progress.check();
}

// Sections another segment's lumen crosses are flagged kSectionMeetsBranch.
void markBranchCrossings(TreeMeasurement& m, const std::vector<double>& lumenHint, double stepMm) {
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
      const double margin = 2 * maxOuter + stepMm;
      if ((boxes[si].lo.array() - margin > boxes[sj].hi.array()).any() ||
          (boxes[sj].lo.array() - margin > boxes[si].hi.array()).any())
        continue;
      for (int i : m.segments[si].sections) {
        const CrossSection& a = m.sections[static_cast<size_t>(i)];
        for (int j : m.segments[sj].sections) {
          const CrossSection& b = m.sections[static_cast<size_t>(j)];
          const Vec3 d = b.centreMm - a.centreMm;
          // b's lumen (its equivalent radius, or its hint radius when not measured) crosses a's plane
          // within a's own boundary.
          const double rb = b.measured() ? 0.5 * b.equivalentDiameterMm : lumenHint[static_cast<size_t>(j)];
          const double along = a.tangent.dot(d);
          if (std::abs(along) > rb) continue;
          if ((d - along * a.tangent).norm() > a.outerRadiusMm + rb) continue;
          meets[static_cast<size_t>(i)] = 1;
          break;
        }
      }
    }
  for (size_t i = 0; i < m.sections.size(); ++i)
    if (meets[i]) m.sections[i].flags |= kSectionMeetsBranch;
}

// Per segment: mean and minimum diameters, stenosis against the robust reference line, the
// narrowest point refined between two stations.
void measureSegments(const SectionContext& ctx, double sign, const std::vector<Curve>& curves, TreeMeasurement& m) {
  const QuantifyOptions& o = ctx.o;
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
    segmentStenosis(s, d, o.healthyFraction, seg, slope);
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

// Branch angles: each child's start direction against the parent's end direction, and between
// children, over windows scaled by the local lumen radius.
void branchAngles(const QuantifyOptions& o, const std::vector<Curve>& curves, TreeMeasurement& m) {
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

// One path root -> tip ending with segment `tip`: its sections, diameters, stenosis and shape.
PathMeasure measurePath(const std::vector<Curve>& curves, const TreeMeasurement& m, size_t tip) {
  PathMeasure p;
  for (int s = static_cast<int>(tip); s >= 0; s = m.segments[static_cast<size_t>(s)].parent) p.segments.push_back(s);
  std::reverse(p.segments.begin(), p.segments.end());
  p.tipNode = m.segments[tip].nodes.back();
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
  return p;
}

}  // namespace

TreeMeasurement measureTree(const VolumeF32& volume, const Tree& input, const QuantifyOptions& o, Progress& progress) {
  VS_REQUIRE(o.stepMm > 0 && std::isfinite(o.stepMm), "quantify: stepMm must be > 0");
  VS_REQUIRE(o.rays >= 8, "quantify: at least 8 rays");
  VS_REQUIRE(o.sampleStepVoxels > 0 && o.sampleStepVoxels <= 1, "quantify: sampleStepVoxels in (0, 1]");
  VS_REQUIRE(o.maxRadiusMm > 0, "quantify: maxRadiusMm must be > 0");
  VS_REQUIRE(o.healthyFraction > 0 && o.healthyFraction < 1, "quantify: healthyFraction in (0, 1)");
  VS_REQUIRE(!volume.empty(), "quantify: empty volume");
  checkTreeInVolume(volume.geometry(), input);
  const double vox = volume.geometry().spacing.minCoeff();

  TreeMeasurement m;
  m.tree = mergeCoincidentBranches(input, &m.mergedBranches);
  splitIntoSegments(m);
  strahlerOrders(m);
  const std::vector<Curve> curves = segmentCurves(m, vox);
  const std::vector<double> hints = placeSections(m, curves, o.stepMm);
  const SectionContext ctx(volume, o);
  const double sign = lumenSign(ctx, m, hints, vox);
  m.polarity = sign > 0 ? LumenPolarity::Bright : LumenPolarity::Dark;
  measureSections(ctx, sign, hints, m, progress);
  markBranchCrossings(m, hints, o.stepMm);
  for (auto& cs : m.sections)
    if (!cs.measured()) {
      cs.areaMm2 = cs.equivalentDiameterMm = cs.minDiameterMm = cs.maxDiameterMm = kNaN;
      cs.minDirection = cs.maxDirection = Vec3::Zero();
    }
  measureSegments(ctx, sign, curves, m);
  branchAngles(o, curves, m);
  for (size_t si = 0; si < m.segments.size(); ++si)  // paths: root -> tip
    if (m.segments[si].children.empty()) m.paths.push_back(measurePath(curves, m, si));
  return m;
}

Tree treeWithMeasuredRadii(const TreeMeasurement& m) {
  const Tree& tree = m.tree;
  Tree out = tree;
  if (out.radii.size() != out.size()) out.radii.assign(out.size(), 0.0);
  for (const auto& seg : m.segments) {
    std::vector<std::pair<double, double>> prof;  // arc, radius
    for (int i : seg.sections) {
      const CrossSection& cs = m.sections[static_cast<size_t>(i)];
      if (cs.measured()) prof.emplace_back(cs.arcMm, 0.5 * cs.equivalentDiameterMm);
    }
    if (prof.empty()) continue;
    double s = 0;
    for (size_t k = 0; k < seg.nodes.size(); ++k) {
      if (k > 0)
        s += (tree.points[static_cast<size_t>(seg.nodes[k])] - tree.points[static_cast<size_t>(seg.nodes[k - 1])])
                 .norm();
      if (k == 0 && seg.parent >= 0) continue;  // a branch point keeps its parent segment's radius
      auto best = std::min_element(prof.begin(), prof.end(), [&](const auto& a, const auto& b) {
        return std::abs(a.first - s) < std::abs(b.first - s);
      });
      out.radii[static_cast<size_t>(seg.nodes[k])] = best->second;
    }
  }
  return out;
}

}  // namespace vs
