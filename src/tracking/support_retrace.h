// A path through the background where the tree's route is dearer (issue 21, session 37 crowd37; session 33 diag717's
// fix (iii)): a crowded block reads three thin tubes' partial volume as its local background (11702: p75 69.7 against
// 33-46 in its neighbours), so the first halves of two curled-back branches cost the cost's ceiling and the cheapest
// way to their ends is a hop from the trunk through 4-8 voxels of background. The path support test (path_support.h)
// flags the longer hops in the trace's notes ("crosses ... without lumen", 5 mm and more). Here a run of path voxels
// without lumen in the cost's model that crosses the background (its mean contrast no brighter than the local
// background) over two steps or more is searched again (session 38 hop702: the note's 5 mm left 11702's 4-voxel hop
// to b9): the background it runs through is blocked, the path searched again from its start to its target, and the
// new route is kept only where it has no such run at all - by support, not by cost (the tree's route is the dearer
// one: that is why the search took the hop). A route with such runs has them blocked too and is searched again, up
// to CrossingOptions::maxRounds searches per box; the box is the path's with the re-searches' margin, its margin
// doubled while no route is kept, up to the whole volume or the re-searches' 2^23 voxels. The note is unchanged.
// Session 38 hop927: a run's steps are counted in the finest spacing (a step across a thick slice counts the finest
// voxels it spans); the block is the run's own background, no brighter than the run; where no route of the schedule
// is free of such runs, the one whose darkest run is the brightest is kept if that run lies within the noise spread
// of the background and is brighter than the path's own (a dim tube's end at the background's level, 10731's b12).
#pragma once

#include <vector>

#include "tracking/crossing_retrace.h"

namespace vs {

struct SupportRetrace : RetraceOutcome {
  int stretches = 0;  // stretches the support test flags on the input path
  int rounds = 0;     // searches run
};

// Off (unchanged) unless o.autoCost, o.background, o.estimate and o.smoothed are set.
SupportRetrace retraceUnsupported(const NodeCost3D& cost, const std::vector<Index3>& path, int connectivity,
                                  const CrossingOptions& o);

}  // namespace vs
