// Wall and CPU seconds of a computation's phases (a trace's report: where its time goes).
#pragma once

#include <chrono>
#include <ctime>
#include <string>
#include <vector>

namespace vs {

struct PhaseTime {
  std::string name;
  double wall = 0;  // seconds
  double cpu = 0;   // CPU seconds of the whole process meanwhile (all its threads)
};

// lap(name, out) appends the phase that began at the previous lap (or at construction) and starts the next.
class PhaseTimer {
 public:
  PhaseTimer() : wall_(Clock::now()), cpu_(std::clock()) {}
  void lap(const std::string& name, std::vector<PhaseTime>& out) {
    const Clock::time_point w = Clock::now();
    const std::clock_t c = std::clock();
    out.push_back(
        {name, std::chrono::duration<double>(w - wall_).count(), static_cast<double>(c - cpu_) / CLOCKS_PER_SEC});
    wall_ = w;
    cpu_ = c;
  }

 private:
  using Clock = std::chrono::steady_clock;
  Clock::time_point wall_;
  std::clock_t cpu_;
};

}  // namespace vs
