// Runs a function in a forked child process, so that an abort(), a crash or an endless loop in
// it (Debian's TetGen has all three on hard inputs) becomes an ordinary error for the caller.
#pragma once
#include <sys/types.h>

#include <chrono>
#include <functional>
#include <string>

namespace partet {

class IsolatedRun {
 public:
  struct Outcome {
    bool ok = false;
    std::string bytes;    // work()'s result when ok
    std::string message;  // otherwise: work()'s exception text, or how the process ended
  };

  // Starts work() in a child process; its returned bytes (or exception text) come back through
  // a pipe. The child never returns into the caller's code and never touches MPI.
  IsolatedRun(const std::function<std::string()>& work, double timeout_seconds);
  ~IsolatedRun();  // kills and reaps a child that is still running
  IsolatedRun(const IsolatedRun&) = delete;
  IsolatedRun& operator=(const IsolatedRun&) = delete;

  // Reads what the child sent, waiting at most wait_ms; true once the child has finished
  // (or was killed for running past its time limit).
  bool poll(int wait_ms);
  // Blocks until the child has finished.
  void wait();
  // After poll() returned true or wait(): the outcome.
  Outcome outcome() const { return outcome_; }

 private:
  void finish(bool timed_out);

  pid_t child_ = -1;
  int fd_ = -1;
  double timeout_seconds_;
  std::chrono::steady_clock::time_point deadline_;
  std::string received_;
  bool done_ = false;
  Outcome outcome_;
};

}  // namespace partet
