#include "app/cpu_view.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <thread>

#include "app/viewer_app.h"
#include "util/error.h"
#include "util/progress.h"

namespace vs::viewer {

namespace {

bool sameCamera(const Camera& a, const Camera& b) {
  return a.eye == b.eye && a.target == b.target && a.up == b.up && a.perspective == b.perspective &&
         a.fovDeg == b.fovDeg && a.orthoHeight == b.orthoHeight;
}

// The fields cpuFrameRequest sets (the others keep RenderOptions' defaults).
bool sameOptions(const RenderOptions& a, const RenderOptions& b) {
  return a.mode == b.mode && a.sampleStep == b.sampleStep && a.shading == b.shading && a.box == b.box &&
         a.planes == b.planes && a.planeAxis == b.planeAxis && a.planeIndex == b.planeIndex &&
         a.window.window == b.window.window && a.window.level == b.window.level && a.labelOpacity == b.labelOpacity &&
         a.background == b.background;
}

bool sameFrame(const CpuFrameRequest& a, const CpuFrameRequest& b) {
  return a.volumeRevision == b.volumeRevision && a.tfRevision == b.tfRevision && a.labelsRevision == b.labelsRevision &&
         a.hiddenLabels == b.hiddenLabels && a.width == b.width && a.height == b.height &&
         sameCamera(a.camera, b.camera) && sameOptions(a.options, b.options);
}

}  // namespace

CpuFrameRequest cpuFrameRequest(const ViewerApp& app, int width, int height, const std::array<float, 3>& background) {
  CpuFrameRequest r;
  r.volume = app.sharedVolume();
  r.volumeRevision = app.volumeRevision();
  r.tf = app.transferFunction();
  r.tfRevision = app.transferFunctionRevision();
  r.labels = app.labels();
  r.labelsRevision = app.labelsRevision();
  r.hiddenLabels = app.overlays().hiddenLabels;
  const ViewSettings& v = app.view();
  RenderOptions& o = r.options;
  o.mode = v.mode;
  o.sampleStep = v.sampleStep;
  o.shading = v.shading;
  o.box = app.cutBox();
  o.planes = Vec3(double(v.cursor[0]), double(v.cursor[1]), double(v.cursor[2]));
  o.planeAxis = v.monoAxis;
  o.planeIndex = double(v.cursor[static_cast<size_t>(v.monoAxis)]);
  o.window = v.window;
  o.labelOpacity = app.overlays().labelOpacity;
  o.background = background;
  r.camera = app.camera();
  r.width = width;
  r.height = height;
  return r;
}

struct CpuView::Impl {
  std::mutex mutex;
  std::condition_variable wake;
  std::optional<CpuFrameRequest> pending, last;
  uint64_t lastSerial = 0, doneSerial = 0;
  std::shared_ptr<Progress> running;  // the work in progress, to cancel it
  bool runningCancellable = false;
  std::shared_ptr<const Frame> newest;
  std::string error;
  bool stop = false;
  // Worker only: the renderer and what it holds.
  std::unique_ptr<Renderer> renderer;
  uint64_t rendererVolume = 0, rendererTf = 0, rendererLabels = 0;
  std::set<int> rendererHidden;
  std::function<void()> onFrame;
  std::thread worker;

  void prepare(const CpuFrameRequest& r, Progress& progress) {
    if (!renderer || rendererVolume != r.volumeRevision) {
      renderer.reset();
      renderer = std::make_unique<Renderer>(*r.volume, progress);
      rendererVolume = r.volumeRevision;
      rendererTf = rendererLabels = 0;
      rendererHidden.clear();
    }
    if (rendererTf != r.tfRevision) {
      renderer->setTransferFunction(r.tf);
      rendererTf = r.tfRevision;
    }
    if (rendererLabels != r.labelsRevision || rendererHidden != r.hiddenLabels) {
      if (r.labels) {
        VolumeU16 shown = *r.labels;
        if (!r.hiddenLabels.empty())
          for (uint16_t& l : shown.voxels())
            if (l && r.hiddenLabels.count(l)) l = 0;
        renderer->setLabels(AnyVolume(std::move(shown)));
      } else {
        renderer->clearLabels();
      }
      rendererLabels = r.labelsRevision;
      rendererHidden = r.hiddenLabels;
    }
    renderer->setOptions(r.options);
  }

