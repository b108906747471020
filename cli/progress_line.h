// The command line's progress sink: one line on stderr, "render: rays 42% (~3 s left)",
// redrawn at most ten times a second while stderr is a terminal and --quiet is off; nothing
// at all in a pipe or a log file. Every long command creates one ProgressLine and passes
// progress() to the core; the line is erased when the ProgressLine goes away.
#pragma once

#include <chrono>
#include <string>

#include "util/progress.h"

namespace vs::cli {

class ProgressLine {
 public:
  explicit ProgressLine(std::string command);
  ~ProgressLine();
  ProgressLine(const ProgressLine&) = delete;
  ProgressLine& operator=(const ProgressLine&) = delete;

  Progress& progress() { return progress_; }
  bool drawing() const { return drawing_; }
  // Erases the line (before other output); the next report draws it again.
  void clear();

 private:
  void draw(double fraction, const std::string& stage);

  std::string command_;
  bool drawing_ = false;                                         // stderr is a terminal and --quiet is off
  bool drawn_ = false;                                           // something is on the line now
  std::chrono::steady_clock::time_point stageStart_, lastDraw_;  // the estimate is per stage
  std::string lastStage_;
  Progress progress_;
  ProgressLine* previous_ = nullptr;  // the enclosing line, active again when this one ends
};

// The Progress of the ProgressLine alive now (the innermost), or nullptr: what a SIGINT
// handler cancels so that the running operation stops at its next report (exit 130).
Progress* activeProgress();

// Erases the active progress line, if one is drawn: note() and results call it first.
void clearProgressLine();

// "~3 s left" / "~2 min left" text for an estimate in seconds (tests).
std::string timeLeftText(double seconds);

}  // namespace vs::cli
