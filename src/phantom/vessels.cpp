// Vessel-tree phantom: a binary tree of curved, tapered tubes grown in world mm by
// rejection sampling, then rendered with partial-volume edges and Gaussian noise.
#include <Eigen/Geometry>
#include <algorithm>
#include <atomic>
#include <cmath>

#include "phantom/phantom.h"
#include "phantom/phantom_internal.h"
#include "util/error.h"
#include "util/parallel.h"

namespace vs {

using namespace phantom_detail;

namespace {

struct Params {
  Vec3 spacing{1, 1, 1};
  Vec3 extent{0, 0, 0};  // mm, centre of first to centre of last voxel
  double unit = 1;       // mm per radius unit (largest spacing)
  double rootR = 5, minR = 1;
  double pad = 2;         // extra distance between a tube surface and the volume border, mm
  double gap = 2;         // clearance between surfaces of non-adjacent branches, mm
  double step = 0.5;      // centerline sampling, mm
  double baseLen = 40;    // root branch length, mm
  double kappa = 0.02;    // typical curvature, 1/mm
  double corrLen = 15;    // curvature correlation length, mm
  double influence = 15;  // distance from the border where steering away starts, mm
  double repel = 0.2;
  int rootAxis = 2;
  double angleMin = 25, angleMax = 50;  // degrees, daughter to parent direction
};

struct Branch {
  int parent = -1;
  int depth = 0;
  std::vector<int> children;
  std::vector<Vec3> pts;  // world mm
  std::vector<double> r;  // mm
  std::vector<double> arc;
  Vec3 lo{0, 0, 0}, hi{0, 0, 0};  // bounding box of the points
  void finish() {
    lo = hi = pts.front();
    for (const Vec3& p : pts) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
};

bool insideBox(const Params& P, const Vec3& p, double r) {
  for (int i = 0; i < 3; ++i)
    if (p[i] < r + P.pad || p[i] > P.extent[i] - r - P.pad) return false;
  return true;
}

Vec3 randomPerpendicular(PhantomRng& rng, const Vec3& d) {
  for (;;) {
    Vec3 g(rng.normal(), rng.normal(), rng.normal());
    g -= g.dot(d) * d;
    if (g.norm() > 1e-6) return g.normalized();
  }
}

Vec3 snapToVoxel(const Params& P, const Vec3& p) {
  Vec3 out;
  for (int i = 0; i < 3; ++i) out[i] = std::round(p[i] / P.spacing[i]) * P.spacing[i];
  return out;
}

// Grows one curved tapered tube from p0 along d0. `snapEnd`: move the last point onto
// the nearest voxel centre (terminal voxels lie exactly on the centerline).
Branch grow(PhantomRng& rng, const Params& P, const Vec3& p0, const Vec3& d0, double r0, double r1, double length,
            bool snapEnd) {
  Branch b;
  const int n = std::max(2, static_cast<int>(std::ceil(length / P.step)));
  const double alpha = std::exp(-P.step / P.corrLen);
  const double beta = std::sqrt(1 - alpha * alpha);
  Vec3 p = p0, d = d0.normalized(), w = Vec3::Zero();
  b.pts.push_back(p);
  b.r.push_back(r0);
  b.arc.push_back(0);
  for (int k = 1; k <= n; ++k) {
    const double r = r0 + (r1 - r0) * k / n;
    Vec3 g(rng.normal(), rng.normal(), rng.normal());
    w = alpha * w + beta * P.kappa * g;
    w -= w.dot(d) * d;
    Vec3 rep = Vec3::Zero();
    for (int i = 0; i < 3; ++i) {
      const double low = p[i] - (r + P.pad), high = P.extent[i] - r - P.pad - p[i];
      if (low < P.influence) rep[i] += (P.influence - std::max(low, 0.0)) / P.influence;
      if (high < P.influence) rep[i] -= (P.influence - std::max(high, 0.0)) / P.influence;
    }
    d = (d + P.step * (w + P.repel * rep)).normalized();
    p += P.step * d;
    b.pts.push_back(p);
    b.r.push_back(r);
    b.arc.push_back(b.arc.back() + P.step);
  }
  if (snapEnd) b.pts.back() = snapToVoxel(P, b.pts.back());
  b.finish();
  return b;
}

bool insideVolume(const Params& P, const Branch& b) {
  for (size_t i = 0; i < b.pts.size(); ++i)
    if (!insideBox(P, b.pts[i], b.r[i])) return false;
  return true;
}

// Candidate c against an existing branch b. Adjacent branches (parent, sibling) share
// the junction at c's start: points of c closer than `skip` (arc length) to it are not checked.
bool separated(const Params& P, const Branch& c, const Branch& b, bool adjacent) {
  double rmax = 0;
  for (double r : c.r) rmax = std::max(rmax, r);
  for (double r : b.r) rmax = std::max(rmax, r);
  const double reach = 2 * rmax + P.gap;
  for (int i = 0; i < 3; ++i)
    if (c.lo[i] > b.hi[i] + reach || b.lo[i] > c.hi[i] + reach) return true;
  const double skip = adjacent ? 2.5 * (c.r.front() + std::max(b.r.front(), b.r.back()) + P.gap) : -1.0;
  for (size_t i = 0; i < c.pts.size(); ++i) {
    if (c.arc[i] < skip) continue;
    for (size_t j = 0; j < b.pts.size(); ++j) {
      const double need = c.r[i] + b.r[j] + P.gap;
      if ((c.pts[i] - b.pts[j]).squaredNorm() < need * need) return false;
    }
  }
  return true;
}

// Topology: split the shallowest leaf (random among ties) until there are `terminals`.
std::vector<Branch> planTopology(PhantomRng& rng, int terminals) {
  std::vector<Branch> t(1);
  std::vector<int> leaves{0};
  while (static_cast<int>(leaves.size()) < terminals) {
    int minDepth = 1 << 30;
    for (int l : leaves) minDepth = std::min(minDepth, t[static_cast<size_t>(l)].depth);
    std::vector<int> cands;
    for (size_t i = 0; i < leaves.size(); ++i)
      if (t[static_cast<size_t>(leaves[i])].depth == minDepth) cands.push_back(static_cast<int>(i));
    const int pick = cands[static_cast<size_t>(rng.integer(0, static_cast<int64_t>(cands.size()) - 1))];
    const int node = leaves[static_cast<size_t>(pick)];
    leaves.erase(leaves.begin() + pick);
    for (int c = 0; c < 2; ++c) {
      Branch b;
      b.parent = node;
      b.depth = t[static_cast<size_t>(node)].depth + 1;
      t.push_back(b);
      t[static_cast<size_t>(node)].children.push_back(static_cast<int>(t.size()) - 1);
      leaves.push_back(static_cast<int>(t.size()) - 1);
    }
  }
  return t;
}

// One attempt at the whole tree; false if some branch could not be placed.
bool growTree(PhantomRng& rng, const Params& P, std::vector<Branch>& t, const Progress& progress) {
  constexpr int kBranchAttempts = 25;
  std::vector<Vec3> splitAxis(t.size(), Vec3::Zero());  // u of the first child, per parent
  for (size_t id = 0; id < t.size(); ++id) {
    progress.check();
    Branch& node = t[id];
    const bool leaf = node.children.empty();
    bool placed = false;
    for (int attempt = 0; attempt < kBranchAttempts && !placed; ++attempt) {
      Vec3 p0, d0;
      double r0;
      if (node.parent < 0) {
        Vec3 c;
        for (int i = 0; i < 3; ++i) c[i] = P.extent[i] * (0.5 + rng.uniform(-0.1, 0.1));
        c[P.rootAxis] = P.rootR + P.pad + P.unit;
        p0 = snapToVoxel(P, c);
        if (p0[P.rootAxis] < P.rootR + P.pad) p0[P.rootAxis] += P.spacing[P.rootAxis];
        Vec3 axis = Vec3::Zero();
        axis[P.rootAxis] = 1;
        const double tilt = rng.uniform(0.0, 0.25);
        d0 = std::cos(tilt) * axis + std::sin(tilt) * randomPerpendicular(rng, axis);
        r0 = P.rootR;
      } else {
        const Branch& par = t[static_cast<size_t>(node.parent)];
        p0 = par.pts.back();
        const Vec3 d = (par.pts.back() - par.pts[par.pts.size() - 2]).normalized();
        const bool first = par.children.front() == static_cast<int>(id);
        Vec3 u;
        if (first) {
          u = randomPerpendicular(rng, d);
          splitAxis[static_cast<size_t>(node.parent)] = u;
        } else {  // opposite side of the first child, rotated by up to ~35 degrees about d
          const Vec3 u1 = splitAxis[static_cast<size_t>(node.parent)];
          const double phi = rng.uniform(-0.6, 0.6);
          u = -(std::cos(phi) * u1 + std::sin(phi) * d.cross(u1));
        }
        const double theta = rng.uniform(P.angleMin, P.angleMax) * M_PI / 180.0;
        d0 = std::cos(theta) * d + std::sin(theta) * u;
        r0 = std::max(P.minR, par.r.back() * rng.uniform(0.78, 0.92));
      }
      const double r1 = std::max(P.minR, r0 * (leaf ? 0.75 : 0.88));
      const double minLen = 3.5 * (2 * r0 + P.gap);
      const double len = std::max(minLen, P.baseLen * std::pow(0.75, node.depth) * rng.uniform(0.85, 1.15));
      Branch cand = grow(rng, P, p0, d0, r0, r1, len, leaf);
      if (!insideVolume(P, cand)) continue;
      bool ok = true;
      for (size_t other = 0; other < id && ok; ++other) {
        const Branch& b = t[other];
        const bool adjacent = static_cast<int>(other) == node.parent || (node.parent >= 0 && b.parent == node.parent);
        ok = separated(P, cand, b, adjacent);
      }
      if (!ok) continue;
      node.pts = std::move(cand.pts);
      node.r = std::move(cand.r);
      node.arc = std::move(cand.arc);
      node.lo = cand.lo;
      node.hi = cand.hi;
      placed = true;
    }
    if (!placed) return false;
  }
  return true;
}

void validate(const VesselPhantomOptions& o) {
  requireDims(o.dims, 24, 24, "vessel phantom");
  requireSpacing(o.spacing, "vessel phantom");
  requireFiniteIn(o.noiseSigma, 0, 1000, "vessel phantom: noise sigma");
  requireFiniteIn(o.background, 0, 255, "vessel phantom: background");
  requireFiniteIn(o.foreground, 0, 255, "vessel phantom: foreground");
  requireFiniteIn(o.minRadius, 0.5, 20, "vessel phantom: min radius");
  requireFiniteIn(o.rootRadius, o.minRadius, 20, "vessel phantom: root radius");
  requireFiniteIn(o.contrastFalloff, 0, 0.99, "vessel phantom: contrast falloff");
  requireFiniteIn(o.branchAngleMinDeg, 0, 89, "vessel phantom: smallest branch angle");
  requireFiniteIn(o.branchAngleMaxDeg, o.branchAngleMinDeg, 89, "vessel phantom: largest branch angle");
  if (o.minTerminals < 1 || o.maxTerminals < o.minTerminals || o.maxTerminals > 64)
    throw InvalidArgument("vessel phantom: need 1 <= min terminals <= max terminals <= 64");
}

Params paramsOf(const VesselPhantomOptions& o) {
  Params P;
  P.spacing = o.spacing;
  for (int i = 0; i < 3; ++i) P.extent[i] = static_cast<double>(o.dims[i] - 1) * o.spacing[i];
  P.unit = o.spacing.maxCoeff();
  const double eMin = P.extent.minCoeff();
  P.rootR = std::min(o.rootRadius * P.unit, eMin / 20.0);
  P.minR = std::min(o.minRadius * P.unit, P.rootR);
  P.pad = 2 * P.unit;
  P.gap = 2 * P.unit;
  P.step = 0.5 * o.spacing.minCoeff();
  P.rootAxis = 2;
  P.angleMin = o.branchAngleMinDeg;
  P.angleMax = o.branchAngleMaxDeg;
  for (int i : {1, 0})
    if (P.extent[i] > P.extent[P.rootAxis] * 1.01) P.rootAxis = i;
  const double eMean = std::cbrt(P.extent[0] * P.extent[1] * P.extent[2]);
  P.baseLen = std::min(0.3 * eMean, 0.45 * P.extent[P.rootAxis]);
  P.kappa = 0.8 / P.baseLen;
  P.corrLen = 0.4 * P.baseLen;
  P.influence = std::max(0.12 * eMin, 3 * P.unit);
  P.repel = 3.0 / P.influence;
  return P;
}

// Draws the number of terminals and re-draws until every branch fits.
std::vector<Branch> buildTree(const VesselPhantomOptions& o, const Params& P, const Geometry& geom,
                              Progress& progress) {
  PhantomRng rng(PhantomRng::derive(o.seed, 1));
  int terminals = static_cast<int>(rng.integer(o.minTerminals, o.maxTerminals));
  std::vector<Branch> tree;
  constexpr int kTreeAttempts = 40;
  bool ok = false;
  while (!ok) {
    for (int attempt = 0; attempt < kTreeAttempts && !ok; ++attempt) {
      tree = planTopology(rng, terminals);
      ok = growTree(rng, P, tree, progress);
    }
    if (!ok) {
      if (terminals == 1)
        throw DataError("vessel phantom: no tree fits in a " + geom.describe() + " volume; use a larger size");
      --terminals;
    }
  }
  return tree;
}

// Max partial-volume coverage of one tube segment over the voxels of the box [boxLo, boxHi]
// (inclusive), written into cov (box-local, x fastest).
void renderSegment(const Params& P, const Vec3& s, const Vec3& a, const Vec3& e, double ra, double rb,
                   const Index3& boxLo, const Index3& boxHi, float* cov, float* contrast = nullptr, double c0 = 1,
                   double c1 = 1) {
  const double reach = std::max(ra, rb) + P.unit;
  int64_t lo[3], hi[3];
  for (int i = 0; i < 3; ++i) {
    lo[i] = std::max<int64_t>(boxLo[i], static_cast<int64_t>(std::floor((std::min(a[i], e[i]) - reach) / s[i])));
    hi[i] = std::min<int64_t>(boxHi[i], static_cast<int64_t>(std::ceil((std::max(a[i], e[i]) + reach) / s[i])));
  }
  const int64_t nx = boxHi[0] - boxLo[0] + 1, ny = boxHi[1] - boxLo[1] + 1;
  const Vec3 ab = e - a;
  const double ab2 = std::max(ab.squaredNorm(), 1e-18);
  for (int64_t z = lo[2]; z <= hi[2]; ++z)
    for (int64_t y = lo[1]; y <= hi[1]; ++y)
      for (int64_t x = lo[0]; x <= hi[0]; ++x) {
        const Vec3 p(static_cast<double>(x) * s[0], static_cast<double>(y) * s[1], static_cast<double>(z) * s[2]);
        const double t = std::clamp((p - a).dot(ab) / ab2, 0.0, 1.0);
        const Vec3 dv = p - (a + t * ab);
        const double d = dv.norm();
        const double sd = d - (ra + t * (rb - ra));
        if (sd > P.unit) continue;
        const Vec3 n = d > 1e-12 ? Vec3(dv / d) : Vec3(1, 0, 0);
        const float c = static_cast<float>(coverage(sd, voxelExtentAlong(n, s)));
        float& dst = cov[static_cast<size_t>((x - boxLo[0]) + nx * ((y - boxLo[1]) + ny * (z - boxLo[2])))];
        if (contrast && c > dst)
          contrast[static_cast<size_t>((x - boxLo[0]) + nx * ((y - boxLo[1]) + ny * (z - boxLo[2])))] =
              static_cast<float>(c0 + t * (c1 - c0));
        dst = std::max(dst, c);
      }
}

VesselTruth truthOf(const VesselPhantomOptions& o, const Params& P, const std::vector<Branch>& tree) {
  VesselTruth T;
  const Vec3& s = o.spacing;
  T.seed = o.seed;
  T.dims = o.dims;
  T.spacing = o.spacing;
  T.background = o.background;
  T.foreground = o.foreground;
  T.noiseSigma = o.noiseSigma;
  T.iso = 0.5 * (o.background + o.foreground);
  T.radiusUnitMm = P.unit;
  T.clearanceMm = P.gap - P.step;  // point sampling of the centerline loses at most one step
  for (const Branch& b : tree) {
    VesselBranch vb;
    vb.parent = b.parent;
    vb.children = b.children;
    vb.depth = b.depth;
    for (const Vec3& p : b.pts) vb.points.push_back(p.cwiseQuotient(s));
    vb.radiiMm = b.r;
    T.branches.push_back(std::move(vb));
  }
  phantom_detail::addRootTerminalsAndBranchPoints(T);
  return T;
}

// Counter-based standard normals for voxels 2j and 2j+1 (one splitmix64 draw of pair j split
// into two 32-bit uniforms, Box-Muller's cosine and sine): any chunk can be rendered on its own,
// and the transcendental work is halved.
std::pair<double, double> pairNormal(uint64_t seed, uint64_t j) {
  const uint64_t a = PhantomRng::derive(seed, j);
  const double u1 = (double(a >> 32) + 0.5) * 0x1.0p-32, u2 = double(a & 0xffffffffu) * 0x1.0p-32;
  const double r = std::sqrt(-2.0 * std::log(u1)), t = 6.283185307179586 * u2;
  return {r * std::cos(t), r * std::sin(t)};
}

}  // namespace

VesselPhantom makeVesselPhantom(const VesselPhantomOptions& o, Progress& progress) {
  validate(o);
  Geometry geom;
  geom.dims = o.dims;
  geom.spacing = o.spacing;
  checkAllocation(o.dims, sizeof(uint8_t) + sizeof(float), "vessel phantom");
  const Params P = paramsOf(o);
  const std::vector<Branch> tree = buildTree(o, P, geom, progress);
  progress.report(0.2, "phantom tree");

  // --- render: max partial-volume coverage over all tube segments ----------------
  std::vector<float> cov(static_cast<size_t>(geom.voxelCount()), 0.0f);
  // Contrast falloff: the relative contrast of the segment that covers a voxel most.
  const bool fading = o.contrastFalloff > 0;
  std::vector<float> contrast(fading ? cov.size() : 0, 1.0f);
  std::vector<double> arcStart(tree.size(), 0.0);  // path length from the root to a branch's start
  double maxArc = 0;
  for (size_t bi = 0; bi < tree.size(); ++bi) {  // parents come before their children
    if (tree[bi].parent >= 0)
      arcStart[bi] =
          arcStart[static_cast<size_t>(tree[bi].parent)] + tree[static_cast<size_t>(tree[bi].parent)].arc.back();
    maxArc = std::max(maxArc, arcStart[bi] + tree[bi].arc.back());
  }
  auto contrastAt = [&](size_t bi, double arc) {
    return 1.0 - o.contrastFalloff * (arcStart[bi] + arc) / std::max(maxArc, 1e-9);
  };
  const Vec3& s = o.spacing;
  const Index3 boxHi{o.dims[0] - 1, o.dims[1] - 1, o.dims[2] - 1};
  for (size_t bi = 0; bi < tree.size(); ++bi) {
    const Branch& b = tree[bi];
    progress.report(0.2 + 0.5 * static_cast<double>(bi) / static_cast<double>(tree.size()), "phantom render");
    for (size_t k = 0; k + 1 < b.pts.size(); ++k)
      renderSegment(P, s, b.pts[k], b.pts[k + 1], b.r[k], b.r[k + 1], {0, 0, 0}, boxHi, cov.data(),
                    fading ? contrast.data() : nullptr, contrastAt(bi, b.arc[k]), contrastAt(bi, b.arc[k + 1]));
  }

  VesselPhantom out;
  out.volume = VolumeU8(geom, 0);
  PhantomRng noise(PhantomRng::derive(o.seed, 2));
  const int64_t slice = o.dims[0] * o.dims[1];
  uint8_t* vox = out.volume.data();
  for (int64_t z = 0; z < o.dims[2]; ++z) {
    if ((z & 7) == 0)
      progress.report(0.7 + 0.3 * static_cast<double>(z) / static_cast<double>(o.dims[2]), "phantom noise");
    for (int64_t i = z * slice; i < (z + 1) * slice; ++i) {
      double v = o.background + (o.foreground - o.background) * cov[static_cast<size_t>(i)] *
                                    (fading ? contrast[static_cast<size_t>(i)] : 1.0f);
      if (o.noiseSigma > 0) v += o.noiseSigma * noise.normal();
      vox[i] = static_cast<uint8_t>(std::lround(std::clamp(v, 0.0, 255.0)));
    }
  }
  out.truth = truthOf(o, P, tree);
  progress.report(1.0, "phantom");
  return out;
}

VesselTruth makeVesselPhantomChunked(const VesselPhantomOptions& o, int chunk, const VesselChunkSink& sink,
                                     Progress& progress) {
  validate(o);
  if (o.contrastFalloff > 0)
    throw InvalidArgument("vessel phantom: the chunked writer renders no contrast falloff (use makeVesselPhantom)");
  if (chunk < 4 || chunk > 1024)
    throw InvalidArgument("vessel phantom: chunk size " + std::to_string(chunk) + " outside 4..1024");
  Geometry geom;
  geom.dims = o.dims;
  geom.spacing = o.spacing;
  const Params P = paramsOf(o);
  const std::vector<Branch> tree = buildTree(o, P, geom, progress);
  progress.report(0.05, "phantom tree");
  const Vec3& s = o.spacing;
  const Index3 grid{(o.dims[0] + chunk - 1) / chunk, (o.dims[1] + chunk - 1) / chunk, (o.dims[2] + chunk - 1) / chunk};
  // Segments binned by the chunks their reach box overlaps.
  struct Seg {
    int b;
    int k;
  };
  std::vector<std::vector<Seg>> bins(static_cast<size_t>(grid[0] * grid[1] * grid[2]));
  for (size_t bi = 0; bi < tree.size(); ++bi) {
    const Branch& b = tree[bi];
    for (size_t k = 0; k + 1 < b.pts.size(); ++k) {
      const Vec3 a = b.pts[k], e = b.pts[k + 1];
      const double reach = std::max(b.r[k], b.r[k + 1]) + P.unit;
      int64_t lo[3], hi[3];
      for (int i = 0; i < 3; ++i) {
        lo[i] = std::clamp<int64_t>(static_cast<int64_t>(std::floor((std::min(a[i], e[i]) - reach) / s[i])), 0,
                                    o.dims[i] - 1) /
                chunk;
        hi[i] = std::clamp<int64_t>(static_cast<int64_t>(std::ceil((std::max(a[i], e[i]) + reach) / s[i])), 0,
                                    o.dims[i] - 1) /
                chunk;
      }
      for (int64_t z = lo[2]; z <= hi[2]; ++z)
        for (int64_t y = lo[1]; y <= hi[1]; ++y)
          for (int64_t x = lo[0]; x <= hi[0]; ++x)
            bins[static_cast<size_t>(x + grid[0] * (y + grid[1] * z))].push_back({int(bi), int(k)});
    }
  }
  const uint64_t noiseSeed = PhantomRng::derive(o.seed, 3);
  const int64_t total = grid[0] * grid[1] * grid[2];
  std::atomic<int64_t> done{0};
  parallelFor(
      0, total,
      [&](int64_t c0, int64_t c1) {
        const size_t n = size_t(chunk) * size_t(chunk) * size_t(chunk);
        std::vector<float> cov(n), vox(n);
        for (int64_t ci = c0; ci < c1; ++ci) {
          const Index3 c{ci % grid[0], (ci / grid[0]) % grid[1], ci / (grid[0] * grid[1])};
          const Index3 lo{c[0] * chunk, c[1] * chunk, c[2] * chunk};
          const Index3 hi{lo[0] + chunk - 1, lo[1] + chunk - 1, lo[2] + chunk - 1};
          const std::vector<Seg>& bin = bins[static_cast<size_t>(ci)];
          if (!bin.empty()) std::fill(cov.begin(), cov.end(), 0.0f);
          for (const Seg& sg : bin) {
            const Branch& b = tree[size_t(sg.b)];
            renderSegment(P, s, b.pts[size_t(sg.k)], b.pts[size_t(sg.k) + 1], b.r[size_t(sg.k)], b.r[size_t(sg.k) + 1],
                          lo, hi, cov.data());
          }
          const double fg = o.foreground - o.background;
          for (int64_t z = 0; z < chunk; ++z)
            for (int64_t y = 0; y < chunk; ++y) {
              const size_t row = static_cast<size_t>(chunk * (y + chunk * z));
              const uint64_t g0 = static_cast<uint64_t>(geom.linear(lo[0], lo[1] + y, lo[2] + z));
              // Noise pair j covers voxels 2j, 2j+1 of the volume's linear index (a row starting
              // on an odd index takes its first voxel from the previous pair's sine).
              for (int64_t x = 0; x < chunk;) {
                const uint64_t i = g0 + static_cast<uint64_t>(x);
                double n0 = 0, n1 = 0;
                if (o.noiseSigma > 0) std::tie(n0, n1) = pairNormal(noiseSeed, i >> 1);
                const int take = (i & 1) ? 1 : int(std::min<int64_t>(2, chunk - x));
                for (int k = 0; k < take; ++k, ++x) {
                  double v = o.background + (bin.empty() ? 0.0 : fg * cov[row + size_t(x)]);
                  v += o.noiseSigma * (((i + uint64_t(k)) & 1) ? n1 : n0);
                  vox[row + size_t(x)] = std::nearbyint(static_cast<float>(std::clamp(v, 0.0, 255.0)));
                }
              }
            }
          sink(c, vox.data());
          const int64_t d = ++done;
          if ((d & 63) == 0) progress.report(0.05 + 0.95 * double(d) / double(total), "phantom chunks");
        }
      },
      1);
  progress.report(1.0, "phantom");
  return truthOf(o, P, tree);
}

CenterlineDistance distanceToCenterline(const VesselTruth& truth, const Vec3& indexPoint) {
  CenterlineDistance best;
  const Vec3 p = indexPoint.cwiseProduct(truth.spacing);
  for (size_t bi = 0; bi < truth.branches.size(); ++bi) {
    const VesselBranch& b = truth.branches[bi];
    for (size_t k = 0; k < b.points.size(); ++k) {
      const Vec3 a = b.points[k].cwiseProduct(truth.spacing);
      const Vec3 e = (k + 1 < b.points.size() ? b.points[k + 1] : b.points[k]).cwiseProduct(truth.spacing);
      const Vec3 ab = e - a;
      const double ab2 = ab.squaredNorm();
      const double t = ab2 > 0 ? std::clamp((p - a).dot(ab) / ab2, 0.0, 1.0) : 0.0;
      const Vec3 c = a + t * ab;
      const double d = (p - c).norm();
      if (d < best.distanceMm) {
        best.distanceMm = d;
        best.branch = static_cast<int>(bi);
        best.segment = static_cast<int>(std::min(k, b.points.size() >= 2 ? b.points.size() - 2 : 0));
        const double r0 = b.radiiMm.empty() ? 0 : b.radiiMm[k];
        const double r1 = b.radiiMm.empty() ? 0 : b.radiiMm[std::min(k + 1, b.radiiMm.size() - 1)];
        best.radiusMm = r0 + t * (r1 - r0);
        best.closest = c.cwiseQuotient(truth.spacing);
      }
    }
  }
  return best;
}

}  // namespace vs
