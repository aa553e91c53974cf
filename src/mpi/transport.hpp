// Moving bytes and small agreements between ranks (internal header), without busy waiting:
// OpenMPI's blocking calls poll at 100% CPU, which on a machine with as many cores as ranks
// steals the core of a TetGen process. Every wait here tests its request and sleeps in the
// kernel between tests. MPI 3.1 counts are int, so buffers go in chunks.
#pragma once
#include <mpi.h>

#include <cstdint>
#include <deque>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace partet::mpi {

// Largest chunk sent in one MPI call (1 GiB).
constexpr std::size_t kMaxChunk = std::size_t{1} << 30;

// A wait gave up: the other side has been silent for longer than the caller allows.
struct Stalled : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Waits for a request to complete: a short spin, then tests with sleeps growing to 1 ms.
// Throws Stalled after timeout_seconds (never when 0).
void wait_sleeping(MPI_Request& request, MPI_Status* status = MPI_STATUS_IGNORE, double timeout_seconds = 0);

// Sends a size header, then the bytes in chunks of at most max_chunk. Returns bytes sent. Each
// part may wait up to timeout_seconds for the receiver (0: no limit).
std::uint64_t send_bytes(std::string_view bytes, int dest, int tag, MPI_Comm comm, std::size_t max_chunk = kMaxChunk,
                         double timeout_seconds = 0);
// Receives what send_bytes sent; the header may take up to timeout_seconds to come (0: no limit).
std::string recv_bytes(int source, int tag, MPI_Comm comm, std::size_t max_chunk = kMaxChunk,
                       double timeout_seconds = 0);

// Messages to one rank that go while this rank works on: each is sent as send_bytes sends it
// (its size, then its bytes) but only posted here, and kept until the receiver has taken it.
// They arrive in the order pushed (MPI lets no message overtake another on the same tag).
class SendQueue {
 public:
  SendQueue(int dest, int tag, MPI_Comm comm, double timeout_seconds = 0)
      : dest_(dest), tag_(tag), comm_(comm), timeout_seconds_(timeout_seconds) {}
  // Waits for what is still on its way (without a limit: only an exception can leave any).
  ~SendQueue();
  SendQueue(const SendQueue&) = delete;
  SendQueue& operator=(const SendQueue&) = delete;

  void push(std::string bytes);
  // The bytes not yet taken (it lets go of those taken).
  std::size_t bytes_waiting();
  // Waits, at most timeout_seconds, for the oldest message, or for all; Stalled after that.
  void wait_oldest();
  void wait_all();

 private:
  struct Message {
    std::string bytes;
    std::uint64_t size = 0;
    std::vector<MPI_Request> requests;  // the size, then the bytes' chunks
  };
  bool taken(Message& message);

  int dest_, tag_;
  MPI_Comm comm_;
  double timeout_seconds_;
  std::deque<Message> messages_;  // oldest first (a deque: MPI holds their addresses)
  std::size_t waiting_bytes_ = 0;
};

// Collectives that sleep while they wait, at most timeout_seconds (0: no limit).
int broadcast_int(int value, int root, MPI_Comm comm, double timeout_seconds = 0);
bool all_true(bool mine, MPI_Comm comm, double timeout_seconds = 0);  // every rank learns whether all said true
// Starts a broadcast of `bytes` (at most INT_MAX) at `data` from root; wait_sleeping finishes it.
MPI_Request start_broadcast(void* data, std::size_t bytes, int root, MPI_Comm comm);
// The same, waiting for it (at most timeout_seconds; 0: no limit).
void broadcast_bytes(void* data, std::size_t bytes, int root, MPI_Comm comm, double timeout_seconds = 0);
void gather_bytes(const void* mine, int bytes, void* all, int root, MPI_Comm comm, double timeout_seconds = 0);

}  // namespace partet::mpi
