// A daughter's axis read from the image near a wide trunk (issue 21, session 31 wide29; internal to
// src/tracking, used by replaceJunctions in wide_trunk.cpp).
//
// A wide trunk's junction J lies 16-26 mm back along the trunk's axis from its daughter's chord, so the
// chord's axial errors become J's, multiplied (docs/notes/tracking.md, sessions 26-30: wide26 - wide28).
// The centred points of a daughter thinner than a slice sit on plateaus along the slice axis (10206: 5 mm of
// its course within 0.05 mm while it rises 0.5; 11206: its last 3 points), which the fitted course cannot
// tell from a change of slope. Fitting the tube itself to the voxels around the chord - a straight cylinder
// with a linear partial-volume edge (the fraction of a voxel inside, its extent along the normal), its
// lumen and background levels free - reads the daughter's place from every voxel's partial volume, not
// from one centred point per section.
#pragma once

#include <vector>

#include "volume/sample.h"

namespace vs::centreline_detail {

// The daughter's axis (a point `centre` and unit `dir`, mm, oriented as the chord's points run) fitted to the
// voxels within its radius and two voxel extents of the line through the chord's points (outward from the trunk)
// that lie beyond the trunk's partial volume (at least 3; else false), over their extent (from a daughter radius before
// its first point to its last: not past its last, where the daughter's own end or fork lies), beyond the trunk's wall
// and partial volume (farther than trunkMm + the largest spacing from the trunk's axis through ac along ea). The
// cylinder's radius starts at daughterMm. False (nothing changed) where fewer than minVoxels voxels take part, the fit
// leaves its radius outside (0, 3 x daughterMm], the fitted tube is not on the lumen's side (`side`: 1 bright, -1
// dark), or a chord point lies outside the fitted tube (farther from its axis than its radius).
bool fitDaughterTube(const TrilinearSampler& sample, const Vec3& spacing, const std::vector<Vec3>& chordIn,
                     const Vec3& ac, const Vec3& ea, double trunkMm, double daughterMm, int side, Vec3& centre,
                     Vec3& dir);

}  // namespace vs::centreline_detail
