// Moving byte buffers between ranks (internal header). MPI 3.1 counts are int, so buffers go
// in chunks.
#pragma once
#include <mpi.h>

#include <cstdint>
#include <string>

namespace partet::mpi {

// Largest chunk sent in one MPI call (1 GiB).
constexpr std::size_t kMaxChunk = std::size_t{1} << 30;

// Sends a size header, then the bytes in chunks of at most max_chunk. Returns bytes sent.
std::uint64_t send_bytes(const std::string& bytes, int dest, int tag, MPI_Comm comm, std::size_t max_chunk = kMaxChunk);
std::string recv_bytes(int source, int tag, MPI_Comm comm, std::size_t max_chunk = kMaxChunk);

}  // namespace partet::mpi
