// The neck re-search's sections (neck_retrace.cpp's sectionAt) and a tracker's memo of them (issue 21, session 43
// lazyA4): a section reads only the smoothed volume, the lumen's sign and three of the path's points - the point
// itself and the two its tangent is taken between (3 points either side, fewer at the path's ends) - so one read on
// any route is the same on every route through those three points. The tracker reads a route's sections several times
// (the neck re-search, held to the cost and then to the intensity; the width reading of retraceByWidth; the new
// routes' checks), and consecutive routes share all but the stretch a re-search replaced.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <unordered_map>

#include "volume/geometry.h"

namespace vs {

namespace neck_detail {

struct Section {
  bool two = false;  // own lobe at the path's voxel and another lobe beside it
  Vec3 own{0, 0, 0}, other{0, 0, 0};
  double rOwn = 0, rOther = 0;  // radii of discs of the lobes' areas (mm)
  Vec3 t{0, 0, 1};
  Vec3 ownPeak{0, 0, 0}, otherPeak{0, 0, 0}, neck{0, 0, 0};
};

}  // namespace neck_detail

// The sections already read, by the three points each read (first, the point, last of the tangent's span); for one
// smoothed volume and sign (another clears it). Exact: a section found here is the one sectionAt returns for them.
class NeckSectionMemo {
 public:
  using Key = std::array<Index3, 3>;
  // The section for key, read with `readSection` where not known yet.
  template <class Read>
  const neck_detail::Section& get(const void* sm, double sign, const Key& key, Read&& readSection) {
    if (sm != sm_ || sign != sign_) known_.clear(), sm_ = sm, sign_ = sign;
    const auto it = known_.find(key);
    if (it != known_.end()) {
      ++reused;
      return it->second;
    }
    if (known_.size() >= kMaxSections) known_.clear();  // memory bounded; what is dropped is read again
    ++read;
    return known_.emplace(key, readSection()).first->second;
  }
  int64_t read = 0, reused = 0;  // sections read, and found read before

 private:
  static constexpr size_t kMaxSections = size_t(1) << 17;
  struct Hash {
    size_t operator()(const Key& k) const {
      size_t h = 0;
      for (const Index3& v : k)
        for (const int64_t c : v) h = h * 1000003u ^ std::hash<int64_t>{}(c);
      return h;
    }
  };
  const void* sm_ = nullptr;  // the smoothed volume's address
  double sign_ = 0;
  std::unordered_map<Key, neck_detail::Section, Hash> known_;
};

}  // namespace vs
