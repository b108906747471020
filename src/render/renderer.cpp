// Renderer's public side: construction (compact voxel copy, automatic window, block min/max),
// options, labels, overlays, preparation (TF table, block cell words, gradients) and render(),
// which rasterises the overlays (overlay_raster.h) and casts the rays (ray_cast.h).
#include "render/renderer.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <limits>

#include "render/ray_cast.h"
#include "render/renderer_impl.h"
#include "util/error.h"
#include "util/parallel.h"

namespace vs {

RenderMode renderModeFromName(const std::string& n) {
  if (n == "full") return RenderMode::Full;
  if (n == "cutbox") return RenderMode::CutBox;
  if (n == "triplanar") return RenderMode::Triplanar;
  if (n == "monoplanar") return RenderMode::Monoplanar;
  if (n == "mip") return RenderMode::Mip;
  throw InvalidArgument("unknown render mode '" + n + "' (valid: full, cutbox, triplanar, monoplanar, mip, slice)");
}

std::string renderModeName(RenderMode m) {
  switch (m) {
    case RenderMode::Full:
      return "full";
    case RenderMode::CutBox:
      return "cutbox";
    case RenderMode::Triplanar:
      return "triplanar";
    case RenderMode::Monoplanar:
      return "monoplanar";
    case RenderMode::Mip:
      return "mip";
  }
  return "full";
}

std::array<float, 3> labelColor(int label) {
  static const float pal[12][3] = {{0.9f, 0.2f, 0.2f}, {0.2f, 0.8f, 0.2f}, {0.25f, 0.4f, 1.0f}, {1.0f, 0.85f, 0.1f},
                                   {0.9f, 0.3f, 0.9f}, {0.1f, 0.9f, 0.9f}, {1.0f, 0.55f, 0.1f}, {0.6f, 0.4f, 0.2f},
                                   {0.6f, 1.0f, 0.5f}, {0.5f, 0.5f, 1.0f}, {1.0f, 0.6f, 0.7f},  {0.7f, 0.7f, 0.7f}};
  if (label <= 0) return {0, 0, 0};
  const float* c = pal[(label - 1) % 12];
  return {c[0], c[1], c[2]};
}

namespace {
constexpr float kInf = std::numeric_limits<float>::infinity();
}  // namespace

void Renderer::Impl::buildBlocks(BlockGrid& G, int shift) {
  G.shift = shift;
  G.bx = std::max(1, ((nx - 1) + (1 << shift) - 1) >> shift);
  G.by = std::max(1, ((ny - 1) + (1 << shift) - 1) >> shift);
  G.bz = std::max(1, ((nz - 1) + (1 << shift) - 1) >> shift);
  const size_t nb = static_cast<size_t>(G.bx) * G.by * G.bz;
  G.mn.assign(nb, kInf);
  G.mx.assign(nb, -kInf);
  parallelFor(0, G.bz, [&](int64_t b0, int64_t b1) {
    for (int64_t kb = b0; kb < b1; ++kb)
      for (int jb = 0; jb < G.by; ++jb)
        for (int ib = 0; ib < G.bx; ++ib) {
          float lo = kInf, hi = -kInf;
          // Voxels [2^s b, 2^s (b+1)] inclusive: a trilinear sample in the block's cells reads them.
          const int z1 = std::min<int>(nz - 1, static_cast<int>((kb + 1) << shift));
          const int y1 = std::min<int>(ny - 1, (jb + 1) << shift);
          const int x1 = std::min<int>(nx - 1, (ib + 1) << shift);
          for (int z = static_cast<int>(kb << shift); z <= z1; ++z)
            for (int y = jb << shift; y <= y1; ++y) {
              const size_t row = static_cast<size_t>(y * sy + z * sz);
              for (int x = ib << shift; x <= x1; ++x) {
                const float v = val(row + static_cast<size_t>(x));
                lo = std::min(lo, v);
                hi = std::max(hi, v);
              }
            }
          const size_t bi = static_cast<size_t>(ib + G.bx * (jb + static_cast<int64_t>(G.by) * kb));
          G.mn[bi] = lo;
          G.mx[bi] = hi;
        }
  });
}

void Renderer::Impl::buildGradients(Progress& progress) {
  const size_t n = nvox;
  grad.assign(n, {0, 0, 0});
  const double sx_ = g.spacing.x(), sy_ = g.spacing.y(), sz_ = g.spacing.z();
  auto central = [&](int x, int y, int z, float out[3]) {
    const int xm = std::max(0, x - 1), xp = std::min(nx - 1, x + 1);
    const int ym = std::max(0, y - 1), yp = std::min(ny - 1, y + 1);
    const int zm = std::max(0, z - 1), zp = std::min(nz - 1, z + 1);
    auto V = [&](int a, int b, int c) { return val(static_cast<size_t>(a + b * sy + c * sz)); };
    // Eq. 1-3 with the reading notes' correction: divide by the spacing.
    out[0] = xp > xm ? static_cast<float>((V(xp, y, z) - V(xm, y, z)) / ((xp - xm) * sx_)) : 0.f;
    out[1] = yp > ym ? static_cast<float>((V(x, yp, z) - V(x, ym, z)) / ((yp - ym) * sy_)) : 0.f;
    out[2] = zp > zm ? static_cast<float>((V(x, y, zp) - V(x, y, zm)) / ((zp - zm) * sz_)) : 0.f;
  };
  std::vector<float> sliceMax(static_cast<size_t>(nz), 0.f);
  parallelFor(0, nz, [&](int64_t z0, int64_t z1) {
    for (int64_t z = z0; z < z1; ++z) {
      float m = 0;
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) {
          float gv[3];
          central(x, y, static_cast<int>(z), gv);
          m = std::max({m, std::abs(gv[0]), std::abs(gv[1]), std::abs(gv[2])});
        }
      sliceMax[static_cast<size_t>(z)] = m;
    }
  });
  progress.report(0.5, "gradients");
  const float gmax = *std::max_element(sliceMax.begin(), sliceMax.end());
  const float q = gmax > 0 ? 32767.f / gmax : 0.f;
  parallelFor(0, nz, [&](int64_t z0, int64_t z1) {
    for (int64_t z = z0; z < z1; ++z)
      for (int y = 0; y < ny; ++y)
        for (int x = 0; x < nx; ++x) {
          float gv[3];
          central(x, y, static_cast<int>(z), gv);
          auto& o = grad[static_cast<size_t>(x + y * sy + z * sz)];
          for (int a = 0; a < 3; ++a) o[a] = static_cast<int16_t>(std::lrint(std::clamp(gv[a] * q, -32767.f, 32767.f)));
        }
  });
  gradReady = true;
}

