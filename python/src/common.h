// Shared pieces of the Python bindings: the Volume holder, argument checks that raise
// ValueError/TypeError with the argument's name, and runReleased(), which runs a long core call
// without the GIL while the calling thread stays responsive to Ctrl-C and progress callbacks.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <unistd.h>  // getpid

#include <chrono>
#include <condition_variable>
#include <deque>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <type_traits>

#include "util/error.h"
#include "util/progress.h"
#include "volume/volume.h"

namespace py = pybind11;

namespace vspy {

// A Python-side Volume: shares the core volume so that NumPy views (volume.array) keep it alive.
struct PyVolume {
  std::shared_ptr<vs::AnyVolume> data;
  const vs::AnyVolume& any() const { return *data; }
  const vs::Geometry& geometry() const { return vs::geometryOf(*data); }
};

// A sequence of exactly n finite numbers, else ValueError naming `what`.
std::vector<double> finiteNumbers(const py::handle& obj, size_t n, const std::string& what);
// An (x, y, z) voxel index: integers (or integral floats) inside the volume, else ValueError.
vs::Index3 voxelIndex(const py::handle& obj, const vs::Geometry& g, const std::string& what);
// A list of (x, y, z) points: an (N, 3) array-like or a sequence of triples.
std::vector<vs::Vec3> pointList(const py::handle& obj, const std::string& what);
// The volume argument: a volscissors.Volume, else TypeError telling how to wrap an array once.
const PyVolume& volumeArg(const py::handle& obj, const std::string& what);

// Calls fn(const VolumeF32&) on the voxels: a float32 volume in place, any other voxel type
// converted for this call (the core's tools work in float32, as the CLI converts on load).
template <class Fn>
decltype(auto) withFloat(const vs::AnyVolume& volume, Fn&& fn) {
  if (const auto* f = std::get_if<vs::VolumeF32>(&volume)) return fn(*f);
  return fn(vs::toFloat(volume));
}

// The thread that runs the core calls of runReleased for one calling thread: created on the
// first call, reused by every later one, joined when the calling thread ends. A fresh std::thread
// per call cost 10-15 % of a 25 ms live-wire map (thread start, cold caches; measured by
// bench_python_overhead's BM_LiveWireMapNewThread). Tasks run in submission order.
class CallWorker {
 public:
  static CallWorker& forThisThread() {
    // In a child of fork() the copied worker has no thread: it is left alone (never joined) and
    // a new one started, so multiprocessing's fork workers can call volscissors too.
    struct Holder {
      CallWorker* worker = nullptr;
      pid_t pid = 0;
      ~Holder() {
        if (worker && pid == getpid()) delete worker;
      }
    };
    thread_local Holder holder;
    if (!holder.worker || holder.pid != getpid()) {
      holder.worker = new CallWorker();
      holder.pid = getpid();
    }
    return *holder.worker;
  }
  void submit(std::function<void()> task) {
    std::lock_guard<std::mutex> lock(mutex_);
    tasks_.push_back(std::move(task));
    wake_.notify_one();
  }
  ~CallWorker() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_one();
    thread_.join();
  }
  CallWorker(const CallWorker&) = delete;
  CallWorker& operator=(const CallWorker&) = delete;

 private:
  CallWorker() : thread_([this] { loop(); }) {}
  void loop() {
    for (;;) {
      std::function<void()> task;
      {
        std::unique_lock<std::mutex> lock(mutex_);
        wake_.wait(lock, [&] { return stop_ || !tasks_.empty(); });
        if (tasks_.empty()) return;
        task = std::move(tasks_.front());
        tasks_.pop_front();
      }
      task();
    }
  }
  std::mutex mutex_;
  std::condition_variable wake_;
  std::deque<std::function<void()>> tasks_;
  bool stop_ = false;
  std::thread thread_;  // last: starts once the members above exist
};

// Runs work(progress) on the calling thread's CallWorker; the calling thread releases the GIL
// and wakes every 20 ms (or on a progress report) to call Python's signal handlers and the
// user's callback (in the caller's thread). An exception from either (KeyboardInterrupt from
// Ctrl-C, anything the callback raises) cancels the core call through vs::Progress and is
// re-raised once the work has stopped. Core exceptions are re-thrown in the caller for
// pybind11's translators.
template <class Work>
auto runReleased(const py::object& callback, Work&& work) {
  using Result = std::invoke_result_t<Work&, vs::Progress&>;
  struct Shared {
    std::mutex mutex;
    std::condition_variable wake;
    bool done = false, reported = false;
    double fraction = 0;
    std::string stage;
  };
  auto shared = std::make_shared<Shared>();
  vs::Progress progress([shared](double fraction, const std::string& stage) {
    std::lock_guard<std::mutex> lock(shared->mutex);
    shared->fraction = fraction;
    shared->stage = stage;
    shared->reported = true;
    shared->wake.notify_all();
  });
  using Stored = std::conditional_t<std::is_void_v<Result>, bool, std::optional<Result>>;
  Stored result{};
  std::exception_ptr coreError;
  // `shared` by value: the worker still signals through it after the caller saw `done`.
  CallWorker::forThisThread().submit([&, shared] {
    try {
      if constexpr (std::is_void_v<Result>)
        work(progress);
      else
        result.emplace(work(progress));
    } catch (...) {
      coreError = std::current_exception();
    }
    std::lock_guard<std::mutex> lock(shared->mutex);
    shared->done = true;
    shared->wake.notify_all();
  });

  std::optional<py::error_already_set> pyError;
  std::exception_ptr callbackError;  // a C++ exception out of the callback (a failed cast)
  const bool hasCallback = callback && !callback.is_none();
  for (;;) {
    bool done = false, reported = false;
    double fraction = 0;
    std::string stage;
    {
      py::gil_scoped_release nogil;
      std::unique_lock<std::mutex> lock(shared->mutex);
      shared->wake.wait_for(lock, std::chrono::milliseconds(20), [&] { return shared->done || shared->reported; });
      done = shared->done;
      reported = shared->reported;
      fraction = shared->fraction;
      stage = shared->stage;
      shared->reported = false;
    }
    if (!pyError && !callbackError) {
      try {
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
        if (reported && hasCallback) callback(fraction, stage);
      } catch (py::error_already_set& e) {
        pyError.emplace(std::move(e));
        progress.cancel();
      } catch (...) {
        callbackError = std::current_exception();
        progress.cancel();
      }
    }
    if (done) break;
  }
  if (pyError) throw *pyError;
  if (callbackError) std::rethrow_exception(callbackError);
  if (coreError) std::rethrow_exception(coreError);
  if constexpr (!std::is_void_v<Result>) return std::move(*result);
}

// Registrations, one per source file.
void bindVolume(py::module_& m);
void bindLiveWire(py::module_& m);
void bindTrace(py::module_& m);
void bindRender(py::module_& m);
void bindMesh(py::module_& m);
void bindCost(py::module_& m);

}  // namespace vspy
