#include "progress_line.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>

#include "command.h"

namespace vs::cli {

namespace {
std::atomic<ProgressLine*> gActive{nullptr};
}

Progress* activeProgress() {
  ProgressLine* line = gActive.load();
  return line ? &line->progress() : nullptr;
}

void clearProgressLine() {
  if (ProgressLine* line = gActive.load()) line->clear();
}

void ProgressLine::clear() {
  if (drawn_) std::fputs("\r\033[K", stderr);
  drawn_ = false;
}

std::string timeLeftText(double s) {
  if (!(s >= 0) || !std::isfinite(s)) return {};
  char buf[32];
  if (s < 90)
    std::snprintf(buf, sizeof buf, "~%.0f s left", std::max(1.0, std::round(s)));
  else if (s < 5400)
    std::snprintf(buf, sizeof buf, "~%.0f min left", std::round(s / 60));
  else
    std::snprintf(buf, sizeof buf, "~%.1f h left", s / 3600);
  return buf;
}

ProgressLine::ProgressLine(std::string command)
    : command_(std::move(command)),
      drawing_(!quiet() && isatty(STDERR_FILENO) == 1),
      stageStart_(std::chrono::steady_clock::now()),
      progress_([this](double f, const std::string& stage) { draw(f, stage); }) {
  previous_ = gActive.exchange(this);
}

ProgressLine::~ProgressLine() {
  gActive.store(previous_);
  clear();
}

void ProgressLine::draw(double fraction, const std::string& stage) {
  if (!drawing_) return;
  const auto now = std::chrono::steady_clock::now();
  const std::string shown = stage.empty() ? lastStage_ : stage;
  if (shown != lastStage_) stageStart_ = now;
  // A new stage is drawn at once; within a stage at most ten redraws a second.
  if (drawn_ && shown == lastStage_ && now - lastDraw_ < std::chrono::milliseconds(100) && fraction < 1) return;
  lastDraw_ = now;
  lastStage_ = shown;
  fraction = std::clamp(fraction, 0.0, 1.0);
  const double elapsed = std::chrono::duration<double>(now - stageStart_).count();
  std::string line = "\r\033[K" + command_ + ": " + (shown.empty() ? "" : shown + " ") +
                     std::to_string(static_cast<int>(std::floor(fraction * 100))) + "%";
  // An estimate only once there is something to extrapolate from.
  if (fraction > 0.02 && fraction < 1 && elapsed > 1)
    line += " (" + timeLeftText(elapsed * (1 - fraction) / fraction) + ")";
  std::fputs(line.c_str(), stderr);
  std::fflush(stderr);
  drawn_ = true;
}

}  // namespace vs::cli
