// Kissing vessels (issue 21): a minimal path that crosses from one tube into a neighbouring one
// where the two touch. Where the neck between them is not in the data, every voxel of both routes
// costs the same and the search may take the shorter one: along the first tube, then sideways into
// the second. A path that stays in one tube keeps its direction through a section; a crossing
// shows as a sideways step of about the two radii between stretches of the same direction, where
// the tube left goes on past the step and the tube entered reaches back before it.
// `findLateralSteps` finds such steps on a voxel path; `retraceAcrossCrossings` blocks the tube
// the path leaves along the contact (the voxels within a step's size of the path before the step,
// on its side of the plane half-way across, back to where the other tube no longer lies alongside)
// and searches the stretch around the strongest step again (in a box around it; the rest of the
// path is kept), up to maxRounds times while the new stretch still steps sideways. The new path is
// kept only when it takes a route of its own (farther than departSteps steps from the old one) and
// costs at most costSlack more: a single tortuous vessel whose bend is blocked has no such route.
#pragma once

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "cost/cost3d.h"
#include "volume/volume.h"

namespace vs {

struct AutoCostOptions;
struct LocalBackground;
struct LumenEstimate;
class NeckSectionMemo;

struct CrossingOptions {
  bool enabled = true;
  // The node cost at or below which a voxel is lumen; NaN: the tracker takes lumenCostThreshold.
  double lumenLevel = std::numeric_limits<double>::quiet_NaN();
  double parallelDeg = 30;   // the path's direction before and after the step differ by at most this
  double minStepVoxels = 2;  // sideways step of at least this many smallest spacings ...
  double steepness = 0.5;    // ... and at least this times its length along the path's direction
  int spanSteps = 2;         // the step is measured between points this many steps before and after
  int directionSteps = 5;    // the directions before and after over this many steps
  // Drifts (session 16): the path may also cross the contact gradually, its 26-connected staircase
  // moving sideways over many steps. Spans up to driftSteps (path steps between the stretches) are
  // tried too (0: steps only); there the steepness is not asked, but the tubes must lie side by
  // side at both ends (the other tube's lumen across the step from the stretch before, the tube
  // left's across it from the stretch after), and the sideways move must be at least driftRadii x
  // the two half-widths (from one tube's axis to the other's). Drifts are looked for only with the
  // cost (without the lumen tests a drift is any bend of the path).
  int driftSteps = 24;
  double driftRadii = 0.8;
  double reachLeft = 3;       // the tube left goes on in the lumen for this many times the step past it
  double reachEntered = 1.5;  // the tube entered reaches back in the lumen this many times the step
  double radiiShare = 0.4;    // the step is at least this times the two tubes' half-widths (summed)
  int maxRounds = 3;          // searches with more blocks while the new path still steps sideways
  double costSlack = 0.1;     // new cost <= old x (1 + costSlack)
  double departSteps = 2;     // the new path goes farther than this times the step from the old one
  double lengthSlack = 0.5;   // new length <= old x (1 + lengthSlack)
  double windowBack = 20;     // searched again from this many times the step before it ...
  double windowAhead = 8;     // ... to this many after it (the rest of the path is kept)
  double marginSteps = 5;     // the box: the path's box + marginSteps x the largest step, >= 12 voxels
  // A step inside one lumen at least oneLumenSteps x the step wide both along the step and across
  // it at its middle (holes in the lumen of up to lumenHoleVoxels smallest spacings bridged) is no
  // crossing (session 24: a 2.6 mm step in a ~10 mm sinus whose cost is patchy; 0: off).
  double oneLumenSteps = 2.5;
  double lumenHoleVoxels = 2;
  // Kissing drifts (session 20): the path to one tube takes its neighbour from the fork and crosses
  // where they touch, gradually, so the cost shows no step. The smoothed intensity's sections
  // normal to the path hold two lobes along the contact; where the path's own lobe changes to the
  // other one, the neck between the lobes is blocked along the whole two-lobe stretch and the
  // stretch searched again from before it. Where that finds no crossing or no route, the two lobes
  // are followed section by section and the last of an odd number of changes is taken, with a
  // thinner band (session 21: the crossing where the tubes part or where the other still converges,
  // across thick slices). Off without the smoothed intensities. The re-search: neck_retrace.h.
  const VolumeF32* smoothed = nullptr;
  bool brightLumen = true;  // the smoothed volume's lumen is brighter than its surroundings
  // The sections of smoothed already read (neck_sections.h; null: none kept). The tracker sets its own in the copy it
  // hands its re-searches (session 43 lazyA4): every read of a section it finds there is the one read again.
  NeckSectionMemo* neckSections = nullptr;
  int neckLobeSteps = 4;        // a crossing: the own lobe k points on nearer the other lobe k points back
  int neckBridge = 6;           // two-lobe stretches with gaps of up to this many points are one
  double neckCostSlack = 0.25;  // the new part's cost <= (1 + slack) x the old part's
  // Set by the tracker on a route the dip re-search changed, where the node cost is known to read a
  // tube as background (and by the neck re-search across unlike lobes, below): a neck route the slack
  // refuses is then held to the lumen by intensity.
  bool neckByIntensity = false;
  // Set by the tracker where no re-search changed the path (session 34, neck35): the neck route held to the lumen by
  // intensity is taken only where the node cost reads a stretch of it as no lumen (above the lumen level, at least the
  // path support test's length: path_support.h) that the intensity reads as lumen all along - the cost's refusal
  // then comes from its own hole (11709: 12 mm of the thin tube at cost 1.0), not from a route it rightly prices.
  bool neckByIntensityInHole = false;
  // The tube left blocked (the third try) also across a crossing whose lobes are up to this factor
  // apart in radius (kissing tubes' are within 2.5), its route held to the lumen by intensity.
  double neckUnlikeRatio = 3.5;
  // Parallel tubes a slice apart (session 22): a path that jumps the background between two lumens
  // (dip_retrace.h). dipSteps: the flanks' points either side (0: off); dipShare: the dip lies
  // within this share of the way from the background (shell of dipShellVoxels smallest spacings)
  // to the dimmer flank; dipLevel: the re-search keeps to voxels this share of the way from the dip
  // to that flank; dipBack: points searched again before the dip; dipBoxVoxels: the searched box's
  // margin round that stretch (smallest spacings; session 23: the faded tube's route from its fork
  // can run further from the old path than the other re-searches' 12).
  int dipSteps = 4;
  double dipShare = 0.15;
  double dipShellVoxels = 10;
  double dipLevel = 0.5;
  int dipBack = 200;
  double dipBoxVoxels = 20;
  // Tubes touching where they cross at an angle (session 25, contact_retrace.h): a turn of at least
  // contactTurnDeg where each tube's own sections go on at both sides of the contact,
  // contactReachRadii of its own radii beyond the other tube (10301 found up to 3, other family
  // lines change from 1 down).
  double contactTurnDeg = 60;
  double contactReachRadii = 2;
  // A path stretch the path support test flags (path_support.h: no lumen in the auto cost's model and no contrast
  // beyond the noise, at least its least length) searched again with that background blocked (support_retrace.h).
  // Set by the trace session with the auto cost only (null: off).
  const AutoCostOptions* autoCost = nullptr;
  const LocalBackground* background = nullptr;
  const LumenEstimate* estimate = nullptr;
};

struct LateralStep {
  size_t before = 0, after = 0;  // path indices around the step
  Vec3 mid{0, 0, 0};             // half-way across (mm)
  Vec3 normal{0, 0, 0};          // unit, from the tube left to the tube entered
  double lateralMm = 0;
  bool drift = false;  // found over a span longer than spanSteps
};

// Sideways steps between parallel stretches of a 26-connected voxel chain (strongest first per
// stretch, non-overlapping). With a cost: only where the stretch before the step goes on in the
// lumen past it and the stretch after reaches back in the lumen before it (reachLeft,
// reachEntered x the step), i.e. two tubes side by side.
std::vector<LateralStep> findLateralSteps(const Geometry& g, const std::vector<Index3>& path,
                                          const CrossingOptions& o = {}, const NodeCost3D* cost = nullptr,
                                          double lumenLevel = 0);

// Cost of a voxel chain with the node cost's edge costs (the engine's).
double chainCost(const NodeCost3D& cost, const std::vector<Index3>& path);

// What every re-search of a path returns (this one and the dip, neck and contact re-searches).
struct RetraceOutcome {
  bool changed = false;        // voxels replaced
  std::vector<Index3> voxels;  // the new path (when changed)
  double oldCost = 0, newCost = 0;
  std::string why;  // when something was found but the path was kept
};

struct CrossingRetrace : RetraceOutcome {
  int steps = 0;   // sideways steps found on the input path
  int rounds = 0;  // searches run
};

// connectivity 6, 18 or 26. lumenLevel: the node cost at or below which a voxel is lumen.
CrossingRetrace retraceAcrossCrossings(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                                       double lumenLevel, const CrossingOptions& o = {});

}  // namespace vs
