// trace's default cost: the intensity cost of cost/cost3d.h with its polarity and window
// estimated from the root's neighbourhood against its surroundings, so one default follows
// contrast-filled vessels (CTA, MRA: bright) and air-filled airways (CT: dark) without tuning.
//
// Estimate (on the smoothed intensities the cost sees):
//   lumen    L = median over a ball of lumenRadiusMm around the root (at least its 26 neighbours);
//   spread   s = robust noise: the smaller of 1.4826 * MAD over that ball and 1.4826 * median
//            |v(x+1) - v(x)| / sqrt(2) within shellOuterMm (edges inflate the first, texture the second);
//   surround B: among the shell voxels (shellInnerMm..shellOuterMm from the root, moved out to
//            start at 1.5 x the root's lumen radius in a wide lumen) that differ
//            from L by more than max(3 s, 5% of |median(shell) - L|) in the direction of
//            median(shell), the surroundPercentile-th one counted from the lumen's side: the most
//            lumen-like material that is not lumen (lung parenchyma around airways, soft tissue
//            around vessels), so the window does not let paths wander into it;
//   polarity bright if L > median(shell), else dark;
//   window   from L to L + windowFraction * (B - L): the lumen is cheap, everything at or beyond
//            that point (half-way to the surroundings by default) costs the most.
// No contrast (the root's contrast beyond its own wall, WallContrastOptions below, <= minContrastToNoise *
// max(s, tiny), or no surround voxel): DataError that names the contrast found and --cost intensity --polarity
// --window as the way out. (Before session 16 the test took |B - L|: a noisy CT aorta's root, 7 mm deep, had 140
// against a bar of 140.4, B being the vertebra's and the wall's most lumen-like values.)
//
// The root's connected lumen (the window, bounded along the structure): the window is cut into
// connectSteps steps from L towards its far edge; the region connected (26-neighbours) to the root
// through voxels up to step k grows with k (one minimax flood from the root's 26-neighbourhood).
// Where it spills into a material beyond the lumen - from one step to the next it grows more than
// spillGrowth (4) times and beyond spillShare (2 %) of the volume, at a step past 3 noise spreads s from L -
// the window ends at the step before (the upper trachea's window reached half-way to the neck's soft
// tissue, -935..-553 HU, and held the lung parenchyma, -800..-900, 40 mm away: the flood from the
// root stays in the airway tree, 26 k voxels, up to -792 HU and fills both lungs, 1.2 M, at -768).
// Only voxels in that connected region take s_root; elsewhere (a dark pocket in the lung, a bright
// bone or vessel not joined to the root's lumen within the window) only local contrast counts.
//
// Lumen model ("connected root window + local contrast"): a voxel is lumen as much as the larger of
//   s_root  = its place in the root's window (above: voxels like the root; wide flat lumens) where
//            it is connected to the root through the window (above), else 0, and
//   s_local = clip((d - t0) / (t1 - t0), 0, 1), d = its contrast against its OWN local
//            background, signed towards the lumen (I - Bloc for bright, Bloc - I for dark),
//            t0 = localNoiseFloor x the larger of the root's noise s and the local spread
//            (1.4826 x median neighbour difference / sqrt 2 of the background voxels of the
//            coarsest blocks, the median over a block and its 26 neighbours, blocks with fewer
//            background pairs than half their background voxels left out: noise and texture
//            such as lung parenchyma, not the edges of walls around a lumen),
//            t1 = max(2 t0, t0 + s, localFraction * |B - L|);
// cost c = eps + (1 - max(s_root, s_local, s_ring))^power (s_ring below). So a branch dimmer than the root (partial
// volume, wash-out, bias) but standing out from its own surroundings by half the root's contrast
// is as cheap as the root, and a point without local contrast stays expensive.
// Local background Bloc, at localScales block sizes (localBlockMm, its half, its quarter ...):
// per scale the volume is cut into blocks; per block the localPercentile-th percentile counted
// from the lumen's side (bright: the 100-p-th) of its voxels outside the root's window (those are
// lumen), i.e. background as long as other lumen fills less than p % of it. With structureFraction > 0
// (the default since session 14, 0.65: wide-lumen targets 41 -> 68 of 70 on the family's tuning seeds;
// docs/notes/tracking.md sessions 13 bg3 and 14 wide4), beside a wide lumen the
// root's structure (below) is left out as well: in a block where the structure fills more than p %
// and that holds, or touches a block that holds, a part of it structureDepth (2) voxels deep (a cube
// of that radius inside it: a wide lumen, not two thin tubes side by side, whose gap would become
// lumen against the tissue farther off). A block with fewer than min(8, half its samples) such voxels
// has no background of its own: it borrows the most lumen-like value of the nearest blocks that have
// one (26-neighbour waves); only when no block has any it takes the window's far edge.
// The root's structure: the voxels connected (26-neighbours) to the root through voxels up to
// structureFraction (0.65) of the way from L to the farther of B and the shell's median (in a lumen
// fading along its length B is the lumen itself a little farther on) - the lumen faded below the
// window by falloff or bias, the daughters - found by the connected lumen's flood continued past the
// window in the window's steps (cut back at a spill, tested over the structure's own step), plus the voxels
// within structureWall (1) voxel of it (its partial-volume wall). Where the structure has a deep part, its wide
// lumen's wall is measured against the former background (without the structure: a block of window voxels takes
// the window's far edge), so the wall of the trachea or the aorta is not lumen against the tissue beyond it:
// (a) the root's window region and the voxels within wideWallVoxels (2) of it (there s_root, the window, grades
// the lumen towards its wall and centres paths; against the tissue the whole trachea would be flat lumen), within
// structureDepth + wideWallVoxels of the deep part but not in the deep part's core (wideWallVoxels deeper than it:
// a wide lumen fading past the window's far edge along its length is not measured against that edge, session 17),
// and (b) beyond the window or in that core, within structureDepth + wideWallVoxels of the deep part, the voxels on the
// tissue's side of the half-maximum between the wide lumen's level (the median of its deep part in the block, else of
// the 26 neighbour blocks') and the new background. The faded lumen's inside, the daughters and everything
// farther out are measured against the new background. Before (session 12) a block inside a wide lumen took the
// window's far edge and a block beside it the lumen's faded or partial-volume values, so a
// daughter's end or a dim branch a block from the lumen had no contrast. Then, per block, the most lumen-like of it and
// its 26 neighbours (a vessel beside a brighter region or tissue at the skin is not measured against air), interpolated
// trilinearly between block centres but never more lumen-like than the value of the voxel's own block (a step between
// two backgrounds is not smoothed into contrast). Bloc is the most lumen-like of the scales: a thin branch is measured
// against the fine blocks around it (coarse ones hold brighter tissue a few mm away), a thick one against the coarse
// blocks (fine ones lie inside it). Ring contrast (the lumen model's third term, s_ring, ramped by the same t0..t1 as
// s_local): at ring radii ringVoxels x 2^k smallest spacings, the voxel against the 13 opposite pairs of the 26
// neighbour directions scaled to the radius: per pair the more lumen-like of its two samples (bright: the brighter),
// the contrast being the median over the pairs of the voxel minus it. A thin branch in a dark pocket inside brighter
// tissue is brighter than both sides across it (most pairs) and stands out against the pocket, not the tissue; tissue
// at the skin or lung parenchyma beside a vessel has one side at least as lumen-like in most pairs, so no contrast (the
// guard the blocks' most-lumen-like neighbour gives at 8 mm, here at the branch's scale). s_ring counts only for voxels
// on the lumen side of the root's surroundings B: darker than the ring but brighter than the lung (fat, partial-volume
// air in the mediastinum) is not an airway.
// Upper edge (upperFraction, default 1.5; auto_cost_upper.cpp): with c = |L - B| the root's contrast, s_upper is 1 up
// to L + upperFraction c and 0 from L + 1.5 upperFraction c (bright; mirrored below L for dark), linear between, and s
// is capped by it: bone, calcium and metal far brighter than a contrast lumen are not lumen, whatever their local
// contrast, while a segment brighter than the root by less (inflow; LIDC2's ascending aorta reaches L + 0.89 c) is.
// It is tested on the voxel's value, but in the partial-volume shell of such material (a voxel with a neighbour beyond
// the far end and one beyond the window on the background's side) on its 26-neighbourhood's most extreme value: the
// shell's values pass through the lumen's on the way to the tissue. The connected lumen and the structure stop at
// the same test (beyond the far end: none), and those voxels are not sampled as local background either.
// Valley (tracking/valley_cost.h): s is then capped by 1 - s_valley, s_valley the ramped depth of
// the dip (bright) or ridge (dark) the voxel lies in between two more lumen-like sides, so the neck
// between two touching vessels is not lumen: c = eps + (1 - min(max(s_root, s_local, s_ring),
// 1 - s_valley))^power.
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <exception>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "cost/cost3d.h"
#include "tracking/medial_cost.h"
#include "util/phase_timer.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace vs {