template <class T>
void Renderer::Impl::buildBlockCellsT(const T* vox) {
  const BlockGrid& G = coarse;
  blockCells.assign(static_cast<size_t>(G.bx) * G.by * G.bz, 0);
  // Cells exist for lower corners 0..n-2 (0 along a 1-voxel axis, whose offset is 0), as in cell().
  const int mc[3] = {std::max(0, nx - 2), std::max(0, ny - 2), std::max(0, nz - 2)};
  parallelFor(0, G.bz, [&](int64_t kb0, int64_t kb1) {
    for (int64_t kb = kb0; kb < kb1; ++kb)
      for (int jb = 0; jb < G.by; ++jb)
        for (int ib = 0; ib < G.bx; ++ib) {
          uint64_t word = 0;
          for (int lz = 0; lz < 4; ++lz) {
            const int z = static_cast<int>(kb) * 4 + lz;
            if (z > mc[2]) break;
            for (int ly = 0; ly < 4; ++ly) {
              const int y = jb * 4 + ly;
              if (y > mc[1]) break;
              for (int lx = 0; lx < 4; ++lx) {
                const int x = ib * 4 + lx;
                if (x > mc[0]) break;
                const T* b = vox + (x + y * sy + z * sz);
                T lo = b[0], hi = b[0];
                for (const int64_t o : {int64_t(ox), int64_t(oy), int64_t(oy + ox), int64_t(oz), int64_t(oz + ox),
                                        int64_t(oz + oy), int64_t(oz + oy + ox)}) {
                  lo = std::min(lo, b[o]);
                  hi = std::max(hi, b[o]);
                }
                if (!table.transparent(q0 + q1 * float(lo), q0 + q1 * float(hi)))
                  word |= uint64_t(1) << (lx + 4 * ly + 16 * lz);
              }
            }
          }
          blockCells[static_cast<size_t>(ib + G.bx * (jb + static_cast<int64_t>(G.by) * kb))] = word;
        }
  });
  blockOn.resize(blockCells.size());
  for (size_t i = 0; i < blockCells.size(); ++i) blockOn[i] = blockCells[i] != 0 ? 1 : 0;
}
void Renderer::Impl::buildBlockCells() {
  if (is8)
    buildBlockCellsT(v8.data());
  else
    buildBlockCellsT(v16.data());
}

