// The window tests' traced tree: a 64^3 vessel phantom with three terminals written to a NIfTI
// file, and the script lines that trace it (vessel transfer function, MIP, the trace tool, the
// root and terminal points).
#pragma once
#include <string>

#include "io/volume_io.h"
#include "phantom/phantom.h"

namespace vs::viewer::testing {

inline std::string voxelArg(const Index3& p) {
  return std::to_string(p[0]) + "," + std::to_string(p[1]) + "," + std::to_string(p[2]);
}

// Writes the phantom to `niftiPath`; returns the script lines up to (not including) `run`.
inline std::string writeTracePhantom(const std::string& niftiPath) {
  VesselPhantomOptions o;
  o.dims = {64, 64, 64};
  o.minTerminals = 3;
  o.maxTerminals = 3;
  const VesselPhantom ph = makeVesselPhantom(o);
  writeVolume(AnyVolume(ph.volume), niftiPath);
  std::string s = "tf vessels\nmode mip\ntool trace\npoint " + voxelArg(ph.truth.rootVoxel) + "\n";
  for (const auto& t : ph.truth.terminalVoxels) s += "point " + voxelArg(t) + "\n";
  return s;
}

}  // namespace vs::viewer::testing