// The root's contrast test (auto_cost_contrast.cpp): `rays` rays from the root, evenly over the sphere, sampled
// (trilinear, half the smallest spacing apart) out to reachMm; a ray's wall is its first sample more than 3 noise
// spreads from the lumen towards the surroundings whose surroundings are too (a dip whose surroundings are the lumen's
// values again is the lumen's own: the ray looks on past it), its surroundings the median of its samples from
// skipVoxels (largest spacings: the partial-volume wall) past the wall over widthMm, its contrast their signed distance
// from the lumen towards the surroundings (0 for a ray that stays in the lumen's values); the root's contrast is the
// median over the rays. So a wide lumen (aorta, trachea) is measured against the tissue beyond its own wall, not
// against its own noise tail and the most lumen-like tissue within a fixed shell (the shell's percentile B below,
// which stays the window's far edge), and a root without a lumen around it (most rays never leave its values) has
// none.
struct WallContrastOptions {
  int rays = 128;         // 0: the test takes the shell's contrast |B - L| (before session 16)
  double reachMm = 30;    // how far a ray looks for the wall (a wide lumen's far side)
  double skipVoxels = 2;  // the wall's partial-volume width past its first sample beyond the lumen
  double widthMm = 11;    // the surroundings' depth along the ray (the shell's)
};
struct WallContrast {
  double contrast = 0;        // median over the rays (towards the surroundings)
  double surround = 0;        // L + that contrast towards the surroundings
  int rays = 0, leaving = 0;  // rays cast, rays that left the lumen's values
};
// The test's measure above at `root` of the smoothed volume for lumen level `lumen`, `dir` +1 (dark lumen: the
// surroundings brighter) or -1 (bright), `minSep` the lumen's extent (3 noise spreads).
WallContrast rootContrastBeyondWall(const VolumeF32& smoothed, const Index3& root, double lumen, double dir,
                                    double minSep, const WallContrastOptions& options = {});