void Renderer::Impl::prepare(Progress& progress) {
  if (tableStale) {
    table = TfTable(tf, vrange.min, vrange.max, stepMm());
    buildBlockCells();
    tableStale = false;
  }
  const bool needGrad = opt.shading && (opt.mode == RenderMode::Full || opt.mode == RenderMode::CutBox);
  if (needGrad && !gradReady) buildGradients(progress);
  progress.report(1.0, "prepare");
}

Renderer::Renderer(const AnyVolume& volume, Progress& progress) : impl_(std::make_unique<Impl>()) {
  auto& I = *impl_;
  requireFinite(volume, "render volume");
  I.g = geometryOf(volume);
  I.g.validate();
  VS_REQUIRE(I.g.dims[0] < (1 << 30) && I.g.dims[1] < (1 << 30) && I.g.dims[2] < (1 << 30), "render: volume too large");
  I.nx = static_cast<int>(I.g.dims[0]);
  I.ny = static_cast<int>(I.g.dims[1]);
  I.nz = static_cast<int>(I.g.dims[2]);
  I.sy = I.nx;
  I.sz = static_cast<int64_t>(I.nx) * I.ny;
  I.ox = I.nx > 1 ? 1 : 0;
  I.oy = I.ny > 1 ? static_cast<int>(I.sy) : 0;
  I.oz = I.nz > 1 ? static_cast<int>(I.sz) : 0;
  I.vrange = valueRange(volume);
  I.nvox = static_cast<size_t>(I.g.voxelCount());
  if (const auto* u8 = std::get_if<VolumeU8>(&volume)) {
    I.is8 = true;
    I.v8 = u8->voxels();
  } else {
    const double span = I.vrange.max - I.vrange.min;
    const bool integer = !std::holds_alternative<VolumeF32>(volume);
    I.q0 = static_cast<float>(I.vrange.min);
    I.q1 = integer || span <= 0 ? 1.f : static_cast<float>(span / 65535.0);
    if (integer && span > 65535) I.q1 = static_cast<float>(span / 65535.0);
    I.v16.resize(I.nvox);
    std::visit(
        [&](const auto& vol) {
          const auto* d = vol.data();
          const double inv = 1.0 / I.q1;
          for (size_t i = 0; i < I.nvox; ++i)
            I.v16[i] = static_cast<uint16_t>(std::clamp(std::lrint((double(d[i]) - I.vrange.min) * inv), 0L, 65535L));
        },
        volume);
  }
  progress.report(0.3, "load");
  I.D = I.g.direction;
  I.M = I.g.direction * I.g.spacing.asDiagonal();
  I.Minv = I.M.inverse();
  // Automatic window: 1st..99.5th percentile (shared with the slice renderer).
  {
    WindowHistogram histogram(I.vrange);
    for (size_t i = 0; i < I.nvox; ++i) histogram.add(I.val(i));
    I.autoWl = histogram.window();
  }
  I.buildBlocks(I.coarse, 2);
  I.tf = TransferFunction::preset("auto", I.vrange);
  progress.report(1.0, "load");
}