  // The render in progress: a request cancels a full-resolution one (its preview comes sooner);
  // previews and the renderer's preparation finish, so that a drag still shows pictures.
  void setRunning(const std::shared_ptr<Progress>& progress, bool cancellableByRequest) {
    std::lock_guard<std::mutex> g(mutex);
    running = progress;
    runningCancellable = cancellableByRequest;
    if (stop) progress->cancel();
  }

  void run() {
    std::unique_lock<std::mutex> lock(mutex);
    for (;;) {
      wake.wait(lock, [&] { return stop || pending.has_value(); });
      if (stop) return;
      const CpuFrameRequest r = std::move(*pending);
      pending.reset();
      const uint64_t serial = lastSerial;
      lock.unlock();
      std::optional<std::string> failure;
      bool full = false;
      try {
        auto progress = std::make_shared<Progress>();
        setRunning(progress, false);
        prepare(r, *progress);
        // No preview of a view too small to need one; its full frame is not cancelled either.
        const bool preview = int64_t(r.width) * r.height >= 160 * 120;
        for (const int divisor : {kPreviewDivisor, 1}) {
          if (divisor > 1 && !preview) continue;
          if (divisor == 1) {
            progress = std::make_shared<Progress>();
            setRunning(progress, preview);
          }
          const auto t0 = std::chrono::steady_clock::now();
          RenderResult res =
              renderer->render(r.camera, std::max(1, r.width / divisor), std::max(1, r.height / divisor), *progress);
          auto frame = std::make_shared<Frame>();
          frame->renderMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
          frame->image = std::move(res.image);
          frame->serial = serial;
          frame->preview = divisor > 1;
          full = divisor == 1;
          {
            std::lock_guard<std::mutex> g(mutex);
            newest = std::move(frame);
            if (pending) break;  // a newer request: skip this one's full resolution
          }
          if (onFrame) onFrame();
        }
      } catch (const Cancelled&) {
        // Superseded by a newer request (or the window closes); a process-wide cancel with
        // nothing newer is a failure, so that nobody waits for this frame.
        failure = "cancelled";
      } catch (const std::exception& e) {
        failure = std::string(e.what());
      }
      lock.lock();
      running.reset();
      if (full) {
        doneSerial = serial;
        error.clear();
      } else if (failure && (!pending || *failure != "cancelled")) {
        doneSerial = serial;
        error = "CPU renderer: " + *failure;
      }
      if (onFrame && (full || failure)) {
        lock.unlock();
        onFrame();
        lock.lock();
      }
    }
  }
};

CpuView::CpuView() : impl_(std::make_unique<Impl>()) {
  impl_->worker = std::thread([this] { impl_->run(); });
}

CpuView::~CpuView() {
  {
    std::lock_guard<std::mutex> g(impl_->mutex);
    impl_->stop = true;
    if (impl_->running) impl_->running->cancel();
  }
  impl_->wake.notify_all();
  impl_->worker.join();
}

bool CpuView::request(CpuFrameRequest r) {
  VS_REQUIRE(r.volume && r.width > 0 && r.height > 0, "CPU view: a volume and a positive image size are needed");
  std::lock_guard<std::mutex> g(impl_->mutex);
  if (impl_->last && sameFrame(*impl_->last, r)) return false;
  impl_->last = r;
  impl_->pending = std::move(r);
  ++impl_->lastSerial;
  if (impl_->running && impl_->runningCancellable) impl_->running->cancel();
  impl_->wake.notify_one();
  return true;
}

std::shared_ptr<const CpuView::Frame> CpuView::newest() const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  return impl_->newest;
}

uint64_t CpuView::lastRequest() const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  return impl_->lastSerial;
}

bool CpuView::settled() const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  return impl_->doneSerial == impl_->lastSerial;
}

std::string CpuView::error() const {
  std::lock_guard<std::mutex> g(impl_->mutex);
  return impl_->error;
}

}  // namespace vs::viewer

namespace vs::viewer {

void CpuView::setOnFrame(std::function<void()> onFrame) {
  std::lock_guard<std::mutex> g(impl_->mutex);
  impl_->onFrame = std::move(onFrame);
}

}  // namespace vs::viewer
