// Every real volume in ../shared/data loads with the dims, spacing, orientation and value
// scaling that MANIFEST.md documents. Skips (with the reason) when the folder is missing.
#include <gtest/gtest.h>

#include <cstdlib>

#include "io/volume_io.h"
#include "io_test_util.h"

using namespace vs;
using namespace vs::test;

namespace {

struct Expect {
  const char* path;  // relative to the shared data folder
  Index3 dims;
  Vec3 spacing;
  VoxelType type;
  double min, max;
  Vec3 diag;  // expected diagonal of the direction matrix (LPS), off-diagonals ~0
  const char* format;
};

std::string dataPath(const std::string& rel) { return sharedData() + "/" + rel; }

void checkVolume(const std::string& path, const Expect& e, const ReadInfo& info, const AnyVolume& v) {
  const Geometry& g = geometryOf(v);
  EXPECT_EQ(g.dims, e.dims) << path;
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(g.spacing[i], e.spacing[i], 1e-4) << path << " spacing " << i;
    for (int j = 0; j < 3; ++j)
      EXPECT_NEAR(g.direction(i, j), i == j ? e.diag[i] : 0.0, 1e-6) << path << " direction " << i << "," << j;
  }
  EXPECT_EQ(voxelType(v), e.type) << path;
  const ValueRange r = valueRange(v);
  EXPECT_NEAR(r.min, e.min, 0.05) << path;
  EXPECT_NEAR(r.max, e.max, 0.05) << path;
  EXPECT_EQ(r.nonFinite, 0) << path;
  EXPECT_EQ(info.format, e.format) << path;
}

const Expect kFiles[] = {
    {"chest_cta_totalseg/ct_cropped.nii.gz",
     {120, 126, 164},
     {1.5, 1.5, 1.5},
     VoxelType::Int16,
     -1078,
     3343,
     {1, 1, 1},
     "nifti"},
    {"chest_ct_lidc2/LIDC2.mha",
     {256, 256, 133},
     {1.40625, 1.40625, 2.5},
     VoxelType::UInt8,
     0,
     255,
     {1, -1, -1},
     "metaimage"},
    {"head_cta_avm/AVM.nii.gz",
     {337, 319, 154},
     {0.5469, 0.5469, 1.0},
     VoxelType::Float32,
     0,
     563.2,
     {-1, -1, 1},
     "nifti"},
    {"head_3dra_aneurism/aneurism.vti", {256, 256, 256}, {1, 1, 1}, VoxelType::UInt8, 0, 255, {1, 1, 1}, "vti"},
    {"neck_mra_carotid_vtk/carotid.vtk", {76, 49, 45}, {1, 1, 1}, VoxelType::Float32, 0, 580, {1, 1, 1}, "vtk"},
    {"abdomen_mra_aorta_vmtk/aorta.mha",
     {157, 393, 34},
     {0.878906, 0.878906, 1.50009},
     VoxelType::Float32,
     0,
     2570.2048,
     {-1, -1, 1},
     "metaimage"},
    {"head_ct_cranium_invesalius/cranium.nhdr",
     {256, 256, 108},
     {0.9570312, 0.9570312, 1.5},
     VoxelType::Int16,
     -1024,
     2986,
     {1, 1, 1},
     "nrrd"},
    {"head_ct_headsq_vtk/quarter.nhdr", {64, 64, 93}, {3.2, 3.2, 1.5}, VoxelType::Int16, 0, 3926, {1, 1, 1}, "nrrd"},
    {"head_mr_t1_face/chris_t1.nii.gz",
     {188, 256, 190},
     {0.88, 0.88, 0.88},
     VoxelType::UInt8,
     0,
     255,
     {-1, -1, 1},
     "nifti"},
    {"head_mr_seg3d/MR.nii.gz",
     {160, 232, 160},
     {1.0, 0.898437, 0.898437},
     VoxelType::Float32,
     0,
     512,
     {-1, -1, 1},
     "nifti"},
    {"head_mr_small_vtk/HeadMRVolume.mhd", {48, 62, 42}, {4, 4, 4}, VoxelType::UInt8, 0, 255, {1, 1, 1}, "metaimage"},
    {"engine_ct_scivis/engine.nii.gz", {256, 256, 128}, {1, 1, 1}, VoxelType::UInt8, 0, 255, {-1, -1, 1}, "nifti"},
    {"abdomen_ct_dicom_j2k_totalseg/example_ct_dicom",
     {512, 512, 20},
     {0.9765625, 0.9765625, 2.0},
     VoxelType::Int16,
     -1024,
     1839,
     {1, 1, 1},
     "dicom"},
};

}  // namespace

class RealData : public ::testing::TestWithParam<Expect> {};

TEST_P(RealData, LoadsWithManifestGeometryAndValues) {
  const Expect& e = GetParam();
  const std::string path = dataPath(e.path);
  if (!fs::exists(path)) GTEST_SKIP() << "shared data missing: " << path;
  ReadInfo info;
  const AnyVolume v = readVolume(path, {}, &info);
  checkVolume(path, e, info, v);
}

INSTANTIATE_TEST_SUITE_P(Manifest, RealData, ::testing::ValuesIn(kFiles), [](const auto& i) {
  std::string n = i.param.path;
  n = n.substr(0, n.find('/'));
  for (char& c : n)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  return n;
});

