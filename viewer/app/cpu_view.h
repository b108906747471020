// The 3D view drawn by the project's CPU renderer (render/renderer.h, the one `volscissors render`
// uses: same camera, mode, transfer function, window and labels) on a worker thread, for windows
// whose OpenGL cannot run the GPU ray caster (no 3.3 core context, or its shaders fail). The UI
// thread never waits for a render: it posts the frame it wants (request) and shows the newest
// finished picture (newest). A new request cancels the render in progress; each request is drawn
// first at 1/kPreviewDivisor of the resolution (what a drag shows) and then at full resolution
// unless a newer request came meanwhile.
// Differences to the GPU ray caster: no jittered ray starts, no stereo pair, and a hidden label's
// voxels lose their colour but are still drawn (the CPU renderer cannot skip them).
#pragma once
#include <array>
#include <functional>
#include <memory>
#include <set>
#include <string>

#include "render/camera.h"
#include "render/renderer.h"
#include "render/transfer_function.h"
#include "util/image.h"
#include "volume/volume.h"

namespace vs::viewer {

class ViewerApp;

struct CpuFrameRequest {
  std::shared_ptr<const AnyVolume> volume;
  uint64_t volumeRevision = 0;
  TransferFunction tf;
  uint64_t tfRevision = 0;
  std::shared_ptr<const VolumeU16> labels;  // null: none
  uint64_t labelsRevision = 0;
  std::set<int> hiddenLabels;
  RenderOptions options;
  Camera camera;
  int width = 0, height = 0;
};

// What the app's 3D view shows now (mono: the centre camera), at width x height pixels.
CpuFrameRequest cpuFrameRequest(const ViewerApp& app, int width, int height, const std::array<float, 3>& background);

class CpuView {
 public:
  static constexpr int kPreviewDivisor = 3;

  struct Frame {
    RgbaImage image;       // top row first
    uint64_t serial = 0;   // the request it shows (1, 2, ... in the order requested)
    bool preview = false;  // drawn at reduced resolution
    double renderMs = 0;   // the render's time on the worker (not the renderer's preparation)
  };

  CpuView();
  ~CpuView();  // cancels and joins the worker
  CpuView(const CpuView&) = delete;
  CpuView& operator=(const CpuView&) = delete;

  // Never waits for a render. A request equal to the last one is ignored; returns whether it was new.
  bool request(CpuFrameRequest r);
  // The newest finished frame (null before the first).
  std::shared_ptr<const Frame> newest() const;
  uint64_t lastRequest() const;
  // The last request has its full-resolution frame or failed.
  bool settled() const;
  // Why the last render failed ("" if it did not).
  std::string error() const;
  // Called on the worker thread after each finished frame or failure (e.g. to wake a window
  // that sleeps until something changes); set it before the first request.
  void setOnFrame(std::function<void()> onFrame);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace vs::viewer
