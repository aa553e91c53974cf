// Chunked transfer under mpiexec -n 2: a message above 2 GiB (beyond MPI's int counts), and
// small chunk sizes that do not divide the message length; then a SendQueue: messages pushed
// before the receiver takes any (so pushing must not wait for it), empty ones among them, taken
// by recv_bytes in the order pushed. Exits non-zero on any mismatch.
#include <mpi.h>

#include <cstdint>
#include <cstdio>
#include <string>

#include "mpi/transport.hpp"

namespace {

char pattern(std::size_t i) { return static_cast<char>((i * 2654435761u) >> 13); }

std::string make_message(std::size_t size) {
  std::string s(size, '\0');
  for (std::size_t i = 0; i < size; ++i) s[i] = pattern(i);
  return s;
}

bool matches(const std::string& s, std::size_t size) {
  if (s.size() != size) return false;
  for (std::size_t i = 0; i < size; ++i)
    if (s[i] != pattern(i)) return false;
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  MPI_Init(&argc, &argv);
  int rank = 0, size = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  int failures = 0;
  if (size < 2) {
    if (rank == 0) std::fprintf(stderr, "run with mpiexec -n 2\n");
    MPI_Finalize();
    return 1;
  }
  struct Case {
    std::size_t bytes, chunk;
  };
  const std::size_t big = (std::size_t{1} << 31) + 12345;  // > 2 GiB, not a multiple of 1 GiB
  const Case cases[] = {{0, partet::mpi::kMaxChunk}, {1000003, 4096}, {1000003, 1}, {big, partet::mpi::kMaxChunk}};
  for (const Case& c : cases) {
    if (rank == 0) {
      const std::uint64_t sent = partet::mpi::send_bytes(make_message(c.bytes), 1, 7, MPI_COMM_WORLD, c.chunk);
      if (sent != c.bytes + sizeof(std::uint64_t)) ++failures;
    } else if (rank == 1) {
      const std::string got = partet::mpi::recv_bytes(0, 7, MPI_COMM_WORLD, c.chunk);
      const bool ok = matches(got, c.bytes);
      std::printf("%s: %zu bytes in chunks of %zu\n", ok ? "ok" : "MISMATCH", c.bytes, c.chunk);
      if (!ok) ++failures;
    }
  }
  // A SendQueue: rank 1 pushes every message, then tells rank 0 (on another tag) to start taking.
  const std::size_t queued[] = {3000017, 0, 17, 5000011, 0, 1};
  if (rank == 1) {
    partet::mpi::SendQueue queue(0, 9, MPI_COMM_WORLD, 60);
    std::size_t pushed = 0;
    for (std::size_t bytes : queued) queue.push(make_message(bytes)), pushed += bytes;
    if (queue.bytes_waiting() > pushed) ++failures;
    partet::mpi::send_bytes("go", 0, 10, MPI_COMM_WORLD);
    queue.wait_all();
    if (queue.bytes_waiting() != 0) ++failures;
  } else if (rank == 0) {
    if (partet::mpi::recv_bytes(1, 10, MPI_COMM_WORLD) != "go") ++failures;
    for (std::size_t bytes : queued) {
      const bool ok = matches(partet::mpi::recv_bytes(1, 9, MPI_COMM_WORLD), bytes);
      std::printf("%s: queued message of %zu bytes, in order\n", ok ? "ok" : "MISMATCH", bytes);
      if (!ok) ++failures;
    }
  }
  int total = 0;
  MPI_Allreduce(&failures, &total, 1, MPI_INT, MPI_SUM, MPI_COMM_WORLD);
  MPI_Finalize();
  return total == 0 ? 0 : 1;
}
