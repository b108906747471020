// Junctions and forks of refineCentreline (centreline.h): the junction zones' placement and the
// re-branching of forks whose discrete branch point lies past the junction.
#include "tracking/centreline_junctions.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace vs::centreline_detail {

namespace {

// Junctions (issue 21). Near a branch point the plane normal to a side branch also cuts the trunk it leaves (a fused
// cross-section): its rays escape into the trunk, the chords that remain pull its points towards the ostium's far
// wall, and the smoothing bends them into the trunk.
// Per branch point b: each arm (the tree walked up to the parent side, down each child, to the next branch point or
// end) has its own radius (the median radius of its points beyond the junction's reach, 1.5 parent radii + 2 voxels
// from b) and a junction zone: its points within reach up to the last one whose section is fused, i.e. whose disc of
// the arm's own radius (x 1.5, + 1 voxel) leaves the lumen (two rays or more find no wall: `fusedAt`). The next
// `linePoints` points, centred in round sections, give the arm's axis direction. Where one child continues the parent
// (aligned within 30 degrees, at least 0.6 x its radius; the best aligned child), the trunk (parent and that child) is
// left to the ordinary refinement, so a wide trunk with side branches (an aorta) stays on its own axis instead of being
// pulled towards each ostium, and each side branch's zone points move onto the segment from b to its first point out of
// the zone (evenly, in its order) and are frozen: the later centring and smoothing leave them. First, though, where the
// two children's axes meet near b (placeFork, session 13), both children's zones are placed from that junction instead,
// the trunk's included (along its own axis). A fork whose axes do not meet there is left to the ordinary refinement
// (placing its arms' zones from the least-squares junction of all three arms' lines, or from b, cost the vessel
// family's tuning seeds 1-40 accuracy: docs/notes/tracking.md, sessions 10 and 12). Returns the count of moved points.

// Forks (issue 21, session 13). Near a branch point the sections of both children are fused, and their ordinary
// centring puts their first points in the middle of the fused lumen, between the children's axes, or leaves them on
// the discrete paths, which part near the crotch (the saddle between the arms), not at the junction. Here the junction
// J is where the two children's axes (the lines through their first `linePoints` round sections beyond their zones, as
// for side branches) pass nearest to each other: the midpoint of their closest approach, or the point on the continuing
// child's axis where one child continues the parent. Accepted when the axes nearly meet (closer than the wider child's
// radius + 1 voxel) behind both first round sections G and J, G lie within reach of b (4 parent radii + 2 voxels), J
// within half the parent's radius of the tree's points there (session 22: curved arms' axes can meet off the lumen;
// this also holds for splitForks' re-branching, which may also `snap` J onto the tree, session 30). Then each child's
// zone points go evenly (by index) onto J -> G, or onto b -> J -> G when b lies more than a voxel before J (the
// discrete paths part before the junction), and are frozen; in that case, where the sections' widening along the tree
// (imageJunction, its fitted line only) puts J before the axes' J, J is taken from there (session 22). A zone's leading
// points whose sections read the parent's own lumen at b (inParent, as placeParted's) lie before the junction: they
// stay the rounds', whatever J (axes of curved or near-parallel arms meet early or beside the fork: 14808's J 3.4
// voxels early, 14712's 1.9 voxels beside it; session 49). The parent's points are not moved: spreading those beyond J
// (a branch point past the junction) between J and the parent's last point before it measured no better on the
// family's tuning seeds (docs/notes/tracking.md, session 13). Returns false (nothing moved) when not accepted.
struct ForkArms {
  const std::vector<std::vector<size_t>>& arms;  // the parent arm first, outward from b
  const std::vector<size_t>& zone;               // per arm: its count of fused points from b
  const std::vector<double>& ownR;               // per arm: its own radius (mm)
  size_t cont;                                   // the child that continues the parent (0: none)
};

// The junction of a fork: where its two children's axes meet (see above), with G[1], G[2] the
// children's first round sections and `before` whether b lies more than a voxel before J (the
// discrete paths part before the junction; false also where b lies past it). False where the axes
// do not meet near b.
struct ForkJunction {
  Vec3 J{0, 0, 0};
  Vec3 G[3];
  double along = 0;   // (J - b) along the children's mean direction (mm; negative: b lies past J)
  Vec3 dir{0, 0, 0};  // the children's mean direction (unit)
};

bool forkJunction(const ForkArms& f, size_t b, const std::vector<Vec3>& q, double voxMm, ForkJunction& out,
                  bool snap = false) {
  constexpr size_t linePoints = 5;
  constexpr double reachRadii = 4;
  if (f.arms.size() != 3 || f.ownR[0] <= 0 || f.ownR[1] <= 0 || f.ownR[2] <= 0) return false;
  Vec3 e[3];
  Vec3* G = out.G;
  for (size_t a = 1; a < 3; ++a) {
    const auto& arm = f.arms[a];
    if (f.zone[a] + linePoints > arm.size()) return false;
    G[a] = q[arm[f.zone[a]]];
    const Vec3 d = q[arm[f.zone[a] + linePoints - 1]] - G[a];
    if (d.norm() < voxMm) return false;
    e[a] = d.normalized();
  }
  const Vec3 w = G[1] - G[2];
  const double c = e[1].dot(e[2]), denom = 1 - c * c;
  if (denom < 1e-3) return false;  // parallel children
  const double u1 = (c * e[2].dot(w) - e[1].dot(w)) / denom, u2 = (e[2].dot(w) - c * e[1].dot(w)) / denom;
  if (u1 > 0 || u2 > 0) return false;  // the axes would meet beyond a child's first round section
  const Vec3 X1 = G[1] + u1 * e[1], X2 = G[2] + u2 * e[2];
  if ((X1 - X2).norm() > std::max(f.ownR[1], f.ownR[2]) + voxMm) return false;  // skew: no junction
  const Vec3 J = f.cont == 1 ? X1 : f.cont == 2 ? X2 : Vec3(0.5 * (X1 + X2));
  const double reachMm = reachRadii * f.ownR[0] + 2 * voxMm;
  if ((J - q[b]).norm() > reachMm || (G[1] - J).norm() > reachMm || (G[2] - J).norm() > reachMm) return false;
  // Axes extrapolated back from curved arms can meet off the lumen (10529's root fork: 6 voxels
  // beside it), and the zones would go onto segments through the background: J must lie within
  // half the parent's radius of the tree's points within reach of b (thin12); with `snap`, within the
  // parent's radius, J is the nearest of them (a narrow fork's ill-conditioned axes meet beside the
  // lumen those points centre: 11302's b3 -> {b7, b8}, 1.6 voxels; session 30).
  Vec3 onTree = q[b];
  for (const auto& arm : f.arms)
    for (size_t i = 0; i < arm.size() && (q[arm[i]] - q[b]).norm() <= reachMm; ++i)
      if ((q[arm[i]] - J).norm() < (onTree - J).norm()) onTree = q[arm[i]];
  const double offTree = (onTree - J).norm();
  if (offTree > (snap ? 1.0 : 0.5) * f.ownR[0]) return false;
  out.J = offTree > 0.5 * f.ownR[0] ? onTree : J;
  out.dir = (e[1] + e[2]).normalized();
  out.along = out.dir.dot(out.J - q[b]);
  return true;
}

bool imageForkJunction(const JunctionInput& in, const ForkArms& f, size_t b, const std::vector<Vec3>& q,
                       const ForkJunction& fj, const SectionWidths& widths, double voxMm, Vec3& J,
                       double reachRadii = 4, bool plateau = false);

bool placeFork(const JunctionInput& in, const ForkArms& f, size_t b, const std::vector<Vec3>& q,
               std::vector<Vec3>& target, std::vector<uint8_t>& moved, double voxMm, const SectionWidths& widths) {
  ForkJunction fj;
  if (!forkJunction(f, b, q, voxMm, fj)) return false;
  const Vec3 B = q[b];
  Vec3 J = fj.J;
  bool before = fj.along >= voxMm;  // b lies before J
  // ... and J ahead of it on the parent's course, not beside it (a hairpin fork's, fork_start.cpp).
  if (before && !alongParent(f.arms[0], f.ownR[0], voxMm, q, b, J)) return false;
  // Where b lies before the axes' J, J from near-parallel axes (a narrow fork) is ill-conditioned
  // (10532: 4 mm late, both children's first points on b -> J between them): the sections'
  // widening along the tree gives it instead, where it lies before the axes' J (thin13) but not
  // behind b: the image's track runs up the parent arm, and the widening it finds there may be the
  // fused section of the fork above (10621: 12 voxels up the parent; the zones went onto J -> G
  // from that fork, 2-3 voxels off; thin14).
  Vec3 Ji;
  if (before && widths && imageForkJunction(in, f, b, q, fj, widths, voxMm, Ji) && fj.dir.dot(Ji - B) < fj.along &&
      fj.dir.dot(Ji - B) >= -0.5 * voxMm) {
    J = Ji;
    before = fj.dir.dot(J - B) >= voxMm;
  }
  for (size_t a = 1; a < 3; ++a) {
    const auto& arm = f.arms[a];
    const Vec3& G = fj.G[a];
    const double l1 = before ? (J - B).norm() : 0, l2 = (G - J).norm(), total = l1 + l2;
    const size_t inParentRun =
        inParent(arm, b, f.zone[a], widths, 4 * f.ownR[0] + 2 * voxMm, f.ownR[0], voxMm, in.coarseMm);
    for (size_t i = inParentRun; i < f.zone[a]; ++i) {
      const double s = total * static_cast<double>(i + 1) / static_cast<double>(f.zone[a] + 1);
      const Vec3 p = s < l1 ? Vec3(B + (s / l1) * (J - B)) : Vec3(J + ((s - l1) / std::max(l2, 1e-9)) * (G - J));
      // Laid past the midline onto the sibling's side (fork_start.cpp): the rounds' position kept, frozen.
      target[arm[i]] = ontoSibling(in, arm[i], f.arms[3 - a], p) ? q[arm[i]] : p;
      moved[arm[i]] = 1;
    }
  }
  return true;
}

// A parted fork's chains (see placeParted): each child's arm extended through further branch
// points (ext), its together part's end S, its first round section's index Gi and position G.
struct PartedChains {
  const JunctionInput& in;
  const ForkArms& f;
  size_t b;
  const std::vector<Vec3>& q;
  const std::vector<size_t> (&ext)[3];
  const size_t (&S)[3];
  const size_t (&Gi)[3];
  const Vec3 (&G)[3];
  double voxMm;
};

// The junction of a parted fork from the image's cross-sections (session 18). The chains' own
// geometry places it badly where the arms curve (their axes, extrapolated back, meet beside the
// fork) or where the tree branches far from it (at the root, or past it). Along the track that runs
// down the parent arm (within reach of b), through b and down the child whose chain runs together
// with the other's the longest, up to its first round section, each point's cross-section gives its
// widest and narrowest chord (`widths`). In a round lumen (the parent's) they are equal but for
// noise and the grid (d0: the lower quartile of d = widest - narrowest over the track); past the
// junction the children's lumens, fused, widen the section along the fork's plane by their centres'
// separation, which grows linearly with the distance from the junction, while the narrowest chord
// stays a child's diameter. The run: going back from the track's widest section, past sections
// whose separation d - d0 exceeds the narrowest chord (the lumens no longer overlap, or the section
// is cut obliquely through both), the points with d - d0 of at least half a voxel; J is where the
// least-squares line of d - d0 over the track's arc length reaches 0; a run of one point (a wide
// fork, widened within one step) puts J between the last round section and it (unless oneStep is
// false). False where no widening of a voxel is seen, the run does not rise, or its line reaches 0
// before the track's start or farther back than the reach before the run.
bool imageJunction(const PartedChains& c, const SectionWidths& widths, Vec3& J, bool oneStep = true,
                   double reachRadii = 4, bool plateau = false) {
  const double voxMm = c.voxMm;
  const double reachMm = reachRadii * c.f.ownR[0] + 2 * voxMm;
  std::vector<size_t> track;
  const auto& up = c.f.arms[0];
  size_t nUp = 0;
  while (nUp < up.size() && (c.q[up[nUp]] - c.q[c.b]).norm() <= reachMm) ++nUp;
  for (size_t i = nUp; i-- > 0;) track.push_back(up[i]);
  track.push_back(c.b);
  const size_t a = c.S[1] >= c.S[2] ? 1 : 2;
  for (size_t i = 0; i <= c.Gi[a] && i < c.ext[a].size(); ++i) track.push_back(c.ext[a][i]);
  const double maxMm = reachMm;
  const size_t n = track.size();
  std::vector<double> s(n, 0), d(n, -1), narrow(n, 0);
  std::vector<uint8_t> ok(n, 0);
  size_t m = n;
  for (size_t i = 0; i < n; ++i) {
    if (i > 0) s[i] = s[i - 1] + (c.q[track[i]] - c.q[track[i - 1]]).norm();
    double widest = 0, narrowest = 0;
    ok[i] = widths(track[i], maxMm, widest, narrowest);
    if (!ok[i]) continue;
    d[i] = widest - narrowest, narrow[i] = narrowest;
    if (m == n || d[i] > d[m]) m = i;
  }
  if (m == n) return false;
  // The round section's own d (the chords' spread over noise and the grid): the lower quartile of
  // the track's (most of it runs in round sections: the parent's and the chain's own lumen).
  std::vector<double> valid;
  for (size_t i = 0; i < n; ++i)
    if (ok[i]) valid.push_back(d[i]);
  if (valid.size() < 4) return false;
  std::nth_element(valid.begin(), valid.begin() + static_cast<std::ptrdiff_t>(valid.size() / 4), valid.end());
  const double d0 = valid[valid.size() / 4];
  if (d[m] < d0 + voxMm) return false;
  // The run: going back from the widest, past the points where the children's lumens no longer
  // overlap (the separation above the narrowest chord, the children's own diameter), while the
  // section is widened by at least half a voxel.
  size_t hi = m;
  while (hi > 0 && d[hi] - d0 > narrow[hi]) --hi;
  size_t j = hi + 1;
  while (j > 0 && ok[j - 1] && d[j - 1] - d0 >= 0.5 * voxMm && d[j - 1] - d0 <= narrow[j - 1]) --j;
  // No run, the first widened section already parted (11501): J at the round one before it, where the next is widened
  // by a voxel too (not a lone oblique cut at b: 10432) and a round one lies before the widest (11412; session 33).
  if (j > hi) {
    if (!oneStep || hi == m || !ok[hi] || d[hi] - d0 >= 0.5 * voxMm || hi + 2 >= n || d[hi + 2] - d0 < voxMm)
      return false;
    J = c.q[track[hi]];
    return true;
  }
  if (j == hi) {  // a wide fork widens within one step: J between the last round section and it
    if (!oneStep || j == 0 || !ok[j - 1]) return false;
    // The junction lies between the last round section and the widened one. The widening grows linearly from J;
    // the next section, already parted, gives its rate: J where that line through the widened section reaches 0,
    // kept between the two (the round section alone put J a step early at worst: half a 2.28 mm slice on 10308).
    double back = 1;
    if (j + 1 < n && ok[j + 1] && d[j + 1] > d[j] && s[j + 1] > s[j] && s[j] > s[j - 1]) {
      const double rate = (d[j + 1] - d[j]) / (s[j + 1] - s[j]);
      back = std::clamp((d[j] - d0) / rate / (s[j] - s[j - 1]), 0.0, 1.0);
    }
    J = c.q[track[j]] + back * Vec3(c.q[track[j - 1]] - c.q[track[j]]);
    return true;
  }
  m = hi;
  for (size_t i = j; i <= m; ++i) d[i] -= d0;
  double ss = 0, sd = 0, sss = 0, ssd = 0;
  const double k = static_cast<double>(m - j + 1);
  for (size_t i = j; i <= m; ++i) ss += s[i], sd += d[i], sss += s[i] * s[i], ssd += s[i] * d[i];
  const double den = k * sss - ss * ss;
  if (den <= 1e-12) return false;
  const double beta = (k * ssd - ss * sd) / den, alpha = (sd - beta * ss) / k;
  // `plateau` (splitForks' b past J): children that part and then run on side by side at a nearly
  // constant separation widen the sections by a plateau, not a rising line; J is the last round
  // section before a run of three or more that reaches b (round sections between the run and b
  // are another fork's widening). Nothing else is taken in that mode.
  if (plateau) {
    const bool flat = beta <= 0.05 || -alpha / beta < std::max(0.0, s[j] - reachMm);
    if (!flat || hi + 1 < nUp || hi < j + 2 || j == 0 || !ok[j - 1]) return false;
    J = c.q[track[j - 1]];
    return true;
  }
  if (beta <= 0.05) return false;
  // A zero before the track's reach is no junction on it (a slow rise from a plateau, such as a
  // parent arm in the fused section of the fork above); clamped, it put J at the track's start and
  // placeParted refused the fork (10203, 545; thin14).
  if (-alpha / beta < std::max(0.0, s[j] - reachMm)) return false;
  const double sJ = std::min(-alpha / beta, s[m]);
  size_t i = 0;
  while (i + 1 < n && s[i + 1] < sJ) ++i;
  const double seg = i + 1 < n ? s[i + 1] - s[i] : 0;
  const double t = seg > 1e-9 ? std::clamp((sJ - s[i]) / seg, 0.0, 1.0) : 0.0;
  J = c.q[track[i]] + t * (i + 1 < n ? Vec3(c.q[track[i + 1]] - c.q[track[i]]) : Vec3(0, 0, 0));
  return true;
}

// placeFork's J from the image: imageJunction's widening along the parent, b and the child with
// the longer zone, up to its first round section (the zones stand for the together parts).
bool imageForkJunction(const JunctionInput& in, const ForkArms& f, size_t b, const std::vector<Vec3>& q,
                       const ForkJunction& fj, const SectionWidths& widths, double voxMm, Vec3& J, double reachRadii,
                       bool plateau) {
  const std::vector<size_t> ext[3] = {f.arms[0], f.arms[1], f.arms[2]};
  const size_t S[3] = {0, f.zone[1], f.zone[2]};
  const PartedChains chains{in, f, b, q, ext, S, S, fj.G, voxMm};
  return imageJunction(chains, widths, J, false, reachRadii, plateau);
}

// The junction of a parted fork from its arms' axes (session 14; e: the axes' directions from
// G): where they meet (as forkJunction's: behind both G, closer than the wider child's radius + a
// voxel). J lies in the lumen the chains run through together. Axes extrapolated from curved arms
// can meet beside it (on the family's thin seeds up to 8 voxels past the true junction, off both
// branches): where J lies farther than half the parent's radius from every together point, J is
// the together point nearest both axes instead (session 17). False where the axes do not meet.
bool axesJunction(const PartedChains& c, const Vec3 (&e)[3], Vec3& J) {
  const auto& G = c.G;
  const auto& f = c.f;
  const Vec3 w = G[1] - G[2];
  const double cs = e[1].dot(e[2]), denom = 1 - cs * cs;
  if (denom < 1e-3) return false;
  const double u1 = (cs * e[2].dot(w) - e[1].dot(w)) / denom, u2 = (e[2].dot(w) - cs * e[1].dot(w)) / denom;
  if (u1 > 0 || u2 > 0) return false;
  const Vec3 X1 = G[1] + u1 * e[1], X2 = G[2] + u2 * e[2];
  if ((X1 - X2).norm() > std::max(f.ownR[1], f.ownR[2]) + c.voxMm) return false;
  J = f.cont == 1 ? X1 : f.cont == 2 ? X2 : Vec3(0.5 * (X1 + X2));
  double offChain = std::numeric_limits<double>::infinity();
  for (size_t a = 1; a < 3; ++a)
    for (size_t i = 0; i < c.S[a]; ++i) offChain = std::min(offChain, (c.q[c.ext[a][i]] - J).norm());
  if (offChain <= 0.5 * f.ownR[0]) return true;
  auto axisDistance = [&](const Vec3& p, size_t a) {
    const Vec3 d = p - G[a];
    return (d - d.dot(e[a]) * e[a]).norm();
  };
  double best = std::numeric_limits<double>::infinity();
  for (size_t a = 1; a < 3; ++a)
    for (size_t i = 0; i < c.S[a]; ++i) {
      const Vec3& p = c.q[c.ext[a][i]];
      const double v = axisDistance(p, 1) + axisDistance(p, 2);
      if (v < best) best = v, J = p;
    }
  return true;
}

// The junction lies no farther than where the children's discrete paths part: beyond, each path runs in its own
// lumen. Axes extrapolated back from curved arms can meet past it (10601 with its tree's fork where the chains part:
// 2.6 voxels past the junction, on the straighter child's axis; the other child's first points went onto J -> G from
// there, one on the sibling: session 25 fork4). Where the paths part at b (each child's first input voxel farther
// than sepMm, the together parts' separation, from every input voxel of the other) and J lies ahead of b towards
// both children's G, J is b. Not at the root's own fork: the paths start there, they did not arrive together. Nor
// where both children's first sections are round (widest - narrowest under half a voxel): the paths part side by side
// in the parent's lumen, which tells nothing of the junction (11521's branch 1 fork, 8 mm before it; session 33).
Vec3 notPastParting(const JunctionInput& in, const ForkArms& f, size_t b, const std::vector<Vec3>& q,
                    const Vec3 (&G)[3], double sepMm, const SectionWidths& widths, double voxMm, double maxMm,
                    const Vec3& J) {
  if (f.arms[0].empty()) return J;
  size_t round = 0;
  for (size_t a = 1; a < 3; ++a) {
    const auto &arm = f.arms[a], &other = f.arms[3 - a];
    if (arm.empty() || (J - q[b]).dot(G[a] - q[b]) <= 0) return J;
    for (size_t k : other)
      if ((in.raw(k) - in.raw(arm[0])).norm() <= sepMm) return J;
    double widest = 0, narrowest = 0;
    if (widths && widths(arm[0], maxMm, widest, narrowest) && widest - narrowest < 0.5 * voxMm) ++round;
  }
  return round == 2 ? J : q[b];
}

// Forks whose children's discrete paths part before the junction and run together through the
// parent and the fused section (session 14): both chains are centred onto one line there, the
// fused lumen's, and placeFork, whose zones reach only 1.5 parent radii from b, does not see the
// junction. Per child, its "together" part runs from b to its first point farther than half the
// children's radii (summed, at least a voxel) from every point of the other child (S); its first
// round section G is the first point from S on whose disc is not fused; its axis runs through G
// and the next linePoints - 1 points. J from the image's cross-sections (imageJunction), else where
// the axes meet (axesJunction); within 4 parent radii + 2 voxels of the together part's end.
// Each child's points before G that lie beyond J along J -> G go onto the curve from J to G that
// arrives at G along the arm's axis (session 18; the nearest of its samples) and are frozen; those
// before J are left in the parent. The root's own fork is placed too (its parent's radius from the
// children's first points). False (nothing moved) when the chains part at b or no junction is found. An arm that ends
// at a further branch point inside the fused section continues through it along first children for S, G and the axis
// (its own points only are moved).
bool placeParted(const JunctionInput& in, const ForkArms& f, size_t b, const std::vector<Vec3>& q,
                 std::vector<Vec3>& target, std::vector<uint8_t>& moved, double voxMm, const FusedAt& fusedAt,
                 const SectionWidths& widths, const SectionLobes& lobes, std::vector<double>& lobeR) {
  // 3 points (session 17; 5 before): the arms are often curved past the fused section and their
  // axes are extrapolated far back to J (thin 1-40 98.71 -> 98.83 %, docs/notes/tracking.md).
  constexpr size_t linePoints = 3;
  constexpr size_t minTogether = 2;
  if (f.arms.size() != 3 || f.ownR[0] <= 0 || f.ownR[1] <= 0 || f.ownR[2] <= 0) return false;
  const double sepMm = std::max(voxMm, 0.5 * (f.ownR[1] + f.ownR[2]));
  size_t S[3] = {0, 0, 0}, Gi[3] = {0, 0, 0};
  Vec3 G[3], e[3];
  // An arm that ends at a further branch point (the tree branched again inside the fused section)
  // continues through it along first children, for G and the axis only.
  std::vector<size_t> ext[3];
  for (size_t a = 1; a < 3; ++a) {
    ext[a] = f.arms[a];
    if (ext[a].empty()) continue;
    for (size_t k = ext[a].back(); ext[a].size() < f.arms[a].size() + 4 * linePoints && !in.children[k].empty();) {
      k = static_cast<size_t>(in.children[k][0]);
      ext[a].push_back(k);
    }
  }
  for (size_t a = 1; a < 3; ++a) {
    const auto &arm = ext[a], &other = ext[3 - a];
    auto apart = [&](size_t i) {
      for (size_t j : other)
        if ((q[j] - q[arm[i]]).norm() <= sepMm) return false;
      return true;
    };
    size_t i = 0;
    while (i < arm.size() && !apart(i)) ++i;
    S[a] = i;
    const double discMm = 1.5 * f.ownR[a] + voxMm;
    while (i < arm.size() && i < S[a] + 2 * linePoints && fusedAt(arm[i], discMm)) ++i;
    if (i + linePoints > arm.size()) return false;
    Gi[a] = i;
    G[a] = q[arm[i]];
    const Vec3 d = q[arm[i + linePoints - 1]] - G[a];
    if (d.norm() < voxMm) return false;
    e[a] = d.normalized();
  }
  if (S[1] < minTogether && S[2] < minTogether) return false;
  // J from the image's cross-sections; where they show no junction, from the arms' axes.
  const PartedChains chains{in, f, b, q, ext, S, Gi, G, voxMm};
  Vec3 J;
  if (!(widths && imageJunction(chains, widths, J)) && !axesJunction(chains, e, J)) return false;
  const double reachMm = 4 * f.ownR[0] + 2 * voxMm;
  if (in.raw) J = notPastParting(in, f, b, q, G, sepMm, widths, voxMm, reachMm, J);
  for (size_t a = 1; a < 3; ++a) {
    const size_t end = std::max<size_t>(S[a], 1) - 1;
    if ((q[ext[a][end]] - J).norm() > reachMm) return false;
  }
  // Where the points would move further than the child's own radius (the fused lumen's centre lies within it of both
  // children's axes), J or an axis is not that of the fork: nothing moves. The path from J to G: the quadratic curve
  // that leaves J towards the control point C and arrives at G along the arm's own direction there (C = G - e l / 2;
  // the chord where C lies behind J): the arms curve past the fused section, a chord cuts across them. In a fused
  // section (two lobes: the widest chord longer than both children's diameters by half a voxel or more, and by no more
  // than them) the child's own centre is known from the section itself: from its lobe's own walls
  // (lobeCentreFromWalls), else its lobe's end of the widest chord less its own radius (session 20). The curve runs
  // from a J that may lie a few voxels off the true junction; the lobe does not depend on it. An arm's leading points
  // in the parent's lumen (inParent) stay the rounds', tested as the others.
  struct Move {
    size_t k;
    Vec3 p;
    double r;  // NaN: the radius is the one measured at p
  };
  std::vector<Move> moves;
  constexpr int samples = 64;
  const double both = f.ownR[1] + f.ownR[2];
  for (size_t a = 1; a < 3; ++a) {
    const auto& arm = f.arms[a];
    const Vec3 seg = G[a] - J;
    const double l = seg.norm();
    if (l < 1e-9) continue;
    Vec3 C = G[a] - 0.5 * l * e[a];
    if ((C - J).dot(seg) <= 0) C = 0.5 * (J + G[a]);
    Vec3 curve[samples + 1];
    for (int k = 0; k <= samples; ++k) {
      const double t = static_cast<double>(k) / samples;
      curve[k] = (1 - t) * (1 - t) * J + 2 * t * (1 - t) * C + t * t * G[a];
    }
    const size_t inParentRun = inParent(arm, b, Gi[a], widths, reachMm, f.ownR[0], voxMm, in.coarseMm);
    for (size_t i = 0; i < std::min(Gi[a], arm.size()); ++i) {
      const double s = (q[arm[i]] - J).dot(seg) / (l * l);
      if (s <= 0) continue;
      Vec3 p = curve[0];
      for (const Vec3& x : curve)
        if ((x - q[arm[i]]).squaredNorm() < (p - q[arm[i]]).squaredNorm()) p = x;
      double r = std::numeric_limits<double>::quiet_NaN();
      Vec3 d;
      double plus = 0, minus = 0, narrowest = 0;
      if (lobes && lobes(arm[i], reachMm, d, plus, minus, narrowest)) {
        const double sep = plus + minus - both;  // the children's centres' separation
        const double side = (G[a] - G[3 - a]).dot(d);
        Vec3 lobe = q[arm[i]] + (side > 0 ? plus - f.ownR[a] : f.ownR[a] - minus) * d;
        if (in.lobeCentre) in.lobeCentre(arm[i], d, side > 0 ? plus : -minus, side > 0 ? -minus : plus, reachMm, lobe);
        // Two lobes, not one wider round lumen (the parent's before the junction, a neighbour's beside it): two
        // overlapping discs elongate the section (widest - narrowest) by their centres' separation or more (half of it
        // let 516's parent section pass for lobes); the widest chord lies along the fork's plane (the children's round
        // sections' offset) and the lobe lies within the child's radius of its point on the curve.
        if (sep >= 0.5 * voxMm && sep <= both && plus + minus - narrowest >= std::max(0.5 * voxMm, sep) &&
            std::abs(side) >= 0.8 * (G[a] - G[3 - a]).norm() && (lobe - p).norm() <= f.ownR[a]) {
          p = lobe;
          r = f.ownR[a];
        }
      }
      // A lobe point moves from the fused section's centre to its own lobe's centre: up to half the
      // children's summed radii (the lobe test's widest separation), more than the smaller child's
      // own radius where its sibling is the wider (10525's coarse slices: 2.09 mm for 2.02; thin12).
      const double maxMove = std::isnan(r) ? f.ownR[a] : std::max(f.ownR[a], 0.5 * both);
      if ((p - q[arm[i]]).norm() > maxMove) return false;
      if (i >= inParentRun) moves.push_back({arm[i], p, r});
    }
  }
  for (const Move& m : moves) {
    target[m.k] = m.p, moved[m.k] = 1;
    if (!lobeR.empty()) lobeR[m.k] = m.r;
  }
  return true;
}

// One branch point's arms (the parent arm first, outward from b), their junction zones, own radii,
// axis directions beyond the zones and the child that continues the parent (see placeJunctions).
// False where the parent arm gives no radius.
struct ForkGeometry {
  std::vector<std::vector<size_t>> arms;
  std::vector<size_t> zone;
  std::vector<double> ownR;
  std::vector<Vec3> lineD;  // the arm's axis direction beyond its zone
  std::vector<uint8_t> hasLine;
  size_t cont = 0;  // 0: none (arm 0 is the parent)
  bool anyFused = false;
};

bool analyseFork(const JunctionInput& in, size_t b, const std::vector<Vec3>& q, double voxMm, const FusedAt& fusedAt,
                 ForkGeometry& g) {
  constexpr size_t linePoints = 5;
  constexpr double reachRadii = 1.5;  // zones reach this many parent radii (+ 2 voxels) from b
  constexpr size_t maxGap = 2;
  const double continueCos = std::cos(30.0 * M_PI / 180.0);
  auto median = [](std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
  };
  // Arms outward from b (b excluded); the parent arm first.
  g = ForkGeometry{};
  auto walk = [&](int32_t start, bool up) {
    std::vector<size_t> a;
    for (int32_t p = start; p >= 0;) {
      const size_t k = static_cast<size_t>(p);
      if (in.children[k].size() >= 2 || (a.size() > 2 * linePoints && (q[k] - q[b]).norm() > 60 * voxMm)) break;
      a.push_back(k);
      if (k == 0) break;  // the root stays where it is
      p = up ? in.parent[k] : (in.children[k].size() == 1 ? in.children[k][0] : -1);
    }
    g.arms.push_back(std::move(a));
  };
  walk(in.parent[b], true);
  for (int32_t c : in.children[b]) walk(c, false);
  const auto& arms = g.arms;
  // The parent's radius: the median over its arm's first points (the root is not cast: no radius).
  // At the root's own fork (no parent arm), the children's first points, in the parent's lumen.
  std::vector<double> pr;
  for (size_t i = 0; i < arms[0].size() && i < 4 * linePoints; ++i)
    if (in.radius[arms[0][i]] > 0) pr.push_back(in.radius[arms[0][i]]);
  for (size_t a = 1; pr.empty() && a < arms.size(); ++a)
    for (size_t i = 0; i < arms[a].size() && i < 2; ++i) pr.push_back(in.radius[arms[a][i]]);
  if (pr.empty()) return false;
  const double reachMm = reachRadii * median(pr) + 2 * voxMm;
  const size_t na = arms.size();
  g.zone.assign(na, 0);
  g.ownR.assign(na, 0);
  g.lineD.assign(na, Vec3(0, 0, 0));
  g.hasLine.assign(na, 0);
  for (size_t a = 0; a < na; ++a) {
    const auto& arm = arms[a];
    // The arm's own radius: beyond the reach (its round sections); a short arm: its far half.
    std::vector<double> rr;
    for (size_t i = 0; i < arm.size() && rr.size() < 4 * linePoints; ++i)
      if ((q[arm[i]] - q[b]).norm() > reachMm && in.radius[arm[i]] > 0) rr.push_back(in.radius[arm[i]]);
    for (size_t i = arm.size() / 2; rr.empty() && i < arm.size(); ++i)
      if (in.radius[arm[i]] > 0) rr.push_back(in.radius[arm[i]]);
    if (a == 0 && rr.empty()) rr = pr;  // the root's fork: the parent arm is the root alone, or none
    g.ownR[a] = median(rr);
    if (g.ownR[a] <= 0) continue;
    const double discMm = 1.5 * g.ownR[a] + voxMm;
    // The zone: up to the last fused point within reach, ending at maxGap round points in a row.
    size_t& zone = g.zone[a];
    for (size_t i = 0; i < arm.size() && (zone == 0 || i <= zone + maxGap) && (q[arm[i]] - q[b]).norm() <= reachMm; ++i)
      if (arm[i] != 0 && fusedAt(arm[i], discMm)) zone = i + 1;
    g.anyFused = g.anyFused || zone > 0;
    if (arm.size() < zone + 3) continue;  // no round cross-sections beyond the zone to give an axis
    const size_t e = std::min(arm.size(), zone + linePoints);
    const Vec3 d = q[arm[e - 1]] - q[arm[zone]];  // outward from b
    if (d.norm() < voxMm) continue;
    g.lineD[a] = d.normalized(), g.hasLine[a] = 1;
  }
  // The child that continues the parent, if any.
  if (g.hasLine[0]) {
    double best = continueCos;
    for (size_t a = 1; a < na; ++a)
      if (g.hasLine[a] && g.ownR[a] >= 0.6 * g.ownR[0] && -g.lineD[0].dot(g.lineD[a]) >= best)
        best = -g.lineD[0].dot(g.lineD[a]), g.cont = a;
  }
  return true;
}

// The continuing child's zone where neither fork placement applies (session 17): left to the rays,
// its fused points are centred in the section fused with the sibling and pulled towards it (1-2
// voxels off on the family's thin seeds). They go onto the trunk's chord from the parent's first
// round point to the child's first round section G (each at its own projection onto it); nothing
// moves where a point would move further than the child's own radius (the chord is not the trunk's).
bool placeTrunk(const ForkGeometry& g, const std::vector<Vec3>& q, std::vector<Vec3>& target,
                std::vector<uint8_t>& moved) {
  const size_t c = g.cont;
  if (c == 0 || g.zone[c] == 0 || g.zone[c] >= g.arms[c].size() || g.zone[0] >= g.arms[0].size()) return false;
  const auto& arm = g.arms[c];
  const Vec3 A = q[g.arms[0][g.zone[0]]], G = q[arm[g.zone[c]]];
  const double l = (G - A).norm();
  if (l < 1e-9) return false;
  // Positions by the points' own projections onto A -> G (their order along the trunk).
  std::vector<std::pair<size_t, Vec3>> moves;
  for (size_t i = 0; i < g.zone[c]; ++i) {
    const double s = std::clamp((q[arm[i]] - A).dot(G - A) / (l * l), 0.0, 1.0);
    const Vec3 p = A + s * (G - A);
    if ((p - q[arm[i]]).norm() > g.ownR[c]) return false;
    moves.emplace_back(arm[i], p);
  }
  for (const auto& [k, p] : moves) target[k] = p, moved[k] = 1;
  return true;
}

// A child's overlap that runs into the next fork down its arm (the discrete paths to two of its own branches part
// there, early, a voxel or two apart in one lumen: 11521's root fork, whose child to branch 2 is 2 points long before
// the paths to its branches 5 / 6 part, while it stays fused with branch 1 for ~10 points): the arm is followed
// through that fork into each of its children (the walk's own rules), and the overlap fitted once per child.
void overlapPastNextFork(const JunctionInput& in, size_t b, const std::vector<Vec3>& q, double voxMm,
                         const SectionLobes& lobes, const ForkGeometry& g, std::vector<Vec3>& target,
                         std::vector<uint8_t>& moved, std::vector<double>& lobeR, bool freeFork) {
  constexpr size_t linePoints = 5;
  std::vector<std::vector<size_t>> variants[3];  // per child arm: itself, or its ways on past the next fork
  for (size_t a = 1; a < 3; ++a) {
    const auto& arm = g.arms[a];
    variants[a] = {arm};
    // The point after the arm's last one (b's child itself where the arm is empty).
    size_t f = static_cast<size_t>(in.children[b][a - 1]);
    if (!arm.empty()) {
      if (in.children[arm.back()].size() != 1) continue;
      f = static_cast<size_t>(in.children[arm.back()][0]);
    }
    if (in.children[f].size() < 2) continue;
    variants[a].clear();
    for (int32_t c2 : in.children[f]) {
      std::vector<size_t> ext = arm;
      ext.push_back(f);
      for (int32_t p = c2; p >= 0;) {
        const size_t k = static_cast<size_t>(p);
        if (in.children[k].size() >= 2 || (ext.size() > 2 * linePoints && (q[k] - q[b]).norm() > 60 * voxMm)) break;
        ext.push_back(k);
        p = in.children[k].size() == 1 ? in.children[k][0] : -1;
      }
      variants[a].push_back(std::move(ext));
    }
  }
  if (variants[1].size() == 1 && variants[2].size() == 1) return;  // no arm ends at a fork
  for (const auto& v1 : variants[1])
    for (const auto& v2 : variants[2]) {
      const std::vector<std::vector<size_t>> arms{g.arms[0], v1, v2};
      placeOverlaps({arms, g.zone, g.ownR, &in.raw}, in.radius, q, voxMm, lobes, target, moved, lobeR, freeFork);
    }
}

}  // namespace

