// Helpers for the I/O tests: private temp folders, byte files, synthetic volumes.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "volume/volume.h"

namespace vs::test {

namespace fs = std::filesystem;

// A fresh folder under the system temp dir, removed at destruction.
struct TempDir {
  fs::path path;
  explicit TempDir(const std::string& name) {
    path = fs::temp_directory_path() / ("vs_io_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string file(const std::string& name) const { return (path / name).string(); }
};

inline void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

inline std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Non-trivial geometry: anisotropic spacing, offset origin, a rotation about z by 30 degrees
// combined with a flip of y (so the direction is not a pure rotation).
inline Geometry testGeometry(Index3 dims) {
  Geometry g;
  g.dims = dims;
  g.spacing = Vec3(0.7, 1.3, 2.5);
  g.origin = Vec3(-12.5, 40.25, 7.0);
  const double a = M_PI / 6;
  g.direction << std::cos(a), std::sin(a), 0, std::sin(a), -std::cos(a), 0, 0, 0, 1;
  return g;
}

// A volume whose voxel values encode their position (and are exact in every type).
template <class T>
Volume<T> rampVolume(const Geometry& g) {
  Volume<T> v(g);
  for (int64_t z = 0; z < g.dims[2]; ++z)
    for (int64_t y = 0; y < g.dims[1]; ++y)
      for (int64_t x = 0; x < g.dims[0]; ++x) {
        double val = static_cast<double>((x * 7 + y * 13 + z * 29) % 250);
        if constexpr (std::is_same_v<T, int16_t>) val = val * 10 - 1000;
        if constexpr (std::is_same_v<T, uint16_t>) val = val * 200;
        if constexpr (std::is_same_v<T, float>) val = val * 0.25 - 3.5;
        v(x, y, z) = static_cast<T>(val);
      }
  return v;
}

inline void expectSameGeometry(const Geometry& a, const Geometry& b, double tol = 1e-5) {
  EXPECT_EQ(a.dims, b.dims);
  for (int i = 0; i < 3; ++i) {
    EXPECT_NEAR(a.spacing[i], b.spacing[i], tol) << "spacing " << i;
    EXPECT_NEAR(a.origin[i], b.origin[i], tol) << "origin " << i;
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(a.direction(i, j), b.direction(i, j), tol) << "direction " << i << "," << j;
  }
}

inline std::string sharedData() { return VS_SHARED_DATA_DIR; }

}  // namespace vs::test
