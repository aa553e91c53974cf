// Spreading independent work over this process's CPUs (internal header).
#pragma once
#include <sched.h>

#include <algorithm>
#include <atomic>
#include <cstddef>
#include <exception>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

namespace partet {

// The CPUs this process may run on (its affinity mask: what Slurm or mpirun's binding gave it),
// at most `cap`. Used while the other ranks wait (the writes), so it takes no core from meshing.
inline unsigned usable_cpus(unsigned cap = 8) {
  cpu_set_t set;
  unsigned n = 1;
  if (::sched_getaffinity(0, sizeof set, &set) == 0) n = static_cast<unsigned>(CPU_COUNT(&set));
  return std::clamp(n, 1u, cap);
}

// Lends this thread, for its lifetime, the CPUs in `cpus` besides its own (threads it starts
// meanwhile inherit them): rank 0 borrows the cores of the ranks on its node while they wait for
// it (the writes), so its writing threads and usable_cpus() are not confined to its one core.
// The kernel keeps the mask within the CPUs the process may use at all (a Slurm cgroup); when it
// refuses the loan nothing changes.
class CpuLoan {
 public:
  explicit CpuLoan(const cpu_set_t& cpus) {
    if (::sched_getaffinity(0, sizeof own_, &own_) != 0) return;
    cpu_set_t both;
    CPU_OR(&both, &own_, &cpus);
    lent_ = !CPU_EQUAL(&both, &own_) && ::sched_setaffinity(0, sizeof both, &both) == 0;
  }
  ~CpuLoan() {
    if (lent_) ::sched_setaffinity(0, sizeof own_, &own_);
  }
  CpuLoan(const CpuLoan&) = delete;
  CpuLoan& operator=(const CpuLoan&) = delete;

 private:
  cpu_set_t own_;
  bool lent_ = false;
};

// Calls work(i) for every i in [0, count), on up to `threads` threads (this one included);
// rethrows the first exception once all have stopped. The order of the calls is unspecified:
// work(i) must only touch what belongs to i.
template <class Work>
void parallel_for(std::size_t count, unsigned threads, const Work& work) {
  std::atomic<std::size_t> next{0};
  std::exception_ptr failure;
  std::mutex failure_mutex;
  auto run = [&] {
    for (std::size_t i; (i = next++) < count;) {
      try {
        work(i);
      } catch (...) {
        std::lock_guard<std::mutex> lock(failure_mutex);
        if (!failure) failure = std::current_exception();
        next = count;
      }
    }
  };
  std::vector<std::thread> helpers;
  try {
    for (std::size_t t = 1; t < std::min<std::size_t>(threads, count); ++t) helpers.emplace_back(run);
  } catch (const std::system_error&) {
    // No room for another thread's stack (a tight ulimit -v): the threads already started, and
    // this one, do the work.
  }
  run();
  for (std::thread& h : helpers) h.join();
  if (failure) std::rethrow_exception(failure);
}

}  // namespace partet
