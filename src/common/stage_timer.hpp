// Wall-clock seconds and memory per named stage, used by the pipeline and the MPI driver alike.
#pragma once
#include <chrono>
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

}  // namespace partet
