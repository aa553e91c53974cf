#include "mpi/heartbeat.hpp"

#include "common/awake_clock.hpp"
#include "common/test_hooks.hpp"
#include "mpi/transport.hpp"

namespace partet::mpi {

double silence_limit() {
  static const double limit = test_hooks::silence_seconds(kSilentSeconds);
  return limit;
}

Heartbeat::~Heartbeat() {
  for (auto it = sent_.begin(); it != sent_.end();) {
    try {
      wait_sleeping(it->request, MPI_STATUS_IGNORE, silence_limit() / 12);
      it = sent_.erase(it);
    } catch (const Stalled&) {
      // Rank 0 is gone (the job ends anyway); MPI may still read the message, so it stays.
      MPI_Request_free(&it->request);
      static auto* const left = new std::list<Sent>;
      left->splice(left->end(), sent_, it++);
    }
  }
}

void Heartbeat::meshing() {
  if (last_ < 0 || awake_seconds() - last_ >= silence_limit() / 12) send(true);
}

void Heartbeat::done() {
  if (last_ >= 0) send(false);
}

void Heartbeat::send(bool meshing) {
  for (auto it = sent_.begin(); it != sent_.end();) {  // those that have left
    int left = 0;
    MPI_Test(&it->request, &left, MPI_STATUS_IGNORE);
    it = left ? sent_.erase(it) : std::next(it);
  }
  Sent& sent = sent_.emplace_back();
  sent.message = Alive{task_, meshing ? 1u : 0u};
  MPI_Isend(&sent.message, sizeof sent.message, MPI_BYTE, 0, kTagAlive, comm_, &sent.request);
  last_ = awake_seconds();
}

std::vector<std::pair<int, Alive>> take_heartbeats(MPI_Comm comm) {
  std::vector<std::pair<int, Alive>> taken;
  for (;;) {
    int arrived = 0;
    MPI_Status status;
    MPI_Iprobe(MPI_ANY_SOURCE, kTagAlive, comm, &arrived, &status);
    if (!arrived) return taken;
    Alive alive;
    MPI_Recv(&alive, sizeof alive, MPI_BYTE, status.MPI_SOURCE, kTagAlive, comm, MPI_STATUS_IGNORE);
    taken.emplace_back(status.MPI_SOURCE, alive);
  }
}

}  // namespace partet::mpi