size_t placeJunctions(const JunctionInput& in, std::vector<Vec3>& q, std::vector<uint8_t>& frozen, double voxMm,
                      const FusedAt& fusedAt, const SectionWidths& widths, const SectionLobes& lobes,
                      std::vector<double>* ownRadius, double wideTrunkMm) {
  const size_t n = q.size();
  std::vector<double> lobeR(ownRadius ? n : 0, std::numeric_limits<double>::quiet_NaN());
  size_t placed = 0;
  std::vector<Vec3> target = q;
  std::vector<uint8_t> moved(n, 0), freeFork(n, 0);
  ForkGeometry g;
  for (size_t b = 0; b < n; ++b) {
    if (in.children[b].size() < 2 || !analyseFork(in, b, q, voxMm, fusedAt, g)) continue;
    const auto& arms = g.arms;
    const size_t cont = g.cont;
    // Both children placed from their axes' junction (placeFork); else a side branch from b, a fork
    // left to the ordinary refinement.
    const ForkArms fa{arms, g.zone, g.ownR, cont};
    if (placeFork(in, fa, b, q, target, moved, voxMm, widths) ||
        placeParted(in, fa, b, q, target, moved, voxMm, fusedAt, widths, lobes, lobeR))
      continue;
    freeFork[b] = cont == 0;  // left to the ordinary refinement: placeOverlaps fits its zones too
    if (!g.anyFused || cont == 0) continue;
    placeTrunk(g, q, target, moved);
    for (size_t a = 1; a < arms.size() && g.ownR[0] <= wideTrunkMm; ++a) {  // a wide trunk's: placeWideTrunk's
      const size_t zone = g.zone[a];
      if (a == cont || zone == 0 || zone >= arms[a].size()) continue;
      const Vec3 G = q[arms[a][zone]];
      for (size_t i = 0; i < zone; ++i) {
        target[arms[a][i]] = q[b] + (static_cast<double>(i + 1) / static_cast<double>(zone + 1)) * (G - q[b]);
        moved[arms[a][i]] = 1;
      }
    }
  }
  // Overlapping children past the zones (placeOverlaps), once every fork is placed: its fit of two
  // discs re-places the fork placements' points beyond the zones where it applies.
  for (size_t b = 0; b < n; ++b)
    if (in.children[b].size() == 2 && analyseFork(in, b, q, voxMm, fusedAt, g) &&
        !placeOverlaps({g.arms, g.zone, g.ownR, &in.raw}, in.radius, q, voxMm, lobes, target, moved, lobeR,
                       freeFork[b]))
      overlapPastNextFork(in, b, q, voxMm, lobes, g, target, moved, lobeR, freeFork[b]);
  for (size_t i = 1; i < n; ++i)
    if (moved[i] && !frozen[i]) {  // splitForks placed the frozen ones
      q[i] = target[i], frozen[i] = 1, ++placed;
      if (ownRadius && !std::isnan(lobeR[i])) (*ownRadius)[i] = lobeR[i];
    }
  return placed;
}