TEST(RealDataDetails, ScalingAndOriginNotes) {
  const std::string avm = dataPath("head_cta_avm/AVM.nii.gz");
  if (!fs::exists(avm)) GTEST_SKIP() << "shared data missing: " << avm;
  ReadInfo info;
  readVolume(avm, {}, &info);
  EXPECT_EQ(info.sourceType.rfind("uint8*2.208", 0), 0u) << info.sourceType;
  ASSERT_FALSE(info.notes.empty());
  const std::string carotid = dataPath("neck_mra_carotid_vtk/carotid.vtk");
  const AnyVolume c = readVolume(carotid, {}, &info);
  EXPECT_NEAR(geometryOf(c).origin[0], 100, 1e-9);
  EXPECT_NEAR(geometryOf(c).origin[1], 80, 1e-9);
  EXPECT_NEAR(geometryOf(c).origin[2], 1, 1e-9);
  const AnyVolume aorta = readVolume(dataPath("abdomen_mra_aorta_vmtk/aorta.mha"));
  EXPECT_NEAR(geometryOf(aorta).origin[0], -156.445, 1e-4);
  EXPECT_NEAR(geometryOf(aorta).origin[1], -24.6094, 1e-4);
  const AnyVolume j2k = readVolume(dataPath("abdomen_ct_dicom_j2k_totalseg/example_ct_dicom"), {}, &info);
  EXPECT_NEAR(geometryOf(j2k).origin[2], -804.5, 1e-3);  // the lowest slice comes first
  EXPECT_NE(info.sourceType.find("-1024"), std::string::npos) << info.sourceType;
}

// The 141-slice CT is packed as .tar.gz: unpack once into a temp folder.
class ChestDicom : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    const std::string tgz = dataPath("chest_ct_4dct_dicom/chest_ct_4dct_dicom_00.tar.gz");
    if (!fs::exists(tgz)) return;
    present_ = true;
    dir_ = new TempDir("chestdicom");
    const std::string cmd = "tar xzf '" + tgz + "' -C '" + dir_->path.string() + "'";
    if (std::system(cmd.c_str()) != 0) return;  // folder_ stays empty: the tests fail (data present)
    folder_ = (dir_->path / "chest_ct_4dct_dicom_00").string();
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  static inline TempDir* dir_ = nullptr;
  static inline std::string folder_;
  static inline bool present_ = false;
};

TEST_F(ChestDicom, SeriesWithRescaleAndSliceOrder) {
  if (!present_) GTEST_SKIP() << "shared data missing: chest_ct_4dct_dicom";
  ASSERT_FALSE(folder_.empty()) << "could not unpack chest_ct_4dct_dicom_00.tar.gz with tar";
  ReadInfo info;
  const AnyVolume v = readVolume(folder_, {}, &info);
  const Expect e{"chest",   {512, 512, 141}, {0.9765625, 0.9765625, 2.0}, VoxelType::Int16, -1024, 2976,
                 {1, 1, 1}, "dicom"};
  checkVolume(folder_, e, info, v);
  EXPECT_NEAR(geometryOf(v).origin[2], -164.5, 1e-3);
  EXPECT_EQ(info.sourceType.rfind("uint16", 0), 0u) << info.sourceType;
  // A single file of the series names the whole series.
  std::string one;
  for (const auto& f : fs::directory_iterator(folder_)) {
    one = f.path().string();
    break;
  }
  const AnyVolume v1 = readVolume(one);
  EXPECT_EQ(geometryOf(v1).dims[2], 141);
}

TEST_F(ChestDicom, SeveralSeriesInOneFolder) {
  const std::string j2k = dataPath("abdomen_ct_dicom_j2k_totalseg/example_ct_dicom");
  if (!present_ || !fs::exists(j2k)) GTEST_SKIP() << "shared data missing: chest_ct_4dct_dicom or " << j2k;
  ASSERT_FALSE(folder_.empty()) << "could not unpack chest_ct_4dct_dicom_00.tar.gz with tar";
  TempDir mixed("mixeddicom");
  for (const auto& f : fs::directory_iterator(folder_)) fs::create_symlink(f.path(), mixed.path / f.path().filename());
  for (const auto& f : fs::directory_iterator(j2k)) fs::create_symlink(f.path(), mixed.path / f.path().filename());
  ReadInfo info;
  const AnyVolume big = readVolume(mixed.path.string(), {}, &info);
  EXPECT_EQ(geometryOf(big).dims[2], 141);  // the largest series wins
  std::string other;
  for (const auto& n : info.notes)
    if (n.rfind("other DICOM series in folder: ", 0) == 0) other = n.substr(30, n.find(" (") - 30);
  ASSERT_FALSE(other.empty()) << "the J2K series is not listed in the notes";
  ReadOptions pick;
  pick.dicomSeriesUid = other;
  const AnyVolume small = readVolume(mixed.path.string(), pick, &info);
  EXPECT_EQ(geometryOf(small).dims, (Index3{512, 512, 20}));
  pick.dicomSeriesUid = "9.9.9.no.such.series";
  EXPECT_THROW(readVolume(mixed.path.string(), pick), IoError);
}
