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
  timed_out,  // killed for running past its time limit
  no_result,  // exited without sending its bytes
};

class IsolatedRun {
 public:
  // Starts work() in a child process; the bytes it returns come back through a pipe. work()
  // must not throw. The child never returns into the caller's code and never touches MPI. With
  // memory_limit_mb > 0 the child can allocate at most that much beyond what it inherits (an
  // allocation past it fails in the child, which then reports it instead of taking the machine's
  // memory).
  IsolatedRun(const std::function<std::string()>& work, double timeout_seconds, double memory_limit_mb = 0);
  ~IsolatedRun();  // kills and reaps a child that is still running
  IsolatedRun(const IsolatedRun&) = delete;
  IsolatedRun& operator=(const IsolatedRun&) = delete;

  // Reads what the child sent, waiting at most wait_ms; true once the child has ended (or was
  // killed for running past its time limit).
  bool poll(int wait_ms);
  // Blocks until the child has ended.
  void wait();

  ProcessEnd end() const { return end_; }
  int signal() const { return signal_; }  // when crashed
  double peak_mb() const { return peak_mb_; }  // once ended: the child's peak resident memory
  double timeout_seconds() const { return timeout_seconds_; }
  // When finished: the bytes work() returned (moved out).
  std::string take_bytes() { return std::move(received_); }
  // Once ended: the start of what the child printed (stdout and stderr, at most 64 KB), e.g.
  // TetGen's findings or an assertion's text.
  std::string output() const;

 private:
  void finish(bool timed_out);
  bool read_available();  // false at the end of the pipe

  pid_t child_ = -1;
  int fd_ = -1;
  int output_fd_ = -1;  // an in-memory file the child's stdout and stderr go to
  double timeout_seconds_;
  std::chrono::steady_clock::time_point deadline_;
  std::string header_;    // the result's size, as it arrives
  std::string received_;  // sized once the header is complete
  std::size_t filled_ = 0;
  bool overflow_ = false;
  ProcessEnd end_ = ProcessEnd::running;
  double peak_mb_ = 0;
  int signal_ = 0;
};

}  // namespace partet