// Re-branching at the junction (session 14). Where a fork's children's axes meet (forkJunction)
// more than a voxel before the branch point b, the discrete paths of both children run through the
// parent's points between J and b (the "past" class of the family's misses: one point cannot lie
// on both arms). The parent arm's point P nearest to J becomes the branch point: the points after
// P up to b stay with one child (the one that continues the parent, else the first) and are copied
// for each other child, whose first point is re-parented to the last copy. `copy(k)` appends a
// copy of point k to every per-point array and returns its index. The placement (placeJunctions)
// then sees P with both children's own points. Returns the number of forks re-branched.
// Where a narrow fork's children run on side by side, their lumens fused, the discrete paths share
// the fused stretch and the tree branches where it ends, past the junction; the children's axes,
// taken from their first round sections there, diverge from b and meet at it (or not at all), so
// they do not show b past J. The sections' widening along the parent arm through b does
// (imageJunction): the fork is re-branched there when that J lies more than a voxel back up the
// parent arm (10929 / 10221: 7-8 shared points centred between the children, 1.0-1.3 voxels off
// both). G: each child's first round section.
bool imagePastJunction(const JunctionInput& in, const ForkArms& f, size_t b, const std::vector<Vec3>& q,
                       const SectionWidths& widths, double voxMm, ForkJunction& fj) {
  if (!widths || f.arms.size() != 3 || f.arms[0].empty() || f.ownR[0] <= 0) return false;
  ForkJunction out;
  for (size_t a = 1; a < 3; ++a) {
    if (f.zone[a] >= f.arms[a].size()) return false;
    out.G[a] = q[f.arms[a][f.zone[a]]];
  }
  // The track reaches 8 parent radii up the arm (4 as placeFork's left 10221's shared stretch with
  // no round section before it to set the round d0).
  Vec3 J;
  if (!imageForkJunction(in, f, b, q, out, widths, voxMm, J, 8, true) || (J - q[b]).norm() <= voxMm) return false;
  out.J = J;
  out.dir = (q[b] - J).normalized();
  out.along = out.dir.dot(J - q[b]);
  fj = out;
  return true;
}