Renderer::~Renderer() = default;

const Geometry& Renderer::geometry() const { return impl_->g; }
ValueRange Renderer::range() const { return impl_->vrange; }
WindowLevel Renderer::autoWindow() const { return impl_->autoWl; }
const TransferFunction& Renderer::transferFunction() const { return impl_->tf; }
const RenderOptions& Renderer::options() const { return impl_->opt; }

void Renderer::setTransferFunction(const TransferFunction& tf) {
  VS_REQUIRE(!tf.empty(), "render: empty transfer function");
  impl_->tf = tf;
  impl_->tableStale = true;
}

void Renderer::setOptions(const RenderOptions& o) {
  auto& I = *impl_;
  VS_REQUIRE(std::isfinite(o.sampleStep) && o.sampleStep > 0.01 && o.sampleStep <= 16,
             "render: sample step must be in (0.01, 16] voxels");
  VS_REQUIRE(o.earlyTermination > 0 && o.earlyTermination <= 1, "render: early termination must be in (0, 1]");
  VS_REQUIRE(o.depthThreshold > 0 && o.depthThreshold <= 1, "render: depth threshold must be in (0, 1]");
  VS_REQUIRE(o.faceOpacity >= 0 && o.faceOpacity <= 1, "render: face opacity must be in [0, 1]");
  VS_REQUIRE(o.labelOpacity >= 0 && o.labelOpacity <= 1, "render: label opacity must be in [0, 1]");
  VS_REQUIRE(o.ambient >= 0 && o.ambient <= 1 && o.diffuse >= 0 && o.diffuse <= 1 && o.specular >= 0 && o.specular <= 1,
             "render: lighting: ambient, diffuse and specular coefficients must be in [0, 1]");
  VS_REQUIRE(o.specularPower >= 0 && o.specularPower <= 128, "render: lighting: specular power must be in [0, 128]");
  VS_REQUIRE(!(o.window.window < 0) && std::isfinite(o.window.window) && std::isfinite(o.window.level),
             "render: window must be >= 0 and finite");
  const int n[3] = {I.nx, I.ny, I.nz};
  const char* axn = "xyz";
  const bool wholeBox =
      o.box[0] == 0 && o.box[1] == 0 && o.box[2] == 0 && o.box[3] == -1 && o.box[4] == -1 && o.box[5] == -1;
  if (o.mode == RenderMode::CutBox && !wholeBox) {
    for (int a = 0; a < 3; ++a) {
      const double lo = o.box[static_cast<size_t>(a)], hi = o.box[static_cast<size_t>(a) + 3];
      VS_REQUIRE(std::isfinite(lo) && std::isfinite(hi), "render: cut box must be finite");
      VS_REQUIRE(hi > lo || (n[a] == 1 && hi == lo), std::string("render: cut box is empty along ") + axn[a] + " (" +
                                                         std::to_string(lo) + " .. " + std::to_string(hi) +
                                                         "); give x0,y0,z0,x1,y1,z1 with x0 < x1 etc.");
      VS_REQUIRE(hi >= 0 && lo <= n[a] - 1, std::string("render: cut box lies outside the volume along ") + axn[a] +
                                                " (volume index 0.." + std::to_string(n[a] - 1) + ")");
    }
  }
  if (o.mode == RenderMode::Triplanar)
    for (int a = 0; a < 3; ++a)
      VS_REQUIRE(o.planes[a] < 0 || o.planes[a] <= n[a] - 1,
                 std::string("render: plane ") + axn[a] + "=" + std::to_string(o.planes[a]) +
                     " is outside the volume (0.." + std::to_string(n[a] - 1) + ")");
  if (o.mode == RenderMode::Monoplanar) {
    VS_REQUIRE(o.planeAxis >= 0 && o.planeAxis <= 2, "render: plane axis must be 0 (x), 1 (y) or 2 (z)");
    VS_REQUIRE(o.planeIndex < 0 || o.planeIndex <= n[o.planeAxis] - 1,
               std::string("render: plane ") + axn[o.planeAxis] + "=" + std::to_string(o.planeIndex) +
                   " is outside the volume (0.." + std::to_string(n[o.planeAxis] - 1) + ")");
  }
  if (o.sampleStep != I.opt.sampleStep) I.tableStale = true;
  I.opt = o;
}

