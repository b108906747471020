// One background job off the UI thread (features, searches): runs a function on its own thread
// with a vs::Progress the UI reads (fraction, stage) and can cancel. The UI thread only polls;
// it never waits longer than it asks to (wait() is for scripts and tests).
#pragma once
#include <atomic>
#include <chrono>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "util/error.h"
#include "util/progress.h"

namespace vs::viewer {

class BackgroundJob {
 public:
  enum class State { Idle, Running, Done, Failed, Cancelled };

  BackgroundJob() = default;
  ~BackgroundJob() {
    cancel();
    join();
  }
  BackgroundJob(const BackgroundJob&) = delete;
  BackgroundJob& operator=(const BackgroundJob&) = delete;

  // Starts `work` on a new thread; a job already running is cancelled and joined first.
  void start(std::string name, std::function<void(Progress&)> work) {
    cancel();
    join();
    name_ = std::move(name);
    progress_ = std::make_unique<Progress>([this](double f, const std::string& stage) {
      fraction_.store(f);
      std::lock_guard<std::mutex> lock(mutex_);
      stage_ = stage;
    });
    fraction_.store(0);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      error_.clear();
      stage_.clear();
    }
    state_.store(State::Running);
    thread_ = std::thread([this, work = std::move(work)] {
      State end = State::Done;
      try {
        work(*progress_);
      } catch (const Cancelled&) {
        end = State::Cancelled;
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(mutex_);
        error_ = e.what();
        end = State::Failed;
      }
      fraction_.store(1);
      state_.store(end);
    });
  }
  // Asks the job to stop at its next progress report (acts within one report interval).
  void cancel() {
    if (progress_ && state_.load() == State::Running) progress_->cancel();
  }
  // Waits until the job ended or `timeout` passed; true if it ended.
  bool wait(std::chrono::milliseconds timeout = std::chrono::hours(24)) {
    const auto until = std::chrono::steady_clock::now() + timeout;
    while (state_.load() == State::Running) {
      if (std::chrono::steady_clock::now() >= until) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    join();
    return true;
  }
  bool running() const { return state_.load() == State::Running; }
  State state() const { return state_.load(); }
  double fraction() const { return fraction_.load(); }
  const std::string& name() const { return name_; }
  std::string stage() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return stage_;
  }
  std::string error() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return error_;
  }

 private:
  void join() {
    if (thread_.joinable()) thread_.join();
  }
  std::string name_;
  std::unique_ptr<Progress> progress_;
  std::thread thread_;
  std::atomic<State> state_{State::Idle};
  std::atomic<double> fraction_{0};
  mutable std::mutex mutex_;
  std::string stage_, error_;
};

}  // namespace vs::viewer
