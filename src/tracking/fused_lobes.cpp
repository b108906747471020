// A fork's fused section placed by its lobes, read along each child's chain (session 41 lobeC; centreline_junctions.h:
// placeFusedLobes).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "tracking/centreline_junctions.h"
#include "tracking/own_lobe.h"

namespace vs::centreline_detail {

size_t placeFusedLobes(const JunctionInput& in, const FusedLobeInput& fl, std::vector<Vec3>& q,
                       std::vector<uint8_t>& frozen, std::vector<double>& ownRadius) {
  constexpr size_t ownPoints = 10;  // placeOverlaps' own-tube run
  const CentrelineOptions& o = fl.o;
  const size_t n = q.size();
  if (!(o.lobeValley > 0) || !(o.lobeForkRadii > 0) || n == 0) return 0;
  LobeScratch sc;
  // Point k's section (the rounds' plane, ownLobeOffset's level and half size) read from `anchor`: its lobes and the
  // anchor's lobe.
  const auto lobeAt = [&](size_t k, const Vec3& anchor) {
    const double value = fl.sample.at(q[k].cwiseProduct(fl.spacing.cwiseInverse())), s = fl.surroundings[k];
    if (std::isnan(s) || value == s || !(in.radius[k] > 0)) return LobeResult{};
    const double halfMm = std::min(o.maxRadiusMm, 2.5 * in.radius[k] + 2 * fl.spacing.minCoeff());
    return ownLobe(fl.sample, fl.spacing, q[k], fl.tangent(k), anchor, 0.5 * (value + s), value > s, halfMm,
                   o.lobeValley, sc);
  };
  std::vector<Vec3> target = q;
  std::vector<double> lobeR(n, std::numeric_limits<double>::quiet_NaN());
  std::vector<uint8_t> hold(n, 0);
  for (size_t f = 0; f < n; ++f) {
    if (in.children[f].size() != 2) continue;
    const double reach = o.lobeForkRadii * in.radius[f];
    // Each child's chain from the fork (to its next fork or end): the part within the fused section's reach along it,
    // and up to ownPoints more where it leaves it; and the first section past one of two lobes or more (within the
    // reach) that is the child's own tube alone (one lobe): where the child has left the fused section.
    std::vector<size_t> chain[2];
    size_t end[2] = {0, 0};
    for (size_t a = 0; a < 2; ++a) {
      size_t within = 0;
      double along = 0;
      for (size_t k = static_cast<size_t>(in.children[f][a]), prev = f;;) {
        along += (q[k] - q[prev]).norm();
        if (along <= reach) within = chain[a].size() + 1;
        chain[a].push_back(k);
        if (in.children[k].size() != 1 || chain[a].size() >= within + ownPoints) break;
        prev = k, k = static_cast<size_t>(in.children[k][0]);
      }
      end[a] = chain[a].size();
      bool fusedSeen = false;
      for (size_t i = 0; i < chain[a].size() && end[a] == chain[a].size(); ++i) {
        const int lobes = lobeAt(chain[a][i], q[chain[a][i]]).lobes;
        if (lobes >= 2 && i < within) fusedSeen = true;
        if (lobes == 1 && fusedSeen) end[a] = i;
      }
    }
    for (size_t a = 0; a < 2; ++a) {
      if (end[a] == chain[a].size()) continue;
      // The sibling's own tube: its point past its fused section, else its chain's last.
      const Vec3 sibling = q[chain[1 - a][std::min(end[1 - a], chain[1 - a].size() - 1)]];
      // Back towards the fork, each section of two lobes or more whose own lobe is not the sibling's: its point to
      // the centre of its own lobe, the lobe read from the centre placed before it (the own tube's point first) -
      // in order along the child.
      // A lobe that swells as the walk goes back takes in another tube (two tubes fused less than a slice apart):
      // the walk stops where the own lobe's width grows by more than the walk's step along the child since the
      // section read before it (the own tube's section at `end` first) - a wall opening at over 45 degrees.
      Vec3 anchor = q[chain[a][end[a]]];
      double width = lobeAt(chain[a][end[a]], anchor).widthMm;
      bool lastPlaced = false;
      for (size_t i = end[a]; i-- > 0;) {
        const size_t k = chain[a][i];
        LobeResult l = lobeAt(k, anchor);
        const Vec3 centroid = l.centre;
        // A section of one lobe next to a placed point (towards the fork) is the two tubes' union: the final centring
        // would take its point to the union's middle, with no free neighbour's step to hold it (11302's k 259: 1.5 mm
        // towards the sibling, on it). Its point keeps the rounds' position (kindC4).
        if (l.lobes < 2 && lastPlaced) hold[k] = 1;
        if (l.lobes < 2 || l.radiusMm > o.wideRadii * o.maxRadiusMm) break;
        // The own lobe's peak of lumen-ness, not its centroid: the centroid leans towards the sibling's through their
        // overlap (session 42 kindC3).
        l.centre = l.peak;
        const double lobeWidth = l.widthMm;
        if (lobeWidth - width > (q[k] - q[chain[a][i + 1]]).norm()) break;
        width = lobeWidth;
        lastPlaced = false;
        // A fork's fused section holds its two children's lobes; one of three lobes or more holds another tube or a
        // lumen split by noise, and which lobe is the child's own is not told by the anchor: the point stays
        // (head_3dra 126,95,183's moves of 1-2.9 mm in sections of 3 and 6 lobes; kindC4).
        if (l.lobes > 2) {
          anchor = q[k];
          continue;
        }
        const LobeResult other = lobeAt(k, sibling);
        if (other.lobes < 2 || (other.centre - centroid).norm() <= 0.5 * fl.spacing.minCoeff()) break;
        // The union's centre leans towards the sibling, the own lobe's peak away from it: a point the lobe would take
        // nearer the sibling's lobe is read as on its own tube already and stays (12124's b1, 0.2-0.3 voxel off it).
        if ((l.centre - other.centre).norm() < (q[k] - other.centre).norm()) {
          anchor = q[k];
          continue;
        }
        target[k] = anchor = l.centre;
        lastPlaced = true;
        lobeR[k] = l.radiusMm;
      }
    }
  }
  size_t placed = 0;
  for (size_t k = 1; k < n; ++k) {
    if (!std::isnan(lobeR[k])) q[k] = target[k], frozen[k] = 1, ownRadius[k] = lobeR[k], ++placed;
    if (hold[k]) frozen[k] = 1;
  }
  return placed;
}

}  // namespace vs::centreline_detail
