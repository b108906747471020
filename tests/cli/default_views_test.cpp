// Defaults that show something: every display mode, given no options, on every volume in
// ../shared/data, gives a picture that shows the mode - measured, not looked at: the picture
// is not flat, the modes differ from each other, the MIP is not saturated, and each of the
// three triplanar planes is visible somewhere in the triplanar picture. The old defaults fail
// these floors: the monoplanar plane seen edge-on is all black.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "io/volume_io.h"
#include "render/camera.h"
#include "render/renderer.h"
#include "render/slice_render.h"
#include "render/transfer_function.h"
#include "render/view_defaults.h"

namespace fs = std::filesystem;
using namespace vs;

namespace {

const std::string kData = VS_SHARED_DATA_DIR;
constexpr int kSide = 128;  // small pictures: the properties do not depend on the size
// Angiograms (aneurism, AVM, carotid) are vessels in black: a plane through them is mostly
// black by nature, so the floors say "something is shown", not "the picture is bright".
constexpr double kMinStddev = 3.0;                     // luminance levels
constexpr double kMinLit = 0.001;                      // fraction of pixels with luminance > 20
constexpr double kMinModeDifference = 0.3;             // mean |difference| of two modes, levels
constexpr int kMinPlanePixels = kSide * kSide / 1000;  // pixels where a triplanar plane shows alone

double luminance(const RgbaImage& im, int x, int y) {
  const uint8_t* p = im.at(x, y);
  return 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
}

struct Stats {
  double mean = 0, stddev = 0, litFraction = 0, whiteFraction = 0;
};

Stats stats(const RgbaImage& im) {
  Stats s;
  double sum = 0, sum2 = 0;
  int lit = 0, white = 0;
  const int n = im.width * im.height;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const double l = luminance(im, x, y);
      sum += l, sum2 += l * l;
      lit += l > 20;
      white += l > 250;
    }
  s.mean = sum / n;
  s.stddev = std::sqrt(std::max(0.0, sum2 / n - s.mean * s.mean));
  s.litFraction = double(lit) / n;
  s.whiteFraction = double(white) / n;
  return s;
}

double meanAbsDifference(const RgbaImage& a, const RgbaImage& b) {
  double d = 0;
  for (size_t i = 0; i < a.pixels.size(); ++i) d += std::abs(int(a.pixels[i]) - int(b.pixels[i]));
  return d / static_cast<double>(a.pixels.size());
}

RgbaImage render(Renderer& ren, const AnyVolume& vol, RenderMode mode, int planeAxis = -1) {
  RenderOptions o = defaultRenderOptions(vol, mode);
  if (planeAxis >= 0) o.planeAxis = planeAxis;
  ren.setOptions(o);
  ren.prepare();
  const OrbitView view;
  return ren.render(orbitCamera(geometryOf(vol), view.azimuthDeg, view.elevationDeg, 1.0, false), kSide, kSide).image;
}

void checkDefaults(const std::string& name, const AnyVolume& vol) {
  SCOPED_TRACE(name);
  Renderer ren(vol);
  ren.setTransferFunction(TransferFunction::preset("auto", valueRange(vol)));
  const std::vector<std::pair<std::string, RenderMode>> modes{{"full", RenderMode::Full},
                                                              {"cutbox", RenderMode::CutBox},
                                                              {"triplanar", RenderMode::Triplanar},
                                                              {"monoplanar", RenderMode::Monoplanar},
                                                              {"mip", RenderMode::Mip}};
  std::vector<RgbaImage> pics;
  for (const auto& [mode, m] : modes) {
    pics.push_back(render(ren, vol, m));
    const Stats s = stats(pics.back());
    EXPECT_GT(s.stddev, kMinStddev) << mode << ": flat picture (mean " << s.mean << ")";
    EXPECT_GT(s.litFraction, kMinLit) << mode << ": black";
    if (m == RenderMode::Mip) {
      EXPECT_LT(s.whiteFraction, 0.25) << mode << ": saturated";
    }
  }
  for (size_t i = 0; i < pics.size(); ++i)
    for (size_t j = i + 1; j < pics.size(); ++j)
      EXPECT_GT(meanAbsDifference(pics[i], pics[j]), kMinModeDifference)
          << modes[i].first << " and " << modes[j].first << " look the same";
  // Each triplanar plane shows: where the plane alone (monoplanar) shows something, the
  // triplanar picture shows the same pixels - for at least a quarter of them, or kMinPlanePixels.
  const RgbaImage& tri = pics[2];
  for (int axis = 0; axis < 3; ++axis) {
    const RgbaImage mono = render(ren, vol, RenderMode::Monoplanar, axis);
    int lit = 0, shown = 0;
    for (int y = 0; y < kSide; ++y)
      for (int x = 0; x < kSide; ++x)
        if (luminance(mono, x, y) > 20) {
          ++lit;
          if (std::abs(luminance(mono, x, y) - luminance(tri, x, y)) < 3) ++shown;
        }
    EXPECT_GT(lit, 0) << "plane "
                      << "xyz"[axis] << " shows nothing";
    EXPECT_GE(shown, std::min(kMinPlanePixels, lit / 4))
        << "triplanar plane "
        << "xyz"[axis] << " is hidden (" << shown << " of " << lit << " pixels)";
  }
  SliceImageOptions so;
  so.fitWidth = so.fitHeight = kSide;
  const Geometry& g = geometryOf(vol);
  const int axial = axialIndexAxis(g);
  const Stats s = stats(renderSlice(vol, axial, (g.dims[static_cast<size_t>(axial)] - 1) / 2, so));
  EXPECT_GT(s.stddev, kMinStddev) << "slice: flat picture";
}

}  // namespace

TEST(DefaultViews, EveryModeShowsSomethingOnEverySharedVolume) {
  const std::vector<std::string> files{"abdomen_ct_dicom_j2k_totalseg/example_ct_dicom",
                                       "abdomen_mra_aorta_vmtk/aorta.mha",
                                       "chest_ct_lidc2/LIDC2.mha",
                                       "chest_cta_totalseg/ct_cropped.nii.gz",
                                       "engine_ct_scivis/engine.nii.gz",
                                       "head_3dra_aneurism/aneurism.vti",
                                       "head_ct_cranium_invesalius/cranium.nhdr",
                                       "head_ct_headsq_vtk/quarter.nhdr",
                                       "head_cta_avm/AVM.nii.gz",
                                       "head_mr_seg3d/MR.nii.gz",
                                       "head_mr_small_vtk/HeadMRVolume.mhd",
                                       "head_mr_t1_face/chris_t1.nii.gz",
                                       "neck_mra_carotid_vtk/carotid.vtk"};
  int found = 0;
  for (const auto& f : files) {
    const std::string path = kData + "/" + f;
    if (!fs::exists(path)) continue;
    ++found;
    checkDefaults(f, readVolume(path));
  }
  // The 512x512x141 chest CT comes packed; unpack it when present.
  const std::string tgz = kData + "/chest_ct_4dct_dicom/chest_ct_4dct_dicom_00.tar.gz";
  if (fs::exists(tgz)) {
    const fs::path dir = fs::temp_directory_path() / ("vs_defaults_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    ASSERT_EQ(std::system(("tar xzf '" + tgz + "' -C '" + dir.string() + "'").c_str()), 0);
    checkDefaults("chest_ct_4dct_dicom", readVolume((dir / "chest_ct_4dct_dicom_00").string()));
    fs::remove_all(dir);
    ++found;
  }
  if (found == 0) GTEST_SKIP() << "shared data missing: " << kData;
}