// The shell's voxels (innerMm..outerMm from the root) that are not the root's own lumen reaching through the shell:
// left out (counted in `left`) is a voxel on the lumen's side of `half` (signed distance from `lumen` towards the
// surroundings, `dir` as above) joined to the root by a straight line that stays on that side (a wide lumen fading
// along its trunk: its faded middle is lumen, not the most lumen-like surroundings).
std::vector<double> shellOutsideLumen(const VolumeF32& smoothed, const Index3& root, double innerMm, double outerMm,
                                      double lumen, double dir, double half, int64_t* left = nullptr);

struct AutoCostOptions {
  double smoothMm = 0.5;      // Gaussian pre-smoothing sigma of the intensities (mm; 0: none);
                              // more merges thin vessels into the background
  double lumenRadiusMm = 0;   // the root's neighbourhood (0: its 26 neighbours)
  double shellInnerMm = 4.0;  // the surroundings: a shell around the root
  double shellOuterMm = 15.0;
  double surroundPercentile = 5;    // of the non-lumen shell voxels, counted from the lumen's side
  double windowFraction = 0.5;      // the window ends this fraction of the way from L to B
  double minContrastToNoise = 4.0;  // the root's contrast (wallContrast) must exceed this many noise spreads
  double power = 4;                 // cost exponent (as the intensity cost)
  double epsilon = 1e-3;            // cost floor (as the intensity cost)
  double localBlockMm = 8;          // local background: the coarsest block edge (mm)
  int localScales = 1;              // block edges localBlockMm / 2^k, k < localScales
  double localPercentile = 25;      // of a block's voxels, counted from the lumen's side
  double localTailCap = 5;          // ... beside no wide lumen at most this many widths of the background side's
                                    // tail (its quartile to its 5th percentile, >= the root's noise) beyond that
                                    // quartile (0: no cap, before session 17; docs/notes/tracking.md par1)
  double localFraction = 0.35;      // local contrast of this fraction of the root's is full lumen
  double localNoiseFloor = 3;       // local contrast under this many noise spreads counts nothing
  double ringVoxels = 0;            // ring contrast: the first ring radius, in smallest spacings (0: none;
                                    // 3 tried, not the default: docs/notes/tracking.md session 10)
  int ringScales = 1;               // ring radii ringVoxels x 2^k, k < ringScales
  double valleyVoxels = 1;          // valley term (tracking/valley_cost.h): the first radius in smallest
                                    // spacings (0: none)
  int valleyScales = 2;             // valley radii valleyVoxels x 2^k, k < valleyScales
  double valleyNoiseFloor = 2;      // a valley under this many noise spreads (of the unsmoothed
                                    // intensities) counts nothing
  int connectSteps = 16;            // the connected lumen: steps of the window (0: s_root unconnected,
                                    // the window as estimated; session 11's model)
  double spillGrowth = 4;           // a spill: the region grows more than this many times in one step
  double spillShare = 0.02;         // ... and beyond this share of the volume's voxels
  MedialOptions medial;             // the medial term added last (medial_cost.h; weight 0: none)
  double structureFraction = 0.65;  // local background: voxels connected to the root through this fraction of
                                    // the way from L to B are the root's structure, not background (0: none,
                                    // main's model before session 14; docs/notes/tracking.md session 13 bg3, 14 wide4)
  int structureDepth = 2;           // ... left out of a block only where its part this deep fills > p % of it
  int structureWall = 1;            // the structure's partial-volume wall (voxels)
  double upperFraction = 1.5;       // the lumen's upper edge (bright; dark: its lower edge): full lumen up to this many
                                    // root contrasts |L - B| beyond L, none from 1.5 x as many (bone, calcium, metal
  // far brighter than a contrast lumen); 0: no edge (docs/notes/tracking.md s15 bone1)
  int wideWallVoxels = 2;  // beside a wide lumen: the root's window region's wall (voxels), and the zone beyond the
                           // window (structureDepth + this many voxels around the deep part) where the half-maximum
                           // between the lumen's level and the tissue marks its wall
  // The root's contrast test (WallContrastOptions above; rays 0: |B - L|, before session 16).
  WallContrastOptions wallContrast;
};

