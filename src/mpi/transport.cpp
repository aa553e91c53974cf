#include "mpi/transport.hpp"

#include <algorithm>

namespace partet::mpi {

std::uint64_t send_bytes(const std::string& bytes, int dest, int tag, MPI_Comm comm, std::size_t max_chunk) {
  std::uint64_t size = bytes.size();
  MPI_Send(&size, 1, MPI_UINT64_T, dest, tag, comm);
  for (std::size_t offset = 0; offset < bytes.size(); offset += max_chunk) {
    const std::size_t n = std::min(max_chunk, bytes.size() - offset);
    MPI_Send(bytes.data() + offset, static_cast<int>(n), MPI_BYTE, dest, tag, comm);
  }
  return size + sizeof(size);
}

std::string recv_bytes(int source, int tag, MPI_Comm comm, std::size_t max_chunk) {
  std::uint64_t size = 0;
  MPI_Recv(&size, 1, MPI_UINT64_T, source, tag, comm, MPI_STATUS_IGNORE);
  std::string bytes(size, '\0');
  for (std::size_t offset = 0; offset < size; offset += max_chunk) {
    const std::size_t n = std::min<std::size_t>(max_chunk, size - offset);
    MPI_Recv(bytes.data() + offset, static_cast<int>(n), MPI_BYTE, source, tag, comm, MPI_STATUS_IGNORE);
  }
  return bytes;
}

}  // namespace partet::mpi
