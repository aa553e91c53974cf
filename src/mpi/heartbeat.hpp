// Heartbeats (internal header). While a worker's TetGen process works on a piece, the worker
// tells rank 0 every few seconds that it is alive, so rank 0 notices within kSilentSeconds a
// rank that is stopped, hung or lost with its node, rather than after the piece's own wall time
// limit (hours for a large piece with a quality bound). Before and after the TetGen process
// (taking the task, splitting and keeping the result) that limit still bounds the wait.
#pragma once
#include <mpi.h>

#include <cstdint>
#include <list>
#include <utility>
#include <vector>

namespace partet::mpi {

constexpr int kTagAlive = 9;
constexpr double kSilentSeconds = 60;
// How long rank 0 lets such a worker be silent: kSilentSeconds, unless a test sets it. The worker
// says it is alive 12 times as often.
double silence_limit();

// What a heartbeat says: the worker's task (pieces, regions and caps, counted from 1 by both
// sides, so a late heartbeat for a task already answered is told apart) and whether its TetGen
// process is at work (1) or done (0).
struct Alive {
  std::uint64_t task = 0;
  std::uint64_t meshing = 0;
};

// A worker's heartbeats for one task, to rank 0.
class Heartbeat {
 public:
  Heartbeat(MPI_Comm comm, std::uint64_t task) : comm_(comm), task_(task) {}
  // Waits for the heartbeats sent to leave (they are small: at once, unless rank 0 is gone).
  ~Heartbeat();
  Heartbeat(const Heartbeat&) = delete;
  Heartbeat& operator=(const Heartbeat&) = delete;
  // The TetGen process is at work: says so now, then again each time silence_limit() / 12 has passed.
  void meshing();
  // It is done: says so once, if it said it was at work.
  void done();

 private:
  void send(bool meshing);
  struct Sent {
    Alive message;
    MPI_Request request;
  };
  MPI_Comm comm_;
  std::uint64_t task_;
  double last_ = -1;      // when the last heartbeat went (awake_seconds); -1: none yet
  std::list<Sent> sent_;  // not yet known to have left
};

// Rank 0: the heartbeats that have come, with their sources, in the order taken.
std::vector<std::pair<int, Alive>> take_heartbeats(MPI_Comm comm);

}  // namespace partet::mpi