// One ring of the ring contrast (see above): 13 offsets d_j (the other sample at -d_j).
struct RingScale {
  double radiusMm = 0;
  std::array<Index3, 13> offset{};
  std::array<int64_t, 13> linear{};  // the offsets' linear index steps
  Index3 reach{0, 0, 0};             // the largest |offset| per axis (no clamping farther inside)
};
// stepsAtLeast (the smoothed valley's scales): at least voxels x 2^k steps along every direction, also where the radius
// in mm is fewer of a coarse axis's steps (a neck thinner than a slice is two partial-volume voxels side by side, one
// per lumen: only a line 2 steps each way reaches across both; docs/notes/tracking.md session 19 par2).
std::vector<RingScale> ringScalesFor(const Geometry& g, double voxels, int scales, bool stepsAtLeast = false);
// The ring contrast of voxel (x, y, z) towards the lumen (bright: v - the brighter of each pair,
// the median over the 13 pairs); samples outside the volume take its nearest face voxel. Returns
// -infinity as soon as 7 pairs (the median's worth) have a contrast <= `floor`.
double ringContrast(const VolumeF32& smoothed, const RingScale& ring, int64_t x, int64_t y, int64_t z, bool bright,
                    double floor = -std::numeric_limits<double>::infinity());

// One scale of the local background: per-block values on a coarse grid.
struct BlockGrid {
  Index3 blocks{0, 0, 0};        // grid size
  Index3 blockVoxels{1, 1, 1};   // block edge in voxels
  std::vector<float> value;      // per block (x fastest), after the neighbour filter
  std::vector<uint8_t> differs;  // per block (the former background's grid): it or a neighbour differs from the new
  std::vector<float> spread;     // per block: robust spread of its background, after the same filter
  // Per block: the wide lumen's level (its deep part's median; NaN: none; empty without).
  std::vector<float> lumenLevel;
  // `field` (value or spread) trilinear between block centres.
  double at(const std::vector<float>& field, int64_t x, int64_t y, int64_t z) const;
  // The same along the row (y, z): out[x] for every x < out.size().
  void row(const std::vector<float>& field, int64_t y, int64_t z, std::vector<double>& out) const;
  // `field` of the block holding the voxel (no interpolation).
  double own(const std::vector<float>& field, int64_t x, int64_t y, int64_t z) const;
  // row(), each voxel's value clamped to be no more lumen-like than its own block's (bright: >= it); with `fold`
  // out[x] becomes the more lumen-like (bright: the smaller) of out[x] and that value.
  void rowNotBeyondOwn(const std::vector<float>& field, int64_t y, int64_t z, bool bright, std::vector<double>& out,
                       bool fold = false) const;
  // Per x of rows nx voxels long: the block centres around x, the second one's weight and the block
  // holding x, so a row needs no division per voxel (the same values; set by prepareRows).
  std::vector<int32_t> rowI0, rowI1, rowOwn;
  std::vector<double> rowF;
  void prepareRows(int64_t nx);
};
// The local background Bloc (see above): the most lumen-like of its scales.
struct LocalBackground {
  TubePolarity polarity = TubePolarity::Bright;
  std::vector<BlockGrid> scales;   // coarsest first
  std::vector<RingScale> rings;    // the ring contrast's radii (smallest first)
  std::vector<RingScale> valleys;  // the valley term's radii (smallest first; tracking/valley_cost.h)
  // With the root's structure (estimateLocalBackground's `structure`): its voxels and its wall are
  // measured against structureScales, the background that keeps it (the window's far edge inside a wide
  // lumen): their own partial-volume wall is not lumen against the tissue beyond it.
  std::vector<BlockGrid> structureScales;
  std::vector<uint8_t> structure;  // per voxel (x fastest), empty without
  Index3 dims{0, 0, 0};
  double at(int64_t x, int64_t y, int64_t z) const;  // outside the wide lumen's wall
  // Voxel of intensity v: the wide lumen's wall (isWall) is measured against structureScales.
  double at(int64_t x, int64_t y, int64_t z, double v) const;
  // In the root's window region or its wall, or beside the wide lumen's deep part beyond the window and on the
  // background's side of the half-maximum between the lumen's level (its block's) and the background b.
  bool isWall(int64_t x, int64_t y, int64_t z, double v, double b) const;
  bool formerDiffers(int64_t x, int64_t y, int64_t z) const;  // the former background differs from the new here
  double spreadAt(int64_t x, int64_t y, int64_t z) const;     // the local spread (coarsest scale)
  // Along the row (y, z).
  void row(int64_t y, int64_t z, std::vector<double>& out) const;
  // row() and the first scale's spread along the row, in one pass.
  void rowWithSpread(int64_t y, int64_t z, std::vector<double>& out, std::vector<double>& spread) const;
  // The row's wall voxels (intensities v; out: the background outside the wall) set to structureScales' background.
  void wallRow(int64_t y, int64_t z, const float* v, std::vector<double>& out) const;
};
// Block helpers of the wide lumen (auto_cost_structure.cpp): per block 1 where it holds, or touches a block that
// holds, a voxel of `deep`; the level per block, its own where it has one, else the median of its 26 neighbours'
// (NaN: none); `former`'s differs flags against `now` (same grid).
std::vector<uint8_t> nearDeepBlocks(const BlockGrid& grid, const Geometry& g, const std::vector<int64_t>& deep);
std::vector<float> levelFilter(const BlockGrid& grid, const std::vector<float>& raw);
void markDiffers(BlockGrid& former, const BlockGrid& now);
// A block's samples (blockBackground): the values outside the root's window and not beyond the upper edge
// (`vals`; `valIn`: in the structure's mask), their differences to the next voxel along x where that is
// outside the window too (`diffs`; `diffIn`: either in the mask), the structure's deep values, the number
// of samples and of those in the structure (mask >= 2). The appends are branch-free (a voxel's tests
// are unpredictable at tissue edges); the values and their order are those of one push per sample.
// `up` (upperShell; nullptr: no upper edge): beyond the edge are its voxels and the values beyond hiUp.
struct BlockSamples {
  std::vector<float> vals, diffs, deepVals;
  std::vector<uint8_t> valIn, diffIn;
  size_t sampled = 0, inStructure = 0;
};
void sampleBlock(const VolumeF32& vol, const int64_t lo[3], const int64_t blockVoxels[3], const int64_t step[3],
                 bool bright, float edge, const uint8_t* up, float hiUp, const uint8_t* bm, BlockSamples& s);
