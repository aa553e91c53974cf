#include "mpi/collective_watch.hpp"

#include <chrono>

#include "common/awake_clock.hpp"
#include "common/test_hooks.hpp"
#include "mpi/ranks.hpp"

namespace partet::mpi {

namespace {
CollectiveWatch* newest = nullptr;  // only the rank's own thread, which makes the MPI calls, uses it
}  // namespace

double collective_step_limit() {
  static const double limit = test_hooks::collective_step_seconds(kRootSeconds);
  return limit;
}

void collective_step_ended() {
  if (newest) newest->step();
}

CollectiveWatch::CollectiveWatch(std::string what, double limit_seconds)
    : outer_(newest), what_(std::move(what)), limit_(limit_seconds), deadline_(awake_seconds() + limit_seconds) {
  thread_ = std::thread([this] { watch(); });
  newest = this;
}

CollectiveWatch::~CollectiveWatch() {
  newest = outer_;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    over_ = true;
  }
  wake_.notify_one();
  thread_.join();
}

void CollectiveWatch::step() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    deadline_ = awake_seconds() + limit_;
  }
  if (outer_) outer_->step();  // a step inside a watched step is one of the outer watch's too
}

void CollectiveWatch::watch() {
  std::unique_lock<std::mutex> lock(mutex_);
  // Looks a few times a second: the awake clock, not this wait, decides (a suspended job's
  // pause does not count).
  while (!wake_.wait_for(lock, std::chrono::milliseconds(200), [this] { return over_; }))
    if (awake_seconds() > deadline_)
      // (From this thread: the rank's own is inside an MPI call it cannot leave. MPI_Abort only
      // asks the launcher to end every rank, the stopped one too.)
      abort_job("rank " + std::to_string(my_rank()) + " has waited " + std::to_string(static_cast<long>(limit_)) +
                " s for the other ranks in one step of " + what_ +
                ": a rank stopped, hung or lost its node there (or the filesystem stopped answering it)");
}

}  // namespace partet::mpi
