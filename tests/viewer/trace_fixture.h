// The window tests' traced tree: a 64^3 vessel phantom with three terminals written to a NIfTI
// file, and the script lines that trace it (vessel transfer function, MIP, the trace tool, the
// root and terminal points).
#pragma once
#include <sys/wait.h>

#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

#include "io/volume_io.h"
#include "phantom/phantom.h"
#include "xserver.h"

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

// `volscissors view VOLUME --size WxH --renderer gpu --script SCRIPT` on the test's X server, its
// stdout and stderr in outDir/out.txt and outDir/err.txt. noWindow: the viewer exited because no
// window could be opened (the caller skips, saying so).
struct ViewerScriptRun {
  int rc = -1;
  std::string err;
  bool noWindow = false;
};
inline ViewerScriptRun runViewerScript(const XServer& xserver, const std::string& volume, const std::string& script,
                                       const std::string& outDir, int w, int h) {
  const std::string cmd = "env " + xserver.env() + " " + std::string(VS_CLI_PATH) + " view " + volume + " --size " +
                          std::to_string(w) + "x" + std::to_string(h) + " --renderer gpu --script " + script + " > " +
                          outDir + "/out.txt 2> " + outDir + "/err.txt";
  const int status = std::system(cmd.c_str());
  ViewerScriptRun run;
  run.rc = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream ef(outDir + "/err.txt");
  run.err.assign(std::istreambuf_iterator<char>(ef), {});
  run.noWindow = run.rc != 0 && (run.err.find("cannot open a window") != std::string::npos ||
                                 run.err.find("cannot create a window") != std::string::npos);
  return run;
}

}  // namespace vs::viewer::testing