// The block grid of one scale: block edges of blockMm (at least 2 voxels); a block's sample steps (at most ~8^3
// samples); the percentile-th of `vals` counted as `p` (bright: 100 - percentile), or NaN with fewer than min(8, half
// the block's samples) values (a block of lumen); its spread from the neighbour differences (`diffs` reordered), -1
// for none: a block of lumen (`raw` NaN), or fewer pairs than half its `nVals` values (a block of edges around a
// lumen).
BlockGrid blockGrid(const Geometry& g, double blockMm);
void blockSampleSteps(const BlockGrid& grid, int64_t step[3]);
float blockPercentile(std::vector<float>& vals, size_t sampled, double p);
float blockSpread(std::vector<float>& diffs, float raw, size_t nVals);
// A block's value r (its percentile, counted as `p`) capped beside no wide lumen (AutoCostOptions::localTailCap k):
// at most the background side's quartile q plus max(k x |q - the tail|, floorWidth) (auto_cost_blocks.cpp). `vals` as
// blockPercentile(vals, sampled, p) left them when it gave r (r's value in place: q and the tail are searched beside
// it).
void capAtBackgroundTail(std::vector<float>& vals, double p, double percentile, bool bright, double floorWidth,
                         double k, float& r);
// A block's background away from the root's structure (no mask read: never heavy, no deep voxel): its percentile
// capped at tailCap tail widths (AutoCostOptions::localTailCap; 0: no cap; at least tailFloor), before the cap (the
// former background's value) and its spread. The one home of that step for blockBackground and BackgroundPresample.
struct PlainBlock {
  float raw = 0, uncapped = 0, spread = -1;
};
PlainBlock plainBlock(const VolumeF32& vol, const BlockGrid& grid, int64_t block, bool bright, float edge,
                      const uint8_t* up, float hiUp, double percentile, double tailCap, double tailFloor,
                      BlockSamples& sample);
