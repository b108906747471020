// The narrow fused fork (issue 21, session 35): two children whose walls overlap for several mm past
// their junction. A path to one child runs a few voxels in its sibling's lumen and crosses into its
// own child 5-15 mm along (the shortest chord through the fused union, both routes at the cost
// floor), so the child's first stretch lies on no path (11825's paths 0 / 1, 10823, 10227, 36). Blocking
// the sibling's fused tube alone also seals the own child's fused start (session 34, fork34), so the own
// child's tube is found first: walked back from where the path enters it, section by section along its own
// lumen, to the shared chain before the parting (refused where a walked centre lies nearer the sibling's chain
// than the path's fused stretch, or where the walk never leaves that stretch by its own radius). The sibling's
// tube and the path's chord are then blocked only where they lie nearer the sibling's chain or the chord than
// the walked centres, and the stretch searched again from the shared chain to past the entry; kept by cost per
// mm and as a tube of its own (through the walked tube's farthest section from the old route).
// Session 40 (fork331): ported onto the walks' step (contact_walk.h stepOn); the walk meets the shared chain also
// within the trunk's radius of its last point continued along the trunk, and the shared chain up to the meeting stays
// open in the block (12331's paths 2 / 3: 97.7 -> 99.3 %; 11825 as main).
#pragma once

#include <string>
#include <vector>

#include "tracking/crossing_retrace.h"

namespace vs {

struct FusedForkRetrace : RetraceOutcome {
  bool walked = false;  // the own child's tube walked back to the shared chain
};

// `path` searched again against `sibling`, an other traced path sharing its first voxels (their parting:
// the first voxel where they differ). lumenLevel: the node cost at or below which a voxel is lumen.
FusedForkRetrace retraceFusedFork(const NodeCost3D& cost, const std::vector<Index3>& path,
                                  const std::vector<Index3>& sibling, int connectivity, double lumenLevel,
                                  const CrossingOptions& o);

// The second reading of the parting (session 43 forkE), where the first found no route: the own child read from its
// far end back along the path, section by section, to its first section joined with the sibling's chain past the
// parting c; where that joined run reaches back before c (the paths to both children share it: the route cut through
// the sibling's start) and the shared stretch lies off the own child's axis continued back, the sibling's chain from
// the run's back end is blocked and the stretch searched again from the shared chain to past the entry e.
FusedForkRetrace retraceFromJoinedSection(const NodeCost3D& cost, const std::vector<Index3>& path,
                                          const std::vector<Index3>& sibling, size_t c, size_t e, double rS,
                                          double rOwn, int connectivity, double lumenLevel, const CrossingOptions& o);

}  // namespace vs