size_t splitForks(std::vector<int32_t>& parent, std::vector<std::vector<int32_t>>& children, std::vector<Vec3>& q,
                  std::vector<uint8_t>& frozen, const std::vector<double>& radius, double voxMm, const FusedAt& fusedAt,
                  const std::function<size_t(size_t)>& copy, const SectionWidths& widths,
                  const std::function<Vec3(size_t)>& raw, const SectionLobes& lobes, const Vec3& spacing) {
  const size_t n0 = q.size();
  size_t split = 0;
  ForkGeometry g;
  for (size_t b = 1; b < n0; ++b) {
    const JunctionInput in{parent, children, radius, raw};
    if (children[b].size() != 2 || !analyseFork(in, b, q, voxMm, fusedAt, g)) continue;
    const ForkArms f{g.arms, g.zone, g.ownR, g.cont};
    ForkJunction fj;
    const bool axes = forkJunction(f, b, q, voxMm, fj);
    bool fromImage = !axes || fj.along > -voxMm, fromRun = false;
    const RunInput ri{g.arms, g.zone, g.hasLine, g.ownR, q, voxMm, spacing, lobes, fusedAt};
    FusedRun run;
    // Where neither shows b past J, the axes' J taken onto the tree may (forkJunction's snap), else the children's
    // fused run (fork_start.cpp); the image's J first: 10221's, 7-8 points back, is the junction, the snapped one lay
    // 1.5 mm past it (98.4 -> 96.3 %).
    if (fromImage && !imagePastJunction(in, f, b, q, widths, voxMm, fj)) {
      if ((axes || !forkJunction(f, b, q, voxMm, fj, true) || fj.along > -voxMm) &&
          !(fromRun = twoDiscRun(ri, b, run, fj.J, fj.G)))
        continue;
      fromImage = false;
    }
    // P: the parent arm's point nearest to J; the shared section runs from after P down to b. b's parent is itself a
    // branch point: analyseFork's parent arm is empty (its radius came from the children): no P to re-branch at.
    const auto& up = g.arms[0];
    if (up.empty()) continue;
    size_t k = 0;
    for (size_t i = 1; i < up.size(); ++i)
      if ((q[up[i]] - fj.J).norm() < (q[up[k]] - fj.J).norm()) k = i;
    if ((q[up[k]] - fj.J).norm() >= (q[b] - fj.J).norm()) continue;
    std::vector<size_t> shared;  // from P's child down to b
    for (size_t i = k; i-- > 0;) shared.push_back(up[i]);
    shared.push_back(b);
    if (fromImage && !twoLumens(g.ownR[1], g.ownR[2], b, children, q, shared, voxMm, lobes, spacing)) continue;
    // Each child's copy of the shared section goes onto J -> G (its projection, as placeParted's)
    // where every shared point lies within a child's own radius of that child's axis, in the lumen
    // the axes describe (else the fork is left alone). One child's tube is enough: past J the point sits in
    // one child while the other has left it (10311: b 2.5 mm past J, 0.7 mm off the wide child's axis, 1.8
    // off the steep thin one's, r 1.7; requiring both tubes left it shared, 1.6 voxels off the thin one).
    auto onAxis = [&](size_t a, const Vec3& p) {
      const Vec3 seg = fj.G[a] - fj.J;
      const double l2 = std::max(seg.squaredNorm(), 1e-12);
      return Vec3(fj.J + std::clamp((p - fj.J).dot(seg) / l2, 0.0, 1.0) * seg);
    };
    // The fork not there yet (fork_start.cpp): the shared points before it stay the trunk's, J at the last of them.
    const std::vector<size_t> above(up.begin() + static_cast<std::ptrdiff_t>(k) + 1, up.end());
    const SharedStretch st{up[k], above, shared, q, g.ownR[0], g.ownR[0] + std::max(g.ownR[1], g.ownR[2]), voxMm};
    const auto apart = [&](size_t s) { return (onAxis(1, q[s]) - onAxis(2, q[s])).norm(); };
    const size_t stay = fromRun ? 0 : trunkPointsBeforeFork(st, apart, widths);  // a run starts at its top
    if (stay == shared.size()) continue;
    if (stay > 0)
      k -= stay, shared.erase(shared.begin(), shared.begin() + static_cast<std::ptrdiff_t>(stay)), fj.J = q[up[k]];
    bool near = true;
    for (size_t s : shared)
      near = near && ((onAxis(1, q[s]) - q[s]).norm() <= g.ownR[1] || (onAxis(2, q[s]) - q[s]).norm() <= g.ownR[2]);
    // The image's J: the straight J -> G segments of curved side-by-side children lie up to ~1.1 own
    // radii from the shared points (10929 / 10221), so the move is not bounded there.
    if (!near && !fromImage && !fromRun) continue;
    const size_t P = up[k];
    const size_t keep = g.cont == 2 ? 2 : 1;                // the arm that keeps the shared points
    const int32_t moving = children[b][keep == 1 ? 1 : 0];  // the other child's first point
    std::vector<Vec3> kept, copied;                         // per shared point: its place and its copy's
    for (size_t s : shared) kept.push_back(onAxis(keep, q[s])), copied.push_back(onAxis(3 - keep, q[s]));
    if (fromRun && !runDiscs(ri, run, shared, keep, kept, copied, q, frozen)) continue;
    int32_t prev = static_cast<int32_t>(P);
    for (size_t i = 0; i < shared.size(); ++i) {
      const int32_t id = static_cast<int32_t>(copy(shared[i]));
      parent[static_cast<size_t>(id)] = prev;
      children[static_cast<size_t>(prev)].push_back(id);
      q[static_cast<size_t>(id)] = copied[i];
      frozen[static_cast<size_t>(id)] = 1;
      prev = id;
    }
    for (size_t i = 0; i < shared.size(); ++i) q[shared[i]] = kept[i], frozen[shared[i]] = 1;
    auto& cb = children[b];
    cb.erase(std::find(cb.begin(), cb.end(), moving));
    parent[static_cast<size_t>(moving)] = prev;
    children[static_cast<size_t>(prev)].push_back(moving);
    ++split;
  }
  return split;
}

}  // namespace vs::centreline_detail