struct LumenEstimate;
// The local background's blocks as blockBackground finds them without the root's structure (its raw percentile and
// spread per scale and block: a block away from the structure's deep part samples no mask), found while the connect
// flood runs (serial) on a second thread, then on the caller's (whileRunning; the flood cannot change them unless it
// cuts the window: matches() says whether they hold for the estimate after it). VS_THREADS=1: no second thread.
class BackgroundPresample {
 public:
  BackgroundPresample(const VolumeF32& smoothed, const LumenEstimate& estimate, double blockMm, double percentile,
                      int scales, const std::vector<uint8_t>* upperShell);
  BackgroundPresample(const BackgroundPresample&) = delete;
  BackgroundPresample& operator=(const BackgroundPresample&) = delete;
  ~BackgroundPresample() { stop(); }
  // Runs fn() on this thread while the other workers sample blocks; returns fn()'s value. Then finish().
  template <class F>
  auto whileRunning(F&& fn) {
    startHelper();
    try {
      return fn();
    } catch (...) {
      stop();
      throw;
    }
  }
  void finish();  // the blocks left sampled on this thread too, the helpers joined (the first exception rethrown)
  void work();    // samples blocks until none is left (on any number of threads at once)
  bool matches(const LumenEstimate& estimate, double blockMm, double percentile, int scales,
               const std::vector<uint8_t>* upperShell) const;
  std::vector<std::vector<PlainBlock>> blocks;  // per scale (finest last), per block

