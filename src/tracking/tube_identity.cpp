// The tube's identity along a route by the width of the lobe it runs in (issue 21, session 41 tieA).
#include <algorithm>
#include <cmath>
#include <vector>

#include "tracking/neck_retrace.h"

namespace vs {

// Where two touching tubes of unlike width are cut by the neck re-search's sections (two lobes), the path's own lobe
// is the thinner or the wider one. A route that crosses a contact the thick slices fuse shows no lobe change where it
// crosses (the sections there have one lobe) but its own lobe is the other width before and after. Each two-lobe
// section's identity: the thinner or the wider lobe, where the two radii differ by more than the section's sampling
// step (sectionAt's grid, half the finest spacing: a difference under it is not read); runs of one identity shorter
// than 2k such sections are flicker (kissA's run rule); a change counted between two runs of 2k or more.
int tubeWidthChanges(const std::vector<Index3>& path, const CrossingOptions& o) {
  const std::vector<LobeWidths> w = lobeWidthsAlong(path, o);
  if (w.empty()) return 0;
  const double step = 0.5 * o.smoothed->geometry().spacing.minCoeff();
  const size_t k = size_t(std::max(1, o.neckLobeSteps));
  int changes = 0, last = 0, id = 0;  // id: +1 the wider lobe, -1 the thinner
  size_t run = 0;
  const auto close = [&] {  // a run of 2k sections or more: a change where its width is not the last run's
    if (run < 2 * k) return;
    changes += last != 0 && id != last;
    last = id;
  };
  for (const LobeWidths& s : w) {
    if (!s.two || std::abs(s.rOwn - s.rOther) <= step) continue;
    const int here = s.rOwn > s.rOther ? 1 : -1;
    if (here != id) close(), id = here, run = 0;
    ++run;
  }
  close();
  return changes;
}

}  // namespace vs
