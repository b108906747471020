#include "tracking/auto_cost.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <vector>

#include "features/vesselness.h"
#include "tracking/block_filters.h"
#include "tracking/valley_cost.h"
#include "util/parallel.h"
#include "volume/neighbourhood.h"

namespace vs {

namespace {
double median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// Values of `vol` at voxels whose physical distance from `c` lies in [r0, r1] mm.
std::vector<double> ballValues(const VolumeF32& vol, const Index3& c, double r0, double r1) {
  std::vector<double> out;
  forEachVoxelNear(vol.geometry(), c, r1, [&](int64_t x, int64_t y, int64_t z, double d) {
    if (d >= r0 && d <= r1) out.push_back(vol(x, y, z));
  });
  return out;
}

// The root's lumen radius (mm): the first radius whose spherical shell (one largest spacing
// thick) has its median at least half-way from the lumen level L to the median of the shell at
// maxMm. A sphere centred in a tube of radius R has most of its surface outside the tube from
// about 1.15 R on, so this is the tube's radius within ~15 %; 0 when no shell gets there.
double rootLumenRadius(const VolumeF32& vol, const Index3& c, double lumen, double maxMm) {
  const Geometry& g = vol.geometry();
  const double width = g.spacing.maxCoeff();
  const int bins = std::max(2, static_cast<int>(std::ceil(maxMm / width)));
  std::vector<std::vector<double>> shells(static_cast<size_t>(bins));
  forEachVoxelNear(g, c, maxMm, [&](int64_t x, int64_t y, int64_t z, double d) {
    const int b = static_cast<int>(d / width);
    if (b < bins) shells[static_cast<size_t>(b)].push_back(vol(x, y, z));
  });
  if (shells.back().empty()) return 0;
  const double far = median(shells.back());
  for (int b = 1; b < bins; ++b) {
    if (shells[static_cast<size_t>(b)].empty()) continue;
    const double m = median(shells[static_cast<size_t>(b)]);
    if (std::abs(m - lumen) >= 0.5 * std::abs(far - lumen)) return b * width;
  }
  return 0;
}

// Robust noise of the intensities around `c`: 1.4826 x the median absolute difference between
// x-neighbours divided by sqrt(2) (edges are a minority of the pairs; a flat region gives the
// noise, a smoothed one its smoothed noise).
double noiseSpread(const VolumeF32& vol, const Index3& c, double radiusMm) {
  const Geometry& g = vol.geometry();
  std::vector<double> diffs;
  int64_t ext[3];
  for (int a = 0; a < 3; ++a) ext[a] = static_cast<int64_t>(std::ceil(radiusMm / g.spacing[a]));
  for (int64_t z = std::max<int64_t>(0, c[2] - ext[2]); z <= std::min(g.dims[2] - 1, c[2] + ext[2]); ++z)
    for (int64_t y = std::max<int64_t>(0, c[1] - ext[1]); y <= std::min(g.dims[1] - 1, c[1] + ext[1]); ++y)
      for (int64_t x = std::max<int64_t>(0, c[0] - ext[0]); x < std::min(g.dims[0] - 1, c[0] + ext[0]); ++x)
        diffs.push_back(std::abs(static_cast<double>(vol(x + 1, y, z)) - vol(x, y, z)));
  return diffs.empty() ? 0.0 : 1.4826 * median(diffs) / std::sqrt(2.0);
}

// The noise spread of the unsmoothed intensities over that of the smoothed ones around the root
// (>= 1; 1 without smoothing).
double unsmoothedNoiseRatio(const VolumeF32& raw, const VolumeF32& sm, const Index3& root, const AutoCostOptions& o) {
  if (&raw == &sm || o.smoothMm <= 0) return 1.0;
  const double a = noiseSpread(raw, root, o.shellOuterMm), b = noiseSpread(sm, root, o.shellOuterMm);
  return b > 0 ? std::max(1.0, a / b) : 1.0;
}

std::string fmt(const char* f, double a, double b = 0, double c = 0, double d = 0, double e = 0) {
  char buf[256];
  std::snprintf(buf, sizeof buf, f, a, b, c, d, e);
  return buf;
}

// ", rings of 1.5, 3 mm" (the ring contrast's radii), or nothing without them.
std::string ringText(const std::vector<double>& radii) {
  std::string s;
  for (size_t k = 0; k < radii.size(); ++k) s += fmt(k == 0 ? ", rings of %.3g" : ", %.3g", radii[k]);
  return radii.empty() ? s : s + " mm";
}

// ", valleys at 0.5, 1 mm" (the valley term's radii), or nothing without them.
std::string valleyText(const std::vector<RingScale>& v) {
  std::string s;
  for (size_t k = 0; k < v.size(); ++k) s += fmt(k == 0 ? ", valleys at %.3g" : ", %.3g", v[k].radiusMm);
  return v.empty() ? s : s + " mm";
}
}  // namespace

std::string LumenEstimate::describe() const {
  std::string blocks;
  for (int k = 0; k < localScales; ++k) blocks += fmt(k == 0 ? "%.3g" : ", %.3g", localBlockMm / (1 << k));
  return std::string(polarity == TubePolarity::Bright ? "bright" : "dark") +
         fmt(", lumen %.6g (spread %.3g, radius %.3g mm)", lumen, spread, rootRadiusMm) +
         fmt(", surroundings %.6g at %.3g..%.3g mm, window %.6g..%.6g", surround, shellInnerMm, shellOuterMm, windowLo,
             windowHi) +
         (wall.rays > 0
              ? fmt(", contrast beyond the wall %.3g (%.0f of %.0f rays)", wall.contrast, wall.leaving, wall.rays)
              : std::string()) +
         upperText() + fmt(", local contrast %.3g..%.3g over ", localLo, localHi) + blocks +
         fmt(" mm blocks (p%.3g", localPercentile) +
         (localTailCap > 0 ? fmt(", at most %.3g tail widths beyond the background's quartile)", localTailCap) : ")") +
         backgroundText() + ringText(ringRadiiMm) + connectText();
}

// ", background outside the root's structure (connected to it up to 124.5, 0.65 of the way to the tissue; ...)".
std::string LumenEstimate::backgroundText() const {
  if (structureFraction <= 0) return ", blocks without background take the window's far edge";
  return fmt(", background outside the root's structure (connected to it up to %.6g, %.3g of the way to the "
             "tissue; %.0f voxels with %.0f voxel(s) of wall) in blocks it fills over the percentile beside a part "
             "of it ",
             structureEdge, structureFraction, static_cast<double>(structureVoxels), structureWall) +
         fmt("%.0f voxels deep; blocks without background borrow from the nearest; the wide lumen's wall against the "
             "former background: %.0f voxel(s) around the root's window region, beyond it below the half-maximum "
             "between the lumen's level and the tissue)",
             structureDepth, wideWallVoxels);
}

// ", connected to the root: 26370 voxels (window cut from -553: 1.17e+06 voxels one step further)".
std::string LumenEstimate::connectText() const {
  if (connectSteps == 0) return "";
  std::string s = fmt(", connected to the root: %.0f voxels", static_cast<double>(connectedVoxels));
  if (spillVoxels > 0)
    s += fmt(" (window cut from %.6g: %.3g voxels one step further)", spillFrom, static_cast<double>(spillVoxels));
  return s;
}

std::string LocalContrast::describe(const LumenEstimate& e) const {
  return fmt("intensity %.6g, local surroundings %.6g (spread %.3g), contrast %.3g", intensity, background, spread,
             contrast) +
         (e.polarity == TubePolarity::Bright ? " towards the bright lumen" : " towards the dark lumen") +
         fmt(" (lumen from %.3g, full at %.3g; root noise %.3g)", lo, hi, e.spread) + ringContrastText(e);
}

std::string LocalContrast::ringContrastText(const LumenEstimate& e) const {
  std::string s;
  for (size_t k = 0; k < ringContrast.size() && k < e.ringRadiiMm.size(); ++k)
    s += fmt(k == 0 ? "; against its rings of %.3g mm: contrast %.3g" : ", %.3g mm: %.3g", e.ringRadiiMm[k],
             ringContrast[k]);
  return s;
}

std::vector<RingScale> ringScalesFor(const Geometry& g, double voxels, int scales, bool stepsAtLeast) {
  VS_REQUIRE(voxels >= 0 && std::isfinite(voxels), "auto cost: the ring radius must be >= 0 voxels");
  VS_REQUIRE(scales >= 0 && scales <= 8, "auto cost: ring scales in [0,8]");
  std::vector<RingScale> out;
  if (voxels <= 0) return out;
  static const int dirs[13][3] = {{1, 0, 0}, {0, 1, 0},  {0, 0, 1}, {1, 1, 0},  {1, -1, 0}, {1, 0, 1},  {1, 0, -1},
                                  {0, 1, 1}, {0, 1, -1}, {1, 1, 1}, {1, 1, -1}, {1, -1, 1}, {1, -1, -1}};
  for (int k = 0; k < scales; ++k) {
    RingScale r;
    r.radiusMm = voxels * (1 << k) * g.spacing.minCoeff();
    for (int j = 0; j < 13; ++j) {
      const Vec3 d(dirs[j][0], dirs[j][1], dirs[j][2]);
      int64_t n = std::max<int64_t>(1, std::lround(r.radiusMm / g.stepLength(d)));
      if (stepsAtLeast) n = std::max<int64_t>(n, std::lround(voxels * (1 << k)));
      for (int a = 0; a < 3; ++a) {
        r.offset[j][a] = n * dirs[j][a];
        r.reach[a] = std::max(r.reach[a], std::abs(r.offset[j][a]));
      }
      r.linear[j] = g.linear(r.offset[j][0], r.offset[j][1], r.offset[j][2]);
    }
    out.push_back(r);
  }
  return out;
}

double ringContrast(const VolumeF32& sm, const RingScale& r, int64_t x, int64_t y, int64_t z, bool bright,
                    double floor) {
  const Geometry& g = sm.geometry();
  const float* base = sm.data() + g.linear(x, y, z);
  const double v = *base;
  const bool inside = x >= r.reach[0] && x < g.dims[0] - r.reach[0] && y >= r.reach[1] && y < g.dims[1] - r.reach[1] &&
                      z >= r.reach[2] && z < g.dims[2] - r.reach[2];
  auto sample = [&](int j, int64_t sign) -> double {
    if (inside) return base[sign * r.linear[static_cast<size_t>(j)]];
    const Index3& o = r.offset[static_cast<size_t>(j)];
    return sm(std::clamp<int64_t>(x + sign * o[0], 0, g.dims[0] - 1),
              std::clamp<int64_t>(y + sign * o[1], 0, g.dims[1] - 1),
              std::clamp<int64_t>(z + sign * o[2], 0, g.dims[2] - 1));
  };
  double c[13];
  int low = 0;
  for (int j = 0; j < 13; ++j) {
    const double a = sample(j, 1), b = sample(j, -1);
    c[j] = bright ? v - std::max(a, b) : std::min(a, b) - v;
    if (c[j] <= floor && ++low >= 7) return -std::numeric_limits<double>::infinity();
  }
  std::nth_element(c, c + 6, c + 13);
  return c[6];
}

namespace {
// One scale of the local background (see auto_cost.h); with the root's structure, `former` gets the
// background that keeps it (the same samples, one pass).
BlockGrid blockBackground(const VolumeF32& vol, const LumenEstimate& e, double blockMm, double percentile,
                          const RootStructure* structure, BlockGrid* former, const std::vector<uint8_t>* upper,
                          const std::vector<PlainBlock>* pre) {
  const Geometry& g = vol.geometry();
  BlockGrid bg = blockGrid(g, blockMm);
  int64_t step[3];
  blockSampleSteps(bg, step);
  const bool bright = e.polarity == TubePolarity::Bright;
  const double p = bright ? 100.0 - percentile : percentile;
  // The root's window marks lumen: those voxels are not background. A block (almost) full of
  // them (inside a wide lumen) takes the window's far edge.
  const float edge = static_cast<float>(bright ? e.windowLo : e.windowHi);
  const int64_t nb = bg.blocks[0] * bg.blocks[1] * bg.blocks[2];
  std::vector<float> raw(static_cast<size_t>(nb)), rawSpread(static_cast<size_t>(nb)), rawFormer, rawLevel;
  const uint8_t* mask = structure ? structure->mask.data() : nullptr;
  const uint8_t* up = upper && e.hasUpperEdge() ? upper->data() : nullptr;
  const float hiUp = static_cast<float>(e.upperHi);
  if (former) rawFormer.resize(raw.size());
  if (former) rawLevel.assign(raw.size(), std::numeric_limits<float>::quiet_NaN());
  // Blocks that hold a part of the root's structure deep inside it or touch one that does: beside a
  // wide lumen, not between thin tubes.
  const std::vector<uint8_t> nearDeep =
      structure ? nearDeepBlocks(bg, g, structure->deep) : std::vector<uint8_t>(static_cast<size_t>(nb));
  parallelFor(
      0, nb,
      [&](int64_t b0, int64_t b1) {
        BlockSamples sample;
        std::vector<float>&vals = sample.vals, &diffs = sample.diffs, &deepVals = sample.deepVals, all;
        const std::vector<uint8_t>&valIn = sample.valIn, &diffIn = sample.diffIn;
        for (int64_t b = b0; b < b1; ++b) {
          const int64_t bi = b % bg.blocks[0], bj = (b / bg.blocks[0]) % bg.blocks[1],
                        bk = b / (bg.blocks[0] * bg.blocks[1]);
          // The structure's mask only beside a wide lumen: elsewhere the block is never heavy and holds no deep voxel.
          const uint8_t* bm = nearDeep[static_cast<size_t>(b)] ? mask : nullptr;
          if (!bm) {  // away from the structure; sampled while the connect flood ran when `pre` (BackgroundPresample)
            const PlainBlock v = pre ? (*pre)[static_cast<size_t>(b)]
                                     : plainBlock(vol, bg, b, bright, edge, up, hiUp, percentile, e.localTailCap,
                                                  e.localTailCap * e.spread, sample);
            raw[static_cast<size_t>(b)] = v.raw;
            rawSpread[static_cast<size_t>(b)] = v.spread;
            if (former) rawFormer[static_cast<size_t>(b)] = v.uncapped;
            continue;
          }
          const int64_t lo[3] = {bi * bg.blockVoxels[0], bj * bg.blockVoxels[1], bk * bg.blockVoxels[2]};
          sampleBlock(vol, lo, bg.blockVoxels.data(), step, bright, edge, up, hiUp, bm, sample);
          const size_t sampled = sample.sampled, inStructure = sample.inStructure;
          // The root's structure is left out where it fills more than p % of the block (its
          // percentile would be the structure's) beside a wide lumen: a thin vessel's block keeps its
          // partial-volume wall among its background, as before (without it the wall of a thin vessel is
          // lumen and paths cut its bends: family seed 19, docs/notes).
          const bool heavy = nearDeep[static_cast<size_t>(b)] &&
                             100.0 * static_cast<double>(inStructure) > percentile * static_cast<double>(sampled);
          if (former && !deepVals.empty()) {  // the wide lumen's level here: the median of its deep part
            const auto mid = deepVals.begin() + static_cast<std::ptrdiff_t>(deepVals.size() / 2);
            std::nth_element(deepVals.begin(), mid, deepVals.end());
            rawLevel[static_cast<size_t>(b)] = *mid;
          }
          if (former && heavy) {
            all = vals;
            rawFormer[static_cast<size_t>(b)] = blockPercentile(all, sampled, p);
          }
          if (heavy) {
            size_t kv = 0, kd = 0;
            for (size_t j = 0; j < vals.size(); ++j)
              if (!valIn[j]) vals[kv++] = vals[j];
            for (size_t j = 0; j < diffs.size(); ++j)
              if (!diffIn[j]) diffs[kd++] = diffs[j];
            vals.resize(kv);
            diffs.resize(kd);
          }
          const size_t nVals = vals.size();
          raw[static_cast<size_t>(b)] = blockPercentile(vals, sampled, p);
          if (former && !heavy) rawFormer[static_cast<size_t>(b)] = raw[static_cast<size_t>(b)];  // the same samples
          rawSpread[static_cast<size_t>(b)] = blockSpread(diffs, raw[static_cast<size_t>(b)], nVals);
        }
      },
      64);
  if (structure) {
    borrowBackground(bg, raw, edge, bright);
  } else {
    for (float& v : raw)
      if (std::isnan(v)) v = edge;
  }
  neighbourFilter(bg, raw, &rawSpread, bright);
  if (former) {
    *former = blockGrid(g, blockMm);
    for (float& v : rawFormer)
      if (std::isnan(v)) v = edge;
    neighbourFilter(*former, rawFormer, nullptr, bright);
    bg.lumenLevel = levelFilter(bg, rawLevel);
  }
  return bg;
}
}  // namespace

LocalBackground estimateLocalBackground(const VolumeF32& vol, const LumenEstimate& e, double blockMm, double percentile,
                                        int scales, RootStructure* structure, const std::vector<uint8_t>* upper,
                                        const BackgroundPresample* pre) {
  VS_REQUIRE(blockMm > 0 && std::isfinite(blockMm), "auto cost: the local block must be > 0 mm");
  VS_REQUIRE(percentile >= 0 && percentile <= 100, "auto cost: local percentile in [0,100]");
  VS_REQUIRE(scales >= 1 && scales <= 8, "auto cost: local scales in [1,8]");
  VS_REQUIRE(structure == nullptr || structure->mask.size() == static_cast<size_t>(vol.geometry().voxelCount()),
             "auto cost: the structure mask must have one entry per voxel");
  if (structure && structure->mask.empty()) structure = nullptr;
  LocalBackground bg;
  bg.polarity = e.polarity;
  // The wide lumen and its wall keep the former background (structureScales).
  const bool zone = structure && !structure->wideZone.empty();
  // The blocks sampled while the flood ran hold, unless the flood cut the window (or the options differ).
  if (pre && !pre->matches(e, blockMm, percentile, scales, upper)) pre = nullptr;
  for (int k = 0; k < scales; ++k) {
    BlockGrid former;
    bg.scales.push_back(blockBackground(vol, e, blockMm / (1 << k), percentile, structure, zone ? &former : nullptr,
                                        upper, pre ? &pre->blocks[static_cast<size_t>(k)] : nullptr));
    if (zone) bg.structureScales.push_back(std::move(former));
  }
  if (zone) {
    bg.structure = std::move(structure->wideZone);
    bg.dims = vol.geometry().dims;
  }
  for (BlockGrid& grid : bg.scales) grid.prepareRows(vol.geometry().dims[0]);
  for (size_t k = 0; k < bg.structureScales.size(); ++k) {
    BlockGrid& f = bg.structureScales[k];
    f.prepareRows(vol.geometry().dims[0]);
    markDiffers(f, bg.scales[k]);
  }
  return bg;
}

LocalContrast localContrastAt(const VolumeF32& smoothed, const LocalBackground& background, const LumenEstimate& e,
                              const Index3& v, bool withRings) {
  LocalContrast c;
  c.intensity = smoothed(v[0], v[1], v[2]);
  c.spread = background.spreadAt(v[0], v[1], v[2]);
  c.lo = e.localNoiseFloor * std::max(e.spread, c.spread);
  c.hi = std::max({2 * c.lo, e.localHi, c.lo + e.spread});
  c.background = background.at(v[0], v[1], v[2], c.intensity);
  c.contrast = e.polarity == TubePolarity::Bright ? c.intensity - c.background : c.background - c.intensity;
  if (withRings)
    for (const RingScale& r : background.rings)
      c.ringContrast.push_back(ringContrast(smoothed, r, v[0], v[1], v[2], e.polarity == TubePolarity::Bright));
  return c;
}

LumenEstimate estimateLumen(const VolumeF32& vol, const Index3& root, const AutoCostOptions& o) {
  const Geometry& g = vol.geometry();
  if (!g.contains(root))
    throw InvalidArgument("auto cost: root (" + std::to_string(root[0]) + "," + std::to_string(root[1]) + "," +
                          std::to_string(root[2]) + ") is outside the volume " + g.describe());
  VS_REQUIRE(o.lumenRadiusMm >= 0 && o.shellInnerMm >= 0 && o.shellOuterMm > o.shellInnerMm,
             "auto cost: need 0 <= lumen radius, 0 <= shell inner < shell outer (mm)");
  VS_REQUIRE(o.surroundPercentile >= 0 && o.surroundPercentile <= 100, "auto cost: surround percentile in [0,100]");
  VS_REQUIRE(o.windowFraction > 0 && o.windowFraction <= 1, "auto cost: window fraction in (0,1]");
  // At least the 26 neighbours, whatever the spacing.
  const double ball = std::max(o.lumenRadiusMm, g.stepLength(Vec3(1, 1, 1)));
  std::vector<double> lumenVals = ballValues(vol, root, 0, ball);
  LumenEstimate e;
  e.lumen = median(lumenVals);
  for (double& v : lumenVals) v = std::abs(v - e.lumen);
  // Both are noise estimates with an upward bias (edges inside the ball; texture between
  // neighbours), so the smaller is the better one.
  e.spread = std::min(1.4826 * median(lumenVals), noiseSpread(vol, root, o.shellOuterMm));
  // The surroundings lie outside the root's own lumen: in a wide lumen (aorta, trachea) the
  // shell starts at 1.5 x its radius instead of shellInnerMm (the aorta's own dimmer voxels were
  // its "surroundings": window 1754..1872 in a lumen of 1600-1900 against tissue of ~400).
  e.rootRadiusMm = rootLumenRadius(vol, root, e.lumen, 2 * o.shellOuterMm);
  e.shellInnerMm = std::max(o.shellInnerMm, 1.5 * e.rootRadiusMm);
  e.shellOuterMm = e.shellInnerMm + (o.shellOuterMm - o.shellInnerMm);
  std::vector<double> shell = ballValues(vol, root, e.shellInnerMm, e.shellOuterMm);
  const auto noContrast = [&](const std::string& why) {
    return DataError("auto cost: no contrast around the root (" + why + "; lumen " + fmt("%.6g", e.lumen) +
                     "): give --cost intensity with --polarity bright|dark and --window lo,hi, or another --cost");
  };
  if (shell.empty()) throw noContrast("no voxel in the surroundings");
  const double shellMedian = median(shell);
  e.shellMedian = shellMedian;
  e.polarity = shellMedian > e.lumen ? TubePolarity::Dark : TubePolarity::Bright;
  const double dir = e.polarity == TubePolarity::Dark ? 1.0 : -1.0;  // from the lumen towards the surroundings
  const double tiny = 1e-6 * std::max(1.0, std::abs(e.lumen));
  const double minSep = std::max(3.0 * e.spread, 0.05 * std::abs(shellMedian - e.lumen));
  size_t counted = 0;  // how many voxels surroundOf's last call counted beyond the lumen
  const auto surroundOf = [&](const std::vector<double>& values) {  // the percentile of those beyond the lumen
    std::vector<double> beyond;  // signed distance from the lumen towards the surroundings
    for (double v : values)
      if (dir * (v - e.lumen) > std::max(minSep, tiny)) beyond.push_back(dir * (v - e.lumen));
    counted = beyond.size();
    if (beyond.empty()) return -1.0;
    const auto k = static_cast<std::ptrdiff_t>(o.surroundPercentile / 100.0 * static_cast<double>(beyond.size() - 1));
    std::nth_element(beyond.begin(), beyond.begin() + k, beyond.end());
    return beyond[static_cast<size_t>(k)];
  };
  double contrast = surroundOf(shell);
  if (contrast < 0) throw noContrast("the surroundings hold the lumen's values");
  const size_t countedAll = counted;
  if (o.wallContrast.rays > 0)
    e.wall = rootContrastBeyondWall(vol, root, e.lumen, dir, std::max(3.0 * e.spread, tiny), o.wallContrast);
  // B on the lumen's side of the half-maximum between the lumen and the surroundings beyond its wall: the shell may
  // lie in the root's own lumen (a wide trunk fading along its length: B inside the lumen, the window a few noise
  // spreads wide). B is then taken without the shell voxels the lumen reaches along straight lines from the root,
  // where those make up the percentile or more of the voxels beyond the lumen (B itself is a lumen voxel; a few
  // partial-volume voxels of the lumen's fringe, as around the trachea, leave B as it is).
  if (o.wallContrast.rays > 0 && contrast < 0.5 * e.wall.contrast) {
    std::vector<double> outside = shellOutsideLumen(vol, root, e.shellInnerMm, e.shellOuterMm, e.lumen, dir,
                                                    0.5 * e.wall.contrast, &e.shellInLumen);
    const double c = surroundOf(outside);
    const bool bInLumen =
        static_cast<double>(countedAll - counted) >= o.surroundPercentile / 100.0 * static_cast<double>(countedAll);
    e.shellInLumen = bInLumen && c > 0 ? static_cast<int64_t>(countedAll - counted) : 0;
    if (e.shellInLumen > 0) contrast = c;
  }
  e.surround = e.lumen + dir * contrast;
  // The test: the root's contrast beyond its own wall (rays; auto_cost_contrast.cpp), or |B - L| without rays.
  if (o.wallContrast.rays > 0) {
    if (e.wall.contrast <= o.minContrastToNoise * std::max(e.spread, tiny))
      throw noContrast(fmt("surroundings beyond its wall %.6g differ from the lumen by %.3g, under %.3g noise "
                           "spreads of %.3g",
                           e.wall.surround, e.wall.contrast, o.minContrastToNoise, e.spread) +
                       fmt(" (median of %.0f rays, %.0f leave the lumen within %.3g mm; the nearest surroundings "
                           "%.6g differ by %.3g)",
                           e.wall.rays, e.wall.leaving, o.wallContrast.reachMm, e.surround, contrast));
  } else if (contrast <= o.minContrastToNoise * std::max(e.spread, tiny)) {
    throw noContrast(fmt("surroundings %.6g differ from the lumen by %.3g, under %.3g noise spreads of %.3g",
                         e.surround, contrast, o.minContrastToNoise, e.spread));
  }
  const double edge = e.lumen + dir * o.windowFraction * contrast;
  e.windowLo = std::min(e.lumen, edge);
  e.windowHi = std::max(e.lumen, edge);
  VS_REQUIRE(o.localFraction > 0 && o.localFraction <= 1, "auto cost: local fraction in (0,1]");
  VS_REQUIRE(o.localNoiseFloor >= 0 && std::isfinite(o.localNoiseFloor), "auto cost: local noise floor >= 0");
  e.localLo = o.localNoiseFloor * e.spread;
  e.localHi = std::max({2 * e.localLo, e.localLo + std::max(e.spread, tiny), o.localFraction * contrast});
  e.localBlockMm = o.localBlockMm;
  e.localScales = o.localScales;
  e.localPercentile = o.localPercentile;
  VS_REQUIRE(o.localTailCap >= 0 && std::isfinite(o.localTailCap), "auto cost: the local tail cap must be >= 0");
  e.localTailCap = o.localTailCap;
  e.localFraction = o.localFraction;
  e.localNoiseFloor = o.localNoiseFloor;
  for (const RingScale& r : ringScalesFor(g, o.ringVoxels, o.ringScales)) e.ringRadiiMm.push_back(r.radiusMm);
  // The upper edge: values beyond the lumen by more than upperFraction root contrasts are less and less lumen
  // (none from 1.5 x as far): bone, calcium and metal far brighter than a contrast lumen (mirrored for dark).
  VS_REQUIRE(o.upperFraction >= 0 && std::isfinite(o.upperFraction), "auto cost: the upper edge must be >= 0");
  e.upperFraction = o.upperFraction;
  e.upperLo = e.lumen - dir * o.upperFraction * contrast;
  e.upperHi = e.lumen - dir * 1.5 * o.upperFraction * contrast;
  return e;
}

AutoCost computeAutoCost(const VolumeF32& volume, const Index3& root, const AutoCostOptions& o, Progress& progress) {
  VS_REQUIRE(o.smoothMm >= 0 && std::isfinite(o.smoothMm), "auto cost: smoothing must be >= 0 mm");
  AutoCost out;
  PhaseTimer timer;
  out.smoothed = o.smoothMm > 0 ? gaussianSmooth3D(volume, o.smoothMm, progress) : volume;
  timer.lap("smooth", out.phases);
  VS_REQUIRE(o.power > 0 && std::isfinite(o.power), "auto cost: power must be > 0");
  VS_REQUIRE(o.epsilon >= 0 && std::isfinite(o.epsilon), "auto cost: epsilon must be >= 0");
  out.estimate = estimateLumen(out.smoothed, root, o);
  timer.lap("estimate", out.phases);
  // The connected lumen and the root's structure (one flood); the voxels within structureDepth + wideWallVoxels
  // of the structure's deep part (the wide lumen and its own partial-volume wall) are measured against the
  // former background (its wall is not lumen against the tissue beyond it: 4D-CT trachea, aorta).
  RootStructure structure;
  const std::vector<uint8_t> shell =
      out.estimate.hasUpperEdge() ? upperShell(out.smoothed, out.estimate) : std::vector<uint8_t>();
  const std::vector<uint8_t>* upperVals = out.estimate.hasUpperEdge() ? &shell : nullptr;
  // The local background's blocks away from the structure need no flood: sampled on a second thread meanwhile
  // (the flood is serial), then on both.
  BackgroundPresample pre(out.smoothed, out.estimate, o.localBlockMm, o.localPercentile, o.localScales, upperVals);
  const std::vector<uint8_t> connected =
      pre.whileRunning([&] { return connectRootLumen(out.smoothed, root, out.estimate, o, &structure, upperVals); });
  const LumenEstimate& e = out.estimate;
  timer.lap("connect", out.phases);
  pre.finish();
  out.background = estimateLocalBackground(out.smoothed, e, o.localBlockMm, o.localPercentile, o.localScales,
                                           structure.mask.empty() ? nullptr : &structure, upperVals, &pre);
  timer.lap("background", out.phases);
  out.background.rings = ringScalesFor(out.smoothed.geometry(), o.ringVoxels, o.ringScales);
  out.background.valleys = ringScalesFor(out.smoothed.geometry(), o.valleyVoxels, o.valleyScales);
  // On the smoothed intensities at least 2 steps at the second scale in every direction (a neck under a slice).
  const std::vector<RingScale> smValleys = ringScalesFor(out.smoothed.geometry(), o.valleyVoxels, o.valleyScales, true);
  const Geometry& g = out.smoothed.geometry();
  NodeCost3D& nc = out.cost;
  nc.kind = CostKind3D::Intensity;
  nc.geometry = g;
  nc.node.resize(static_cast<size_t>(g.voxelCount()));
  const bool bright = e.polarity == TubePolarity::Bright, upper = e.hasUpperEdge();
  const double wLo = e.windowLo, wSpan = e.windowHi - e.windowLo;
  const double floor = e.localNoiseFloor, rootSpread = std::max(e.spread, 1e-12), hiMin = e.localHi;
  const VolumeF32& sm = out.smoothed;
  const LocalBackground& bg = out.background;
  // The valley's noise floor: valleyNoiseFloor spreads of the unsmoothed intensities it samples
  // (the spreads above are of the smoothed ones: scaled by the ratio of the two at the root).
  const double valleyFloor = bg.valleys.empty() ? 0.0 : o.valleyNoiseFloor * unsmoothedNoiseRatio(volume, sm, root, o);
  // Per voxel only what its s can read (session 47 speed2; the same arithmetic in the same order): the root window's
  // share only on a connected voxel, the span only where s may rise above 0, the valley and upper caps only where s
  // is above 0 (neither raises it), and a voxel left at s = 0 takes the one cost of no lumen (1 - (+-0) is 1).
  const bool quartic = o.power == 4, withRings = !bg.rings.empty();
  const auto nodeOf = [&](double s) {
    const double q = 1.0 - s;
    return static_cast<float>(o.epsilon + (quartic ? (q * q) * (q * q) : std::pow(q, o.power)));
  };
  const float noLumen = nodeOf(0.0);  // s = +-0: q is 1 either way
  parallelFor(
      0, g.dims[2],
      [&](int64_t z0, int64_t z1) {
        std::vector<double> row(static_cast<size_t>(g.dims[0])), spread(row.size());
        for (int64_t z = z0; z < z1; ++z)
          for (int64_t y = 0; y < g.dims[1]; ++y) {
            bg.rowWithSpread(y, z, row, spread);
            const int64_t at = g.linear(0, y, z);
            const float* smRow = sm.data() + at;
            bg.wallRow(y, z, smRow, row);
            const uint8_t* connectedRow = connected.data() + at;
            const uint8_t* shellRow = upper ? shell.data() + at : nullptr;
            float* nodeRow = nc.node.data() + at;
            for (int64_t x = 0; x < g.dims[0]; ++x) {
              const size_t i = static_cast<size_t>(x);
              const double v = smRow[x];
              double s = 0.0;
              if (connectedRow[x]) {
                const double t = std::clamp((v - wLo) / wSpan, 0.0, 1.0);
                s = bright ? t : 1.0 - t;
              }
              const double d = bright ? v - row[i] : row[i] - v;
              const double l = floor * std::max(rootSpread, spread[i]);
              const auto spanOf = [&] { return std::max({2 * l, hiMin, l + rootSpread}) - l; };
              const double dl = d - l;
              // At or below l the local share is 0 (the span is > 0): s keeps the root's.
              if (dl > 0) s = std::max(s, std::clamp(dl / spanOf(), 0.0, 1.0));
              // The ring term, only where it can raise s (its early exit skips most background).
              // Only on the lumen side of the root's surroundings B: a voxel more background-like
              // than the material around the root is not this lumen's (fat or partial-volume air
              // in soft tissue is darker than its ring but brighter than the lung around airways).
              const bool lumenSide = withRings && (bright ? v > e.surround : v < e.surround);
              for (size_t k = 0; lumenSide && k < bg.rings.size() && s < 1; ++k) {
                const double sp = spanOf();
                const double dr = ringContrast(sm, bg.rings[k], x, y, z, bright, l + s * sp);
                if (dr > l + s * sp) s = std::min(1.0, (dr - l) / sp);
              }
              if (!(s > 0)) {
                nodeRow[x] = s == 0 ? noLumen : nodeOf(s);
                continue;
              }
              const double sp = spanOf();
              // The dip between two lumens (tracking/valley_cost.h), on the unsmoothed intensities
              // (the smoothing fills a neck under a voxel wide) and on the smoothed ones (one noisy
              // voxel of the neck is no way through).
              s = capByValley(volume, bg.valleys, x, y, z, bright, s, valleyFloor * std::max(rootSpread, spread[i]),
                              sp);
              s = capByValley(sm, smValleys, x, y, z, bright, s, l, sp);
              // Far beyond the lumen (bone, metal; the upper edge) is not lumen, whatever its contrast.
              // A shell voxel tests its neighbourhood's most extreme value, beyond the far end: no lumen.
              if (upper) s = std::min(s, shellRow[x] ? 0.0 : e.upperCap(v));
              nodeRow[x] = nodeOf(s);
            }
          }
      },
      4);
  timer.lap("cost", out.phases);
  const std::string medial = addMedialTerm(nc, o.epsilon + std::pow(1 - o.medial.lumenLevel, o.power), o.medial);
  nc.description =
      "auto: " + std::string(LumenEstimate::model) + (bg.rings.empty() ? "" : " + ring contrast") + " (" +
      e.describe() + valleyText(bg.valleys) +
      fmt(e.hasUpperEdge() ? ", smooth %.3g mm, c = eps + (1 - min(max(s_root, s_local, s_ring), 1 - s_valley, "
                             "s_upper))^%.3g"
                           : ", smooth %.3g mm, c = eps + (1 - min(max(s_root, s_local, s_ring), 1 - "
                             "s_valley))^%.3g",
          o.smoothMm, o.power) +
      medial + ")";
  timer.lap("medial", out.phases);
  progress.report(1.0, "cost");
  return out;
}

}  // namespace vs