 private:
  void startHelper();
  void stop();  // no more blocks claimed, the helpers joined
  const VolumeF32& vol_;
  bool bright_, upper_;
  float edge_, hiUp_;
  double blockMm_, percentile_, tailCap_, tailFloor_;
  const std::vector<uint8_t>* shell_;
  std::vector<BlockGrid> grids_;
  std::vector<int64_t> first_;  // per scale, its first block's number among all scales' (then the total)
  std::atomic<int64_t> next_{0};
  std::vector<std::thread> helpers_;
  std::vector<std::exception_ptr> errors_;  // per helper
};
// `structure` (per voxel, optional): voxels that are not background whatever their value (the root's
// structure and its wall); blocks (almost) full of them or of the window borrow from the nearest blocks that
// have background, and take the window's far edge only when no block has any.
// With the root's structure (connectRootLumen), its wide-lumen zone is moved into the background.
struct RootStructure;
// With the upper edge, `upperShell` (upperShell()); `presample`: blocks already sampled (used where it matches()).
LocalBackground estimateLocalBackground(const VolumeF32& smoothed, const LumenEstimate& estimate, double blockMm,
                                        double percentile, int scales, RootStructure* structure = nullptr,
                                        const std::vector<uint8_t>* upperShell = nullptr,
                                        const BackgroundPresample* presample = nullptr);

struct LumenEstimate {
  TubePolarity polarity = TubePolarity::Bright;
  double lumen = 0;                   // L
  double spread = 0;                  // s (noise)
  double surround = 0;                // B
  WallContrast wall;                  // the root's contrast beyond its wall (the contrast test; rays 0: |B - L|)
  double shellMedian = 0;             // the median of the surroundings' shell (all its voxels)
  double windowLo = 0, windowHi = 0;  // the root's window (s_root)
  double localLo = 0, localHi = 0;    // local contrast t0..t1 (s_local)
  double localBlockMm = 0, localPercentile = 0, localFraction = 0, localNoiseFloor = 0, localTailCap = 0;
  int localScales = 0;
  std::vector<double> ringRadiiMm;            // the ring contrast's radii (none: no ring term)
  double rootRadiusMm = 0;                    // the root's lumen radius (radial shell medians)
  double shellInnerMm = 0, shellOuterMm = 0;  // the surroundings' shell used (wide lumen: beyond 1.5 x the radius)
  int64_t shellInLumen = 0;  // shell voxels left out of B as the root's own lumen (shellOutsideLumen; 0: none)
  // The connected lumen (0 steps: not used): voxels connected to the root through the window; at a
  // spill the window's far edge was moved from `spillFrom` (the estimate's) back to the step before.
  int connectSteps = 0;
  int64_t connectedVoxels = 0;  // the region's size with the final window
  int64_t spillVoxels = 0;      // the region one step further (0: no spill)
  double spillFrom = 0;         // the window's far edge before the cut (spill only)
  // The local background's exclusion (structureFraction 0: none): the root's structure, connected to it
  // through voxels up to structureEdge (cut back at a spill, like the window), plus structureWall voxels.
  double structureFraction = 0, structureEdge = 0;
  int structureWall = 0, structureDepth = 0, wideWallVoxels = 0;
  int64_t structureVoxels = 0;  // the structure with its wall
  // The upper edge (bright; dark: mirrored below L): s is full lumen up to upperLo, none beyond upperHi (linear
  // between); the connected lumen and the structure stop at upperHi. upperFraction 0: none (both +-infinity).
  double upperFraction = 0, upperLo = 0, upperHi = 0;
  bool hasUpperEdge() const { return upperFraction > 0; }
  double upperCap(double v) const;     // 1 up to upperLo, 0 from upperHi (bright; mirrored for dark)
  std::string upperText() const;       // ", upper edge 149..162 (1, 1.5 contrasts beyond the lumen)"
  std::string backgroundText() const;  // the local background's part of describe()
  static constexpr const char* model = "connected root window + local contrast";
  std::string connectText() const;  // the connected lumen's part of describe()
  std::string describe() const;     // "bright, lumen 312 (spread 9.5), surroundings 48, window 180..312, local
                                    // contrast 28..132 over 8, 4, 2 mm blocks (p25)"
};

