// Wall-clock seconds per named stage, used by the pipeline and the MPI driver alike.
#pragma once
#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace partet {

// Seconds per stage, in the order the stages ran (a stage may appear more than once).
using StageTimes = std::vector<std::pair<std::string, double>>;

inline double now_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// Records the time since the previous lap (or construction) under a stage name.
class StageTimer {
 public:
  explicit StageTimer(StageTimes* times) : times_(times), start_(now_seconds()) {}
  void lap(const std::string& stage) {
    const double now = now_seconds();
    if (times_) times_->emplace_back(stage, now - start_);
    start_ = now;
  }

 private:
  StageTimes* times_;
  double start_;
};

}  // namespace partet
