// A fork whose tree branches past its junction, found from the sections along the shared chain (session 44 kindC6).
#pragma once

#include "tracking/centreline_junctions.h"

namespace vs::centreline_detail {

// A fork whose tree branches past its junction where neither the axes, the sections' widening nor a fit of two discs
// shows it (splitForks' last reading; scan60b's form (i): 6321's root fork, the children's union read as one elongated
// lumen, no two discs): b's section is fused - its widest chord wider than the parent's own sections' before the fork
// (their median past forkJunction's reach, session 44 kindC7: not the analysed radius, which a real vessel's
// non-round, tapering or widening lumen outgrows) by more than the grid's spacing: more than the parent's tube -
// and, walking the shared chain up from b, J is the first section that is the parent's round lumen again, within
// forkJunction's reach of b, and not b's parent (at least one shared point before b in the union: b itself lies in
// both children's lobes at any fork; 12524, 6624); both arms' first sections are fused too (a child already out of the
// union at b: the tree branches at the parting, thin 25), and the fused run from J down through b and on along both
// arms (to the nearer arm's first round section) must reach farther than the junction's reach (twoDiscRun's: the
// parent's radius + the wider child's; a shorter fused stretch is the junction zone's own). G[1] / G[2]: the children's
// first points past their zones, or an arm's last where its zone runs to its end (a next fork close by).
bool sectionRun(const RunInput& in, size_t b, Vec3& J, Vec3 (&G)[3]);

}  // namespace vs::centreline_detail
