#include "graph/block_search.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <string>

#include "util/error.h"

namespace vs {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr uint8_t kSettled = 0x40;
constexpr uint8_t kNone = 0x1f;
constexpr uint8_t kDir = 0x1f;

struct Slab {
  std::vector<double> t;
  std::vector<float> c;
  std::vector<uint8_t> s;
};

struct Entry {
  double f;
  uint64_t id;
  bool operator>(const Entry& o) const { return f > o.f; }
};

std::string voxelText(const std::array<int64_t, 3>& p) {
  return "(" + std::to_string(p[0]) + "," + std::to_string(p[1]) + "," + std::to_string(p[2]) + ")";
}

}  // namespace

struct BlockSearch::Impl {
  BlockCostSource src;
  int sh = 5;
  int64_t B = 32;
  uint64_t localMask = 0;
  std::array<int64_t, 3> nb{};
  std::vector<Slab*> dir;                    // one entry per block of the grid (nullptr: untouched)
  std::vector<int64_t> touched;              // blocks allocated by the current search
  std::vector<std::unique_ptr<Slab>> slabs;  // every slab ever made (pooled)
  std::vector<Slab*> freeSlabs;
  std::array<std::array<int, 3>, 26> off{};
  std::array<int64_t, 26> localOff{};
  std::array<double, 26> halfLen{}, len{};
  std::vector<float> fillBuf;
  BlockSearchStats stats;

