// A point where its own tube bends as tightly as its radius (issue 21, session 38 apex930: thin forced 11930's trunk
// curl, a child leaving beside its apex and turning back). Where the bend's radius is no larger than the tube's, the
// lumen on the bend's inner side is the curl's own (the plane normal to the tangent at the apex cuts the tube's arms
// on either side of it) and whatever lies beside it (a child leaving at the apex: the fused crotch), so the section is
// open on the inside: its chords and its own lobe (own_lobe.h) draw the point inwards, by up to 1.4 voxels at 11930's
// apex, and the rounds' smoothing against a centring that has not settled keeps it there. The outer wall and the chord
// across the bend's plane (along the binormal) are the tube's own: the point goes one such half chord in from the
// outer wall.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "volume/geometry.h"
#include "volume/sample.h"

namespace vs::centreline_detail {

// The radius (mm) of the circle through q[k] and the points `arcMm` along its chain each way (walking up to the root
// or a branch point and down a plain chain to a branch point or an end, each included); `centre` receives that
// circle's centre. +inf where k is the root, a branch point or an end, or the three points lie in line.
double chainBendRadius(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                       const std::vector<Vec3>& q, size_t k, double arcMm, Vec3& centre);

// One cast's rays at q[k] (unit directions `dirs` in the section plane normal to `tangent`, mm; `radius` per ray, < 0:
// no crossing; every `stride`-th marched, ray j + n/2 opposite ray j; `medianRadius` their median). Where the chain
// bends at q[k] no wider than the tube's radius (chainBendRadius over one median ray each way, at most the median
// ray), the step's component along the bend's outward normal (in the section plane) becomes the one that puts the
// point a half chord across the bend's plane (the chord nearest the binormal) in from the outer wall (the ray nearest
// the outward normal) - unless that ray or chord found no wall, or the ray ran more than twice the median (castRays'
// own rule: it left the lumen's section). The component across the bend's plane stays. Returns whether `off` changed.
// Session 38 apex930b: where `section` is given, the chord across the bend's plane at the new position (marched
// from it along the binormal both ways to the cast's level, half way from the value at q[k] to its surroundings)
// must be no narrower than the one through q[k]: in a round tube the chord across widens towards the axis, where the
// step goes; a fused pair's section (run37's 12024: the across chord one tube's, the outward ray running on through
// the contact into the other tube) narrows towards their contact, the waist, which is not a curl's centre.
struct BendSection {
  const TrilinearSampler& sample;
  const Vec3& spacing;
  double surroundings;  // the cast's background value
};
bool tightBendStep(const std::vector<int32_t>& parent, const std::vector<std::vector<int32_t>>& children,
                   const std::vector<Vec3>& q, size_t k, const Vec3& tangent, const std::vector<Vec3>& dirs,
                   const std::vector<double>& radius, size_t stride, double medianRadius, bool awayFromForks, Vec3& off,
                   const BendSection* section = nullptr);

// The chord (mm) through `at` along `dir` (both ways) to `level` in `section`, marched in steps of half the smallest
// spacing up to `maxMm` each way; -1 where a side finds no wall within maxMm or leaves the volume.
double chordThrough(const BendSection& section, const Vec3& at, const Vec3& dir, double level, bool bright,
                    double maxMm);

}  // namespace vs::centreline_detail
