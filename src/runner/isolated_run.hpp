// Runs a function in a forked child process, so that an abort(), a crash or an endless loop in
// it (Debian's TetGen has all three on hard inputs) becomes an ordinary outcome for the caller
// (internal header).
#pragma once
#include <sys/types.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

namespace partet {

// How a child process ended.
enum class ProcessEnd {
  running,    // not yet
  finished,   // exited normally after sending its bytes
  crashed,    // killed by a signal (signal())
  timed_out,  // killed for using its CPU time without finishing
  stalled,    // killed for not finishing within kWallPerCpuSecond times that in wall time
  no_result,  // exited without sending its bytes
};

// How much wall time a child gets per second of its CPU time limit. The limit counts CPU time,
// so a child waiting for a core that other processes hold (a neighbouring job, more ranks than
// cores) is not stopped for it, and whether it fails does not depend on the load. The wall
// limit only ends a child that cannot run at all (stopped, or starved below a quarter of a core).
constexpr double kWallPerCpuSecond = 4;

class IsolatedRun {
 public:
  // Starts work() in a child process; the bytes it returns come back through a pipe. work()
  // must not throw. The child never returns into the caller's code and never touches MPI. It may
  // use cpu_seconds of CPU time, within kWallPerCpuSecond times that in wall time. With
  // memory_limit_mb > 0 the child can allocate at most that much beyond what it inherits (an
  // allocation past it fails in the child, which then reports it instead of taking the machine's
  // memory).
  IsolatedRun(const std::function<std::string()>& work, double cpu_seconds, double memory_limit_mb = 0);
  ~IsolatedRun();  // kills and reaps a child that is still running
  IsolatedRun(const IsolatedRun&) = delete;
  IsolatedRun& operator=(const IsolatedRun&) = delete;

  // Reads what the child sent, waiting at most wait_ms; true once the child has ended (or was
  // killed for running past its CPU or wall time).
  bool poll(int wait_ms);
  // Blocks until the child has ended.
  void wait();

  ProcessEnd end() const { return end_; }
  int signal() const { return signal_; }  // when crashed
  double peak_mb() const { return peak_mb_; }  // once ended: the child's peak resident memory
  double cpu_limit_seconds() const { return cpu_limit_; }
  double wall_limit_seconds() const { return kWallPerCpuSecond * cpu_limit_; }
  double cpu_seconds() const { return cpu_seconds_; }  // once ended: the CPU time the child used
  // When finished: the bytes work() returned (moved out).
  std::string take_bytes() { return std::move(received_); }
  // Once ended: the start of what the child printed (stdout and stderr, at most 64 KB), e.g.
  // TetGen's findings or an assertion's text.
  std::string output() const;

 private:
  void finish(ProcessEnd killed_for = ProcessEnd::running);
  bool read_available();  // false at the end of the pipe
  bool used_its_cpu_time();  // and if not, when to look again

  pid_t child_ = -1;
  int fd_ = -1;
  int output_fd_ = -1;  // an in-memory file the child's stdout and stderr go to
  double cpu_limit_;
  double wall_deadline_;  // awake_seconds(): a pause of the whole job (suspended) does not count
  // The child's CPU clock, and the first moment it could have used all its CPU time: CPU time
  // never runs faster than the wall clock, so the clock is read only then.
  clockid_t cpu_clock_{};
  bool has_cpu_clock_ = false;
  std::chrono::steady_clock::time_point cpu_look_;
  std::string header_;    // the result's size, as it arrives
  std::string received_;  // sized once the header is complete
  std::size_t filled_ = 0;
  bool overflow_ = false;
  ProcessEnd end_ = ProcessEnd::running;
  double peak_mb_ = 0;
  double cpu_seconds_ = 0;
  int signal_ = 0;
};

}  // namespace partet
