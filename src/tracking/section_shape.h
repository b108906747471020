// One flat lumen or two tubes fused at a contact, read from a section's shape (issue 21, flat lumens): a dural
// sinus or an aorta pressed flat is an ellipse in its section, convex all round, widest across its middle; two
// round tubes touching (a kiss, a root fork's fused arms) make a figure of eight, widest across each tube's axis
// and narrowest at their contact (a waist). Both are elongated, so the aspect alone does not tell them apart.
//
// The section is sectionCentre's (the plane normal to `tangent` at `c`, its own half-way level): the component
// holding c, its principal axes (second moments), and its profile along the major axis - the chord across at each
// step (the mask) and the contrast summed across (the image: a blurred waist is filled in the mask first).
// waist = the narrowest profile value between the widest on either side of the centroid, over the smaller of
// those two (1: the widest is at the middle, an ellipse; towards 0: two lobes).
#pragma once

#include "tracking/cross_section.h"

namespace vs {

struct SectionShape {
  bool ok = false;
  bool clipped = false;  // the component reaches the grid's edge (wider than 2 halfMm)
  double aspect = 0;     // sqrt(major / minor second moment): an ellipse's a / b
  double lengthMm = 0;   // the component's extent along its major axis
  double widthMm = 0;    // its widest chord across the major axis
  double waist = 0;      // the mask's chord profile (see above)
  double massWaist = 0;  // the image's contrast profile
  double plateau = 0;    // the share of the component beyond 3/4 of its peak contrast (see the .cpp)
  double stepMm = 0;
  double level = 0;
};

SectionShape sectionShape(const TrilinearSampler& sample, const Vec3& spacing, const Vec3& c, const Vec3& tangent,
                          double centreValue, double surroundings, double halfMm, SectionScratch& scratch);

}  // namespace vs
