// A watch over collective steps that cannot wait with a limit of their own (internal header).
// Parallel HDF5 writes through MPI-IO and the distributed check's exchanges: every rank must be
// inside the same call, and a rank that stops, hangs or loses its node there holds every other
// rank in that call for ever, where the job's other waits (ranks.hpp) end it within minutes,
// naming the rank. While a watch lives, a thread of this rank ends the job once no step has
// ended for the watch's limit (awake time, so a job suspended whole and resumed goes on).
#pragma once
#include <condition_variable>
#include <mutex>
#include <string>
#include <thread>

namespace partet::mpi {

// The default limit of a step: as long as a worker waits for rank 0 (kRootSeconds), unless a
// test sets PARTET_TEST_COLLECTIVE_S. A step is one call of at most 256 MB per rank (parallel_hdf5),
// so only a filesystem that writes less than 0.1 MB/s to a rank for an hour could outlast it; in
// the check, a step is one exchange or one pass over at most 256 MB of records (check_exchange.hpp).
double collective_step_limit();

// Tells the newest watch alive in this process (if any) that a step has ended: the check's
// collective calls sit in helpers that know only a communicator, so they report here.
void collective_step_ended();

class CollectiveWatch {
 public:
  // `what` says what the ranks do together ("writing 'out.h5'"), for the message.
  explicit CollectiveWatch(std::string what, double limit_seconds = collective_step_limit());
  ~CollectiveWatch();
  CollectiveWatch(const CollectiveWatch&) = delete;
  CollectiveWatch& operator=(const CollectiveWatch&) = delete;

  // A step every rank takes part in has ended here: the limit starts again (of the watches
  // alive before this one too).
  void step();

 private:
  void watch();

  CollectiveWatch* const outer_;  // the newest watch before this one, current again after it
  const std::string what_;
  const double limit_;
  std::mutex mutex_;
  std::condition_variable wake_;
  double deadline_;  // awake_seconds()
  bool over_ = false;
  std::thread thread_;
};

}  // namespace partet::mpi