void Renderer::setLabels(const AnyVolume& labels) {
  auto& I = *impl_;
  const auto& lg = geometryOf(labels);
  VS_REQUIRE(lg.dims == I.g.dims,
             "render: label volume " + lg.describe() + " does not match the volume " + I.g.describe());
  const VolumeF32 f = toFloat(labels);
  I.labels.resize(f.voxels().size());
  for (size_t i = 0; i < I.labels.size(); ++i) {
    const float v = f.voxels()[i];
    I.labels[i] = static_cast<uint16_t>(std::isfinite(v) ? std::clamp(v, 0.f, 65535.f) : 0.f);
  }
}

void Renderer::clearLabels() { impl_->labels.clear(); }

void Renderer::addMesh(const TriMesh& mesh, const std::array<float, 3>& color) {
  mesh.validate();
  impl_->meshes.push_back({mesh, color});
}

void Renderer::addPolylines(const std::vector<Polyline>& lines, const std::array<float, 3>& color, double radiusMm) {
  for (const auto& l : lines)
    for (const auto& p : l.points)
      VS_REQUIRE(std::isfinite(p.x()) && std::isfinite(p.y()) && std::isfinite(p.z()),
                 "render: overlay point is not finite");
  impl_->lineSets.push_back({lines, color, radiusMm});
}

void Renderer::clearOverlays() {
  impl_->meshes.clear();
  impl_->lineSets.clear();
}

double Renderer::overlayFractionOutside() const {
  const auto& I = *impl_;
  int64_t total = 0, outside = 0;
  auto test = [&](const Vec3& w) {  // the overlay readers' check (io/overlay_io.h)
    ++total;
    if (!I.g.nearVolume(w)) ++outside;
  };
  for (const auto& m : I.meshes)
    for (const auto& p : m.mesh.positions) test(p);
  for (const auto& l : I.lineSets)
    for (const auto& pl : l.lines)
      for (const auto& p : pl.points) test(p);
  return total ? double(outside) / double(total) : 0.0;
}

void Renderer::prepare(Progress& progress) { impl_->prepare(progress); }

RenderResult Renderer::render(const Camera& camera, int width, int height, Progress& progress) {
  VS_REQUIRE(width >= 1 && height >= 1 && width <= kMaxImageSide && height <= kMaxImageSide,
             "render: image size " + std::to_string(width) + "x" + std::to_string(height) + " is outside 1x1 .. " +
                 std::to_string(kMaxImageSide) + "x" + std::to_string(kMaxImageSide));
  const CameraFrame cf(camera, width, height);
  auto& I = *impl_;
  I.prepare(progress);

  RenderResult res;
  res.image = RgbaImage(width, height);
  const size_t npx = static_cast<size_t>(width) * height;
  res.depth.assign(npx, std::numeric_limits<float>::infinity());

  OverlayBuffer ob;
  const bool haveOverlays = !I.meshes.empty() || !I.lineSets.empty();
  if (haveOverlays) {
    ob.depth.assign(npx, std::numeric_limits<float>::infinity());
    ob.color.assign(npx, {0, 0, 0});
    rasteriseOverlays(cf, I.meshes, I.lineSets, ob);
  }
  const CastFrame frame(I, cf, haveOverlays ? &ob : nullptr);
  res.samples = castImage(frame, res, progress);
  progress.report(1.0, "render");
  return res;
}

}  // namespace vs
