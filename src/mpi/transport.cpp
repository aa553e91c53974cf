#include "mpi/transport.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

#include "common/awake_clock.hpp"

namespace partet::mpi {

void wait_sleeping(MPI_Request& request, MPI_Status* status, double timeout_seconds) {
  int done = 0;
  for (int spin = 0; spin < 64; ++spin) {
    MPI_Test(&request, &done, status);
    if (done) return;
  }
  // Counted in awake time: a job suspended and resumed as a whole does not time itself out.
  const double start = awake_seconds();
  auto pause = std::chrono::microseconds(20);
  for (;;) {
    MPI_Test(&request, &done, status);
    if (done) return;
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds(1000));
    if (timeout_seconds > 0 && awake_seconds() - start > timeout_seconds)
      throw Stalled("no message for " + std::to_string(static_cast<long long>(timeout_seconds)) + " s");
  }
}

std::uint64_t send_bytes(std::string_view bytes, int dest, int tag, MPI_Comm comm, std::size_t max_chunk,
                         double timeout_seconds) {
  std::uint64_t size = bytes.size();
  MPI_Request request;
  MPI_Isend(&size, 1, MPI_UINT64_T, dest, tag, comm, &request);
  wait_sleeping(request, MPI_STATUS_IGNORE, timeout_seconds);
  for (std::size_t offset = 0; offset < bytes.size(); offset += max_chunk) {
    const std::size_t n = std::min(max_chunk, bytes.size() - offset);
    MPI_Isend(bytes.data() + offset, static_cast<int>(n), MPI_BYTE, dest, tag, comm, &request);
    wait_sleeping(request, MPI_STATUS_IGNORE, timeout_seconds);
  }
  return size + sizeof(size);
}

SendQueue::~SendQueue() {
  for (Message& message : messages_)
    MPI_Waitall(static_cast<int>(message.requests.size()), message.requests.data(), MPI_STATUSES_IGNORE);
}

// The framing is send_bytes' (the size, then parts of at most kMaxChunk), but every part is
// posted at once: send_bytes posts one part at a time, since with small parts (any max_chunk)
// a million requests outstanding would swamp the receiver's queue of unexpected messages.
void SendQueue::push(std::string bytes) {
  Message& message = messages_.emplace_back();
  message.bytes = std::move(bytes);
  message.size = message.bytes.size();
  message.requests.emplace_back();
  MPI_Isend(&message.size, 1, MPI_UINT64_T, dest_, tag_, comm_, &message.requests.back());
  for (std::size_t offset = 0; offset < message.bytes.size(); offset += kMaxChunk) {
    const std::size_t n = std::min(kMaxChunk, message.bytes.size() - offset);
    message.requests.emplace_back();
    MPI_Isend(message.bytes.data() + offset, static_cast<int>(n), MPI_BYTE, dest_, tag_, comm_,
              &message.requests.back());
  }
  waiting_bytes_ += message.bytes.size();
}

bool SendQueue::taken(Message& message) {
  int done = 0;
  MPI_Testall(static_cast<int>(message.requests.size()), message.requests.data(), &done, MPI_STATUSES_IGNORE);
  return done != 0;
}

std::size_t SendQueue::bytes_waiting() {
  while (!messages_.empty() && taken(messages_.front())) {
    waiting_bytes_ -= messages_.front().bytes.size();
    messages_.pop_front();
  }
  return waiting_bytes_;
}

void SendQueue::wait_oldest() {
  if (messages_.empty()) return;
  for (MPI_Request& request : messages_.front().requests) wait_sleeping(request, MPI_STATUS_IGNORE, timeout_seconds_);
  waiting_bytes_ -= messages_.front().bytes.size();
  messages_.pop_front();
}

void SendQueue::wait_all() {
  while (!messages_.empty()) wait_oldest();
}

std::string recv_bytes(int source, int tag, MPI_Comm comm, std::size_t max_chunk, double timeout_seconds) {
  std::uint64_t size = 0;
  MPI_Request request;
  MPI_Irecv(&size, 1, MPI_UINT64_T, source, tag, comm, &request);
  wait_sleeping(request, MPI_STATUS_IGNORE, timeout_seconds);
  std::string bytes(size, '\0');
  for (std::size_t offset = 0; offset < size; offset += max_chunk) {
    const std::size_t n = std::min<std::size_t>(max_chunk, size - offset);
    MPI_Irecv(bytes.data() + offset, static_cast<int>(n), MPI_BYTE, source, tag, comm, &request);
    wait_sleeping(request);
  }
  return bytes;
}

int broadcast_int(int value, int root, MPI_Comm comm, double timeout_seconds) {
  MPI_Request request;
  MPI_Ibcast(&value, 1, MPI_INT, root, comm, &request);
  wait_sleeping(request, MPI_STATUS_IGNORE, timeout_seconds);
  return value;
}

MPI_Request start_broadcast(void* data, std::size_t bytes, int root, MPI_Comm comm) {
  MPI_Request request;
  MPI_Ibcast(data, static_cast<int>(bytes), MPI_BYTE, root, comm, &request);
  return request;
}

void broadcast_bytes(void* data, std::size_t bytes, int root, MPI_Comm comm, double timeout_seconds) {
  MPI_Request request = start_broadcast(data, bytes, root, comm);
  wait_sleeping(request, MPI_STATUS_IGNORE, timeout_seconds);
}

bool all_true(bool mine, MPI_Comm comm, double timeout_seconds) {
  int value = mine ? 1 : 0, all = 0;
  MPI_Request request;
  MPI_Iallreduce(&value, &all, 1, MPI_INT, MPI_MIN, comm, &request);
  wait_sleeping(request, MPI_STATUS_IGNORE, timeout_seconds);
  return all == 1;
}

void gather_bytes(const void* mine, int bytes, void* all, int root, MPI_Comm comm, double timeout_seconds) {
  MPI_Request request;
  MPI_Igather(mine, bytes, MPI_BYTE, all, bytes, MPI_BYTE, root, comm, &request);
  wait_sleeping(request, MPI_STATUS_IGNORE, timeout_seconds);
}

}  // namespace partet::mpi
