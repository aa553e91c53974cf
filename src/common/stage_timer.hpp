// Wall-clock seconds and memory per named stage, used by the pipeline and the MPI driver alike.
#pragma once
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "common/memory.hpp"

namespace partet {

struct StageTime {
  std::string stage;
  double seconds = 0;
  double rss_mb = 0;  // this process's resident memory at the end of the stage
};
// In the order the stages ran (a stage may appear more than once).
using StageTimes = std::vector<StageTime>;

inline double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Prints one progress line for a finished stage: its time, the total so far, memory.
void log_stage(const StageTimes& times);

// Records the time since the previous lap (or construction) under a stage name, and says so
// (one line per stage, as the run goes).
class StageTimer {
 public:
  explicit StageTimer(StageTimes* times, double start = now_seconds()) : times_(times), start_(start) {}
  void lap(const std::string& stage) {
    const double now = now_seconds();
    if (times_) {
      times_->push_back({stage, now - start_, current_rss_mb()});
      log_stage(*times_);
    }
    start_ = now;
  }

 private:
  StageTimes* times_;
  double start_;
};

// Seconds spent on the named steps of one stage, for --verbose ("plan 0.044 s, region 0.012 s"):
// rank 0's bookkeeping between other ranks' work is serial, so it is worth watching.
struct StepClock {
  double last = now_seconds();
  std::string steps;
  void lap(const char* step) {
    const double now = now_seconds();
    char text[64];
    std::snprintf(text, sizeof text, "%s%s %.3f s", steps.empty() ? "" : ", ", step, now - last);
    steps += text;
    last = now;
  }
};

}  // namespace partet
