// DICOM series with known geometry, written by tests/io/dicom_fixtures.py with pydicom at test
// time (axial, coronal, sagittal, oblique, gantry-tilted, single slices, MONOCHROME1, NM, 1-bit,
// a 3-plane localizer, two series in one folder, an RT export with RTDOSE/RTSTRUCT/SEG/DICOMDIR).
// Every voxel is checked against the linear value model the script wrote.
#include <gtest/gtest.h>

#include <cstdlib>
#include <nlohmann/json.hpp>

#include "io/volume_io.h"
#include "io_test_util.h"

namespace vs::test {
namespace {

#ifndef VS_SOURCE_DIR
#define VS_SOURCE_DIR "."
#endif

class DicomSeries : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (std::system("/usr/bin/python3 -c 'import pydicom, numpy' >/dev/null 2>&1") != 0) return;
    dir_ = new TempDir("dicomfixtures");
    const std::string script = std::string(VS_SOURCE_DIR) + "/tests/io/dicom_fixtures.py";
    const std::string cmd = "/usr/bin/python3 '" + script + "' '" + dir_->path.string() + "'";
    if (std::system(cmd.c_str()) != 0) return;
    std::ifstream in(dir_->file("expected.json"));
    expected_ = new nlohmann::json(nlohmann::json::parse(in));
  }
  static void TearDownTestSuite() {
    delete dir_;
    delete expected_;
    dir_ = nullptr;
    expected_ = nullptr;
  }
  static inline TempDir* dir_ = nullptr;
  static inline nlohmann::json* expected_ = nullptr;
};

TEST_F(DicomSeries, EveryFixtureReadWithItsKnownGeometry) {
  if (!dir_) GTEST_SKIP() << "python3-pydicom (or numpy) not installed: scripts/install-deps.sh installs it";
  ASSERT_NE(expected_, nullptr) << "tests/io/dicom_fixtures.py failed";
  const auto& coef = (*expected_)["coef"];
  const double offset = (*expected_)["offset"];
  int checked = 0;
  for (const auto& c : (*expected_)["cases"]) {
    const std::string name = c["name"], path = c["read"];
    SCOPED_TRACE(name + ": " + path);
    ReadInfo info;
    if (c.contains("error")) {
      try {
        readVolume(path, {}, &info);
        ADD_FAILURE() << "read without error";
      } catch (const IoError& e) {
        EXPECT_NE(std::string(e.what()).find(c["error"].get<std::string>()), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(fs::path(path).filename().string()), std::string::npos) << e.what();
      }
      ++checked;
      continue;
    }
    AnyVolume v;
    try {
      v = readVolume(path, {}, &info);
    } catch (const std::exception& e) {
      ADD_FAILURE() << e.what();
      continue;
    }
    const Geometry& g = geometryOf(v);
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(g.dims[i], c["dims"][i].get<int64_t>()) << "axis " << i;
      EXPECT_NEAR(g.spacing[i], c["spacing"][i].get<double>(), 1e-4) << "axis " << i;
      EXPECT_NEAR(g.origin[i], c["origin"][i].get<double>(), 1e-3) << "axis " << i;
      for (int j = 0; j < 3; ++j)
        EXPECT_NEAR(g.direction(i, j), c["direction"][3 * i + j].get<double>(), 1e-4) << "(" << i << "," << j << ")";
    }
    if (c.contains("notes"))
      for (const auto& want : c["notes"]) {
        bool found = false;
        for (const auto& n : info.notes) found = found || n.find(want.get<std::string>()) != std::string::npos;
        EXPECT_TRUE(found) << "no note with '" << want.get<std::string>() << "'";
      }
    const VolumeF32 f = std::visit(
        [](const auto& vol) {
          VolumeF32 out(vol.geometry());
          for (int64_t i = 0; i < vol.size(); ++i) out.data()[i] = static_cast<float>(vol.data()[i]);
          return out;
        },
        v);
    if (c["values"].get<bool>()) {
      const double tol = c["tolerance"];
      int64_t bad = 0, inside = 0;
      for (int64_t z = 0; z < g.dims[2]; ++z)
        for (int64_t y = 0; y < g.dims[1]; ++y)
          for (int64_t x = 0; x < g.dims[0]; ++x) {
            const Vec3 w = g.indexToWorld(Vec3(double(x), double(y), double(z)));
            const double want =
                offset + coef[0].get<double>() * w[0] + coef[1].get<double>() * w[1] + coef[2].get<double>() * w[2];
            const double got = f(x, y, z);
            // Gantry tilt: the resampled slices' uncovered border holds the fill value.
            if (tol > 0 && (x < 3 || y < 6 || x >= g.dims[0] - 3 || y >= g.dims[1] - 6)) continue;
            ++inside;
            if (std::fabs(got - want) > tol + 0.5) ++bad;
          }
      EXPECT_EQ(bad, 0) << "of " << inside << " voxels differ from the value model";
    } else {
      double lo = 1e30, hi = -1e30, sum = 0;
      for (float x : f.voxels()) lo = std::min<double>(lo, x), hi = std::max<double>(hi, x), sum += x;
      EXPECT_EQ(lo, c["range"][0].get<double>());
      EXPECT_EQ(hi, c["range"][1].get<double>());
      EXPECT_EQ(sum, c["sum"].get<double>());
    }
    ++checked;
  }
  EXPECT_GE(checked, 20);
}

}  // namespace
}  // namespace vs::test