// A voxel's contrast against its local background (what s_local sees).
struct LocalContrast {
  double intensity = 0, background = 0, spread = 0;
  double lo = 0, hi = 0;                                       // t0, t1 here
  double contrast = 0;                                         // towards the lumen (bright: intensity - background)
  std::vector<double> ringContrast;                            // per ring radius (LumenEstimate::ringRadiiMm)
  std::string ringContrastText(const LumenEstimate& e) const;  // "; against its rings of 1.5 mm: contrast 3, 3 mm: 5"
  std::string describe(const LumenEstimate& e) const;          // "intensity 80, local surroundings 78, contrast 2
                                                               // towards the bright lumen (lumen from 28, full at
                                                               // 132; noise 9.5)"
};

// Estimates polarity and window at `root` (0-based voxel inside `smoothed`). Throws
// InvalidArgument for a root outside the volume, DataError when there is no contrast.
LumenEstimate estimateLumen(const VolumeF32& smoothed, const Index3& root, const AutoCostOptions& options = {});
// The root's connected lumen (see above) for `estimate` (its window is cut back at a spill and its
// connect* / spill* fields set): per voxel 1 where it is connected to the root through the final
// window, else 0. `steps` 0: every voxel 1 and the estimate unchanged.
std::vector<uint8_t> connectRootLumen(const VolumeF32& smoothed, const Index3& root, LumenEstimate& estimate,
                                      int steps = 16, double spillGrowth = 4, double spillShare = 0.02);

// The root's structure for the local background (see above), found by the connected lumen's flood.
struct RootStructure {
  std::vector<uint8_t> mask;      // per voxel: 0 none, 1 its wall, 2 in it, 3 its deep part; empty without
  std::vector<int64_t> deep;      // the deep part's voxels (linear indices)
  std::vector<uint8_t> wideZone;  // per voxel 1 within structureDepth + wideWallVoxels of the deep part (the wide
                                  // lumen and its own wall), else 0; empty without a deep part
};
// The connected lumen as above (options' connect* and spill*) and, with structureFraction > 0 and `structure`
// given, the root's structure from the same flood continued past the window (estimate's structure* fields set).
// With the upper edge, `upperShell` (upperShell) marks the voxels it tests as beyond its far end whatever their own
// value (nullptr: none).
std::vector<uint8_t> connectRootLumen(const VolumeF32& smoothed, const Index3& root, LumenEstimate& estimate,
                                      const AutoCostOptions& options, RootStructure* structure,
                                      const std::vector<uint8_t>* upperShell = nullptr);
// The upper edge's shell: per voxel 1 in the partial-volume shell of bone or metal (a voxel with both a neighbour
// beyond the edge's far end and one beyond the window on the background's side: its value passes through the lumen's
// on the way from the bone to the tissue), else 0. The edge tests a shell voxel on the most lumen-beyond value of it
// and its 26 neighbours, which is beyond the far end (a neighbour's is): a shell voxel tests as beyond it, so the shell
// is not lumen either; every other voxel tests its own value; a lumen touching bone keeps its voxels (lumen, not
// tissue, on their other side).
std::vector<uint8_t> upperShell(const VolumeF32& smoothed, const LumenEstimate& estimate);

struct AutoCost {
  NodeCost3D cost;  // description starts with "auto"
  LumenEstimate estimate;
  LocalBackground background;
  VolumeF32 smoothed;  // the intensities the cost and the estimate saw
  // Its phases: "smooth", "estimate", "connect" (the flood and the root's structure), "background", "cost" (per
  // voxel), "medial".
  std::vector<PhaseTime> phases;
};
// `withRings`: also the ring contrasts (only `describe` reads them; each samples a ring of voxels).
LocalContrast localContrastAt(const VolumeF32& smoothed, const LocalBackground& background,
                              const LumenEstimate& estimate, const Index3& voxel, bool withRings = true);

// Smooths, estimates at `root` and returns the lumen model's node cost (above).
AutoCost computeAutoCost(const VolumeF32& volume, const Index3& root, const AutoCostOptions& options = {},
                         Progress& progress = Progress::none());

}  // namespace vs
