// The tube's identity along a route by the width of the lobe it runs in (issue 21, session 41 tieA, tieA2).
#include <algorithm>
#include <cmath>
#include <vector>

#include "tracking/neck_retrace.h"
#include "util/median.h"

namespace vs {

namespace {

// Whether the two tubes a route's sections cut read as two widths at all: the median of the two lobes' radius
// difference over every two-lobe section along the route is larger than the section grid's step (the step under which
// one section's difference is not read) and than its own scatter along the route (median absolute deviation). A
// near-equal pair across thick slices reads the lobe nearer a slice wider, and which one wanders along the pair: its
// differences are read on some sections and not on others, their median under the step (tieA2, 3109).
bool widthsApart(const std::vector<LobeWidths>& w, double step) {
  std::vector<double> d;
  for (const LobeWidths& s : w)
    if (s.two) d.push_back(std::abs(s.rOwn - s.rOther));
  if (d.empty()) return false;
  const double m = medianOf(d);
  for (double& x : d) x = std::abs(x - m);
  return m > step && m > medianOf(d);
}

}  // namespace

// Where two touching tubes of unlike width are cut by the neck re-search's sections (two lobes), the path's own lobe
// is the thinner or the wider one. A route that crosses a contact the thick slices fuse shows no lobe change where it
// crosses (the sections there have one lobe) but its own lobe is the other width before and after. Read only where the
// route's two-lobe sections show two widths (widthsApart); then each two-lobe section's identity: the thinner or the
// wider lobe, where the two radii differ by more than the section's sampling step (sectionAt's grid, half the finest
// spacing: a difference under it is not read); runs of one identity shorter than 2k such sections are flicker (kissA's
// run rule); a change counted between two runs of 2k or more.
int tubeWidthChanges(const std::vector<Index3>& path, const CrossingOptions& o) {
  const std::vector<LobeWidths> w = lobeWidthsAlong(path, o);
  const double step = w.empty() ? 0.0 : 0.5 * o.smoothed->geometry().spacing.minCoeff();
  if (!widthsApart(w, step)) return 0;
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