  explicit Impl(BlockCostSource s) : src(std::move(s)) {
    if (!src.fill) throw InvalidArgument("block search: no cost provider");
    if (src.blockShift < 2 || src.blockShift > 8)
      throw InvalidArgument("block search: block shift " + std::to_string(src.blockShift) + " outside 2..8");
    for (int a = 0; a < 3; ++a) {
      if (src.dims[a] < 1) throw InvalidArgument("block search: dimension " + std::to_string(src.dims[a]) + " < 1");
      if (!(src.spacing[a] > 0) || !std::isfinite(src.spacing[a]))
        throw InvalidArgument("block search: spacing must be finite and > 0");
    }
    if (!(src.minCost >= 0) || !std::isfinite(src.minCost))
      throw InvalidArgument("block search: minCost must be finite and >= 0");
    sh = src.blockShift;
    B = int64_t(1) << sh;
    localMask = (uint64_t(1) << (3 * sh)) - 1;
    for (int a = 0; a < 3; ++a) nb[a] = (src.dims[a] + B - 1) >> sh;
    const double blocks = double(nb[0]) * double(nb[1]) * double(nb[2]);
    if (blocks > double(int64_t(1) << 28))
      throw InvalidArgument("block search: " + std::to_string(int64_t(blocks)) +
                            " blocks; use larger blocks (blockShift) for this grid");
    dir.assign(size_t(blocks), nullptr);
    int k = 0;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (!dx && !dy && !dz) continue;
          off[k] = {dx, dy, dz};
          localOff[k] = dx + (int64_t(dy) << sh) + (int64_t(dz) << (2 * sh));
          const double x = dx * src.spacing[0], y = dy * src.spacing[1], z = dz * src.spacing[2];
          len[k] = std::sqrt(x * x + y * y + z * z);
          halfLen[k] = len[k] * 0.5;
          ++k;
        }
  }

  int64_t blockIndex(int64_t bx, int64_t by, int64_t bz) const { return bx + nb[0] * (by + nb[1] * bz); }

  uint64_t idOf(const std::array<int64_t, 3>& p) const {
    const int64_t b = blockIndex(p[0] >> sh, p[1] >> sh, p[2] >> sh);
    const int64_t l = (p[0] & (B - 1)) + ((p[1] & (B - 1)) << sh) + ((p[2] & (B - 1)) << (2 * sh));
    return (uint64_t(b) << (3 * sh)) | uint64_t(l);
  }
  std::array<int64_t, 3> coordsOf(uint64_t id) const {
    const int64_t b = int64_t(id >> (3 * sh));
    const int64_t l = int64_t(id & localMask);
    const int64_t bx = b % nb[0], by = (b / nb[0]) % nb[1], bz = b / (nb[0] * nb[1]);
    return {(bx << sh) + (l & (B - 1)), (by << sh) + ((l >> sh) & (B - 1)), (bz << sh) + (l >> (2 * sh))};
  }

  Slab* slab(int64_t b) {
    Slab*& p = dir[size_t(b)];
    if (p) return p;
    const size_t n = size_t(1) << (3 * sh);
    Slab* s;
    if (!freeSlabs.empty()) {
      s = freeSlabs.back();
      freeSlabs.pop_back();
    } else {
      slabs.push_back(std::make_unique<Slab>());
      s = slabs.back().get();
      s->t.resize(n);
      s->c.resize(n);
      s->s.resize(n);
    }
    std::fill(s->t.begin(), s->t.end(), kInf);
    std::fill(s->s.begin(), s->s.end(), kNone);
    const int64_t bx = b % nb[0], by = (b / nb[0]) % nb[1], bz = b / (nb[0] * nb[1]);
    src.fill({bx, by, bz}, std::span<float>(s->c.data(), n));
    // Validate and mark voxels outside the grid impassable.
    for (int64_t lz = 0; lz < B; ++lz)
      for (int64_t ly = 0; ly < B; ++ly)
        for (int64_t lx = 0; lx < B; ++lx) {
          const size_t i = size_t(lx + (ly << sh) + (lz << (2 * sh)));
          const int64_t x = (bx << sh) + lx, y = (by << sh) + ly, z = (bz << sh) + lz;
          if (x >= src.dims[0] || y >= src.dims[1] || z >= src.dims[2]) {
            s->c[i] = float(kInf);
            continue;
          }
          const float c = s->c[i];
          if (!(c >= 0))
            throw DataError("block search: node cost " + std::to_string(c) + " at voxel " + voxelText({x, y, z}) +
                            " is " + (std::isnan(c) ? "NaN" : "negative") + " (costs must be >= 0)");
        }
    p = s;
    touched.push_back(b);
    ++stats.blocksTouched;
    stats.blockBytes += int64_t(n) * 13;
    return s;
  }

  void releaseAll() {
    for (int64_t b : touched) {
      freeSlabs.push_back(dir[size_t(b)]);
      dir[size_t(b)] = nullptr;
    }
    touched.clear();
  }

  std::vector<Path> run(const std::array<int64_t, 3>& source, std::span<const std::array<int64_t, 3>> targets,
                        Progress& progress) {
    auto check = [&](const std::array<int64_t, 3>& p, const char* what) {
      for (int a = 0; a < 3; ++a)
        if (p[a] < 0 || p[a] >= src.dims[a])
          throw InvalidArgument(std::string(what) + " voxel " + voxelText(p) + " is outside the grid " +
                                std::to_string(src.dims[0]) + "x" + std::to_string(src.dims[1]) + "x" +
                                std::to_string(src.dims[2]));
    };
    check(source, "source");
    for (const auto& t : targets) check(t, "target");
    releaseAll();
    stats = {};
    // Heuristic: cmin (slightly lowered so float64 rounding keeps it below the true remaining
    // cost) times the Euclidean mm distance to the nearest target; 0 = Dijkstra.
    const double cmin = src.minCost * (1 - 1e-9);
    std::vector<std::array<double, 3>> tmm;
    for (const auto& t : targets)
      tmm.push_back({double(t[0]) * src.spacing[0], double(t[1]) * src.spacing[1], double(t[2]) * src.spacing[2]});
    auto h = [&](const std::array<int64_t, 3>& p) {
      if (cmin <= 0 || tmm.empty()) return 0.0;
      const double x = double(p[0]) * src.spacing[0], y = double(p[1]) * src.spacing[1],
                   z = double(p[2]) * src.spacing[2];
      double best = kInf;
      for (const auto& q : tmm) {
        const double a = x - q[0], b = y - q[1], c = z - q[2];
        best = std::min(best, a * a + b * b + c * c);
      }
      return cmin * std::sqrt(best);
    };
    std::vector<uint64_t> tid;
    for (const auto& t : targets) tid.push_back(idOf(t));
    std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> q;
    const uint64_t sid = idOf(source);
    {
      Slab* s = slab(int64_t(sid >> (3 * sh)));
      const size_t l = size_t(sid & localMask);
      if (!std::isfinite(s->c[l]))
        throw InvalidArgument("source voxel " + voxelText(source) + " is impassable (cost +inf)");
      s->t[l] = 0;
      q.push({h(source), sid});
    }
    auto settledT = [&](uint64_t id) -> bool {
      Slab* s = dir[size_t(id >> (3 * sh))];
      return s && (s->s[size_t(id & localMask)] & kSettled);
    };
    size_t remaining = 0;
    for (uint64_t t : tid) remaining += settledT(t) ? 0 : 1;
    int64_t pops = 0;
    const int64_t Bm = B - 1;
    while (remaining > 0 && !q.empty()) {
      stats.peakQueue = std::max<int64_t>(stats.peakQueue, int64_t(q.size()));
      const Entry e = q.top();
      q.pop();
      const int64_t b = int64_t(e.id >> (3 * sh));
      Slab* s = dir[size_t(b)];
      const int64_t l = int64_t(e.id & localMask);
      if (s->s[size_t(l)] & kSettled) continue;
      s->s[size_t(l)] |= kSettled;
      ++stats.settled;
      if (++pops >= 65536) {
        pops = 0;
        progress.report(double(tid.size() - remaining) / double(std::max<size_t>(1, tid.size())), "search");
      }
      for (uint64_t t : tid)
        if (t == e.id) --remaining;  // (duplicate targets count once each)
      const double Tu = s->t[size_t(l)];
      const double cu = s->c[size_t(l)];
      const int64_t lx = l & Bm, ly = (l >> sh) & Bm, lz = l >> (2 * sh);
      const bool inner = lx > 0 && ly > 0 && lz > 0 && lx < Bm && ly < Bm && lz < Bm;
      const std::array<int64_t, 3> pu = coordsOf(e.id);
      for (int k = 0; k < 26; ++k) {
        Slab* sv;
        int64_t lv;
        uint64_t vid;
        if (inner) {
          sv = s;
          lv = l + localOff[k];
          vid = (uint64_t(b) << (3 * sh)) | uint64_t(lv);
        } else {
          const int64_t x = pu[0] + off[k][0], y = pu[1] + off[k][1], z = pu[2] + off[k][2];
          if (x < 0 || y < 0 || z < 0 || x >= src.dims[0] || y >= src.dims[1] || z >= src.dims[2]) continue;
          vid = idOf({x, y, z});
          sv = slab(int64_t(vid >> (3 * sh)));
          lv = int64_t(vid & localMask);
        }
        const double nt = Tu + halfLen[k] * (cu + double(sv->c[size_t(lv)]));
        if (nt < sv->t[size_t(lv)]) {
          if (sv->s[size_t(lv)] & kSettled)  // re-opened (float64 rounding of h): a target counts again
            for (uint64_t t : tid) remaining += t == vid;
          sv->t[size_t(lv)] = nt;
          sv->s[size_t(lv)] = uint8_t(25 - k);  // back direction (opposite of k); clears settled: re-opened
          q.push({nt + h({pu[0] + off[k][0], pu[1] + off[k][1], pu[2] + off[k][2]}), vid});
        }
      }
    }
    std::vector<Path> out;
    out.reserve(tid.size());
    for (size_t i = 0; i < tid.size(); ++i) out.push_back(path(tid[i]));
    return out;
  }

  Path path(uint64_t id) const {
    Path p;
    Slab* s = dir[size_t(id >> (3 * sh))];
    if (!s) return p;
    const size_t l0 = size_t(id & localMask);
    if (!(s->s[l0] & kSettled) || !(s->t[l0] < kInf)) return p;
    p.cost = s->t[l0];
    std::array<int64_t, 3> v = coordsOf(id);
    for (;;) {
      p.voxels.push_back(v);
      p.nodes.push_back(v[0] + src.dims[0] * (v[1] + src.dims[1] * v[2]));
      const uint64_t vid = idOf(v);
      const Slab* sv = dir[size_t(vid >> (3 * sh))];
      const int d = sv->s[size_t(vid & localMask)] & kDir;
      if (d == kNone) break;
      if (p.voxels.size() > size_t(stats.settled) + 1) throw Error("block search: back pointers form a cycle");
      p.lengthMm += len[size_t(d)];
      v = {v[0] + off[size_t(d)][0], v[1] + off[size_t(d)][1], v[2] + off[size_t(d)][2]};
    }
    std::reverse(p.voxels.begin(), p.voxels.end());
    std::reverse(p.nodes.begin(), p.nodes.end());
    return p;
  }
};

BlockSearch::BlockSearch(BlockCostSource source) : impl_(std::make_unique<Impl>(std::move(source))) {}
BlockSearch::~BlockSearch() = default;
BlockSearch::BlockSearch(BlockSearch&&) noexcept = default;
BlockSearch& BlockSearch::operator=(BlockSearch&&) noexcept = default;

std::vector<Path> BlockSearch::findPaths(const std::array<int64_t, 3>& source,
                                         std::span<const std::array<int64_t, 3>> targets, Progress& progress) {
  return impl_->run(source, targets, progress);
}

Path BlockSearch::findPath(const std::array<int64_t, 3>& source, const std::array<int64_t, 3>& target,
                           Progress& progress) {
  const std::array<int64_t, 3> t[1] = {target};
  return impl_->run(source, t, progress).front();
}

const BlockSearchStats& BlockSearch::stats() const { return impl_->stats; }

}  // namespace vs
